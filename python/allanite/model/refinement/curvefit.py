"""The weighted fit of an Allan curve with extra effects: the curve, the IRLS NNLS solution, the grid search
of an effect's nonlinear parameter with its profile interval, and the NoiseFit it becomes.

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
from scipy.stats import chi2 as chi2_dist

from .. import fitting
from ..effects import EFFECTS, butterworth_order, filtered_white_avar, resonance_avar
from ..terms import TERM_ALPHA, design_matrix
from . import _brent
from ._irls import chi2_at, irls

__all__ = [
    "base_name",
    "has_floor",
    "bw_kind",
    "FLOOR_TAG",
    "held_key",
    "held_theta",
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
    "PROFILE_RHO",
    "upper_theta",
    "theta_terms",
    "noise_fit",
]


def base_name(key: str) -> str:
    """The effect of a column key ("bandwidth:single_pole" → "bandwidth")."""
    return key.split(":", 1)[0]


#: The tail of a bandwidth key whose N column stays beside a kind other than a Butterworth: a white floor after
#: the filter that the samples' spectrum shows and the Allan curve's fit agrees with (:func:`._rolloff.floor_choice`).
FLOOR_TAG = "|floor"


def bw_kind(key: str) -> str:
    """The filter kind of a bandwidth key ("bandwidth:boxcar|floor" → "boxcar")."""
    return key.split(":", 1)[1].removesuffix(FLOOR_TAG)


def held_key(effect: str, theta: float, var: float) -> str:
    """The key of ``effect`` held at coefficient ``theta`` (amplitude², measured in the time domain) with
    variance ``var`` in every fit of the curve."""
    return f"{effect}:held:{theta!r}:{var!r}"


def held_theta(key: str) -> tuple[float, float] | None:
    """(coefficient, its variance) of a held effect's key (:func:`held_key`), else None."""
    parts = key.split(":")
    if len(parts) == 4 and parts[1] == "held":
        return float(parts[2]), float(parts[3])
    return None


def column(key, p, curve):
    """Allan variance per unit amplitude² of effect ``key`` with nonlinear parameter ``p`` on ``curve`` (read-only:
    remembered by the curve, which every step's searches ask for the same grids)."""
    got = curve.cached(("column", key, float(p)))
    if got is None:
        got = curve.remember(("column", key, float(p)), _column(key, p, curve))
    return got


def _column(key, p, curve):
    base = base_name(key)
    tau = curve.tau
    if base == "bandwidth":
        return filtered_white_avar(tau, bw_kind(key), p, curve.fs)
    if base == "resonance":
        return resonance_avar(tau, p, float(key.split(":", 1)[1]), curve.fs)
    sig = EFFECTS[base].signature
    assert sig is not None
    return sig(tau, p, curve.fs)


def _alpha_of(key, p, tau):
    """Noise type each effect resembles at τ, for the EDF of the estimates."""
    alpha = EFFECTS[base_name(key)].alpha
    if alpha is None:
        return np.zeros(tau.size, dtype=int)
    return alpha(tau, p)


#: EDF per τ by (α, averaging factors, record length, estimator): the last :data:`_EDF_KEPT` computed.
_EDF: dict = {}
_EDF_KEPT = 64


class Curve:
    """One Allan curve to fit: τ, m, estimates, record length, estimator (for the EDF)."""

    def __init__(self, tau, m, avar, fs, n_points, estimator):
        self.tau, self.m, self.avar = tau, m, avar
        self.fs, self.n_points, self.estimator = fs, n_points, estimator
        self._edf: dict = {}
        self._memo: dict = {}
        self.n_eff = max(2.0, math.log2(tau[-1] / tau[0]) + 1.0)

    def edf(self, alpha: int) -> np.ndarray:
        """EDF of each estimate for noise type ``alpha`` (computed once per α — and once per averaging factors,
        record length and estimator: the curve of the samples a removal left, or of its held-out parts, has
        the same EDF as the curve before it)."""
        if alpha not in self._edf:
            est = self.estimator if isinstance(self.estimator, str) else tuple(self.estimator)
            key = (int(alpha), self.m.tobytes(), int(self.n_points), est)
            got = _EDF.get(key)
            if got is None:
                got = fitting.edf_per_tau(np.full(self.m.size, alpha), self.m, self.n_points, self.estimator)
                got.flags.writeable = False
                while len(_EDF) >= _EDF_KEPT:  # the oldest out (another thread may be at it too)
                    try:
                        del _EDF[next(iter(_EDF))]
                    except (KeyError, RuntimeError, StopIteration):
                        break
                _EDF[key] = got
            self._edf[alpha] = got
        return self._edf[alpha]

    def subset(self, idx):
        """The curve at the τ indexed by ``idx`` (the same object for the same ``idx``: its columns are
        remembered)."""
        key = ("subset", np.asarray(idx).tobytes())
        got = self.cached(key)
        if got is None:
            est = self.estimator if isinstance(self.estimator, str) else tuple(np.asarray(self.estimator)[idx])
            got = self.remember(key, Curve(self.tau[idx], self.m[idx], self.avar[idx], self.fs, self.n_points, est))
        return got

    def cached(self, key):
        """What :meth:`remember` kept under ``key``, or None (the curve's τ and estimates never change)."""
        return self._memo.get(key)

    def remember(self, key, value):
        """Keep ``value`` (an array is made read-only) for this curve under ``key``; returns it."""
        if isinstance(value, np.ndarray):
            value.flags.writeable = False
        self._memo[key] = value
        return value


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


def design(curve, terms, effects):
    """Columns of the terms and the effects [(key, nonlinear parameter)] on ``curve``, and each column's
    noise type per τ (for the EDF)."""
    tau = curve.tau
    a0 = _term_columns(curve, terms)
    zeroed = [EFFECTS[base_name(key)].replaces for key, _p in effects if not has_floor(key)]
    if any(rep in terms for rep in zeroed):
        a0 = a0.copy()
        for rep in zeroed:
            if rep in terms:
                a0[:, list(terms).index(rep)] = 0.0
    cols = [a0] + [column(key, p, curve)[:, None] for key, p in effects]
    alphas = [np.full(tau.size, TERM_ALPHA[t]) for t in terms] + [_alpha_of(k, p, tau) for k, p in effects]
    return np.hstack(cols), alphas


def has_floor(key: str) -> bool:
    """Whether the term a bandwidth ``key`` carries keeps its own column beside it — white noise added after the
    filter (a quantised output's floor; the bandwidth's ``floor``): beside a Butterworth, whose stop band the
    samples' spectrum shows and a floor is flat in, and beside any other kind whose key carries
    :data:`FLOOR_TAG` — only where the spectrum above the roll-off shows a floor and the fit's floor agrees with
    it (:func:`._rolloff.floor_choice`). Untagged, beside a single pole or a boxcar the term is replaced: there a
    floor trades with the pole's cutoff, the boxcar's span and white angle noise on the Allan curve (ADIS16405
    run 5 gyro_y's boxcar read 1.41 → 1.61 samples with a floor of 0 and white angle noise in its place, run 1
    gyro_z's single pole beside a second resonance at 24.5 Hz)."""
    if base_name(key) != "bandwidth":
        return False
    return key.endswith(FLOOR_TAG) or butterworth_order(bw_kind(key)) > 0


def _term_columns(curve, terms):
    """The terms' columns on ``curve`` (read-only, remembered by the curve)."""
    got = curve.cached(("terms", tuple(terms)))
    if got is None:
        tau = curve.tau
        got = curve.remember(("terms", tuple(terms)), design_matrix(tau, tau * curve.fs, curve.fs, terms))
    return got


def _edf_columns(curve, alphas):
    """Each column's EDF per τ under its noise type per τ (``alphas``, as :func:`design` gives them)."""
    return np.column_stack([_edf_column(curve, al) for al in alphas])


def _edf_column(curve, al):
    """EDF per τ of a column whose noise type per τ is ``al`` (remembered by the curve)."""
    al = np.asarray(al)
    key = ("edf", al.dtype.str, al.tobytes())
    got = curve.cached(key)
    if got is None:
        nu = np.where(
            al == -2,
            curve.edf(-2),
            np.where(al == -1, curve.edf(-1), np.where(al == 2, curve.edf(2), curve.edf(0))),
        )
        got = curve.remember(key, nu)
    return got


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
        return np.stack([d for d, _al in designs]), np.stack([_edf_columns(curve, al) for _d, al in designs])
    a0, al0 = design(curve, terms, models[0])
    a = np.empty((len(models),) + a0.shape)
    nu = np.empty_like(a)
    first: dict = {}
    for g, eff in enumerate(models):
        key, p = eff[-1]
        group = (tuple((k, float(q)) for k, q in eff[:-1]), key)
        if group not in first:
            d, al = (a0, al0) if g == 0 else design(curve, terms, eff)
            a[g], nu[g] = d, _edf_columns(curve, al)
            first[group] = g
            continue
        g0 = first[group]
        a[g, :, :-1], nu[g, :, :-1] = a[g0, :, :-1], nu[g0, :, :-1]
        a[g, :, -1] = column(key, p, curve)
        nu[g, :, -1] = _edf_of(curve, key, p)
    return a, nu


def _edf_of(curve, key, p):
    """EDF per τ of effect ``key``'s column at parameter ``p`` (:func:`_edf_column` of its noise types per τ;
    remembered by the curve under the effect and parameter, as its column is)."""
    got = curve.cached(("edf_of", key, float(p)))
    if got is None:
        got = curve.remember(("edf_of", key, float(p)), _edf_column(curve, _alpha_of(key, p, curve.tau)))
    return got


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
    d = (lc - min(sol.chi2, lc.min())) * scale - 1.0
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
    return (min(lo, p), max(hi, p))


def upper_theta(curve, sol, terms, effects, theta, slow=("B", "K"), delta_chi2=4.0):
    """``theta`` with each slow term (flicker, random walk of rate) raised to the upper end of what the curve
    allows: the largest value with the others refitted (weighted NNLS, the fit's weights) whose χ² rises by
    at most ``delta_chi2`` (≈ 2σ; in effective points). A null model for a time-domain test must not leave
    out a random walk the curve merely could not pin down: one that is there makes warm-up-like wander in the
    block means."""
    out = theta.copy()
    a, _ = design(curve, terms, effects)
    w = np.sqrt(sol.nu / (2.0 * sol.model**2))
    # a held effect's column (a line measured in the time domain) stays at its coefficient
    held = [len(terms) + j for j, (key, _p) in enumerate(effects) if held_theta(key) is not None]
    y = curve.avar - a[:, held] @ sol.theta[held] if held else curve.avar
    a = np.delete(a, held, axis=1) if held else a
    aw, yw = a * w[:, None], y * w
    chi_min = float(np.sum((yw - aw @ fitting.nnls(aw, yw)) ** 2))
    # the dense curve's points are strongly correlated: χ² counts ~n_eff independent ones (as the fit's
    # covariance does), so the rise allowed on the dense χ² is scaled by points / n_eff
    delta_chi2 = delta_chi2 * curve.tau.size / curve.n_eff
    for name in slow:
        if name not in terms:
            continue
        j = list(terms).index(name)
        col = aw[:, j]
        others = np.delete(aw, j, axis=1)
        top = float(np.min(curve.avar / np.maximum(a[:, j], 1e-300)))  # alone it would explain a point
        best = 0.0
        for v in top * np.geomspace(1e-4, 1.0, 41):
            r = yw - v * col
            chi = float(np.sum((r - others @ fitting.nnls(others, r)) ** 2))
            if chi - chi_min <= delta_chi2:
                best = v
        out[j] = max(out[j], best)
    return out


def theta_terms(sol, terms, effects):
    """Squared coefficients of the terms (a bandwidth's N — the white noise before its filter — in place of the N
    column's: zeroed, or where :func:`has_floor` keeps it the floor after the filter, the bandwidth's ``floor``)."""
    k = len(terms)
    theta = sol.theta[:k].copy()
    for j, (key, _p) in enumerate(effects):
        if EFFECTS[base_name(key)].replaces == "N" and "N" in terms:
            theta[list(terms).index("N")] = sol.theta[k + j]
    return theta


def _coefficients(sol, terms, effects, unit, zq, inflate) -> tuple[dict, np.ndarray, np.ndarray]:
    """The terms' coefficients (a bandwidth's N reported as N) and each effect's amplitude, with intervals."""
    k = len(terms)
    theta = sol.theta[:k].copy()
    cov = sol.cov[:k, :k].copy()
    # a bandwidth carries the white rate noise N (before the filter): report it as N
    for j, (key, _p) in enumerate(effects):
        if EFFECTS[base_name(key)].replaces == "N" and "N" in terms:
            i_n = list(terms).index("N")
            theta[i_n] = sol.theta[k + j]
            cov[i_n, :] = cov[:, i_n] = np.nan
            cov[i_n, i_n] = sol.cov[k + j, k + j]
    coeffs = fitting.coefficients(terms, theta, cov, zq, inflate, unit)
    for j, (key, _param) in enumerate(effects):
        i = k + j
        name = effect_column_name(key, j, effects)
        # a column's amplitude is in the rate unit (σ, A), but a bandwidth's is the white noise N before the
        # filter: N's unit (rate unit·√s), not the rate unit
        n_unit = EFFECTS[base_name(key)].replaces == "N" and "N" in coeffs
        coeffs[name] = fitting.Coefficient(
            name=name,
            value=float(math.sqrt(max(sol.theta[i], 0.0))),
            ci=fitting.interval(sol.theta[i], sol.cov[i, i], zq, inflate),
            unit=coeffs["N"].unit if n_unit else unit,
        )
    return coeffs, theta, cov


def effect_column_name(key, j, effects) -> str:
    """The name of effect ``j``'s column among a fit's coefficients and components (numbered when the same
    effect is in the model more than once)."""
    name = base_name(key) if base_name(key) != "regression" else key.replace(":", "_")
    return f"{name}{j + 1}" if sum(base_name(e[0]) == base_name(key) for e in effects) > 1 else name


def noise_fit(curve, terms, effects, sol, result, unit, confidence, removed=None):
    """A NoiseFit for the solution, with the effects' parameters among the coefficients.

    ``removed``: (change, numbers, [(name, own change)]) when components were removed from the samples before
    ``sol`` was fitted: ``curve`` is then the original record's, the model ``sol``'s plus ``change`` (what the
    removals changed in the Allan curve, AVAR(y) − AVAR(y − components)), its χ² on ``curve`` with the
    removals' fitted ``numbers`` off the degrees of freedom, and each removal's own change one of the
    components."""
    zq = fitting.z_quantile(confidence)
    k = len(terms)
    inflate = max(1.0, math.sqrt(sol.chi2_dof))
    coeffs, theta, cov = _coefficients(sol, terms, effects, unit, zq, inflate)
    comps = {t: sol.a[:, i] * sol.theta[i] for i, t in enumerate(terms)}
    for j, (key, _param) in enumerate(effects):
        comps[effect_column_name(key, j, effects)] = sol.a[:, k + j] * sol.theta[k + j]
    model, z, chi2, dof = sol.model, sol.z, sol.chi2, sol.dof
    if removed is not None:
        change, numbers, own = removed
        comps.update(own)
        model = np.maximum(sol.model + change, 1e-300)
        z = (curve.avar - model) * np.sqrt(sol.nu / (2.0 * model**2))
        chi2, dof = float(np.sum(z**2)), max(1, sol.dof - numbers)
    readoffs = fitting.readoffs(result, np.sqrt(np.atleast_2d(result.avar)[0]))
    return fitting.NoiseFit(
        coefficients=coeffs,
        terms=terms,
        tau=curve.tau,
        m=curve.m,
        avar=curve.avar,
        edf=sol.nu,
        model=model,
        components=comps,
        z=z,
        chi2=chi2,
        dof=dof,
        chi2_dof=chi2 / max(1, dof),
        p_value=float(chi2_dist.sf(chi2, dof)),
        readoffs=readoffs,
        fs=curve.fs,
        confidence=confidence,
        unit=unit,
        iterations=0,
        theta=theta,
        covariance=cov,
    )
