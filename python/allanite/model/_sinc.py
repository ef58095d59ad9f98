"""The sinc^k roll-off of a CIC decimator read at its output rate: white noise through k cascaded boxcars of
one span, sampled.

A CIC (cascaded integrator–comb) of order k and decimation R is k boxcars of R taps at the input rate, then every
R-th sample kept: H(f) = (sin(πfR/f_in)/(R·sin(πf/f_in)))^k. White input of variance σ² gives an output whose
autocorrelation at output lag l is σ²·b^{*2k}(l·R) — the boxcar's autocorrelation (a triangle) convolved with
itself k times, read every R input samples. For R large this is the centred cardinal B-spline of order 2k
(degree 2k − 1), M_2k, read at the lags in output samples: ρ(l) = M_2k(l/D)/M_2k(0) with D the span of each
boxcar in output samples (1 for a CIC read at its own output rate; any real ≥ 1/k as a continuous parameter — a
part that averages further, or a rate read off a decimated chain), zero from |l| ≥ k·D on. At k = 1 it is the
boxcar kind's triangle (1 − l/D)₊. The discrete filter's ρ(1) lies below the spline's by O(1/R²): at k = 3,
0.3724 for R = 4 and 0.3926 for R = 16 against 0.3939 (the fitted span absorbs it: the same roll-off at a span
a few % shorter). Its Allan variance follows exactly from ρ (:func:`allanite.model.effects.filtered_white_avar`).

The −3 dB frequency is the continuous filter's, sinc^{2k}(πf·D/f_s) = ½: x_k·f_s/(π·D), x_k solving
sinc²(x) = 2^{−1/k} (0.4430·f_s/D at k = 1, 0.2619·f_s at k = 3, D = 1) — before the output sampling aliases it.
"""

from __future__ import annotations

import functools
import math

import numpy as np

__all__ = ["SINC_ORDERS", "sinc_order", "sinc_autocorrelation", "sinc_cutoff"]

#: Orders k of the sinc^k (CIC) kinds of the bandwidth effect ("sinc2" … "sinc5"); order 1 is the "boxcar".
SINC_ORDERS = (2, 3, 4, 5)


def sinc_order(kind: str) -> int:
    """The order of a sinc^k kind ("sinc3" → 3); 0 for any other kind."""
    tail = kind[len("sinc") :] if kind.startswith("sinc") else ""
    return int(tail) if tail.isdigit() and int(tail) in SINC_ORDERS else 0


def _bspline(n: int, x: np.ndarray) -> np.ndarray:
    """The centred cardinal B-spline of order n (n unit boxcars convolved, support |x| < n/2)."""
    x = np.abs(np.asarray(x, dtype=np.float64))
    s = np.zeros_like(x)
    for j in range(n + 1):
        s += (-1) ** j * math.comb(n, j) * np.maximum(0.0, x + n / 2.0 - j) ** (n - 1)
    return np.maximum(s / math.factorial(n - 1), 0.0)  # rounding below zero near the support's end


def sinc_autocorrelation(order: int, span: float) -> np.ndarray:
    """Normalised autocorrelation r(l), l = 0, 1, …, of unit-DC-gain sinc^``order`` filtered white noise of span
    ``span`` output samples per boxcar (at least 1/order: shorter is white), Σ_l r(|l|) = 1."""
    span = max(1.0 / order, float(span))
    lags = np.arange(max(1, int(math.ceil(order * span))), dtype=np.float64)
    r = _bspline(2 * order, lags / span)
    return r / (r[0] + 2.0 * r[1:].sum())


@functools.lru_cache(maxsize=16)
def _x_half(order: int) -> float:
    """x solving sinc²(x) = 2^{−1/order} (bisection: sinc² falls monotonically on (0, π))."""
    target, lo, hi = 2.0 ** (-1.0 / order), 1e-9, math.pi - 1e-9
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if (math.sin(mid) / mid) ** 2 > target else (lo, mid)
    return 0.5 * (lo + hi)


def sinc_cutoff(order: int, span: float, fs: float) -> float:
    """−3 dB frequency (Hz) of the continuous sinc^``order`` of span ``span`` output samples at rate ``fs``."""
    return float(_x_half(order) * fs / (math.pi * max(1.0 / order, float(span))))
