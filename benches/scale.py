"""Issue 19: allanite.dask at scale — a record larger than the workers' memory, a fleet, task overhead.

    python benches/scale.py --samples 100000000 --fleet 40 --scratch /work/tmp-scale

Writes benches/results/<--out>.json (default scale.json); benches/results/scale.md says what the runs
measured. ``--compare-numpy`` also runs the static tasks with the NumPy kernel they used before the
Rust one (allanite._reference.angle_term_sums), in the same run. The record is written to ``--scratch`` as a .npy and
read memory-mapped; it is deleted at the end. Workers get ``--memory-limit`` (default 400 MB, well
below the record's 8·samples bytes). Peak memory: each worker process's RSS and the client's
RSS, sampled every 0.2 s during the Dask calls (``*_client_peak_rss``), and the client's ru_maxrss over
the whole run (``client_peak_rss``: includes writing the record through a memory map and, unless
``--no-single``, loading it for the single-machine calls).
"""

from __future__ import annotations

import argparse
import gzip
import json
import os
import resource
import shutil
import threading
import time
from pathlib import Path

import dask
import dask.array as da
import numpy as np
import psutil
from distributed import Client, LocalCluster

import allanite
from allanite import dask as adask

RESULTS = Path(__file__).parent / "results"


class RssPeak:
    """Peak RSS of the worker processes (each with its children), sampled every 0.2 s."""

    def __init__(self, pids):
        self.procs = [psutil.Process(p) for p in pids]
        self.peak = {p.pid: 0 for p in self.procs}
        self.stop = threading.Event()
        self.t = threading.Thread(target=self._run, daemon=True)
        self.t.start()

    def _run(self):
        while not self.stop.is_set():
            for p in self.procs:
                try:
                    self.peak[p.pid] = max(self.peak[p.pid], p.memory_info().rss)
                except psutil.Error:
                    pass
            time.sleep(0.2)

    def close(self):
        self.stop.set()
        self.t.join()
        return max(self.peak.values())


def _write_record(path: Path, n: int, seed: int = 0) -> None:
    """White rate noise with a bias and a tenfold noise step, written in 2^22-sample slabs."""
    mm = np.lib.format.open_memmap(path, mode="w+", dtype=np.float64, shape=(n,))
    rng = np.random.default_rng(seed)
    step = 1 << 22
    for a in range(0, n, step):
        b = min(n, a + step)
        mm[a:b] = 0.5 + rng.normal(size=b - a) * (10.0 if a >= n // 2 else 1.0)
    mm.flush()
    del mm


def _read_slab(path: str, a: int, b: int) -> np.ndarray:
    return np.array(np.load(path, mmap_mode="r")[a:b])


def from_npy(path: Path, chunk: int) -> da.Array:
    """A memory-mapped .npy as a dask array whose tasks open the file themselves (a memmap passed to
    da.from_array would be pickled — i.e. read whole — into the graph)."""
    n = np.load(path, mmap_mode="r").shape[0]
    parts = [
        da.from_delayed(dask.delayed(_read_slab)(str(path), a, min(n, a + chunk)), (min(n, a + chunk) - a,), np.float64)
        for a in range(0, n, chunk)
    ]
    return da.concatenate(parts)


def _sum_block_numpy(blocks, ks, bounds, offsets, *, fs, input, q_exp, plan, classic, threads):
    """The static task as it was before the Rust kernel: the NumPy twin (allanite._reference). Defined
    here, in __main__, so that the workers receive it by value when it stands in for the module's."""
    from allanite._reference import angle_term_sums

    rates = []
    for b in blocks:
        r = np.asarray(b, dtype=np.float64).reshape(len(b), -1)
        rates.append(r * fs if input == "increment" else r)
    return angle_term_sums(
        rates,
        [int(bounds[k]) for k in ks],
        [o[0] for o in offsets],
        [o[1] for o in offsets],
        q_exp,
        [(m, i0, i1) for _j, m, i0, i1 in plan],
        classic,
    )


def _best(f, repeat: int = 3) -> tuple[float, object]:
    best, out = float("inf"), None
    for _ in range(repeat):
        t = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - t)
    return best, out


def _cluster(workers: int, memory_limit: str):
    cluster = LocalCluster(
        n_workers=workers,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address=None,
        memory_limit=memory_limit,
    )
    return cluster, Client(cluster)


def bench_record(args) -> dict:
    n = args.samples
    scratch = Path(args.scratch)
    scratch.mkdir(parents=True, exist_ok=True)
    path = scratch / "record.npy"
    t0 = time.perf_counter()
    _write_record(path, n)
    out = {"samples": n, "bytes": 8 * n, "write_s": time.perf_counter() - t0}
    window, hop = n // 100, n // 1000
    out.update(window=window, hop=hop, memory_limit=args.memory_limit, chunk=args.chunk)
    try:
        cluster, client = _cluster(2, args.memory_limit)
        with cluster, client:
            pids = list(client.run(os.getpid).values())
            x = from_npy(path, args.chunk)
            mon, me = RssPeak(pids), RssPeak([os.getpid()])
            t = time.perf_counter()
            d = adask.davar(x, 100.0, window=window, hop=hop, taus="octave", chunk=args.chunk)
            out["davar_s"] = time.perf_counter() - t
            out["davar_worker_peak_rss"] = mon.close()
            out["davar_client_peak_rss"] = me.close()
            print("davar on Dask", out["davar_s"], "s", flush=True)
            mon, me = RssPeak(pids), RssPeak([os.getpid()])
            t = time.perf_counter()
            s = adask.avar(x, 100.0, taus="octave", chunk=args.chunk, client=client)
            out["avar_s"] = time.perf_counter() - t
            out["avar_worker_peak_rss"] = mon.close()
            out["avar_client_peak_rss"] = me.close()
            print("static OAVAR on Dask", out["avar_s"], "s", flush=True)
            if args.compare_numpy:  # the same tasks with the NumPy kernel they used before
                rust_kernel = adask.arrays._sum_block
                adask.arrays._sum_block = _sum_block_numpy
                try:
                    t = time.perf_counter()
                    s_np = adask.avar(x, 100.0, taus="octave", chunk=args.chunk, client=client)
                    out["avar_numpy_kernel_s"] = time.perf_counter() - t
                finally:
                    adask.arrays._sum_block = rust_kernel
                out["avar_rust_vs_numpy_kernel_max_rel"] = float(np.max(np.abs(s.avar / s_np.avar - 1)))
        out["client_peak_rss"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
        out["davar_shape"] = list(d.avar.shape)
        out["n_tau_static"] = int(s.tau.size)
        if not args.no_single:
            y = np.load(path)  # fits this machine (8·n bytes)
            # best of three: a short call on a shared machine
            out["single_avar_s"], ref_s = _best(lambda: allanite.avar(y, 100.0, taus="octave"))
            out["single_davar_s"], ref_d = _best(
                lambda: allanite.davar(y, 100.0, window=window, hop=hop, taus="octave")
            )
            out["avar_max_rel"] = float(np.max(np.abs(s.avar / ref_s.avar - 1)))
            out["davar_max_rel"] = float(np.max(np.abs(d.avar / ref_d.avar - 1)))
            out["davar_bitwise"] = bool(np.array_equal(d.avar, ref_d.avar))
            del y
    finally:
        shutil.rmtree(scratch, ignore_errors=True)  # the big file goes, whatever happened
    return out


def bench_fleet(args) -> dict:
    root = Path(args.scratch) / "fleet"
    rng = np.random.default_rng(3)
    for i in range(args.fleet):
        d = root / "logs" / f"line{i % 4}"
        d.mkdir(parents=True, exist_ok=True)
        with gzip.open(d / f"imu{i:03d}.csv.gz", "wt") as f:
            f.write("gx,gy,gz\n")
            np.savetxt(f, rng.normal(size=(args.fleet_samples, 3)), fmt="%.7e", delimiter=",")
    out = {"files": args.fleet, "samples_per_file": args.fleet_samples}
    try:
        for workers in (1, 2):
            cluster, client = _cluster(workers, "2GB")
            with cluster, client:
                t = time.perf_counter()
                res = adask.batch(
                    str(root / "logs" / "**" / "*.csv.gz"), out=root / f"out{workers}", fs=100.0, client=client
                )
                out[f"fleet_{workers}w_s"] = time.perf_counter() - t
                out[f"fleet_{workers}w_failed"] = len(res.failed)
                # per-task overhead: many no-op tasks
                t = time.perf_counter()
                client.gather(client.map(lambda i: i, range(2000), pure=False))
                out[f"noop_task_{workers}w_ms"] = (time.perf_counter() - t) / 2000 * 1e3
    finally:
        shutil.rmtree(root, ignore_errors=True)
    return out


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--samples", type=int, default=100_000_000)
    p.add_argument("--chunk", type=int, default=1 << 20)
    p.add_argument("--memory-limit", default="400MB")
    p.add_argument("--fleet", type=int, default=200)
    p.add_argument("--fleet-samples", type=int, default=4000)
    p.add_argument("--scratch", default="/tmp/allanite-scale")
    p.add_argument("--no-single", action="store_true")
    p.add_argument("--skip-record", action="store_true")
    p.add_argument("--skip-fleet", action="store_true")
    p.add_argument("--compare-numpy", action="store_true", help="also time the static tasks with the NumPy kernel")
    p.add_argument("--out", default="scale", help="results/<OUT>.json")
    args = p.parse_args()
    res = {"load_before": os.getloadavg(), "cpus": os.cpu_count()}
    if not args.skip_record:
        res["record"] = bench_record(args)
        print(json.dumps(res["record"], indent=1))
    if not args.skip_fleet:
        res["fleet"] = bench_fleet(args)
        print(json.dumps(res["fleet"], indent=1))
    res["load_after"] = os.getloadavg()
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / f"{args.out}.json").write_text(json.dumps(res, indent=1), encoding="utf-8")


if __name__ == "__main__":
    main()
