"""A lag or a d(ch)/dt term, chosen by the evidence (r11lagrate; docs/channels.md, "A lag or a d(ch)/dt term"):
where the d(ch)/dt term passes its test, the pure lag model is weighed against it at the same count of numbers —
the larger likelihood kept, and within LAG_MARGIN of each other the phase's sign decides (r/c < 0 a delay: the
lag; r/c > 0 a lead: the rate term). On a cycling temperature both are a phase shift at its one frequency.
Power at scale: benches/channel_lag_first_test.py."""

from __future__ import annotations

import numpy as np
import pytest

import allanite
from allanite.model._coupling import LAG_MARGIN
from allanite.model.channels import regress_channel
from allanite.model.refinement.levels import LEVEL, alpha
from allanite.report._regression import _optional_words
from sensors import first_order_lag, temperature_profile
from test_channel_lag_first_test import FS, UNIT, N, _record


def _regress(y, temp):
    return regress_channel(y, temp, FS, name="temp", alpha=alpha("regression", LEVEL), level=LEVEL)


def test_a_600_s_lag_that_ties_with_a_delaying_rate_term_is_kept_as_the_lag():
    # 2.3 lags per cycle's 2π, 1.2·10⁻⁴ per °C: the lag's own test does not pass (it pays for its search over T),
    # the rate term's does — before, the rate term was kept (r/c ≈ −c·T) and the lag never weighed against it
    y, temp = _record(3, 1.2e-4, 600.0)
    r = _regress(y, temp)
    t_l, t_r = r.terms["lag_s"], r.terms["rate_coefficient"]
    assert t_r["statistic"] > t_r["threshold"] and not t_r["kept"] and "rate_coefficient" not in r.params
    assert t_l["kept"] and r.params["lag_s"] == pytest.approx(600.0, rel=0.2)
    assert t_l["statistic"] < t_l["threshold"]
    assert r.params["coefficient"] == pytest.approx(1.2e-4, rel=0.15)
    assert t_l["rate_over_coefficient"] < 0.0
    # the record cannot tell them apart: both numbers said, and why the lag
    assert t_l["tie"] and abs(t_l["against_rate"]) <= LAG_MARGIN
    assert "a delay (r/c < 0)" in t_l["why"] and f"{t_l['against_rate']:+.3g}" in t_l["why"]
    words = _optional_words(r.terms)
    assert f"lag_s kept (statistic {t_l['statistic']:.3g} < threshold" in words
    assert f"rate_coefficient not kept (statistic {t_r['statistic']:.3g} ≥ threshold" in words


def _lead_record(seed: int, coef: float, rate: float):
    """test_channel_lag_first_test's record with the rate on T + (rate/coef)·dT/dt instead of a lag."""
    rng = np.random.default_rng(seed)
    t = np.arange(N) / FS
    y = allanite.simulate(N, FS, N=8e-4, B=1.4e-4, K=2e-6, seed=seed + 100)
    temp = temperature_profile(t, "cycle", rng, lo=20.0, hi=45.0)
    y = y + coef * (temp - temp.mean()) + rate * np.gradient(temp, 1.0 / FS)
    return y, temp + 0.01 * rng.standard_normal(N)


def test_a_leading_rate_term_is_kept_not_a_lag():
    # T + r·dT/dt with r/c = +265 s (a lead, as a FOG's Shupe term can be): no lag makes a lead, so the rate term
    # fits better by far and is kept at its own size
    y, temp = _lead_record(3, 2e-4, 2e-4 * UNIT)
    r = _regress(y, temp)
    t_l, t_r = r.terms["lag_s"], r.terms["rate_coefficient"]
    assert t_r["kept"] and not t_l["kept"] and "lag_s" not in r.params
    assert r.params["rate_coefficient"] == pytest.approx(2e-4 * UNIT, rel=0.2)
    assert r.params["coefficient"] == pytest.approx(2e-4, rel=0.1)
    assert t_l["rate_over_coefficient"] > 0.0 and t_l["against_rate"] < -LAG_MARGIN and not t_l["tie"]
    assert t_r["why"].startswith("kept over the lag: it fits better")


def _chamber(seed: int, lag_s: float, before: float):
    """10 Hz × 4·10⁴ (4000 s), MEMS-like noise; a chamber cycling 0–50 °C every 1000 s (random phase, ±1 °C of
    wander) reaching the rate through ``lag_s`` at 10⁻³ per °C, the lag run from ``before`` seconds before the
    record (0: started with it, in equilibrium)."""
    fs, n = 10.0, 40_000
    rng = np.random.default_rng(seed)
    pre = int(before * fs)
    t = (np.arange(pre + n) - pre) / fs
    walk = first_order_lag(np.cumsum(rng.standard_normal(t.size)), fs, 200.0)
    temp = 25.0 + 25.0 * np.sin(2 * np.pi * t / 1000.0 + rng.uniform(0, 2 * np.pi)) + 2.0 * walk / np.ptp(walk)
    drive = first_order_lag(temp, fs, lag_s)[pre:]
    y = allanite.simulate(n, fs, N=4e-3, B=4e-4, K=3e-5, seed=seed + 100) + 1e-3 * (drive - drive.mean())
    return y, temp[pre:] + 0.02 * rng.standard_normal(n), fs


@pytest.mark.parametrize(("seed", "lag_s", "before"), [(4, 150.0, 0.0), (6, 477.0, 4000.0)])
def test_a_lag_near_one_radian_is_weighed_in_time_and_kept(seed, lag_s, before):
    # ωT 0.94 started with the record, and ωT 3 run long before it: the rate term passes its test on both. Weighed
    # as each bin times the lag's response at its own frequency (a cycle's leakage is lagged at the cycle's) and
    # in equilibrium at the first sample, the lag lost by 159 and 99 and the coefficient read −46 % and −90 %
    y, temp, fs = _chamber(seed, lag_s, before)
    r = _regress_at(y, temp, fs)
    t_l, t_r = r.terms["lag_s"], r.terms["rate_coefficient"]
    assert t_r["statistic"] > t_r["threshold"] and not t_r["kept"] and "rate_coefficient" not in r.params
    assert t_l["kept"] and r.params["lag_s"] == pytest.approx(lag_s, rel=0.2)
    assert r.params["coefficient"] == pytest.approx(1e-3, rel=0.2)
    if before == 0.0:  # in equilibrium at the start, the wander tells them apart
        assert t_l["against_rate"] > LAG_MARGIN and t_l["why"].startswith("kept over the d(ch)/dt term: it fits")
    else:  # its state free, the lag fits as well as the rate term: the delay decides
        assert t_l["against_rate"] > -LAG_MARGIN and t_l["rate_over_coefficient"] < 0.0


def _regress_at(y, temp, fs):
    return regress_channel(y, temp, fs, name="temp", alpha=alpha("regression", LEVEL), level=LEVEL)
