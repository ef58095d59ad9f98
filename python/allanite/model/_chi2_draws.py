"""χ²_ν/ν quantiles of many Gaussian copula draws, through a table per ν.

:class:`allanite.model.tracing.ScoreTest` draws Allan curves from a model: per τ, ``n_boot`` values
χ²_ν⁻¹(Φ(z))/ν of correlated standard normal z, one ν per τ. The inverse incomplete gamma function costs
about a microsecond per value, and a default :func:`allanite.refine` draws 63 × 1000 values for each of its
steps' models. Every row shares its ν, so :func:`scaled_quantiles` evaluates the quantile exactly at
:data:`NODES` equally spaced z spanning the draws, and interpolates between them: cubic Hermite on
g(z) = ln(χ²_ν⁻¹(Φ(z))/ν), with the exact slope g′(z) = φ(z) / (f_ν(x)·x) (f_ν the χ²_ν density at the
quantile x). In log space the curve is close to a polynomial for any ν (≈ linear for large ν; ≈ −z² in the
lower tail of small ν), so the relative error is ≤ 1e-7 for ν from 0.05 to 10⁹ over |z| ≤ 4.5
(``tests/test_refine_irls.py`` checks ≤ 1e-6), some six times cheaper than the values one by one. With fewer
draws per row than :data:`NODES` × 2 the values are computed one by one.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.special import gammaincinv, gammaln, ndtr, xlogy

__all__ = ["NODES", "scaled_quantiles"]

#: Nodes of the table per ν (the interpolation error falls as 1/NODES⁴).
NODES = 257


def scaled_quantiles(z: np.ndarray, nu: np.ndarray) -> np.ndarray:
    """χ²_ν⁻¹(Φ(z))/ν of ``z`` (rows × draws) with ν per row (``nu``, rows): the χ² marginals of the copula."""
    z = np.asarray(z, dtype=np.float64)
    nu = np.asarray(nu, dtype=np.float64)
    half = 0.5 * nu[:, None]
    lo, hi = (float(z.min()), float(z.max())) if z.size else (0.0, 0.0)
    if z.shape[1] < 2 * NODES or not (hi > lo) or not (math.isfinite(lo) and math.isfinite(hi)):
        return 2.0 * gammaincinv(half, ndtr(z)) / nu[:, None]
    zn = np.linspace(lo, hi, NODES)
    h = (hi - lo) / (NODES - 1)
    x = 2.0 * gammaincinv(half, ndtr(zn)[None, :])
    if not (np.all(x > 0) and np.all(np.isfinite(x))):  # the draws reach where the table cannot go
        return 2.0 * gammaincinv(half, ndtr(z)) / nu[:, None]
    log_f = xlogy(half - 1.0, x) - 0.5 * x - half * math.log(2.0) - gammaln(half)
    g = np.log(x / nu[:, None])
    slope = np.exp(-0.5 * zn[None, :] ** 2 - 0.5 * math.log(2.0 * math.pi) - log_f - np.log(x)) * h
    return _hermite(z, lo, h, g, slope)


def _hermite(z: np.ndarray, lo: float, h: float, g: np.ndarray, slope: np.ndarray) -> np.ndarray:
    """exp of the cubic Hermite interpolant of ``g`` (rows × :data:`NODES`, slopes ``slope`` per node step) at ``z``
    (rows × draws; nodes from ``lo`` by ``h``): (2s³ − 3s² + 1)·g₀ + (s³ − 2s² + s)·d₀ + (3s² − 2s³)·g₁ + (s³ − s²)·d₁,
    summed in that order — in place in a few buffers, the nodes' values taken by flat index (the same numbers as
    whole-array expressions and ``np.take_along_axis``, a third of the temporaries)."""
    s = z - lo
    s /= h
    j = s.astype(np.int64)
    np.minimum(j, NODES - 2, out=j)
    s -= j
    j += (np.arange(z.shape[0], dtype=np.int64) * NODES)[:, None]  # flat indices of the rows' nodes
    s2 = s * s
    s3 = s2 * s
    g_f, d_f = g.ravel(), slope.ravel()
    out = 2 * s3
    out -= 3 * s2
    out += 1
    out *= g_f.take(j)
    term = s3 - 2 * s2
    term += s
    term *= d_f.take(j)
    out += term
    j += 1
    np.multiply(3, s2, out=term)
    term -= 2 * s3
    term *= g_f.take(j)
    out += term
    np.subtract(s3, s2, out=term)
    term *= d_f.take(j)
    out += term
    return np.exp(out, out=out)
