"""The channel tests at the record's edges (`allanite.model._edge`, docs/channels.md "The record's edges"): a
temperature warming once, most of its change in the record's first eighth, lines up with the differenced noise's
end term in every low DFT bin, and Whittle's independent bins understate its score's null variance several times.
The exact variance (in time, at the fitted noise) against simulated records, and the tests' references widened by
it. Calibration at scale: benches/channel_warmup_edge_null.py, benches/channel_turnover_null.py."""

from __future__ import annotations

import math

import numpy as np
import pytest

import allanite
from allanite.model import _edge
from allanite.model import _whittle as wh
from allanite.model.channels import channel_bands, regress_channel
from sensors import temperature_profile

FS, N = 20.0, 2000


def _channel(kind: str, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return temperature_profile(np.arange(N) / FS, kind, rng, lo=15.0, hi=35.0) + 0.01 * rng.standard_normal(N)


@pytest.mark.parametrize("kind", ["swing", "cycle"])
def test_the_scores_exact_variance_matches_simulated_records(kind):
    x = _channel(kind, 1)
    y = allanite.simulate(N, FS, N=1e-3, seed=2)
    y, _, _, _, xs, _, mean, _, bands = channel_bands(y, x, FS)
    null = wh.joint_fit(bands, wh.Design([], []))
    n_bins = (bands.n_diff - 1) // 2
    w = wh._taper(bands.n_diff)
    norm = math.sqrt(float(w @ w))
    z = wh._dft(xs - mean, w, n_bins) / norm
    # the noise as simulated (white: N²·fs on the differenced record's s² shape) in the parametric bands
    amounts = np.zeros(null["amounts"].size)
    amounts[bands.names.index("N")] = 1e-6 * FS
    exact, whittle = _edge.covariances(bands, null | {"amounts": amounts}, [z])
    # the score Re Σ conj(Z)·D/S over 600 records of the same noise beside the same channel
    s_bin = null["s"][_edge._band_of(bands, np.arange(1, n_bins + 1, dtype=np.float64))]
    u = [
        float(
            np.sum(
                np.conj(z) * wh._dft(allanite.simulate(y.size, FS, N=1e-3, seed=100 + r), w, n_bins) / norm / s_bin
            ).real
        )
        for r in range(600)
    ]
    simulated = float(np.var(u)) / whittle[0, 0]
    computed = exact[0, 0] / whittle[0, 0]
    assert computed == pytest.approx(simulated, rel=0.15)
    if kind == "swing":
        assert computed > 3.0  # the warm-up's edge: several times Whittle's variance
    else:
        assert computed < 1.25  # a cycling channel: no excess in phase (below 1: the fitted S is above the true one)


def _null_warmup(seed: int):
    """The warm-up records of benches/channel_turnover_null.py (its seeds 31 and 49: 20 Hz × 8000, white noise with
    rate random walk or flicker), which the pair's test accepted at 0.375 % before the edge factor."""
    rng = np.random.default_rng(1000 + seed)
    n, fs = 8000, 20.0
    noise = [dict(N=1e-3, K=2e-5), dict(N=1e-3, B=3e-4), dict(N=1e-3, gauss_markov=[(5e-3, n / fs / 20)])]
    y = allanite.simulate(n, fs, seed=rng, **noise[seed // 3 % 3])
    temp = temperature_profile(np.arange(n) / fs, "swing", rng, lo=15.0, hi=35.0)
    return y, temp + 0.01 * rng.standard_normal(n), fs


@pytest.mark.parametrize("seed", [31, 49])
def test_a_null_warm_up_is_no_longer_taken(seed):
    y, temp, fs = _null_warmup(seed)
    r = regress_channel(y, temp, fs, name="temp")
    edge = r.test["edge"]
    # it passed the reference without the factor; the factor (> 1.4) turns it down
    assert edge["computed"] and edge["factor"] > 1.4
    assert r.test["threshold"] / edge["factor"] < r.test["statistic"] < r.test["threshold"]
    assert min(edge["ratios"]) <= edge["factor"] <= max(edge["ratios"]) * (1 + 1e-9)  # between E's eigenvalues
    assert not r.accepted


def test_the_factor_is_not_computed_below_the_threshold():
    # a cycling channel that does not couple: the statistic is below the reference, the factor would change nothing
    x = _channel("cycle", 3)
    r = regress_channel(allanite.simulate(N, FS, N=1e-3, seed=4), x, FS, name="temp")
    assert r.test["statistic"] < r.test["threshold"]
    assert r.test["edge"] == {"factor": 1.0, "ratios": [], "computed": False}
    assert r.test["in_phase"]["edge"]["factor"] == 1.0


def test_a_coupling_off_the_edge_keeps_its_statistic():
    # the same cycling channel coupled: the score lies in phase, away from the quadrature's edge — factor ≈ 1
    x = _channel("cycle", 3)
    y = allanite.simulate(N, FS, N=1e-3, seed=4) + 2e-4 * (x - x.mean())
    r = regress_channel(y, x, FS, name="temp")
    assert r.accepted and r.test["accepted_by"] == "channel"
    assert r.test["edge"]["computed"] and 1.0 <= r.test["edge"]["factor"] < 1.1
    assert r.params["coefficient"] == pytest.approx(2e-4, rel=0.1)
