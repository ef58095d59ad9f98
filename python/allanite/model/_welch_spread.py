"""How unequal a Welch average's segments are, band by band: the line search's degrees of freedom where the noise
is not stationary.

Welch's equivalent degrees of freedom (:func:`allanite.model.lines._edof`) hold for segments of one expected power.
Where the power differs between segments — a pump switched on for three stretches of a record, a noise level that
doubles halfway — the average of K periodograms scatters as one of K_eff = (Σ σ_s²)² / Σ σ_s⁴ equal ones (σ_s² the
s-th segment's expected power at that frequency; Satterthwaite): the F test against the neighbours' median, with
the dof of K segments, then takes the average's own scatter for lines. Each segment's level in a band of
:data:`BAND` bins is the median of its periodogram there (a line in the band does not move it); the ratio
K_eff/K, corrected for the medians' own scatter under stationarity (:data:`MEDIAN_SCATTER` / bins) and given
three of the ratio's own standard errors there, scales the dof of every bin of the band, at most 1 (a stationary
record's search is unchanged).

Measured on ``benches/refine_blind7.py``'s pump (200 Hz × 2·10⁶, a 20–40 Hz band noise on for 3 × 600 s, its
segments' powers there 144× apart): K_eff 24 of 121 segments in 19–31 Hz, and three sinusoids taken at 1.59–1.67×
the neighbours' median against the threshold 1.53 at the lines' α (with the spread: 2.4, none);
``tests/test_lines_nonstationary.py``: 24–39 false lines per record before, none after.
"""

from __future__ import annotations

import numpy as np

__all__ = ["BAND", "SegmentLevels"]

#: Bins per band whose level is read per segment (a band's median of 64 periodogram bins).
BAND = 64
#: Relative variance of the median of ``BAND`` bins of one Blackman–Harris periodogram of white noise, × ``BAND``
#: (measured: 4.2 at 64 bins, segments of 2048 and 32768 samples; an exponential's median alone gives 1/ln²2 ≈ 2.08,
#: the window's correlated bins raise it).
MEDIAN_SCATTER = 4.2


class SegmentLevels:
    """Collects each segment's band medians (call it with a group of periodograms, segments × bins) and gives the
    per-bin factor K_eff/K (:meth:`factor`)."""

    def __init__(self) -> None:
        self.levels: list[np.ndarray] = []

    def __call__(self, pw: np.ndarray) -> None:
        nb = pw.shape[1] // BAND
        if nb:
            self.levels.append(np.median(pw[:, : nb * BAND].reshape(pw.shape[0], nb, BAND), axis=2))

    def factor(self, n_bins: int) -> np.ndarray:
        """Per bin (0 … n_bins − 1): min(1, K_eff·(1 + v)/K·(1 + 3v·√(2/K))) of its band (the last partial band
        takes the one before it); ones where there are fewer than 4 segments or no whole band."""
        out = np.ones(n_bins)
        if not self.levels:
            return out
        lv = np.concatenate(self.levels, axis=0)
        k = lv.shape[0]
        if k < 4:
            return out
        s1, s2 = lv.sum(axis=0), (lv * lv).sum(axis=0)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(s2 > 0, s1 * s1 / s2 / k, 1.0) * (1.0 + MEDIAN_SCATTER / BAND)
        # under stationarity the ratio scatters by ≈ v·√(2/K) about 1 (v the medians' relative variance): three
        # of those are given, so that a stationary record's bands keep their dof
        v = MEDIAN_SCATTER / BAND
        ratio = np.minimum(ratio * (1.0 + 3.0 * v * np.sqrt(2.0 / k)), 1.0)
        band = np.minimum(np.arange(n_bins) // BAND, ratio.size - 1)
        return ratio[band]
