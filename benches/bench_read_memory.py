#!/usr/bin/env python3
"""Memory of reading a text log: ``read_log``'s peak resident set against the arrays it returns.

A seeded CSV (a time column at 100 Hz and three gyro columns, ≈ 40 bytes a row; also gzipped) is written once;
each read runs in a fresh process that notes its resident set after ``import allanite``, calls
``allanite.read_log(path, time_column="time")`` and reads the peak resident set (``VmHWM``; Linux). The ratio is
(peak − before) / (bytes of ``Log.data`` + ``Log.time``): 1 would be the arrays alone. With ``--baseline DIR`` (a
``python`` folder of another checkout, its ``_core`` built) the same reads alternate between it and this tree.

Usage::

    python benches/bench_read_memory.py                       # -> benches/results/read_memory.{json,md}
    python benches/bench_read_memory.py --baseline /tmp/base/python --rows 10000000
    python benches/bench_read_memory.py --quick --out DIR     # 10⁵ rows (seconds), not a measurement

Needs numpy and allanite; no external data. Times are printed for orientation (wall, CPU user + system).
"""

from __future__ import annotations

import argparse
import gzip
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from _common import log, machine_info

HERE = Path(__file__).resolve().parent
TREE = HERE.parent / "python"

# VmHWM, not ru_maxrss: a child's ru_maxrss starts from its parent's peak (kept across exec), VmHWM is its own
CHILD = """
import json, os, sys, time
def hwm():
    with open("/proc/self/status") as f:
        return next(int(ln.split()[1]) * 1024 for ln in f if ln.startswith("VmHWM:"))
sys.path.insert(0, sys.argv[2])
import allanite
before = hwm()
c0, w0 = time.process_time(), time.perf_counter()
lg = allanite.read_log(sys.argv[1], time_column="time")
cpu, wall = time.process_time() - c0, time.perf_counter() - w0
peak = hwm()
arrays = lg.data.nbytes + (lg.time.nbytes if lg.time is not None else 0)
print(json.dumps(dict(before=before, peak=peak, arrays=arrays, cpu=cpu, wall=wall, rows=int(lg.n_samples))))
"""


def write_log(path: Path, rows: int) -> None:
    """A seeded CSV: time (s, 100 Hz, two decimals) and three gyro columns (seven decimals)."""
    import numpy as np

    rng = np.random.default_rng(1)
    with open(path, "w") as f:
        f.write("time,gx,gy,gz\n")
        for s in range(0, rows, 1_000_000):
            k = min(rows, s + 1_000_000) - s
            block = np.c_[np.arange(s, s + k) / 100.0, rng.normal(0.0, 0.05, (k, 3))]
            np.savetxt(f, block, fmt=["%.2f", "%.7f", "%.7f", "%.7f"], delimiter=",")


def read_once(path: Path, tree: Path) -> dict:
    out = subprocess.run([sys.executable, "-c", CHILD, str(path), str(tree)], capture_output=True, text=True)
    if out.returncode:
        raise RuntimeError(out.stderr)
    r = json.loads(out.stdout)
    r["ratio"] = (r["peak"] - r["before"]) / r["arrays"]
    return r


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rows", type=int, default=10_000_000)
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--baseline", type=Path, help="a python/ folder of another checkout to alternate with")
    ap.add_argument("--quick", action="store_true", help="10⁵ rows, one repeat (not a measurement)")
    ap.add_argument("--out", type=Path, default=HERE / "results")
    ap.add_argument("--write", type=Path, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.write is not None:
        write_log(args.write, args.rows)
        return
    rows, repeats = (100_000, 1) if args.quick else (args.rows, args.repeats)
    trees = [("this tree", TREE)] + ([("baseline", args.baseline)] if args.baseline else [])
    tmp = Path(tempfile.mkdtemp(prefix="read_memory_"))
    results = []
    try:
        csv = tmp / "log.csv"
        # written by a process of its own: this one stays small (its children's peaks are their own)
        subprocess.run([sys.executable, __file__, "--write", str(csv), "--rows", str(rows)], check=True)
        gz = tmp / "log.csv.gz"
        with open(csv, "rb") as src, gzip.open(gz, "wb", compresslevel=1) as dst:
            shutil.copyfileobj(src, dst)
        for path in (csv, gz):
            for rep in range(repeats):
                for name, tree in trees if rep % 2 == 0 else trees[::-1]:
                    r = read_once(path, tree)
                    r.update(file=path.name, file_bytes=os.path.getsize(path), tree=name, repeat=rep)
                    log(
                        f"{name:10s} {path.name:11s} ratio {r['ratio']:.2f} wall {r['wall']:.2f} s cpu {r['cpu']:.2f} s"
                    )
                    results.append(r)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    args.out.mkdir(parents=True, exist_ok=True)
    stem = "read_memory" if not args.quick else "read_memory_quick"
    (args.out / f"{stem}.json").write_text(json.dumps(dict(machine=machine_info(), rows=rows, runs=results), indent=1))
    lines = [
        "| tree | file | file MiB | arrays MiB | peak − before MiB | ratio to the arrays | wall s | CPU s |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        lines.append(
            f"| {r['tree']} | {r['file']} | {r['file_bytes'] / 2**20:.0f} | {r['arrays'] / 2**20:.0f} | "
            f"{(r['peak'] - r['before']) / 2**20:.0f} | {r['ratio']:.2f} | {r['wall']:.2f} | {r['cpu']:.2f} |"
        )
    (args.out / f"{stem}.md").write_text(
        f"# Memory of reading a text log ({rows} rows)\n\n`python benches/bench_read_memory.py"
        f"{' --baseline DIR' if args.baseline else ''}` (each read a fresh process; VmHWM after the read − "
        "after `import allanite`, over the bytes of `Log.data` + `Log.time`).\n\n" + "\n".join(lines) + "\n"
    )


if __name__ == "__main__":
    main()
