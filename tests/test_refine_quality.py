"""Clipped and held samples in ``Refinement.unexplained`` (issue 29, "say what is still missing").

The two checks of :mod:`allanite.model.refinement._quality` look only at the samples as given, so most tests
run them on a context of the record alone (no curve fit); one default ``refine`` call shows the words on every
surface. The ADIS16405 logs (quantised: 0.05 °/s and 1/300 g steps) must raise neither.
"""

from __future__ import annotations

import html as html_mod
import json
import re
import types

import numpy as np
import pytest

import allanite
from allanite import cli
from allanite.model.refinement import _quality as qc
from allanite.model.refinement.levels import alpha
from allanite.model.refinement.missing import CHECKS
from allanite.model.refinement.words import describe_region

A_CLIP = alpha("unexplained:clipped", 0.05)
A_HELD = alpha("unexplained:held", 0.05)


def _ctx(y, fs: float, unit: str | None = "deg/s"):
    """What the two checks read of a ``MissingContext``: the samples as given, their rate, τ₀, unit, level."""
    tau0 = types.SimpleNamespace(tau=np.array([1.0 / fs]))
    return types.SimpleNamespace(samples=np.asarray(y, dtype=np.float64), fs=fs, curve=tau0, unit=unit, level=0.05)


def _both(y, fs: float = 100.0) -> list[dict]:
    ctx = _ctx(y, fs)
    return qc.clipped_check(ctx, A_CLIP) + qc.held_check(ctx, A_HELD)


def test_the_checks_are_registered_with_their_shares():
    assert CHECKS["clipped"] is qc.clipped_check and CHECKS["held"] is qc.held_check
    assert A_CLIP == pytest.approx(0.05 * 0.0025) and A_HELD == pytest.approx(0.05 * 0.0025)


def test_a_record_saturated_at_its_rail_is_said_clipped_with_the_value_and_times():
    rng = np.random.default_rng(1)
    fs = 400.0
    t = np.arange(400_000) / fs
    x = 0.015 * rng.standard_normal(t.size) + 0.1 * np.exp(-(((t - 300.0) / 3.0) ** 2))  # a bump past 0.08 (5σ)
    out = _both(np.minimum(x, 0.08), fs)
    assert [e["domain"] for e in out] == ["clipped"]
    e = out[0]
    assert e["value"] == 0.08 and e["samples"] == int(np.sum(x >= 0.08))
    assert 295.0 < e["t"][0] < e["t"][1] < 305.0
    assert "clipped at 0.08 deg/s" in e["what"] and "largest value" in e["what"]
    assert describe_region(e).startswith("t 29")


def test_a_stretch_held_at_one_value_inside_the_range_is_said_with_its_length():
    """refine_blind3's case: 6 s at 0.08 °/s while the noise elsewhere reaches beyond it (400 Hz × 10⁶)."""
    rng = np.random.default_rng(3)
    fs = 400.0
    y = allanite.simulate(1_000_000, fs, N=2e-3, B=4e-4, K=1e-5, seed=rng)
    assert y.max() > 0.08
    y[480_000:482_400] = 0.08
    out = _both(y, fs)
    assert [e["domain"] for e in out] == ["clipped"]
    e = out[0]
    assert e["samples"] == 2400 and e["runs"] == 1 and e["value"] == 0.08
    assert e["t"] == pytest.approx((1200.0, 1206.0))
    assert "2400 samples in a row at 0.08 deg/s" in e["what"]
    assert describe_region(e).startswith("t 1200–1206 s, τ 0.0025 s: the record holds one value")


def test_repeated_samples_of_a_continuous_record_are_said_with_their_rate_and_period():
    y = allanite.simulate(200_000, 100.0, N=2e-3, K=2e-5, seed=5)
    idx = np.arange(50, y.size, 50)  # the driver repeats one output every 0.5 s
    y[idx] = y[idx - 1]
    out = _both(y)
    assert [e["domain"] for e in out] == ["held"]
    e = out[0]
    assert e["repeats"] == idx.size and e["fraction"] == pytest.approx(idx.size / y.size, rel=1e-3)
    assert "2 % of the samples repeat the one before" in e["what"] and "every ≈ 0.5 s" in e["what"]


def test_repeated_samples_of_a_quantised_record_are_told_from_its_own_ties():
    rng = np.random.default_rng(7)
    y = np.round(6.4 * rng.standard_normal(1_000_000)) * 0.05  # ADIS16405-like gyro: ≈ 9 steps per difference
    counts = qc.tie_counts(y)
    expected = qc.expected_ties(counts["n1"], counts["n2"])
    assert counts["n0"] == pytest.approx(expected, rel=0.03)  # the lattice predicts the quantisation's ties
    assert _both(y) == []
    idx = np.arange(50, y.size, 50)
    y[idx] = y[idx - 1]
    out = _both(y)
    assert [e["domain"] for e in out] == ["held"]
    assert out[0]["repeats"] > 1.25 * out[0]["expected"] and out[0]["expected"] == pytest.approx(expected, rel=0.05)


@pytest.mark.parametrize("sigma", [0.5, 1.0, 3.0, 20.0])
def test_clean_quantised_records_say_nothing(sigma):
    """Quantised white noise with a random walk, from half a step to twenty steps of noise: neither check."""
    for seed in range(3):
        rng = np.random.default_rng(100 + seed)
        x = sigma * rng.standard_normal(200_000) + 0.01 * sigma * np.cumsum(rng.standard_normal(200_000))
        assert _both(np.round(x)) == []


def _counter_output(seed: int, n: int = 1_000_000, fs: float = 2000.0) -> np.ndarray:
    """A delta-angle counter's rate: the angle quantised to 3× its white noise's step per sample, differenced."""
    rng = np.random.default_rng(seed)
    rate = 1.7e-3 * np.sqrt(fs) * rng.standard_normal(n) + 4.2e-3
    q = 3.0 * 1.7e-3 / np.sqrt(fs)
    return np.diff(np.floor(np.cumsum(rate) / fs / q), prepend=0.0) * (q * fs)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_delta_angle_counters_output_is_not_said_held(seed):
    """Q-dominated, anti-correlated, three levels: 56 % of neighbours tie, the lattice's log-quadratic predicts
    31 % (it was said held: "25 % of the samples repeat the one before"), the ties at lag 2 are 57 %."""
    y = _counter_output(seed)
    c = qc.tie_counts(y)
    assert c["n0"] > 1.7 * qc.expected_ties(c["n1"], c["n2"])  # the lattice's prediction alone is far off
    assert qc.held_check(_ctx(y, 2000.0), A_HELD) == []
    assert 1.0 < qc.lag2_ties(y) / c["n0"] < 1.1  # the ties two samples apart are the null


def test_repeats_in_a_continuous_record_outrun_its_ties_at_lag_2():
    """The lag-2 reference leaves a driver's repeats said: a repeat ties with the sample before only."""
    y = allanite.simulate(200_000, 100.0, N=2e-3, K=2e-5, seed=6)
    idx = np.arange(50, y.size, 50)
    y[idx] = y[idx - 1]
    y[idx[::2] + 1] = y[idx[::2]]  # every other one repeated twice: those tie at lag 2 too
    twice = idx[::2].size
    assert qc.lag2_ties(y) == twice
    out = qc.held_check(_ctx(y, 100.0), A_HELD)
    assert [e["domain"] for e in out] == ["held"] and out[0]["repeats"] == idx.size + twice


def test_float32_and_continuous_records_say_nothing():
    rng = np.random.default_rng(11)
    on_bias = (250.0 + 0.01 * rng.standard_normal(1_000_000)).astype(np.float32)  # float32 spacing 1.5e-5
    counts = qc.tie_counts(np.asarray(on_bias, dtype=np.float64))
    assert counts["n0"] > 100  # float32 samples do tie …
    assert _both(on_bias, 1000.0) == []  # … at the rate their spacing gives
    assert _both((0.012 + 0.01 * rng.standard_normal(500_000)).astype(np.float32)) == []
    assert _both(rng.standard_normal(200_000)) == []


def test_refine_says_repeated_samples_on_every_surface():
    y = allanite.simulate(100_000, 100.0, N=2e-3, K=2e-5, seed=5)
    idx = np.arange(50, y.size, 50)
    y[idx] = y[idx - 1]
    r = allanite.refine(y, 100.0, unit="deg/s", progress=False)
    held = [e for e in r.unexplained if e["domain"] == "held"]
    assert len(held) == 1 and held[0]["repeats"] == idx.size
    assert any("repeat the one before" in s for s in r.missing_sentences())
    assert "repeat the one before" in r.report()
    assert "repeat the one before" in r._repr_html_()


def test_the_adis16405_logs_are_neither_clipped_nor_held(shared_data):
    """Quantised gyros (0.05 °/s, ≈ 9 steps of noise per difference) and accelerometers (1/300 g, 1.2–1.7)."""
    log = allanite.read_log(shared_data / "adis16405" / "adis16405_run1_100Hz.csv.gz", fs=100.0)
    data = np.asarray(log.data, dtype=np.float64)
    for k in range(data.shape[1]):
        assert _both(data[:, k]) == [], k


def test_cli_console_page_and_json_say_a_clipped_record(tmp_path, capsys):
    """``allanite report --refine-candidates none`` (only the checks): the console, the page and summary.json."""
    rng = np.random.default_rng(2)
    t = np.arange(60_000) / 100.0
    x = 0.015 * rng.standard_normal(t.size) + 0.1 * np.exp(-(((t - 300.0) / 3.0) ** 2))
    log, out = tmp_path / "clipped.npy", tmp_path / "out"
    np.save(log, np.minimum(x, 0.08))
    args = ["report", str(log), "--fs", "100", "--unit", "deg/s", "--window", "6000", "--hop", "3000", "--no-fit"]
    assert cli.main([*args, "--refine-candidates", "none", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    json.dumps(summary, allow_nan=False)
    (clip,) = [e for e in summary["refinement"]["axes"][0]["unexplained"] if e["domain"] == "clipped"]
    assert 290.0 < clip["t_s"][0] < clip["t_s"][1] < 310.0
    assert "clipped at 0.08 deg/s" in clip["text"]
    page = html_mod.unescape(re.sub(r"<[^>]+>", "", (out / "report.html").read_text(encoding="utf-8")))
    assert clip["text"] in page[page.index("What the model still misses") :]
    assert clip["text"] in printed
