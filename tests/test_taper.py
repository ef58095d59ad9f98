"""Hann-weighted DAVAR (issue 14, paper 002): the Rust kernel against an extended-precision twin,
the static counterpart, thread independence, the EDF by Monte Carlo, hann_signal, bad input."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

import allanite
from allanite.errors import ParameterError


def _twin(y, window, hop, ms):
    """Σ w_i d_{s+i} / Σw per window, from exact block sums (Fractions) and math.fsum: (T, J)."""
    y = np.asarray(y, dtype=np.float64)
    pre = [Fraction(0)]
    for v in y.tolist():
        pre.append(pre[-1] + Fraction(v))
    n_win = (y.size - window) // hop + 1
    out = np.empty((len(ms), n_win))
    for t, m in enumerate(ms):
        mt = window + 1 - 2 * m
        k_end = (n_win - 1) * hop + mt
        d = []
        for k in range(k_end):
            diff = (pre[k + 2 * m] - pre[k + m]) - (pre[k + m] - pre[k])
            d.append(float(diff * diff / (2 * m * m)))
        w = [math.sin(math.pi * (i + 1) / (mt + 1)) ** 2 for i in range(mt)]
        for j in range(n_win):
            s = j * hop
            out[t, j] = math.fsum(wi * di for wi, di in zip(w, d[s : s + mt])) / math.fsum(w)
    return out


def _contrast_record(n=2400, seed=5):
    """White noise whose level jumps by 10^6 (and back) between segments."""
    y = np.random.default_rng(seed).normal(size=n)
    y[n // 3 : 2 * n // 3] *= 1e6
    return y


@pytest.mark.parametrize("hop", [1, 37])
def test_hann_matches_extended_precision_twin(hop):
    y = _contrast_record()
    ms = [1, 3, 17, 64, 190]
    d = allanite.davar(y, 1.0, window=401, hop=hop, taus=ms, taper="hann")
    ref = _twin(y, 401, hop, ms)
    err = np.max(np.abs(d.avar - ref) / ref)
    assert err <= 1e-9, err


def test_hann_float32_input_and_naive_method():
    y = (_contrast_record(1200, seed=9) * 1e-3).astype(np.float32)
    ms = [1, 2, 9, 150]
    fast = allanite.davar(y, 1.0, window=333, hop=11, taus=ms, taper="hann")
    naive = allanite.davar(y, 1.0, window=333, hop=11, taus=ms, taper="hann", method="naive")
    ref = _twin(y.astype(np.float64), 333, 11, ms)
    assert np.max(np.abs(fast.avar - ref) / ref) <= 1e-9
    # the naive path integrates to angle in plain float64: close, not exact
    assert np.max(np.abs(naive.avar - ref) / ref) <= 1e-6


def test_window_equal_record_is_the_static_hann_estimator():
    y = np.random.default_rng(2).normal(size=3000).cumsum() * 1e-2 + np.random.default_rng(3).normal(size=3000)
    ms = [1, 4, 40, 400, 1400]
    static = allanite.avar(y, 1.0, taus=ms, taper="hann")
    dyn = allanite.davar(y, 1.0, window=3000, taus=ms, taper="hann")
    ref = _twin(y, 3000, 1, ms)[:, 0]
    assert np.max(np.abs(static.avar - ref) / ref) <= 1e-12
    np.testing.assert_array_equal(static.avar, dyn.avar[:, 0])
    assert static.taper == "hann" and dyn.taper == "hann"
    assert np.array_equal(static.n, 3001 - 2 * np.asarray(ms))


def test_hann_is_bit_identical_for_any_thread_count():
    y = np.random.default_rng(4).normal(size=(20_000, 2))
    kw = dict(window=1500, hop=3, taus=[1, 5, 50, 300], taper="hann")
    one = allanite.davar(y, 1.0, workers=1, **kw).avar
    two = allanite.davar(y, 1.0, workers=2, **kw).avar
    np.testing.assert_array_equal(one, two)


def test_rect_stays_todays_behaviour():
    y = np.random.default_rng(6).normal(size=5000)
    a = allanite.davar(y, 1.0, window=500, hop=10, taus=[1, 10])
    b = allanite.davar(y, 1.0, window=500, hop=10, taus=[1, 10], taper="rect")
    np.testing.assert_array_equal(a.avar, b.avar)
    assert a.taper == "rect"


def test_hann_monte_carlo_bias_and_interval_coverage():
    """White noise, W = 401, independent windows: mean within 2 % of the truth at m = 1…133, and
    the 68.3 % interval covers the truth about as often as the rectangular window's does."""
    w, k = 401, 6000
    y = np.random.default_rng(14).normal(size=w * k)
    ms = np.array([1, 2, 5, 10, 20, 40, 80, 133])
    truth = 1.0 / ms
    cov = {}
    for taper in ("rect", "hann"):
        d = allanite.davar(y, 1.0, window=w, hop=w, taus=ms, taper=taper).with_confidence(alpha=0)
        ratio = d.avar.mean(axis=1) / truth
        assert np.all(np.abs(ratio - 1.0) <= 0.02), (taper, ratio)
        cov[taper] = np.mean((d.ci_low <= truth[:, None]) & (truth[:, None] <= d.ci_high), axis=1)
    # the rect EDF model's own error carries over (coverage 0.65 at m = 1); the taper adds little
    assert np.all(np.abs(cov["hann"] - 0.683) <= 0.11), cov["hann"]
    assert np.all(np.abs(cov["hann"] - cov["rect"]) <= 0.05), cov
    d = allanite.davar(y, 1.0, window=w, hop=w, taus=ms, taper="hann")
    nu_emp = 2 * d.avar.mean(axis=1) ** 2 / d.avar.var(axis=1)
    r = allanite.davar(y, 1.0, window=w, hop=w, taus=ms).avar
    nu_rect = 2 * r.mean(axis=1) ** 2 / r.var(axis=1)
    share = allanite.estimators.taper.hann_edf_factor(ms, w)
    assert np.all(np.abs(nu_emp / nu_rect / share - 1.0) <= 0.08), nu_emp / nu_rect / share


def test_hann_signal_is_paper_eq1():
    y = np.random.default_rng(7).normal(size=1000)
    ms = [1, 5, 40]
    d = allanite.davar(y, 1.0, window=401, hop=100, taus=ms, taper="hann_signal")
    w = np.sin(np.pi * np.arange(1, 402) / 402) ** 2
    w /= np.sqrt(np.mean(w * w))
    for j in range(d.avar.shape[1]):
        seg = y[j * 100 : j * 100 + 401]
        x = np.concatenate([[0.0], np.cumsum((seg - seg.mean()) * w)])
        for t, m in enumerate(ms):
            dd = x[2 * m :] - 2 * x[m:-m] + x[: -2 * m]
            assert d.avar[t, j] == pytest.approx(np.mean(dd * dd) / (2 * m * m), rel=1e-12)
    with pytest.raises(ParameterError, match="hann_signal"):
        d.with_confidence(alpha=0)


def test_bad_taper_input():
    y = np.random.default_rng(8).normal(size=2000)
    with pytest.raises(ParameterError, match="unknown taper 'hamming'.*'rect', 'hann', 'hann_signal'"):
        allanite.davar(y, 1.0, window=400, taper="hamming")
    with pytest.raises(ParameterError, match="valid pairs: 'rect' with any estimator; 'hann' with 'oavar'"):
        allanite.davar(y, 1.0, window=400, taus=[1], estimator="avar", taper="hann")
    with pytest.raises(ParameterError, match="valid pairs"):
        allanite.avar(y, 1.0, estimator="theo1", taper="hann")
    with pytest.raises(ParameterError, match=r"M = window \+ 1 − 2m = 1 at τ = 200 s \(m = 200\): use m ≤ 199"):
        allanite.davar(y, 1.0, window=400, taus=[1, 200], taper="hann")
    # a named grid keeps only the τ that leave ≥ 3 terms
    d = allanite.davar(y, 1.0, window=400, taus="all", hop=100, taper="hann")
    assert d.m.max() == 199 and np.all(d.n >= 3)
