"""A temperature that swings once (a warm-up of a few hundred seconds in a 30-min record): the coupling's test
keeps its power when its Satterthwaite ν is a few (`allanite.model._coupling.coupling_test`, the bootstrap's
Bartlett factor in place of 2·F(2, ν) — docs/channels.md). Calibration at scale: benches/channel_regression.py,
benches/regression_swing_null.py."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import chi2
from scipy.stats import f as f_dist

import allanite
from allanite.model import _whittle as wh
from allanite.model._coupling import BOOT_COST, _null_bands, bootstrap_scale
from allanite.model.channels import regress_channel

FS, SECONDS, TAU = 5.0, 1800, 400.0


def _record(coefficient: float, seed: int = 0):
    """A MEMS gyro (white, flicker, a little random walk) whose temperature rises 25 → 33 °C as 1 − e^(−t/400 s),
    logged with 0.02 °C of noise, and the rate following it by ``coefficient`` rad/s per °C."""
    n = int(FS * SECONDS)
    rng = np.random.default_rng(seed)
    temp = 25 + 8 * (1 - np.exp(-np.arange(n) / FS / TAU)) + 0.02 * rng.standard_normal(n)
    y = allanite.simulate(n, FS, N=2.4e-4, B=3e-5, K=2e-6, seed=seed + 100)
    return y + coefficient * (temp - temp.mean()), temp


def test_a_swing_with_few_dof_is_found_and_its_null_twin_is_not():
    y, temp = _record(1.5e-4)
    r = regress_channel(y, temp, FS, name="temp")
    nu, a = r.test["dof"], r.test["alpha"]
    satterthwaite = 2 * f_dist.isf(a, 2, nu)
    # the case: ν ≈ 2.9, where 2·F(2, ν) asks 141 — the statistic (22.8) never reached it
    assert nu < 6 and satterthwaite > 50 > r.test["statistic"]
    assert r.test["reference"].startswith("χ²₂ × Bartlett")
    # the bootstrap's χ²₂ × Bartlett, widened by the record's edge factor (a rise from the record's start)
    edge = r.test["edge"]["factor"]
    assert 1.0 <= edge < 1.5
    assert r.test["threshold"] == pytest.approx(r.test["bartlett"] * chi2.isf(a, 2) * edge)
    assert r.test["threshold"] < satterthwaite / 2
    one = r.test["in_phase"]
    assert one["threshold"] == pytest.approx(one["bartlett"] * chi2.isf(a, 1) * one["edge"]["factor"])
    assert one["threshold"] < f_dist.isf(a, 1, nu) / 2
    assert r.accepted
    assert r.params["coefficient"] == pytest.approx(1.5e-4, rel=0.2)
    y0, temp0 = _record(0.0)
    r0 = regress_channel(y0, temp0, FS, name="temp")
    assert not r0.accepted and r0.test["statistic"] < r0.test["threshold"] / 2


def test_null_bands_draw_the_whittle_model_and_the_factor_is_seeded():
    y, temp = _record(0.0, seed=3)
    bands = wh.spectra(y[:4000], [temp[:4000] - temp[:4000].mean()], FS)
    null = wh.joint_fit(bands, wh.Design([], []))
    rng = np.random.default_rng(1)
    draws = [_null_bands(bands, null["s"], rng) for _ in range(300)]
    # each band's power is m·S on average, and the channel's cross sum has variance S·G
    q = np.mean([d.q for d in draws], axis=0)
    assert np.median(q / (bands.m * null["s"])) == pytest.approx(1.0, abs=0.1)
    g2 = np.mean([abs(d.g[:, 0]) ** 2 for d in draws], axis=0)
    assert np.median(g2 / (null["s"] * bands.G[:, 0, 0].real)) == pytest.approx(1.0, abs=0.15)
    # seeded: the same record gets the same draws, so the same threshold
    again = _null_bands(bands, null["s"], np.random.default_rng(1))
    assert np.array_equal(again.q, draws[0].q)
    assert min(bootstrap_scale(bands, null)) >= 1.0
    assert BOOT_COST > 1.0


def test_unexplained_says_the_channel_when_the_regression_is_left_out():
    # the same swing with the regression candidate left out: the model absorbs it (no effect added), and
    # unexplained's channel check — the pair and the in-phase test, each with its own Bartlett factor — says so;
    # with 2·F(2, ν) and F(1, ν) at ν ≈ 2.9 (thresholds in the hundreds at its share) it said nothing
    from allanite.model.refinement import CANDIDATES

    y, temp = _record(1.5e-4)
    cands = tuple(c for c in CANDIDATES if c != "regression")
    r = allanite.refine(y, FS, unit="rad/s", channels={"temp": temp}, candidates=cands)
    said = [u for u in r.unexplained if u.get("domain") == "channels"]
    assert len(said) == 1 and "'temp'" in said[0]["what"]
    assert said[0]["statistic"] > said[0]["threshold"]
