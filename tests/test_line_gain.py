"""An accepted line whose amplitude follows a channel: its term a·(1 + g·(channel − mean))·cos(2πf0t + φ), kept
by its own nested test and held-out blocks (allanite.model.refinement._line_gain); small seeded records."""

from __future__ import annotations

import numpy as np
import pytest

from allanite.model.refinement import _line_gain as lg
from allanite.model.refinement._line_constancy import line_constancy
from allanite.model.refinement.levels import CONDITIONAL_SHARES, share
from allanite.model.refinement.loop import refine

FS, F0, AMP = 50.0, 2.0, 0.02


def _record(gain: float, couple: float = 0.0, n: int = 30_000, seed: int = 3):
    """A 2 Hz line of amplitude AMP·(1 + gain·(temp − mean)) on white noise, the temperature cycling 1.5 times
    over the record (±10 °C) and logged with 0.01 °C noise; ``couple`` the bias's own coupling to it."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / FS
    temp = 25.0 + 10.0 * np.sin(2 * np.pi * 1.5 * t / t[-1])
    line = AMP * (1.0 + gain * (temp - temp.mean())) * np.sin(2 * np.pi * F0 * t + 0.7)
    y = line + 0.01 * rng.standard_normal(n) + couple * (temp - 25.0)
    return y, {"temp": temp + 0.01 * rng.standard_normal(n)}


def test_share_is_conditional():
    assert CONDITIONAL_SHARES["sinusoid:gain"] == 0.02
    assert share("sinusoid:gain") == 0.02


def test_gain_found_and_its_component_leaves_a_constant_line():
    y, ch = _record(0.02)
    g = lg.line_gain(y, FS, F0, ch | {"other": np.cos(np.arange(y.size) / 5e3)}, 0.001)
    assert g is not None and g["channel"] == "temp"
    assert g["gain"] == pytest.approx(0.02, rel=0.2)
    lo, hi = g["gain_interval"]
    assert lo < g["gain"] < hi and hi - lo < 0.2 * g["gain"]
    assert g["heldout_ratio"] < 0.5 and g["statistic"] > g["threshold"]
    assert line_constancy(y, FS, F0, 0.001)["rejected"]  # the line changes along the record ...
    rest = y - lg.gain_component(y.size, FS, F0, g, ch["temp"])
    assert not line_constancy(rest, FS, F0, 0.001)["rejected"]  # ... and less its gain's part it does not


def test_constant_line_gets_no_gain():
    y, ch = _record(0.0, couple=0.002)
    assert lg.line_gain(y, FS, F0, ch, 0.001) is None
    assert lg.line_gain(y, FS, F0, {}, 0.001) is None


def test_refine_models_the_gain():
    y, ch = _record(0.02)
    r = refine(y, FS, channels=ch, candidates=("sinusoid", "regression", "change_point"))
    # the gain's part of the line is out of the samples the change points see: left in, its ±20 % modulation read
    # as the noise level changing (two change points, at 215 and 436 s of 600)
    assert [s.effect for s in r.steps] == ["sinusoid"]
    (st,) = [s for s in r.steps if s.effect == "sinusoid"]
    assert st.params["channel"] == "temp" and st.params["gain"] == pytest.approx(0.02, rel=0.2)
    assert st.final_params["gain"] == st.params["gain"] and "gain" in st.intervals
    assert st.evidence["gain_test"]["statistic"] > st.evidence["gain_test"]["threshold"]
    assert "gain = " in r.params_text(st) and "per unit of temp" in r.params_text(st)
    assert not [u for u in r.unexplained if u.get("domain") == "line"]  # modelled, not said


def test_refine_constant_line_beside_coupled_temperature():
    y, ch = _record(0.0, couple=0.002)
    r = refine(y, FS, channels=ch, candidates=("sinusoid", "regression"))
    (st,) = [s for s in r.steps if s.effect == "sinusoid"]
    assert "gain" not in st.params and "channel" not in st.params
    assert [s.params["channel"] for s in r.steps if s.effect == "regression"] == ["temp"]
