#!/usr/bin/env python3
"""The report command's figure process (issue 30 item 2): its set-up, and the two processes that draw.

1. **Set-up**: CPU seconds of importing what the figures need (``matplotlib.figure``, the Agg canvas,
   ``mpl_toolkits.mplot3d``, ``allanite.plot``) in a fresh process, with and without the figure process's
   ``_worker._skip_setter_docs`` (matplotlib's Artist classes not writing their ``set`` docstrings), alternating.
2. **The command**: ``allanite report <ADIS16405 run 1> --fs 100 --columns gyro_x,gyro_y,gyro_z --unit deg/s -q``
   in fresh processes with the figure process forced on (``rendering.idle_cores`` reporting every core idle, as
   on an idle two-core machine; otherwise a busy machine would draw the figures in the command's own process),
   this checkout and ``--baseline``'s alternating: wall, CPU (the command and the processes it reaped), when the
   report was handed over, when each of the two drawing processes finished its last figure and the gap between
   them (a process done early leaves its core idle while the other still draws), and whether the PNGs are the
   baseline's bytes.

Usage::

    python benches/bench_figure_worker.py --baseline /path/to/main/python --rounds 5
    # -> benches/results/figure_worker.{md,json}

Timing lives here, never in a pass/fail test. The machine's load is noted at the start and the end: on a
machine busy with other work the wall times are that load's, the CPU times and the gap less so.
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import _common

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
ADIS = "adis16405/adis16405_run1_100Hz.csv.gz"
ARGS = ["--fs", "100", "--columns", "gyro_x,gyro_y,gyro_z", "--unit", "deg/s", "-q"]

SETUP = r"""
import json, sys, time
skip = sys.argv[1] == "skip"
c0 = time.process_time()
import allanite.cli
from allanite.report import _worker
c1 = time.process_time()
if skip:
    _worker._skip_setter_docs()
import matplotlib.figure, matplotlib.backends.backend_agg, mpl_toolkits.mplot3d, allanite.plot
print(json.dumps({"cpu_s": time.process_time() - c1}))
"""

#: The command with the figure process forced on, stamped: the hand-over and every figure (start, end, process).
COMMAND = r"""
import json, os, sys, time
T0 = time.perf_counter()
import allanite.report.rendering as R
R.idle_cores = lambda cores: float(cores)
real_png = R.png
def png(spec, dpi):
    out = real_png(spec, dpi)
    print("FIG " + json.dumps([os.getpid(), spec[0], time.perf_counter() - T0]), file=sys.stderr, flush=True)
    return out
R.png = png
import allanite.report._worker as W
real_hand_over = W.hand_over
def hand_over(rep, dpi):
    print("HAND " + json.dumps(time.perf_counter() - T0), file=sys.stderr, flush=True)
    return real_hand_over(rep, dpi)
W.hand_over = hand_over
from allanite.cli import main
main(sys.argv[1:])
"""


def setup_rounds(rounds: int) -> dict:
    res: dict = {"plain": [], "skip": []}
    for i in range(rounds):
        for mode in ("plain", "skip") if i % 2 == 0 else ("skip", "plain"):
            p = subprocess.run([sys.executable, "-c", SETUP, mode], env=_env(REPO / "python"), capture_output=True,
                               text=True, check=True)  # fmt: skip
            res[mode].append(json.loads(p.stdout.strip().splitlines()[-1])["cpu_s"])
    return res


def _env(python_dir: Path) -> dict:
    return {**os.environ, "PYTHONPATH": str(python_dir)}


def command_once(data: Path, python_dir: Path, out: Path) -> dict:
    """One stamped run of the command; the stamps relative to the driver's start."""
    with tempfile.TemporaryFile() as fe:
        t0 = dt.datetime.now()
        p = subprocess.Popen([sys.executable, "-c", COMMAND, "report", str(data), *ARGS, "--out", str(out)],
                             env=_env(python_dir), stdout=subprocess.DEVNULL, stderr=fe)  # fmt: skip
        _, code, ru = os.wait4(p.pid, 0)
        wall = (dt.datetime.now() - t0).total_seconds()
        p.returncode = os.waitstatus_to_exitcode(code)
        fe.seek(0)
        err = fe.read().decode(errors="replace")
    if p.returncode != 0:
        raise RuntimeError(f"the report failed ({p.returncode}): {err[-2000:]}")
    hand = [json.loads(m) for m in re.findall(r"^HAND (.*)$", err, re.M)]
    figs = [json.loads(m) for m in re.findall(r"^FIG (.*)$", err, re.M)]
    ends: dict = {}
    for pid, name, t in figs:
        if name != "warm-up":
            ends[pid] = max(ends.get(pid, 0.0), t)
    last = sorted(ends.values())
    return {
        "wall_s": wall,
        "cpu_s": ru.ru_utime + ru.ru_stime,
        "hand_over_s": hand[0] if hand else None,
        "drawing_processes": len(ends),
        "last_figure_s": last,
        "gap_s": last[-1] - last[0] if len(last) > 1 else None,
        "figures": len([f for f in figs if f[1] != "warm-up"]),
    }


def pngs(folder: Path) -> dict:
    return {p.name: p.read_bytes() for p in sorted(folder.glob("*.png"))}


def command_rounds(data: Path, baseline: Path | None, rounds: int, tmp: Path) -> dict:
    sides = [("after", REPO / "python")] + ([("before", baseline)] if baseline is not None else [])
    res: dict = {label: [] for label, _ in sides}
    identical = None
    for i in range(rounds):
        for label, pdir in sides if i % 2 == 0 else sides[::-1]:
            res[label].append(command_once(data, pdir, tmp / label))
    if baseline is not None:
        identical = pngs(tmp / "after") == pngs(tmp / "before")
    return {"runs": res, "pngs_identical_to_baseline": identical}


def _med(values) -> float:
    values = [v for v in values if v is not None]
    return statistics.median(values) if values else float("nan")


def write_md(res: dict, path: Path) -> None:
    L = ["# The report's figure process: set-up and the two drawing processes (issue 30 item 2)\n"]
    L.append(
        f"`python benches/bench_figure_worker.py` — {res['date']}, commit {res['commit']}, baseline "
        f"{res['baseline']}. Load at start {res['load_start']}, at end {res['load_end']} (2 CPUs).\n"
    )
    s = res["setup"]
    ratios = [a / b for a, b in zip(s["plain"], s["skip"])]
    L.append("## Set-up: importing what the figures need (fresh processes, alternating)\n")
    L.append("| | CPU s, median | each round |\n|---|---|---|")
    for k, name in (("plain", "as matplotlib imports"), ("skip", "with `_skip_setter_docs`")):
        L.append(f"| {name} | {_med(s[k]):.3f} | {', '.join(f'{v:.3f}' for v in s[k])} |")
    L.append(f"\nPer round plain / skip: median {_med(ratios):.2f}× (−{_med(s['plain']) - _med(s['skip']):.3f} s).\n")
    c = res["command"]
    L.append("## The command, figure process forced on (fresh processes, alternating)\n")
    L.append("| | wall s | CPU s | hand-over s | last figure of each drawing process s | gap s |")
    L.append("|---|---|---|---|---|---|")
    for label, runs in c["runs"].items():
        for r in runs:
            ends = " / ".join(f"{t:.2f}" for t in r["last_figure_s"])
            gap = "—" if r["gap_s"] is None else f"{r['gap_s']:.2f}"
            L.append(f"| {label} | {r['wall_s']:.2f} | {r['cpu_s']:.2f} | {r['hand_over_s']:.2f} | {ends} | {gap} |")
    L.append("")
    for label, runs in c["runs"].items():
        L.append(
            f"- {label}: median wall {_med(r['wall_s'] for r in runs):.2f} s, CPU {_med(r['cpu_s'] for r in runs):.2f}"
            f" s, gap between the drawing processes {_med(r['gap_s'] for r in runs):.2f} s"
        )
    if c["pngs_identical_to_baseline"] is not None:
        L.append(f"- PNG bytes identical to the baseline's: {c['pngs_identical_to_baseline']}")
    path.write_text("\n".join(L) + "\n", encoding="utf-8")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--baseline", type=Path, default=None, help="python/ folder of the checkout to compare with")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--out", type=Path, default=HERE / "results")
    args = ap.parse_args()
    data = _common.shared_data_dir() / ADIS
    load = lambda: Path("/proc/loadavg").read_text().split()[:3]  # noqa: E731
    res: dict = {"date": dt.datetime.now(dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"), "load_start": load()}
    res["commit"] = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=REPO, capture_output=True,
                                   text=True).stdout.strip()  # fmt: skip
    res["baseline"] = str(args.baseline) if args.baseline else "none"
    res["setup"] = setup_rounds(args.rounds)
    if data.exists():
        with tempfile.TemporaryDirectory() as tmp:
            res["command"] = command_rounds(data, args.baseline, args.rounds, Path(tmp))
    else:
        print(f"skipping the command: {data} not found (ALLANITE_SHARED_DATA)", file=sys.stderr)
        res["command"] = {"runs": {}, "pngs_identical_to_baseline": None}
    res["load_end"] = load()
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "figure_worker.json").write_text(json.dumps(res, indent=1), encoding="utf-8")
    write_md(res, args.out / "figure_worker.md")
    print((args.out / "figure_worker.md").read_text(encoding="utf-8"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
