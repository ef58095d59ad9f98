"""``allantools.noise``: white, random-walk (brown), violet and flicker (pink) noise, and two PSD helpers.

Every generator draws from NumPy's global random state (``numpy.random.seed`` makes it repeatable)
and is a filter of white noise, N. J. Kasdin and T. Walter, *Discrete simulation of power law
noise*, Proc. IEEE FCS 1992 (:func:`allanite.simulation.power_law_filter`): one-sided PSD
S(f) = b·f^β up to the Nyquist frequency fs/2 with

* ``white``  β = 0: samples of variance b0·fs/2;
* ``brown``  β = −2: the running sum (the filter for α = 2) of white noise of PSD 4π²·b₋₂, divided by fs;
* ``violet`` β = 2: the first difference (α = −2) of white noise of PSD b2/(2π)², times fs;
* ``pink``   β = −1: the α = 1 (flicker) filter of white noise of variance 4, so S(f) ≈ (4/π)/f for
  fs = 1 — the level of allantools' Voss–McCartney generator in its 1/f band (measured 1.2–1.34/f).

Their levels and spectra are allantools'; the random draws are not. ``pink`` is flicker noise down
to the lowest frequency of the record (allantools' generator turns white below ≈ fs/256 and adds a
random offset); its ``depth`` is accepted and unused.
"""

from __future__ import annotations

import math

import numpy as np

from .._validate import check_count, check_nonnegative, check_positive
from ..simulation import power_law_filter

__all__ = ["white", "brown", "violet", "pink", "numpy_psd", "scipy_psd"]


def _count(num_points) -> int:
    return check_count(num_points, "num_points", 0)


def white(num_points=1024, b0=1.0, fs=1.0):
    """White noise of one-sided PSD ``b0`` up to fs/2: √(b0·fs/2)·N(0, 1).

    Examples
    --------
    >>> import numpy as np
    >>> from allanite.compat import noise
    >>> np.random.seed(1)
    >>> x = noise.white(100000, b0=2.0, fs=10.0)
    >>> round(float(x.var()), 1)       # b0·fs/2
    10.0
    """
    n = _count(num_points)
    scale = math.sqrt(check_nonnegative(b0, "b0") * check_positive(fs, "fs") / 2.0)
    return scale * np.random.standard_normal(n)


def brown(num_points=1024, b_minus2=1.0, fs=1.0):
    """Random-walk (Brownian) noise of PSD b₋₂·f⁻²: the running sum of white noise, divided by fs."""
    fs = check_positive(fs, "fs")
    w = white(num_points, b0=4.0 * math.pi**2 * check_nonnegative(b_minus2, "b_minus2"), fs=fs)
    return np.cumsum(w) / fs  # Kasdin & Walter's α = 2 filter is the running sum


def violet(num_points=1024, b2=1, fs=1):
    """Violet noise of PSD b2·f²: fs times the first difference of num_points + 1 white samples."""
    fs = check_positive(fs, "fs")
    w = white(_count(num_points) + 1, b0=check_nonnegative(b2, "b2") / (2.0 * math.pi) ** 2, fs=fs)
    return fs * np.diff(w)  # the α = −2 filter is the first difference


def pink(num_points=1024, depth=80):
    """Flicker (1/f) noise, S(f) ≈ (4/π)/f at fs = 1: Kasdin & Walter's α = 1 filter of white noise of
    variance 4. ``depth`` (the rows of allantools' Voss–McCartney generator) is accepted and unused."""
    n = _count(num_points)
    w = 2.0 * np.random.standard_normal(n)
    return power_law_filter(w, 1.0) if n > 1 else w


def numpy_psd(x, f_sample=1.0):
    """One-sided periodogram 2|FFT(x)|²/(N·f_sample) on the rfft frequencies 0 … f_sample/2:
    (frequencies, PSD) in x's units²/Hz."""
    x = np.asarray(x, dtype=np.float64)
    psd = 2.0 / (x.size * float(f_sample)) * np.abs(np.fft.rfft(x)) ** 2
    return np.linspace(0.0, float(f_sample) / 2.0, psd.size), psd


def scipy_psd(x, f_sample=1.0, nr_segments=4):
    """Welch's PSD (scipy.signal.welch) with ``nr_segments`` segments: (frequencies, PSD)."""
    from scipy.signal import welch

    x = np.asarray(x, dtype=np.float64)
    return welch(x, f_sample, nperseg=int(x.size / nr_segments))
