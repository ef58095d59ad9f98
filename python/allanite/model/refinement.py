"""Close the loop: find what a fitted noise model lacks, add that effect, report the error before and after.

:func:`refine` fits the starting IEEE-952 model (weighted least squares in variance space, as
:func:`allanite.fit`), looks at the normalised residual per τ, and tries each candidate effect by its
Allan-variance signature (closed forms, ``docs/FORMULAS.md`` §5 and the references below):

- ``"gauss_markov"`` — first-order Gauss–Markov rate of variance σ² and correlation time T_c:
  σ²_A(τ) = σ²·(T_c/τ)²·(2τ/T_c − 3 + 4e^{−τ/T_c} − e^{−2τ/T_c}) (IEEE Std 952 App. C; a bump that
  peaks near τ ≈ 1.89·T_c, K-like below, N-like above; T_c in [τ_min, τ_max/4] so that the bump lies
  inside the curve — a "T_c" below the shortest τ would only describe a roll-off there, e.g. an
  anti-alias filter's);
- ``"sinusoid"`` — a rate sinusoid of amplitude A and frequency f0: σ²_A(τ) = A²·sin⁴(πf0τ)/(πf0τ)²
  (nulls at τ = k/f0). Only f0 ≥ 2/τ_max are tried: a sinusoid is told apart from a Gauss–Markov bump
  by its nulls, so at least two (τ = 1/f0, 2/f0) must fall inside the curve (a best f0 or T_c at the
  edge of its search range is not taken as identified);
- ``"change_point"`` — nonstationarity: the Allan variance of non-overlapping windows is tested for a
  step in level along the record (all τ jointly), located at sample resolution by the two-segment
  likelihood of the squared differences at the τ where the step is strongest, with a 2-unit support
  interval; repeated on each side (binary segmentation).

Nonlinear parameters (T_c, f0) are found by a grid search with the linear coefficients by weighted
NNLS at each grid point, then refined by a bounded scalar search; their intervals come from the
profile of χ² (Δχ²_eff = 1). A candidate is accepted only if it earns its parameters by BIC on an
*effective* χ²: the τ estimates are correlated, so χ² is scaled by n_eff/n with n_eff the number of
octaves the curve spans (``fit`` thins to octaves for the same reason), and the penalty is
k·ln(n_eff) per added parameter pair, plus a floor so that chance wiggles on a clean record are not
modelled (calibrated on clean simulated records: ≤ 5 % false alarms, see ``tests/test_refine.py``); the
effect must also lower χ²/dof.
The loop stops when χ²/dof ≤ 1.5 or no candidate earns its parameters.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize_scalar
from scipy.stats import chi2 as chi2_dist

from .._display import RichDisplay, Summary, Table, fmt_ci, thin
from .._progress import StepBar
from .._validate import as_rate_columns
from ..analysis import avar, davar
from ..errors import ParameterError
from ..estimators.grid import tau_grid
from ..results import AllanResult
from . import fitting
from .effects import EFFECTS, describe, gm_avar, sinusoid_avar
from .terms import TERM_ALPHA, check_terms, design_matrix

__all__ = ["refine", "Refinement", "Step", "gm_avar", "sinusoid_avar", "CANDIDATES"]

#: Effects refine can add, from the registry in :mod:`allanite.model.effects`.
CANDIDATES = tuple(EFFECTS)
#: Stop refining once the model is this good (χ²/dof of the diagonal-weighted residuals).
GOOD_CHI2_DOF = 1.5
#: Minimum improvement of the effective χ² (beyond the BIC penalty) to accept an effect.
MIN_GAIN = 6.0
MAX_STEPS = 4


def _column(effect, p, tau):
    sig = EFFECTS[effect].signature
    assert sig is not None
    return sig(tau, p)


def _alpha_of(effect, p, tau):
    """Noise type each effect resembles at τ, for the EDF of the estimates."""
    alpha = EFFECTS[effect].alpha
    assert alpha is not None
    return alpha(tau, p)


# ----------------------------------------------------------------------------------------------
# weighted fit with extra effects


class _Curve:
    """One Allan curve to fit: τ, m, estimates, record length, estimator (for the EDF)."""

    def __init__(self, tau, m, avar, fs, n_points, estimator):
        self.tau, self.m, self.avar = tau, m, avar
        self.fs, self.n_points, self.estimator = fs, n_points, estimator
        self._edf = {}
        self.n_eff = max(2.0, math.log2(tau[-1] / tau[0]) + 1.0)

    def edf(self, alpha: int) -> np.ndarray:
        if alpha not in self._edf:
            self._edf[alpha] = fitting.edf_per_tau(np.full(self.m.size, alpha), self.m, self.n_points, self.estimator)
        return self._edf[alpha]


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


def _solve(curve: _Curve, terms, effects, max_iter: int = 40) -> _Solution:
    """IRLS weighted NNLS of the terms plus effects [(name, nonlinear parameter)]."""
    tau = curve.tau
    cols = [design_matrix(tau, tau * curve.fs, curve.fs, terms)]
    alphas = [np.full(tau.size, TERM_ALPHA[t]) for t in terms]
    for name, p in effects:
        cols.append(_column(name, p, tau)[:, None])
        alphas.append(_alpha_of(name, p, tau))
    a = np.hstack(cols)
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
        done = np.allclose(new, theta, rtol=1e-7, atol=0.0)
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


def _metrics(sol: _Solution) -> dict:
    return {"chi2_dof": sol.chi2_dof, "rms_z": float(np.sqrt(np.mean(sol.z**2)))}


def _curve_metrics(curve: _Curve, sol: _Solution) -> dict:
    out = _metrics(sol)
    out["rms_adev_pct"] = float(100 * np.sqrt(np.mean((np.sqrt(curve.avar / sol.model) - 1) ** 2)))

    out["p_value"] = float(chi2_dist.sf(sol.chi2_eff(curve), max(1.0, curve.n_eff - 1)))
    return out


# ----------------------------------------------------------------------------------------------
# candidates


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


def _search(curve, terms, effects, name, grid):
    """Best nonlinear parameter for effect ``name`` on ``grid`` (then refined), its solution and profile."""

    chis = np.array([_solve(curve, terms, effects + [(name, p)]).chi2 for p in grid])
    k = int(np.argmin(chis))
    lo, hi = math.log(grid[max(0, k - 1)]), math.log(grid[min(grid.size - 1, k + 1)])
    if hi > lo:
        res = minimize_scalar(
            lambda lp: _solve(curve, terms, effects + [(name, math.exp(lp))]).chi2,
            bounds=(lo, hi),
            method="bounded",
            options={"xatol": 1e-4},
        )
        p = math.exp(res.x)
    else:
        p = float(grid[k])
    sol = _solve(curve, terms, effects + [(name, p)])
    if sol.chi2 > chis[k]:
        p, sol = float(grid[k]), _solve(curve, terms, effects + [(name, float(grid[k]))])
    return p, sol, (grid, chis)


#: Octave-to-octave correlation of Allan estimates used for the parameters' effective sample size
#: (the mid value of fit.OCTAVE_CORRELATION: 0.42 white angle … 0.87 random walk).
PROFILE_RHO = 0.68


def _profile_interval(curve, terms, effects, name, p, sol, grid_chis):
    """Interval of the nonlinear parameter where the effective χ² rises by ≤ 1 over its minimum.

    χ² of the dense, correlated τ points is scaled to n_eff·(1 − ρ)/(1 + ρ) independent ones (n_eff
    octaves whose estimates correlate by ρ = ``PROFILE_RHO`` from one to the next); the crossings are
    interpolated on a fine log grid around the best value."""
    scale = curve.n_eff * (1 - PROFILE_RHO) / (1 + PROFILE_RHO) / curve.tau.size
    local = p * np.exp(np.linspace(-1.5, 1.5, 121))
    lc = np.array([_solve(curve, terms, effects + [(name, q)]).chi2 for q in local])
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


def _joint(curve, terms, effects, sol, passes: int = 3):
    """Re-estimate every effect's nonlinear parameter with the others held (coordinate descent): an
    effect added first may have absorbed part of a later one's signature."""

    effects = list(effects)
    for _ in range(passes):
        moved = False
        for i, (name, p) in enumerate(effects):

            def chi(lp, i=i, name=name):
                trial = effects[:i] + [(name, math.exp(lp))] + effects[i + 1 :]
                return _solve(curve, terms, trial).chi2

            res = minimize_scalar(
                chi, bounds=(math.log(p) - 1.5, math.log(p) + 1.5), method="bounded", options={"xatol": 1e-4}
            )
            if res.fun < sol.chi2 - 1e-9:
                effects[i] = (name, math.exp(res.x))
                sol = _solve(curve, terms, effects)
                moved = moved or abs(res.x - math.log(p)) > 1e-3
        if not moved:
            break
    return effects, sol


def _update_steps(steps, curve, terms, effects, sol, truth):
    """Steps' parameters and intervals from the joint solution (in the order the effects were added)."""
    k = len(terms)
    curve_steps = [st for st in steps if EFFECTS[st.effect].kind == "curve"]
    for j, (st, (name, p)) in enumerate(zip(curve_steps, effects)):
        i = k + j
        amp = math.sqrt(max(sol.theta[i], 0.0))
        var_i = sol.cov[i, i]
        sd = math.sqrt(max(var_i, 0.0)) / (2 * amp) if amp > 0 and np.isfinite(var_i) else float("nan")
        others = effects[:j] + effects[j + 1 :]
        names = EFFECTS[name].param_names
        p_int = _profile_interval(curve, terms, others, name, p, sol, None)
        st.params = {names[0]: amp, names[1]: p}
        st.intervals = {names[0]: (max(0.0, amp - sd), amp + sd), names[1]: p_int}
        if truth and name in truth:
            st.truth_error = {kk: st.params[kk] / v - 1 for kk, v in truth[name].items() if kk in st.params}


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

    ``params`` in the input unit's base form (Gauss–Markov: ``sigma`` rate unit, ``tc`` s; sinusoid:
    ``amplitude`` rate unit, ``f0`` Hz; change point: ``t`` s); ``intervals`` the same keys →
    (low, high); ``before``/``after``: ``chi2_dof``, ``rms_z``, ``rms_adev_pct`` (and ``p_value``
    for curve effects); ``evidence``: where in τ or t the residual was; ``truth_error``: relative
    parameter errors when ``truth`` was given.
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
    hold the added effects' parameters), ``start`` the starting model, ``steps`` the effects added."""

    steps: list
    fit: fitting.NoiseFit
    start: fitting.NoiseFit
    result: AllanResult
    terms: tuple
    effects: list = field(default_factory=list)
    change_points: list = field(default_factory=list)
    considered: dict = field(default_factory=dict)

    @property
    def found(self) -> list:
        return [s.effect for s in self.steps]

    def report(self) -> str:
        """Markdown: the starting residual, each step with its parameters, evidence and errors."""
        s0 = self.start
        lines = [
            "# Model refinement",
            "",
            f"Starting model {'+'.join(self.terms)}: χ²/dof = {s0.chi2_dof:.3g}, "
            f"RMS z = {np.sqrt(np.mean(s0.z**2)):.3g}.",
            "",
        ]
        if not self.steps:
            lines.append("Nothing added: the residual is consistent with noise or no candidate earned its parameters.")
        for i, st in enumerate(self.steps, 1):
            ps = ", ".join(
                f"{k} = {v:.4g} [{st.intervals[k][0]:.4g}, {st.intervals[k][1]:.4g}]" for k, v in st.params.items()
            )
            lines += [
                f"## Step {i}: {st.effect}",
                "",
                f"- parameters: {ps}",
                f"- evidence: {st.evidence}",
                "- before → after: "
                + ", ".join(
                    f"{k} {st.before[k]:.3g} → {st.after[k]:.3g}" for k in ("chi2_dof", "rms_z", "rms_adev_pct")
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


def _noise_fit(curve, terms, effects, sol, result, unit, confidence):
    """A NoiseFit for the solution, with the effects' parameters among the coefficients."""
    zq = fitting.z_quantile(confidence)
    k = len(terms)
    inflate = max(1.0, math.sqrt(sol.chi2_dof))
    coeffs = fitting.coefficients(terms, sol.theta[:k], sol.cov[:k, :k], zq, inflate, unit)
    comps = {t: sol.a[:, i] * sol.theta[i] for i, t in enumerate(terms)}
    for j, (name, _param) in enumerate(effects):
        i = k + j
        key = f"{name}{j + 1}" if sum(e[0] == name for e in effects) > 1 else name
        comps[key] = sol.a[:, i] * sol.theta[i]
        coeffs[key] = fitting.Coefficient(
            name=key,
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
        theta=sol.theta[:k],
        covariance=sol.cov[:k, :k],
    )


# ----------------------------------------------------------------------------------------------
# the loop


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
    progress=None,
) -> Refinement:
    """Fit the starting model, find what it lacks, add it, repeat; report the error before and after.

        Parameters
        ----------
        x_or_result : array_like or AllanResult
            Samples (then ``fs`` is needed; the Allan variance is computed on a dense exponential grid of
            ``points`` τ so that a sinusoid's nulls are resolved, and change points can be searched), or
            a static :class:`~allanite.AllanResult` (curve effects only).
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
        tau_range : (float, float), optional
            τ (s) to use, as in :func:`allanite.fit` (e.g. to leave out a non-white shortest τ).
        truth : dict, optional
            Known parameters per effect (``{"gauss_markov": {"sigma": …, "tc": …}}``, ``{"change_point":
            {"t": …}}``): each step then records its relative errors.
        axis : int
            Which axis of multi-axis input to refine.
        progress : bool, optional
            A ``tqdm.auto`` bar over the steps (the search of each step is the long part on real logs):
            None (default) shows it only in a notebook or a terminal, True always, False never.

        Returns
        -------
        Refinement

        Examples
        --------
        >>> import allanite
        >>> y = allanite.simulate(1_000_000, 100.0, N=2e-3, K=2e-5, gauss_markov=[(5e-3, 10.0)], seed=11)
        >>> r = allanite.refine(y, 100.0)               # the generator's GM is not in the starting model
        >>> r.found, round(r.steps[0].params["tc"], 1), round(r.steps[0].after["chi2_dof"], 1)
        (['gauss_markov'], 10.2, 1.1)
    """
    with StepBar(progress, 2 + MAX_STEPS, "refine") as bar:
        return _refine(x_or_result, fs, start, candidates, unit, input, tau_range, truth, confidence, points, axis, bar)


def _refine(x_or_result, fs, start, candidates, unit, input, tau_range, truth, confidence, points, axis, bar):
    """:func:`refine`, telling ``bar`` before each stage."""
    bar.step("Allan variance")
    start = check_terms(start)
    if isinstance(candidates, str):
        candidates = (candidates,)
    bad = [c for c in candidates if c not in CANDIDATES]
    if bad:
        raise ParameterError(f"unknown candidate effect {bad[0]!r}; allowed: {', '.join(CANDIDATES)}")
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
    lo, hi = (0.0, np.inf) if tau_range is None else fitting.check_tau_range(tau_range)
    keep = (result.tau >= lo) & (result.tau <= hi) & (result.avar > 0)
    if keep.sum() < len(start) + 3:
        raise ParameterError(
            f"{int(keep.sum())} usable τ points; refining {len(start)} terms needs at least {len(start) + 3}"
        )
    est = result.estimator if result.source is None else tuple(np.asarray(result.source)[keep])
    curve = _Curve(
        result.tau[keep], result.m[keep].astype(np.float64), result.avar[keep], result.fs, result.n_samples + 1, est
    )
    effects: list = []
    steps: list = []
    sol = _solve(curve, start, effects)
    start_sol = sol
    considered: dict[str, list] = {}
    tmin, tmax = curve.tau[0], curve.tau[-1]
    for k in range(MAX_STEPS):
        if sol.chi2_dof <= GOOD_CHI2_DOF:
            break
        bar.step(f"search {k + 1} (χ²/dof {sol.chi2_dof:.3g})")
        best = None
        for cand in candidates:
            if cand == "change_point":
                continue
            search = EFFECTS[cand].search
            assert search is not None
            grid = search(tmin, tmax)
            p, s_new, prof = _search(curve, start, effects, cand, grid)
            gain = sol.chi2_eff(curve) - s_new.chi2_eff(curve)
            penalty = 2 * math.log(curve.n_eff) + MIN_GAIN
            considered.setdefault(cand, []).append({"param": p, "gain_chi2_eff": float(gain), "penalty": penalty})
            # a parameter pinned at its search range's edge is not identified by the curve
            at_edge = p <= grid[0] * 1.02 or p >= grid[-1] / 1.02
            # ... and an effect must make the fit better per degree of freedom, not only in total (on a grossly
            # wrong model a χ² drop can pass the BIC test while χ²/dof rises)
            if (
                gain > penalty
                and s_new.theta[-1] > 0
                and not at_edge
                and s_new.chi2_dof < sol.chi2_dof
                and (best is None or gain > best[0])
            ):
                best = (gain, cand, p, s_new, prof)
        if best is None:
            break
        gain, cand, p, s_new, prof = best
        evidence = _residual_evidence(curve, sol)
        p_int = _profile_interval(curve, start, effects, cand, p, s_new, prof)
        new_effects = effects + [(cand, p)]
        i = s_new.theta.size - 1
        amp = math.sqrt(s_new.theta[i])
        var_i = s_new.cov[i, i]
        sd_amp = math.sqrt(max(var_i, 0.0)) / (2 * amp) if amp > 0 and np.isfinite(var_i) else float("nan")
        names = EFFECTS[cand].param_names
        params = {names[0]: amp, names[1]: p}
        intervals = {names[0]: (max(0.0, amp - sd_amp), amp + sd_amp), names[1]: p_int}
        before, after = _curve_metrics(curve, sol), _curve_metrics(curve, s_new)
        terr = None
        if truth and cand in truth:
            terr = {k: params[k] / v - 1 for k, v in truth[cand].items() if k in params}
        steps.append(
            Step(
                effect=cand,
                params=params,
                intervals=intervals,
                evidence=evidence,
                before=before,
                after=after,
                delta_chi2_eff=float(gain),
                truth_error=terr,
            )
        )
        effects, sol = new_effects, s_new
        if len(effects) > 1:
            effects, sol = _joint(curve, start, effects, sol)
            _update_steps(steps, curve, start, effects, sol, truth)
    change_points = []
    if y is not None and "change_point" in candidates:
        bar.step("change points")
        change_points = _change_points(y, fs, start)
        for c in change_points:
            terr = None
            if truth and "change_point" in truth:
                ts = np.atleast_1d(truth["change_point"]["t"])
                terr = {"t": float(np.min(np.abs(ts - c["t"])) / (y.size / fs))}
            steps.append(
                Step(
                    effect="change_point",
                    params={"t": c["t"]},
                    intervals={"t": c["interval"]},
                    evidence={
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
    )


refine.__doc__ = (refine.__doc__ or "").replace("{effects}", describe())
