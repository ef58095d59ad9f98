"""Sharp rippled low-passes as kinds of the bandwidth effect: the elliptic and Chebyshev IIRs and equiripple
FIR decimators of MEMS and tactical parts, whose passband ripples before a steep roll-off.

What an Allan curve tells apart among them (measured at 2·10⁵ samples, 54 τ from one sample to n/20, each AVAR
weighted by its EDF-based SD, cutoff and amplitude fitted; ``benches/results/r18sharp.md``): the passband's ripple
and its sign, much more than the design. Normalised to unit gain at DC, an even-order Chebyshev or elliptic (DC at
a trough of the ripple) rises above DC before the cutoff and lifts the curve over N²/τ near τ ≈ 1/(2f_c); an odd
order (DC at a peak) dips. An elliptic of order 4 and 1 dB against a Butterworth-6 at its best cutoff: χ² 751,
against an elliptic of order 6 and 1 dB: 108, of order 6 and 0.5 dB: 251; a Chebyshev I of order 5 and 1 dB
against an elliptic of order 5 and 1 dB: 22, and of order 6 and 0.1 dB: 714. Ripples of 0.1 dB and less (a
remez FIR decimator's) leave a curve a Butterworth-6 fits within χ² 5–40. The steepness of the transition
matters next (an elliptic 6/60 dB and a 4/40 dB design differ by ~100–400 at the same ripple).

So a sharp kind is a fixed design family with two parameters, the cutoff f_c (searched, as a Butterworth's) and
the signed ripple r in dB (named in the kind, searched on :data:`SHARP_RIPPLES` and then between its
neighbours): ``"elliptic6:<r>"`` is ``scipy.signal.ellip(order, |r|, 60, f_c, fs=f_s)`` of order 6 where r > 0
(the gain rises |r| dB above DC) and 5 where r < 0 (it dips |r| dB below DC); ``"elliptic4:<r>"`` the milder
transition, orders 4 and 3 with a 40 dB stop band. f_c is the passband's edge (where the gain leaves the ripple
band), its −3 dB frequency reported beside it (:func:`sharp_cutoff`). Its autocorrelation is closed
(:func:`allanite.model.effects.rational_terms`, the residues at its poles), exact for the sampled filter; a
decimated part's aliasing folds its stop band, which neither design holds (a Chebyshev I at 4× the output rate
fits to χ² ~90 where a Butterworth-6 leaves 229).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ..errors import ParameterError

__all__ = ["SHARP_DESIGNS", "SHARP_RIPPLES", "RIPPLE_RANGE", "sharp_kind", "sharp_of", "sharp_zpk", "sharp_cutoff"]

#: The sharp designs: name → (order where the ripple is positive, stop-band attenuation dB, decimation); the
#: order is one less where the ripple is negative (odd: DC at a peak of the ripple). A decimation D > 1: the filter
#: runs at D·f_s and every D-th output is kept, its stop band above f_s/2 folded into the output's band.
SHARP_DESIGNS: dict[str, tuple[int, float, int]] = {
    "elliptic4": (4, 40.0, 1),
    "elliptic6": (6, 60.0, 1),
    "elliptic4_dec4": (4, 40.0, 4),
    "elliptic6_dec4": (6, 60.0, 4),
}
#: The signed ripples (dB) each design is searched at before its ripple is refined between neighbours.
SHARP_RIPPLES = (-2.0, -0.7, -0.25, 0.25, 0.7, 2.0)
#: The range of |ripple| (dB) a sharp kind may have.
RIPPLE_RANGE = (0.05, 3.0)


def sharp_kind(design: str, ripple: float) -> str:
    """The bandwidth kind of the sharp ``design`` (:data:`SHARP_DESIGNS`) with signed passband ripple ``ripple`` dB
    (three significant digits: the name is the kind's key)."""
    if design not in SHARP_DESIGNS:
        raise ParameterError(f"sharp filter design {design!r}: must be one of {tuple(SHARP_DESIGNS)}")
    lo, hi = RIPPLE_RANGE
    if not lo <= abs(ripple) <= hi:
        raise ParameterError(f"sharp filter ripple {ripple!r} dB: its size must lie in [{lo}, {hi}] dB, either sign")
    return f"{design}:{float(f'{ripple:.3g}')!r}"


def sharp_of(kind: str) -> tuple[int, float, float, int] | None:
    """(order, |ripple| dB, stop band dB, decimation) of a sharp kind ("elliptic6:-0.5" → (5, 0.5, 60.0, 1)); None
    for another kind."""
    design, sep, tail = kind.partition(":")
    if not sep or design not in SHARP_DESIGNS:
        return None
    try:
        ripple = float(tail)
    except ValueError:
        return None
    order, stop, dec = SHARP_DESIGNS[design]
    return (order if ripple > 0 else order - 1), abs(ripple), stop, dec


@functools.lru_cache(maxsize=4096)
def sharp_zpk(kind: str, fc: float, fs: float) -> tuple[np.ndarray, np.ndarray, float]:
    """Zeros, poles and gain of the sharp ``kind`` with passband edge ``fc`` Hz for output samples at ``fs``, the
    filter at its own rate (D·``fs``; remembered, read-only)."""
    from scipy import signal

    got = sharp_of(kind)
    if got is None:
        raise ParameterError(f"bandwidth kind {kind!r}: not a sharp kind ({tuple(SHARP_DESIGNS)} with a ripple)")
    if not 0.0 < fc < fs / 2.0:
        raise ParameterError(f"sharp filter cutoff {fc!r} Hz: must lie in (0, fs/2 = {fs / 2.0!r})")
    order, ripple, stop, dec = got
    zeros, poles, k = signal.ellip(order, ripple, stop, fc, fs=fs * dec, output="zpk")
    zeros.flags.writeable = poles.flags.writeable = False
    return zeros, poles, float(k)


def sharp_cutoff(kind: str, fc: float, fs: float) -> float:
    """−3 dB frequency (Hz) of the sharp ``kind`` at passband edge ``fc``: where its power, at the rate it runs at,
    falls to half its value at DC (a fine grid, then linear between its two points); ``fs``/2 at fc ≥ fs/2."""
    from scipy import signal

    if fc >= fs / 2.0:
        return float(fs / 2.0)
    dec = SHARP_DESIGNS[kind.partition(":")[0]][2]
    f, h = signal.freqz_zpk(*sharp_zpk(kind, float(fc), float(fs)), worN=1 << 14, fs=fs * dec)
    power = np.abs(h) ** 2
    half = 0.5 * power[0]
    below = np.flatnonzero(power <= half)
    if not below.size:
        return float(fs / 2.0)
    j = int(below[0])
    if j == 0:
        return 0.0
    p0, p1 = power[j - 1], power[j]
    return float(f[j - 1] + (f[j] - f[j - 1]) * (p0 - half) / (p0 - p1)) if math.isfinite(p0 - p1) else float(f[j])
