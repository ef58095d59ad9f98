"""refine's speed-ups of round r6cost give the numbers of the computations they stand for, bit for bit.

The channel regression's transforms (:mod:`allanite.model._rfft`: a real FFT and a band-limited channel, each
remembered by its input's content) against fresh ones, and a whole ``refine`` with a temperature channel with
every memory against one that recomputes everything; the outlier replacement and the span a record is white for
remembered against fresh ones; the waveform template's choice of bins with its alternate
blocks gathered once against the plain gathering per number of bins. No timings here:
``benches/bench_refine_cost.py``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import fft as sfft
from scipy import signal

import allanite
from allanite.model import _rfft, channels, outliers, template
from allanite.model._recent import Recent, remembering


def test_remembered_transforms_equal_fresh_ones(monkeypatch):
    rng = np.random.default_rng(5)
    x = np.cumsum(rng.standard_normal(50_001)) * 1e-2 + rng.standard_normal(50_001) * 1e-3
    other = x + 1e-3
    bands = [(0.0, 0.05), (0.4, 0.6)]
    fresh_fft = sfft.rfft(np.diff(x))
    fresh = [_rfft.band_limited(v, 10.0, bands) for v in (x, other)]
    calls, plain_rfft = [], sfft.rfft
    monkeypatch.setattr(_rfft.sfft, "rfft", lambda z: calls.append(z.size) or plain_rfft(z))
    with remembering():
        got = [_rfft.band_limited(v, 10.0, bands) for v in (x, other)]
        again = _rfft.band_limited(x.copy(), 10.0, bands)  # a copy: found by content
        narrower = _rfft.band_limited(x, 10.0, bands[:1])  # other bands: computed, on the remembered transform
        spectrum = _rfft.rfft(np.diff(x))
        assert len(calls) == 2  # one transform per record's differences
    assert again is got[0] and not got[0].flags.writeable and not spectrum.flags.writeable
    for g, f in zip(got, fresh):
        np.testing.assert_array_equal(g, f)
    np.testing.assert_array_equal(spectrum, fresh_fft)
    np.testing.assert_array_equal(narrower, _rfft.band_limited(x, 10.0, bands[:1]))
    assert len(calls) == 3  # outside a refine nothing is remembered
    assert _rfft.band_limited(x, 10.0, None) is x
    assert channels.band_limited is _rfft.band_limited  # the channel regression's own name for it


# slow: the default run's twin is tests/test_refine_cost.py::test_refine_with_remembered_columns_equals_recomputing,
# whose record carries a temperature coupling beside its Gauss–Markov term and whose plain refine gets nothing from
# these memories either — one pair of refines instead of two
@pytest.mark.slow
def test_refine_with_a_channel_and_its_memories_equals_recomputing(monkeypatch):
    n, fs = 120_000, 10.0
    t = np.arange(n) / fs
    temp = 10.0 + 5.0 * np.sin(2 * np.pi * t / (n / fs / 2.5)) + 0.01 * np.random.default_rng(2).standard_normal(n)
    y = allanite.simulate(n, fs, N=2e-3, B=5e-4, K=1e-5, seed=3) + 2e-3 * temp
    kept = allanite.refine(y, fs, channels={"temp": temp}, progress=False)
    monkeypatch.setattr(Recent, "get", lambda self, arr, key=(): None)  # every transform and channel afresh
    plain = allanite.refine(y, fs, channels={"temp": temp}, progress=False)
    assert "regression" in kept.found and kept.found == plain.found
    for a, b in zip(kept.steps, plain.steps):
        assert a.params == b.params and a.intervals == b.intervals
        assert a.before == b.before and a.after == b.after
    assert kept.fit.chi2 == plain.fit.chi2
    assert kept.unexplained == plain.unexplained


def _plain_choice(y, fs, f0):
    """The held-out power and filled bins per number of bins as fit_template chose them before: every part's
    indices gathered again for each number of bins, the filled bins counted on every sample."""
    n, nu = y.size, f0 / fs
    per = n // template.HELDOUT_BLOCKS
    blocks = [np.arange(j * per, (j + 1) * per) for j in range(template.HELDOUT_BLOCKS)]
    parts = [
        tuple(np.concatenate([b for j, b in enumerate(blocks) if (j % 2 == parity) == side]) for side in (True, False))
        for parity in (0, 1)
    ]
    u = np.arange(n, dtype=np.float64) * nu
    u = (u - np.floor(u)).astype(np.float32)
    heldout, filled, b = {}, {}, template.MIN_BINS
    while b <= min(template.MAX_BINS, max(template.MIN_BINS, (n // 2) // template.MIN_PER_BIN)):
        k = np.minimum((u * b).astype(np.int64), b - 1)
        num = den = 0.0
        for held_in, held_out in parts:
            count = np.bincount(k[held_in], minlength=b).astype(np.float64)
            total = np.bincount(k[held_in], weights=y[held_in], minlength=b)
            mean = np.where(count > 0, total / np.maximum(count, 1.0), 0.0)
            if not (count > 0).all():
                have = np.flatnonzero(count > 0)
                mean = np.interp(np.arange(b, dtype=np.float64), have.astype(np.float64), mean[have], period=b)
            comp = mean[k[held_out]]
            z = y[held_out] - y[held_out].mean()
            r = z - (comp - comp.mean())
            num, den = num + float(r @ r), den + float(z @ z)
        heldout[b] = num / den if den > 0 else math.inf
        filled[b] = int(np.count_nonzero(np.bincount(k, minlength=b)))
        b *= 2
    return heldout, filled


@pytest.mark.parametrize(("n", "fs", "f0"), [(200_003, 400.0, 2.3), (100_000, 100.0, 0.19), (4_000, 100.0, 25.0)])
def test_template_choice_equals_the_plain_gathering(n, fs, f0):
    t = np.arange(n) / fs
    y = 0.05 * signal.sawtooth(2 * np.pi * f0 * t) + np.random.default_rng(1).normal(0.0, 0.01, n)
    heldout, filled = _plain_choice(y, fs, f0)
    got = template.fit_template(y, fs, f0)
    assert got.heldout == heldout  # every number of bins' held-out power, bit for bit
    u = np.arange(n, dtype=np.float64) * (f0 / fs)
    sides, tail = template._sides(y, (u - np.floor(u)).astype(np.float32))
    assert {b: template._heldout_power(sides, tail, b)[1] for b in filled} == filled
    assert got.bins in heldout and 0.0 < min(heldout.values()) < 1.0  # the waveform predicts held-out samples


def test_remembered_replacement_equals_a_fresh_one(monkeypatch):
    rng = np.random.default_rng(4)
    y = rng.standard_normal(60_000) + np.cumsum(rng.standard_normal(60_000)) * 1e-3
    y[rng.choice(y.size, 40, replace=False)] += 12.0
    flags = outliers.outlier_test(y, 100.0, 0.01)["flags"]
    fewer = flags.copy()
    fewer[np.flatnonzero(flags)[0]] = False
    fresh = [outliers.replace_outliers(y, f) for f in (flags, fewer)]
    spans, plain_span = [], outliers._white_span_of
    monkeypatch.setattr(outliers, "_white_span_of", lambda v: spans.append(v.size) or plain_span(v))
    with remembering():
        got = [outliers.replace_outliers(y, f) for f in (flags, fewer)]
        again = outliers.replace_outliers(y.copy(), flags.copy())  # found by content
        again[0] += 1.0  # each caller its own array: the remembered samples stay as they were
        later = outliers.replace_outliers(y, flags)
    assert spans == [y.size]  # the span once for the record, not once per replacement
    assert 30 <= flags.sum() <= 60 and not np.array_equal(fresh[0], fresh[1])
    for g, f in zip(got, fresh):
        np.testing.assert_array_equal(g, f)
    np.testing.assert_array_equal(later, fresh[0])
    assert again[0] == fresh[0][0] + 1.0 and got[0].flags.writeable
