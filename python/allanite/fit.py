"""Fitting the IEEE-952 noise model to an Allan variance: weighted non-negative least squares in linear
variance space, iteratively reweighted by the model's own variance of each estimate.

Model (FORMULAS.md §6, IEEE Std 952-1997 Annex C), τ in s, coefficients in the input unit's base form:

    σ²(τ) = 3Q²/τ² + N²/τ + (2 ln2/π)·B² + K²·τ0(2m² + 1)/(6m) + R²τ²/2

The rate-random-walk column is the exact Allan variance of a *sampled* random walk (K²τ/3 for
m ≫ 1, 1.5× that at m = 1); the others are exact for sampled data (white angle, white rate, ramp)
or the usual asymptote (flicker's plateau).

Why not a line fit in log-log space: ln σ̂² is biased low by ≈ 1/ν and its variance 2/ν makes the
few-cluster long-τ points weigh as much as the good ones (FORMULAS.md §7). Here each estimate is
weighted by ν/(2σ⁴_model), ν the equivalent degrees of freedom of the overlapping (or classic)
estimator for the noise type that dominates the model at that τ (Greenhall's algorithm), and the
weights are recomputed from the fitted model until they settle. Neighbouring overlapping estimates
are strongly correlated, so by default only τ at least an octave apart enter the fit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .errors import ParameterError
from .results import AllanResult, DynamicAllanResult

__all__ = ["fit", "NoiseFit", "Coefficient", "CoefficientSeries", "TERMS"]

#: Terms of the model, in order.
TERMS = ("Q", "N", "B", "K", "R")
#: Power-law noise type (α of S_y ∝ f^α, in phase/angle terms) that each term is, for the EDF.
TERM_ALPHA = {"Q": 2, "N": 0, "B": -1, "K": -2, "R": -2}
TERM_NAMES = {
    "Q": "quantization", "N": "angle random walk", "B": "bias instability",
    "K": "rate random walk", "R": "rate ramp",
}
_FLICKER = 2.0 * math.log(2.0) / math.pi


def design_matrix(tau: np.ndarray, m: np.ndarray, fs: float, terms) -> np.ndarray:
    """Columns of σ²(τ) per squared coefficient, one per term."""
    tau0 = 1.0 / fs
    cols = {
        "Q": 3.0 / tau**2,
        "N": 1.0 / tau,
        "B": np.full_like(tau, _FLICKER),
        "K": tau0 * (2.0 * m**2 + 1.0) / (6.0 * m),
        "R": tau**2 / 2.0,
    }
    return np.column_stack([cols[t] for t in terms])


@dataclass(frozen=True)
class Coefficient:
    """One fitted coefficient.

    ``value`` and ``ci`` are in the input unit's base form (for °/s samples: Q in °, N in °/√s,
    B in °/s, K in °/s^1.5, R in °/s²); ``ieee`` and ``ieee_ci`` in IEEE-952 units
    (``ieee_unit``: °, °/√h, °/h, °/h^1.5, °/h²) when the input unit is known.
    """

    name: str
    value: float
    ci: tuple
    unit: str | None = None
    ieee: float | None = None
    ieee_ci: tuple | None = None
    ieee_unit: str | None = None

    def __repr__(self) -> str:
        u = f" {self.unit}" if self.unit else ""
        s = f"{self.name} = {self.value:.4g}{u} [{self.ci[0]:.4g}, {self.ci[1]:.4g}]"
        if self.ieee is not None:
            s += f" = {self.ieee:.4g} {self.ieee_unit} [{self.ieee_ci[0]:.4g}, {self.ieee_ci[1]:.4g}]"
        return s


@dataclass(frozen=True, repr=False, eq=False)
class NoiseFit:
    """The fitted model: coefficients with intervals, the fitted curve and the residuals.

    Attributes
    ----------
    coefficients : dict
        Term name → :class:`Coefficient`.
    tau, avar, edf : ndarray
        The τ used in the fit, the estimates there and their equivalent degrees of freedom.
    model : ndarray
        Fitted Allan variance at ``tau``; ``components`` maps each term to its share.
    z : ndarray
        Residual per τ in units of the estimate's standard deviation: (σ̂² − σ²_model)/(σ²_model·√(2/ν)).
    chi2, dof, chi2_dof, p_value : float
        Goodness of fit (χ² of z, degrees of freedom = points − active terms, its p-value).
    readoffs : dict
        Datasheet read-offs from the full curve: ``adev_at_1s`` (ARW read-off, °/√s for °/s input:
        σ(1 s)·√1 s), ``adev_min``, ``tau_at_min`` and ``bias_instability_readoff`` = min/0.664.
    confidence : float
        Level of the intervals.
    """

    coefficients: dict
    terms: tuple
    tau: np.ndarray
    m: np.ndarray
    avar: np.ndarray
    edf: np.ndarray
    model: np.ndarray
    components: dict
    z: np.ndarray
    chi2: float
    dof: int
    chi2_dof: float
    p_value: float
    readoffs: dict
    fs: float
    confidence: float
    unit: str | None = None
    iterations: int = 0
    theta: np.ndarray = field(default=None)
    covariance: np.ndarray = field(default=None)

    def curve(self, tau) -> np.ndarray:
        """The fitted Allan variance at any τ (s)."""
        tau = np.asarray(tau, dtype=np.float64)
        m = np.maximum(1.0, tau * self.fs)  # real m: a smooth curve between the integer points
        return design_matrix(tau, m, self.fs, self.terms) @ self.theta

    def component(self, name: str, tau) -> np.ndarray:
        """One term's Allan variance at τ (s)."""
        tau = np.asarray(tau, dtype=np.float64)
        m = np.maximum(1.0, tau * self.fs)  # real m: a smooth curve between the integer points
        k = self.terms.index(name)
        return design_matrix(tau, m, self.fs, (name,))[:, 0] * self.theta[k]

    def __repr__(self) -> str:
        lines = [f"NoiseFit({len(self.tau)} τ, χ²/dof = {self.chi2_dof:.3g}, p = {self.p_value:.3g}, "
                 f"{self.confidence:.1%} intervals)"]
        lines += [f"  {c!r}" for c in self.coefficients.values()]
        return "\n".join(lines)

    def plot(self, ax=None, **kwargs):
        """ADEV estimates with the fitted model and each term as its own line."""
        from .plot import plot_fit

        return plot_fit(self, ax=ax, **kwargs)


@dataclass(frozen=True, repr=False, eq=False)
class CoefficientSeries:
    """Coefficients fitted in every window of a dynamic result (paper 002's 2-D representation).

    ``values``, ``ci_low``, ``ci_high`` map term → array over ``t`` (input unit's base form);
    ``ieee`` maps term → array in IEEE-952 units (``ieee_units``) when the unit is known.
    """

    t: np.ndarray
    terms: tuple
    values: dict
    ci_low: dict
    ci_high: dict
    chi2_dof: np.ndarray
    confidence: float
    unit: str | None = None
    ieee: dict | None = None
    ieee_units: dict | None = None

    def __repr__(self) -> str:
        parts = ", ".join(f"{k} median {np.median(v):.3g}" for k, v in self.values.items())
        return f"CoefficientSeries({self.t.size} windows: {parts})"

    def plot(self, axes=None, ieee: bool = True):
        """Each coefficient against time, with its interval band."""
        from .plot import plot_coefficient_series

        return plot_coefficient_series(self, axes=axes, ieee=ieee)


#: Correlation of overlapping Allan variance estimates one octave apart, by noise type, measured on
#: 150 simulated records of 2^18 samples (log-AVAR at octave τ): white angle 0.42, white rate 0.53,
#: flicker rate 0.68, random-walk rate 0.87 (ramp: taken as random walk). Two estimates a factor r
#: apart are given ρ^|log2 r|. Classic estimates are less correlated; the same values are used
#: for them (conservative).
OCTAVE_CORRELATION = {"Q": 0.42, "N": 0.53, "B": 0.68, "K": 0.87, "R": 0.87}


def _estimate_correlation(tau, parts, terms, estimator) -> np.ndarray:
    """Correlation matrix of the Allan variance estimates at ``tau`` under the model mixture."""
    share = parts / np.maximum(parts.sum(axis=1, keepdims=True), 1e-300)
    rho = np.array([OCTAVE_CORRELATION[t] for t in terms])
    rho_tau = np.clip(share @ rho, 0.0, 0.99)  # per-τ octave correlation of the mixture
    lt = np.log2(tau)
    dist = np.abs(lt[:, None] - lt[None, :])
    # geometric mean of the two ends' octave correlations, to the power of the octave distance
    base = np.sqrt(np.outer(rho_tau, rho_tau))
    return np.where(dist == 0, 1.0, base**dist)


def _octave_thin(tau: np.ndarray) -> np.ndarray:
    """Indices of τ at least a factor 2 apart, starting from the shortest."""
    keep = [0]
    for i in range(1, tau.size):
        if tau[i] >= 2.0 * tau[keep[-1]] * (1 - 1e-12):
            keep.append(i)
    return np.asarray(keep)


def _edf(alpha: np.ndarray, m: np.ndarray, n_points: int, estimator) -> np.ndarray:
    """ν per τ for one noise type. ``estimator``: "oavar"/"avar", or a tuple naming the estimator of
    every τ (Theo-family results: Greenhall's EDF for Allan τ, Howe's Theo1 EDF for Theo τ)."""
    from .confidence import _edf_mixed, edf_greenhall

    if not isinstance(estimator, str):
        return _edf_mixed(np.asarray(alpha), np.asarray(m), int(n_points), np.asarray(estimator))
    overlapping = estimator == "oavar"
    return np.array([edf_greenhall(int(a), 2, int(mm), int(n_points), overlapping=overlapping)
                     for a, mm in zip(alpha, m)], dtype=np.float64)


def _nnls(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    from scipy.optimize import nnls

    # Column scaling keeps the problem well conditioned (columns span many decades in τ).
    scale = np.linalg.norm(a, axis=0)
    scale[scale == 0] = 1.0
    x, _ = nnls(a / scale, b, maxiter=50 * a.shape[1])
    return x / scale


def _fit_core(tau, m, avar, fs, n_points, estimator, terms, confidence, max_iter=50, edf_cache=None):
    """IRLS for one curve. Returns theta, covariance, model, edf, z, iterations.

    ``m`` are the estimator's averaging factors (for the EDF); the closed forms are evaluated at
    τ·fs, which is m for the Allan estimators and 0.75·m for Theo1-based points."""
    a = design_matrix(tau, tau * fs, fs, terms)
    cache = {} if edf_cache is None else edf_cache
    # EDF of each term's noise type at every τ (Greenhall), cached across windows of a dynamic fit.
    nu_terms = []
    for t in terms:
        key = (TERM_ALPHA[t], tuple(m), n_points, estimator)
        if key not in cache:
            cache[key] = _edf(np.full(m.size, TERM_ALPHA[t]), m, n_points, estimator)
        nu_terms.append(cache[key])
    nu_terms = np.column_stack(nu_terms)

    def edf_of(parts):
        # Mixture of independent noises: Var(σ̂²) ≈ Σ_k 2 s_k²/ν_k, so ν = (Σ s_k)² / Σ s_k²/ν_k —
        # continuous in the coefficients (an arg-max noise type would make the weights jump and the
        # iteration cycle between neighbouring solutions).
        tot = parts.sum(axis=1)
        den = np.sum(parts**2 / nu_terms, axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            nu = np.where(den > 0, tot**2 / den, nu_terms[:, 0])
        return nu

    # Start: weights from the estimates themselves, white-rate EDF.
    model = avar.copy()
    nu = nu_terms[:, terms.index("N")] if "N" in terms else nu_terms[:, 0]
    theta = np.zeros(len(terms))
    it = 0
    for it in range(1, max_iter + 1):
        w = nu / (2.0 * np.maximum(model, 1e-300) ** 2)
        sw = np.sqrt(w)
        new = _nnls(a * sw[:, None], avar * sw)
        parts = a * new
        floor = 1e-12 * np.max(avar)
        new_model = np.maximum(parts.sum(axis=1), floor)
        done = np.allclose(new, theta, rtol=1e-7, atol=0.0)
        # Damped reweighting: weights from the geometric mean of the last two models. Undamped,
        # a term on the edge of significance can flip in and out every other iteration.
        model = new_model if it == 1 else np.sqrt(model * new_model)
        theta = new
        if new.any():
            nu = edf_of(parts)
        if done:
            break
    model = np.maximum((a * theta).sum(axis=1), 1e-12 * np.max(avar))
    w = nu / (2.0 * model**2)
    z = (avar - model) * np.sqrt(w)
    active = theta > 0
    cov = np.full((len(terms), len(terms)), np.nan)
    # Covariance of the estimates: variances 2σ⁴/ν, correlated across τ (overlapping estimates share
    # data). The weighted fit treats them as independent, so its covariance is the sandwich
    # (AᵀWA)⁻¹ AᵀW Σ W A (AᵀWA)⁻¹ with Σ = D R D — R from the octave correlations per noise type.
    parts = a * theta
    corr = _estimate_correlation(tau, parts if theta.any() else a, terms, estimator)
    sd = np.sqrt(2.0 / nu) * model
    sigma = corr * np.outer(sd, sd)

    def sandwich(idx):
        aw = a[:, idx] * w[:, None]
        bread = np.linalg.pinv(aw.T @ a[:, idx])
        return bread @ (aw.T @ sigma @ aw) @ bread

    if active.any():
        idx = np.flatnonzero(active)
        cov[np.ix_(idx, idx)] = sandwich(idx)
    # Inactive terms: the variance each would have if freed alone with the active ones.
    for k in np.flatnonzero(~active):
        idx = np.append(np.flatnonzero(active), k)
        cov[k, k] = sandwich(idx)[-1, -1]
    return theta, cov, model, nu, z, it, a


def _interval(theta_k, var_k, zq, inflate):
    se = math.sqrt(max(var_k, 0.0)) * inflate if np.isfinite(var_k) else math.inf
    lo = max(0.0, theta_k - zq * se)
    hi = theta_k + zq * se
    return math.sqrt(lo), math.sqrt(hi) if np.isfinite(hi) else math.inf


def _readoffs(result: AllanResult, adev_row: np.ndarray) -> dict:
    tau = result.tau
    out = {}
    if tau[0] <= 1.0 <= tau[-1]:
        # log-log interpolation between the neighbours of 1 s (exact when 1 s is on the grid)
        out["adev_at_1s"] = float(np.exp(np.interp(0.0, np.log(tau), np.log(adev_row))))
        out["adev_at_1s_interpolated"] = not np.any(np.isclose(tau, 1.0))
    else:
        out["adev_at_1s"] = None
        out["adev_at_1s_interpolated"] = None
    i = int(np.argmin(adev_row))
    out["adev_min"] = float(adev_row[i])
    out["tau_at_min"] = float(tau[i])
    out["bias_instability_readoff"] = float(adev_row[i] / 0.664)
    return out


def _check_terms(terms) -> tuple:
    if isinstance(terms, str):
        terms = (terms,)
    try:
        terms = tuple(terms)
    except TypeError:
        raise ParameterError(f"terms must be a sequence of {TERMS}, got {terms!r}") from None
    bad = [t for t in terms if t not in TERMS]
    if bad or not terms or len(set(terms)) != len(terms):
        raise ParameterError(f"terms must be distinct names from {TERMS}, got {terms!r}")
    return tuple(t for t in TERMS if t in terms)


def _zq(confidence) -> float:
    from scipy.stats import norm

    if isinstance(confidence, bool) or not isinstance(confidence, (int, float, np.floating)) \
            or not 0.0 < float(confidence) < 1.0:
        raise ParameterError(f"confidence must be a level strictly between 0 and 1, got {confidence!r}")
    return float(norm.ppf(0.5 + float(confidence) / 2.0))


def _coefficients(terms, theta, cov, zq, inflate, unit):
    from .units import ieee952

    coeffs = {}
    for k, name in enumerate(terms):
        value = math.sqrt(theta[k])
        ci = _interval(theta[k], cov[k, k], zq, inflate)
        if unit is not None:
            q = ieee952(name, value, unit)
            lo = ieee952(name, ci[0], unit).value
            hi = ieee952(name, ci[1], unit).value if np.isfinite(ci[1]) else math.inf
            coeffs[name] = Coefficient(name, value, ci, _base_unit(name, unit), q.value, (lo, hi), q.unit)
        else:
            coeffs[name] = Coefficient(name, value, ci)
    return coeffs


def _base_unit(term: str, unit) -> str:
    """Label of a coefficient's base form for samples in ``unit`` (°/s → °, °/√s, °/s, °/s^1.5, °/s²)."""
    from .units import rate_unit

    u = str(rate_unit(unit))
    if u.endswith("/s"):
        angle = u[:-2]
        return {"Q": angle, "N": f"{angle}/√s", "B": u, "K": f"{angle}/s^1.5", "R": f"{angle}/s²"}[term]
    return {"Q": f"({u})·s", "N": f"({u})·√s", "B": u, "K": f"({u})/√s", "R": f"({u})/s"}[term]


def fit(result, *, terms=TERMS, unit=None, confidence: float = 0.683, thin: bool = True, tau_range=None,
        max_iter: int = 50):
    """Fit the IEEE-952 noise terms to an Allan variance result.

    Parameters
    ----------
    result : AllanResult or DynamicAllanResult
        Static result → :class:`NoiseFit` (a list of them for several axes). Dynamic result →
        :class:`CoefficientSeries`, the coefficients of every window (a list for several axes).
        The result should be of the overlapping ("oavar") or classic ("avar") estimator.
    terms : sequence of {"Q", "N", "B", "K", "R"}
        Terms to fit (drop the ones the data cannot support).
    unit : str, optional
        Unit of the rate samples the result was computed from (e.g. "deg/s"); gives each
        coefficient its IEEE-952 value (``ieee``). Must be a rate unit.
    confidence : float
        Level of the coefficient intervals (default 68.3 %).
    thin : bool
        Use only τ at least an octave apart (default), so correlated neighbours do not overcount
        information; ``False`` uses every τ of the result.
    tau_range : (float, float), optional
        Fit only τ in [low, high] seconds (either may be None). Real sensors are often not white
        at the shortest τ (anti-alias filters, vibration lines): those points carry the largest
        EDF and can dominate a fit of a model that does not describe them.
    max_iter : int
        Reweighting iterations at most.

    Notes
    -----
    Intervals: the covariance of the weighted fit's coefficients (θ = coefficient²) is the sandwich
    (AᵀWA)⁻¹AᵀWΣWA(AᵀWA)⁻¹, where Σ holds the estimates' variances 2σ⁴/ν and their correlation
    across τ (octave correlations per noise type, measured by simulation: see
    ``OCTAVE_CORRELATION``); it is inflated by √(χ²/dof) when the model fits worse than its
    noise, and intervals are θ ± z·SE, clipped at zero, then square-rooted. On 100 simulated
    records (1e6 samples; Q, N, B, K each dominating a τ range; ``benches/noise_fit.py``) 68.3 %
    intervals covered the truth in 61 % (Q), 69 % (N), 51 % (B) and 55 % (K) of runs — about
    right for N, somewhat narrow for Q and K, too narrow for B (see docs/noise-model.md).

    Examples
    --------
    >>> import numpy as np, allanite
    >>> y = allanite.simulate(1_000_000, 100.0, N=0.01, K=1e-4, seed=3)
    >>> f = allanite.fit(allanite.avar(y, 100.0), terms=("N", "K"), unit="deg/s")
    >>> round(f.coefficients["N"].value, 3), f.coefficients["N"].ieee_unit
    (0.01, '°/√h')
    """
    terms = _check_terms(terms)
    zq = _zq(confidence)
    tau_range = _check_tau_range(tau_range)
    if unit is not None:
        from .units import rate_unit

        rate_unit(unit)
    if isinstance(result, DynamicAllanResult):
        _check_fit_estimator(result)
        return _fit_dynamic(result, terms, unit, float(confidence), zq, thin, max_iter, tau_range)
    if not isinstance(result, AllanResult):
        raise ParameterError(f"fit needs an AllanResult or DynamicAllanResult, got {type(result).__name__}")
    _check_fit_estimator(result)
    if result.avar.ndim == 2:
        return [_fit_static_row(result, row, terms, unit, float(confidence), zq, thin, max_iter, tau_range)
                for row in result.avar]
    return _fit_static_row(result, result.avar, terms, unit, float(confidence), zq, thin, max_iter, tau_range)


#: Estimators whose values estimate the Allan variance (raw Theo1 does not: it is biased by a
#: noise-type-dependent factor, which TheoBR's kf removes).
FIT_ESTIMATORS = ("oavar", "avar", "theobr", "theoh", "theoh_a")


def _check_fit_estimator(result) -> None:
    if result.estimator == "theo1":
        raise ParameterError("fit needs Allan-variance estimates; raw Theo1 is biased against the Allan variance by "
                             "a noise-type-dependent factor: use estimator='theobr' or 'theoh'")
    if result.estimator not in FIT_ESTIMATORS:
        raise ParameterError(f"fit supports the estimators {FIT_ESTIMATORS}, not {result.estimator!r}")


def _est_key(result, idx):
    """The estimator argument of _fit_core: a name, or a tuple of per-τ sources for Theo-family results."""
    return result.estimator if result.source is None else tuple(np.asarray(result.source)[idx])


def _check_tau_range(tau_range):
    if tau_range is None:
        return (0.0, np.inf)
    try:
        lo, hi = tau_range
    except (TypeError, ValueError):
        raise ParameterError(f"tau_range must be a (low, high) pair of seconds, got {tau_range!r}") from None
    lo = 0.0 if lo is None else float(lo)
    hi = np.inf if hi is None else float(hi)
    if not (lo >= 0 and hi > lo) or np.isnan(lo) or np.isnan(hi):
        raise ParameterError(f"tau_range must satisfy 0 ≤ low < high, got {tau_range!r}")
    return (lo, hi)


def _select(tau, avar, thin, n_terms, what, tau_range=(0.0, np.inf)):
    if not np.all(np.isfinite(avar)):
        i = int(np.flatnonzero(~np.isfinite(avar))[0])
        raise ParameterError(f"{what} has a non-finite Allan variance ({avar[i]}) at τ = {tau[i]:g} s")
    inside = np.flatnonzero((tau >= tau_range[0]) & (tau <= tau_range[1]))
    if inside.size == 0:
        raise ParameterError(f"no τ of {what} lies in tau_range {tau_range} s (τ spans {tau[0]:g}–{tau[-1]:g} s)")
    idx = inside[_octave_thin(tau[inside])] if thin else inside
    idx = idx[avar[idx] > 0]
    if idx.size <= n_terms:
        raise ParameterError(
            f"{what} has {idx.size} usable τ{' (octave-spaced)' if thin else ''} for {n_terms} terms; "
            f"at least {n_terms + 1} are needed — use a wider τ grid, fewer terms, or thin=False"
        )
    return idx


def _fit_static_row(result, avar_row, terms, unit, confidence, zq, thin, max_iter, tau_range):
    from scipy.stats import chi2 as chi2_dist

    avar_row = np.asarray(avar_row, dtype=np.float64)
    idx = _select(result.tau, avar_row, thin, len(terms), "the result", tau_range)
    tau, m, y = result.tau[idx], result.m[idx].astype(np.float64), avar_row[idx]
    theta, cov, model, nu, z, it, a = _fit_core(
        tau, m, y, result.fs, result.n_samples + 1, _est_key(result, idx), terms, confidence, max_iter)
    n_active = int(np.count_nonzero(theta > 0))
    dof = max(1, tau.size - n_active)
    chi2 = float(np.sum(z**2))
    chi2_dof = chi2 / dof
    inflate = max(1.0, math.sqrt(chi2_dof))
    coeffs = _coefficients(terms, theta, cov, zq, inflate, unit)
    return NoiseFit(
        coefficients=coeffs, terms=terms, tau=tau, m=m, avar=y, edf=nu, model=model,
        components={t: a[:, k] * theta[k] for k, t in enumerate(terms)}, z=z, chi2=chi2, dof=dof,
        chi2_dof=chi2_dof, p_value=float(chi2_dist.sf(chi2, dof)),
        readoffs=_readoffs(result, np.sqrt(avar_row)), fs=result.fs, confidence=confidence, unit=unit,
        iterations=it, theta=theta, covariance=cov,
    )


def _fit_dynamic(result, terms, unit, confidence, zq, thin, max_iter, tau_range):
    rows = [result.avar] if result.avar.ndim == 2 else list(result.avar)
    series = []
    for rows_avar in rows:
        idx = _select(result.tau, rows_avar[:, 0], thin, len(terms), "the dynamic result", tau_range)
        tau, m = result.tau[idx], result.m[idx].astype(np.float64)
        cache = {}
        n_t = rows_avar.shape[1]
        vals = {t: np.empty(n_t) for t in terms}
        lo = {t: np.empty(n_t) for t in terms}
        hi = {t: np.empty(n_t) for t in terms}
        chi = np.empty(n_t)
        for j in range(n_t):
            y = rows_avar[idx, j]
            if not np.all(np.isfinite(y)):
                raise ParameterError(f"the dynamic result has a non-finite Allan variance in window {j}")
            if np.all(y == 0):
                for t in terms:
                    vals[t][j] = lo[t][j] = hi[t][j] = 0.0
                chi[j] = 0.0
                continue
            theta, cov, model, nu, z, it, a = _fit_core(
                tau, m, np.maximum(y, 1e-300), result.fs, result.window + 1, _est_key(result, idx), terms,
                confidence, max_iter, edf_cache=cache)
            dof = max(1, tau.size - int(np.count_nonzero(theta > 0)))
            chi[j] = float(np.sum(z**2)) / dof
            inflate = max(1.0, math.sqrt(chi[j]))
            for k, t in enumerate(terms):
                vals[t][j] = math.sqrt(theta[k])
                lo[t][j], hi[t][j] = _interval(theta[k], cov[k, k], zq, inflate)
        ieee = ieee_units = None
        if unit is not None:
            from .units import ieee952

            ieee = {t: ieee952(t, vals[t], unit).value for t in terms}
            ieee_units = {t: ieee952(t, 1.0, unit).unit for t in terms}
        series.append(CoefficientSeries(t=result.t, terms=terms, values=vals, ci_low=lo, ci_high=hi,
                                        chi2_dof=chi, confidence=confidence, unit=unit, ieee=ieee,
                                        ieee_units=ieee_units))
    return series[0] if result.avar.ndim == 2 else series
