#!/usr/bin/env python3
"""Peak memory of one default ``allanite.refine`` on a clean simulated record (results: refine_cost.md, "Memory";
refine_memory.md).

Usage::

    python benches/refine_memory.py 1e7                  # float64, no channel: peak RSS beyond the loaded record
    python benches/refine_memory.py 3e7 --float32 --temperature --trace

The record (N 0.01, B 0.002, K 1e-4 at 100 Hz, seed 3) is simulated in one process and saved to the temporary
folder, then loaded in a fresh one, so the high-water mark (``VmHWM``) before the call is the loaded record's and
not the simulation's peak; the mark after the call less that is refine's own. Linux only (/proc).

``--float32`` passes the samples as float32 (the record's bytes halve; refine's own arrays do not all follow).
``--temperature`` adds a channel ``{"temp": …}`` of the same length (a slow random walk, independent of the rate: a
clean record, so nothing is removed). ``--trace`` runs a second fresh process under ``tracemalloc`` (NumPy's and
Python's allocations; the compiled core's working arrays are not traced) and prints its peak, the traced peak's
call stack (a thread samples the traced size every 5 ms and keeps the main thread's stack at each new maximum)
and the largest allocation sites at that moment's snapshot — RSS peak − traced peak is the compiled core's share
and the allocator's, roughly (the two peaks need not be at the same moment).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import threading
import time
import traceback

import numpy as np


def _path(n: int, dtype: str, temperature: bool) -> str:
    tag = f"{n}_{dtype}" + ("_temp" if temperature else "")
    return os.path.join(tempfile.gettempdir(), f"allanite_refine_memory_{tag}.npz")


def _status_mb(key: str) -> float:
    """``VmRSS`` / ``VmHWM`` of this process (MB) from /proc (Linux): the high-water mark of this process's own
    memory — ``ru_maxrss`` keeps the pre-exec process's mark across ``exec``."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(key + ":"):
                return float(line.split()[1]) / 1024
    raise RuntimeError(f"/proc/self/status has no {key}")


class _PeakWatch:
    """The main thread's stack (and the top allocation sites) at the traced size's running maximum."""

    def __init__(self, every: float = 0.005) -> None:
        import tracemalloc

        self.tm, self.every, self.best, self.stack, self.sites = tracemalloc, every, 0, "", []
        self.main = threading.main_thread().ident
        self.done = threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)

    def _run(self) -> None:
        while not self.done.wait(self.every):
            cur = self.tm.get_traced_memory()[0]
            if cur > 1.1 * self.best:  # a new maximum by 10 %: keep where it is (snapshots are slow)
                frame = sys._current_frames().get(self.main)
                self.best = cur
                self.stack = "".join(traceback.format_stack(frame)[-8:]) if frame else ""
                snap = self.tm.take_snapshot().statistics("lineno")[:6]
                self.sites = [f"{s.size / 2**20:.0f} MB {s.traceback[0]}" for s in snap]

    def __enter__(self) -> _PeakWatch:
        self.tm.start(1)
        self.thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self.done.set()
        self.thread.join()
        self.peak = self.tm.get_traced_memory()[1]
        self.tm.stop()


def _refine(path: str, trace: bool) -> dict:
    import allanite

    with np.load(path) as f:
        y = f["y"]
        chans = {"temp": f["temp"]} if "temp" in f else None
    r0 = _status_mb("VmHWM")
    t, c = time.perf_counter(), time.process_time()
    if trace:
        with _PeakWatch() as w:
            res = allanite.refine(y, 100.0, channels=chans, progress=False)
    else:
        res = allanite.refine(y, 100.0, channels=chans, progress=False)
    dt, dc = time.perf_counter() - t, time.process_time() - c
    r1 = _status_mb("VmHWM")
    out = {
        "n": int(y.size),
        "dtype": str(y.dtype),
        "temperature": chans is not None,
        "record_mb": y.nbytes / 2**20,
        "rss_before_mb": r0,
        "rss_peak_beyond_mb": r1 - r0,
        "wall_s": dt,
        "cpu_s": dc,
        "effects": [s.effect for s in res.steps],
        "unexplained": len(res.unexplained),
    }
    if trace:
        out |= {"traced_peak_mb": w.peak / 2**20, "peak_stack": w.stack, "peak_sites": w.sites}
    return out


def _say(d: dict) -> str:
    mb = d["record_mb"]
    s = (
        f"n={d['n']:.0e} {d['dtype']}{' +temp' if d['temperature'] else ''}: record {mb:.0f} MB; "
        f"RSS before refine {d['rss_before_mb']:.0f} MB, peak +{d['rss_peak_beyond_mb']:.0f} MB "
        f"({d['rss_peak_beyond_mb'] / mb:.1f}× the record); {d['wall_s']:.1f} s wall, {d['cpu_s']:.1f} s CPU; "
        f"effects {d['effects']}; unexplained {d['unexplained']}"
    )
    if "traced_peak_mb" in d:
        s += f"\n  traced peak {d['traced_peak_mb']:.0f} MB ({d['traced_peak_mb'] / mb:.1f}× the record)"
        s += "\n  at:\n" + d["peak_stack"] + "  sites:\n    " + "\n    ".join(d["peak_sites"])
    return s


def main(argv: list[str]) -> int:
    args = [a for a in argv[1:] if not a.startswith("--")]
    n = int(float(args[0])) if args else 10**6
    dtype = "float32" if "--float32" in argv else "float64"
    temperature = "--temperature" in argv
    path = _path(n, dtype, temperature)
    if "--worker" in argv:
        print("RESULT " + json.dumps(_refine(path, "--trace" in argv)))
        return 0
    if not os.path.exists(path):
        import allanite

        y = np.asarray(allanite.simulate(n, 100.0, seed=3, N=0.01, B=0.002, K=1e-4), dtype=dtype)
        extra = {}
        if temperature:  # a slow channel independent of the rate: 0.5 K per √h random walk about 25 °C
            extra["temp"] = (25.0 + np.cumsum(np.random.default_rng(4).normal(0.0, 0.5 / 60 / 100, n))).astype(dtype)
        np.savez(path, y=y, **extra)
    runs = [[]] + ([["--trace"]] if "--trace" in argv else [])
    for extra_args in runs:
        flags = [f for f in ("--float32", "--temperature") if f in argv] + extra_args
        cmd = [sys.executable, __file__, str(n), "--worker", *flags]
        out = subprocess.run(cmd, capture_output=True, text=True, check=False)
        if out.returncode:
            sys.stderr.write(out.stderr)
            return out.returncode
        line = next(s for s in out.stdout.splitlines() if s.startswith("RESULT "))
        print(_say(json.loads(line[7:])), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv))
