"""Equivalent degrees of freedom (EDF) of Allan-family variance estimates.

* :func:`edf_greenhall` — Greenhall & Riley's algorithm ("Uncertainty of stability variances based on
  finite differences", PTTI 2003), the one Stable32 uses for ADEV and OADEV;
* :func:`edf_sp1065` — the simple formulas of NIST SP 1065 Table 5 (overlapping ADEV);
* :func:`edf_theo1` — Howe & Peppler's fits for Theo1 (NIST SP 1065 §5.5.7).

:mod:`allanite.estimators.confidence` identifies the noise type, calls these and turns ν into χ²
intervals.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from .._validate import check_count
from ..errors import ParameterError

__all__ = ["ALPHAS", "check_alpha", "edf_greenhall", "edf_sp1065", "edf_theo1"]

#: Noise types of the Allan family (α of S_y(f) ∝ f^α) that the Allan variance can distinguish.
ALPHAS = (2, 1, 0, -1, -2)


# --------------------------------------------------------------------------------------------
# argument checks


def check_alpha(alpha, allowed=ALPHAS, what="alpha") -> np.ndarray:
    """``alpha`` as an int64 array, checked to hold integer noise exponents from ``allowed``.

    Raises :class:`~allanite.errors.ParameterError` naming the value and the allowed set otherwise.
    """
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


def _sz(t, F: float, alpha: int, d: int) -> np.ndarray:
    """Σ_k (−1)^k C(2d, d + k)·sx(t + k) (eq. 9) with sx(t) = F²·(2sw(t) − sw(t − 1/F) − sw(t + 1/F)) (eq. 8; the
    F → ∞ limit: sw with exponent α + 2, a pure sample of w): every sw of every shift in one call, the sum over
    k in order."""
    t = np.asarray(t, dtype=np.float64)
    ks = range(-d, d + 1)
    shifted = np.stack([t + k for k in ks])
    if math.isinf(F):
        sx = _sw(shifted, alpha + 2)
    else:
        w = _sw(np.stack([shifted, shifted - 1.0 / F, shifted + 1.0 / F]), alpha)
        sx = F * F * (2.0 * w[0] - w[1] - w[2])
    out = np.zeros_like(t)
    for i, k in enumerate(ks):
        out = out + (-1) ** k * math.comb(2 * d, d + k) * sx[i]
    return out


def _basic_sum(J: int, M: float, S: float, F: float, alpha: int, d: int) -> float:
    """Greenhall & Riley eq. 10 (sz at 0, J/S and every j/S, 0 < j < J, in one call)."""
    j = np.arange(1, int(J), dtype=np.float64)
    sz = _sz(np.concatenate([[0.0, J / S], j / S]), F, alpha, d)
    total = float(sz[0]) ** 2
    total += (1.0 - J / M) * float(sz[1]) ** 2
    total += 2.0 * float(np.sum((1.0 - j / M) * sz[2:] ** 2))
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
    a_arr = check_alpha(alpha, allowed)
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
    a = check_alpha(alpha)
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
    a = check_alpha(alpha)
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
