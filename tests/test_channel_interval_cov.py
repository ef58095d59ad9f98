"""A channel regression's intervals do not take the noise fitted beside the coefficients as known
(``allanite.model._gls_cov``, docs/channels.md "Intervals that cover"): the noise refitted on the residual lies low
in the bands the coefficients are read in — they took their own share of its power there —, and the restricted
noise gives that share back; a channel that swings once meets the record's edge term, and the score's exact
variance is taken in place of Whittle's. Coverage at scale: benches/results/channel_interval_coverage.md."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.stats import t as t_dist

import allanite
from allanite.model import _whittle as wh
from allanite.model._gls_cov import interval_cov, leverage, restricted_noise
from allanite.model._regressors import regressor_design
from allanite.model.channels import channel_bands, regress_channel
from sensors import temperature_profile

FS, N = 1.0, 8192


def _bands(seed: int, kind: str = "cycle", k: float = 1e-5):
    """A 1 Hz × 8192 record (white noise and a rate random walk ``k`` whose level the lowest bins set) beside a
    temperature cycling three times (or swinging once), coupled at 10⁻⁴ per °C; the band sums, the noise alone,
    and the channel's design."""
    rng = np.random.default_rng(seed)
    temp = temperature_profile(np.arange(N) / FS, kind, rng, lo=10.0, hi=30.0)
    noise = allanite.simulate(N, FS, N=1e-3, K=k, seed=seed + 1000)
    y, *_, bands = channel_bands(noise + 1e-4 * temp, temp, FS)
    return bands, noise[: y.size], regressor_design([], bands.m.size)


def test_the_leverage_is_half_a_complex_bin_per_coefficient():
    bands, _, one = _bands(1)
    fit = wh.joint_fit(bands, one)
    assert leverage(bands, one, fit["s"]).sum() == pytest.approx(0.5, rel=1e-9)
    three = regressor_design(["quadratic", "rate_coefficient"], bands.m.size)
    h = leverage(bands, three, wh.joint_fit(bands, three)["s"])
    assert h.sum() == pytest.approx(1.5, rel=1e-9) and h.min() >= 0.0


def test_the_restricted_noise_gives_back_what_the_coefficient_took():
    # the noise at the cycle's band, over 30 records, against the noise fitted on the record with the coupling
    # removed exactly (nothing taken): the fit beside the coefficient 0.95× (±0.01), the restricted one 1.0×
    fitted, restricted = [], []
    for seed in range(30):
        bands, noise, one = _bands(seed)
        fit = wh.joint_fit(bands, one)
        own = wh.joint_fit(wh.spectra(noise, [], FS), wh.Design([], []))["s"]
        j = int(np.argmax(wh.band_info(bands, one, np.ones(1)) / fit["s"]))
        fitted.append(fit["s"][j] / own[j])
        restricted.append(restricted_noise(bands, one, fit)["s"][j] / own[j])
    assert np.mean(fitted) < 0.975
    assert 0.97 < np.mean(restricted) < 1.05
    assert np.all(np.array(restricted) > np.array(fitted))


def test_a_swing_weighs_its_score_by_the_exact_variance():
    # a temperature warming once beside white noise: the score's exact variance (the record's edge term) several
    # times Whittle's (tests/test_channel_edge.py), and the interval's variance the sandwich of it — without the
    # source (no regressors in time) only the restricted noise's share
    bands, _, one = _bands(3, "swing", k=0.0)
    fit = wh.joint_fit(bands, one)
    with_edge, _ = interval_cov(bands, one, fit)
    bands.source = None
    without, _ = interval_cov(bands, one, fit)
    fisher = fit["cov"][0, 0]
    assert 1.0 <= without[0, 0] / fisher < 1.3
    assert with_edge[0, 0] / without[0, 0] > 5.0  # 13.9 (seeds 4, 5: 13.0, 15.4)


def test_the_reported_interval_is_the_sandwich_at_the_restricted_noise():
    bands, _, _ = _bands(2)
    rng = np.random.default_rng(2)
    temp = temperature_profile(np.arange(N) / FS, "cycle", rng, lo=10.0, hi=30.0)
    y = allanite.simulate(N, FS, N=1e-3, K=1e-5, seed=1002) + 1e-4 * temp
    # at α 0.2 the coupling's reference is 2·F(2, ν), not the bootstrap's (5 s here): the interval does not depend on α
    r = regress_channel(y, temp, FS, name="temp", terms=(), alpha=0.2)
    lo, hi = r.intervals["coefficient"]
    fit = wh.joint_fit(bands, regressor_design([], bands.m.size))
    cov, _ = interval_cov(bands, regressor_design([], bands.m.size), fit)
    q = float(t_dist.isf((1.0 - 0.683) / 2.0, r.test["in_phase"]["dof"]))
    assert r.params["coefficient"] == pytest.approx(float(fit["c"][0]), rel=1e-9)
    assert (hi - lo) / 2.0 == pytest.approx(q * math.sqrt(cov[0, 0]), rel=1e-6)
    assert (hi - lo) / 2.0 > 1.01 * q * math.sqrt(fit["cov"][0, 0])  # wider than at the fitted noise
