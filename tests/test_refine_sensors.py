"""``refine`` with default arguments on simulated sensors unlike the ADIS16405 (issue 29): the CI subset of
``tests/sensors.py`` — a 25-hour 1 Hz log whose bias follows a temperature that swings once, and sparse spikes in
the slow set only (``ALLANITE_SLOW=1``: outliers are tests/test_refine_lines.py's and tests/test_outliers.py's by
default; the issue's cycling temperature and a square wave's line family are tests/test_channels.py's and
tests/test_refine_lines.py's). Each must be named with its parameters (20 %, frequencies 1 %), lower the errors in sample
and held out, and leave nothing unexplained; refined without its effect's candidate, the model cannot be
complete, and ``unexplained`` must say so (the slow set; by default a shorter swing's twin in
tests/test_channel_swing_bootstrap.py). The whole suite (17 cases) is ``benches/refine_sensors.py``."""

from __future__ import annotations

import pytest

import allanite
import sensors

CI_CASES = [c for c in sensors.CASES if c.ci]
SLOW = {"sparse spikes"}


@pytest.fixture(
    scope="module",
    params=[pytest.param(c, marks=[pytest.mark.slow] if c.name.split(",")[0] in SLOW else []) for c in CI_CASES],
    ids=lambda c: c.name.split(",")[0],
)
def case_record(request):
    case = request.param
    y, fs, channels = sensors.make(case)
    return case, y, fs, ({"channels": channels} if channels else {})


def test_the_default_call_names_the_effect_and_leaves_nothing_unexplained(case_record):
    case, y, fs, kw = case_record
    r = allanite.refine(y, fs, unit=case.unit, progress=False, **kw)
    v = sensors.judge(r, case)
    assert v["named"] and v["params"], (r.found, v["param_errors"])
    assert v["falling"] and v["heldout_falling"], (v.get("rms_adev_pct"), v.get("heldout_rms_adev_pct"))
    assert v["explained"], [u["what"] for u in r.unexplained]


# a second refine of the 25-hour record: slow. The default run's cheaper twin of the same property (a temperature
# swinging once, refined without the regression candidate: `unexplained` names the channel, its statistic above its
# threshold) is tests/test_channel_swing_bootstrap.py::test_unexplained_says_the_channel_when_the_regression_is_left_out
@pytest.mark.slow
def test_without_its_candidate_the_model_says_what_it_misses(case_record):
    case, y, fs, kw = case_record
    r = allanite.refine(y, fs, unit=case.unit, candidates=sensors.candidates_without(case), progress=False, **kw)
    assert not set(r.found) & {i.effect for i in case.injected}
    assert r.unexplained, f"{case.name}: refined without {[i.effect for i in case.injected]}, nothing said"
    assert "still misses" in r.report() and all(u["alpha"] > 0 for u in r.unexplained)
