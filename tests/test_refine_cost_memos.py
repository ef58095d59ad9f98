"""refine's content memories of round r6cost give the numbers of the computations they stand for, bit for bit.

The channel regression's transforms (:mod:`allanite.model._rfft`: a real FFT and a band-limited channel, each
remembered by its input's content) against fresh ones, and a whole ``refine`` with a temperature channel with
every memory against one that recomputes everything. No timings here: ``benches/bench_refine_cost.py``.
"""

from __future__ import annotations

import numpy as np
from scipy import fft as sfft

import allanite
from allanite.model import _rfft, channels
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
