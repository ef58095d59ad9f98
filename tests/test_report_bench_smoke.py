"""Smoke test of ``benches/bench_report.py --quick``: it runs and writes sane JSON. Never timing or memory."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[1] / "benches" / "bench_report.py"
pytestmark = pytest.mark.skipif(not SCRIPT.is_file(), reason=f"{SCRIPT} not found")


def test_bench_report_quick(tmp_path):
    proc = subprocess.run(
        [sys.executable, str(SCRIPT), "--quick", "--out", str(tmp_path)], capture_output=True, text=True, timeout=300
    )
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-4000:]
    rep = json.loads((tmp_path / "report_bench.json").read_text(encoding="utf-8"))
    m = rep["memory"]
    assert m["samples"] == 1_000_000 and m["file_bytes"] > 8_000_000
    assert m["davar"]["shape"][1] == (1_000_000 - 10_000) // 1_000 + 1 and m["davar"]["shape"][0] > 10
    assert m["davar"]["finite"] and m["avar"]["finite"]
    assert m["davar"]["vmhwm_bytes"] > m["file_bytes"]  # the mapped file's pages were touched
    assert "Report and large-log benchmark" in (tmp_path / "report_bench.md").read_text(encoding="utf-8")
