#!/usr/bin/env python3
"""DAVAR's small-hop case against its true floor (issue 30, item 5).

N = 10⁵ white-noise samples, window 10⁴, hop 1, the exp grid m = unique(round(1.073^k)) ≤ window/9 (76 τ):
``allanite.davar`` returns a (76, 90001) surface, 55 MB. Writing that output once into fresh pages
(``np.full`` of the result's shape: the kernel's page faults and zeroing, then one pass of stores) is
what any implementation that hands the surface back pays — the floor. The call and the floor are
timed interleaved in one run (call, floor, call, floor, …, after one untimed warm-up of each), and the
ratio is median(call) / median(floor) over ``--repeats`` (≥ 11) pairs. Target: ≤ 2×.

The values are checked in the same run against the per-window recomputation (``method="naive"``,
every window from its own samples) — the largest relative difference over the surface.

Usage::

    python benches/bench_davar_floor.py              # -> benches/results/davar_floor.{json,md}
    python benches/bench_davar_floor.py --quick --out DIR   # smoke run (small sizes)
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from _common import OtherLoad, log, machine_info, max_rel_diff

HERE = Path(__file__).resolve().parent
SEED = 20240611
FS = 100.0
CONFIGS = {
    "full": {"n": 100_000, "window": 10_000, "hop": 1, "growth": 1.073, "repeats": 21},
    "quick": {"n": 20_000, "window": 2_000, "hop": 1, "growth": 1.073, "repeats": 11},
}
TARGET = 2.0


def exp_ms(window: int, growth: float) -> np.ndarray:
    ms = np.unique(np.round(growth ** np.arange(400)).astype(np.int64))
    return ms[ms <= window // 9]


def interleaved(fns: dict, repeats: int) -> dict:
    """Seconds of every repeat of each function, run in turn (one untimed warm-up each first); each
    result is dropped before the next call starts, outside the timing."""
    for f in fns.values():
        f()
    times: dict[str, list[float]] = {k: [] for k in fns}
    for _ in range(repeats):
        for k, f in fns.items():
            t0 = time.perf_counter()
            r = f()
            times[k].append(time.perf_counter() - t0)
            del r
    return times


def run(quick: bool, out: Path) -> dict:
    import allanite

    cfg = CONFIGS["quick" if quick else "full"]
    n, window, hop = cfg["n"], cfg["window"], cfg["hop"]
    y = np.random.default_rng(SEED).standard_normal(n)
    taus = exp_ms(window, cfg["growth"]) / FS
    n_win = (n - window) // hop + 1
    shape = (taus.size, n_win)
    log(f"N={n} window={window} hop={hop} τ={taus.size} windows={n_win}: {8 * taus.size * n_win / 1e6:.0f} MB")
    machine = machine_info()

    def call():
        return allanite.davar(y, FS, window=window, hop=hop, taus=taus, method="fast", estimator="oavar")

    def floor():
        return np.full(shape, 1.0)

    with OtherLoad() as ld:
        times = interleaved({"call": call, "floor": floor}, cfg["repeats"])
    med = {k: statistics.median(v) for k, v in times.items()}
    ratio = med["call"] / med["floor"]
    log(f"call median {med['call']:.4f} s, floor median {med['floor']:.4f} s: {ratio:.2f}× the floor")
    fast = call().avar
    naive = allanite.davar(y, FS, window=window, hop=hop, taus=taus, method="naive", estimator="oavar").avar
    diff = max_rel_diff(fast, naive)
    log(f"max rel. diff against the per-window recomputation: {diff:.2g}")
    report = {
        "benchmark": "davar_floor",
        "mode": "quick" if quick else "full",
        "machine": machine,
        "params": {"n": n, "window": window, "hop": hop, "n_taus": int(taus.size), "n_windows": n_win},
        "output_mb": 8 * taus.size * n_win / 1e6,
        "repeats": cfg["repeats"],
        "times": times,
        "median": med,
        "ratio": ratio,
        "target": TARGET,
        "met": ratio <= TARGET,
        "max_rel_diff_vs_naive": diff,
        "other_processes_cpu_fraction": ld.fraction,
        "loadavg_end": list(os.getloadavg()),
    }
    (out / "davar_floor.json").write_text(json.dumps(report, indent=2) + "\n", encoding="utf-8")
    write_markdown(report, out / "davar_floor.md")
    return report


def write_markdown(r: dict, path: Path) -> None:
    m, p = r["machine"], r["params"]
    lines = [
        f"# DAVAR hop 1 against its output floor ({r['mode']} run)",
        "",
        f"{m['date_utc']} · {m['cpu_model']} · {m['cpus_usable']} usable of {m['cpu_count']} CPUs · "
        f"numpy {m['versions']['numpy']} · allanite {m['versions']['allanite']} · git {m['git_commit']}",
        "",
        f"N = {p['n']}, window {p['window']}, hop {p['hop']}, {p['n_taus']} τ (exp grid 1.073^k ≤ window/9), "
        f"{p['n_windows']} windows: a {r['output_mb']:.0f} MB surface. Floor = `np.full` of the result's shape "
        "(fresh pages, written once). Call and floor interleaved after one warm-up each; medians of "
        f"{r['repeats']} each.",
        "",
        "| call median s | floor median s | call ÷ floor | target | met? | max rel. diff vs per-window (naive) |",
        "|---|---|---|---|---|---|",
        f"| {r['median']['call']:.4f} | {r['median']['floor']:.4f} | {r['ratio']:.2f}× | ≤ {r['target']:g}× | "
        f"{'yes' if r['met'] else '**no**'} | {r['max_rel_diff_vs_naive']:.2g} |",
        "",
        "- call repeats: " + ", ".join(f"{t:.4f}" for t in r["times"]["call"]) + " s",
        "- floor repeats: " + ", ".join(f"{t:.4f}" for t in r["times"]["floor"]) + " s",
        f"- load average at start: {[round(v, 2) for v in m['loadavg_start']]}, at end: "
        f"{[round(v, 2) for v in r['loadavg_end']]}; CPU share used by other processes during the timing: "
        + ("unknown" if r["other_processes_cpu_fraction"] is None else f"{r['other_processes_cpu_fraction']:.0%}"),
    ]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="small sizes: a smoke run, not a timing check")
    ap.add_argument("--out", type=Path, default=None, help="output directory (default: benches/results)")
    args = ap.parse_args(argv)
    out = args.out or (Path(tempfile.mkdtemp(prefix="allanite-floor-")) if args.quick else HERE / "results")
    out.mkdir(parents=True, exist_ok=True)
    run(args.quick, out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
