"""The slow-line test's noise fits (:mod:`allanite.model.slowline`): block means ``z`` beside fixed effects ``x``
under σ²(I + r₁·RW + r₂·flicker), σ² profiled out, fitted in ln r by restricted (REML) or plain maximum likelihood.

The deviances come with their gradients in ln r, so that L-BFGS-B takes one Cholesky factorisation a step where
finite differences took three (the bootstrap of the test's second reading fits 120 records three times each). With
C = I + Σₖ rₖPₖ, u = C⁻¹e (e the generalised least-squares residual) and ν the residual degrees of freedom (m − p
under REML, m under ML):

- ∂ ln det C / ∂ ln rₖ = rₖ·tr(C⁻¹Pₖ);
- ∂ RSS / ∂ ln rₖ = −rₖ·u′Pₖu (the coefficients are at their minimum: no term of theirs);
- under REML also ∂ ln det(X′C⁻¹X) / ∂ ln rₖ = −rₖ·tr((X′C⁻¹X)⁻¹·W′PₖW), W = C⁻¹X.

The deviance is ν·ln(RSS/ν) + ln det C (+ ln det X′C⁻¹X under REML), so its gradient is
rₖ·[tr(C⁻¹Pₖ) − ν·u′Pₖu/RSS (− tr((X′C⁻¹X)⁻¹W′PₖW))]; ``tests/test_slowline.py`` checks it against finite
differences. The REML fit's start is the best of a 3 × 3 grid in ln r, evaluated for many records at once (one
factorisation a grid point serves them all).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg.lapack import dpotrf, dpotrs, dtrtri
from scipy.optimize import minimize

__all__ = ["FLICKER_D", "LOG_R_BOUNDS", "noise_parts", "deviance", "reml_fit", "reml_starts", "ml_fit"]

#: The flicker part's fractional difference (d → ½ is 1/f; below it the noise is stationary).
FLICKER_D = 0.45
#: The noise's relative parts' bounds, ln r.
LOG_R_BOUNDS = (-20.0, 12.0)
#: The REML fit's start: the best of these (ln r₁, ln r₂).
START_GRID = tuple((a, b) for a in (-8.0, -2.0, 4.0) for b in (-8.0, -2.0, 4.0))


def _flicker_cov(m: int) -> np.ndarray:
    """Autocorrelation of fractionally integrated noise (d = FLICKER_D) at lags 0 … m−1, as a Toeplitz matrix."""
    k = np.arange(1, m)
    rho = np.concatenate([[1.0], np.cumprod((k - 1 + FLICKER_D) / (k - FLICKER_D))])
    idx = np.abs(np.arange(m)[:, None] - np.arange(m)[None, :])
    return rho[idx]


def noise_parts(m: int) -> tuple[np.ndarray, np.ndarray]:
    """The random walk's (its variance 1 at the record's end) and the flicker's covariance of m block means."""
    i = np.arange(m)
    rw = (np.minimum(i[:, None], i[None, :]) + 1.0) / m
    return rw, _flicker_cov(m)


def _factor(parts: tuple, logr: np.ndarray) -> tuple[np.ndarray, float, np.ndarray] | None:
    """The lower Cholesky factor of C = I + r₁P₁ + r₂P₂ (its upper triangle zero), ln det C and r; None where C
    does not factor (numerically)."""
    r = np.exp(np.clip(logr, -30.0, 30.0))
    c = r[0] * parts[0]
    c += r[1] * parts[1]
    c.flat[:: c.shape[0] + 1] += 1.0
    low, info = dpotrf(c, lower=1, clean=1, overwrite_a=1)
    if info != 0:
        return None
    return low, 2.0 * float(np.sum(np.log(low.diagonal()))), r


def _traces(low: np.ndarray, r: np.ndarray) -> np.ndarray:
    """rₖ·tr(C⁻¹Pₖ) for the random walk and the flicker, from C's Cholesky factor L with one triangular inverse:
    the random walk is BB′/m (B the lower triangle of ones), so tr(C⁻¹P₁) = ‖L⁻¹B‖²/m, L⁻¹B the sums of L⁻¹'s
    row tails; and tr(C⁻¹C) = m gives r₂·tr(C⁻¹P₂) = m − tr(C⁻¹) − r₁·tr(C⁻¹P₁), tr(C⁻¹) = ‖L⁻¹‖²."""
    linv, info = dtrtri(low, lower=1)
    if info != 0:
        return np.full(2, np.nan)
    m = low.shape[0]
    tails = np.cumsum(linv.T[::-1], axis=0)
    t1 = r[0] * float(np.einsum("ij,ij->", tails, tails)) / m
    return np.array([t1, m - float(np.einsum("ij,ij->", linv, linv)) - t1])


def _solve(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    try:
        return np.linalg.solve(a, b)
    except np.linalg.LinAlgError:  # the fixed effects numerically collinear under C: least squares' minimum norm
        return np.linalg.lstsq(a, b, rcond=None)[0]


def deviance(
    z: np.ndarray, x: np.ndarray, parts: tuple, logr: np.ndarray, restricted: bool
) -> tuple[float, np.ndarray]:
    """−2 × the log-likelihood of ``z`` beside fixed effects ``x`` under σ²(I + r₁·RW + r₂·flicker) (``parts``,
    :func:`noise_parts`), σ² profiled out, up to a constant — restricted (REML) or not (ML; comparable between
    nested ``x``) — and its gradient in ln r (the module's docstring)."""
    return _deviance(np.column_stack([x, z]), parts, logr, restricted)


def _deviance(xz: np.ndarray, parts: tuple, logr: np.ndarray, restricted: bool) -> tuple[float, np.ndarray]:
    """:func:`deviance` of ``z`` (``xz``'s last column) beside ``x`` (its others)."""
    fac = _factor(parts, logr)
    if fac is None:
        return float("inf"), np.zeros(2)
    low, logdet, r = fac
    x, z = xz[:, :-1], xz[:, -1]
    sol, _info = dpotrs(low, xz, lower=1)
    w, v = sol[:, :-1], sol[:, -1]
    a, xv = x.T @ w, x.T @ v
    beta = _solve(a, xv)
    rss = max(float(z @ v - xv @ beta), 1e-300)
    nu = z.size - x.shape[1] if restricted else z.size
    u = v - w @ beta
    m = z.size
    # u′P₁u = ‖B′u‖²/m, B′u the tails' sums of u
    quad = np.array([r[0] * float(np.sum(np.cumsum(u[::-1]) ** 2)) / m, r[1] * float(u @ parts[1] @ u)])
    f = nu * math.log(rss / nu) + logdet
    g = _traces(low, r) - nu * quad / rss
    if restricted:
        f += float(np.linalg.slogdet(a)[1])
        bw = np.cumsum(w[::-1], axis=0)
        pw = (r[0] * (bw.T @ bw) / m, r[1] * (w.T @ (parts[1] @ w)))
        g -= [float(np.trace(_solve(a, pk))) for pk in pw]
    return f, g


def reml_starts(zs: np.ndarray, x: np.ndarray, parts: tuple) -> np.ndarray:
    """Each column of ``zs``'s REML start: the point of :data:`START_GRID` where its deviance is least (shape
    (columns, 2)); one factorisation a grid point for all columns."""
    dev = np.empty((len(START_GRID), zs.shape[1]))
    nu = zs.shape[0] - x.shape[1]
    for i, g in enumerate(START_GRID):
        fac = _factor(parts, np.array(g))
        if fac is None:
            dev[i] = np.inf
            continue
        low, logdet, _r = fac
        sol, _info = dpotrs(low, np.column_stack([x, zs]), lower=1)
        a, v = x.T @ sol[:, : x.shape[1]], sol[:, x.shape[1] :]
        xv = x.T @ v
        rss = np.einsum("ij,ij->j", zs, v) - np.einsum("ij,ij->j", xv, np.linalg.solve(a, xv))
        dev[i] = nu * np.log(np.maximum(rss / nu, 1e-300)) + logdet + float(np.linalg.slogdet(a)[1])
    return np.array(START_GRID)[np.argmin(dev, axis=0)]


def reml_fit(z: np.ndarray, x: np.ndarray, parts: tuple, start: np.ndarray | None = None) -> np.ndarray:
    """The REML fit's ln r (from ``start``, by default the best of :data:`START_GRID`)."""
    start = reml_starts(z[:, None], x, parts)[0] if start is None else start
    return _least(z, x, parts, start, True)[1]


def ml_fit(z: np.ndarray, x: np.ndarray, parts: tuple, start: np.ndarray) -> tuple[float, np.ndarray]:
    """The smallest ML deviance over ln r (from ``start``, clipped to :data:`LOG_R_BOUNDS`) and where."""
    return _least(z, x, parts, np.clip(start, *LOG_R_BOUNDS), False)


def _least(z: np.ndarray, x: np.ndarray, parts: tuple, start: np.ndarray, restricted: bool) -> tuple[float, np.ndarray]:
    """The smallest deviance from ``start`` by L-BFGS-B (its gradient analytic) within :data:`LOG_R_BOUNDS`."""
    xz = np.column_stack([x, z])
    res = minimize(
        lambda g: _deviance(xz, parts, g, restricted), start, jac=True, method="L-BFGS-B", bounds=[LOG_R_BOUNDS] * 2
    )
    return float(res.fun), res.x
