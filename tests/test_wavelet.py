"""The db5 wavelet split (issue 14, paper 002): closure, bands, grouping, periodic trend, bad input."""

from __future__ import annotations

import numpy as np
import pytest
import pywt

import allanite
from allanite.errors import ParameterError


def _record(n=8192, fs=100.0, seed=1):
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    return 3.0 * np.sin(2 * np.pi * 0.5 * t + 0.3) + 0.5 * np.cos(2 * np.pi * 1.0 * t) + rng.normal(size=n), fs


@pytest.mark.parametrize("trend", ["a5", "periodic", "none"])
def test_parts_sum_back_to_the_record(trend):
    y, fs = _record()
    s = allanite.wavelet_split(y, fs, trend=trend)
    assert np.max(np.abs(s.trend + s.low + s.high - y)) <= 1e-12 * np.max(np.abs(y))
    assert s.trend.shape == y.shape
    yy = np.stack([y, 2 * y + 1], axis=1)
    s2 = allanite.wavelet_split(yy, fs, trend=trend)
    assert s2.low.shape == yy.shape
    assert np.max(np.abs(s2.trend + s2.low + s2.high - yy)) <= 1e-12 * np.max(np.abs(yy))


def test_default_bands_are_pywavelets_levels():
    y, fs = _record()
    s = allanite.wavelet_split(y, fs)
    assert s.bands["trend"] == {"levels": ("a5",), "hz": (0.0, fs / 64)}
    assert s.bands["low"] == {"levels": ("d5", "d4", "d3"), "hz": (fs / 64, fs / 8)}
    assert s.bands["high"] == {"levels": ("d2", "d1"), "hz": (fs / 8, fs / 2)}
    # the high part is PyWavelets' own reconstruction of D2 + D1
    c = pywt.wavedec(y, "db5", mode="symmetric", level=5)
    keep = [np.zeros_like(v) for v in c[:4]] + c[4:]
    np.testing.assert_allclose(s.high, pywt.waverec(keep, "db5", mode="symmetric")[: y.size], atol=1e-12)


def test_user_grouping_and_periodic_trend():
    y, fs = _record()
    s = allanite.wavelet_split(y, fs, bands={"trend": ("a5", "d5"), "low": ("d4", "d3", "d2"), "high": ("d1",)})
    assert s.bands["high"]["hz"] == (fs / 4, fs / 2) and s.bands["trend"]["hz"] == (0.0, fs / 32)
    p = allanite.wavelet_split(y, fs, trend="periodic")
    assert p.trend_freq == pytest.approx(0.5, abs=0.002)
    t = np.arange(y.size) / fs
    truth = 3.0 * np.sin(2 * np.pi * 0.5 * t + 0.3) + 0.5 * np.cos(2 * np.pi * 1.0 * t)
    # noise σ = 1, 11 parameters on 8192 samples: ≈ 0.04 rms from the noise alone
    assert np.sqrt(np.mean((p.trend - truth) ** 2)) < 0.08
    q = allanite.wavelet_split(y, fs, trend="periodic", trend_freq=0.5)
    assert q.trend_freq == 0.5 and q.bands["low"]["levels"][0] == "a5"


def test_bad_input():
    y, fs = _record(2000)
    with pytest.raises(ParameterError, match="unknown wavelet 'db99'"):
        allanite.wavelet_split(y, fs, wavelet="db99")
    with pytest.raises(ParameterError, match="level = 9 is too deep for 2000 samples.*deepest useful level is 7"):
        allanite.wavelet_split(y, fs, level=9)
    with pytest.raises(ParameterError, match=r"partition.*missing \['d1'\]"):
        allanite.wavelet_split(y, fs, bands={"trend": ("a5",), "low": ("d5", "d4", "d3"), "high": ("d2",)})
    with pytest.raises(ParameterError, match=r"repeated \['d2'\]"):
        allanite.wavelet_split(y, fs, bands={"trend": ("a5",), "low": ("d5", "d4", "d3", "d2"), "high": ("d2", "d1")})
    with pytest.raises(ParameterError, match="trend"):
        allanite.wavelet_split(y, fs, trend="linear")
