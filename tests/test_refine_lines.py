"""refine with line families and outliers (issue 29 items 2 and 3): the ``"periodic"`` and ``"outliers"`` removals
in time, the ``"sinusoid"`` curve candidate fed by the same line search, and list parameters rendered everywhere
(report, notebook summary, summary.json, HTML page)."""

from __future__ import annotations

import json

import numpy as np
import pytest

import allanite
from allanite.model.effects import EFFECTS, format_param
from allanite.model.refinement import levels
from allanite.report.fmt import json_value

FS = 100.0
N = 200_000


def _noise(seed):
    return allanite.simulate(N, FS, N=0.01, B=5e-4, seed=seed)


@pytest.fixture(scope="module")
def square():
    t = np.arange(N) / FS
    y = _noise(1) + 0.05 * np.sign(np.sin(2 * np.pi * 0.73 * t + 0.3))
    return allanite.refine(y, FS, progress=False)


def test_a_square_wave_is_one_periodic_step(square):
    assert square.found == ["periodic"]
    st = square.steps[0]
    assert len(st.params["fundamentals"]) == 1 and abs(st.params["fundamentals"][0] / 0.73 - 1) < 1e-3
    assert isinstance(st.params["lines"], int) and st.params["lines"] >= 8
    assert abs(st.params["rms"] / 0.05 - 1) < 0.05
    lo, hi = st.intervals["fundamentals"][0]
    assert lo < st.params["fundamentals"][0] < hi
    assert st.evidence["test"]["alpha"] == pytest.approx(levels.alpha("lines", levels.LEVEL))
    assert st.before["chi2_dof"] > 50 and st.after["chi2_dof"] < 2
    assert st.after["heldout_rms_adev_pct"] < st.before["heldout_rms_adev_pct"]


def test_list_and_int_params_render_everywhere(square):
    st = square.steps[0]
    text = square.report()
    assert "fundamentals = 0.73" in text and f"lines = {st.params['lines']}" in text
    html = square._repr_html_()
    assert "fundamentals = 0.73" in html and "in ;" not in html
    # summary.json: arrays and whole numbers
    js = json.loads(json.dumps({k: json_value(v) for k, v in st.params.items()}))
    assert isinstance(js["fundamentals"], list) and isinstance(js["lines"], int)
    iv = json_value(st.intervals["fundamentals"])
    assert isinstance(iv, list) and len(iv) == 1 and len(iv[0]) == 2
    two = format_param("fundamentals", [0.19, 1.37], [(0.18, 0.2), (1.36, 1.38)], "Hz", 3)
    assert two == "fundamentals = 0.19 [0.18, 0.2], 1.37 [1.36, 1.38] Hz"
    assert format_param("taps", 7) == "taps = 7" and format_param("filter", "boxcar") == "filter = boxcar"


@pytest.mark.slow  # a second square wave
def test_without_the_periodic_candidate_the_lines_come_one_sinusoid_at_a_time():
    t = np.arange(N) / FS
    y = _noise(2) + 0.05 * np.sign(np.sin(2 * np.pi * 0.73 * t + 0.3))
    cands = tuple(c for c in EFFECTS if c != "periodic")
    r = allanite.refine(y, FS, candidates=cands, progress=False)
    assert "periodic" not in r.found and r.found[0] == "sinusoid"
    assert abs(r.steps[0].params["f0"] / 0.73 - 1) < 1e-3


@pytest.mark.slow  # test_periodic.py's isolated line; test_refine.py's sinusoid
def test_an_isolated_line_stays_a_sinusoid():
    t = np.arange(N) / FS
    y = _noise(3) + 0.02 * np.sin(2 * np.pi * 3.1 * t)
    r = allanite.refine(y, FS, progress=False)
    assert r.found == ["sinusoid"]
    assert abs(r.steps[0].params["f0"] / 3.1 - 1) < 1e-4
    assert abs(r.steps[0].params["amplitude"] / 0.02 - 1) < 0.05


def test_a_family_whose_phase_wanders_is_left_to_the_sinusoid_term():
    # a site's sway: a 0.56 Hz line and its third harmonic whose phase random-walks (coherence ≈ 10 s), as the
    # ADIS16405 accelerometers' 0.56 Hz line does across their blocks. Removed in time, the family does not
    # predict the samples of the other part (turned down); its power is still on the curve, which the sinusoid
    # term describes — the lines must reach that candidate (before, they were dropped with the family).
    n = 150_000
    rng = np.random.default_rng(1)
    t = np.arange(n) / FS
    phase = 2 * np.pi * 0.56 * t + np.cumsum(rng.standard_normal(n)) * np.sqrt(2.0 / (10.0 * FS))
    y = allanite.simulate(n, FS, N=2e-3, B=3e-4, seed=101) + 0.02 * np.sin(phase) + 0.006 * np.sin(3 * phase + 1)
    r = allanite.refine(y, FS, progress=False)
    assert any("rejected" in e for e in r.considered["periodic"])
    assert r.found[0] == "sinusoid" and abs(r.steps[0].params["f0"] / 0.56 - 1) < 0.02
    # nothing found: 347 (the lines were lost). The line's power is held in the curve's fits (0.0191 by its power
    # in the spectrum; the free curve column had said 0.0194): the misfit left is the column's shape, a
    # sinusoid's, which a line whose phase wanders follows only up to its coherence time (10 s) — a short-τ term
    # takes part of it (before, a Gauss–Markov term of T_c 0.09 s, χ²/dof 10; held, a 7 Hz pole, 47), and the
    # report says the model still misses something there
    assert r.start.chi2_dof > 300 and r.fit.chi2_dof < 60
    assert r.steps[0].final_params == r.steps[0].params and r.unexplained


def test_sparse_spikes_are_one_outliers_step():
    y = _noise(4)
    rng = np.random.default_rng(4)
    at = rng.choice(np.arange(5, N - 5), 30, replace=False)
    y[at] += rng.choice([-1.0, 1.0], 30) * 1.0  # 10 σ of the white noise
    r = allanite.refine(y, FS, progress=False)
    assert r.found[0] == "outliers"
    st = r.steps[0]
    assert st.params["rate"] == pytest.approx(30 / N, rel=0.2)
    assert st.evidence["heldout_variance_ratio"] < 1
    assert len(st.evidence["adev_before"]) == len(st.evidence["adev_after"]) == len(st.evidence["adev_tau_s"])
    assert st.evidence["adev_after"][0] < st.evidence["adev_before"][0]
    assert "outliers" in r.report()


def test_the_budget_has_an_outlier_share_and_the_lines_share_both_line_effects():
    assert levels.share("outliers") == pytest.approx(0.05)
    assert levels.share("curve") == pytest.approx(
        1 - 0.2 - 0.008 - 0.2 - 0.05 - 2 * 0.075 - 0.002 - sum(levels.UNEXPLAINED_SHARES.values())
    )  # 0.008: a line of few cycles, tested in time (allanite.model.slowline); 0.002: random telegraph noise
    assert "periodic" not in levels.TIME_SHARES  # the line search's share covers it
