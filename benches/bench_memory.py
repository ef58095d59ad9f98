#!/usr/bin/env python3
"""Memory of the dynamic Allan variance: what a call holds beyond its input and its output.

Issue 17 kept the engine's memory "as today": the overlapping DAVAR's double-word phase path holds 16
bytes of phase per sample, so it is built per *segment* of max(2^22, 16 · window) samples' worth of
windows, not for the whole record (4 · window on records over 2^26 samples × axes). Records of ≤ 2^26
samples × axes take it at any window, longer ones for windows ≤ 2^21 (a segment of ≤ 2^23 samples);
longer windows on longer records stream their sums in O(window) per worker. This bench measures it: every case runs in a fresh
process that builds a seeded white-noise record (float64), notes its resident set, calls
``allanite.davar`` and reads the peak resident set (``ru_maxrss``); the extra memory is
peak − (resident before the call) − (the output array's bytes). Reported per sample of the record,
against the bound the segments promise (16 B × segment span + per-worker scratch) and as a fraction
of the input; the streaming path (a window over 2^21 samples on a record past 2^26) is the reference. A
C-ordered (samples, axes) array is copied to contiguous columns (8 B per sample and axis); a
Fortran-ordered one is not — both cases are measured.

Usage::

    python benches/bench_memory.py            # -> benches/results/memory.{json,md}
    python benches/bench_memory.py --quick --out DIR   # small sizes (< 30 s), not a measurement

Needs numpy and allanite; no external data. Times are printed for orientation only (best of 1).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

from _common import log, machine_info

HERE = Path(__file__).resolve().parent

# (label, samples, axes, window, hop) — the exp grid m = unique(round(1.073^k)) ≤ window/9
CASES = [
    ("phase path, 1 axis, 2^25 samples, window 1e4, hop 1e3", 1 << 25, 1, 10_000, 1_000),
    ("phase path, 1 axis, 2^25 samples, window 1e4, hop 10", 1 << 25, 1, 10_000, 10),
    ("phase path, 3 axes (C order), 2^24 samples, window 1e5, hop 1e3", 1 << 24, 3, 100_000, 1_000),
    ("phase path, 3 axes (Fortran order), 2^24 samples, window 1e5, hop 1e3", 1 << 24, -3, 100_000, 1_000),
    ("phase path, 1 axis, 10^7 samples, window 1e6, hop 1e4 (one segment)", 10_000_000, 1, 1_000_000, 10_000),
    ("phase path (segments), 1 axis, 7·10^7 samples, window 1e4, hop 1e3", 70_000_000, 1, 10_000, 1_000),
    ("streaming path, 1 axis, 7·10^7 samples, window 2^22, hop 1e6", 70_000_000, 1, 1 << 22, 1_000_000),
]
QUICK = [
    ("phase path, 1 axis, 2^23 samples, window 1e4, hop 1e3", 1 << 23, 1, 10_000, 1_000),
    ("phase path, 1 axis, 2^22 samples, window 1e3, hop 10", 1 << 22, 1, 1_000, 10),
]

CHILD = r"""
import json, resource, sys, time
import numpy as np
import allanite
n, axes, window, hop = (int(v) for v in sys.argv[1:5])
def rss():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4096
rng = np.random.default_rng(1)
if axes < 0:  # Fortran order (every axis a contiguous column), built without a copy
    y = rng.standard_normal((-axes, n)).T
else:
    y = rng.standard_normal((n, axes) if axes > 1 else n)
m = np.unique(np.round(1.073 ** np.arange(0, 400))).astype(int)
m = m[m <= window // 9]
before = rss()
peak_before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
t0 = time.perf_counter()
r = allanite.davar(y, 1.0, window=window, hop=hop, taus=m.astype(float))
sec = time.perf_counter() - t0
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
print(json.dumps(dict(before=before, peak_before=peak_before, peak=peak, out=r.avar.nbytes,
                      n_tau=int(m.size), windows=int(r.t.size), seconds=sec)))
"""


def run_case(n: int, axes: int, window: int, hop: int) -> dict:
    env = dict(os.environ, RAYON_NUM_THREADS=os.environ.get("RAYON_NUM_THREADS", "2"))
    out = subprocess.run(
        [sys.executable, "-c", CHILD, str(n), str(axes), str(window), str(hop)],
        capture_output=True,
        text=True,
        check=True,
        env=env,
    )
    d = json.loads(out.stdout.strip().splitlines()[-1])
    # the extra: above the larger of the resident set before the call and the record's build peak
    base = max(d["before"], d["peak_before"])
    d["extra"] = max(0, d["peak"] - base - d["out"])
    return d


def segment_bound(n: int, axes: int, window: int, hop: int, workers: int = 2) -> int:
    """Bytes the phase path may hold beyond input and output: one segment's phase (16 B/sample) plus,
    at hops < 64, each worker's terms and block sums of one segment (8 + 16/hop B/sample)."""
    span = min(max(1 << 22, (4 if n * axes > 1 << 26 else 16) * window), n)
    per = 16 * span
    if hop < 64:
        per += workers * (8 + 16 / hop) * span
    return int(per)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", type=Path, default=HERE / "results")
    args = ap.parse_args()
    cases = QUICK if args.quick else CASES
    rows = []
    for label, n, axes, window, hop in cases:
        log(f"{label} …")
        d = run_case(n, axes, window, hop)
        d.update(label=label, n=n, axes=abs(axes), window=window, hop=hop)
        phase = n * abs(axes) <= 1 << 26 or max(1 << 22, 4 * window) <= 1 << 23
        d["bound"] = segment_bound(n, abs(axes), window, hop) if phase else None
        log(f"  extra {d['extra'] / 2**20:.0f} MiB, {d['seconds']:.2f} s")
        rows.append(d)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "memory.json").write_text(json.dumps({"machine": machine_info(), "rows": rows}, indent=1) + "\n")
    lines = [
        "# Memory of the dynamic Allan variance beyond its input and output",
        "",
        "`python benches/bench_memory.py` (each case a fresh process; peak resident set − resident set before",
        "the call − the output's bytes). Exp grid m = round(1.073^k) ≤ window/9, white noise, float64, 2 workers.",
        "",
        "| case | input MiB | output MiB | extra MiB | extra B/sample | segment bound MiB | extra / input | s |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        per = r["extra"] / (r["n"] * r["axes"])
        ratio = f"{r['extra'] / (r['n'] * r['axes'] * 8):.2f}"
        bound = f"{r['bound'] / 2**20:.0f}" if r["bound"] is not None else "– (O(window) per worker)"
        lines.append(
            f"| {r['label']} | {r['n'] * r['axes'] * 8 / 2**20:.0f} | {r['out'] / 2**20:.1f} | "
            f"{r['extra'] / 2**20:.0f} | {per:.2f} | {bound} | {ratio} | {r['seconds']:.2f} |"
        )
    lines += [
        "",
        "The bound: one segment's phase (16 B × max(2^22, 16 · window) samples — 4 · window past 2^26 samples ×",
        "axes —, capped at the record) plus, at",
        "hops below 64, each worker's terms and block sums of one segment. A C-ordered (samples, axes) input",
        "adds a contiguous copy of its columns (8 B per sample and axis, made before the call reaches the core);",
        "`np.asfortranarray` input avoids it.",
    ]
    (args.out / "memory.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
