"""Close the loop: find what a fitted noise model lacks, add that effect, report the error before and after.

:func:`refine` fits the starting IEEE-952 model (weighted least squares in variance space, as
:func:`allanite.fit`), then traces what it leaves in more than one domain and tries each candidate effect
of the registry :data:`allanite.model.effects.EFFECTS`:

- on the **Allan curve**, by signature (closed forms, ``docs/FORMULAS.md`` §5): ``"bandwidth"`` — the
  sensor's low-pass on its white rate noise (single pole, moving-average or Bartlett FIR, or a boxcar of
  any span), exact in discrete time, replacing the N column; ``"gauss_markov"`` — a bump, T_c in
  [5·τ_min, τ_max/4]; ``"resonance"`` — narrowband noise, a PSD hump at f_r with quality factor Q (near the
  shortest τ, tried after the bandwidth); and, for curve-only input, ``"sinusoid"`` (nulls at τ = k/f0,
  f0 ≥ 2/τ_max);
- in the **PSD** (Welch) for spectral lines: ``"sinusoid"`` with f0 from the periodogram peak, refined;
- in **time**: ``"drift"`` (warm-up a·e^{−t/T} on block means) and ``"change_point"`` (steps of the noise
  level along the record);
- in **other channels** of the log (``channels=``): ``"regression"`` — the rate regressed on each, band by
  band (octaves) where the coupling differs across frequency (:func:`allanite.model.tracing.band_regression`).

Every curve effect enters the model as a non-negative column of Allan variance; the time-domain ones (drift,
regression) are removed from the samples, and their in-sample "after" adds back what the removal changed in
the curve, AVAR(y) − AVAR(y − component) (own variance and cross terms, exactly). A candidate is **accepted** only if

1. a calibrated test says the residual asks for it: the GLS score statistic on ~4 τ per octave with the
   covariance of the estimates across τ (exact for the five terms, :mod:`allanite.model._covariance`),
   above the (1 − α) quantile of its maximum over all candidate families under the fitted model
   (parametric bootstrap, :class:`allanite.model.tracing.ScoreTest`); spectral lines by their own
   χ² test on the Welch PSD (Bonferroni over the bins); α splits the per-record ``level``;
2. its parameter is not pinned at the edge of its search range and its amplitude is positive;
3. χ²/dof of the dense curve falls; and
4. the **held-out** error falls: the record is cut into 8 blocks, the odd and the even ones joined end to end;
   the model with and without the effect is fitted on one part's Allan curve and predicts the other's (both
   ways, RMS ADEV error averaged, on the τ whose estimate is within ±10 %). A drift or regression is refitted
   on the held-in part's samples; change points are held out per segment (each segment's own alternate
   blocks, predicted by the segment's model vs the one-level model). Curve-only input has no held-out error
   (reported as None) and relies on the calibrated test.

RMS ADEV errors (in-sample and held out) are scored on 4 τ per octave whose estimate is informative (EDF ≥ 50
under the five-term fit: ±10 %); beyond, the estimate's own scatter, not the model, would decide the score.

Nonlinear parameters (T_c, cutoff, f0 on curves) are found by a grid search with the linear coefficients
by weighted NNLS at each grid point, then refined by a bounded scalar search; their intervals come from the
profile of χ² (Δχ²_eff = 1). The loop stops when no candidate is accepted or after ``MAX_STEPS`` effects.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize_scalar
from scipy.stats import chi2 as chi2_dist
from scipy.stats import t as t_dist

from .._display import RichDisplay, Summary, Table, fmt_ci, thin
from .._progress import StepBar
from .._validate import as_rate_columns
from ..analysis import avar, davar
from ..errors import InputError, ParameterError
from ..estimators.grid import tau_grid
from ..results import AllanResult
from . import fitting, tracing
from .effects import (
    CASCADE_SPANS,
    EFFECTS,
    RESONANCE_Q,
    describe,
    drift_avar,
    filter_autocorrelation,
    filter_cutoff,
    filtered_white_avar,
    gm_avar,
    resonance_avar,
    sinusoid_avar,
)
from .terms import TERM_ALPHA, check_terms, design_matrix

__all__ = ["refine", "Refinement", "Step", "gm_avar", "sinusoid_avar", "CANDIDATES", "LEVEL"]

#: Effects refine can add, from the registry in :mod:`allanite.model.effects`.
CANDIDATES = tuple(EFFECTS)
#: Default false-alarm level per record (clean record: probability that anything is added).
LEVEL = 0.05
#: Share of ``level`` spent on spectral lines (the rest on the Allan-curve families and change points).
LINE_SHARE = 0.2
CHANGE_POINT_SHARE = 0.2
MAX_STEPS = 4
N_BOOT = 1000
#: Blocks for the held-out error (odd blocks predict even ones and back).
HELDOUT_BLOCKS = 8
#: A bandwidth that raises the held-out error alone may enter with a Gauss–Markov term if its statistic is
#: at least this multiple of the threshold.
PAIR_FACTOR = 100.0
#: Share of ``level`` for each time-domain test (regression on channels, drift).
TIME_SHARE = 0.075
#: Blocks in time of a regression (each de-meaned; SE from the blocks' scores, t with at most blocks − 1 dof).
REGRESSION_BLOCKS = 8
#: RMS ADEV errors: only τ whose ADEV estimate is within ±10 % (EDF ≥ 50 under the five-term fit).
HELDOUT_MIN_EDF = 50.0
#: Held-out error: only τ where the two parts' own ADEV agree within this fraction.
HELDOUT_AGREE = 0.2
#: Kept for the change-point test's penalty (calibrated with it on clean records).
MIN_GAIN = 6.0


def _base(key: str) -> str:
    return key.split(":", 1)[0]


def _column(key, p, curve):
    """Allan variance per unit amplitude² of effect ``key`` with nonlinear parameter ``p`` on ``curve``."""
    base = _base(key)
    tau = curve.tau
    if base == "bandwidth":
        return filtered_white_avar(tau, key.split(":", 1)[1], p, curve.fs)
    if base == "drift":
        return sum(
            math.exp(-2.0 * s0 / (curve.fs * p)) * drift_avar(tau, p, curve.fs, nb) for s0, nb in curve.blocks
        ) / len(curve.blocks)
    if base == "regression":
        return curve.channels[key.split(":", 1)[1]]
    if base == "resonance":
        return resonance_avar(tau, p, float(key.split(":", 1)[1]), curve.fs)
    sig = EFFECTS[base].signature
    assert sig is not None
    return sig(tau, p, curve.fs)


def _alpha_of(key, p, tau):
    """Noise type each effect resembles at τ, for the EDF of the estimates."""
    alpha = EFFECTS[_base(key)].alpha
    if alpha is None:
        return np.zeros(tau.size, dtype=int)
    return alpha(tau, p)


# ----------------------------------------------------------------------------------------------
# weighted fit with extra effects


class _Curve:
    """One Allan curve to fit: τ, m, estimates, record length, estimator (for the EDF); the blocks of
    samples it averages ([(first sample, samples)]) and the channels' Allan curves on it."""

    def __init__(self, tau, m, avar, fs, n_points, estimator, blocks=None, channels=None):
        self.tau, self.m, self.avar = tau, m, avar
        self.fs, self.n_points, self.estimator = fs, n_points, estimator
        self.blocks = blocks or [(0, n_points - 1)]
        self.channels = channels or {}
        self._edf = {}
        self.n_eff = max(2.0, math.log2(tau[-1] / tau[0]) + 1.0)

    def edf(self, alpha: int) -> np.ndarray:
        if alpha not in self._edf:
            self._edf[alpha] = fitting.edf_per_tau(np.full(self.m.size, alpha), self.m, self.n_points, self.estimator)
        return self._edf[alpha]

    def subset(self, idx):
        c = _Curve(
            self.tau[idx],
            self.m[idx],
            self.avar[idx],
            self.fs,
            self.n_points,
            self.estimator if isinstance(self.estimator, str) else tuple(np.asarray(self.estimator)[idx]),
            self.blocks,
            {k: v[idx] for k, v in self.channels.items()},
        )
        return c


@dataclass
class _Solution:
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
        return self.chi2 / max(1, self.dof)

    def chi2_eff(self, curve):
        return self.chi2 * curve.n_eff / curve.tau.size


def _design(curve, terms, effects):
    tau = curve.tau
    a0 = design_matrix(tau, tau * curve.fs, curve.fs, terms)
    for key, _p in effects:
        rep = EFFECTS[_base(key)].replaces
        if rep in terms:
            a0[:, list(terms).index(rep)] = 0.0
    cols = [a0] + [_column(key, p, curve)[:, None] for key, p in effects]
    alphas = [np.full(tau.size, TERM_ALPHA[t]) for t in terms] + [_alpha_of(k, p, tau) for k, p in effects]
    return np.hstack(cols), alphas


def _solve(curve: _Curve, terms, effects, max_iter: int = 40) -> _Solution:
    """IRLS weighted NNLS of the terms plus effects [(key, nonlinear parameter)]."""
    tau = curve.tau
    a, alphas = _design(curve, terms, effects)
    nu_cols = np.column_stack(
        [
            np.where(
                al == -2,
                curve.edf(-2),
                np.where(al == -1, curve.edf(-1), np.where(al == 2, curve.edf(2), curve.edf(0))),
            )
            for al in alphas
        ]
    )
    y = curve.avar
    model = y.copy()
    nu = nu_cols[:, 1] if len(terms) > 1 else nu_cols[:, 0]
    theta = np.zeros(a.shape[1])
    floor = 1e-12 * np.max(y)
    for it in range(max_iter):
        w = nu / (2.0 * np.maximum(model, floor) ** 2)
        sw = np.sqrt(w)
        new = fitting.nnls(a * sw[:, None], y * sw)
        parts = a * new
        new_model = np.maximum(parts.sum(axis=1), floor)
        done = bool(np.all(np.abs(new - theta) <= 1e-6 * np.abs(theta)))  # np.allclose(rtol=1e-6, atol=0)
        model = new_model if it == 0 else np.sqrt(model * new_model)
        theta = new
        if new.any():
            tot = parts.sum(axis=1)
            den = np.sum(parts**2 / nu_cols, axis=1)
            nu = np.where(den > 0, tot**2 / np.maximum(den, 1e-300), nu)
        if done:
            break
    model = np.maximum(a @ theta, floor)
    w = nu / (2.0 * model**2)
    z = (y - model) * np.sqrt(w)
    active = theta > 0
    cov = np.full((a.shape[1], a.shape[1]), np.nan)
    if active.any():
        idx = np.flatnonzero(active)
        aw = a[:, idx] * w[:, None]
        cov[np.ix_(idx, idx)] = np.linalg.pinv(aw.T @ a[:, idx]) * (tau.size / curve.n_eff)
    dof = max(1, tau.size - int(active.sum()) - len(effects))
    return _Solution(theta, model, nu, z, float(np.sum(z**2)), dof, a, cov)


def _rms_adev_pct(obs, model) -> float:
    return float(100 * np.sqrt(np.mean((np.sqrt(obs / model) - 1) ** 2)))


def _informative(tau, nu) -> np.ndarray:
    """The τ an RMS ADEV error is scored on: 4 per octave (each octave weighs alike, not the dense grid's
    points) whose estimate is itself within ±10 % — EDF ≥ 50 under the five-term fit's own noise mix (white
    at short τ; far fewer for flicker and random walk at long τ). Beyond, the estimate's own scatter would
    decide the score. Falls back to every thinned τ if fewer than 4 qualify."""
    thin = tracing.thin_indices(tau)
    mask = np.zeros(tau.size, dtype=bool)
    mask[thin] = True
    good = mask & (nu >= HELDOUT_MIN_EDF)
    return good if np.count_nonzero(good) >= 4 else mask


def _removal_metrics(curve: _Curve, sol: _Solution, change, n_params: int, heldout, scored) -> dict:
    """In-sample errors of a time-domain removal on the curve it was removed *from*: the noise model
    fitted after the removal plus the change the removal made to the Allan curve, against the same
    estimates the "before" model was scored on (apples to apples). ``change`` = AVAR(y) − AVAR(y − c):
    the component's own Allan variance and its cross terms with the rest of the record, exactly — a
    regression's component is *not* independent of the noise (a channel's coupling varies across
    frequency, so the residual keeps a band-by-band cross term that the component's own variance misses)."""
    model = np.maximum(sol.model + change, 1e-300)
    z = (curve.avar - model) * np.sqrt(sol.nu / (2.0 * model**2))
    chi2 = float(np.sum(z**2))
    dof = max(1, sol.dof - n_params)
    return {
        "chi2_dof": chi2 / dof,
        "rms_z": float(np.sqrt(np.mean(z**2))),
        "rms_adev_pct": _rms_adev_pct(curve.avar[scored], model[scored]),
        "p_value": float(chi2_dist.sf(chi2 * curve.n_eff / curve.tau.size, max(1.0, curve.n_eff - 1))),
        "heldout_rms_adev_pct": heldout,
    }


def _curve_metrics(curve: _Curve, sol: _Solution, heldout, scored=None) -> dict:
    sc = slice(None) if scored is None else scored
    return {
        "chi2_dof": sol.chi2_dof,
        "rms_z": float(np.sqrt(np.mean(sol.z**2))),
        "rms_adev_pct": _rms_adev_pct(curve.avar[sc], sol.model[sc]),
        "p_value": float(chi2_dist.sf(sol.chi2_eff(curve), max(1.0, curve.n_eff - 1))),
        "heldout_rms_adev_pct": heldout,
    }


# ----------------------------------------------------------------------------------------------
# held-out error


class _Split:
    """Alternate blocks in time (odd ↔ even) for the held-out error.

    Each part's blocks are joined end to end (samples keep their true times); the model fitted on one part's
    Allan curve predicts the other part's, both ways. Interleaved parts share the record's slow changes (a
    noise level that steps, a warm-up), so the score asks whether the model carries over, not whether the
    two halves of a non-stationary record agree at long τ. A time effect is fitted on one part's samples
    and removed from both. Joining keeps τ up to part/9 (a warm-up's time scale) where an Allan curve per
    block would stop at block/9; the seams affect the model with and without an effect alike."""

    def __init__(self, y, fs, grid_m, lo, hi, estimator, n_blocks, terms):
        self.y = y
        n = y.size
        per = n // n_blocks
        self.fs, self.estimator = fs, estimator
        self.idx = [
            np.concatenate([np.arange(j * per, (j + 1) * per) for j in range(n_blocks) if j % 2 == parity])
            for parity in (0, 1)
        ]
        size = min(i.size for i in self.idx)
        self.idx = [i[:size] for i in self.idx]
        m = grid_m[grid_m <= size // 9]
        tau = m / fs
        keep = (tau >= lo) & (tau <= hi)
        if np.count_nonzero(keep) < 8:
            raise ValueError("too few τ in range for held-out blocks")
        self.m, self.size = m[keep], size
        self.curves = [self._curve(y[i]) for i in self.idx]
        self.scored = _informative(self.curves[0].tau, _solve(self.curves[0], terms, []).nu)
        # ... and where the record reproduces itself: the two parts' own ADEV agree within ±20 % (twice the
        # ±10 % of EDF 50). Beyond, the parts differ more than their estimates scatter (a non-stationary
        # record, an under-estimated EDF at long τ), no model predicts both, and the score would be decided
        # by which model happens to sit nearer the other part's values there.
        agree = np.abs(np.sqrt(self.curves[0].avar / self.curves[1].avar) - 1.0) <= HELDOUT_AGREE
        if np.count_nonzero(self.scored & agree) >= 4:
            self.scored &= agree

    def _curve(self, z):
        av = np.maximum(avar(z, self.fs, taus=self.m / self.fs).avar, 1e-300)
        return _Curve(self.m / self.fs, self.m.astype(np.float64), av, self.fs, self.size + 1, self.estimator)

    def error(self, terms, effects, remove=None, on_raw=False) -> float:
        """RMS ADEV error (%) of one part's model predicting the other's curve, both ways; ``remove(samples,
        indices)`` fits a component on the held-in part and returns it as a function of sample indices.

        ``on_raw``: with ``remove``, predict the other part's *raw* curve — the model fitted on the held-in
        part's corrected curve plus what the correction changed in the held-in part's curve — so that "before"
        and "after" are scored on the same curve. Removing a large component the two parts share (a
        multi-position profile's steps) otherwise changes the scale the relative error is taken on."""
        errs = []
        for f, h in ((0, 1), (1, 0)):
            extra = 0.0
            if remove is None:
                cf, ch = self.curves[f], self.curves[h]
            else:
                yf, yh = self.y[self.idx[f]], self.y[self.idx[h]]
                g = remove(yf, self.idx[f])
                cf = self._curve(yf - g(self.idx[f]))
                if on_raw:
                    ch, extra = self.curves[h], self.curves[f].avar - cf.avar
                else:
                    ch = self._curve(yh - g(self.idx[h]))
            sol = _solve(cf, terms, effects)
            a_h, _ = _design(ch, terms, effects)
            pred = np.maximum(a_h @ sol.theta + extra, 1e-300)
            errs.append(_rms_adev_pct(ch.avar[self.scored], pred[self.scored]))
        return float(np.mean(errs))


def _upper_theta(curve, sol, terms, effects, theta, slow=("B", "K"), delta_chi2=4.0):
    """``theta`` with each slow term (flicker, random walk of rate) raised to the upper end of what the curve
    allows: the largest value with the others refitted (weighted NNLS, the fit's weights) whose χ² rises by
    at most ``delta_chi2`` (≈ 2σ; in effective points). A null model for a time-domain test must not leave
    out a random walk the curve merely could not pin down: one that is there makes warm-up-like wander in the
    block means."""
    out = theta.copy()
    a, _ = _design(curve, terms, effects)
    w = np.sqrt(sol.nu / (2.0 * sol.model**2))
    aw, yw = a * w[:, None], curve.avar * w
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


def _theta_terms(sol, terms, effects):
    """Squared coefficients of the terms (a bandwidth's N in place of the zeroed N column)."""
    k = len(terms)
    theta = sol.theta[:k].copy()
    for j, (key, _p) in enumerate(effects):
        if EFFECTS[_base(key)].replaces == "N" and "N" in terms:
            theta[list(terms).index("N")] = sol.theta[k + j]
    return theta


def _heldout_split(y, fs, m_all, lo, hi, terms):
    """Alternate blocks of the record for the held-out error, or None if the record is too short."""
    try:
        return _Split(y, fs, m_all, lo, hi, "oavar", HELDOUT_BLOCKS, terms)
    except ValueError:
        return None


def _segments_heldout(whole: _Split, y, fs, m_all, lo, hi, terms, effects, times):
    """Held-out error of change points at ``times`` (s): (without, with), or None if a segment is too short.

    Each segment between change points gets its own alternate blocks; its held-out part's Allan curve is
    predicted once by the model fitted on the held-in part of the whole record (no change point) and once by
    the model fitted on the segment's own held-in part (the noise level changes there). Mean over both ways,
    segments weighted by their length. A change point that is not real leaves the segments alike, and the
    segment's model, fitted on less data, predicts no better."""
    edges = [0] + sorted(int(round(t * fs)) for t in times) + [y.size]
    out = np.zeros(2)
    for a, b in zip(edges[:-1], edges[1:]):
        seg = _heldout_split(y[a:b], fs, m_all, lo, hi, terms)
        if seg is None:
            return None
        for f, h in ((0, 1), (1, 0)):
            a_h, _ = _design(seg.curves[h], terms, effects)
            obs = seg.curves[h].avar[seg.scored]
            for k, part in enumerate((whole.curves[f], seg.curves[f])):
                pred = np.maximum(a_h @ _solve(part, terms, effects).theta, 1e-300)[seg.scored]
                out[k] += 0.5 * (b - a) / y.size * _rms_adev_pct(obs, pred)
    return float(out[0]), float(out[1])


# ----------------------------------------------------------------------------------------------
# candidates on the curve


def _residual_evidence(curve, sol) -> dict:
    """Where the residual is: runs of same-signed |z| > 2, and the τ of the largest |z|."""
    z = sol.z
    runs = []
    i = 0
    while i < z.size:
        if abs(z[i]) > 2:
            j = i
            while j + 1 < z.size and abs(z[j + 1]) > 2 and np.sign(z[j + 1]) == np.sign(z[i]):
                j += 1
            runs.append(
                {
                    "tau_from": float(curve.tau[i]),
                    "tau_to": float(curve.tau[j]),
                    "sign": int(np.sign(z[i])),
                    "points": int(j - i + 1),
                }
            )
            i = j + 1
        else:
            i += 1
    k = int(np.argmax(np.abs(z)))
    return {"runs_beyond_2sigma": runs, "max_abs_z": float(abs(z[k])), "tau_of_max": float(curve.tau[k])}


def _search(curve, terms, effects, key, grid, continuous=True):
    """Best nonlinear parameter for effect ``key`` on ``grid`` (then refined), its solution and profile."""

    # screen the grid with a few reweighting passes (the ranking settles early), then solve fully
    chis = np.array([_solve(curve, terms, effects + [(key, p)], max_iter=6).chi2 for p in grid])
    k = int(np.argmin(chis))
    lo, hi = math.log(grid[max(0, k - 1)]), math.log(grid[min(grid.size - 1, k + 1)])
    p = float(grid[k])
    if continuous and hi > lo:
        res = minimize_scalar(
            lambda lp: _solve(curve, terms, effects + [(key, math.exp(lp))]).chi2,
            bounds=(lo, hi),
            method="bounded",
            options={"xatol": 1e-3},
        )
        p = math.exp(res.x)
    sol = _solve(curve, terms, effects + [(key, p)])
    if p != float(grid[k]):
        at_k = _solve(curve, terms, effects + [(key, float(grid[k]))])
        if sol.chi2 > at_k.chi2:
            p, sol = float(grid[k]), at_k
    # a best value at the edge of its range is not identified — except a FIR's shortest length (2 taps):
    # below it lies "no filter", which is the null model itself
    at_edge = (k == 0 and continuous) or k == grid.size - 1
    return p, sol, at_edge


#: Octave-to-octave correlation of Allan estimates used for the parameters' effective sample size
#: (the mid value of fit.OCTAVE_CORRELATION: 0.42 white angle … 0.87 random walk).
PROFILE_RHO = 0.68


def _profile_interval(curve, terms, effects, key, p, sol):
    """Interval of the nonlinear parameter where the effective χ² rises by ≤ 1 over its minimum.

    χ² of the dense, correlated τ points is scaled to n_eff·(1 − ρ)/(1 + ρ) independent ones (n_eff
    octaves whose estimates correlate by ρ = ``PROFILE_RHO`` from one to the next); the crossings are
    interpolated on a log grid around the best value."""
    scale = curve.n_eff * (1 - PROFILE_RHO) / (1 + PROFILE_RHO) / curve.tau.size
    local = p * np.exp(np.linspace(-1.5, 1.5, 41))
    lc = np.array([_solve(curve, terms, effects + [(key, q)]).chi2 for q in local])
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


def _bandwidth_grids(curve):
    """Search grids per filter kind: single-pole cutoffs whose roll-off falls inside the curve, FIR lengths."""
    # the roll-off must reach into the curve: a time constant (or FIR span) of at least a third of the
    # shortest τ — a faster filter leaves no mark on it
    fs = curve.fs
    f_lo = 1.0 / (2 * math.pi * 10 * curve.tau[0])
    f_hi = min(0.45 * fs, 3.0 / (2 * math.pi * curve.tau[0]))
    grids = {}
    if f_lo < f_hi:
        grids["single_pole"] = np.geomspace(f_lo, f_hi, 24)
    l_min = max(2, int(math.ceil(curve.tau[0] * fs / 3)))
    l_max = int(max(2, min(64, 0.1 * curve.tau[-1] * fs)))
    if l_max > l_min:
        grids["moving_average"] = np.arange(l_min, l_max + 1, dtype=np.float64)
        grids["bartlett"] = np.arange(max(2, l_min // 2), max(3, l_max // 2) + 1, dtype=np.float64)
        grids["boxcar"] = np.geomspace(max(1.02, curve.tau[0] * fs / 3), l_max, 32)
    if "single_pole" in grids and curve.tau[0] * fs <= 1.0:
        # a single pole after the part's own short averaging (only where the curve starts at one sample)
        for span in CASCADE_SPANS:
            grids[f"single_pole+boxcar:{span:g}"] = grids["single_pole"]
    return grids


def _families(curve, candidates, has_samples, channel_names, drift_grid):
    """Every column the curve-domain candidates could add, for the bootstrap of the maximum statistic."""
    fam = []
    tmin, tmax = curve.tau[0], curve.tau[-1]
    if "gauss_markov" in candidates:
        search = EFFECTS["gauss_markov"].search
        assert search is not None
        fam += [_column("gauss_markov", p, curve) for p in search(tmin, tmax)]
    if "bandwidth" in candidates:
        for kind, grid in _bandwidth_grids(curve).items():
            fam += [_column(f"bandwidth:{kind}", p, curve) - 1.0 / curve.tau for p in grid]
    if "resonance" in candidates:
        search = EFFECTS["resonance"].search
        assert search is not None
        fam += [_column(f"resonance:{q:g}", p, curve) for q in RESONANCE_Q for p in search(tmin, tmax)]
    if "sinusoid" in candidates and not has_samples:
        fam += [_column("sinusoid", p, curve) for p in np.geomspace(2.0 / tmax, 0.5 / tmin, 120)]
    if "drift" in candidates and drift_grid is not None:
        fam += [_column("drift", p, curve) for p in drift_grid]
    if "regression" in candidates:
        fam += [curve.channels[c] for c in channel_names]
    return np.column_stack(fam) if fam else np.zeros((curve.tau.size, 0))


# ----------------------------------------------------------------------------------------------
# change points (needs the samples)


def _change_points(y, fs, terms, max_points=2):
    """Level steps of the Allan variance along the record: [(t, (t_lo, t_hi), evidence, before, after)]."""
    n = y.size
    n_win = 16
    window = n // n_win
    if window < 64:
        return []
    d = davar(y, fs, window=window, hop=window, taus="octave")
    lav = np.log(np.maximum(d.avar, 1e-300))  # (tau, windows)
    # SD of log σ̂² per τ: from the EDF of the dominant noise (white rate is a fair middle)
    nu = fitting.edf_per_tau(np.zeros(d.m.size, dtype=int), d.m, window + 1, "oavar")
    # 1/var(log σ̂²): ν/2 for white rate, but long τ scatter more (fewer degrees of freedom for
    # flicker/random walk): take the larger of 2/ν and the robust scatter of consecutive windows
    # (median |difference|, insensitive to a few steps).
    mad = 1.4826 * np.median(np.abs(np.diff(lav, axis=1)), axis=1)
    w = 1.0 / np.maximum(2.0 / nu, mad**2 / 2.0)
    out = []

    def best_split(a, b):
        seg = lav[:, a:b]
        best = (0.0, None, None)
        for j in range(a + 1, b):
            left, right = lav[:, a:j], lav[:, j:b]
            chi_const = np.sum(w[:, None] * (seg - seg.mean(axis=1, keepdims=True)) ** 2)
            chi_step = np.sum(w[:, None] * (left - left.mean(axis=1, keepdims=True)) ** 2) + np.sum(
                w[:, None] * (right - right.mean(axis=1, keepdims=True)) ** 2
            )
            gain = chi_const - chi_step
            if gain > best[0]:
                gain_tau = (
                    np.sum(w[:, None] * (seg - seg.mean(axis=1, keepdims=True)) ** 2, axis=1)
                    - np.sum(w[:, None] * (left - left.mean(axis=1, keepdims=True)) ** 2, axis=1)
                    - np.sum(w[:, None] * (right - right.mean(axis=1, keepdims=True)) ** 2, axis=1)
                )
                best = (gain, j, int(np.argmax(gain_tau)))
        return best

    # windows are independent but the τ of one window are correlated: penalise per octave count
    n_tau_eff = max(2.0, math.log2(d.tau[-1] / d.tau[0]) + 1.0)
    penalty = n_tau_eff * math.log(n_win) + 4.0 * MIN_GAIN
    stack = [(0, n_win)]
    while stack and len(out) < max_points:
        a, b = stack.pop(0)
        if b - a < 3:
            continue
        gain, j, k_tau = best_split(a, b)
        if j is None or gain * n_tau_eff / d.m.size < penalty / d.m.size * 1.0 and gain < penalty:
            continue
        if gain < penalty:
            continue
        # locate at sample resolution with the squared differences at the τ of the largest gain
        m = int(d.m[k_tau])
        lo_s, hi_s = a * window, b * window
        t_hat, t_int = _locate(y[lo_s:hi_s], m, fs)
        t_abs = t_hat + lo_s / fs
        if any(abs(c["t"] - t_abs) < window / fs for c in out):
            continue
        out.append(
            {
                "t": t_abs,
                "interval": (t_int[0] + lo_s / fs, t_int[1] + lo_s / fs),
                "gain": float(gain),
                "tau": float(d.tau[k_tau]),
                "window_s": window / fs,
                "coarse_split_s": j * window / fs,
            }
        )
        # search each side again, leaving out the window that straddles the change
        jw = int(t_abs * fs // window)
        stack += [(a, min(jw, j)), (max(jw + 1, j), b)]
    out.sort(key=lambda c: c["t"])
    # before/after: per-window log-AVAR against one constant level vs piecewise-constant levels
    # windows that straddle a change belong to neither level: left out of both comparisons
    straddle = sorted({int(c["t"] * fs // window) for c in out})
    keep = np.ones(n_win, dtype=bool)
    keep[[j for j in straddle if j < n_win]] = False
    edges = [0] + [j for j in straddle] + [n_win]

    def stats(segments):
        res, k = [], 0
        for a, b in segments:
            sel = np.arange(a, b)[keep[a:b]]
            if sel.size:
                r = lav[:, sel] - lav[:, sel].mean(axis=1, keepdims=True)
                res.append(r)
                k += lav.shape[0]
        res = np.concatenate(res, axis=1)
        z = res * np.sqrt(w)[:, None]
        return {
            "chi2_dof": float(np.sum(z**2) / max(1, z.size - k)),
            "rms_z": float(np.sqrt(np.mean(z**2))),
            "rms_adev_pct": float(100 * np.sqrt(np.mean((np.exp(res / 2) - 1) ** 2))),
        }

    before = stats([(0, n_win)])
    after = stats([(a, b) for a, b in zip(edges[:-1], edges[1:])])
    for c in out:
        c["before"], c["after"] = before, after
    return out


def _locate(y, m, fs):
    """Change in the mean of the squared m-sample second differences: MLE split and 2-unit support."""
    k = y.size // m
    b = y[: k * m].reshape(k, m).mean(axis=1)
    d = np.diff(b) ** 2 + 1e-300  # independent-ish terms at stride m
    n = d.size
    c = np.cumsum(d)
    j = np.arange(2, n - 1)
    mu1 = c[j - 1] / j
    mu2 = (c[-1] - c[j - 1]) / (n - j)
    ll = -0.5 * (j * np.log(mu1) + (n - j) * np.log(mu2))  # exponential-family profile (χ²₁ terms)
    i = int(np.argmax(ll))
    ok = j[ll >= ll[i] - 2.0]
    to_t = lambda idx: (idx + 1) * m / fs  # noqa: E731  boundary after term idx
    return to_t(j[i]), (to_t(ok.min()) - m / fs, to_t(ok.max()) + m / fs)


# ----------------------------------------------------------------------------------------------
# results


@dataclass
class Step:
    """One effect added by :func:`refine`.

    ``params`` in the input unit's base form (see :data:`allanite.model.effects.EFFECTS` for each
    effect's parameters and units: Gauss–Markov ``sigma`` rate unit, ``tc`` s; sinusoid ``amplitude``
    rate unit, ``f0`` Hz; bandwidth ``cutoff`` Hz, ``taps``, ``filter``; drift ``amplitude`` rate unit,
    ``T`` s; regression ``channel``, ``coefficient`` rate unit per channel unit; change point ``t`` s);
    ``intervals`` the numeric keys → (low, high); ``before``/``after``: ``chi2_dof``, ``rms_z``,
    ``rms_adev_pct`` (on ``Refinement.scored_tau``), ``p_value`` and ``heldout_rms_adev_pct`` (None for
    curve-only input); ``evidence``: where in τ, f or t the residual was and the test that accepted it;
    ``truth_error``: relative parameter errors when ``truth`` was given.
    """

    effect: str
    params: dict
    intervals: dict
    evidence: dict
    before: dict
    after: dict
    delta_chi2_eff: float = 0.0
    truth_error: dict | None = None


@dataclass
class Refinement(RichDisplay):
    """What :func:`refine` found. ``fit`` is the final model (a NoiseFit whose ``coefficients`` also
    hold the added effects' parameters), ``start`` the starting model, ``steps`` the effects added.
    ``heldout_note`` says how (or why not) the held-out error was computed; ``scored_tau`` the τ the RMS ADEV
    errors are scored on (:meth:`rms_adev_pct` gives a fit's)."""

    steps: list
    fit: fitting.NoiseFit
    start: fitting.NoiseFit
    result: AllanResult
    terms: tuple
    effects: list = field(default_factory=list)
    change_points: list = field(default_factory=list)
    considered: dict = field(default_factory=dict)
    heldout_note: str = ""
    start_heldout_rms_adev_pct: float | None = None
    tau_range: tuple = (0.0, math.inf)
    scored_tau: np.ndarray | None = None

    def rms_adev_pct(self, fit) -> float:
        """RMS ADEV error (%) of a fit (``start`` or ``fit``) on the τ the steps' errors are scored on
        (``scored_tau``: 4 per octave, each estimate within ±10 %, EDF ≥ 50 under the five-term fit)."""
        sel = np.isin(fit.tau, self.scored_tau) if self.scored_tau is not None else slice(None)
        return _rms_adev_pct(fit.avar[sel], fit.model[sel])

    @property
    def found(self) -> list:
        return [s.effect for s in self.steps]

    def report(self) -> str:
        """Markdown: the starting residual, each step with its parameters, evidence and errors."""
        s0 = self.start
        ho = self.start_heldout_rms_adev_pct
        lines = [
            "# Model refinement",
            "",
            f"Starting model {'+'.join(self.terms)}: χ²/dof = {s0.chi2_dof:.3g}, "
            f"RMS z = {np.sqrt(np.mean(s0.z**2)):.3g}, RMS ADEV error = "
            f"{self.rms_adev_pct(s0):.3g} %, held-out RMS ADEV error = "
            + (f"{ho:.3g} %." if ho is not None else "n/a."),
            "",
            f"Held-out error: {self.heldout_note}",
            "",
        ]
        if not self.steps:
            lines.append("Nothing added: the residual is consistent with noise or no candidate earned its parameters.")
        for i, st in enumerate(self.steps, 1):
            ps = ", ".join(_fmt_param(k, v, st.intervals.get(k)) for k, v in st.params.items())
            lines += [
                f"## Step {i}: {st.effect}",
                "",
                f"- parameters: {ps}",
                f"- evidence: {st.evidence}",
                "- before → after: "
                + ", ".join(
                    f"{k} {_fmt(st.before.get(k))} → {_fmt(st.after.get(k))}"
                    for k in ("chi2_dof", "rms_z", "rms_adev_pct", "heldout_rms_adev_pct")
                ),
                "",
            ]
            if st.truth_error:
                lines.append(
                    "- error against the truth: "
                    + ", ".join(f"{k} {100 * v:+.1f} %" for k, v in st.truth_error.items())
                )
                lines.append("")
        return "\n".join(lines)

    def _summary(self) -> Summary:
        s0, s1 = self.start, self.fit
        rows = []
        for i, st in enumerate(self.steps, 1):
            units = {name: unit for name, unit, _ in EFFECTS[st.effect].params} if st.effect in EFFECTS else {}
            ps = "; ".join(
                f"{k} = {fmt_ci(v, *st.intervals[k])} {units.get(k, '')}".rstrip() for k, v in st.params.items()
            )
            rows.append(
                [
                    i,
                    st.effect,
                    ps,
                    f"{st.before['chi2_dof']:.3g} → {st.after['chi2_dof']:.3g}",
                    f"{st.before['rms_adev_pct']:.3g} → {st.after['rms_adev_pct']:.3g}",
                ]
            )
        facts: list = [
            ("starting model", "+".join(self.terms)),
            ("found", ", ".join(self.found) if self.steps else "nothing: the starting model fits"),
            ("χ²/dof", f"{s0.chi2_dof:.3g} → {s1.chi2_dof:.3g}"),
            ("RMS z", f"{np.sqrt(np.mean(s0.z**2)):.3g} → {np.sqrt(np.mean(s1.z**2)):.3g}"),
            (
                "record",
                f"{self.result.n_samples} samples at {self.result.fs:g} Hz, τ {s0.tau[0]:.4g}–{s0.tau[-1]:.4g} s",
            ),
        ]
        if self.change_points:
            facts.append(("change points", ", ".join(f"t = {float(c['t']):.4g} s" for c in self.change_points)))
        tables = []
        if rows:
            tables.append(
                Table(
                    (
                        "step",
                        "effect",
                        "parameters [interval]",
                        "χ²/dof before → after",
                        "RMS ADEV error % before → after",
                    ),
                    rows,
                    "effects added",
                )
            )
        tables.append(fitting.coefficient_table(s1.coefficients, "final model"))
        return Summary(
            title="Refinement",
            what="what the starting noise model lacked, found and fitted by allanite.refine",
            facts=facts,
            tables=tables,
            notes=list(s1.notes),
            figure=self._draw_small,
        )

    def _draw_small(self, ax) -> None:
        """The inline figure: estimates, starting and refined model (≤ MAX_POINTS points each)."""
        i, j = thin(len(self.start.tau)), thin(len(self.fit.tau))
        ax.loglog(self.start.tau[i], np.sqrt(self.start.avar[i]), "k.", ms=2, label="estimate")
        ax.loglog(self.start.tau[i], np.sqrt(self.start.model[i]), "C0-", lw=1, label="start")
        ax.loglog(self.fit.tau[j], np.sqrt(self.fit.model[j]), "C3-", lw=1, label="refined")
        ax.set_xlabel("τ (s)")
        ax.set_ylabel("ADEV")
        ax.legend(fontsize="small", frameon=False)

    def plot(self, fig=None):
        """Residuals before and after, and the ADEV with the starting and the final model."""
        import matplotlib.pyplot as plt

        fig = fig or plt.figure(figsize=(11, 4.2))
        ax1, ax2 = fig.subplots(1, 2)
        tau = self.start.tau
        ax1.loglog(tau, np.sqrt(self.start.avar), "ko", ms=3, label="estimate")
        ax1.loglog(tau, np.sqrt(self.start.model), "C0-", label="starting model")
        ax1.loglog(self.fit.tau, np.sqrt(self.fit.model), "C3-", label="refined model")
        ax1.set_xlabel("τ (s)")
        ax1.set_ylabel("Allan deviation")
        ax1.legend(fontsize="small")
        ax2.semilogx(tau, self.start.z, "C0.-", label="before")
        ax2.semilogx(self.fit.tau, self.fit.z, "C3.-", label="after")
        ax2.axhspan(-2, 2, color="0.9")
        ax2.set_xlabel("τ (s)")
        ax2.set_ylabel("normalised residual z")
        ax2.legend(fontsize="small")
        fig.tight_layout()
        return fig


def _fmt(v) -> str:
    return "n/a" if v is None else f"{v:.3g}"


def _fmt_param(k, v, iv) -> str:
    if isinstance(v, str):
        return f"{k} = {v}"
    if iv is None:
        return f"{k} = {v:.4g}"
    return f"{k} = {v:.4g} [{iv[0]:.4g}, {iv[1]:.4g}]"


def _noise_fit(curve, terms, effects, sol, result, unit, confidence):
    """A NoiseFit for the solution, with the effects' parameters among the coefficients."""
    zq = fitting.z_quantile(confidence)
    k = len(terms)
    inflate = max(1.0, math.sqrt(sol.chi2_dof))
    theta = sol.theta[:k].copy()
    cov = sol.cov[:k, :k].copy()
    # a bandwidth carries the white rate noise N (before the filter): report it as N
    for j, (key, _p) in enumerate(effects):
        if EFFECTS[_base(key)].replaces == "N" and "N" in terms:
            i_n = list(terms).index("N")
            theta[i_n] = sol.theta[k + j]
            cov[i_n, :] = cov[:, i_n] = np.nan
            cov[i_n, i_n] = sol.cov[k + j, k + j]
    coeffs = fitting.coefficients(terms, theta, cov, zq, inflate, unit)
    comps = {t: sol.a[:, i] * sol.theta[i] for i, t in enumerate(terms)}
    for j, (key, _param) in enumerate(effects):
        i = k + j
        name = _base(key) if _base(key) != "regression" else key.replace(":", "_")
        name = f"{name}{j + 1}" if sum(_base(e[0]) == _base(key) for e in effects) > 1 else name
        comps[name] = sol.a[:, i] * sol.theta[i]
        coeffs[name] = fitting.Coefficient(
            name=name,
            value=float(math.sqrt(max(sol.theta[i], 0.0))),
            ci=fitting.interval(sol.theta[i], sol.cov[i, i], zq, inflate),
            unit=unit,
        )
    readoffs = fitting.readoffs(result, np.sqrt(np.atleast_2d(result.avar)[0]))
    return fitting.NoiseFit(
        coefficients=coeffs,
        terms=terms,
        tau=curve.tau,
        m=curve.m,
        avar=curve.avar,
        edf=sol.nu,
        model=sol.model,
        components=comps,
        z=sol.z,
        chi2=sol.chi2,
        dof=sol.dof,
        chi2_dof=sol.chi2_dof,
        p_value=float(chi2_dist.sf(sol.chi2, sol.dof)),
        readoffs=readoffs,
        fs=curve.fs,
        confidence=confidence,
        unit=unit,
        iterations=0,
        theta=theta,
        covariance=cov,
    )


# ----------------------------------------------------------------------------------------------
# the loop


def _step_params(key, p, sol, i, curve, terms, effects_before, extra):
    """Parameters and intervals of the effect in column ``i`` of ``sol``."""
    base = _base(key)
    amp = math.sqrt(max(sol.theta[i], 0.0))
    var_i = sol.cov[i, i]
    sd = math.sqrt(max(var_i, 0.0)) / (2 * amp) if amp > 0 and np.isfinite(var_i) else float("nan")
    amp_int = (max(0.0, amp - sd), amp + sd)
    if base == "bandwidth":
        kind = key.split(":", 1)[1]
        cut = filter_cutoff(kind, p, curve.fs)
        if kind == "single_pole":
            taps, c_int = 0, _profile_interval(curve, terms, effects_before, key, p, sol)
        elif kind.startswith("single_pole+boxcar:"):
            p_lo, p_hi = _profile_interval(curve, terms, effects_before, key, p, sol)
            span = float(kind.split(":", 1)[1])
            return {"cutoff": cut, "taps": span, "filter": "single_pole+boxcar", "pole_cutoff": float(p)}, {
                "cutoff": (filter_cutoff(kind, p_lo, curve.fs), filter_cutoff(kind, p_hi, curve.fs)),
                "pole_cutoff": (p_lo, p_hi),
            }
        elif kind == "boxcar":
            s_lo, s_hi = _profile_interval(curve, terms, effects_before, key, p, sol)
            return {"cutoff": cut, "taps": float(p), "filter": kind}, {
                "cutoff": (filter_cutoff(kind, s_hi, curve.fs), filter_cutoff(kind, s_lo, curve.fs)),
                "taps": (s_lo, s_hi),
            }
        else:
            taps = int(p) if kind == "moving_average" else 2 * int(p) - 1
            c_int = (filter_cutoff(kind, p + 1, curve.fs), filter_cutoff(kind, max(1.0, p - 1), curve.fs))
        return {"cutoff": cut, "taps": taps, "filter": kind}, {"cutoff": c_int}
    if base == "drift":
        d = extra["drift"]
        return {"amplitude": d["amplitude"], "T": d["T"]}, {
            "amplitude": (d["amplitude"] * (1 - sd / amp), d["amplitude"] * (1 + sd / amp)) if amp > 0 else amp_int,
            "T": d["T_interval"],
        }
    if base == "regression":
        name = key.split(":", 1)[1]
        r = extra["regression"][name]
        return {"channel": name, "coefficient": r["coefficient"]}, {
            "coefficient": (r["coefficient"] - r["se"], r["coefficient"] + r["se"])
        }
    names = EFFECTS[base].param_names
    if base == "resonance":
        p_int = _profile_interval(curve, terms, effects_before, key, p, sol)
        return {"sigma": amp, "f0": p, "q": float(key.split(":", 1)[1])}, {"sigma": amp_int, "f0": p_int}
    if base == "sinusoid" and extra.get("line") is not None:
        ln = extra["line"]  # found in the PSD: amplitude and f0 from the samples, with their intervals
        return {names[0]: ln["amplitude"], names[1]: p}, {
            names[0]: ln["amplitude_interval"],
            names[1]: ln["f0_interval"],
        }
    p_int = _profile_interval(curve, terms, effects_before, key, p, sol)
    return {names[0]: amp, names[1]: p}, {names[0]: amp_int, names[1]: p_int}


def _resolve_tau_range(tau_range, result, start):
    if isinstance(tau_range, str):
        if tau_range != "auto":
            raise ParameterError(f"tau_range must be a (low, high) pair of seconds or 'auto', got {tau_range!r}")
        nf = fitting.fit(result, terms=start, tau_range="auto")
        return float(nf.tau[0]) * (1 - 1e-9), math.inf
    return (0.0, math.inf) if tau_range is None else fitting.check_tau_range(tau_range)


#: refine's searches square and multiply variances: samples beyond this magnitude range are refused (fit and
#: avar handle any scale exactly; refine's NNLS searches on 1e-300 variances do not).
REFINE_SCALE = (1e-100, 1e100)


def _check_scale(x_or_result) -> None:
    values = x_or_result.avar if isinstance(x_or_result, AllanResult) else x_or_result
    if np.iscomplexobj(values):
        return  # the samples' own checks refuse complex samples (a float cast would drop the imaginary part)
    try:
        arr = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        return  # the samples' own checks report it
    finite = arr[np.isfinite(arr)] if arr.size else arr
    peak = float(np.max(np.abs(finite))) if finite.size else 0.0
    if isinstance(x_or_result, AllanResult):
        peak = peak**0.5
    if peak > 0 and not REFINE_SCALE[0] < peak < REFINE_SCALE[1]:
        raise InputError(
            f"refine needs samples of magnitude within {REFINE_SCALE[0]:g}…{REFINE_SCALE[1]:g}, got {peak:.3g}: "
            f"express them in another unit (avar and fit take any scale)"
        )


def refine(
    x_or_result,
    fs=None,
    *,
    start=("Q", "N", "B", "K", "R"),
    candidates=CANDIDATES,
    unit=None,
    input: str = "rate",
    tau_range=None,
    truth=None,
    confidence: float = 0.683,
    points: int = 300,
    axis: int = 0,
    channels=None,
    level: float = LEVEL,
    progress=None,
) -> Refinement:
    """Fit the starting model, find what it lacks, add it, repeat; report the error before and after.

        Parameters
        ----------
        x_or_result : array_like or AllanResult
            Samples (then ``fs`` is needed; the Allan variance is computed on a dense exponential grid of
            ``points`` τ so that a sinusoid's nulls are resolved, the PSD and the record along time are
            searched too, and the held-out error is computed), or a static :class:`~allanite.AllanResult`
            (curve effects only; no held-out error).
        fs : float, optional
            Sampling rate, Hz (samples only).
        start : tuple of str
            The starting model's terms (``"Q"``, ``"N"``, ``"B"``, ``"K"``, ``"R"``).
        candidates : tuple of str
            Effects to try (:data:`CANDIDATES`, the registry :data:`allanite.model.effects.EFFECTS`), with the
            parameters each step reports and their units ("rate unit": the samples' rate unit):

    {effects}
        unit : str, optional
            Unit of the samples, for IEEE-952 values of the terms.
        tau_range : (float, float) or "auto", optional
            τ (s) to use, as in :func:`allanite.fit`. Default: every τ — the shortest τ carry the sensor's
            bandwidth, which is a candidate effect; ``"auto"`` cuts them as ``fit`` does.
        channels : dict of str → array_like, optional
            Other channels of the same log (same length as the samples: temperature, other axes,
            accelerometers): the rate is regressed on each ("regression" effect; band by band where the
            coupling differs across frequency, the bands in the step's ``evidence["bands"]``).
        level : float
            False-alarm probability per record on a clean record (default 0.05), split between spectral
            lines, the Allan-curve test and change points.
        progress : bool, optional
            A ``tqdm.auto`` bar: None (default) in a notebook or a terminal only, True/False always/never.
        truth : dict, optional
            Known parameters per effect (``{"gauss_markov": {"sigma": …, "tc": …}}``, ``{"change_point":
            {"t": …}}``): each step then records its relative errors.
        axis : int
            Which axis of multi-axis input to refine.

        Returns
        -------
        Refinement

        Examples
        --------
        >>> import allanite
        >>> y = allanite.simulate(1_000_000, 100.0, N=2e-3, K=2e-5, gauss_markov=[(5e-3, 10.0)], seed=11)
        >>> r = allanite.refine(y, 100.0)               # the generator's GM is not in the starting model
        >>> r.found, round(r.steps[0].params["tc"], 0)
        (['gauss_markov'], 10.0)
    """
    _check_scale(x_or_result)
    with StepBar(progress, 1, "refine") as bar:
        bar.step("fit, trace and test the candidates")
        return _refine(
            x_or_result,
            fs,
            start=start,
            candidates=candidates,
            unit=unit,
            input=input,
            tau_range=tau_range,
            truth=truth,
            confidence=confidence,
            points=points,
            axis=axis,
            channels=channels,
            level=level,
        )


def _refine(
    x_or_result,
    fs=None,
    *,
    start=("Q", "N", "B", "K", "R"),
    candidates=CANDIDATES,
    unit=None,
    input: str = "rate",
    tau_range=None,
    truth=None,
    confidence: float = 0.683,
    points: int = 300,
    axis: int = 0,
    channels=None,
    level: float = LEVEL,
) -> Refinement:
    """The loop behind :func:`refine` (its parameters, without ``progress``)."""
    start = check_terms(start)
    if isinstance(candidates, str):
        candidates = (candidates,)
    bad = [c for c in candidates if c not in CANDIDATES]
    if bad:
        raise ParameterError(f"unknown candidate effect {bad[0]!r}; allowed: {', '.join(CANDIDATES)}")
    if not (isinstance(level, (int, float)) and 0.0 < level < 1.0):
        raise ParameterError(f"level must be a probability in (0, 1), got {level!r}")
    y = None
    if isinstance(x_or_result, AllanResult):
        if fs is not None:
            raise ParameterError("fs is taken from the result; pass fs only with samples")
        result = x_or_result
    elif hasattr(x_or_result, "tau") and hasattr(x_or_result, "t"):
        raise ParameterError(
            "refine needs samples or a static AllanResult; for a dynamic result pass the samples "
            "so that change points can be located"
        )
    else:
        if fs is None:
            raise ParameterError("fs (Hz) is needed with samples")
        cols, fs, _ = as_rate_columns(x_or_result, fs, input)
        if not 0 <= axis < len(cols):
            raise ParameterError(f"axis = {axis} is outside 0..{len(cols) - 1}")
        y = cols[axis]
        top = max(1, y.size // 9)
        grid = tau_grid(y.size, fs, "exp", points=points, m_max=top) if top > 1 else "octave"
        result = avar(y, fs, taus=grid)
    chans: dict = {}
    if channels:
        if y is None:
            raise ParameterError("channels need samples (a regression is fitted along time), not an AllanResult")
        for name, c in channels.items():
            c = np.asarray(c, dtype=np.float64).ravel()
            if c.size != y.size:
                raise ParameterError(f"channel {name!r} has {c.size} samples; the rate has {y.size}")
            if not np.all(np.isfinite(c)):
                raise ParameterError(f"channel {name!r} has non-finite samples")
            chans[str(name)] = c
    if result.avar.ndim == 2:
        result = AllanResult(
            tau=result.tau,
            avar=result.avar[axis],
            n=result.n,
            m=result.m,
            estimator=result.estimator,
            fs=result.fs,
            n_samples=result.n_samples,
            input=result.input,
            source=result.source,
        )
    lo, hi = _resolve_tau_range(tau_range, result, start)
    keep = (result.tau >= lo) & (result.tau <= hi) & (result.avar > 0)
    if keep.sum() < len(start) + 3:
        raise ParameterError(
            f"{int(keep.sum())} usable τ points; refining {len(start)} terms needs at least {len(start) + 3}"
        )
    est = result.estimator if result.source is None else tuple(np.asarray(result.source)[keep])
    fs = result.fs

    def build(res, samples):
        """The curve (and, with samples, the held-out split) of ``res``'s estimates in the τ range."""
        c = _Curve(
            res.tau[keep], res.m[keep].astype(np.float64), res.avar[keep], fs, res.n_samples + 1, est, channels={}
        )
        if samples is None:
            return c, None
        return c, _heldout_split(samples, fs, np.asarray(res.m, dtype=np.int64), lo, hi, start)

    curve, heldout = build(result, y)
    note = "curve-only input (an AllanResult without samples): no held-out error; steps rest on the calibrated test"
    if y is not None:
        note = (
            f"alternate blocks in time ({HELDOUT_BLOCKS}; odd ↔ even, each part's blocks joined): the model fitted "
            "on one part predicts the other part's Allan curve, both ways, mean RMS ADEV error on the τ whose "
            "estimate is within ±10 % (4 per octave); a drift is refitted on the held-in part"
            if heldout is not None
            else "record too short to hold out alternate blocks: no held-out error"
        )
    k_terms = len(start)
    steps: list = []
    sol = _solve(curve, start, [])
    start_sol = sol
    # in-sample RMS ADEV error: on the τ whose estimate is informative under the five-term fit (fixed for
    # the whole refinement, so every before/after compares the same τ)
    scored = _informative(curve.tau, sol.nu)

    def metrics(c, s, ho):
        return _curve_metrics(c, s, ho, scored)

    start_heldout = heldout.error(start, []) if heldout is not None else None
    alpha_curve = level * (1.0 - LINE_SHARE - CHANGE_POINT_SHARE - 2 * TIME_SHARE)

    # removing a time-domain component (a drift, a regression: before the curve effects; rescored at the end)
    def removal_step(name, component, refit, params, intervals, evidence, truth_key, held_in_time=None, on_raw=False):
        """Accept removing ``component`` if the held-out error falls; returns the step or None.

        ``refit(samples, indices)`` fits the component on the held-in part's samples (at those sample indices)
        and returns it as a function of sample indices, for the held-out error.

        ``held_in_time``: for a regression, the held-out test in time (the residual variance of each half with
        the coefficient of the other half, relative to its raw variance) decides instead: removing a white-like
        component changes the Allan curve's level, not how well one part predicts the other's."""
        nonlocal y, result, curve, heldout, sol
        assert y is not None
        y_new = y - component
        res_new = avar(y_new, fs, taus=result.tau)
        c_new, h_new = build(res_new, y_new)
        ho_b = heldout.error(start, effects) if heldout is not None else None
        ho_a = heldout.error(start, effects, remove=refit, on_raw=on_raw) if heldout is not None else None
        s_new = _solve(c_new, start, effects)
        if held_in_time is not None:
            evidence["heldout_variance_ratio"] = held_in_time
            rejected = not held_in_time < 1.0
        else:
            rejected = ho_b is not None and ho_a is not None and not ho_a < ho_b
        if rejected:
            considered.setdefault(name, []).append(
                params
                | {
                    "rejected": f"held-out error {ho_b} → {ho_a} %, variance ratio {held_in_time}",
                    "test": evidence["test"],
                }
            )
            return None
        terr = None
        if truth and truth_key in truth:
            terr = {k: params[k] / v - 1 for k, v in truth[truth_key].items() if k in params and v}
        st = Step(
            effect=name,
            params=params,
            intervals=intervals,
            evidence=evidence,
            before=metrics(curve, sol, ho_b),
            # on the same curve as "before": the new noise model plus what the removal changed in the curve
            after=_removal_metrics(
                curve,
                s_new,
                result.avar[keep] - res_new.avar[keep],
                # fitted numbers only (a regression's channel is a name), one per band keeping its own coupling
                sum(not isinstance(v, str) for v in params.values()) + len(evidence.get("bands", ())),
                ho_a,
                scored,
            ),
            delta_chi2_eff=float(sol.chi2_eff(curve) - s_new.chi2_eff(c_new)),
            truth_error=terr,
        )
        y, result, curve, heldout, sol = y_new, res_new, c_new, h_new, s_new
        return st

    considered: dict[str, list] = {}
    effects: list = []
    first_steps: list = []  # time effects removed before the curve loop (kept apart: steps[j] ↔ effects[j] below)
    # (step, component, refit, fitted numbers, held-out on the raw curve) of each time effect removed before the
    # curve loop
    removed_first: list = []
    # ---- a warm-up drift first: its time-domain evidence is unambiguous, and left in the samples it bends
    # the long-τ curve that every curve effect is fitted against (its threshold comes from the five-term fit,
    # which the drift itself inflates: conservative)
    if y is not None and "drift" in candidates:
        dr = tracing.drift_fit(y, fs)
        theta_null = _upper_theta(curve, sol, start, effects, _theta_terms(sol, start, effects))
        thr_d = tracing.drift_threshold(y.size, fs, start, theta_null, TIME_SHARE * level)
        ev = {"domain": "time", "test": {"statistic": dr["statistic"], "threshold": thr_d, "alpha": TIME_SHARE * level}}
        if dr["statistic"] > thr_d and not dr["at_edge"]:
            t_s = np.arange(y.size) / fs
            span = y.size / fs
            pieces = HELDOUT_BLOCKS // 2
            drift_comp = dr["amplitude"] * np.exp(-t_s / dr["T"])

            def drift_refit(z, idx, span=span, pieces=pieces):
                g = tracing.drift_component(z, idx / fs, span, pieces)
                return lambda i: g(i / fs)

            st = removal_step(
                "drift",
                drift_comp,
                drift_refit,
                {"amplitude": dr["amplitude"], "T": dr["T"]},
                {"amplitude": dr["amplitude_interval"], "T": dr["T_interval"]},
                ev,
                "drift",
            )
            if st is not None:
                first_steps.append(st)
                removed_first.append((st, drift_comp, drift_refit, 2, False))
        else:
            considered.setdefault("drift", []).append({"T": dr["T"], "statistic": dr["statistic"], "threshold": thr_d})
    # ---- other channels next, before any curve effect: a component a channel explains (a multi-position
    # profile's steps, a temperature's swing) bends the curve as a Gauss–Markov term or a random walk would,
    # and fitted first those would take it; its test is in time (within blocks), independent of the curve
    if y is not None and chans and "regression" in candidates:
        for name, ch in chans.items():
            rg = tracing.regression_fit(y, ch, REGRESSION_BLOCKS)
            # t with the blocks' effective number − 1 degrees of freedom (≤ REGRESSION_BLOCKS − 1)
            t_thr = t_dist.isf(TIME_SHARE * level / (2 * len(chans)), rg["dof"])
            t_stat = abs(rg["coefficient"]) / rg["se"] if rg["se"] > 0 else 0.0
            ev = {"domain": "channels", "test": {"t": t_stat, "threshold": float(t_thr), "alpha": TIME_SHARE * level}}
            if not t_stat > t_thr:
                considered.setdefault("regression", []).append({"channel": name, "t": t_stat, "threshold": t_thr})
                continue

            # band by band where the coupling differs across frequency (the whole-record coefficient elsewhere)
            br = tracing.band_regression(y, ch, fs, TIME_SHARE * level)
            own = [b for b in br["bands"] if b["own"]]
            if own:
                ev["bands"] = own

            def reg_refit(z, idx, ch=ch, banded=bool(own)):
                if banded:
                    used = tracing.band_regression(z, ch[idx], fs, TIME_SHARE * level)["used"]
                    return lambda i: tracing.band_component(ch[i] - ch.mean(), used)
                cf = tracing.regression_fit(z, ch[idx], 2)["coefficient"]
                return lambda i: cf * (ch[i] - ch.mean())

            comp_r = tracing.band_component(ch - ch.mean(), br["used"])
            st = removal_step(
                "regression",
                comp_r,
                reg_refit,
                {"channel": name, "coefficient": rg["coefficient"]},
                {"coefficient": (rg["coefficient"] - rg["se"], rg["coefficient"] + rg["se"])},
                ev,
                "regression",
                tracing.regression_heldout(y, ch, fs, TIME_SHARE * level) if own else tracing.regression_heldout(y, ch),
                on_raw=True,
            )
            if st is not None:
                first_steps.append(st)
                removed_first.append((st, comp_r, reg_refit, 1 + len(own), True))
    exact = y is not None or (isinstance(est, str) and est == "oavar")
    thin = tracing.thin_indices(curve.tau)
    sub = curve.subset(thin)
    lines = tracing.spectral_lines(y, fs, level * LINE_SHARE) if y is not None and "sinusoid" in candidates else []
    drift = None
    regs: dict = {}
    tmin, tmax = curve.tau[0], curve.tau[-1]
    for n_step in range(MAX_STEPS):
        keys = [e[0] for e in effects]
        theta_t = _theta_terms(sol, start, effects)
        model_t = np.maximum(design_matrix(sub.tau, sub.m, fs, start) @ theta_t, 1e-300)
        cov_t = None
        if exact:
            cov_t = tracing.exact_covariance(sub.m.astype(np.int64), curve.n_points - 1, fs, start, theta_t)
        a_thin, _ = _design(sub, start, effects)
        test = tracing.ScoreTest(sol.model[thin], model_t, sol.nu[thin], sub.tau, a_thin[:, sol.theta > 0], cov_t)
        fam = _families(
            sub,
            candidates,
            y is not None,
            [],
            None,
        )
        thr = test.threshold(fam, alpha_curve, N_BOOT, seed=n_step)
        props: list[dict] = []

        def propose(key, p, s_new, edge, stat, threshold, split, props=props, **extra):
            props.append(
                {"key": key, "p": p, "sol": s_new, "edge": edge, "stat": stat, "thr": threshold, "split": split} | extra
            )

        if "gauss_markov" in candidates:
            search = EFFECTS["gauss_markov"].search
            assert search is not None
            p, s_new, edge = _search(curve, start, effects, "gauss_markov", search(tmin, tmax))
            propose(
                "gauss_markov", p, s_new, edge, test.statistic(sub.avar, _column("gauss_markov", p, sub)), thr, heldout
            )
        if "resonance" in candidates:
            search = EFFECTS["resonance"].search
            assert search is not None
            best_r = None
            for q in RESONANCE_Q:
                key = f"resonance:{q:g}"
                p, s_new, edge = _search(curve, start, effects, key, search(tmin, tmax))
                if best_r is None or s_new.chi2 < best_r[2].chi2:
                    best_r = (key, p, s_new, edge)
            assert best_r is not None
            key, p, s_new, edge = best_r
            propose(key, p, s_new, edge, test.statistic(sub.avar, _column(key, p, sub)), thr, heldout)
        if "bandwidth" in candidates and not any(_base(k) == "bandwidth" for k in keys) and "N" in start:
            best = None
            # the kind with the lowest χ²; within one effective point of it, the one that needs fewer other
            # terms (a 2-tap average plus white angle noise and a boxcar of 1.2 samples are the same MA(1)
            # process: the single filter is the physical reading)
            # (a cascade counts one parameter more: its boxcar span)
            tie = curve.tau.size / curve.n_eff

            def n_par(key, sol):
                return np.count_nonzero(sol.theta > 0) + ("+" in key)

            for kind, grid in _bandwidth_grids(curve).items():
                key = f"bandwidth:{kind}"
                cont = kind in ("single_pole", "boxcar") or kind.startswith("single_pole+")
                p, s_new, edge = _search(curve, start, effects, key, grid, continuous=cont)
                # a kind whose best parameter sits at the edge of its range is not identified: any kind that
                # is comes first
                if (
                    best is None
                    or (best[3] and not edge)
                    or (
                        best[3] == edge
                        and (
                            s_new.chi2 < best[2].chi2 - tie
                            or (
                                s_new.chi2 < best[2].chi2 + tie
                                and (n_par(key, s_new), s_new.chi2) < (n_par(best[0], best[2]), best[2].chi2)
                            )
                        )
                    )
                ):
                    best = (key, p, s_new, edge)
            if best is not None:
                key, p, s_new, edge = best
                stat = test.statistic(sub.avar, _column(key, p, sub) - 1.0 / sub.tau)
                propose(key, p, s_new, edge, stat, thr, heldout)
        if "sinusoid" in candidates:
            if y is not None:
                done_f = [p for k, p in effects if k == "sinusoid"]
                for ln in lines:
                    if all(abs(ln["f0"] - f) > 2 * ln["bin_hz"] for f in done_f):
                        s_new = _solve(curve, start, effects + [("sinusoid", ln["f0"])])
                        propose("sinusoid", ln["f0"], s_new, False, ln["psd_ratio"], ln["threshold"], heldout, line=ln)
                        break
            else:
                search = EFFECTS["sinusoid"].search
                assert search is not None
                p, s_new, edge = _search(curve, start, effects, "sinusoid", search(tmin, tmax))
                propose("sinusoid", p, s_new, edge, test.statistic(sub.avar, _column("sinusoid", p, sub)), thr, heldout)
        for pr in props:
            considered.setdefault(_base(pr["key"]), []).append(
                {"param": float(pr["p"]), "statistic": float(pr["stat"]), "threshold": float(pr["thr"])}
            )
        ok = [
            pr
            for pr in props
            if pr["stat"] > pr["thr"]
            and not pr["edge"]
            and pr["sol"].theta[-1] > 0
            and pr["sol"].chi2_dof < sol.chi2_dof
        ]
        # a spectral line is the most specific evidence (a sinusoid also raises a bump on the curve that a
        # Gauss–Markov term would otherwise take): lines first, then by the statistic over its threshold
        ok.sort(key=lambda pr: (pr.get("line") is None, -pr["stat"] / pr["thr"]))
        # a resonance near the shortest τ can stand in for the sensor's roll-off: while a bandwidth passes its
        # test and is not in the model, the resonance waits until the bandwidth (alone or paired) was tried
        deferred = []
        if any(_base(pr["key"]) == "bandwidth" for pr in ok):
            deferred = [pr for pr in ok if _base(pr["key"]) == "resonance"]
            ok = [pr for pr in ok if _base(pr["key"]) != "resonance"]

        def first_heldout_winner(cands, effects=effects):
            for pr in cands:
                split = pr["split"]
                ho_b = ho_a = None
                if split is not None:
                    ho_b = split.error(start, effects)
                    ho_a = split.error(start, effects + [(pr["key"], pr["p"])])
                    if not ho_a < ho_b:
                        considered[_base(pr["key"])][-1]["rejected"] = f"held-out error {ho_b:.3g} → {ho_a:.3g} %"
                        continue
                return (pr, ho_b, ho_a)
            return None

        chosen = first_heldout_winner(ok)
        bw = next((pr for pr in ok if _base(pr["key"]) == "bandwidth"), None)
        # (only for an unmistakable roll-off: its statistic ≥ PAIR_FACTOR × the threshold)
        if (
            chosen is None
            and bw is not None
            and bw["split"] is not None
            and bw["stat"] >= PAIR_FACTOR * bw["thr"]
            and "gauss_markov" in candidates
        ):
            # a bandwidth alone can lower the held-out fit where a bump sits further up the curve (the five
            # terms bend to the bump once the short τ are right): try it with a Gauss–Markov term on top
            search = EFFECTS["gauss_markov"].search
            assert search is not None
            with_bw = effects + [(bw["key"], bw["p"])]
            p_g, s_pair, edge_g = _search(curve, start, with_bw, "gauss_markov", search(tmin, tmax))
            if not edge_g and s_pair.theta[-1] > 0:
                ho_b = bw["split"].error(start, effects)
                ho_alone = bw["split"].error(start, with_bw)
                ho_pair = bw["split"].error(start, with_bw + [("gauss_markov", p_g)])
                if ho_pair < ho_b:
                    bw["pair_note"] = (
                        f"accepted with the Gauss–Markov term of the next step: alone it moved the held-out error "
                        f"{ho_b:.3g} → {ho_alone:.3g} %, with it → {ho_pair:.3g} %"
                    )
                    chosen = (bw, ho_b, ho_alone)
        if chosen is None and deferred:
            chosen = first_heldout_winner(deferred)
        if chosen is None:
            break
        pr, ho_b, ho_a = chosen
        key, p, s_new = pr["key"], pr["p"], pr["sol"]
        extra = {"drift": drift, "regression": regs, "line": pr.get("line")}
        params, intervals = _step_params(key, p, s_new, s_new.theta.size - 1, curve, start, effects, extra)
        evidence = _residual_evidence(curve, sol)
        evidence["domain"] = EFFECTS[_base(key)].domain
        evidence["test"] = (
            {"psd_ratio": pr["stat"], "threshold": pr["thr"], "alpha": level * LINE_SHARE}
            if pr.get("line") is not None
            else {"gls_score": pr["stat"], "threshold": pr["thr"], "alpha": alpha_curve}
        )
        if _base(key) == "bandwidth":
            evidence["N"] = math.sqrt(max(s_new.theta[-1], 0.0))
            if y is not None:  # a second domain: the roll-off the filter predicts in the spectrum, and the data's
                evidence["psd"] = tracing.rolloff_psd(y, fs, filter_autocorrelation(key.split(":", 1)[1], p, fs))
        if _base(key) == "gauss_markov" and y is not None:
            # a second domain: the correlation time the residual's autocorrelation in time gives
            evidence["autocorrelation"] = tracing.gm_autocorrelation(y, fs, p)
        if "pair_note" in pr:
            evidence["held_out"] = pr["pair_note"]
        terr = None
        base = _base(key)
        if truth and base in truth:
            terr = {
                kk: params[kk] / v - 1
                for kk, v in truth[base].items()
                if kk in params and not isinstance(params[kk], str) and v
            }
        steps.append(
            Step(
                effect=base,
                params=params,
                intervals=intervals,
                evidence=evidence,
                before=metrics(curve, sol, ho_b),
                after=metrics(curve, s_new, ho_a),
                delta_chi2_eff=float(sol.chi2_eff(curve) - s_new.chi2_eff(curve)),
                truth_error=terr,
            )
        )
        effects, sol = effects + [(key, p)], s_new
    n_curve = len(steps)
    # an effect whose amplitude a later one took over entirely is dropped (refit without it)
    dead = [j for j in range(len(effects)) if sol.theta[k_terms + j] <= 0]
    if dead:
        for j in reversed(dead):
            considered.setdefault(_base(effects[j][0]), []).append({"param": float(effects[j][1]), "absorbed": True})
            del effects[j], steps[j]
            n_curve -= 1
        sol = _solve(curve, start, effects)
    # amplitudes of earlier curve steps from the final joint solution
    for j, (st, (key, _p)) in enumerate(zip(steps[:n_curve], effects)):
        base = _base(key)
        if base in ("gauss_markov", "resonance") or (base == "sinusoid" and y is None):
            names = EFFECTS[base].param_names
            st.params[names[0]] = math.sqrt(max(sol.theta[k_terms + j], 0.0))
            if truth and base in truth and st.truth_error is not None:
                st.truth_error = {kk: st.params[kk] / v - 1 for kk, v in truth[base].items() if kk in st.params}
    change_points = []
    if y is not None and "change_point" in candidates:
        change_points = _change_points(y, fs, start)
        ho_cp = None
        if change_points and heldout is not None:
            m_all = np.asarray(result.m, dtype=np.int64)
            ho_cp = _segments_heldout(heldout, y, fs, m_all, lo, hi, start, effects, [c["t"] for c in change_points])
        if ho_cp is not None and not ho_cp[1] < ho_cp[0]:
            for c in change_points:
                considered.setdefault("change_point", []).append(
                    {
                        "t": c["t"],
                        "gain_chi2": c["gain"],
                        "rejected": f"held-out error {ho_cp[0]:.3g} → {ho_cp[1]:.3g} %",
                    }
                )
            change_points = []
        for c in change_points:
            terr = None
            if truth and "change_point" in truth:
                ts = np.atleast_1d(truth["change_point"]["t"])
                terr = {"t": float(np.min(np.abs(ts - c["t"])) / (y.size / fs))}
            c["before"]["heldout_rms_adev_pct"] = None if ho_cp is None else ho_cp[0]
            c["after"]["heldout_rms_adev_pct"] = None if ho_cp is None else ho_cp[1]
            steps.append(
                Step(
                    effect="change_point",
                    params={"t": c["t"]},
                    intervals={"t": c["interval"]},
                    evidence={
                        "domain": "time",
                        "tau": c["tau"],
                        "window_s": c["window_s"],
                        "coarse_split_s": c["coarse_split_s"],
                        "gain_chi2": c["gain"],
                    },
                    before=c["before"],
                    after=c["after"],
                    delta_chi2_eff=c["gain"],
                    truth_error=terr,
                )
            )
    for st, comp, refit, n_fit, on_raw in removed_first:
        # a time effect went before the curve effects (on the five terms alone); its before/after are scored at
        # the end against the final model — the same curve effects with and without it in the samples (the
        # other removals stay removed)
        y_raw = y + comp
        c_raw, h_raw = build(avar(y_raw, fs, taus=result.tau), y_raw)
        s_raw = _solve(c_raw, start, effects)
        st.before = metrics(c_raw, s_raw, h_raw.error(start, effects) if h_raw is not None else None)
        # after: on the raw curve too — the final model plus what removing it changed in the curve
        # (y_raw − comp is the final samples, whose curve the final model was fitted to)
        ho_after = h_raw.error(start, effects, remove=refit, on_raw=on_raw) if h_raw is not None else None
        st.after = _removal_metrics(c_raw, sol, c_raw.avar - curve.avar, n_fit, ho_after, scored)
        st.delta_chi2_eff = float(s_raw.chi2_eff(c_raw) - sol.chi2_eff(curve))
        st.evidence["scored_with"] = [_base(k) for k, _p in effects] or "the five terms"
    steps = first_steps + steps
    start_fit = _noise_fit(curve, start, [], start_sol, result, unit, confidence)
    final_fit = _noise_fit(curve, start, effects, sol, result, unit, confidence)
    return Refinement(
        steps=steps,
        fit=final_fit,
        start=start_fit,
        result=result,
        terms=start,
        effects=effects,
        change_points=change_points,
        considered=considered,
        heldout_note=note,
        start_heldout_rms_adev_pct=start_heldout,
        scored_tau=curve.tau[scored],
        tau_range=(lo, hi),
    )


refine.__doc__ = (refine.__doc__ or "").replace("{effects}", describe())
