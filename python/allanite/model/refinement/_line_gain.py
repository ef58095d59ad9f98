"""A line whose amplitude follows a channel, modelled: an accepted sinusoid's nested option
a·(1 + g·(x̃(t) − x̄))·cos(2πf0t + φ) (docs/lines-and-outliers.md, "A line whose amplitude follows a channel").

A vibrating-structure gyro's drive or quadrature line follows the temperature; :mod:`._line_channel` says so of a
line the ``"line"`` check finds changing. Here the line's term carries it. The fit is the least squares of the
line on cos, sin, (x − x̄)·cos, (x − x̄)·sin at the fixed f0, taken on the line's Hann-weighted complex amplitude
c_k in the blocks of :mod:`._line_constancy` (≥ 20 periods each, at most 16): c_k = A + b·(x̄_k − x̄) + e_k, x̄_k
the channel's mean over block k weighted as the phasor weighs the line — the channel smoothed to the blocks, so
that its own sensor noise does not enter the product (a 0.01 °C noise on a temperature is gone from a block
mean of 10⁴ samples) — and e_k the block's noise, E|e_k|² = s²·u_k (the off-line level at f0 and the block's
phasor variance under unit white noise). The amplitude's relative change per channel unit is g = β/|A|, β the
part of b in phase with A; F = 2·Sxx·β²/s² is F(1, d₂) where the amplitude does not follow the channel
(:func:`._line_channel._one`, its null measured in benches/results/line_channel_null.md).

Kept only where (1) F passes its 1 − α quantile, α = the ``"sinusoid:gain"`` conditional share of ``level``
(:data:`allanite.model._shares.LINE_GAIN_SHARE`, spent only once a line is accepted) over the lines offered and
the channels given, and (2) held out it predicts better: the blocks split in two alternate halves, the constant
line and the line with its gain each fitted on one half and scored on the other (the squared phasor errors
weighted by 1/u_k), their summed ratio below 1 — held out as the line's amplitudes are, refitted on held-in
blocks. The component the gain adds, g·(x̃(t) − x̄)·Re(A·e^{2πif0t}) (x̃ the channel's moving average over an
eighth of a block, :func:`gain_component`), is taken out of the samples every step after the curve effects sees
(:meth:`._final.FinalModel.after_curve`): the change points and the checks of ``unexplained`` — among them the
``"line"`` check, which asks whether the line is the same along the record (:mod:`._line_check`). The line itself
stays, as every line the ``"sinusoid"`` candidate holds on the curve does; its term on the curve is then held at
the exact Allan variance of the modelled component, constant line and gain's part together
(:func:`modulated_held`), not at the line's power in the spectrum.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import ndimage, stats

from ...analysis import avar
from .._signatures import sinusoid_avar
from ._line_channel import block_means, inphase_fit
from ._line_constancy import line_constancy

__all__ = ["line_gain", "gain_component", "gain_params", "modulated_held"]


def _fit(ph: np.ndarray, w: np.ndarray, xk: np.ndarray) -> tuple[complex, float, float, float]:
    """Intercept A (at the weighted mean x̄), in-phase slope β, Sxx and x̄ of c_k on x̄_k (weights ``w``): the words'
    own fit (:func:`._line_channel.inphase_fit`), so the gain and the words read the same slope."""
    a, _, beta, sxx, xbar = inphase_fit(ph, w, xk)
    return a, beta, sxx, xbar


def _heldout_ratio(ph: np.ndarray, w: np.ndarray, xk: np.ndarray) -> float:
    """Held-out squared error of the line with its gain over the constant line's: alternate blocks as the two
    halves, each fitted on one and scored on the other (weights ``w`` = 1/u_k), summed over both ways."""
    idx = np.arange(ph.size)
    err_g = err_c = 0.0
    for k in (0, 1):
        inn, out = idx % 2 == k, idx % 2 != k
        a, beta, sxx, xbar = _fit(ph[inn], w[inn], xk[inn])
        g = beta / abs(a) if sxx > 0.0 and a != 0 else 0.0
        pred = a * (1.0 + g * (xk[out] - xbar))
        err_g += float(np.sum(w[out] * np.abs(ph[out] - pred) ** 2))
        err_c += float(np.sum(w[out] * np.abs(ph[out] - a) ** 2))  # A is the constant line's fit too
    return err_g / err_c if err_c > 0.0 else math.inf


def _one(r: dict, x: np.ndarray, fs: float, alpha: float) -> dict | None:
    ph, u = np.asarray(r["phasors"], dtype=complex), np.asarray(r["phasor_unit"], dtype=float)
    s2, d2 = float(r["noise_level"]), float(r["noise_dof"])
    edges_s = np.asarray(r["edges_s"], dtype=float)
    edges = np.round(edges_s * fs).astype(int)
    if x.ndim != 1 or x.size < edges[-1] or not (s2 > 0.0 and d2 > 0.0):
        return None
    xk = block_means(x, edges)
    w = 1.0 / u
    a, beta, sxx, xbar = _fit(ph, w, xk)
    if not sxx > 0.0 or a == 0:
        return None
    f1, thr = 2.0 * sxx * beta**2 / s2, float(stats.f.isf(alpha, 1, d2))
    sd = math.sqrt(s2 / (2.0 * sxx)) / abs(a)  # β's SD over |A|: g's ±1 SD
    g = beta / abs(a)
    return {
        "gain": g,
        "gain_interval": (g - sd, g + sd),
        "mean": xbar,
        "phasor": (a.real, a.imag),
        "statistic": float(f1),
        "threshold": thr,
        "alpha": alpha,
        "heldout_ratio": _heldout_ratio(ph, w, xk),
        "centres_s": ((edges_s[:-1] + edges_s[1:]) / 2).tolist(),
        "block_means": xk.tolist(),
    }


def line_gain(y: np.ndarray, fs: float, f0: float, channels: dict, alpha: float) -> dict | None:
    """The channel the line at ``f0`` Hz of ``y`` follows in amplitude, kept by its nested F test at ``alpha``
    (split over the channels) and a held-out ratio below 1 (module docstring), or None. Returns ``{"channel",
    "gain" (relative change per channel unit), "gain_interval" (±1 SD), "mean" (x̄), "phasor" (A as (re, im)),
    "statistic", "threshold", "alpha", "heldout_ratio", "centres_s", "block_means"}`` for the passing channel of
    largest F."""
    if not channels:
        return None
    r = line_constancy(np.asarray(y, dtype=float), fs, f0, alpha, phasors=True)
    if r is None or int(r["blocks"]) < 4:
        return None
    best = None
    for name, x in channels.items():
        one = _one(r, np.asarray(x, dtype=float), fs, alpha / len(channels))
        if one is None or not one["statistic"] > one["threshold"] or not one["heldout_ratio"] < 1.0:
            continue
        if best is None or one["statistic"] > best["statistic"]:
            best = one | {"channel": name}
    return best


#: The channel in a line's gain component is its moving average over this share of a block: what the blocks
#: resolve of it (≤ 1/(2·block)) is kept to within 1 % (sinc(π/16) = 0.994), its own sensor noise averaged out.
SMOOTH_SHARE = 1.0 / 8.0


def gain_component(n: int, fs: float, f0: float, gain: dict, x: np.ndarray) -> np.ndarray:
    """The samples the gain adds to the constant line (module docstring): g·(x̃(t) − x̄)·Re(A·e^{2πif0t}) over
    ``n`` samples at ``fs``, x̃ the channel ``x`` (the one the gain was fitted on) as its moving average over
    :data:`SMOOTH_SHARE` of a block. Not the block means interpolated between the blocks' centres: g is the
    gain of the channel itself (the phasors and the block means weigh it alike), and the interpolated means
    flatten a channel's turns — on a temperature cycling three times over 16 blocks the record less that
    component still showed 9 % of the gain (g 0.0024 of 0.026), less this one none."""
    t = np.arange(n) / fs
    edges_s = np.asarray(gain["centres_s"])
    width = max(1, int(round(SMOOTH_SHARE * fs * float(np.mean(np.diff(edges_s))))) if edges_s.size > 1 else 1)
    xt = ndimage.uniform_filter1d(np.asarray(x, dtype=float)[:n], width, mode="nearest")
    line = np.real(complex(*gain["phasor"]) * np.exp(2j * np.pi * f0 * t))
    return gain["gain"] * (xt - gain["mean"]) * line


def modulated_held(n: int, fs: float, f0: float, gain: dict, x: np.ndarray, tau: np.ndarray, amp_sd: float):
    """The coefficient of a line with its gain on the unit sinusoid column at ``tau`` (:func:`.sinusoid_avar`), its
    variance and its coherent share: the exact overlapping Allan variance of the component reconstructed from
    the fit, Re(A·e^{2πif0t})·(1 + g·(x̃(t) − x̄)) (:func:`gain_component`'s x̃), projected on that column by
    least squares — the modelled line's own Allan variance, in place of its power in the spectrum, which with a
    gain also took noise beside the line (``temp200`` of ``benches/r13gain.py``, seed 1: the power 1.7 % above
    the simulated line's Allan variance plus its cross term with the noise, the rebuilt component 0.2 % below
    that sum — 0.8 % below the line alone, the cross term coming with A). The modulation is slow
    against 1/f0, so the component's curve is the column's shape to within 10⁻⁴ there. Variance to first order:
    ``amp_sd`` (|A|'s SD) and the gain's ±1 SD, θ ≈ |A|²·(1 + g²·v). Coherent share |A|²/θ: the modulation's
    sidebands are held like a line's incoherent part (:func:`.calibrated.curve_test`)."""
    t = np.arange(n) / fs
    const = np.real(complex(*gain["phasor"]) * np.exp(2j * np.pi * f0 * t))
    comp = const + gain_component(n, fs, f0, gain, x)
    res = avar(comp, fs, taus=np.asarray(tau, dtype=float))
    col = sinusoid_avar(res.tau, f0, fs)
    theta = float(np.dot(res.avar, col) / np.dot(col, col))
    a2, g = abs(complex(*gain["phasor"])) ** 2, float(gain["gain"])
    g_sd = (gain["gain_interval"][1] - gain["gain_interval"][0]) / 2.0
    d_amp = 2.0 * theta / math.sqrt(a2) if a2 > 0 else 0.0
    d_gain = 2.0 * (theta - a2) / g if g != 0 else 0.0
    var = (d_amp * amp_sd) ** 2 + (d_gain * g_sd) ** 2
    return theta, var, min(1.0, a2 / theta) if theta > 0 else 0.0


def gain_params(line: dict, params: dict, intervals: dict) -> tuple[dict, dict]:
    """A line's step parameters with its gain where it has one: ``channel`` and ``gain`` (relative change of the
    amplitude per unit of the channel, ±1 SD interval)."""
    g = line.get("gain")
    if not g:
        return params, intervals
    return params | {"channel": g["channel"], "gain": g["gain"]}, intervals | {"gain": tuple(g["gain_interval"])}
