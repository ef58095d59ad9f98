"""The three distribution functions the analysis path needs — χ² quantile, χ² survival, normal quantile —
computed by the same :mod:`scipy.special` kernels :mod:`scipy.stats` calls (``chi2._ppf``, ``chi2._sf``,
``norm._ppf``), with its edge cases (ν ≤ 0 → NaN). Importing :mod:`scipy.stats` costs about half a second,
most of ``import allanite``; these give identical numbers without it,
and load :mod:`scipy.special` at their first call."""

from __future__ import annotations

import numpy as np

__all__ = ["chi2_ppf", "chi2_sf", "norm_ppf"]


def _out(v):
    return float(v) if np.ndim(v) == 0 else v


def chi2_ppf(p, nu):
    """``scipy.stats.chi2.ppf(p, nu)``: 2·P⁻¹(ν/2, p); NaN for ν ≤ 0 or p outside [0, 1]."""
    p, nu = np.broadcast_arrays(np.asarray(p, dtype=np.float64), np.asarray(nu, dtype=np.float64))
    from scipy import special  # loaded at the first interval, not at import allanite

    with np.errstate(invalid="ignore"):
        q = 2.0 * special.gammaincinv(nu / 2.0, p)
    return _out(np.where((nu > 0) & (p >= 0) & (p <= 1), q, np.nan))


def chi2_sf(x, nu):
    """``scipy.stats.chi2.sf(x, nu)``: Q(ν/2, x/2), 1 for x ≤ 0; NaN for ν ≤ 0."""
    x, nu = np.broadcast_arrays(np.asarray(x, dtype=np.float64), np.asarray(nu, dtype=np.float64))
    from scipy import special

    with np.errstate(invalid="ignore"):
        q = special.chdtrc(nu, np.maximum(x, 0.0))
    return _out(np.where(nu > 0, np.where(x > 0, q, 1.0), np.nan))


def norm_ppf(p):
    """``scipy.stats.norm.ppf(p)``: the inverse of the standard normal CDF."""
    from scipy import special

    return _out(special.ndtri(np.asarray(p, dtype=np.float64)))
