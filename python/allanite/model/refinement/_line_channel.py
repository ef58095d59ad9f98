"""Does a line whose amplitude changes along the record follow a channel? — the ``"line"`` check's words
(:mod:`._line_check`; docs/lines-and-outliers.md, "A line whose amplitude follows a channel").

A vibrating-structure gyro's drive line, a motor's line, a mains pickup: their amplitude follows the temperature
or a supply's voltage. The ``"line"`` check says the amplitude changes; this says what it changes with, where a
channel was given. The model: the line's complex amplitude in block k (the check's blocks, :mod:`._line_constancy`)
is c_k = A·(1 + g·(x̄_k − x̄)) + e_k — x̄_k the channel's mean over the block, Hann-weighted as the phasor weighs
the line; e_k the block's noise, E|e_k|² = s²·u_k (the pooled off-line level s² at f0, with its d₂ degrees of
freedom, times the block's phasor variance under unit white noise u_k). The complex slope b = A·g is the
weighted least squares of c_k on x̄_k − x̄ (weights 1/u_k); its part in phase with the intercept A,
β = Re(b·Ā)/|A|, has variance s²/(2·Sxx) (Sxx = Σ(x̄_k − x̄)²/u_k) whatever the truth, so F = 2·Sxx·β²/s² is
F(1, d₂) where the amplitude does not follow the channel — calibrated on the blocks' own noise, as the change
itself is tested. Said where F passes its 1 − α quantile (α the line's share of the check, split over the
channels) and what the channel leaves — the phasors less their fit — is not itself a change at that α
(F(2(B − 2), d₂)): a line that changes for another reason while a channel drifts is not said to follow it. The
size said is g, the amplitude's relative change per unit of the channel (β/|A|). It adds no removal: the line's
term stays the record's mean line.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import stats

__all__ = ["follows_channel", "block_means", "inphase_fit"]


def block_means(x: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """The channel's mean over each block, Hann-weighted as the block's phasor weighs the line (a uniform mean
    smooths a channel that moves within the blocks more than the phasors are smoothed: on a noise-free line,
    g 0.0203 for 0.02 on a channel cycling twice over 16 blocks, 0.0213 four times; Hann-weighted 0.0200)."""
    out = np.empty(edges.size - 1)
    for i, (a, b) in enumerate(zip(edges[:-1], edges[1:])):
        w = np.sin(np.pi * (np.arange(b - a) + 0.5) / (b - a)) ** 2
        out[i] = float(np.sum(w * x[a:b]) / np.sum(w))
    return out


def inphase_fit(ph: np.ndarray, w: np.ndarray, xk: np.ndarray) -> tuple[complex, complex, float, float, float]:
    """The weighted least squares of the phasors ``ph`` on the channel's block means ``xk`` (weights ``w`` = 1/u_k;
    module docstring): intercept A at the weighted mean x̄, complex slope b, in-phase slope β = Re(b·Ā)/|A|, Sxx
    and x̄ — b and β zero where the channel does not move across the blocks (Sxx not positive and finite) or A is 0."""
    xbar = float(np.sum(w * xk) / np.sum(w))
    xc = xk - xbar
    sxx = float(np.sum(w * xc**2))
    a = complex(np.sum(w * ph) / np.sum(w))
    if not (sxx > 0.0 and math.isfinite(sxx)) or a == 0:
        return a, 0j, 0.0, sxx, xbar
    b = complex(np.sum(w * xc * ph) / sxx)
    return a, b, (b * a.conjugate()).real / abs(a), sxx, xbar


def _one(ph: np.ndarray, unit: np.ndarray, s2: float, d2: float, xk: np.ndarray, alpha: float) -> dict | None:
    """The in-phase slope's F and the leftover's for one channel's block means ``xk`` (module docstring); None
    where the channel does not move across the blocks."""
    w = 1.0 / unit
    a, b, beta, sxx, xbar = inphase_fit(ph, w, xk)
    if not sxx > 0.0 or not math.isfinite(sxx) or abs(a) == 0.0:
        return None
    f1 = 2.0 * sxx * beta**2 / s2
    left = ph - a - b * (xk - xbar)
    dof_left = 2 * (ph.size - 2)
    f_left = float(np.sum(np.abs(left) ** 2 * w) / s2) / (ph.size - 2)
    return {
        "statistic": float(f1),
        "threshold": float(stats.f.isf(alpha, 1, d2)),
        "left": f_left,
        "left_threshold": float(stats.f.isf(alpha, dof_left, d2)),
        "g": float(beta / abs(a)),
        "mean": xbar,
    }


def follows_channel(
    phasors, unit, s2: float, d2: float, edges_s, fs: float, channels: dict, alpha: float
) -> dict | None:
    """The channel the line's amplitude follows (module docstring), or None: ``phasors`` the line's complex
    amplitude per block as it is in the record, ``unit`` each one's variance under unit white noise, ``s2`` and
    ``d2`` the pooled noise level at f0 and its degrees of freedom, ``edges_s`` the blocks' edges (s), ``alpha``
    split over the channels. Returns ``{"channel", "g", "mean", "statistic", "threshold", "left",
    "left_threshold"}`` for the channel of largest F that passes (g per unit of the channel, about ``mean``)."""
    ph, u = np.asarray(phasors, dtype=complex), np.asarray(unit, dtype=float)
    if not channels or ph.size < 4 or not (s2 > 0.0 and d2 > 0.0):
        return None
    edges = np.round(np.asarray(edges_s, dtype=float) * fs).astype(int)
    best = None
    for name, x in channels.items():
        x = np.asarray(x, dtype=float)
        if x.ndim != 1 or x.size < edges[-1]:
            continue
        r = _one(ph, u, s2, d2, block_means(x, edges), alpha / len(channels))
        if r is None or r["statistic"] <= r["threshold"] or r["left"] > r["left_threshold"]:
            continue
        if best is None or r["statistic"] > best["statistic"]:
            best = r | {"channel": name}
    return best
