"""A line of few cycles tested in time under red noise (:mod:`allanite.model.slowline`)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import allanite
from allanite.errors import ParameterError
from allanite.model import slowline
from allanite.model.slowline import slow_line_test


def _red(n: int, fs: float, seed: int) -> np.ndarray:
    """White noise and a rate random walk (no line)."""
    return allanite.simulate(n, fs, N=0.02, K=2e-4, seed=seed)


def test_a_line_of_five_cycles_is_found_with_its_frequency_and_amplitude():
    fs, n = 1.0, 50_000
    t = np.arange(n) / fs
    f0, amp = 5.3 * fs / n, 0.05
    y = _red(n, fs, 3) + amp * np.sin(2 * np.pi * f0 * t + 1.1) + 0.2 * np.exp(-t / 3000.0)
    r = slow_line_test(y, fs, 1e-3)
    assert r is not None and r["accepted"]
    assert r["statistic"] > r["threshold"]
    # found by the first reading: the second is not read (no bootstrap where it could not change the decision)
    assert r["reading"] == "whole" and r["readings"]["refit"]["bootstrap"] is None
    assert abs(r["f0"] - f0) < 3 * r["f0_sd"]
    assert abs(r["amplitude"] - amp) < 3 * r["amplitude_sd"]
    assert 0.0 < r["separable"] <= 1.0
    assert math.isclose(r["cycles"], r["f0"] * n / fs)


def test_red_noise_alone_and_a_settling_drift_are_no_line(monkeypatch):
    monkeypatch.setattr(slowline, "BOOT_DRAWS", 20)  # calibrate runs the bootstrap: 20 records, not 120, in CI
    fs, n = 1.0, 50_000
    t = np.arange(n) / fs
    y = _red(n, fs, 4) + 0.5 * np.exp(-t / 4000.0)  # a drift 100× the noise's σ, no line
    r = slow_line_test(y, fs, 1e-3, calibrate=True)
    assert r is not None and not r["accepted"]
    assert r["p_value"] > 1e-3
    assert r["threshold"] > -2.0 * math.log(1e-3)  # the scan's maximum is above one frequency's quantile
    quick = slow_line_test(y, fs, 1e-3)  # below that bound: no draws, the bound said as the threshold
    assert quick is not None and not quick["accepted"] and quick["statistic"] == r["statistic"]
    if max(quick["statistic"], quick["readings"]["refit"]["statistic"]) <= -2.0 * math.log(1e-3 / 2):
        # each of the two readings at α/2: both below one frequency's quantile, no draws and no bootstrap
        assert quick["p_value"] is None and quick["threshold"] == pytest.approx(-2.0 * math.log(1e-3 / 2))
    # the Bonferroni p-value of the two readings, the second's from its bootstrap-mapped draws
    ps = [v["p_value"] for v in r["readings"].values()]
    assert r["p_value"] == pytest.approx(min(1.0, 2.0 * min(ps)))
    assert r["readings"]["refit"]["bootstrap"]["draws"] == slowline.BOOT_DRAWS


@pytest.mark.parametrize("restricted", [True, False])
def test_the_noise_fits_gradients_are_the_deviances_slopes(restricted):
    """The REML and ML deviances' analytic gradients in ln r (_slowfit) against central differences, at a white-,
    a random-walk- and a flicker-dominated point and one on the bounds' edge; and the batched start grid picks, per
    record, the grid point whose deviance is least."""
    from allanite.model import _slowfit

    m = 64
    rng = np.random.default_rng(11)
    parts = _slowfit.noise_parts(m)
    t = np.arange(m) + 0.5
    x = np.column_stack([np.ones(m), t / m, np.exp(-t / (0.1 * m))])
    z = np.cumsum(rng.standard_normal(m)) * 0.3 + rng.standard_normal(m)
    h = 1e-5
    for logr in ([-6.0, -3.0], [2.0, -4.0], [-5.0, 3.0], [-19.5, 11.5]):
        g = np.array(logr)
        f, grad = _slowfit.deviance(z, x, parts, g, restricted)
        assert np.isfinite(f) and grad.shape == (2,)
        for k in range(2):
            e = h * np.eye(2)[k]
            up, down = (_slowfit.deviance(z, x, parts, g + s * e, restricted)[0] for s in (1.0, -1.0))
            assert grad[k] == pytest.approx((up - down) / (2 * h), rel=1e-5, abs=1e-6)
    zs = np.column_stack([z, rng.standard_normal(m), 5.0 * np.cumsum(rng.standard_normal(m))])
    starts = _slowfit.reml_starts(zs, x, parts)
    for j in range(zs.shape[1]):
        devs = [_slowfit.deviance(zs[:, j], x, parts, np.array(g), True)[0] for g in _slowfit.START_GRID]
        assert tuple(starts[j]) == _slowfit.START_GRID[int(np.argmin(devs))]


@pytest.mark.slow  # 5·10⁵ samples and the bootstrap's 120 records; the cheap default path (no bootstrap on a line the
# first reading finds, none where both statistics stay low) is test_a_line_of_five_cycles_is_found_... and
# test_red_noise_alone_and_a_settling_drift_are_no_line
def test_a_daily_line_under_flicker_fm_is_found_by_the_refit_reading():
    """A clock's daily line over 5 days under flicker FM: the noise fitted without the line takes its power (the
    first reading misses it), the likelihood ratio with the noise refitted beside it, calibrated by the bootstrap,
    finds it — frequency and amplitude within 3 SD of the truth."""
    fs, n, f0, amp = 1.0, 432_000, 1.0 / 86_400.0, 0.04
    t = np.arange(n) / fs
    y = allanite.simulate(n, fs, N=1.0, B=0.01, seed=1) + amp * np.sin(2 * np.pi * f0 * t + 0.7)
    r = slow_line_test(y, fs, 4e-4)
    assert r is not None and r["accepted"] and r["reading"] == "refit"
    first, second = r["readings"]["whole"], r["readings"]["refit"]
    assert first["statistic"] < first["threshold"] < second["threshold"] < second["statistic"]
    assert second["bootstrap"]["draws"] == slowline.BOOT_DRAWS and second["bootstrap"]["slope"] > 0.0
    assert r["p_value"] == pytest.approx(min(1.0, 2.0 * min(first["p_value"], second["p_value"])))
    assert abs(r["f0"] - f0) < 3 * r["f0_sd"]
    assert abs(r["amplitude"] - amp) < 3 * r["amplitude_sd"]


def test_too_short_a_record_is_not_tested_and_bad_alpha_is_named():
    assert slow_line_test(np.zeros(1000), 1.0, 0.01) is None
    with pytest.raises(ParameterError, match="alpha"):
        slow_line_test(np.zeros(10_000), 1.0, 1.5)
    with pytest.raises(ParameterError, match="fs"):
        slow_line_test(np.zeros(10_000), -1.0, 0.01)


def test_a_line_a_channel_explains_is_the_channels():
    from types import SimpleNamespace

    from allanite.model.refinement._slow_lines import explained_by_channel

    fs, n = 1.0, 50_000
    t = np.arange(n) / fs
    cycle = 0.05 * np.sin(2 * np.pi * 4.2 * t / n)  # a chamber's cycles through the channel's coupling
    y = _red(n, fs, 5) + cycle
    found = slow_line_test(y, fs, 1e-3)
    assert found is not None and found["accepted"]
    line = {"slow": {"alpha": 1e-3, "band_hz": found["band_hz"]}}
    other = SimpleNamespace(
        component=0.01 * np.sign(np.sin(2 * np.pi * 40 * t / n)), evidence={}, params={"channel": "v"}
    )
    coupled = SimpleNamespace(component=cycle, evidence={}, params={"channel": "temp"})
    lagged = SimpleNamespace(component=cycle, evidence={"lag": 1.0}, params={"channel": "temp"})
    assert explained_by_channel(y, fs, line, [other]) is None
    assert explained_by_channel(y, fs, line, [lagged])["explained_by"] == "temp"  # a lag only turns its phase
    why = explained_by_channel(y, fs, line, [other, coupled])
    assert why is not None and why["explained_by"] == "temp"
    assert why["statistic_without_channel"] < found["statistic"]


def test_a_slow_line_is_no_step_where_the_sinusoid_candidate_is_left_out():
    """The line search's few-cycle lines are removed in time as ``"sinusoid"`` steps by the ``"periodic"`` removal;
    with ``"sinusoid"`` left out of ``candidates`` none is taken (it was: blind12's GNSS clock refined without the
    candidate still named its diurnal line) and ``unexplained`` names the line its test found."""
    from allanite.model.refinement import CANDIDATES

    fs, n = 1.0, 20_000
    t = np.arange(n) / fs
    y = _red(n, fs, 3) + 0.05 * np.sin(2 * np.pi * 5.3 / n * t + 1.1)
    assert [s.effect for s in allanite.refine(y, fs, progress=False).steps] == ["sinusoid"]
    without = allanite.refine(y, fs, progress=False, candidates=tuple(c for c in CANDIDATES if c != "sinusoid"))
    assert "sinusoid" not in [s.effect for s in without.steps]
    said = [u for u in without.unexplained if u["what"].startswith("a line of few cycles")]
    assert len(said) == 1 and said[0]["band_hz"][0] <= 5.3 / n <= said[0]["band_hz"][1]
    assert said[0]["statistic"] > said[0]["threshold"] and "not among the candidates" in said[0]["what"]


def test_the_words_for_a_slow_line_the_sinusoid_candidate_turned_down():
    """``unexplained``'s entry for a line of few cycles the candidate tested and did not keep: "a slow periodic
    component may be present", the test's p-value, the candidate's reason, τ over its half period; without the
    candidate, the words as before (``NO_SINUSOID``)."""
    from types import SimpleNamespace

    from allanite.model.refinement import missing

    f0, tau = 1.0 / 86_400.0, np.logspace(0, 5, 40)
    slow = {"statistic": 68.2, "threshold": 33.9, "alpha": 4e-4, "p_value": 1e-4, "cycles": 5.0}
    ln = {"f0": f0, "amplitude": 0.042, "f0_interval": (0.99 * f0, 1.01 * f0), "slow": slow}
    turned = {"param": f0, "statistic": 1.0, "threshold": 2.0, "rejected": "held-out error rose 3.1 → 3.2 %"}
    ctx = SimpleNamespace(
        curve=SimpleNamespace(tau=tau),
        sol=SimpleNamespace(z=np.ones(tau.size)),
        offered_lines=[f0],
        considered={"sinusoid": [turned]},
    )
    u = missing._slow_line(ctx, ln)
    assert u["what"].startswith("a slow periodic component may be present: a line of few cycles at 1.157e-05 Hz")
    assert "p = 0.0001" in u["what"] and "held-out error rose 3.1 → 3.2 %" in u["not_kept"] and u["p_value"] == 1e-4
    assert u["tau"][0] <= 0.5 / f0 <= u["tau"][1] and u["band_hz"] == ln["f0_interval"]
    ctx.offered_lines, ctx.considered = None, {}
    u = missing._slow_line(ctx, ln)
    assert u["what"].startswith("a line of few cycles") and u["not_kept"] == missing.NO_SINUSOID


@pytest.mark.slow  # a refine call (≈ 3.6 s CPU); the words: test_the_words_for_a_slow_line_the_sinusoid_candidate_...
def test_a_slow_line_no_step_kept_is_said_with_its_p_value(monkeypatch):
    """A line of few cycles the test found but no step kept (here: the step's record of it hidden, as where a drift
    or the noise's slow terms took the line) is said in ``unexplained`` in words — "a slow periodic component may
    be present", its test's p-value and why the sinusoid candidate did not keep it — at τ around its half period."""
    from allanite.model.refinement._final import FinalModel

    fs, n = 1.0, 20_000
    t = np.arange(n) / fs
    y = _red(n, fs, 3) + 0.05 * np.sin(2 * np.pi * 5.3 / n * t + 1.1)
    monkeypatch.setattr(FinalModel, "slow_line_kept", lambda self, ln: False)
    r = allanite.refine(y, fs, progress=False)
    said = [u for u in r.unexplained if u["what"].startswith("a slow periodic component may be present")]
    assert len(said) == 1
    u = said[0]
    assert u["p_value"] is not None and 0.0 < u["p_value"] <= u["alpha"]
    assert f"p = {u['p_value']:.2g}" in u["what"] and u["not_kept"] in u["what"]
    assert u["not_kept"] != "the sinusoid candidate was not among the candidates refine ran"
    assert u["tau"][0] <= n / 5.3 / 2 <= u["tau"][1]
