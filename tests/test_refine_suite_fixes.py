"""What the failing cases of issue 29's sensor suite (benches/refine_sensors.py) taught, each on a small record:

- a slow channel's regression is held out on the chain as a drift is — the coupling fitted on the held-in part,
  its component built from the held-out part's own channel (a temperature swings differently in the two parts);
- a periodic removal takes off the Allan curve's degrees of freedom only its generators (a sawtooth's hundreds of
  lines had left χ²/dof = χ²), and a family of harmonics with a jump goes as its waveform folded on the period;
- lines left only in a filter's noise nulls, too weak to move the curve, are not "unexplained";
- the suite's judge: an optional term of a channel is demanded only where the record carries it, and in sample
  the tests' χ²/dof falling counts as the error falling (the RMS ADEV error rewards an effect the five terms
  absorbed: removing the truth raises it).
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
from scipy import signal

import allanite
import sensors
from allanite.model.refinement.curvefit import Curve, solve
from allanite.model.refinement.missing import MissingContext, _lines_move_curve


def _sawtooth_record(n=200_000, fs=400.0, seed=6):
    rng = np.random.default_rng(seed)
    white = np.convolve(rng.standard_normal(n) * 2e-3 * math.sqrt(fs), np.full(4, 0.25), mode="same")
    y = white + 0.045 * signal.sawtooth(2 * np.pi * 2.3 * np.arange(n) / fs + 1.1)
    return np.round(y / 1e-3) * 1e-3, fs


@pytest.fixture(scope="module")
def sawtooth():
    y, fs = _sawtooth_record()
    return allanite.refine(y, fs, unit="deg/s", progress=False)


@pytest.mark.slow  # test_periodic's sawtooth
def test_a_sawtooth_through_a_moving_average_is_one_waveform_and_nothing_is_left(sawtooth):
    r = sawtooth
    (st,) = [s for s in r.steps if s.effect == "periodic"]
    assert abs(st.params["fundamentals"][0] / 2.3 - 1) < 1e-6
    assert abs(st.params["rms"] / (0.045 / math.sqrt(3)) - 1) < 0.01
    # hundreds of lines fitted in time, yet the curve keeps its degrees of freedom: χ²/dof is a ratio, not χ²
    assert st.params["lines"] > 50 and r.steps[-1].after["chi2_dof"] < 2.0
    assert r.steps[-1].after["heldout_rms_adev_pct"] < r.steps[0].before["heldout_rms_adev_pct"]
    assert r.unexplained == []


def test_lines_too_weak_to_move_the_curve_are_not_unexplained():
    y, fs = _sawtooth_record()
    res = allanite.avar(y, fs, taus="octave")
    curve = Curve(res.tau, res.m.astype(float), res.avar, fs, y.size + 1, "oavar")
    sol = solve(curve, ("Q", "N", "B", "K", "R"), [])
    ctx = MissingContext(curve, np.arange(curve.tau.size), sol, ("N",), [], y, fs, 0.05, True)
    # a folded harmonic beside the moving average's null (3·10⁻⁵ against 0.04 per sample): moves nothing
    assert not _lines_move_curve(ctx, np.array([99.1, 100.2]), np.array([3e-5, 3e-5]))
    # the same lines 300× larger move the shortest τ well beyond its scatter
    assert _lines_move_curve(ctx, np.array([99.1, 100.2]), np.array([1e-2, 1e-2]))


def test_a_slow_channel_is_held_out_with_the_held_out_parts_own_channel():
    case = sensors.Case(
        "a temperature through a 300 s lag, 10 Hz × 10⁵",
        10.0,
        100_000,
        {"N": 2e-3, "B": 5e-4, "K": 1e-5},
        [("temperature", {"coefficient": 2e-3, "profile": "cycle"})],
        seed=3,
    )
    y, fs, channels = sensors.make(case)
    r = allanite.refine(y, fs, unit="deg/s", channels=channels, progress=False)
    (st,) = [s for s in r.steps if s.effect == "regression"]
    assert abs(st.params["coefficient"] / 2e-3 - 1) < 0.1
    # the held-in part's own change of the curve, added to the other part's prediction, does not carry over a
    # temperature that cycles three times over eight blocks; the held-out part's own channel does
    assert st.after["heldout_rms_adev_pct"] < 0.5 * st.before["heldout_rms_adev_pct"]


def _fake(before, after, terms=None):
    ev = {"terms": terms or {}}
    step = SimpleNamespace(effect="regression", params={"coefficient": 1e-3}, evidence=ev, before=before, after=after)
    return SimpleNamespace(steps=[step], unexplained=[], found=["regression"])


def test_the_judge_demands_an_optional_term_only_where_the_record_carries_it():
    case = sensors.Case("lag", 10.0, 1000, {}, [])
    case.injected = [sensors.Injected("regression", {"coefficient": 1e-3, "lag_s": 300.0})]
    chain = ({"chi2_dof": 0.7, "rms_adev_pct": 0.7, "heldout_rms_adev_pct": 6.0},)
    after = {"chi2_dof": 0.6, "rms_adev_pct": 0.8, "heldout_rms_adev_pct": 1.1}
    # the 300 s lag case: statistic 14.6 at ν = 15.3 — p = 0.0017 without the search's penalty, α = 0.001
    weak = {"lag_s": {"statistic": 14.58, "dof": 15.34, "alpha": 0.001, "kept": False}}
    v = sensors.judge(_fake(chain[0], after, weak), case)
    assert v["param_errors"]["regression.lag_s"] == "not carried" and v["params"] and v["passed"]
    # a lag the record does carry (p ≈ 2·10⁻⁵) and refine did not keep fails the case
    strong = {"lag_s": {"statistic": 40.0, "dof": 15.34, "alpha": 0.001, "kept": False}}
    assert not sensors.judge(_fake(chain[0], after, strong), case)["params"]


def test_the_judge_counts_the_tests_chi2_falling_as_the_in_sample_error_falling():
    case = sensors.Case("warm-up", 10.0, 1000, {}, [])
    case.injected = []
    # the 1500 s warm-up: the RMS ADEV error 1.41 → 1.79 % (1.78 % with the true warm-up removed) while the
    # chain's χ²/dof on the tests' covariance falls 2.1 → 1.15
    start = {"chi2_dof": 2.1, "rms_adev_pct": 1.41, "heldout_rms_adev_pct": 4.3}
    assert sensors.judge(_fake(start, {"chi2_dof": 1.15, "rms_adev_pct": 1.79, "heldout_rms_adev_pct": 1.7}), case)[
        "falling"
    ]
    # both rising is not falling; the RMS error falling alone is
    assert not sensors.judge(_fake(start, {"chi2_dof": 2.3, "rms_adev_pct": 1.79, "heldout_rms_adev_pct": 1.7}), case)[
        "falling"
    ]
    assert sensors.judge(_fake(start, {"chi2_dof": 2.3, "rms_adev_pct": 1.2, "heldout_rms_adev_pct": 1.7}), case)[
        "falling"
    ]
