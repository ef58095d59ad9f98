#!/usr/bin/env python3
"""Peak memory of one default ``allanite.refine`` on a clean simulated record (results: refine_cost.md, "Memory").

Usage::

    python benches/refine_memory.py 1e7     # simulates and saves the record once, then refines it in a fresh process

The record (N 0.01, B 0.002, K 1e-4 at 100 Hz, seed 3) is simulated in one process and saved to the temporary
folder, then loaded in a fresh one, so the high-water mark (``VmHWM``) before the call is the loaded record's and
not the simulation's peak; the mark after the call less that is refine's own. Linux only (/proc).
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time

import numpy as np


def _path(n: int) -> str:
    return os.path.join(tempfile.gettempdir(), f"allanite_refine_memory_{n}.npy")


def _status_mb(key: str) -> float:
    """``VmRSS`` / ``VmHWM`` of this process (MB) from /proc (Linux): the high-water mark of this process's own
    memory — ``ru_maxrss`` keeps the pre-exec process's mark across ``exec``."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(key + ":"):
                return float(line.split()[1]) / 1024
    raise RuntimeError(f"/proc/self/status has no {key}")


def _refine(n: int) -> None:
    import allanite

    y = np.load(_path(n))
    r0 = _status_mb("VmHWM")
    t, c = time.perf_counter(), time.process_time()
    res = allanite.refine(y, 100.0)
    dt, dc = time.perf_counter() - t, time.process_time() - c
    r1 = _status_mb("VmHWM")
    mb = y.nbytes / 2**20
    print(
        f"n={n:.0e}: record {mb:.0f} MB; RSS before refine {r0:.0f} MB, peak after {r1:.0f} MB "
        f"(+{r1 - r0:.0f} MB = {(r1 - r0) / mb:.1f}× the record); {dt:.1f} s wall, {dc:.1f} s CPU; "
        f"effects {[s.effect for s in res.steps]}; unexplained {len(res.unexplained)}"
    )


def main(argv: list[str]) -> int:
    n = int(float(argv[1])) if len(argv) > 1 else 10**6
    if len(argv) > 2 and argv[2] == "--worker":
        _refine(n)
        return 0
    if not os.path.exists(_path(n)):
        import allanite

        np.save(_path(n), np.asarray(allanite.simulate(n, 100.0, seed=3, N=0.01, B=0.002, K=1e-4), dtype=np.float64))
    return subprocess.call([sys.executable, __file__, str(n), "--worker"])


if __name__ == "__main__":
    raise SystemExit(main(sys.argv))
