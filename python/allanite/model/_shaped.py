"""Noise-shaped (sigma-delta) quantisation: the Allan variance of white noise differenced k times, exact for sampled
data.

A sigma-delta modulator of order k quantises the rate itself and shapes its quantisation error e (white, σ_e² =
Δ²/12 for a step Δ) by (1 − z⁻¹)^k: the rate carries Δ^k e. With q = σ_e·τ0 (the IEEE-952 Q of a quantiser of
that step, in rate unit·s) the noise is y = (q/τ0)·Δ^k w, w white of unit variance; k = 1 is plain quantisation
(white angle noise, Allan variance 3q²/τ²). Its autocorrelation is the binomial sequence R(l) = (−1)^l·C(2k, k + l)
for |l| ≤ k (0 beyond), so its Allan variance at m samples is (q/τ0)²·(1/2m²)·Σ_l A_m(l)·R(l), A_m the Allan
filter's own autocorrelation. For m ≥ k it is C(2k − 2, k − 1)·3q²/τ² — white angle noise of Q² =
C(2k − 2, k − 1)·q² (:func:`shaped_q_factor`) — and above that line at the first k − 1 averaging factors only
(k = 2: 10q²/τ0² at m = 1, 5/3 of the line). Its PSD rises toward f_s/2 as sin^{2k}(πf/f_s), where white angle
noise rises as sin².
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ParameterError

__all__ = ["SHAPED_ORDERS", "shaped_autocorrelation", "shaped_avar", "shaped_q_factor"]

#: Orders of the noise shaping a ``"shaped_quantisation"`` effect may have (k = 1 is the Q term itself).
SHAPED_ORDERS = (2, 3)


def shaped_autocorrelation(order: float) -> np.ndarray:
    """R(l), l = 0 … k, of Δ^k w (w white of unit variance): (−1)^l·C(2k, k + l)."""
    k = _order(order)
    return np.array([(-1.0) ** lag * math.comb(2 * k, k + lag) for lag in range(k + 1)])


def shaped_q_factor(order: float) -> float:
    """C(2k − 2, k − 1): the shaped noise of level q is white angle noise of Q² = this × q² at m ≥ k."""
    k = _order(order)
    return float(math.comb(2 * k - 2, k - 1))


def shaped_avar(tau: np.ndarray | float, order: float, fs: float) -> np.ndarray:
    """Allan variance of y = (q/τ0)·Δ^k w per unit q² at ``tau`` (s; multiples of τ0 = 1/``fs``), exact:
    (1/τ0²)·(1/2m²)·Σ_{|l| ≤ k} A_m(l)·R(l), A_m(l) = 2m − 3|l| for |l| ≤ m, |l| − 2m for m < |l| ≤ 2m."""
    r = shaped_autocorrelation(order)
    m = np.maximum(np.rint(np.atleast_1d(np.asarray(tau, dtype=np.float64)) * fs), 1.0)
    lags = np.arange(r.size, dtype=np.float64)
    mm = m[:, None]
    a = np.where(lags <= mm, 2.0 * mm - 3.0 * lags, np.where(lags <= 2.0 * mm, lags - 2.0 * mm, 0.0))
    w = np.full(r.size, 2.0)
    w[0] = 1.0
    return (a @ (w * r)) / (2.0 * m * m) * fs * fs


def _order(order) -> int:
    k = int(round(float(order)))
    if k < 1 or k != float(order):
        raise ParameterError(f"order must be a whole number ≥ 1, got {order!r}")
    return k
