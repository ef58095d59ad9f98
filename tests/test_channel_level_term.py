"""The level term tested once a d(T)/dt term carries the coupling (r13rate; docs/channels.md, "The level term"): a
coupling through d(T)/dt only (a fibre-optic gyro's Shupe effect) is reported with that term only, a level term that
is there is still kept beside it, and beside a quadratic the level term is not tested. Replicas at scale:
benches/results/r13rate.md."""

from __future__ import annotations

import numpy as np
import pytest

from allanite.model import _whittle as wh
from allanite.model._coupling import level_test
from allanite.model._regressors import regressor_design
from allanite.model._shares import TERM_SHARE
from allanite.model.channels import channel_bands, regress_channel
from allanite.model.refinement.levels import LEVEL, alpha, share
from test_channels import _cycling

#: 8⅓ h at 1 Hz: the 2400 s cycle 12 times
N = 30_000


def _regress(y, temp):
    return regress_channel(y, temp, 1.0, name="temp", alpha=alpha("regression", LEVEL), level=LEVEL)


def test_a_coupling_through_dT_dt_only_keeps_no_level_term():
    true, logged, noise = _cycling(4, n=N)
    y = noise - 0.1 * np.gradient(true)
    r = _regress(y, logged)
    t_c = r.terms["coefficient"]
    assert r.accepted and r.terms["rate_coefficient"]["kept"] and not t_c["kept"]
    assert "coefficient" not in r.params and "coefficient" not in r.intervals
    assert t_c["statistic"] < t_c["threshold"] and t_c["alpha"] == pytest.approx(TERM_SHARE["coefficient"] * LEVEL)
    assert r.params["rate_coefficient"] == pytest.approx(-0.1, rel=0.1)
    lo, hi = r.intervals["rate_coefficient"]
    assert lo < r.params["rate_coefficient"] < hi
    # the component is the d(T)/dt column alone, and the held-in refit refits that column only
    cols = r.columns(logged)
    assert cols.shape == (1, logged.size)
    np.testing.assert_allclose(r.component(logged), r.params["rate_coefficient"] * cols[0])


def test_a_level_term_beside_a_rate_term_is_kept():
    # the same record with 4.5·10⁻⁴ per °C on T itself: the level term's own test keeps it
    true, logged, noise = _cycling(4, n=N)
    y = noise + 4.5e-4 * (true - true.mean()) - 0.1 * np.gradient(true)
    r = _regress(y, logged)
    t_c = r.terms["coefficient"]
    assert t_c["kept"] and t_c["statistic"] > t_c["threshold"]
    assert r.params["coefficient"] == pytest.approx(4.5e-4, rel=0.2)
    assert r.params["rate_coefficient"] == pytest.approx(-0.1, rel=0.2)


def test_beside_a_kept_quadratic_the_level_term_is_not_tested():
    # (T − mean)² alone is a parabola about an origin the sensor does not know, and on a swing T and T² are
    # collinear: the level term stays beside a quadratic, and the turnover is read from both
    true, logged, noise = _cycling(5, n=N)
    m = float(true.mean())
    y = noise + 2e-4 * (true - m) ** 2
    r = _regress(y, logged)
    assert r.terms["quadratic"]["kept"] and "coefficient" not in r.terms and "coefficient" in r.params
    assert r.params["quadratic"] == pytest.approx(2e-4, rel=0.1)
    # T₀ with its 68 % interval (seed 5: 13.90 ± 0.033; the truth 13.98, 2.2 half-widths away)
    turn = r.terms["quadratic"]["turnover"]
    lo, hi = turn["interval"]
    assert turn["inside"] and 0.0 < hi - lo < 0.2 and abs(turn["value"] - m) < 3.0 * (hi - lo) / 2.0


def test_the_level_tests_null_rate_is_its_share_on_an_exact_null():
    # the level test where the record has no level term (only the d(T)/dt one): over 20 records at α 2.5 %, a level
    # term named rarely — not the 20 of 20 of carrying it always — and p-values spread as a null's
    # are (40 such records: 0 below 2.5 %, 1 below 10 %, 20 below 50 %)
    ps = []
    for seed in range(20):
        true, logged, noise = _cycling(100 + seed, n=8192)
        bands = channel_bands(noise - 0.1 * np.gradient(true), logged, 1.0)[-1]
        fit = wh.joint_fit(bands, regressor_design(["rate_coefficient"], bands.m.size))
        test, _fit = level_test(bands, ["rate_coefficient"], fit, 0.025)
        assert test["kept"] == (test["statistic"] > test["threshold"])
        ps.append(test["p_value"])
    assert sum(p < 0.025 for p in ps) <= 2 and 0.2 < float(np.median(ps)) < 0.8
    # the level term's share is the whole level (a claim dropped, not one added: _shares.TERM_SHARE's note)
    assert share("regression:coefficient") == TERM_SHARE["coefficient"] == 1.0
