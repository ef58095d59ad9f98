"""An accepted line whose amplitude follows a channel: its term a·(1 + g·(channel − mean))·cos(2πf0t + φ), kept
by its own nested test and held-out blocks (allanite.model.refinement._line_gain); small seeded records."""

from __future__ import annotations

import numpy as np
import pytest

from allanite import avar
from allanite.model._signatures import sinusoid_avar
from allanite.model.refinement import _line_gain as lg
from allanite.model.refinement import loop
from allanite.model.refinement._line_constancy import line_constancy
from allanite.model.refinement.curvefit import held_theta
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


def _true_gain(gain: float, n: int) -> tuple[dict, np.ndarray]:
    """The gain dict of :func:`_record`'s line as :func:`._line_gain.line_gain` returns it, at the truth (A the
    phasor of AMP·sin(2πF0t + 0.7), 16 blocks), and the noiseless temperature."""
    t = np.arange(n) / FS
    temp = 25.0 + 10.0 * np.sin(2 * np.pi * 1.5 * t / t[-1])
    a = AMP * np.exp(1j * (0.7 - np.pi / 2))
    edges = np.linspace(0.0, n / FS, 17)
    g = {
        "gain": gain,
        "gain_interval": (0.9 * gain, 1.1 * gain),
        "mean": float(temp.mean()),
        "phasor": (a.real, a.imag),
    }
    return g | {"centres_s": ((edges[:-1] + edges[1:]) / 2).tolist()}, temp


@pytest.mark.parametrize("gain", [0.0, 0.02])
def test_modulated_line_held_at_its_exact_allan_variance(gain):
    # the term of a line with its gain: the modelled component's own Allan variance on the unit sinusoid column —
    # A²·(1 + g²·var x) (2 % above A² here), not A², and that column's shape to 10⁻³ where the line matters
    n = 30_000
    g, temp = _true_gain(gain, n)
    tau = np.unique(np.round(np.geomspace(1, 3000, 60))) / FS
    theta, var, share = lg.modulated_held(n, FS, F0, g, temp, tau, 1e-4)
    expect = AMP**2 * (1.0 + gain**2 * np.var(temp))
    assert theta == pytest.approx(expect, rel=2e-3)
    assert share == pytest.approx(AMP**2 / theta, rel=1e-9) and share <= 1.0
    if gain:
        assert theta / AMP**2 - 1.0 > 0.015
    t = np.arange(n) / FS
    comp = AMP * (1.0 + gain * (temp - temp.mean())) * np.sin(2 * np.pi * F0 * t + 0.7)
    res = avar(comp, FS, taus=tau)
    col = theta * sinusoid_avar(res.tau, F0, FS)
    big = col > 0.01 * col.max()
    assert np.max(np.abs(res.avar[big] / col[big] - 1.0)) < 1e-3
    # first-order variance: |A|'s SD 10⁻⁴ (0.5 %) and the gain's ±10 % (of 2 % of θ)
    sd_a = 2.0 * theta / AMP * 1e-4
    assert var == pytest.approx(sd_a**2 + (2.0 * (theta - AMP**2) * 0.1) ** 2, rel=1e-6)


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
    # its term held at the modelled component's exact Allan variance, whose interval covers the simulated line's
    t = np.arange(y.size) / FS
    temp = 25.0 + 10.0 * np.sin(2 * np.pi * 1.5 * t / t[-1])
    truth = AMP**2 * np.mean((1.0 + 0.02 * (temp - temp.mean())) ** 2)
    theta, var = held_theta(r.effects[0][0])
    assert abs(theta - truth) < 2.0 * np.sqrt(var) < 0.02 * truth
    assert not r.unexplained


@pytest.mark.slow  # covered by default: test_refine_models_the_gain (the gain right: nothing said)
def test_refine_tells_a_misfit_gain(monkeypatch):
    # a gain 4× too large: its term's Allan variance (θ 28 % above the line's) departs from the curve — told by
    # "allan" at the line's τ, and by the "line" check (the samples less the wrong gain's part still change)
    y, ch = _record(0.02)
    found = lg.line_gain

    def wrong(*args, **kwargs):
        g = found(*args, **kwargs)
        return None if g is None else g | {"gain": 4.0 * g["gain"]}

    monkeypatch.setattr(loop, "line_gain", wrong)
    r = refine(y, FS, channels=ch, candidates=("sinusoid", "regression", "change_point"))
    said = {u["domain"]: u for u in r.unexplained}
    assert "allan" in said and "line" in said
    lo, hi = said["allan"]["tau"]
    assert lo <= 0.371 / F0 <= hi and said["allan"]["chi2_dof"] > 10.0  # the line's peak, τ ≈ 0.371/f0


def test_refine_constant_line_beside_coupled_temperature():
    y, ch = _record(0.0, couple=0.002)
    r = refine(y, FS, channels=ch, candidates=("sinusoid", "regression"))
    (st,) = [s for s in r.steps if s.effect == "sinusoid"]
    assert "gain" not in st.params and "channel" not in st.params
    assert [s.params["channel"] for s in r.steps if s.effect == "regression"] == ["temp"]
