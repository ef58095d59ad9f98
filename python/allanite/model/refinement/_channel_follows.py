"""``unexplained``'s ``"follows"`` check: an accepted line the model took — a ``"periodic"`` family removed in time,
a ``"sinusoid"`` — that follows a channel of ``channels=`` no regression step uses.

A channel that carries the line's period (a heater's PWM in the temperature, a fan's speed in a supply voltage) and
a rate whose line is coherent with it is one effect read twice: the line family explains the rate, but the channel
given beside it explains the line — a regression on the channel may be the better reading (blind12's heater with
its regression candidate left out: the 60 s sawtooth taken as a family, nothing said). Said, never removed.

The test, per (line, channel) pair: the record is cut into K segments of several periods; in each, the Hann-tapered
Fourier coefficients at the line's frequency f0 of the rate (with the family's removed component added back) and of
the channel (each de-trended in the segment), Y_k and X_k, phase-referenced to the record's start. Both must hold:

- the magnitude-squared coherence C = |Σ X̄_k Y_k|² / (Σ|X_k|² Σ|Y_k|²) exceeds its null: where the channel's
  X_k are independent circular Gaussian (it carries nothing phase-locked to the rate at f0), C ~ Beta(1, K − 1)
  whatever the Y_k — P(C > c) = (1 − c)^(K−1), exact;
- the channel carries a line at f0: Σ|X_k|² against the same at :data:`SIDE_BINS` frequencies on each side,
  ≥ 2 resolution bins away, F(2K, 2K·2·SIDE_BINS) under a locally white channel — a smooth channel's leakage
  (a once-swinging temperature), phase-locked by the segments' geometry though it holds no line, is not a line.

Both at ``a`` split over the pairs: the pair's false-alarm rate is at most that of either. Its share of ``level``
is conditional (:data:`.levels.CONDITIONAL_SHARES`, ``"unexplained:follows"``): it runs only once a line is
accepted and channels are given, so a clean record spends nothing on it; its rate on accepted lines beside channels
that do not carry them: benches/results/channel_follows_null.md.
"""

from __future__ import annotations

import numpy as np
from scipy.stats import f as f_dist

from ._missing_context import MissingContext
from .curvefit import base_name

__all__ = ["follows_check", "coherence_test", "MIN_SEGMENTS", "MAX_SEGMENTS", "PERIODS", "SIDE_BINS"]

#: Fewest segments the coherence is judged over (its null Beta(1, K − 1) needs K ≥ 2; with fewer than 6 a
#: coherent line and chance are hard to tell apart at a share of ``level``).
MIN_SEGMENTS = 6
#: Most segments: longer segments resolve f0 from its neighbours better once there are enough of them.
MAX_SEGMENTS = 32
#: Fewest periods of f0 in a segment (the Hann taper's main lobe is 2 bins: f0 stands clear of the mean).
PERIODS = 6
#: Frequencies on each side of f0 the channel's line is judged against (spaced by one bin, from 2 bins away).
SIDE_BINS = 4


def _coefficients(v: np.ndarray, fs: float, freqs: np.ndarray, k_seg: int) -> np.ndarray:
    """(K, len(freqs)) Hann-tapered Fourier coefficients of ``v`` in ``k_seg`` segments, each de-trended (a line
    fitted by least squares), phase-referenced to the record's start."""
    length = v.size // k_seg
    seg = v[: length * k_seg].reshape(k_seg, length).astype(np.float64)
    t = np.arange(length, dtype=np.float64)
    tc = t - t.mean()
    seg = seg - seg.mean(axis=1, keepdims=True)
    seg = seg - np.outer(seg @ tc / (tc @ tc), tc)
    basis = np.hanning(length)[:, None] * np.exp(-2j * np.pi * np.outer(t / fs, freqs))
    start = np.exp(-2j * np.pi * np.outer(np.arange(k_seg) * length / fs, freqs))
    return (seg @ basis) * start


def coherence_test(y: np.ndarray, x: np.ndarray, fs: float, f0: float) -> dict | None:
    """The coherence of ``y`` and the channel ``x`` at ``f0`` (Hz) over K segments, and the channel's line there
    (module docstring): ``"coherence"``, ``"p_coherence"``, ``"segments"``, ``"line_ratio"``, ``"p_line"``; None
    where the record holds fewer than :data:`MIN_SEGMENTS` × :data:`PERIODS` periods of ``f0`` or ``f0`` is within
    the side frequencies' reach of 0 or the Nyquist frequency."""
    cycles = y.size / fs * f0
    k_seg = int(min(MAX_SEGMENTS, cycles // PERIODS))
    if k_seg < MIN_SEGMENTS:
        return None
    bin_hz = fs / (y.size // k_seg)
    offsets = np.concatenate([np.arange(2, 2 + SIDE_BINS), -np.arange(2, 2 + SIDE_BINS)]) * bin_hz
    freqs = np.concatenate([[f0], f0 + offsets])
    if freqs.min() <= bin_hz or freqs.max() >= fs / 2 - bin_hz:
        return None
    yk = _coefficients(y, fs, freqs[:1], k_seg)[:, 0]
    xk = _coefficients(x, fs, freqs, k_seg)
    px = np.abs(xk) ** 2
    sx, sy = float(px[:, 0].sum()), float(np.sum(np.abs(yk) ** 2))
    coh = float(abs(np.vdot(xk[:, 0], yk)) ** 2 / (sx * sy)) if sx > 0 and sy > 0 else 0.0
    side = float(px[:, 1:].mean()) if px[:, 1:].size else 0.0
    ratio = sx / k_seg / side if side > 0 else (np.inf if sx > 0 else 0.0)
    dof_side = 2 * k_seg * 2 * SIDE_BINS
    return {
        "coherence": coh,
        "p_coherence": float((1.0 - coh) ** (k_seg - 1)),
        "segments": k_seg,
        "line_ratio": float(ratio),
        "p_line": float(f_dist.sf(ratio, 2 * k_seg, dof_side)) if np.isfinite(ratio) else 0.0,
    }


def _lines(ctx: MissingContext) -> list[tuple[str, float, np.ndarray | None]]:
    """The accepted lines to test: (effect, f0 Hz, removed component or None) — each removed family's strongest
    line with its component (added back to the samples), each sinusoid (its line is still in the samples)."""
    out: list[tuple[str, float, np.ndarray | None]] = []
    for _fund, freqs, amps, comp in ctx.families:
        if len(freqs):
            out.append(("periodic", float(np.asarray(freqs)[int(np.argmax(np.abs(amps)))]), comp))
    out += [("sinusoid", float(p), None) for k, p in ctx.effects if base_name(k) == "sinusoid"]  # p: its f0
    return out


def follows_check(ctx: MissingContext, a: float) -> list[dict]:
    """One entry per (accepted line, channel no regression step uses) whose line the channel carries coherently,
    both tests at ``a`` split over the pairs (module docstring)."""
    if ctx.y is None or not ctx.channels:
        return []
    used = {p.get("channel") for k, p in ctx.effects if base_name(k) == "regression" and isinstance(p, dict)}
    free = {name: np.asarray(ch, dtype=np.float64) for name, ch in ctx.channels.items() if name not in used}
    lines = _lines(ctx)
    if not free or not lines:
        return []
    a_pair, out = a / (len(free) * len(lines)), []
    for effect, f0, comp in lines:
        y = ctx.y if comp is None or comp.size != ctx.y.size else ctx.y + comp
        for name, x in free.items():
            r = coherence_test(y, x[: y.size], ctx.fs, f0)
            if r is None or not (r["p_coherence"] < a_pair and r["p_line"] < a_pair):
                continue
            lo, hi = max(0.2 / f0, float(ctx.curve.tau[0])), min(1.0 / f0, float(ctx.curve.tau[-1]))
            what = (
                f"the {effect} line the model took at {f0:.4g} Hz follows channel {name!r}, which carries it "
                f"(coherence {r['coherence']:.2f} over {r['segments']} segments): a regression on {name!r} may "
                f"be the better reading"
            )
            thr = 1.0 - a_pair ** (1.0 / (r["segments"] - 1))  # the coherence's critical value at a_pair
            out.append(
                {"domain": "channels", "tau": (lo, hi), "band_hz": (f0, f0), "chi2_dof": None}  # not the curve's
                | {"what": what, "channel": name, "effect": effect, "f0": f0}
                | r
                | {"statistic": r["coherence"], "threshold": thr, "alpha": a_pair}
            )
    return out
