#!/usr/bin/env python3
"""The report's figures under the garbage collector's default threshold and the report's (issue 30 item 2).

Draws the 9 figures of the ADIS16405 run 1 report (3 gyro axes) one after another in this process, alternating
rounds between CPython's default youngest-generation threshold (700) and the report's
(``allanite.report.rendering.GC_THRESHOLD``, used while figures are drawn): CPU seconds of each round, and the
CPU seconds spent in collections (``gc.callbacks``, less sensitive to the machine's load than the total). The
PNG bytes of both settings are compared.

Usage::

    python benches/bench_figure_gc.py --rounds 16     # -> benches/results/figure_gc.{md,json}

Timing lives here, never in a pass/fail test. The machine's load is noted at the start and the end.
"""

from __future__ import annotations

import argparse
import datetime as dt
import gc
import os
import statistics
import sys
import time
from pathlib import Path

import _common
from allanite import read_log
from allanite.report import rendering
from allanite.report.build import from_log

DEFAULT = 700  # CPython's youngest-generation threshold


def _rounds(specs: list, n: int) -> tuple[dict, bool]:
    spent = {"gc": 0.0, "count": 0, "t": 0.0}

    def watch(phase, _info):
        if phase == "start":
            spent["t"] = time.process_time()
        else:
            spent["gc"] += time.process_time() - spent["t"]
            spent["count"] += 1

    report_threshold = rendering.GC_THRESHOLD
    res: dict = {DEFAULT: [], report_threshold: []}
    pngs = {}
    gc.callbacks.append(watch)
    try:
        for i in range(n):
            for th in (DEFAULT, report_threshold) if i % 2 == 0 else (report_threshold, DEFAULT):
                rendering.GC_THRESHOLD = th
                gc.set_threshold(DEFAULT, 10, 10)
                gc.collect()
                spent.update(gc=0.0, count=0)
                c0 = time.process_time()
                pngs[th] = rendering.render_pngs(specs, 100, lambda s: None, processes=1)
                res[th].append({"cpu_s": time.process_time() - c0, "gc_s": spent["gc"], "collections": spent["count"]})
    finally:
        gc.callbacks.remove(watch)
        rendering.GC_THRESHOLD = report_threshold
    return res, pngs[DEFAULT] == pngs[report_threshold]


def _load() -> list:
    return open("/proc/loadavg").read().split()[:3] if os.path.exists("/proc/loadavg") else []


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=16, help="rounds per setting (alternating)")
    ap.add_argument("--out", type=Path, default=_common.HERE / "results")
    args = ap.parse_args()
    data = _common.shared_data_dir() / "adis16405" / "adis16405_run1_100Hz.csv.gz"
    if not data.exists():
        print(f"the ADIS16405 log {data} is absent (set ALLANITE_SHARED_DATA): nothing to measure", file=sys.stderr)
        return 0
    load_start = _load()
    log = read_log(data, fs=100, columns=["gyro_x", "gyro_y", "gyro_z"], unit="deg/s")
    specs = from_log(log, progress=False).figure_specs()
    rendering.render_pngs(specs[:1], 100, lambda s: None, processes=1)  # matplotlib's set-up outside the timing
    res, identical = _rounds(specs, args.rounds)
    out = {
        "date": dt.datetime.now(dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "machine": _common.machine_info(),
        "load_start": load_start,
        "load_end": _load(),
        "figures": len(specs),
        "png_identical": identical,
        "rounds": {str(k): v for k, v in res.items()},
    }
    med = {k: {f: statistics.median(r[f] for r in v) for f in ("cpu_s", "gc_s", "collections")} for k, v in res.items()}
    pairs = [a["cpu_s"] / b["cpu_s"] for a, b in zip(res[DEFAULT], res[rendering.GC_THRESHOLD])]
    lines = [
        "# The report's figures and the garbage collector (issue 30 item 2)",
        "",
        f"`python benches/bench_figure_gc.py --rounds {args.rounds}` — {out['date']}; "
        f"{_common.machine_line(out['machine'])}. Load at start {load_start}, at end {out['load_end']}.",
        "",
        f"The {len(specs)} figures of the ADIS16405 run 1 report drawn one after another in one process, "
        f"{args.rounds} rounds per setting, alternating; medians.",
        "",
        "| youngest-generation threshold | CPU of the figures | of it in collections | collections |",
        "|---|---|---|---|",
    ]
    for k, m in med.items():
        name = f"{k} (CPython's default)" if k == DEFAULT else f"{k} (the report's, `GC_THRESHOLD`)"
        lines.append(f"| {name} | {m['cpu_s']:.2f} s | {m['gc_s']:.3f} s | {m['collections']:.0f} |")
    lines += [
        "",
        f"Same round's CPU ratio (default / the report's): median {statistics.median(pairs):.3f}, "
        f"{sum(p > 1 for p in pairs)} of {len(pairs)} rounds faster at the report's threshold. "
        f"PNG bytes identical: {identical}.",
        "CPU totals vary with the machine's load by more than the difference; the time in collections is the "
        "direct measure.",
    ]
    _common.write_results(args.out, "figure_gc", lines, out)
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
