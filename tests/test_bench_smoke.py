"""Smoke tests of the engine benchmark scripts (``benches/bench_engine.py --quick``,
``benches/bench_davar_floor.py --quick``).

A correctness check only — it never asserts anything about speed: the script must run, write its
report, and allanite must agree with every baseline (NumPy prefix-sum DAVAR, allantools per window,
allantools static OADEV, workers=1 vs workers=2) to 1e-9 relative.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[1] / "benches" / "bench_engine.py"
FLOOR = SCRIPT.with_name("bench_davar_floor.py")

pytestmark = pytest.mark.skipif(not SCRIPT.is_file(), reason=f"{SCRIPT} not found")


def test_bench_engine_quick(tmp_path):
    pytest.importorskip("allantools")
    proc = subprocess.run(
        [sys.executable, str(SCRIPT), "--quick", "--out", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-4000:]
    report = json.loads((tmp_path / "engine.json").read_text(encoding="utf-8"))
    assert (tmp_path / "engine.md").read_text(encoding="utf-8").count("| ") > 10
    assert report["mode"] == "quick"
    cases = report["cases"]
    assert set(cases) == {"case1", "case2", "case3", "case4"}
    expected = {
        "case1": {"davar_prefix", "allantools_per_window"},
        "case2": {"davar_prefix", "allantools_per_window"},
        "case3": {"davar_prefix", "allantools_per_window", "workers"},
        "case4": {"allantools_oadev"},
    }
    for name, case in cases.items():
        comps = {c["key"]: c for c in case["comparisons"]}
        assert set(comps) == expected[name], name
        assert math.isfinite(case["allanite"]["seconds"]) and case["allanite"]["seconds"] > 0
        for key, c in comps.items():
            assert math.isfinite(c["ratio"]) and c["ratio"] > 0, (name, key, c["ratio"])
            assert math.isfinite(c["max_rel_diff"]), (name, key)
            assert c["max_rel_diff"] <= 1e-9, (name, key, c["max_rel_diff"])
            assert c["n_compared"] > 0, (name, key)
            if "taus_match_exactly" in c:
                assert c["taus_match_exactly"] and c["taus_missing_from_baseline"] == 0, (name, key)
        # case 1 is judged against its output floor (bench_davar_floor.py), not against the twin
        assert len(case["targets"]) >= (0 if name == "case1" else 1)
    assert cases["case2"]["params"]["n_taus"] > 1
    assert next(c for c in cases["case3"]["comparisons"] if c["key"] == "workers")["bit_identical"] is True


def test_bench_davar_floor_quick(tmp_path):
    """The hop-1 surface against its output floor: the script runs, times call and floor interleaved,
    and the surface agrees with the per-window recomputation to 1e-12."""
    proc = subprocess.run(
        [sys.executable, str(FLOOR), "--quick", "--out", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-4000:]
    report = json.loads((tmp_path / "davar_floor.json").read_text(encoding="utf-8"))
    assert "call ÷ floor" in (tmp_path / "davar_floor.md").read_text(encoding="utf-8")
    assert report["params"]["hop"] == 1 and report["params"]["n_taus"] > 10
    assert len(report["times"]["call"]) == len(report["times"]["floor"]) == report["repeats"] >= 11
    assert math.isfinite(report["ratio"]) and report["ratio"] > 0
    assert report["max_rel_diff_vs_naive"] <= 1e-12


def test_clopper_pearson_matches_its_closed_forms():
    """The benches' one binomial interval (``benches/_common.py``): at k = 0 and k = n the exact bounds are
    1 − (α/2)^(1/n) and (α/2)^(1/n); inside, the interval holds k/n and the bounds are beta quantiles."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benches"))
    try:
        import _common
    finally:
        sys.path.pop(0)
    assert _common.clopper_pearson(0, 600) == (0.0, pytest.approx(1 - 0.025 ** (1 / 600), rel=1e-10))
    assert _common.clopper_pearson(10, 10) == (pytest.approx(0.025 ** (1 / 10), rel=1e-10), 1.0)
    lo, hi = _common.clopper_pearson(5, 76)
    assert lo < 5 / 76 < hi and (round(lo, 4), round(hi, 4)) == (0.0217, 0.1469)
    lo90, hi90 = _common.clopper_pearson(5, 76, level=0.9)
    assert lo < lo90 and hi90 < hi


def _bench_common():
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benches"))
    try:
        import _common
    finally:
        sys.path.pop(0)
    return _common


def test_rejection_rates_and_their_cells():
    """The calibration tables' rows (``refine_calibration.py``, ``refine_unexplained_null.py``): per level the
    count of p ≤ level, its share and the share's Clopper–Pearson interval, and the cells that print them."""
    c = _bench_common()
    p = [0.001, 0.004, 0.02, 0.3, 0.5, 0.7, 0.9, 0.05]
    rates = c.rejection_rates(p, (0.0025, 0.01, 0.05, 0.1))
    assert list(rates) == ["0.0025", "0.01", "0.05", "0.1"]
    assert [r["rejections"] for r in rates.values()] == [1, 2, 4, 4]
    assert rates["0.05"]["rate"] == 0.5 and rates["0.05"]["interval_95"] == c.clopper_pearson(4, 8)
    r = {"rejections": 3, "rate": 0.0125, "interval_95": (0.004, 0.029)}
    assert c.rate_cell(r) == "1.25 % (0.40–2.90)"
    assert c.rate_cell(r, count=True) == "3 = 1.25 % (0.40–2.90)"


def test_refine_bench_cells():
    """The cells refine_blind.py, refine_curves.py and refine_sensors.py share."""
    c = _bench_common()
    assert c.arrow_cell((12.04, 1.291)) == "12 → 1.29"
    assert c.arrow_cell((2.5, None)) == "2.5 → —" and c.arrow_cell(None) == c.arrow_cell((None, 1.0)) == "—"
    assert c.param_errors_cell({"f0": 0.0123, "kind": "too wide", "tau": None}) == "f0 +1.2%, kind too wide"
    steps = [{"effect": "sinusoid", "params": {"f0": 1.70123, "harmonics": 2}}, {"effect": "white", "params": {}}]
    assert c.steps_cell(steps, 3) == "sinusoid (f0 1.7, harmonics 2); white ()"
    assert c.steps_cell(steps, 4) == "sinusoid (f0 1.701, harmonics 2); white ()"
    assert c.steps_cell([], 3) == "nothing"
    assert [c.without_candidate_cell(x) for x in (None, [], [{}, {}])] == ["—", "**none**", "2 region(s)"]
    m = {"cpu_model": "CPU X", "cpus_usable": 2, "git_commit": "abc1234", "date_utc": "2026-11-26T17:00:00"}
    assert c.machine_line(m) == "CPU X, 2 CPUs, allanite at abc1234, 2026-11-26"


def test_write_results_writes_the_page_and_its_json(tmp_path):
    c = _bench_common()
    c.write_results(tmp_path, "x", ["# t", "", "| a |"], [{"v": 1.5}])
    c.write_results(tmp_path, "y", ["# t"], [], end="")
    assert (tmp_path / "x.md").read_text() == "# t\n\n| a |\n" and (tmp_path / "y.md").read_text() == "# t"
    assert json.loads((tmp_path / "x.json").read_text()) == [{"v": 1.5}]
