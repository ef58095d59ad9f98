"""The weighted fit of an Allan curve with extra effects: the IRLS NNLS solution, the grid search of an effect's
nonlinear parameter with its profile interval — and, re-exported from the modules below it, the curve and its
columns (:mod:`._columns`) and what a solution says of the noise terms, the NoiseFit it becomes (:mod:`._noisefit`).

Every curve effect enters the model as a non-negative column of Allan variance (its registry signature,
:mod:`allanite.model.effects`); an effect that ``replaces`` a term (a bandwidth: the filtered white noise is
the white rate noise N, reported as N) zeroes that term's column — but beside a Butterworth (and beside another
kind whose key carries :data:`FLOOR_TAG`) the N column stays, as white noise added after the filter (a quantised
output's floor), non-negative, so 0 where there is none (:func:`has_floor`). An effect measured in the time
domain (a spectral line's amplitude, from its power in the samples' spectrum) is *held*: its key carries the
coefficient and its variance (:func:`held_key`), its column enters every fit at that value and the curve fits
only the others — the Allan curve, where a line's column aliases with a bandwidth's or a resonance's, does not
move it.
Weights are the estimates' EDF under the model's own noise mix, iterated (IRLS); the covariance of the
coefficients counts the dense curve's ~one independent estimate per octave.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from . import _brent
from ._columns import (
    FLOOR_TAG,
    Curve,
    base_name,
    bw_kind,
    column,
    design,
    edf_columns,
    edf_of,
    has_floor,
    held_coherent,
    held_key,
    held_theta,
    res_kind,
    term_columns,
)
from ._irls import chi2_at, irls
from ._noisefit import effect_column_name, noise_fit, theta_terms, upper_theta

__all__ = [
    "base_name",
    "has_floor",
    "bw_kind",
    "res_kind",
    "FLOOR_TAG",
    "held_key",
    "held_theta",
    "held_coherent",
    "column",
    "Curve",
    "Solution",
    "chi2_dof_between",
    "design",
    "solve",
    "chi2s",
    "search",
    "searches",
    "chi2s_of",
    "profile_interval",
    "profile_crossings",
    "PROFILE_RHO",
    "upper_theta",
    "theta_terms",
    "noise_fit",
    "effect_column_name",
    "term_columns",
]


@dataclass
class Solution:
    """A weighted fit of a curve: coefficients ``theta``, the model and EDF per τ, normalised residuals ``z``,
    χ² and its degrees of freedom, the design matrix ``a`` and the coefficients' covariance."""

    theta: np.ndarray
    model: np.ndarray
    nu: np.ndarray
    z: np.ndarray
    chi2: float
    dof: int
    a: np.ndarray
    cov: np.ndarray

    @property
    def chi2_dof(self):
        """χ² per degree of freedom."""
        return self.chi2 / max(1, self.dof)

    def chi2_eff(self, curve):
        """χ² scaled to the curve's effective number of independent points (``curve.n_eff`` of its τ)."""
        return self.chi2 * curve.n_eff / curve.tau.size


def chi2_dof_between(tau: np.ndarray, z: np.ndarray, lo: float, hi: float) -> float:
    """Mean z² (a fit's normalised residuals ``z`` on the curve's ``tau``) over the τ in [lo, hi], the ends taken
    within 10⁻⁹ relative (regions are given by their τ): an ``unexplained`` region's χ²/dof; NaN where no τ lies
    there."""
    z = z[(tau >= lo * (1 - 1e-9)) & (tau <= hi * (1 + 1e-9))]
    return float(np.mean(z**2)) if z.size else float("nan")


def solve(curve: Curve, terms, effects, max_iter: int = 40) -> Solution:
    """IRLS weighted NNLS of the terms plus effects [(key, nonlinear parameter)] (:func:`._irls.irls`); a held
    effect's column (:func:`held_key`) at its coefficient, the others fitted."""
    a, theta, nu, floor = _fits(curve, terms, [effects], max_iter)[0]
    return _finish(curve, a, theta, nu, floor, len(effects), _held(terms, effects))


def chi2s(curve: Curve, terms, effects, key, ps, max_iter: int = 40) -> np.ndarray:
    """χ² of :func:`solve` with ``effects`` plus effect ``key`` at each parameter of ``ps`` — the same numbers,
    the fits run together (:func:`._irls.irls`)."""
    return chi2s_of(curve, terms, [effects + [(key, float(p))] for p in np.atleast_1d(ps)], max_iter)


def chi2s_of(curve: Curve, terms, models: list, max_iter: int = 40) -> np.ndarray:
    """χ² of :func:`solve` of each model of ``models`` (lists of effects, all of one size), fitted together."""
    fits = _fits(curve, terms, models, max_iter)
    return np.array([chi2_at(curve.avar, a, theta, nu, floor) for a, theta, nu, floor in fits])


def _fits(curve: Curve, terms, models: list, max_iter: int) -> list:
    """(design, coefficients, EDF per τ, floor) of the IRLS of each model (a list of effects, all of one size)
    on ``curve``; the fits not done before on this curve run together, and are remembered (a search's best
    parameter is solved again, a profile's centre is the best parameter)."""
    if not models:  # a step whose searches are all on fixed grids has no bounded search's first points
        return []
    keys = [("fit", tuple(terms), tuple((k, float(p)) for k, p in eff), max_iter) for eff in models]
    a_all, nu_all = _stacked(curve, terms, models)
    done = [curve.cached(key) for key in keys]
    todo = [g for g, got in enumerate(done) if got is None]
    if todo:
        y = curve.avar
        whole = len(todo) == len(models)
        a, nu_cols = (a_all, nu_all) if whole else (a_all[todo], nu_all[todo])
        nu0 = nu_cols[0][:, 1] if len(terms) > 1 else nu_cols[0][:, 0]
        floor = 1e-12 * np.max(y)
        held = _held(terms, models[todo[0]])  # the models of one call differ in their last column only
        theta, nu_end = irls(a, nu_cols, y, nu0, max_iter, floor, held=held or None)
        for i, g in enumerate(todo):
            th, nu = theta[i].copy(), nu_end[i].copy()
            th.flags.writeable = nu.flags.writeable = False
            done[g] = curve.remember(keys[g], (th, nu, floor))
    return [(a_all[g], *got) for g, got in enumerate(done)]


def _stacked(curve: Curve, terms, models: list) -> tuple[np.ndarray, np.ndarray]:
    """The designs of ``models`` (:func:`design`, all of one size) and their EDF columns, stacked (G × n × k):
    the models of a grid differ in their last effect's parameter only, so each (earlier effects, last effect)
    group's other columns are built once and copied — the same numbers as one design per model."""
    if len(models) == 1 or not all(models):
        designs = [design(curve, terms, eff) for eff in models]
        return np.stack([d for d, _al in designs]), np.stack([edf_columns(curve, al) for _d, al in designs])
    a0, al0 = design(curve, terms, models[0])
    a = np.empty((len(models),) + a0.shape)
    nu = np.empty_like(a)
    first: dict = {}
    for g, eff in enumerate(models):
        key, p = eff[-1]
        group = (tuple((k, float(q)) for k, q in eff[:-1]), key)
        if group not in first:
            d, al = (a0, al0) if g == 0 else design(curve, terms, eff)
            a[g], nu[g] = d, edf_columns(curve, al)
            first[group] = g
            continue
        g0 = first[group]
        a[g, :, :-1], nu[g, :, :-1] = a[g0, :, :-1], nu[g0, :, :-1]
        a[g, :, -1] = column(key, p, curve)
        nu[g, :, -1] = edf_of(curve, key, p)
    return a, nu


def _held(terms, effects) -> dict:
    """The held columns of a model: {column index: (coefficient, its variance)} (:func:`held_key`)."""
    k = len(terms)
    return {k + j: h for j, (key, _p) in enumerate(effects) if (h := held_theta(key)) is not None}


def _finish(curve, a, theta, nu, floor, n_effects, held=None) -> Solution:
    """The solution at ``theta``: model, normalised residual, χ², and the coefficients' covariance (a held
    column's its time-domain variance, uncorrelated with the others). A held column counts among the numbers
    fitted (in the time domain) for the degrees of freedom."""
    tau = curve.tau
    model = np.maximum(a @ theta, floor)
    w = nu / (2.0 * model**2)
    z = (curve.avar - model) * np.sqrt(w)
    active = theta > 0
    is_held = np.zeros(theta.size, dtype=bool)
    held = held or {}
    is_held[list(held)] = True
    cov = np.full((a.shape[1], a.shape[1]), np.nan)
    fit_idx = np.flatnonzero(active & ~is_held)
    if fit_idx.size:
        aw = a[:, fit_idx] * w[:, None]
        cov[np.ix_(fit_idx, fit_idx)] = np.linalg.pinv(aw.T @ a[:, fit_idx]) * (tau.size / curve.n_eff)
    for i, (_th, var) in held.items():
        cov[i, :] = cov[:, i] = 0.0
        cov[i, i] = var
    dof = max(1, tau.size - int(active.sum()) - n_effects)
    return Solution(theta, model, nu, z, float(np.sum(z**2)), dof, a, cov)


def search(curve, terms, effects, key, grid, continuous=True):
    """Best nonlinear parameter for effect ``key`` on ``grid`` (then refined), its solution, and whether it
    sits at the edge of the grid (:func:`searches` of one; a search :func:`searches` ran before on this curve
    is read from its memory)."""
    return searches(curve, terms, effects, [(key, grid, continuous)])[0]


def searches(curve, terms, effects, specs) -> list:
    """:func:`search` of each ``(key, grid, continuous)`` of ``specs`` with ``effects`` — the same numbers, the
    searches run together: their grids screened in one batch of fits, their bounded refinements (Brent's
    method, :mod:`._brent`) advanced in lockstep, each round's points fitted in one batch. Each result
    ``(p, solution, at_edge)`` is remembered by the curve (a step's proposals ask for searches declared
    beforehand, :func:`.candidates.prefetch`)."""
    eff = tuple((k, float(p)) for k, p in effects)
    keys = [("search", tuple(terms), eff, key, np.asarray(g, dtype=np.float64).tobytes(), c) for key, g, c in specs]
    out = [curve.cached(k) for k in keys]
    todo = [i for i, got in enumerate(out) if got is None]
    if todo:
        best = _refined(curve, terms, effects, [specs[i] for i in todo])
        for i, (p, k) in zip(todo, best):
            key, grid, continuous = specs[i]
            out[i] = curve.remember(keys[i], _searched(curve, terms, effects, key, grid, continuous, p, k))
    # each caller its own Solution (its arrays shared, read-only where the fits' memory keeps them)
    return [(p, replace(sol), at_edge) for p, sol, at_edge in out]


def _refined(curve, terms, effects, specs) -> list:
    """(refined parameter, index of the best grid point) of each search of ``specs``: the grids screened with a
    few reweighting passes (the ranking settles early), then Brent's bounded search on the log-parameter
    between the best point's neighbours, every search's next point fitted together."""
    sizes = [np.asarray(grid).size for _key, grid, _c in specs]
    screen = chi2s_of(curve, terms, [effects + [(key, float(p))] for key, grid, _c in specs for p in grid], 6)
    ks = [int(np.argmin(part)) for part in np.split(screen, np.cumsum(sizes)[:-1])]
    out: list = [(float(grid[k]), k) for (_key, grid, _c), k in zip(specs, ks)]
    gens = {}
    for i, ((_key, grid, continuous), k) in enumerate(zip(specs, ks)):
        lo, hi = math.log(grid[max(0, k - 1)]), math.log(grid[min(grid.size - 1, k + 1)])
        if continuous and hi > lo:
            gens[i] = _brent.bounded(lo, hi, xatol=1e-3)
    # the bounded searches' first points (golden sections of the brackets) fitted with the grids' best values
    pending = {i: next(g) for i, g in gens.items()}
    first = [effects + [(specs[i][0], p)] for i, x in pending.items() for p in (math.exp(x), float(specs[i][1][ks[i]]))]
    chi2s_of(curve, terms, first, 40)
    while pending:
        values = chi2s_of(curve, terms, [effects + [(specs[i][0], math.exp(x))] for i, x in pending.items()], 40)
        nxt = {}
        for (i, _x), v in zip(pending.items(), values):
            try:
                nxt[i] = gens[i].send(float(v))
            except StopIteration as stop:
                out[i] = (math.exp(stop.value), ks[i])
        pending = nxt
    return out


def _searched(curve, terms, effects, key, grid, continuous, p, k) -> tuple:
    """(p, solution, at_edge) of a search whose refined parameter is ``p`` and best grid point ``grid[k]``:
    the grid point kept where the refinement did not lower χ²."""
    sol = solve(curve, terms, effects + [(key, p)])
    if p != float(grid[k]):
        at_k = solve(curve, terms, effects + [(key, float(grid[k]))])
        if sol.chi2 > at_k.chi2:
            p, sol = float(grid[k]), at_k
    # a best value at the edge of its range is not identified — except a FIR's shortest length (2 taps):
    # below it lies "no filter", which is the null model itself
    at_edge = (k == 0 and continuous) or k == np.asarray(grid).size - 1
    return p, sol, at_edge


#: Octave-to-octave correlation of Allan estimates used for the parameters' effective sample size
#: (the mid value of fit.OCTAVE_CORRELATION: 0.42 white angle … 0.87 random walk).
PROFILE_RHO = 0.68


def profile_interval(curve, terms, effects, key, p, sol):
    """Interval of the nonlinear parameter where the effective χ² rises by ≤ 1 over its minimum.

    χ² of the dense, correlated τ points is scaled to n_eff·(1 − ρ)/(1 + ρ) independent ones (n_eff
    octaves whose estimates correlate by ρ = ``PROFILE_RHO`` from one to the next); the crossings are
    interpolated on a log grid around the best value."""
    scale = curve.n_eff * (1 - PROFILE_RHO) / (1 + PROFILE_RHO) / curve.tau.size
    local = p * np.exp(np.linspace(-1.5, 1.5, 41))
    lc = chi2s(curve, terms, effects, key, local)
    lo, hi = profile_crossings(local, (lc - min(sol.chi2, lc.min())) * scale - 1.0)
    return (min(lo, p), max(hi, p))


def profile_crossings(local: np.ndarray, d: np.ndarray) -> tuple[float, float]:
    """Where the scaled profile ``d`` (≤ 0 inside the interval) crosses 0 on either side of its least value,
    interpolated in log-parameter over the ascending grid ``local``; the grid's end where it never does."""
    i0 = int(np.argmin(d))
    lo_i, hi_i = i0, i0
    while lo_i > 0 and d[lo_i - 1] <= 0:
        lo_i -= 1
    while hi_i < local.size - 1 and d[hi_i + 1] <= 0:
        hi_i += 1
    ll = np.log(local)

    def cross(i, j):  # log-parameter where d crosses 0 between i (≤ 0) and j (> 0)
        return math.exp(ll[i] + (ll[j] - ll[i]) * (-d[i]) / (d[j] - d[i]))

    lo = cross(lo_i, lo_i - 1) if lo_i > 0 else float(local[0])
    hi = cross(hi_i, hi_i + 1) if hi_i < local.size - 1 else float(local[-1])
    return lo, hi
