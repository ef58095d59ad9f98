"""The slow-line test's bootstrap (its second reading, :mod:`allanite.model.slowline`) before → after its fits took
analytic gradients (:mod:`allanite.model._slowfit`, round r18boot): CPU seconds of a default ``allanite.refine`` on
records where refine's slow-line test runs the bootstrap and on records where it does not, A/B in one run.

A is a copy of the library before the change (``--before``, e.g. ``git archive <main> python/allanite`` unpacked in
/tmp with the compiled core copied beside it), B the one on this script's ``PYTHONPATH``. Each record is refined in
a fresh process per library (one BLAS thread, ``time.process_time`` around ``refine`` alone), A and B alternating
which goes first; each process counts the bootstrap's runs (``slowline._boot_map`` calls). The ratio A/B is what
the round claims; the CPU seconds themselves move with the machine's load (shared cores), which is recorded.

Usage::

    PYTHONPATH=python python3 benches/bench_slowline_boot.py --before /tmp/r18boot/main/python
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

OUT = Path(__file__).parent / "results"

#: Records: name → (kind, arguments). "lfilter": the issue's first-order low-pass record (simulate N=2e-3,
#: K=2e-5 at 100 Hz × 4·10⁵, a = exp(−2π·8/100)); "power": benches/r17slowboot.py's power case, amplitude
#: multiple and seed (a daily line under flicker FM, a 1 h thermal cycle in a gyro).
RECORDS = {
    "low-pass 8 Hz, 100 Hz × 4·10⁵, seed 3": ("lfilter", 3),
    "clock 1 Hz × 5 d, daily line 2×, seed 0": ("power", ("clock", 2.0, 0)),
    "clock 1 Hz × 5 d, daily line 2×, seed 1": ("power", ("clock", 2.0, 1)),
    "clock 1 Hz × 5 d, daily line 1×, seed 1": ("power", ("clock", 1.0, 1)),
    "clock 1 Hz × 5 d, daily line 1×, seed 3": ("power", ("clock", 1.0, 3)),
    "gyro 100 Hz × 4 h, thermal cycle 2×, seed 0": ("power", ("gyro", 2.0, 0)),
    "low-pass 8 Hz, 100 Hz × 4·10⁵, seed 4": ("lfilter", 4),
    "low-pass 8 Hz, 100 Hz × 4·10⁵, seed 5": ("lfilter", 5),
    "tiltmeter 0.5 Hz × 2·10⁵, daily line + settling 1×, seed 0": ("power", ("tiltmeter", 1.0, 0)),
}

WORKER = r"""
import json, sys, time
import numpy as np
sys.path.insert(0, {benches!r})
import allanite
from allanite._blas import one_thread
from allanite.model import slowline
kind, arg = json.loads({spec!r})
if kind == "lfilter":
    import scipy.signal
    a = np.exp(-2 * np.pi * 8 / 100)
    y = scipy.signal.lfilter([1 - a], [1, -a], allanite.simulate(400_000, 100.0, N=2e-3, K=2e-5, seed=arg))
    fs = 100.0
else:
    import r17slowboot as b
    import refine_blind as rb
    name = [k for k in b.CASES if k.startswith(arg[0])][0]
    fs, n, kw, period, amp1, drift = b.CASES[name]
    rng = np.random.default_rng(9_000 + 37 * arg[2] + len(name))
    t = np.arange(n) / fs
    e = rb.noise(n, fs, rng, **kw)
    if drift is not None:
        e = e + drift[0] * np.exp(-t / drift[1])
    y = e + amp1 * arg[1] * np.sin(2 * np.pi * t / period + rng.uniform(0, 2 * np.pi))
runs = [0]
boot = slowline._boot_map
def counted(*a, **k):
    runs[0] += 1
    return boot(*a, **k)
slowline._boot_map = counted
with one_thread():
    t0 = time.process_time()
    r = allanite.refine(y, fs, progress=False)
    cpu = time.process_time() - t0
print(json.dumps({{"cpu": cpu, "boot": runs[0], "steps": [s.effect for s in r.steps]}}))
"""


def _run(lib: str, spec: list) -> dict:
    code = WORKER.format(benches=str(Path(__file__).parent), spec=json.dumps(spec))
    env = dict(os.environ, PYTHONPATH=lib, OPENBLAS_NUM_THREADS="1")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--before", required=True, help="PYTHONPATH of the library before (A)")
    ap.add_argument("--only", default="", help="substrings of the records to run (default all)")
    args = ap.parse_args(argv)
    after = os.environ.get("PYTHONPATH", "python").split(os.pathsep)[0]
    commit = subprocess.run(["git", "describe", "--always", "--dirty"], capture_output=True, text=True).stdout.strip()
    load0 = [round(v, 1) for v in os.getloadavg()]
    rows = {}
    for i, (name, spec) in enumerate(RECORDS.items()):
        if args.only and not any(s in name for s in args.only.split(",")):
            continue
        order = [("A", args.before), ("B", after)][:: 1 if i % 2 == 0 else -1]
        rows[name] = {lab: _run(lib, list(spec)) for lab, lib in order}
        a, b = rows[name]["A"], rows[name]["B"]
        print(f"{name}: A {a['cpu']:.2f} s ({a['boot']} boot), B {b['cpu']:.2f} s ({b['boot']} boot)", flush=True)
    meta = {
        "commit": commit,
        "before": args.before,
        "load_start": load0,
        "load_end": [round(v, 1) for v in os.getloadavg()],
    }
    (OUT / "bench_slowline_boot.json").write_text(json.dumps({"meta": meta, "rows": rows}, indent=1))
    (OUT / "bench_slowline_boot.md").write_text("\n".join(_md(meta, rows)) + "\n")
    print("\n".join(_md(meta, rows)))


def _md(meta: dict, rows: dict) -> list[str]:
    lines = [
        "# The slow-line test's bootstrap: analytic gradients (r18boot), refine's CPU A/B",
        "",
        f"B at {meta['commit']}, A = {meta['before']} (the library before the round); load {meta['load_start']} → "
        f"{meta['load_end']} (2 cores shared with other jobs: the ratio is the claim, not the seconds). One BLAS "
        "thread, `time.process_time` around a default `allanite.refine` in a fresh process per library.",
        "",
        "| record | bootstrap runs (A, B) | A CPU s | B CPU s | A/B | steps equal |",
        "|---|---|---|---|---|---|",
    ]
    for boot in (True, False):
        ta = tb = 0.0
        for name, r in rows.items():
            a, b = r["A"], r["B"]
            if (a["boot"] > 0) != boot:
                continue
            ta, tb = ta + a["cpu"], tb + b["cpu"]
            same = "yes" if a["steps"] == b["steps"] else f"no: {a['steps']} → {b['steps']}"
            lines.append(
                f"| {name} | {a['boot']}, {b['boot']} | {a['cpu']:.2f} | {b['cpu']:.2f} | {a['cpu'] / b['cpu']:.2f} | {same} |"
            )
        if tb:
            what = "where the bootstrap runs" if boot else "where it does not"
            lines.append(f"| **all {what}** | | {ta:.2f} | {tb:.2f} | **{ta / tb:.2f}** | |")
    return lines + [""]


if __name__ == "__main__":
    main()
