"""Smoke test of the paper-000 Table 3 benchmark (``benches/table3.py --quick``).

A correctness check only — never a timing assertion: the script must run, write its report, time every
method (finite, positive seconds) and every method must agree with every other at the (m, window) they
share to 1e-9 relative (the NumPy prefix-sum twin at m ≤ W/9, where its own cancellation is bounded).
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[1] / "benches" / "table3.py"

pytestmark = pytest.mark.skipif(not SCRIPT.is_file(), reason=f"{SCRIPT} not found")

METHODS = {"naive", "fast", "improved", "prefix_all", "prefix_exp", "allantools_all", "allantools_exp"}


def test_table3_quick(tmp_path):
    pytest.importorskip("allantools")
    pytest.importorskip("matplotlib")
    proc = subprocess.run(
        [sys.executable, str(SCRIPT), "--quick", "--out", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-4000:]
    report = json.loads((tmp_path / "table3.json").read_text(encoding="utf-8"))
    assert report["mode"] == "quick"
    assert (tmp_path / "table3.md").read_text(encoding="utf-8").count("| ") > 20
    assert (tmp_path / "table3.png").stat().st_size > 1000
    assert (tmp_path / "scaling.png").stat().st_size > 1000
    assert len(report["table"]) >= 2
    for row in report["table"]:
        assert set(row["methods"]) == METHODS, row["n"]
        for key, m in row["methods"].items():
            assert math.isfinite(m["seconds"]) and m["seconds"] > 0, (row["n"], key, m["seconds"])
            assert isinstance(m["extrapolated"], bool) and m["how"], (row["n"], key)
        assert any(m["extrapolated"] for m in row["methods"].values()) or row["n"] == min(
            r["n"] for r in report["table"]
        )
        compared = 0
        for pair, c in row["agreement"].items():
            if c["n_compared"] == 0:
                continue
            compared += 1
            assert c["checked"] is not None and c["checked"] <= 1e-9, (row["n"], pair, c)
            if "prefix" not in pair:
                assert c["max_rel_diff"] <= 1e-9, (row["n"], pair, c)
        # every method is compared with at least one other
        seen = {name for pair, c in row["agreement"].items() if c["n_compared"] > 0 for name in pair.split(" vs ")}
        assert seen == METHODS, (row["n"], METHODS - seen)
        assert compared >= 10
    assert report["max_rel_diff_overall"] <= 1e-9
    sc = report["scaling"]
    assert {s["workers"] for s in sc} == {1, 2}
    for s in sc:
        assert math.isfinite(s["seconds"]) and s["seconds"] > 0 and s["peak_rss_bytes"] > 0
        assert s["bit_identical_1_vs_2"] is True
