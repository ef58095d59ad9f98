"""A channel regression's regressors (:mod:`allanite.model.channels`): the channel's signal bands — where it stands
above its own white measurement noise (:func:`channel_signal`) — and, built on them, the channel (through a lag),
its square and its derivative (:func:`regressors`), with their design in band space (:func:`regressor_design`).
Below :mod:`allanite.model.channels` and its tests (:mod:`allanite.model._coupling`)."""

from __future__ import annotations

import math

import numpy as np

from . import _whittle as wh
from ._lag import lagged
from ._rfft import band_limited, rfft
from ._staircase import ChannelForm, channel_form, reading_index, reading_rate, reconstructed

__all__ = [
    "CHANNEL_SNR",
    "channel_signal",
    "form_signal",
    "read_channel",
    "regressors",
    "regressor_iter",
    "regressor_design",
]


#: A band of the channel takes part only where its power is this many times its measurement noise's.
CHANNEL_SNR = 20.0


def channel_signal(x: np.ndarray, fs: float) -> tuple[float, list | None]:
    """The channel's white measurement noise per sample (variance) and the frequency intervals (Hz) where it
    stands above it, from one periodogram of its differences.

    The floor: the median of P_k/s_k² (s_k = 2 sin(πk/M)) over the upper half of the band (f ≥ f_s/4), over
    ln 2 (an exponential's median is ln 2 × its mean). The intervals: merged runs of the bands of
    :mod:`allanite.model._whittle` whose power is at least :data:`CHANNEL_SNR` × the floor's (σ²·s²); None
    when that is every band (no noise to keep out)."""
    d = np.diff(x)
    n_bins = d.size // 2
    p = np.abs(rfft(d)[1 : n_bins + 1]) ** 2 / d.size  # remembered: band_limited transforms it again
    k = np.arange(1, n_bins + 1)
    s2 = 4.0 * np.sin(np.pi * k / d.size) ** 2
    top = k >= d.size // 4
    floor = float(np.median(p[top] / s2[top]) / math.log(2.0)) if top.any() else 0.0
    starts = wh.band_starts(n_bins)
    ok = np.add.reduceat(p, starts - 1) >= CHANNEL_SNR * floor * np.add.reduceat(s2, starts - 1)
    if ok.all():
        return floor, None
    ends = np.append(starts[1:], n_bins + 1)
    out: list = []
    for a, b in zip(starts[ok], ends[ok]):
        lo, hi = (0.0 if a == 1 else float((a - 0.5) * fs / d.size)), float((b - 0.5) * fs / d.size)
        if out and abs(out[-1][1] - lo) < 1e-12 * fs:
            out[-1] = (out[-1][0], hi)
        else:
            out.append((lo, hi))
    return floor, out or [(0.0, 0.0)]


def form_signal(xr: np.ndarray, fs: float, form: ChannelForm) -> tuple[float, list | None]:
    """:func:`channel_signal` of a channel read back from its form (``xr``,
    :func:`allanite.model._staircase.reconstructed`): a held channel's on its own readings at their own rate —
    its floor is the readings' noise, not the joining's, and nothing above half the reading rate is signal (only
    the hold's images are there)."""
    if form.hold == 1:
        return channel_signal(xr, fs)
    rate = reading_rate(fs, form)
    floor, sig = channel_signal(xr[reading_index(xr.size, form.hold, form.phase)], rate)
    return floor, sig if sig is not None else [(0.0, 0.5 * rate)]


def read_channel(x: np.ndarray, fs: float) -> tuple[ChannelForm, float, list | None, np.ndarray]:
    """A channel as the regressions read it: its form detected (:func:`allanite.model._staircase.channel_form`)
    and read back, its floor and signal bands (:func:`form_signal`), and the channel band-limited to them. Returns
    (form, floor, signal bands, band-limited channel)."""
    form = channel_form(x)
    xr = reconstructed(x, form)
    floor, sig = form_signal(xr, fs, form)
    return form, floor, sig, band_limited(xr, fs, sig)


def regressors(xs: np.ndarray, mean: float, quad_mean: float, fs: float, lag_s: float | None) -> list:
    """The regressors from the channel's signal bands (``xs``, :func:`band_limited`): the channel (through the
    lag), its square and its derivative. The sensor responds to the true temperature, not to the logging
    sensor's noise, and that noise — squared, differentiated, or only weighed where the gyro's noise is low —
    would bias every coefficient toward zero: a d(ch)/dt coupling of 0.1 rad/s per °C/s came out as 0.019
    through a temperature logged to 0.01 °C with 0.02 °C of noise (0.095–0.102 from its signal bands)."""
    return list(regressor_iter(xs, mean, quad_mean, fs, lag_s))


def regressor_iter(xs: np.ndarray, mean: float, quad_mean: float, fs: float, lag_s: float | None):
    """:func:`regressors` one at a time, for :func:`allanite.model._whittle.spectra` to transform each and let it
    go: the three columns at once were 3× the record beside their transforms (a 10⁷-sample temperature's
    regression peaked at 13× the rate record)."""
    xm = xs - mean
    yield lagged(xm, lag_s, fs) if lag_s else xm
    yield xm**2 - quad_mean
    del xm
    yield np.gradient(xs) * fs


def regressor_design(keys, nb: int, level: bool = True) -> wh.Design:
    """The design of the channel (where ``level``; the level term dropped by its nested test otherwise,
    :func:`allanite.model._coupling.optional_terms`) and the optional terms among ``keys``, in that order."""
    one = np.ones(nb)
    d = wh.Design([0], [one]) if level else wh.Design([], [])
    if "quadratic" in keys:
        d = d.plus(1, one)
    if "rate_coefficient" in keys:
        d = d.plus(2, one)
    return d
