"""Smoke test of ``benches/theo.py --quick``: it runs, writes its report and figures, allanite's Theo1
equals allantools.theo1 at the corrected τ, and the paper-001 part produces a full table. Never speed."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[1] / "benches" / "theo.py"

pytestmark = pytest.mark.skipif(not SCRIPT.is_file(), reason=f"{SCRIPT} not found")


def test_theo_bench_quick(tmp_path):
    pytest.importorskip("allantools")
    proc = subprocess.run(
        [sys.executable, str(SCRIPT), "--quick", "--out", str(tmp_path)], capture_output=True, text=True, timeout=300
    )
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-4000:]
    rep = json.loads((tmp_path / "theo.json").read_text(encoding="utf-8"))
    t = rep["timings"]
    assert t["theo1"]["compared_points"] >= 5 and t["theo1"]["max_rel_diff_variance"] < 1e-12
    assert t["dhvar"]["windows"] == 4_000 - 401 + 1
    p = rep["paper001"]
    for method in ("expected", "DAVAR", "DHVAR-A", "DHVAR"):
        assert set(p["table"][method]) == {"Q", "N", "B", "K", "R"}
    assert p["scatter"] and all("DHVAR" in row for row in p["scatter"])
    for png in ("theo_paper001_surfaces.png", "theo_paper001_series.png"):
        assert (tmp_path / png).stat().st_size > 10_000
    assert "Paper 001 rebuilt" in (tmp_path / "theo.md").read_text(encoding="utf-8")
