"""Fixes from the fifth blind suite (benches/refine_blind5.py): a channel's lag read on the channel lagged in time,
not on the grid's circular response (which reads T short over a record a few lags long); the suite's fast subset
and its Student-t truth."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy import signal

import allanite
from allanite.errors import ParameterError
from allanite.model import _lag
from allanite.model.channels import regress_channel


def _lagged_coupling(seed: int, lag_s: float, coefficient: float):
    """10 Hz × 5·10⁴ (5000 s): white noise and a random walk of rate; a temperature cycling three times (19.5 → 45.5 °C,
    two frequencies); the rate follows it through a first-order lag of ``lag_s`` started in equilibrium."""
    fs, n = 10.0, 50_000
    t = np.arange(n) / fs
    rng = np.random.default_rng(seed)
    y = allanite.simulate(n, fs, N=8e-4, K=2e-6, seed=rng)
    w = 2 * np.pi * t / (n / fs / 3)
    temp = 32.5 - 10.0 * np.cos(w) - 3.0 * np.cos(2.6 * w + 0.5)  # not one sinusoid: a lag, not a rate term
    a = -math.expm1(-1.0 / (fs * lag_s))
    sensor = signal.lfilter([a], [1.0, a - 1.0], temp - temp[0]) + temp[0]
    return y + coefficient * (sensor - sensor.mean()), temp + 0.01 * rng.standard_normal(n), fs


def test_lag_over_a_few_lags_is_not_read_short():
    # the grid's circular profile read 525 s (coefficient −10 %) here, 603 s (+0.0 %) in time; over 8 records of
    # one sinusoid plus wander its median was 473 s, 545 s started in steady state, in time 590 and 602 s
    # (refine_blind5's 10⁷-sample FOG: 420 s for 600 s)
    y, temp, fs = _lagged_coupling(1000, 600.0, 1e-3)
    r = regress_channel(y, temp, fs, name="temp")
    assert r.accepted and "lag_s" in r.params
    assert abs(r.params["lag_s"] / 600.0 - 1.0) < 0.05
    assert abs(r.params["coefficient"] / 1e-3 - 1.0) < 0.03
    lo, hi = r.intervals["lag_s"]
    assert lo < 600.0 < hi
    grid_t = r.terms["lag_s"]["grid_lag_s"]
    assert grid_t < 0.9 * 600.0  # the grid's profile, kept beside it, reads short


def test_exact_lag_moves_the_grid_interval_with_the_maximum():
    # 2Δℓ = ((ln T − ln 600)/0.2)²: the maximum at 600 s; from the grid's 450 s (interval 300–700 s) the interval
    # moves by 600/450
    def objective(t):
        return 5.0 - 0.5 * ((math.log(t) - math.log(600.0)) / 0.2) ** 2

    best, (lo, hi) = _lag.exact_lag(objective, 450.0, (300.0, 700.0), (0.2, 1250.0))
    assert abs(best / 600.0 - 1.0) < 0.02
    assert abs(lo / (300.0 * best / 450.0) - 1.0) < 1e-9 and abs(hi / (700.0 * best / 450.0) - 1.0) < 1e-9
    # within the grid's ends: the search and the interval stop there
    best, (lo, hi) = _lag.exact_lag(objective, 400.0, (300.0, 500.0), (0.2, 550.0))
    assert abs(best / 550.0 - 1.0) < 0.02 and hi == 550.0 and lo < best


def _blind5():
    """benches/refine_blind5.py (its cases, judge and truths)."""
    root = Path(__file__).resolve().parents[1]
    sys.path.insert(0, str(root / "benches"))
    try:
        import refine_blind5
    finally:
        sys.path.pop(0)
    return refine_blind5


def test_blind5_fast_subset_short_record_with_a_line():
    # the suite's fastest case (2·10⁴ samples at 10 Hz, a 0.026 °/s line at 0.45 Hz): named within its 20 % / 1 %,
    # the errors falling, nothing unexplained — and without the sinusoid candidate something is (first run:
    # amplitude −0.2 %, f0 +0.0 %, χ²/dof 1.73·10³ → 4.51, 3 regions without the candidate)
    b5 = _blind5()
    case = next(c for c in b5.CASES if c.name.startswith("short record"))
    v = b5.run_case(case)
    assert v["passed"], v
    assert abs(v["param_errors"]["sinusoid.f0"]) < 0.01 and abs(v["param_errors"]["sinusoid.amplitude"]) < 0.2
    assert v["without_candidate_flags"]


def test_student_flag_rate_closed_forms():
    # off both neighbours with opposite signs at a zero cut: the middle sample the largest or the smallest of three
    b5 = _blind5()
    assert b5.student_flag_rate(0.0, rule="neighbours") == pytest.approx(2.0 / 3.0, rel=1e-3)
    # beyond the cut from the level: both tails of Student-t(3), 2·S(2) = 0.1393 at twice the scale
    assert b5.student_flag_rate(2 * b5.T_SCALE, rule="level") == pytest.approx(0.139326, rel=1e-4)
    assert b5.student_flag_rate(4 * b5.T_SCALE, rule="level") < b5.student_flag_rate(2 * b5.T_SCALE, rule="level")


@pytest.mark.parametrize("name", ["", "  "])
def test_a_channel_without_a_name_is_refused(name):
    # accepted before, the regression then named by a blank in the report, the HTML page and summary.json
    y = np.zeros(1000)
    with pytest.raises(ParameterError, match="a channel's name must not be empty"):
        allanite.refine(y, 10.0, channels={name: np.arange(1000.0)}, progress=False)
