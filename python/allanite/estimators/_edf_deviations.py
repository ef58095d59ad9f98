"""Equivalent degrees of freedom (EDF) and bias factors for the deviation family beyond OAVAR.

Standalone (NumPy only; no other allanite module but :mod:`allanite.errors`), for the estimator
registry to combine with the χ² interval and Greenhall's EDF algorithm it already has.

Conventions: α is the exponent of the fractional-frequency (rate) PSD, S_y(f) ∝ f^α (2 WPM, 1 FPM,
0 WFM, −1 FFM, −2 RWFM, −3 FWFM, −4 RRFM); ``n_points`` is the number of *phase* points N (= M + 1
for M rate samples); τ = m·τ0, so T/τ = N/m (T = N·τ0, as Stable32 uses it).

Sources and what reproduces Stable32 (checked in tests/test_deviations_core.py against the printed
Min/Max Sigma columns, χ² interval at confidence erf(1/√2)):

* MVAR, TVAR, HVAR, OHVAR: Greenhall & Riley's combined EDF algorithm ("Uncertainty of stability
  variances based on finite differences", PTTI 2003) with the parameters in
  :data:`GREENHALL_PARAMETERS` (d = 2 modified for MVAR/TVAR; d = 3 for the Hadamard pair). Stable32's
  bounds reproduced to ≤ 2.2e-4 relative (its χ² iteration tolerance).
* TOTVAR, α ∈ {0, −1, −2}: ν = b·(T/τ) − c, (b, c) = (1.50, 0), (1.17, 0.22), (0.93, 0.36) (NIST SP 1065
  Table 11; Howe, Greenhall & Percival). Stable32 reproduced to ≤ 2e-4. For α = 1, 2 SP 1065 gives no
  formula; Stable32's bounds there are within 2.6 % of those from the overlapping-Allan EDF
  (Greenhall, d = 2) — a residual, not a rule.
* MTOTVAR and TTOTVAR: ν = b·(T/τ) − c, (b, c) = (1.90, 2.10), (1.20, 1.40), (1.10, 1.20), (0.85, 0.50),
  (0.75, 0.31) for α = 2 … −2 (SP 1065 Table 12). Stable32 does something else: its bounds differ
  from these by up to ~6 % (documented residual; at m ≤ 8 they are within ~1 % of the modified-Allan
  Greenhall EDF).
* HTOTVAR: for m ≥ 16 and α ∈ {0, …, −4}, ν = (T/τ) / (b0 + b1·τ/T) with (b0, b1) = (0.559, 1.004),
  (0.868, 1.140), (0.938, 1.696), (2.554, 0.974), (3.149, 1.276) for α = 0, −1, −2, −3, −4 (Howe, Beard,
  Greenhall, Riley, PTTI 2000, Table 1; W. Riley, "CI2") — Stable32 reproduced to ≤ 1e-4. Otherwise
  (m < 16, or α = 1, 2) Stable32 uses a Hadamard-type EDF (:func:`htotvar_uses_ohvar_edf`); the
  overlapping-Hadamard Greenhall EDF gives bounds within 3.1 % of its (documented residual).

Bias factors (the variance Stable32 prints is the estimate divided by B):

* TOTVAR: B = 1 − a·(τ/T), a = 1/(3 ln 2) (α = −1), 3/4 (α = −2), 0 otherwise (Howe 1999).
* MTOTVAR/TTOTVAR: B = 0.94, 0.83, 0.73, 0.70, 0.69 for α = 2 … −2 (Riley, CI2); Stable32 applies it
  only in runs without confidence intervals (its all-τ tables).
* HTOTVAR: B = 0.995, 0.851, 0.771, 0.717, 0.679 for α = 0 … −4, 1 otherwise and at m = 1 (Howe et al.).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ParameterError

__all__ = [
    "GREENHALL_PARAMETERS",
    "edf_totvar",
    "edf_mtotvar",
    "edf_ttotvar",
    "edf_htotvar",
    "htotvar_uses_ohvar_edf",
    "totvar_bias",
    "mtotvar_bias",
    "htotvar_bias",
]

#: (d, overlapping, modified) for Greenhall & Riley's EDF algorithm, per estimator.
GREENHALL_PARAMETERS = {
    "mvar": (2, True, True),
    "tvar": (2, True, True),
    "hvar": (3, False, False),
    "ohvar": (3, True, False),
}

_TOTVAR_EDF = {0: (1.50, 0.0), -1: (1.17, 0.22), -2: (0.93, 0.36)}
_MTOTVAR_EDF = {2: (1.90, 2.10), 1: (1.20, 1.40), 0: (1.10, 1.20), -1: (0.85, 0.50), -2: (0.75, 0.31)}
_HTOTVAR_EDF = {0: (0.559, 1.004), -1: (0.868, 1.140), -2: (0.938, 1.696), -3: (2.554, 0.974), -4: (3.149, 1.276)}
_TOTVAR_BIAS = {-1: 1.0 / (3.0 * math.log(2.0)), -2: 0.75}
_MTOTVAR_BIAS = {2: 0.94, 1: 0.83, 0: 0.73, -1: 0.70, -2: 0.69}
_HTOTVAR_BIAS = {0: 0.995, -1: 0.851, -2: 0.771, -3: 0.717, -4: 0.679}

#: Below this m, HTOTVAR's EDF is the overlapping Hadamard one (Stable32; Howe et al.).
HTOTVAR_EDF_MIN_M = 16


def _check(alpha, m, n_points, allowed, what):
    if isinstance(alpha, bool) or not isinstance(alpha, (int, np.integer)) or int(alpha) not in allowed:
        raise ParameterError(
            f"{what}: noise type alpha = {alpha!r} is not covered; allowed: {sorted(allowed, reverse=True)}"
        )
    for name, v, lo in (("m", m, 1), ("n_points", n_points, 2)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < lo:
            raise ParameterError(f"{what}: {name} = {v!r} must be an integer ≥ {lo}")
    if m >= n_points:
        raise ParameterError(f"{what}: m = {m} must be smaller than n_points = {n_points}")
    return int(alpha), int(m), int(n_points)


def edf_totvar(alpha: int, m: int, n_points: int) -> float:
    """TOTVAR EDF ν = b·(N/m) − c for α ∈ {0, −1, −2} (SP 1065 Table 11).

    >>> round(edf_totvar(0, 100, 1001), 3)
    15.015
    """
    a, m, n = _check(alpha, m, n_points, _TOTVAR_EDF, "TOTVAR EDF")
    b, c = _TOTVAR_EDF[a]
    return b * n / m - c


def edf_mtotvar(alpha: int, m: int, n_points: int) -> float:
    """MTOTVAR EDF ν = b·(N/m) − c for α ∈ {2, …, −2} (SP 1065 Table 12). Not Stable32's (see module).

    >>> round(edf_mtotvar(0, 10, 1001), 3)
    108.91
    """
    a, m, n = _check(alpha, m, n_points, _MTOTVAR_EDF, "MTOTVAR EDF")
    b, c = _MTOTVAR_EDF[a]
    return b * n / m - c


def edf_ttotvar(alpha: int, m: int, n_points: int) -> float:
    """TTOTVAR EDF: the MTOTVAR one (TTOTVAR is MTOTVAR times the constant τ²/3)."""
    return edf_mtotvar(alpha, m, n_points)


def htotvar_uses_ohvar_edf(alpha: int, m: int) -> bool:
    """True where HTOTVAR's EDF is the overlapping Hadamard one: m < 16 or α outside 0 … −4."""
    return m < HTOTVAR_EDF_MIN_M or alpha not in _HTOTVAR_EDF


def edf_htotvar(alpha: int, m: int, n_points: int) -> float:
    """HTOTVAR EDF ν = (N/m) / (b0 + b1·m/N) for m ≥ 16, α ∈ {0, …, −4} (Howe et al. 2000, Table 1).

    Where :func:`htotvar_uses_ohvar_edf` is true, use the overlapping Hadamard EDF instead
    (Greenhall, :data:`GREENHALL_PARAMETERS` ``["ohvar"]``); asking here raises ParameterError.

    >>> round(edf_htotvar(0, 32, 1001), 2)
    52.92
    """
    a, m, n = _check(alpha, m, n_points, _HTOTVAR_EDF, "HTOTVAR EDF")
    if m < HTOTVAR_EDF_MIN_M:
        raise ParameterError(
            f"HTOTVAR EDF: m = {m} < {HTOTVAR_EDF_MIN_M} uses the overlapping "
            "Hadamard EDF (Greenhall, d = 3), not the HTOTVAR formula"
        )
    b0, b1 = _HTOTVAR_EDF[a]
    r = n / m
    return r / (b0 + b1 / r)


def totvar_bias(alpha: int, m: int, n_points: int) -> float:
    """TOTVAR bias B = 1 − a·(m/N) (a = 1/(3 ln 2) for α = −1, 3/4 for α = −2, else 0)."""
    a, m, n = _check(alpha, m, n_points, range(-4, 3), "TOTVAR bias")
    return 1.0 - _TOTVAR_BIAS.get(a, 0.0) * m / n


def mtotvar_bias(alpha: int) -> float:
    """MTOTVAR/TTOTVAR bias factor B(α), α ∈ {2, …, −2}."""
    a, _, _ = _check(alpha, 1, 2, _MTOTVAR_BIAS, "MTOTVAR bias")
    return _MTOTVAR_BIAS[a]


def htotvar_bias(alpha: int, m: int) -> float:
    """HTOTVAR bias factor: B(α) for α ∈ {0, …, −4} and m ≥ 2; 1 at m = 1 (OHVAR) and for α = 1, 2."""
    a, m, _ = _check(alpha, m, m + 1, range(-4, 3), "HTOTVAR bias")
    return 1.0 if m == 1 else _HTOTVAR_BIAS.get(a, 1.0)
