"""The channel regression's transforms, remembered by their input's content within a ``refine`` call.

A channel's regression (:mod:`.channels`, :mod:`._whittle`) transforms the same samples several times in one
refine, from places that do not share them: the channel's periodogram (its signal bands), its band-limited
version, the band sums of the joint fit, of the removal's held-out refits and of the final check's regression,
each on the differenced channel and the differenced rate — 42 real FFTs of 24 distinct inputs on a 10⁶-sample
record with a temperature channel. Each transform, and each band-limited channel, is remembered by its input's
content (the last few, inputs up to 2.1·10⁶ samples: :class:`._recent.Recent`, empty outside
:func:`._recent.remembering`), so the same input is transformed once: the same numbers, read-only.
"""

from __future__ import annotations

import numpy as np
from scipy import fft as sfft

from ._recent import Recent

__all__ = ["rfft", "band_limited"]

#: The transforms last computed, by their input's content (16 bytes per input sample with the kept copy).
_RFFT = Recent(5, 2_100_000)
#: :func:`band_limited`'s last results, by the channel's content and the bands.
_LIMITED = Recent(2, 2_100_000)


def rfft(z: np.ndarray) -> np.ndarray:
    """``scipy.fft.rfft(z)`` (read-only), remembered by ``z``'s content."""
    z = np.asarray(z)
    got = _RFFT.get(z)
    if got is None:
        got = sfft.rfft(z)
        got.flags.writeable = False
        got = _RFFT.put(z, (), got)
    return got


def band_limited(x: np.ndarray, fs: float, bands: list | None) -> np.ndarray:
    """``x`` with only the frequency intervals ``bands`` (Hz) of its differences kept (None: all), integrated
    back from the first sample (filtered as differences, so the record's two ends need not meet). Remembered
    by ``x``'s content (read-only): refine asks for the same channel's in its fit, its removal and the checks."""
    if bands is None:
        return x
    x = np.asarray(x)
    key = (float(fs), tuple((float(lo), float(hi)) for lo, hi in bands))
    got = _LIMITED.get(x, key)
    if got is None:
        d = np.diff(x)
        f = np.fft.rfftfreq(d.size, 1.0 / fs)
        mask = np.zeros(f.size, dtype=bool)
        mask[0] = True
        for lo, hi in bands:
            mask |= (f >= lo) & (f <= hi)
        got = x[0] + np.concatenate([[0.0], np.cumsum(sfft.irfft(rfft(d) * mask, d.size))])
        got.flags.writeable = False
        got = _LIMITED.put(x, key, got)
    return got
