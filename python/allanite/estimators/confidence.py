"""Confidence intervals for Allan variances: equivalent degrees of freedom, noise identification, χ².

An Allan-variance estimate σ̂² at one τ is, to a good approximation, σ² times a χ² variable with ν
*equivalent degrees of freedom* (EDF) divided by ν. ν depends on the estimator (overlapping or
classic), the record length, the averaging factor m and the dominant power-law noise type
α — the exponent of the rate (frequency) PSD, S_y(f) ∝ f^α:

=====  =========================  ===============================  =========================
α      clock name                 gyro term (IEEE 952)             Allan variance slope
=====  =========================  ===============================  =========================
 2     white phase (WPM)          quantization / white angle, Q    τ⁻²
 1     flicker phase (FPM)        flicker angle                    ≈ τ⁻²
 0     white frequency (WFM)      angle random walk, N             τ⁻¹
−1     flicker frequency (FFM)    bias instability, B              τ⁰
−2     random-walk freq. (RWFM)   rate random walk, K              τ⁺¹
=====  =========================  ===============================  =========================

The pieces, usable on their own (they live in :mod:`~allanite.estimators.edf` and
:mod:`~allanite.estimators.noise_id` and are re-exported here):

* :func:`edf_greenhall` — Greenhall & Riley's EDF algorithm ("Uncertainty of stability variances
  based on finite differences", PTTI 2003), the one Stable32 uses for ADEV and OADEV;
  :func:`edf_sp1065` — the older simple formulas of NIST SP 1065 Table 5 (overlapping ADEV).
* :func:`identify_alpha` — the dominant α per τ from the samples: the lag-1 autocorrelation method
  (Riley & Greenhall, EFTF 2004) with Stable32's fallback to the B1 ratio and R(n) when fewer than
  30 points remain at that τ, and — as Stable32 — no identification at all below 8 (OADEV) / 10
  (ADEV) points: there the nearest shorter τ's α (``docs/confidence.md``).
* :func:`chi2_interval` — the two-sided χ² interval for the true variance (SP 1065 eq. 45).

and the one most users want, :func:`confidence_intervals` (also reachable as
``result.with_confidence(x)`` on :class:`~allanite.AllanResult` and
:class:`~allanite.DynamicAllanResult`): identify α from the samples the result was computed from
(or take it as given), compute ν per τ and the interval per τ.

Conventions. N is the number of *phase (angle) points*: a record of M rate samples has N = M + 1.
Stable32 prints "Confidence Factor = 0.683" but uses the exact one-sigma probability
erf(1/√2) = 0.682689… (:data:`ONE_SIGMA`); pass ``confidence=ONE_SIGMA`` to reproduce its bounds.
For ν > 100 Stable32 also replaces the χ² quantile by an approximation (``chi2="stable32"``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._dist import chi2_ppf
from .._validate import as_rate_columns, check_choice, check_probability
from ..errors import ParameterError
from . import _registry
from .edf import ALPHAS, check_alpha, edf_greenhall, edf_sp1065, edf_theo1
from .noise_id import ACF_MIN_POINTS, ESTIMATORS, FALLBACKS, ID_MIN_POINTS, identify_alpha

__all__ = [
    "edf_theo1",
    "ONE_SIGMA",
    "ALPHAS",
    "NOISE_NAMES",
    "edf_greenhall",
    "edf_sp1065",
    "chi2_interval",
    "identify_alpha",
    "ACF_MIN_POINTS",
    "ID_MIN_POINTS",
    "confidence_intervals",
    "ConfidenceIntervals",
]

#: The probability of a normal variable falling within one standard deviation, erf(1/√2).
ONE_SIGMA = math.erf(1.0 / math.sqrt(2.0))

#: Short names of the noise types, clock and gyro vocabulary.
NOISE_NAMES = {
    2: "white phase / quantization (WPM)",
    1: "flicker phase (FPM)",
    0: "white frequency / angle random walk (WFM)",
    -1: "flicker frequency / bias instability (FFM)",
    -2: "random-walk frequency / rate random walk (RWFM)",
}

_EDF_METHODS = ("greenhall", "sp1065")
_CHI2_METHODS = ("exact", "stable32")


# --------------------------------------------------------------------------------------------
# χ² intervals


def _norm_ppf_stable32(p: np.ndarray) -> np.ndarray:
    """Abramowitz & Stegun 26.2.22 rational approximation of the normal quantile, with the
    coefficient 0.27601 where A&S print 0.27061 — as Stable32's source has it (A. Wallin, "Fun
    with chi-squared", 2020)."""
    q = np.minimum(p, 1.0 - p)
    t = np.sqrt(-2.0 * np.log(q))
    x = t - (2.30753 + 0.27601 * t) / (1.0 + 0.99229 * t + 0.04481 * t * t)
    return np.where(p < 0.5, -x, np.where(p == 0.5, 0.0, x))


def _chi2_ppf(p: float, nu: np.ndarray, method: str) -> np.ndarray:
    exact = chi2_ppf(p, nu)
    if method == "exact":
        return exact
    # Stable32: Wilson–Hilferty (A&S 26.4.17) for ν > 100, an iterative inverse below (converged to
    # ~1e-4 in probability; the exact quantile stands in for it).
    z = _norm_ppf_stable32(np.asarray(p, dtype=np.float64))
    with np.errstate(divide="ignore", invalid="ignore"):
        wh = nu * (1.0 - 2.0 / (9.0 * nu) + z * np.sqrt(2.0 / (9.0 * nu))) ** 3
    return np.where(nu > 100, wh, exact)


def chi2_interval(variance, edf, confidence=0.683, *, method="exact"):
    """Two-sided χ² confidence interval for a true variance (NIST SP 1065 eq. 45).

    ``[ν·σ̂²/χ²(1 − p/2, ν),  ν·σ̂²/χ²(p/2, ν)]`` with p = 1 − confidence: equal tail probabilities
    p/2 on either side. Take square roots for the deviation.

    Parameters
    ----------
    variance : float or array_like
        Estimated variance(s) σ̂² (≥ 0).
    edf : float or array_like
        Equivalent degrees of freedom ν (> 0), broadcast against ``variance``.
    confidence : float
        Probability that the interval covers the true variance, in (0, 1). Default 0.683;
        :data:`ONE_SIGMA` (0.682689…) is what Stable32 uses behind its printed "0.683".
    method : {"exact", "stable32"}
        ``"exact"``: SciPy's χ² quantiles. ``"stable32"``: Stable32's approximation for ν > 100
        (Wilson–Hilferty with its variant of the A&S normal quantile), which reproduces its printed
        bounds to the last digit; below ν = 100 the exact quantiles (Stable32 iterates there to
        ~1e-4, so its bounds differ from exact ones by up to ~3e-4 relative).

    Returns
    -------
    (low, high) : floats or ndarrays
        Bounds on the true variance.

    Raises
    ------
    ParameterError
        confidence not in (0, 1), an edf ≤ 0 or non-finite, a negative variance, or an unknown method.

    Examples
    --------
    >>> from allanite.estimators.confidence import chi2_interval
    >>> lo, hi = chi2_interval(1.0, 10.0, 0.9)
    >>> round(lo, 4), round(hi, 4)
    (0.5462, 2.5379)
    """
    c = check_probability(confidence)
    check_choice(method, "method", _CHI2_METHODS)
    var = np.asarray(variance, dtype=np.float64)
    nu = np.asarray(edf, dtype=np.float64)
    if nu.size == 0 or np.any(~np.isfinite(nu)) or np.any(nu <= 0):
        bad = nu[~(np.isfinite(nu) & (nu > 0))].ravel() if nu.size else nu
        raise ParameterError(f"edf must be positive finite degrees of freedom, got {bad[0] if bad.size else edf!r}")
    if np.any(var < 0):
        raise ParameterError(f"variance must be ≥ 0, got {var[var < 0].ravel()[0]!r}")
    var, nu = np.broadcast_arrays(var, nu)
    p = (1.0 - c) / 2.0
    low = nu * var / _chi2_ppf(1.0 - p, nu, method)
    high = nu * var / _chi2_ppf(p, nu, method)
    if low.ndim == 0:
        return float(low), float(high)
    return low, high


# --------------------------------------------------------------------------------------------
# intervals for results


@dataclass(frozen=True, repr=False, eq=False)
class ConfidenceIntervals:
    """Confidence intervals of an Allan-variance result (see :func:`confidence_intervals`).

    Attributes
    ----------
    edf : ndarray, (T,) or (axes, T)
        Equivalent degrees of freedom per τ (and axis).
    ci_low, ci_high : ndarray, shape of the result's ``avar``
        Bounds on the true Allan variance (rate unit squared).
    alpha : ndarray of int, shape of ``edf``
        Noise type used at each τ (identified or given).
    confidence : float
        Coverage probability of the intervals.
    edf_method, chi2 : str
        How ν and the χ² quantiles were computed.
    """

    edf: np.ndarray
    ci_low: np.ndarray
    ci_high: np.ndarray
    alpha: np.ndarray
    confidence: float
    edf_method: str = "greenhall"
    chi2: str = "exact"

    @property
    def adev_low(self) -> np.ndarray:
        """Lower bound on the Allan deviation, √ci_low."""
        return np.sqrt(self.ci_low)

    @property
    def adev_high(self) -> np.ndarray:
        """Upper bound on the Allan deviation, √ci_high."""
        return np.sqrt(self.ci_high)

    def __repr__(self) -> str:
        return (
            f"ConfidenceIntervals({self.confidence:.1%}, ν by {self.edf_method}, {self.edf.shape[-1]} τ, "
            f"ν from {np.min(self.edf):.3g} to {np.max(self.edf):.3g})"
        )


def _alpha_for_result(result, x, alpha, shape_edf, b1_n, fallback) -> np.ndarray:
    if alpha is not None:
        a = check_alpha(alpha)
        try:
            return np.broadcast_to(a, shape_edf).copy()
        except ValueError:
            raise ParameterError(
                f"alpha has shape {a.shape}; it must be one integer, one per τ ({shape_edf[-1]},) "
                f"or one per axis and τ {shape_edf}"
            ) from None
    if x is None:
        raise ParameterError(
            "the noise type is needed for the intervals: pass the samples the result was computed from "
            "(x, with the same input kind) to identify it per τ, or give alpha (2 WPM … −2 RWFM)"
        )
    cols, _, is_multi = as_rate_columns(x, result.fs, result.input)
    n_axes = result.n_axes
    if (n_axes is None) == is_multi or (n_axes is not None and len(cols) != n_axes):
        raise ParameterError(
            f"x has {len(cols) if is_multi else 'no'} axes but the result has {n_axes or 'none'}: "
            f"pass the samples the result was computed from"
        )
    if cols[0].size != result.n_samples:
        raise ParameterError(
            f"x has {cols[0].size} samples (after input={result.input!r} conversion) but the result was "
            f"computed from {result.n_samples}: pass the same samples"
        )
    kind = "angle" if result.input == "angle" else "rate"
    out = np.empty(shape_edf, dtype=np.int64)
    for a_i, y in enumerate(cols):
        data = np.concatenate(([0.0], np.cumsum(y))) if kind == "angle" else y
        est = _registry.get(result.estimator).noise_id
        ids = identify_alpha(data, _allan_m_for_id(result), input=kind, estimator=est, b1_n=b1_n, fallback=fallback)
        if is_multi:
            out[a_i] = ids
        else:
            out[...] = ids
    return out


def edf_of(estimator, alpha, m, n_phase) -> np.ndarray:
    """ν per τ from the registry's EDF model of each τ's estimator: ``estimator`` is one name, or an
    array naming the estimator of every τ (hybrid results such as TheoH: Greenhall's EDF at Allan τ,
    Howe's Theo1 EDF at Theo τ)."""
    alpha = np.asarray(alpha)
    m = np.broadcast_to(np.asarray(m), alpha.shape)
    source = np.broadcast_to(np.asarray(estimator), alpha.shape)
    nu = np.empty(alpha.shape, dtype=np.float64)
    for name in np.unique(source):
        entry = _registry.get(str(name))
        if entry.edf is None:
            raise ParameterError(f"estimator {str(name)!r} has no model of its equivalent degrees of freedom")
        sel = source == name
        nu[sel] = entry.edf(alpha[sel], m[sel], n_phase)
    return nu


#: (span in m, offset): a record of N phase points has N − span·m + offset terms of these estimators.
_GAP_SPAN = {
    "oavar": (2, 0),
    "mvar": (3, 1),
    "tvar": (3, 1),
    "ohvar": (3, 0),
    "totvar": (0, -2),
    "mtotvar": (3, 1),
    "ttotvar": (3, 1),
    "htotvar": (3, 0),
}
#: Classic estimators: a record of (n + k)·m rate samples has n terms (clusters − 1 for AVAR, − 2 for HVAR).
_GAP_CLUSTERS = {"avar": 1, "hvar": 2}


def _edf_from_terms(result, a, m_b, shape_edf) -> np.ndarray:
    """Greenhall's EDF with the record length that gives each τ's *actual* term count ``result.n``:
    the same as the record's own length without gaps; with ``gaps="skip"`` the complete terms only
    (a τ without one: NaN)."""
    n_terms = np.broadcast_to(np.asarray(result.n), shape_edf)
    if result.estimator in _GAP_CLUSTERS:
        n_eff = (n_terms + _GAP_CLUSTERS[result.estimator]) * m_b + 1
    else:
        span, offset = _GAP_SPAN[result.estimator]
        n_eff = n_terms + span * m_b - offset
    nu = np.full(shape_edf, np.nan)
    for n_phase in np.unique(n_eff[n_terms > 0]):
        sel = (n_eff == n_phase) & (n_terms > 0)
        nu[sel] = edf_of(result.estimator, a[sel], m_b[sel], int(n_phase))
    return nu


def _window_length(result) -> int:
    """Samples behind every estimate: the window of a dynamic result, the record of a static one."""
    return int(result.window) if _is_dynamic(result) else int(result.n_samples)


def _is_dynamic(result) -> bool:
    return getattr(result, "window", None) is not None and getattr(result, "t", None) is not None


def _allan_m_for_id(result) -> np.ndarray:
    """Averaging factors at which to identify the noise type. Theo τ = 0.75·m·τ0 is identified at the
    Allan factor nearest that τ — but Theo reaches τ where fewer than 30 intervals fit, where the
    identification is a guess (and a wrong "white phase" call would claim thousands of degrees of
    freedom); there the longest τ with ≥ 30 intervals (lag-1 ACF, reliable) stands in."""
    if result.source is None:
        return np.asarray(result.m)
    n = _window_length(result)
    theo = np.isin(result.source, [e for e in np.unique(result.source) if _registry.get(str(e)).theo_tau])
    reliable = max(1, n // ACF_MIN_POINTS)
    m_id = np.where(theo, np.minimum(np.floor(0.75 * result.m + 0.5), reliable), result.m).astype(np.int64)
    return np.clip(m_id, 1, max(1, n // 2))


def _check_edf_method(result, edf_method: str) -> None:
    """A ParameterError unless the result's estimator has an EDF model and ``edf_method`` has formulas for it."""
    if result.source is None and _registry.get(result.estimator).edf is None:
        with_edf = [n for n in _registry.names() if _registry.get(n).edf is not None]
        raise ParameterError(
            f"confidence intervals are implemented for {', '.join(map(repr, with_edf))}, not {result.estimator!r}"
        )
    if result.source is not None and edf_method != "greenhall":
        raise ParameterError(
            "Theo-family results use Greenhall's EDF (Allan τ) and Howe's Theo1 EDF (Theo τ); "
            f"edf_method={edf_method!r} is for plain Allan results"
        )
    if edf_method == "sp1065" and result.estimator not in ESTIMATORS:
        raise ParameterError(f"edf_method='sp1065' has formulas for {ESTIMATORS}, not {result.estimator!r}")


def _edf_per_tau(result, a, m_b, n_phase, shape_edf, edf_method, dynamic, per_window) -> np.ndarray:
    """ν of the result's estimates for noise types ``a``: per τ (and axis), or per window for a
    ``davar(gaps="skip")`` result, whose windows hold their own counts of complete terms."""
    if per_window and edf_method == "sp1065":
        raise ParameterError(
            "results of davar(gaps='skip') use Greenhall's EDF per window; edf_method='sp1065' has none"
        )
    if edf_method == "sp1065":
        nu = edf_sp1065(a, m_b, n_phase, estimator=result.estimator)
    elif per_window:
        # davar(gaps="skip"): every window's own count of complete terms → one EDF per window
        full = np.shape(result.avar)
        nu = _edf_from_terms(result, np.broadcast_to(a[..., None], full), np.broadcast_to(m_b[..., None], full), full)
        shape_edf = full
    elif not dynamic and result.source is None and (result.estimator in _GAP_SPAN or result.estimator in _GAP_CLUSTERS):
        nu = _edf_from_terms(result, a, m_b, shape_edf)
    else:
        nu = edf_of(result.estimator if result.source is None else result.source, a, m_b, n_phase)
    return np.asarray(nu, dtype=np.float64).reshape(shape_edf)


def _chi2_bounds(avar, nu_b, c, chi2):
    """(low, high) of every variance; NaN where a τ has no EDF (gaps="skip": no complete term)."""
    if np.all(np.isfinite(nu_b)):
        return chi2_interval(avar, nu_b, c, method=chi2)
    ok = np.isfinite(nu_b) & np.isfinite(avar)
    low, high = np.full(avar.shape, np.nan), np.full(avar.shape, np.nan)
    if ok.any():
        low[ok], high[ok] = chi2_interval(avar[ok], nu_b[ok], c, method=chi2)
    return low, high


def confidence_intervals(
    result,
    x=None,
    *,
    confidence=0.683,
    alpha=None,
    edf_method="greenhall",
    chi2="exact",
    b1_n="terms",
    fallback="prudent",
) -> ConfidenceIntervals:
    """χ² confidence intervals of a static or dynamic Allan-variance result, per τ.

    ν per τ comes from :func:`edf_greenhall` (or :func:`edf_sp1065`) for the result's estimator
    and record length — N = n_samples + 1 phase points for :class:`~allanite.AllanResult`, N =
    window + 1 for :class:`~allanite.DynamicAllanResult`, whose windows all share one ν per τ —
    and the noise type α per τ, which is identified from ``x`` by :func:`identify_alpha` unless
    given. The interval is :func:`chi2_interval` applied to every variance.

    Parameters
    ----------
    result : AllanResult or DynamicAllanResult
        Output of :func:`allanite.avar` / :func:`allanite.davar` (``"oavar"`` or ``"avar"``).
    x : array_like, optional
        The samples the result was computed from, exactly as passed (same ``input`` kind, same
        axes). Needed unless ``alpha`` is given. For a dynamic result α is identified once from the
        whole record and applied to every window.
    confidence : float
        Coverage probability in (0, 1); default 0.683 (:data:`ONE_SIGMA` for Stable32's exact
        one-sigma value).
    alpha : int or array_like of int, optional
        Noise type(s) to use instead of identifying them: one for all τ, one per τ, or one per
        axis and τ. 2 WPM (quantization), 1 FPM, 0 WFM (angle random walk), −1 FFM (bias
        instability), −2 RWFM (rate random walk).
    edf_method : {"greenhall", "sp1065"}
        EDF algorithm (SP 1065 formulas exist for ``"oavar"`` only).
    chi2 : {"exact", "stable32"}
        χ² quantiles, see :func:`chi2_interval`.
    b1_n : {"terms", "averages"}
        Convention of the B1 branch of the noise identification, see :func:`identify_alpha`
        (the default ``"terms"`` with ``chi2="stable32"``, ``confidence=ONE_SIGMA`` for Stable32's
        numbers; ``"averages"`` to tell rate random walk from bias instability at long τ).
    fallback : {"prudent", "previous", "none", "conservative"}
        Where too few samples remain to identify the noise type (fewer than 8 τ-intervals for
        ``"oavar"``, 10 for ``"avar"``), α is the nearest shorter τ's (``"previous"``, Stable32's
        rule, see :func:`identify_alpha`), so the last points get the wide interval their few terms
        warrant instead of one from a guessed "white/flicker phase" type. ``"prudent"`` (default)
        also keeps a rise of α above both neighbours (a larger ν) on an octave grid only where it
        was read on ≥ 30 τ-intervals; ``"conservative"`` also a rise that lasts to the longest τ
        only where its first τ holds ≥ 60 (the honest interval where few points read a chance rise;
        not Stable32's, see :func:`identify_alpha`); ``"none"`` identifies every τ on its own samples.

    Returns
    -------
    ConfidenceIntervals
        ``edf`` and ``alpha`` of shape (T,) or (axes, T) — ``edf`` of the shape of ``result.avar`` for a
        ``davar(..., gaps="skip")`` result, whose windows hold different numbers of complete terms;
        ``ci_low``/``ci_high`` of the shape of ``result.avar``; ``adev_low``/``adev_high`` for deviations.

    Examples
    --------
    >>> import numpy as np, allanite
    >>> y = np.random.default_rng(3).normal(size=10_000)          # white rate noise
    >>> r = allanite.avar(y, fs=1.0, taus=[1, 10, 100])
    >>> ci = allanite.confidence_intervals(r, y)
    >>> ci.alpha                                                  # identified: white rate (ARW)
    array([0, 0, 0])
    >>> np.round(ci.edf, 1)
    array([7825.5, 1368. ,  147.8])
    >>> bool(np.all((ci.ci_low < r.avar) & (r.avar < ci.ci_high)))
    True
    >>> d = allanite.davar(y, 1.0, window=2_000, hop=1_000, taus=[1, 10])
    >>> dci = allanite.confidence_intervals(d, alpha=0)           # noise type given
    >>> dci.ci_low.shape == d.avar.shape, np.round(dci.edf, 1)
    (True, array([1564.6,  272.1]))
    """
    if not all(hasattr(result, a) for a in ("tau", "avar", "m", "estimator", "fs", "n_samples", "input", "source")):
        raise ParameterError(f"result must be an AllanResult or DynamicAllanResult, got {type(result).__name__}")
    c = check_probability(confidence)
    check_choice(edf_method, "edf_method", _EDF_METHODS)
    check_choice(chi2, "chi2", _CHI2_METHODS)
    _check_edf_method(result, edf_method)
    dynamic = _is_dynamic(result)
    n_axes = result.n_axes
    shape_edf = (result.m.size,) if n_axes is None else (n_axes, result.m.size)
    check_choice(b1_n, "b1_n", ("averages", "terms"))
    check_choice(fallback, "fallback", FALLBACKS)
    a = _alpha_for_result(result, x, alpha, shape_edf, b1_n, fallback)
    n_phase = _window_length(result) + 1
    m_b = np.broadcast_to(result.m, shape_edf)
    per_window = dynamic and np.ndim(result.n) >= 2
    nu = _edf_per_tau(result, a, m_b, n_phase, shape_edf, edf_method, dynamic, per_window)
    taper = _registry.TAPERS[getattr(result, "taper", "rect")]
    if taper.edf_factor is None:
        raise ParameterError(f"taper {taper.name!r} has no model of its equivalent degrees of freedom")
    if taper.name != "rect":
        # the tapered estimate keeps the share (Σw)²/(M·Σw²) of the rectangular window's ν
        nu = nu * taper.edf_factor(m_b, n_phase - 1)
    nu_b = nu[..., None] if dynamic and not per_window else nu
    low, high = _chi2_bounds(result.avar, nu_b, c, chi2)
    return ConfidenceIntervals(
        edf=nu,
        ci_low=np.asarray(low),
        ci_high=np.asarray(high),
        alpha=a,
        confidence=c,
        edf_method=edf_method,
        chi2=chi2,
    )
