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

The pieces, usable on their own:

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

import functools
import math
from dataclasses import dataclass

import numpy as np

from .._dist import chi2_ppf
from .._validate import as_rate_columns, check_choice, check_count, check_probability
from ..errors import ParameterError
from . import _registry
from ._long_id import LONG_SAMPLES, LongRate

__all__ = [
    "edf_theo1",
    "ONE_SIGMA",
    "ALPHAS",
    "NOISE_NAMES",
    "edf_greenhall",
    "edf_sp1065",
    "chi2_interval",
    "identify_alpha",
    "confidence_intervals",
    "ConfidenceIntervals",
]

#: The probability of a normal variable falling within one standard deviation, erf(1/√2).
ONE_SIGMA = math.erf(1.0 / math.sqrt(2.0))

#: Noise types of the Allan family (α of S_y(f) ∝ f^α) that the Allan variance can distinguish.
ALPHAS = (2, 1, 0, -1, -2)

#: Short names of the noise types, clock and gyro vocabulary.
NOISE_NAMES = {
    2: "white phase / quantization (WPM)",
    1: "flicker phase (FPM)",
    0: "white frequency / angle random walk (WFM)",
    -1: "flicker frequency / bias instability (FFM)",
    -2: "random-walk frequency / rate random walk (RWFM)",
}

#: Stable32 switches from the lag-1 ACF to the B1 ratio below this many points at a given τ.
ACF_MIN_POINTS = 30

#: Fewest τ-intervals (⌊samples/m⌋) at which Stable32 identifies the noise type from that τ's own
#: samples, per estimator; at longer τ it prints the α of the previous τ. Read off its tables (all 34
#: ADEV/OADEV tables of the shared data: docs/confidence.md): OADEV identifies at 8 intervals and
#: carries over at 7, ADEV identifies at 10 and carries over at 9.
ID_MIN_POINTS = {"oavar": 8, "avar": 10}

_FALLBACKS = ("prudent", "previous", "none")

_EDF_METHODS = ("greenhall", "sp1065")
_CHI2_METHODS = ("exact", "stable32")
_INPUTS = ("angle", "rate", "increment")
_ESTIMATORS = ("oavar", "avar")


# --------------------------------------------------------------------------------------------
# argument checks


def _check_alpha(alpha, allowed=ALPHAS, what="alpha") -> np.ndarray:
    a = np.asarray(alpha)
    if a.dtype.kind not in "iuf" or a.size == 0:
        raise ParameterError(f"{what} must be integer noise exponents in {sorted(allowed)}, got {alpha!r}")
    af = a.astype(np.float64)
    bad = ~np.isin(af, np.asarray(allowed, dtype=np.float64))
    if bad.any():
        raise ParameterError(
            f"{what} must be integers in {sorted(allowed)} (2 WPM, 1 FPM, 0 WFM, −1 FFM, −2 RWFM), "
            f"got {af[bad].ravel()[0]!r}"
        )
    return af.astype(np.int64)


# --------------------------------------------------------------------------------------------
# Greenhall's EDF algorithm
#
# The phase is modelled as the first difference of a continuous-time pure power-law process w(t);
# sw is its generalized autocovariance (Greenhall & Riley eq. 7), sx the one of the phase seen
# through the estimator's averaging filter (eq. 8), sz the one of the d-th difference (eq. 9).
# Constant factors of sw cancel in every ratio below, only the sign pattern in α matters.


def _sw(t: np.ndarray, alpha: int) -> np.ndarray:
    """|t|^(3−α) for even α, |t|^(3−α)·ln|t| for odd α (0 at t = 0), with eq. 7's alternating signs."""
    t = np.abs(np.asarray(t, dtype=np.float64))
    p = 3 - alpha
    sign = {2: -1.0, 1: 1.0, 0: 1.0, -1: -1.0, -2: -1.0, -3: 1.0, -4: 1.0}[alpha]
    if alpha % 2 == 0:
        return sign * t**p
    with np.errstate(divide="ignore", invalid="ignore"):
        out = sign * t**p * np.log(t)
    return np.where(t == 0.0, 0.0, out)


def _sx(t, F: float, alpha: int) -> np.ndarray:
    if math.isinf(F):  # the F → ∞ limit: a pure sample of w with exponent α + 2
        return _sw(t, alpha + 2)
    t = np.asarray(t, dtype=np.float64)
    return F * F * (2.0 * _sw(t, alpha) - _sw(t - 1.0 / F, alpha) - _sw(t + 1.0 / F, alpha))


def _sz(t, F: float, alpha: int, d: int) -> np.ndarray:
    t = np.asarray(t, dtype=np.float64)
    out = np.zeros_like(t)
    for k in range(-d, d + 1):
        out = out + (-1) ** k * math.comb(2 * d, d + k) * _sx(t + k, F, alpha)
    return out


def _basic_sum(J: int, M: float, S: float, F: float, alpha: int, d: int) -> float:
    """Greenhall & Riley eq. 10."""
    j = np.arange(1, int(J), dtype=np.float64)
    total = float(_sz(0.0, F, alpha, d)) ** 2
    total += (1.0 - J / M) * float(_sz(J / S, F, alpha, d)) ** 2
    total += 2.0 * float(np.sum((1.0 - j / M) * _sz(j / S, F, alpha, d) ** 2))
    return total


# Tables 1–3 of Greenhall & Riley (2003): 1/ν ≈ (a0 − a1/r)/r for long records.
# Keys: alpha → {d: (a0, a1)}.
_TABLE1 = {  # modified variances (F = 1)
    2: {1: (2 / 3, 1 / 3), 2: (7 / 9, 1 / 2), 3: (22 / 25, 2 / 3)},
    1: {1: (0.840, 0.345), 2: (0.997, 0.616), 3: (1.141, 0.843)},
    0: {1: (1.079, 0.368), 2: (1.033, 0.607), 3: (1.184, 0.848)},
    -1: {2: (1.048, 0.534), 3: (1.180, 0.816)},
    -2: {2: (1.302, 0.535), 3: (1.175, 0.777)},
    -3: {3: (1.194, 0.703)},
    -4: {3: (1.489, 0.702)},
}
_TABLE2 = {  # unmodified variances (F = m)
    2: {1: (3 / 2, 1 / 2), 2: (35 / 18, 1.0), 3: (231 / 100, 3 / 2)},
    1: {1: (78.6, 25.2), 2: (790.0, 410.0), 3: (9950.0, 6520.0)},
    0: {1: (2 / 3, 1 / 6), 2: (2 / 3, 1 / 3), 3: (7 / 9, 1 / 2)},
    -1: {2: (0.852, 0.375), 3: (0.997, 0.617)},
    -2: {2: (1.079, 0.368), 3: (1.033, 0.607)},
    -3: {3: (1.053, 0.553)},
    -4: {3: (1.302, 0.535)},
}
_TABLE3 = {1: (6.0, 4.0), 2: (15.23, 12.0), 3: (47.8, 40.0)}  # α = 1: (b0, b1)
_J_MAX = 100


@functools.lru_cache(maxsize=4096)  # the fits ask for the same (α, m, N) once per candidate model
def _edf_greenhall_one(alpha: int, d: int, m: int, N: int, overlapping: bool, modified: bool) -> float:
    F = 1 if modified else m  # filter factor
    S = m if overlapping else 1  # stride factor
    L = (m // F) + m * d  # span of the estimator's filter, in phase samples
    if N < L:
        raise ParameterError(
            f"N = {N} phase points is too short for m = {m} with d = {d} "
            f"({'modified' if modified else 'unmodified'} estimator): at least {L} are needed"
        )
    M = 1 + math.floor(S * (N - L) / m)  # number of summands
    J = min(M, (d + 1) * S)
    r = M / S

    if F == 1:  # case 1: modified variances, and unmodified ones at m = 1
        if J <= _J_MAX:
            inv = _basic_sum(J, M, S, 1, alpha, d) / (M * float(_sz(0.0, 1, alpha, d)) ** 2)
        elif r >= d + 1:
            a0, a1 = _TABLE1[alpha][d]
            inv = (a0 - a1 / r) / r
        else:
            mp = _J_MAX / r
            inv = _basic_sum(_J_MAX, _J_MAX, mp, 1, alpha, d) / (_J_MAX * float(_sz(0.0, 1, alpha, d)) ** 2)
    elif alpha <= 0:  # case 2: unmodified, WFM and redder
        if J <= _J_MAX:
            mp = m if m * (d + 1) <= _J_MAX else math.inf
            inv = _basic_sum(J, M, S, mp, alpha, d) / (M * float(_sz(0.0, mp, alpha, d)) ** 2)
        elif r >= d + 1:
            a0, a1 = _TABLE2[alpha][d]
            inv = (a0 - a1 / r) / r
        else:
            mp = _J_MAX / r
            inv = _basic_sum(_J_MAX, _J_MAX, mp, math.inf, alpha, d) / (
                _J_MAX * float(_sz(0.0, math.inf, alpha, d)) ** 2
            )
    elif alpha == 1:  # case 3: unmodified, FPM
        b0, b1 = _TABLE3[d]
        if J <= _J_MAX:
            inv = _basic_sum(J, M, S, m, 1, d) / (M * float(_sz(0.0, m, 1, d)) ** 2)
        elif r >= d + 1:
            a0, a1 = _TABLE2[1][d]
            inv = (a0 - a1 / r) / (r * (b0 + b1 * math.log(m)) ** 2)
        else:
            mp = _J_MAX / r
            inv = _basic_sum(_J_MAX, _J_MAX, mp, mp, 1, d) / (_J_MAX * (b0 + b1 * math.log(m)) ** 2)
    else:  # case 4: unmodified, WPM
        K = math.ceil(r)
        c = math.comb(2 * d, d)
        if K <= d:
            s = sum((1.0 - k / r) * math.comb(2 * d, d - k) ** 2 for k in range(1, K))
            inv = (1.0 + 2.0 * s / c**2) / M
        else:
            a0, a1 = math.comb(4 * d, 2 * d) / c**2, d / 2.0
            inv = (a0 - a1 / r) / M
    return 1.0 / inv


def edf_greenhall(alpha, d, m, N, overlapping=True, modified=False):
    """Equivalent χ² degrees of freedom of a finite-difference stability variance (Greenhall & Riley).

    The "combined EDF" algorithm of C. Greenhall and W. Riley, *Uncertainty of stability variances
    based on finite differences*, Proc. 35th PTTI (2003): exact sums of the estimator's
    autocovariance for short filters, the paper's fitted tables (1–3) for long records. Stable32
    uses it for ADEV, OADEV, MDEV, TDEV, HDEV and OHDEV.

    Parameters
    ----------
    alpha : int or array_like of int
        Noise type, the exponent of the rate PSD S_y(f) ∝ f^α: 2 WPM, 1 FPM, 0 WFM, −1 FFM, −2 RWFM
        (−3 and −4 only with d = 3). Must satisfy α + 2d > 1.
    d : {1, 2, 3}
        Order of the phase difference: 2 for the Allan family, 3 for the Hadamard family.
    m : int or array_like of int
        Averaging factor, τ = m·τ0.
    N : int or array_like of int
        Number of phase (angle) points, M + 1 for M rate samples.
    overlapping : bool
        True for the overlapping estimator (stride τ0, ``"oavar"``), False for the classic one
        (stride τ, ``"avar"``).
    modified : bool
        True for the modified Allan (MVAR/TVAR) family.

    Returns
    -------
    float or ndarray
        ν, broadcast over ``alpha``, ``m`` and ``N``.

    Raises
    ------
    ParameterError
        α outside what the d-th difference can handle, d not in {1, 2, 3}, m < 1, or N too short.

    Examples
    --------
    The values of docs/FORMULAS.md §7.2 (overlapping ADEV of 1001 phase points):

    >>> from allanite.estimators.confidence import edf_greenhall
    >>> [round(float(edf_greenhall(a, 2, 1, 1001)), 1) for a in (2, 0, -2)]
    [514.0, 782.0, 762.3]
    >>> [round(float(edf_greenhall(a, 2, 100, 1001)), 2) for a in (2, 0, -2)]
    [440.21, 12.81, 7.75]
    """
    d = check_count(d, "d", 1)
    if d > 3:
        raise ParameterError(f"d must be 1 (first difference), 2 (Allan) or 3 (Hadamard), got {d!r}")
    allowed = tuple(a for a in range(2, -5, -1) if a + 2 * d > 1)
    a_arr = _check_alpha(alpha, allowed)
    m_arr = np.asarray(m)
    n_arr = np.asarray(N)
    for name, arr, lo in (("m", m_arr, 1), ("N", n_arr, 2)):
        if (
            arr.dtype.kind not in "iuf"
            or arr.size == 0
            or not np.all(np.isfinite(arr))
            or np.any(arr < lo)
            or np.any(np.asarray(arr, dtype=np.float64) % 1 != 0)
        ):
            raise ParameterError(f"{name} must be integers ≥ {lo}, got {arr if arr.ndim else arr.item()!r}")
    a_b, m_b, n_b = np.broadcast_arrays(a_arr, m_arr.astype(np.int64), n_arr.astype(np.int64))
    out = np.empty(a_b.shape, dtype=np.float64)
    cache: dict = {}
    for idx in np.ndindex(a_b.shape):
        key = (int(a_b[idx]), int(m_b[idx]), int(n_b[idx]))
        if key not in cache:
            cache[key] = _edf_greenhall_one(key[0], d, key[1], key[2], bool(overlapping), bool(modified))
        out[idx] = cache[key]
    return float(out) if out.ndim == 0 else out


def edf_sp1065(alpha, m, N, estimator="oavar"):
    """EDF of the overlapping Allan variance by the simple formulas of NIST SP 1065, Table 5.

    The approximations of Howe, Allan & Barnes (1981), as tabulated in W. Riley, *Handbook of
    Frequency Stability Analysis* (NIST SP 1065, 2008), for comparison with :func:`edf_greenhall`
    (which Stable32 uses, and which this package uses by default). They are within ~25 % of
    Greenhall's values for the Allan family but not interchangeable with them.

    Parameters
    ----------
    alpha : int or array_like of int
        Noise type, 2 (WPM) … −2 (RWFM).
    m : int or array_like of int
        Averaging factor.
    N : int or array_like of int
        Number of phase points.
    estimator : {"oavar"}
        The formulas exist for the overlapping estimator only; use :func:`edf_greenhall` with
        ``overlapping=False`` for the classic one.

    Returns
    -------
    float or ndarray

    Examples
    --------
    >>> from allanite.estimators.confidence import edf_sp1065
    >>> round(float(edf_sp1065(0, 100, 1001)), 2)     # Greenhall: 12.81
    13.0
    """
    if estimator != "oavar":
        if estimator == "avar":
            raise ParameterError(
                "SP 1065 Table 5 gives EDF formulas for the overlapping estimator only (estimator='oavar'); "
                "for the classic estimator use edf_greenhall(alpha, 2, m, N, overlapping=False)"
            )
        raise ParameterError(f"unknown estimator {estimator!r}; allowed: 'oavar'")
    a = _check_alpha(alpha)
    m_arr = np.asarray(m, dtype=np.float64)
    n_arr = np.asarray(N, dtype=np.float64)
    if np.any(~np.isfinite(m_arr)) or np.any(m_arr < 1) or np.any(~np.isfinite(n_arr)) or np.any(n_arr < 2 * m_arr + 1):
        raise ParameterError(f"need m ≥ 1 and N ≥ 2m + 1 phase points, got m={m!r}, N={N!r}")
    a, m_f, n_f = np.broadcast_arrays(a, m_arr, n_arr)
    out = np.empty(a.shape)
    with np.errstate(divide="ignore", invalid="ignore"):
        wpm = (n_f + 1) * (n_f - 2 * m_f) / (2 * (n_f - m_f))
        fpm = np.exp(np.sqrt(np.log((n_f - 1) / (2 * m_f)) * np.log((2 * m_f + 1) * (n_f - 1) / 4)))
        wfm = (3 * (n_f - 1) / (2 * m_f) - 2 * (n_f - 2) / n_f) * 4 * m_f**2 / (4 * m_f**2 + 5)
        ffm = np.where(m_f == 1, 2 * (n_f - 2) ** 2 / (2.3 * n_f - 4.9), 5 * n_f**2 / (4 * m_f * (n_f + 3 * m_f)))
        rwfm = (n_f - 2) / (m_f * (n_f - 3) ** 2) * ((n_f - 1) ** 2 - 3 * m_f * (n_f - 1) + 4 * m_f**2)
    for val, arr in ((2, wpm), (1, fpm), (0, wfm), (-1, ffm), (-2, rwfm)):
        sel = a == val
        out[sel] = arr[sel]
    return float(out) if out.ndim == 0 else out


# --------------------------------------------------------------------------------------------
# χ² intervals


def edf_theo1(alpha, m, N):
    """Equivalent degrees of freedom of Theo1 (and TheoBR) at even averaging factor ``m``.

    Howe & Peppler's empirical fits (NIST SP 1065 §5.5.7 / Table 11; Riley's *Handbook* CI notes),
    with r = 0.75·m (τ/τ0) and N phase points::

        α =  2 (WPM):  [0.86 (N+1)(N − 4r/3) / (N − r)] · [r / (r + 1.14)]
        α =  1 (FPM):  [(4.798 N² − 6.374 N r + 12.387 r) / (√(r + 36.6) (N − r))] · [r / (r + 0.3)]
        α =  0 (WFM):  [(4.1 N + 0.8)/r − (3.1 N + 6.5)/N] · [r^1.5 / (r^1.5 + 5.2)]
        α = −1 (FFM):  [(2 N² − 1.3 N r − 3.5 r) / (N r)] · [r³ / (r³ + 2.3)]
        α = −2 (RWFM): [(4.4 N − 2) / (2.9 r)] · [((4.4 N − 1)² − 8.6 r (4.4 N − 1) + 11.4 r²) / (4.4 N − 3)²]

    With these and χ² intervals, Stable32's Thêo1 and ThêoH bounds on the Sr87 clock data are
    reproduced (``tests/test_theo_reference.py``). TheoBR uses the same ν (kf treated as exact).

    Parameters
    ----------
    alpha : int or array_like of int
        Noise type(s), 2 … −2 (α of S_y ∝ f^α; gyro terms: Q 2, N 0, B −1, K −2).
    m : int or array_like of int
        Theo1 averaging factors (τ = 0.75·m·τ0).
    N : int
        Number of phase (angle) points: rate samples + 1.

    Returns
    -------
    float or ndarray

    Examples
    --------
    >>> from allanite.estimators.confidence import edf_theo1
    >>> round(float(edf_theo1(0, 10, 1001)), 1)          # white rate, m = 10 (τ = 7.5 τ0)
    434.3
    """
    a = _check_alpha(alpha)
    m_arr = np.asarray(m, dtype=np.float64)
    if np.any(~np.isfinite(m_arr)) or np.any(m_arr < 2):
        raise ParameterError(f"m must be Theo1 averaging factors ≥ 2, got {m!r}")
    n = float(check_count(N, "N", 3))
    a, r = np.broadcast_arrays(a, 0.75 * m_arr)
    out = np.empty(a.shape, dtype=np.float64)
    for idx in np.ndindex(a.shape):
        al, rr = int(a[idx]), float(r[idx])
        if al == 2:
            v = 0.86 * (n + 1) * (n - 4 * rr / 3) / (n - rr) * (rr / (rr + 1.14))
        elif al == 1:
            v = (4.798 * n * n - 6.374 * n * rr + 12.387 * rr) / (math.sqrt(rr + 36.6) * (n - rr)) * (rr / (rr + 0.3))
        elif al == 0:
            v = ((4.1 * n + 0.8) / rr - (3.1 * n + 6.5) / n) * (rr**1.5 / (rr**1.5 + 5.2))
        elif al == -1:
            v = (2 * n * n - 1.3 * n * rr - 3.5 * rr) / (n * rr) * (rr**3 / (rr**3 + 2.3))
        else:
            q = 4.4 * n
            v = (q - 2) / (2.9 * rr) * (((q - 1) ** 2 - 8.6 * rr * (q - 1) + 11.4 * rr * rr) / (q - 3) ** 2)
        out[idx] = max(v, 1.0)  # the fits go below 1 only far outside their range; ν ≥ 1 keeps χ² defined
    return float(out) if out.ndim == 0 else out


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
# noise identification


def _lag1_acf(z: np.ndarray) -> float:
    """Lag-1 autocorrelation with Stable32's (n − 1)/n factor (Riley, Handbook §5.5.3)."""
    z = z - z.mean()
    # einsum, not np.dot: OpenBLAS's threaded dot took 8.8 ms of CPU for 2^20 elements on two busy cores,
    # einsum 0.8 ms (the same sum to rounding)
    den = float(np.einsum("i,i->", z, z))
    if den == 0.0:
        return 0.0
    return float(np.einsum("i,i->", z[:-1], z[1:])) / den * (z.size - 1) / z.size


def _acf_alpha(z: np.ndarray, phase: bool, dmax: int = 2) -> float:
    """Riley & Greenhall's lag-1 ACF algorithm on data already decimated/averaged to τ: difference
    until δ = r1/(1 + r1) < 0.25 (at most dmax times); p = −2(δ + d); α = p + 2 for phase data,
    p for frequency data. Returns the fractional estimate."""
    d = 0
    while True:
        r1 = _lag1_acf(z)
        delta = r1 / (1.0 + r1) if r1 > -1.0 else -1e9  # r1 → −1: as white as it gets
        if delta < 0.25 or d >= dmax or z.size < 4:
            p = -2.0 * (delta + d)
            return p + 2.0 if phase else p
        z = np.diff(z)
        d += 1


def _b1_expected(N: float, mu: int) -> float:
    """Barnes' B1(N, r = 1, μ): expected N-sample over 2-sample variance for the phase exponent μ."""
    if mu == 0:
        return N * math.log(N) / (2.0 * (N - 1.0) * math.log(2.0))
    return N * (1.0 - N**mu) / (2.0 * (N - 1.0) * (1.0 - 2.0**mu))


def _b1_rn_alpha(x: np.ndarray, y: np.ndarray, m: int, n_ref: int, long: LongRate | None = None) -> int:
    """B1 ratio, then R(n) = MVAR/AVAR to split WPM from FPM (Howe, Beard, Greenhall & Riley 2000).
    ``long``: a long rate record read in chunks (``x`` and ``y`` unused)."""
    k = (y.size if long is None else long.n) // m
    if k < 2:
        return 0
    ya = y[: k * m].reshape(k, m).mean(axis=1) if long is None else long.all_means(m)
    avar_classic = 0.5 * float(np.mean(np.diff(ya) ** 2))
    if avar_classic == 0.0:
        return 0
    b1 = float(np.var(ya, ddof=1)) / avar_classic
    # N at which the expected B1 is evaluated: the number of averages (Barnes), or what the caller
    # chose (Stable32: the estimator's number of terms).
    N = max(int(n_ref), 2)
    mus = (1, 0, -1, -2)  # RWFM, FFM, WFM, WPM/FPM
    mu = -2
    for hi, lo in zip(mus[:-1], mus[1:]):
        if b1 > math.sqrt(_b1_expected(N, hi) * _b1_expected(N, lo)):
            mu = hi
            break
    if mu != -2:
        return {1: -2, 0: -1, -1: 0}[mu]
    n = x.size if long is None else long.n + 1
    if n - 3 * m + 1 < 1:
        return 1  # R(n) needs 3m + 1 points; FPM is the conservative (smaller-ν) choice
    rn = _rn(x, m) if long is None else long.rn(m)
    if rn is None:
        return 2
    rn_wpm = 1.0 / m
    rn_fpm = 3.37 / (1.04 + 3.0 * math.log(math.pi * m))  # f_h = 1/(2τ0)
    return 1 if rn > math.sqrt(rn_wpm * rn_fpm) else 2


def _rn(x: np.ndarray, m: int) -> float | None:
    """R(n) = MVAR/AVAR at m from the phase ``x``; None where the AVAR is 0."""
    n = x.size
    dd = x[2 * m :] - 2.0 * x[m : n - m] + x[: n - 2 * m]
    oav = float(np.mean(dd * dd))
    if oav == 0.0:
        return None
    c = np.concatenate(([0.0], np.cumsum(dd)))
    mv = float(np.mean(((c[m:] - c[:-m]) / m) ** 2))
    return mv / oav


def identify_alpha(x, m, *, input="angle", estimator="oavar", method="auto", b1_n="terms", fallback="prudent"):
    """Dominant power-law noise type α at each averaging factor, by Stable32's method.

    At each m the data are brought to τ = m·τ0 — phase (angle) data decimated (every m-th point),
    rate (frequency) data averaged in non-overlapping blocks of m — and then:

    * ``"acf"``: the lag-1 autocorrelation method of Riley & Greenhall (EFTF 2004): difference the
      series d times (d ≤ 2) until δ = r1/(1 + r1) < 0.25; α = −2(δ + d) (+2 for phase data),
      rounded. Reliable from about 30 points.
    * ``"b1"``: the B1 ratio (sample variance of the m-averages over their Allan variance) against
      Barnes' expectation for each noise type, and where that says WPM-or-FPM, the ratio
      R(n) = MVAR/AVAR against 1/m (WPM) and 3.37/(1.04 + 3 ln(πm)) (FPM).
    * ``"auto"`` (default, Stable32's rule): ACF where the record holds at least 30 intervals of
      length τ (⌊M/m⌋ ≥ 30 for M samples), B1/R(n) below.

    Where too few samples remain — fewer than 8 τ-intervals for ``"oavar"``, 10 for ``"avar"``
    (:data:`ID_MIN_POINTS`) — α is not identified from that τ's samples but taken from the nearest
    shorter τ of ``m`` (``fallback="previous"``): Stable32's rule, which its Alpha columns follow
    row by row (``docs/confidence.md``). The default, ``fallback="prudent"``, adds one more rule on
    octave-spaced (or sparser) grids: α may rise above both neighbours' only on ≥ 30 τ-intervals
    (:data:`ACF_MIN_POINTS`) at every τ of the rise; a rise read on fewer falls back to the α before it.

    Parameters
    ----------
    x : array_like, 1-D
        Samples of one axis: cumulative angle (phase) points, or rate / increment samples, per
        ``input``. Offsets and scale do not matter.
    m : int or array_like of int
        Averaging factors (τ = m/fs).
    input : {"angle", "rate", "increment"}
        What ``x`` holds. ``"angle"`` follows Stable32's phase-data path (decimation), ``"rate"`` and
        ``"increment"`` its frequency-data path (block averages).
    estimator : {"oavar", "avar"}
        The estimator the α is for: its number of terms (``b1_n="terms"``) and its minimum of
        τ-intervals (``fallback``) depend on it.
    method : {"auto", "acf", "b1"}
    b1_n : {"terms", "averages"}
        The N at which Barnes' expected B1(N, μ) is evaluated. ``"terms"`` (default, Stable32's):
        the estimator's number of terms, N − 2m (overlapping) or ⌊(N − 1)/m⌋ − 1 (classic), the
        "#" column — with ``fallback="previous"`` it reproduces every Alpha of the Stable32
        ADEV/OADEV octave and decade tables in ``docs/confidence.md``. ``"averages"``: the number
        of τ-averages the measured ratio is made of — Barnes' definition. For the overlapping
        estimator the number of terms is far larger than the number of averages, so with
        ``"terms"`` the RWFM expectation (N/2) is out of reach and random-walk noise comes out as
        FFM: in simulation it identifies RWFM 0 % and FFM 24 % of the time at 7–26 averages,
        against 67 % and 59 % for ``"averages"``. Prefer ``"averages"`` to tell rate random walk
        from bias instability at long τ of an overlapping curve.
    fallback : {"prudent", "previous", "none"}
        ``"previous"``: where too few samples remain (see above), α is that of the
        nearest shorter τ of ``m`` identified on its own samples; if ``m`` holds none, α is
        identified at the longest averaging factor that still has enough τ-intervals.
        ``"prudent"`` (default): the same, and on a grid whose neighbouring m are ≥ 2× apart a *peak*
        — consecutive τ whose α is above the α on both sides — stands only if each of its τ was
        identified on ≥ 30 τ-intervals; otherwise it takes the α before it. A sum of power-law noises
        has α fall as τ grows, and a higher α means a larger ν: a chance rise read on few points would
        give an interval too narrow where data are scarce (e.g. 2¹⁷ white-rate samples read as flicker
        phase at m = 4096 and 8192, ν 94 → 511). On the Stable32 tables of ``docs/confidence.md`` it
        changes no α. ``"none"``: every τ on its own samples, however few (with 2 averages B1 is
        exactly 1, "white FM", whatever the noise).

    Returns
    -------
    int or ndarray of int
        α ∈ {2, 1, 0, −1, −2} per m (values beyond are clipped to that range).

    Notes
    -----
    The lag-1 ACF is exact on average for the white and random-walk types, but on averaged
    flicker noise its fractional estimate drifts towards the neighbouring type (≈ ±1.45 instead
    of ±1 from m ≈ 16 on), so flicker is sometimes reported as its neighbour at long τ — in
    Stable32 as here. With few averages (the B1 branch) any identification is uncertain: in
    simulation 55–80 % of the calls are right.

    Examples
    --------
    >>> import numpy as np
    >>> from allanite.estimators.confidence import identify_alpha
    >>> rng = np.random.default_rng(0)
    >>> identify_alpha(rng.normal(size=10_000), [1, 10, 100], input="rate")      # white rate
    array([0, 0, 0])
    >>> identify_alpha(np.cumsum(rng.normal(size=10_000)), [1, 10, 100], input="rate")  # rate random walk
    array([-2, -2, -2])
    """
    check_choice(input, "input", _INPUTS)
    check_choice(estimator, "estimator", _ESTIMATORS)
    check_choice(method, "method", ("auto", "acf", "b1"))
    check_choice(b1_n, "b1_n", ("averages", "terms"))
    check_choice(fallback, "fallback", _FALLBACKS)
    arr = np.asarray(x)
    if arr.ndim != 1 or arr.dtype.kind not in "iuf":
        raise ParameterError(
            f"x must be a 1-D array of real numbers (one axis), got shape {arr.shape} dtype {arr.dtype}"
        )
    arr = np.asarray(arr, dtype=np.float64)  # no copy of a float64 record: nothing below writes into it
    # min and max are NaN if any sample is, ±inf if any is: no per-sample temporary
    if arr.size and not (np.isfinite(arr.min()) and np.isfinite(arr.max())):
        raise ParameterError("x contains NaN or infinite values; noise identification needs finite samples")
    long = None
    if input == "angle":
        if arr.size < 3:
            raise ParameterError(f"x has {arr.size} angle points; at least 3 are needed")
        phase = arr - arr[0]
        rate = np.diff(arr)
    else:
        if arr.size < 2:
            raise ParameterError(f"x has {arr.size} samples; at least 2 are needed")
        if arr.size > LONG_SAMPLES:  # chunk by chunk: no copy of the record (estimators/_long_id.py)
            long = LongRate(arr, arr.mean())
            rate = phase = arr[:0]
        else:
            rate = arr - arr.mean()
            phase = np.concatenate(([0.0], np.cumsum(rate)))
    n_phase = phase.size if long is None else arr.size + 1
    m_arr = np.atleast_1d(np.asarray(m))
    if m_arr.dtype.kind not in "iuf" or np.any(m_arr % 1 != 0) or np.any(m_arr < 1):
        raise ParameterError(f"m must be integer averaging factors ≥ 1, got {m!r}")
    m_arr = m_arr.astype(np.int64)
    too_big = m_arr > (n_phase - 1) // 2
    if too_big.any():
        raise ParameterError(
            f"m = {int(m_arr[too_big][0])} is too large for {n_phase - 1} samples (largest: {(n_phase - 1) // 2})"
        )
    each = functools.partial(
        _identify_each,
        phase,
        rate,
        phase_input=input == "angle",
        estimator=estimator,
        method=method,
        b1_n=b1_n,
        long=long,
    )
    own = each(m_arr)
    out = own
    if fallback != "none":
        out = _fall_back(own, m_arr, n_phase - 1, ID_MIN_POINTS[estimator], each)
    if fallback == "prudent":
        out = _level_weak_peaks(out, m_arr, (n_phase - 1) // m_arr)
    return int(out[0]) if np.ndim(m) == 0 else out


def _level_weak_peaks(alpha: np.ndarray, m: np.ndarray, points: np.ndarray) -> np.ndarray:
    """A peak — a run of consecutive τ (in order of m) whose α is above the α on both sides of it —
    stands only if every τ of the run was identified on at least :data:`ACF_MIN_POINTS` τ-intervals;
    otherwise the run takes the α before it. A sum of power-law noises has its α fall, never rise, as τ
    grows; a rise that falls back is a chance reading of few points, and a higher α gives a larger ν —
    an interval too narrow exactly where the data are scarce. Dips (a lower α, a wider interval) stay.

    Only on a grid whose neighbouring m are at least a factor 2 apart (octave, decade): on a denser
    grid neighbouring τ re-read nearly the same averages, so a neighbour is no second reading."""
    steps = np.diff(np.unique(m).astype(np.float64))
    if steps.size and np.min(steps / np.unique(m)[:-1]) < 0.99:
        return alpha
    order = np.argsort(m, kind="stable")
    a = alpha[order].copy()
    weak = points[order] < ACF_MIN_POINTS
    i = 1
    while i < a.size:
        j = i
        while j + 1 < a.size and a[j + 1] == a[i]:
            j += 1
        # run i..j; a peak needs a neighbour on both sides, both below it
        if j + 1 < a.size and a[i] > a[i - 1] and a[i] > a[j + 1] and weak[i : j + 1].any():
            a[i : j + 1] = a[i - 1]
            i = max(1, i - 1)  # the run joined its left neighbour's: look at that run again
            while i > 1 and a[i - 1] == a[i]:
                i -= 1
            continue
        i = j + 1
    out = np.empty_like(alpha)
    out[order] = a
    return out


def _fall_back(own: np.ndarray, m: np.ndarray, n_intervals: int, min_points: int, identify) -> np.ndarray:
    """Stable32's rule for τ with too few samples (see :func:`identify_alpha`): every τ with fewer than
    ``min_points`` τ-intervals takes the α of the nearest shorter τ of ``m`` identified on its own; with
    none, the α identified at the longest averaging factor that still has ``min_points`` intervals."""
    needs = n_intervals // m < min_points
    if not needs.any():
        return own
    out = own.copy()
    donors = np.flatnonzero(~needs)
    if donors.size:
        # m need not be sorted: for each τ, the donor with the largest m below it
        order = donors[np.argsort(m[donors], kind="stable")]
        pos = np.searchsorted(m[order], m[needs], side="left") - 1
    else:
        pos = np.full(int(needs.sum()), -1)
    ref = None
    for i, p in zip(np.flatnonzero(needs), pos):
        if p >= 0:
            out[i] = own[order[p]]
        else:
            if ref is None:
                ref = int(identify(np.array([max(1, n_intervals // min_points)]))[0])
            out[i] = ref
    return out


def _identify_each(phase, rate, m_arr, *, phase_input, estimator, method, b1_n, long=None) -> np.ndarray:
    """α at each m on that τ's own samples (no fallback). ``long``: a long rate record read in chunks
    (:class:`~allanite.estimators._long_id.LongRate`; ``phase`` and ``rate`` unused)."""
    n_phase = phase.size if long is None else long.n + 1
    out = np.empty(m_arr.shape, dtype=np.int64)
    for i, mi in enumerate(m_arr.tolist()):
        points = (n_phase - 1) // mi  # τ-intervals in the record, for either kind of data
        use_acf = method == "acf" or (method == "auto" and points >= ACF_MIN_POINTS)
        if use_acf:
            if long is not None and long.n // mi > long.chunk:
                p = long.acf_alpha(mi)  # the block averages too many to hold: in chunks
            else:
                if phase_input:
                    z = phase[::mi]
                elif long is not None:
                    z = long.all_means(mi)
                else:
                    k = rate.size // mi
                    z = rate[: k * mi].reshape(k, mi).mean(axis=1)
                p = _acf_alpha(z, phase=phase_input)
            a = int(np.clip(round(p), -2, 2))
        else:
            if b1_n == "averages":
                n_ref = points
            elif estimator == "oavar":
                n_ref = n_phase - 2 * mi
            else:
                n_ref = (n_phase - 1) // mi - 1
            a = _b1_rn_alpha(phase, rate, mi, n_ref, long)
        out[i] = a
    return out


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
        a = _check_alpha(alpha)
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
    fallback : {"prudent", "previous", "none"}
        Where too few samples remain to identify the noise type (fewer than 8 τ-intervals for
        ``"oavar"``, 10 for ``"avar"``), α is the nearest shorter τ's (``"previous"``, Stable32's
        rule, see :func:`identify_alpha`), so the last points get the wide interval their few terms
        warrant instead of one from a guessed "white/flicker phase" type. ``"prudent"`` (default)
        also keeps a rise of α above both neighbours (a larger ν) on an octave grid only where it
        was read on ≥ 30 τ-intervals; ``"none"`` identifies every τ on its own samples.

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
    if edf_method == "sp1065" and result.estimator not in _ESTIMATORS:
        raise ParameterError(f"edf_method='sp1065' has formulas for {_ESTIMATORS}, not {result.estimator!r}")
    dynamic = _is_dynamic(result)
    n_axes = result.n_axes
    shape_edf = (result.m.size,) if n_axes is None else (n_axes, result.m.size)
    check_choice(b1_n, "b1_n", ("averages", "terms"))
    check_choice(fallback, "fallback", _FALLBACKS)
    a = _alpha_for_result(result, x, alpha, shape_edf, b1_n, fallback)
    n_phase = _window_length(result) + 1
    m_b = np.broadcast_to(result.m, shape_edf)
    per_window = dynamic and np.ndim(result.n) >= 2
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
    nu = np.asarray(nu, dtype=np.float64).reshape(shape_edf)
    taper = _registry.TAPERS[getattr(result, "taper", "rect")]
    if taper.edf_factor is None:
        raise ParameterError(f"taper {taper.name!r} has no model of its equivalent degrees of freedom")
    if taper.name != "rect":
        # the tapered estimate keeps the share (Σw)²/(M·Σw²) of the rectangular window's ν
        nu = nu * taper.edf_factor(m_b, n_phase - 1)
    nu_b = nu[..., None] if dynamic and not per_window else nu
    if np.all(np.isfinite(nu)):
        low, high = chi2_interval(result.avar, nu_b, c, method=chi2)
    else:  # gaps="skip": a τ without a complete term has no EDF and no interval (NaN)
        ok = np.isfinite(nu_b) & np.isfinite(result.avar)
        low, high = np.full(result.avar.shape, np.nan), np.full(result.avar.shape, np.nan)
        if ok.any():
            low[ok], high[ok] = chi2_interval(result.avar[ok], nu_b[ok], c, method=chi2)
    return ConfidenceIntervals(
        edf=nu,
        ci_low=np.asarray(low),
        ci_high=np.asarray(high),
        alpha=a,
        confidence=c,
        edf_method=edf_method,
        chi2=chi2,
    )
