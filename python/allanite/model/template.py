"""A periodic waveform of any shape, estimated by folding the record on its period (epoch averaging).

A line family of harmonics k·f0 (:mod:`allanite.model.periodic`) is a waveform repeating every 1/f0 s. Fitting
it line by line reaches only the harmonics the line search and its targeted test find; a waveform with a jump
(a sawtooth, a square wave, a PWM duty cycle, a motor's cogging), sampled, has harmonics of every order, and
those beyond f_s/2 fold back into the band (a 2.3 Hz sawtooth at 400 Hz: lines at every multiple of 0.1 Hz),
far too weak each to be found, yet together a few per cent of the waveform's power — lines left wherever the
noise is low (a moving average's nulls). Folding takes them all at once, whatever the shape: sample n lies at
the phase u_n = frac(f0·n/f_s) of the waveform; the mean of the samples in each of B phase bins is the
waveform there (the noise, spread over every cycle of the record, averages out), and the component at any
sample is its bin's mean. Linear in the samples, O(N) (two ``bincount``).

The number of bins trades resolution (a bin's mean is the waveform averaged over 1/B of a period) against
noise (each bin's mean carries the noise of N/B samples, and the removal takes B of the record's N degrees of
freedom): :func:`fit_template` chooses B among the powers of two by the held-out residual power — alternate
blocks in time (the odd ones predicting the even ones and back), the template folded on one part and
subtracted from the other. A period of P = p/q samples (a rate and a fundamental in a rational ratio: 400 Hz and
2.3 Hz, p = 4000) puts the samples at exactly p distinct phases; bins finer than their spacing hold one each and
the waveform as sampled is exact — the projection onto the p-periodic sequences, every folded harmonic in it,
nothing aliased from elsewhere — and those bins are used (a coarser bin's mean mixes phases, and its noise
comes from every frequency: removed, it leaves lines where the record's noise is low).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._recent import Recent

__all__ = ["Template", "fit_template", "fold", "MIN_PER_BIN", "MAX_BINS", "HELDOUT_BLOCKS"]

#: Fewest samples per phase bin (on the held-in half of the record) a number of bins may leave.
MIN_PER_BIN = 16
#: Most phase bins tried (a period of up to this many distinct sample phases is resolved exactly).
MAX_BINS = 2**16
#: Fewest phase bins tried.
MIN_BINS = 8
#: Alternate blocks in time for the choice of the number of bins (as refine's held-out error).
HELDOUT_BLOCKS = 8


#: :func:`_phase_bins`' last results by the indices' content, ν and B, within a refine: a template's fold, its
#: spread, its component and its refits on the held-out parts ask for the same indices' bins (19 calls, 3 distinct,
#: in one refine of the line-family sensor of ``tests/sensors.py``: the last two kept find 13 of the 16 repeats,
#: four kept all 16 for ≈ 8 MB more per 10⁶ samples each).
_BINNED = Recent(2, 4_000_000)


def _phase_bins(idx: np.ndarray, nu: float, bins: int) -> np.ndarray:
    """The phase bin of each sample index: ⌊B·frac(ν·n)⌋ (ν in cycles per sample); read-only (:data:`_BINNED`)."""
    idx = np.asarray(idx)
    key = (float(nu), int(bins))
    got = _BINNED.get(idx, key)
    if got is None:
        u = np.asarray(idx, dtype=np.float64) * nu
        u -= np.floor(u)
        got = np.minimum((u * bins).astype(np.int64), bins - 1)
        got.flags.writeable = False
        got = _BINNED.put(idx, key, got)
    return got


def fold(samples: np.ndarray, idx: np.ndarray, nu: float, bins: int) -> tuple[np.ndarray, np.ndarray]:
    """The mean of ``samples`` (taken at sample indices ``idx``) in each of ``bins`` phase bins of the period
    1/ν samples, and each bin's count; a bin no sample fell in takes the circular linear interpolation of its
    neighbours (a period of a whole number of samples fills only that many bins)."""
    k = _phase_bins(idx, nu, bins)
    count = np.bincount(k, minlength=bins).astype(np.float64)
    total = np.bincount(k, weights=np.asarray(samples, dtype=np.float64), minlength=bins)
    full = count > 0
    mean = np.zeros(bins)
    mean[full] = total[full] / count[full]
    if not full.all() and full.any():
        centres = np.arange(bins, dtype=np.float64)
        have = np.flatnonzero(full)
        mean[~full] = np.interp(centres[~full], centres[have], mean[have], period=bins)
    return mean, count


@dataclass
class Template:
    """A periodic waveform of fundamental ``f0`` (Hz) as ``bins`` phase-bin means (``values``, rate unit, mean
    zero over the record's samples), folded on ``n`` samples at ``fs``; ``counts`` the samples per bin;
    ``heldout`` the held-out residual power per number of bins tried ({bins: ratio to the power without it});
    ``spread`` each bin's sample variance about its mean (the noise, for :attr:`rms` and its SD)."""

    fs: float
    f0: float
    bins: int
    values: np.ndarray
    counts: np.ndarray
    n: int
    heldout: dict
    spread: np.ndarray

    @property
    def nu(self) -> float:
        """The fundamental in cycles per sample."""
        return self.f0 / self.fs

    def component(self, idx: np.ndarray | None = None) -> np.ndarray:
        """The waveform at sample indices ``idx`` (all ``n`` samples by default)."""
        idx = np.arange(self.n) if idx is None else np.asarray(idx, dtype=np.int64)
        return self.values[_phase_bins(idx, self.nu, self.bins)]

    def refit(self, samples: np.ndarray, idx: np.ndarray):
        """The template folded on ``samples`` taken at indices ``idx`` (the held-in blocks), the fundamental and
        the number of bins fixed; returns the component as a function of sample indices."""
        mean, count = fold(samples, idx, self.nu, self.bins)
        mean = mean - float(mean @ count) / max(float(count.sum()), 1.0)
        nu, bins = self.nu, self.bins
        return lambda i: mean[_phase_bins(np.asarray(i, dtype=np.int64), nu, bins)]

    @property
    def rms(self) -> float:
        """RMS of the waveform over the record, less the bins' own noise (each bin's mean carries the noise of
        its samples: E[v̂²] = v² + s²/c): √max(0, Σ_b c_b·(v_b² − s_b²/c_b) / Σ_b c_b)."""
        c = self.counts
        return float(math.sqrt(max(0.0, float(c @ self.values**2 - self.spread.sum()) / max(c.sum(), 1.0))))

    @property
    def rms_sd(self) -> float:
        """SD of :attr:`rms` from the bins' noise (delta method: var v̂_b² ≈ 4v_b²·s_b²/c_b)."""
        r = self.rms
        if r <= 0:
            return float("nan")
        c = self.counts
        var_ms = float(np.sum(4.0 * c * self.values**2 * self.spread)) / max(float(c.sum()), 1.0) ** 2
        return math.sqrt(var_ms) / (2.0 * r)


def _sides(y: np.ndarray, u: np.ndarray) -> tuple[list, np.ndarray]:
    """The record's alternate blocks (:data:`HELDOUT_BLOCKS`; the even ones, then the odd ones, each joined end to
    end): per side its samples' phases, its samples and them less their mean; and the phases of the samples after
    the last whole block. Gathered once for every number of bins tried."""
    per = y.size // HELDOUT_BLOCKS
    sides = []
    for parity in (0, 1):
        at = np.concatenate([np.arange(j * per, (j + 1) * per) for j in range(HELDOUT_BLOCKS) if j % 2 == parity])
        v = y[at]
        sides.append((u[at], v, v - v.mean()))
    return sides, u[HELDOUT_BLOCKS * per :]


def _heldout_power(sides: list, tail: np.ndarray, bins: int) -> tuple[float, int]:
    """Residual power of each side (:func:`_sides`) with the template folded on the other side subtracted, both
    ways, over their power without it; and how many of the ``bins`` phase bins the record's samples fill."""
    k = [np.minimum((u * bins).astype(np.int64), bins - 1) for u, _v, _z in sides]
    counts = [np.bincount(kk, minlength=bins) for kk in k]
    num = den = 0.0
    for held_in, held_out in ((0, 1), (1, 0)):
        count = counts[held_in].astype(np.float64)
        total = np.bincount(k[held_in], weights=sides[held_in][1], minlength=bins)
        mean = np.where(count > 0, total / np.maximum(count, 1.0), 0.0)
        if not (count > 0).all():
            have = np.flatnonzero(count > 0)
            mean = np.interp(np.arange(bins, dtype=np.float64), have.astype(np.float64), mean[have], period=bins)
        comp = mean[k[held_out]]
        z = sides[held_out][2]
        r = z - (comp - comp.mean())
        num, den = num + float(r @ r), den + float(z @ z)
    in_tail = np.bincount(np.minimum((tail * bins).astype(np.int64), bins - 1), minlength=bins)
    filled = int(np.count_nonzero(counts[0] + counts[1] + in_tail))
    return (num / den if den > 0 else math.inf), filled


def _exact_bins(filled: dict) -> int | None:
    """The fewest bins that hold the samples' distinct phases one each, when there are few of them: the finest
    bins tried left at least half empty (a continuum of phases would fill them: each gets ≥ MIN_PER_BIN samples on
    average), and the smallest number of bins that already separates (nearly) all the phases the finest does."""
    top = max(filled)
    if filled[top] > top // 2:
        return None
    return int(min(b for b, k in filled.items() if k >= 0.98 * filled[top]))


def fit_template(y, fs: float, f0: float, bins=None) -> Template:
    """The waveform of fundamental ``f0`` (Hz) in the samples ``y`` at ``fs`` Hz, by folding (module docstring);
    ``bins`` fixes the number of phase bins, else it is chosen by the held-out residual power — or, where the
    samples fall on few distinct phases (a period of p/q samples), the fewest bins that hold them one each: the
    waveform as sampled, exactly, whose held-out power is at most a few 0.1 % above the best coarser binning's
    (the noise of p means) while a coarser one aliases noise from every frequency into lines at the folded
    harmonics (176 of them on a 2.3 Hz sawtooth at 400 Hz beside a moving average's noise nulls; none this way).

    Examples
    --------
    >>> import numpy as np
    >>> from scipy import signal
    >>> from allanite.model.template import fit_template
    >>> n, fs = 200_000, 400.0
    >>> saw = 0.05 * signal.sawtooth(2 * np.pi * 2.3 * np.arange(n) / fs)
    >>> y = saw + np.random.default_rng(1).normal(0.0, 0.01, n)
    >>> t = fit_template(y, fs, 2.3)
    >>> round(t.rms / (0.05 / 3**0.5), 2), round(float(np.std(saw - t.component())) / 0.05, 2)
    (1.0, 0.03)
    """
    y = np.asarray(y, dtype=np.float64)
    n = y.size
    nu = float(f0) / float(fs)
    heldout: dict = {}
    if bins is None:
        u = np.arange(n, dtype=np.float64) * nu
        u = (u - np.floor(u)).astype(np.float32)
        sides, tail = _sides(y, u)
        top = min(MAX_BINS, max(MIN_BINS, (n // 2) // MIN_PER_BIN))
        b, filled = MIN_BINS, {}
        while b <= top:
            heldout[b], filled[b] = _heldout_power(sides, tail, b)
            b *= 2
        bins = _exact_bins(filled)
        if bins is None:
            bins = int(min(heldout, key=lambda b: heldout[b]))
    mean, count = fold(y, np.arange(n), nu, int(bins))
    mean = mean - float(mean @ count) / max(float(count.sum()), 1.0)
    # each bin's mean: the variance of its samples about it over their number
    k = _phase_bins(np.arange(n), nu, int(bins))
    ss = np.bincount(k, weights=(y - y.mean() - mean[k]) ** 2, minlength=int(bins))
    spread = np.where(count > 1, ss / np.maximum(count - 1.0, 1.0), 0.0)
    return Template(float(fs), float(f0), int(bins), mean, count, n, heldout, spread)
