"""Smoke test of paper 004's real-data bench (``benches/paper004.py --quick``): it runs on ADIS16405 run 1
and two short simulated records, and writes the tables and figures. The recorded full run is
``benches/results/paper004.md``; nothing here asserts a forecast's quality."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[1] / "benches" / "paper004.py"


def test_paper004_bench_quick(tmp_path, shared_data):
    if not (shared_data / "adis16405" / "adis16405_run1_100Hz.csv.gz").is_file():
        pytest.skip("ADIS16405 run 1 not in the shared data")
    env = dict(os.environ, ALLANITE_SHARED_DATA=str(shared_data), MPLBACKEND="Agg")
    proc = subprocess.run(
        [sys.executable, str(SCRIPT), "--quick", "--out", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=180,
        env=env,
    )
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-4000:]
    md = (tmp_path / "paper004.md").read_text(encoding="utf-8")
    for head in (
        "## Findings",
        "## Which terms the frames resolve",
        "**Paper 004 Table 1 (traditional GM(1,1), its laser gyro)**",
        "**ours, GM(1,1) — honest**",
        "**ours, Holt — paper rule**",
        "## Simulated drifting records (1 seeds per scenario, 270000 samples each)",
    ):
        assert head in md
    # run 1's N is resolved on every axis: a row per axis in the paper layout, with a C (grade) for N
    assert md.count("| X | n.f. | ") >= 1 and "| run 1 | X | N |" in md
    for name in ("paper004_run1_frames_x.png", "paper004_run1_forecast_x.png", "paper004_simulated_steady.png"):
        assert (tmp_path / name).stat().st_size > 10_000
