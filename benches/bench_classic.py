"""Dense τ lists with the classic (non-overlapping) and overlapping Allan variance — issue 17's dense cases.

ROS/Kalibr users ask for every 0.1 s up to 1000 s: at 10 Hz that is m = 1 … 9 999 on each of six IMU axes
(6 × 10⁶ samples). The static classic estimator gathers its N/m cluster sums from one double-word prefix
(``rust/core/src/gather.rs``). Baselines in the same run: the NumPy cumulative-sum gather a pure-Python tool
writes (plain ``np.cumsum``, strided slices — fast, but its prefix loses digits after a loud stretch), and
allanite's own streaming sliding-sum path (a two-window ``davar``, which streams the record once per m: what
``avar(estimator="avar")`` cost before the gather). The overlapping estimator on the same list is timed too and
put against a STREAM-like copy of one axis measured in the same run (ns per sample and τ: issue 17 asks for
within 2× of that roofline). Ratios are what carry over between machines.

    python benches/bench_classic.py            # full: 6 × 1e6 samples, 9 999 τ  → benches/results/classic.md
    python benches/bench_classic.py --quick    # smoke: 6 × 1e5, 999 τ (printed, not written)
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

import _common
import allanite

FS = 10.0


def numpy_gather(y: np.ndarray, ms: np.ndarray) -> np.ndarray:
    """Classic AVAR of one axis at every m from a plain cumulative sum (strided slices of the angle)."""
    n = y.size
    x = np.concatenate(([0.0], np.cumsum(y)))
    out = np.empty(ms.size)
    for i, m in enumerate(ms):
        xs = x[:: int(m)][: n // int(m) + 1]
        d = np.diff(xs, 2) / m
        out[i] = np.mean(d * d) / 2
    return out


def run(n: int, n_tau: int, streaming: bool) -> dict:
    rng = np.random.default_rng(17)
    X = rng.standard_normal((n, 6)) * [1.0, 2.0, 0.5, 1e-2, 1e-2, 1e-2] + [0.0, 0.1, -0.2, 1.0, 0.0, -1.0]
    ms = np.arange(1, n_tau + 1)
    taus = ms / FS
    load0 = os.getloadavg()
    best, reps, res = _common.timed(lambda: allanite.avar(X, FS, taus=taus, estimator="avar"), 3, warmup=True)
    gbest, greps, g = _common.timed(lambda: np.array([numpy_gather(X[:, a], ms) for a in range(6)]), 3)
    out = {
        "n": n,
        "axes": 6,
        "n_taus": int(ms.size),
        "allanite_s": best,
        "allanite_repeats": reps,
        "gather_s": gbest,
        "gather_repeats": greps,
        "ratio_vs_gather": gbest / best,
        "max_rel_diff_vs_gather": _common.max_rel_diff(res.avar, g),
        "ns_per_cluster_sum": best / (6 * float(np.sum(n // ms))) * 1e9,
    }
    if streaming:
        # two windows (n − 1 samples, hop 1): the sliding-sum path, column 0 = the first n − 1 samples
        sbest, sreps, s = _common.timed(
            lambda: allanite.davar(X, FS, window=n - 1, hop=1, taus=taus, estimator="avar").avar, 1
        )
        a2 = allanite.avar(X[: n - 1], FS, taus=taus, estimator="avar").avar
        out |= {
            "streaming_s": sbest,
            "ratio_vs_streaming": sbest / best,
            "max_rel_diff_vs_streaming": _common.max_rel_diff(a2, s[..., 0]),
        }
    if streaming:  # the full run: the overlapping estimator on the same τ list, against a copy of the record
        obest, oreps, _o = _common.timed(lambda: allanite.avar(X, FS, taus=taus, estimator="oavar"), 1, warmup=False)
        col = np.ascontiguousarray(X[:, 0])
        dst = np.empty_like(col)
        cbest, _creps, _ = _common.timed(lambda: np.copyto(dst, col), 5, warmup=True)
        per = obest / (6 * n * ms.size) * 1e9
        out |= {
            "oavar_s": obest,
            "oavar_ns_per_sample_per_tau": per,
            "copy_ns_per_sample": cbest / n * 1e9,
            "oavar_vs_roofline": per / (cbest / n * 1e9),
        }
    out["loadavg_start_end"] = [load0[0], os.getloadavg()[0]]
    return out


def write(r: dict, machine: dict) -> None:
    lines = [
        "# Classic Allan variance on a dense τ list (issue 17) — `benches/bench_classic.py`",
        "",
        f"{machine.get('when', '')} · {machine.get('cpu_model', '')} · load average at start/end "
        f"{r['loadavg_start_end'][0]:.2f} / {r['loadavg_start_end'][1]:.2f}",
        "",
        f"Record: {r['axes']} axes × {r['n']:.0e} white-noise samples at {FS:g} Hz; τ = 0.1 s · k, k = 1 … "
        f"{r['n_taus']} (m = k). allanite: warm-up, then best of 3; NumPy gather: best of 3; streaming path: 1 run.",
        "",
        "| what | seconds | allanite is | max rel. diff |",
        "|---|---|---|---|",
        f"| allanite.avar(estimator='avar') (gather from a double-word prefix) | {r['allanite_s']:.3f} | — | — |",
        f"| NumPy cumulative-sum gather (plain prefix) | {r['gather_s']:.3f} | {r['ratio_vs_gather']:.2f}× faster | "
        f"{r['max_rel_diff_vs_gather']:.1e} |",
    ]
    if "streaming_s" in r:
        lines.append(
            f"| allanite's sliding-sum path (what avar cost before; two-window davar) | {r['streaming_s']:.1f} | "
            f"{r['ratio_vs_streaming']:.0f}× faster | {r['max_rel_diff_vs_streaming']:.1e} |"
        )
    if "oavar_s" in r:
        lines.append(
            f"| allanite.avar(estimator='oavar'), same τ list (one double-word phase, all τ per pass) | "
            f"{r['oavar_s']:.1f} | {r['oavar_ns_per_sample_per_tau']:.3f} ns per sample and τ = "
            f"{r['oavar_vs_roofline']:.2f}× a one-thread copy of the record ({r['copy_ns_per_sample']:.3f} ns/sample; allanite "
            "on its default 2 workers) | — |"
        )
    lines += [
        "",
        f"Cost per gathered cluster sum (all axes, all τ): {r['ns_per_cluster_sum']:.2f} ns. About 0.09 s of the "
        "allanite time is fixed per call (the six C-ordered columns copied and checked, each window's mean and "
        "finite check in one parallel pass, and the 16 B/sample/axis prefix built in parallel blocks); the rest is "
        "the cluster sums: short m walk the prefix per m, the long ones (rows ≥ 4 KiB apart) share one in-order "
        "sweep of the prefix per worker, each taking its rows from the cached stretch (before the sweeps every long "
        "m walked its own stride, a cache miss per row: 0.26 s on a quiet machine on 2026-11-24 and 0.42–0.47 s on "
        "this one today, 1.5–2.1× the gather). Ratio in this run: "
        f"{r['ratio_vs_gather']:.2f}× (load average {r['loadavg_start_end'][0]:.2f} → "
        f"{r['loadavg_start_end'][1]:.2f}; both sides read memory at long strides, so another job's load moves it). "
        "The gather's 2e-9 difference is its plain prefix losing digits on the axes with an "
        "offset.",
        "",
    ]
    path = _common.HERE / "results" / "classic.md"
    path.write_text("\n".join(lines), encoding="utf-8")
    (_common.HERE / "results" / "classic.json").write_text(json.dumps(r | {"machine": machine}, indent=2) + "\n")
    print(path.read_text(encoding="utf-8"))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="6 × 1e5 samples, 999 τ; print only")
    a = ap.parse_args(argv)
    if a.quick:
        print(json.dumps(run(100_000, 999, streaming=False), indent=2))
        return 0
    machine = _common.machine_info()
    machine["when"] = time.strftime("%Y-%m-%dT%H:%M:%S%z")
    write(run(1_000_000, 9_999, streaming=True), machine)
    return 0


if __name__ == "__main__":
    sys.exit(main())
