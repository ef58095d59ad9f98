"""Random telegraph noise (allanite.model.telegraph, the "telegraph" removal of refine): its Allan variance against
a simulated telegraph's, the kurtosis test and two-level fit on a short telegraph record against its Gaussian twin
of the same spectrum, and the removal declined where the heavy tail is a noise level that changes."""

from __future__ import annotations

import math
import types

import numpy as np
import pytest
from scipy.signal import lfilter

import allanite
from allanite.model import telegraph as tg
from allanite.model.refinement._telegraph import telegraph_removal

FS, N = 100.0, 100_000
A, D_LOW, D_HIGH = 0.02, 20.0, 2.0
ALPHA = 0.05 * 0.002  # the telegraph's share of the default level


def _removal(y):
    said: list = []
    ctx = types.SimpleNamespace(y=y, fs=FS, level=0.05, consider=lambda _e, entry: said.append(entry))
    return list(telegraph_removal(ctx)), said


def _gaussian_twin(rng, n):
    gm = tg.telegraph_gm(A, D_LOW, D_HIGH)
    a = math.exp(-1.0 / (FS * gm["tc"]))
    w = rng.standard_normal(n + 5000) * gm["sigma"] * math.sqrt(1 - a * a)
    return lfilter([1.0], [1.0, -a], w)[5000:]


def test_telegraph_avar_is_the_simulated_telegraphs():
    """σ²·gm_avar(τ, T_c) with σ² = A²p(1 − p), T_c = 1/(1/d_low + 1/d_high), against the overlapping Allan variance
    of 2·10⁵ samples of a telegraph at 10 Hz (T_c 0.67 s, 3·10⁴ T_c in the record): within 6 % at τ 0.5–16 s."""
    x = tg.simulate_telegraph(200_000, 10.0, 1.0, 2.0, 1.0, np.random.default_rng(7))
    assert x.mean() == pytest.approx(1.0 / 3.0, abs=0.02)
    taus = np.array([0.5, 1.0, 2.0, 4.0, 8.0, 16.0])
    ratio = allanite.avar(x, 10.0, taus=taus).avar / tg.telegraph_avar(taus, 1.0, 2.0, 1.0)
    assert np.all(np.abs(ratio - 1.0) < 0.06), ratio
    gm = tg.telegraph_gm(1.0, 2.0, 1.0)
    assert gm["sigma"] == pytest.approx(math.sqrt(2.0) / 3.0) and gm["tc"] == pytest.approx(2.0 / 3.0)


def test_telegraph_found_and_its_gaussian_twin_not():
    """10³ s at 100 Hz: white noise of the telegraph's own amplitude per sample, plus a telegraph (0.02, dwells 20 s
    and 2 s) or its Gaussian Gauss–Markov twin of the same spectrum. The telegraph passes the kurtosis test and is
    removed with its amplitude and dwells within their intervals' reach; the twin passes neither."""
    rng = np.random.default_rng(3)
    white = rng.standard_normal(N) * A
    comp = tg.simulate_telegraph(N, FS, A, D_LOW, D_HIGH, rng)
    got, said = _removal(white + comp)
    assert len(got) == 1, said
    rem = got[0]
    p, iv = rem["params"], rem["intervals"]
    assert p["amplitude"] == pytest.approx(A, rel=0.05)
    assert iv["amplitude"][0] < p["amplitude"] < iv["amplitude"][1]
    for k, truth in (("dwell_low", D_LOW), ("dwell_high", D_HIGH)):  # ~40 visits: within 2 intervals' half-widths
        lo, hi = iv[k]
        assert abs(p[k] - truth) < 2 * (hi - lo), (k, p[k], iv[k])
    assert rem["evidence"]["test"]["kurtosis_z"] > rem["evidence"]["test"]["threshold"]
    assert np.mean((comp > A / 2) == (rem["component"] > 0)) > 0.995  # the states, sample by sample
    assert not rem["evidence"]["after"]["z"] > rem["evidence"]["after"]["threshold"]
    twin, said = _removal(white + _gaussian_twin(rng, N))
    assert twin == [] and said[0]["test"]["kurtosis_z"] < said[0]["test"]["threshold"]


def test_changing_noise_level_is_no_telegraph():
    """White noise doubling halfway makes the Allan differences heavy-tailed too (a scale mixture); the test
    passes, but two levels of the mean do not explain it: the samples less them still fail — declined."""
    rng = np.random.default_rng(5)
    y = np.concatenate([rng.standard_normal(N // 2), 2.0 * rng.standard_normal(N // 2)]) * A
    assert tg.telegraph_test(y, FS, ALPHA)["accepted"]
    got, said = _removal(y)
    assert got == [] and "rejected" in said[0]


def test_pulse_train_is_no_telegraph():
    """A pulse train (0.02 high for 2 s of every 20 s) switches between two levels as a telegraph does, but its dwells
    are all alike: declined as periodic (its lines are the periodic candidate's), where the same levels with
    exponential dwells are taken (test above)."""
    t = np.arange(N) / FS
    rng = np.random.default_rng(6)
    y = rng.standard_normal(N) * A + A * ((t % 20.0) < 2.0)
    cv = tg.dwell_cv(((t % 20.0) < 2.0).astype(int))
    assert max(cv) < 1e-12
    got, said = _removal(y)
    assert got == [] and "regular" in said[0].get("rejected", ""), said
