"""The Rust core's per-window noise fit, this checkout against another, interleaved in one run (issue 30 item 1).

``allanite.fit(allanite.davar(y, 100, window=401, hop=10))`` of 10⁶ simulated samples (99,960 windows, five
terms on 6 τ) in fresh processes, the baseline's ``python/`` folder and this one's taking turns, so that both
see the same load: best wall and best CPU (this process's, all its threads) per window of each, their ratio,
and whether the two give the same numbers bit for bit. A shared machine's load inflates wall times most; the
CPU ratio is the comparison to read there.

    python benches/bench_fit_kernel.py --baseline ../main/python [--rounds 3] [--out benches/results]
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent

CODE = r"""
import hashlib, json, sys, time, allanite
y = allanite.simulate(1_000_000, 100.0, Q=1e-4, N=0.01, B=1e-3, K=1e-4, seed=30)
res = allanite.davar(y, 100.0, window=401, hop=10)
fit = allanite.fit(res)
wall, cpu = [], []
for _ in range(int(sys.argv[1])):
    t, c = time.perf_counter(), time.process_time()
    allanite.fit(res)
    wall.append(time.perf_counter() - t)
    cpu.append(time.process_time() - c)
h = hashlib.sha256()
for k in fit.terms:
    h.update(fit.values[k].tobytes())
h.update(fit.chi2_dof.tobytes())
print(json.dumps({"wall": min(wall), "cpu": min(cpu), "windows": int(res.t.size), "digest": h.hexdigest()}))
"""


def run_one(python_dir: Path, repeats: int) -> dict:
    env = dict(os.environ, PYTHONPATH=str(python_dir))
    p = subprocess.run([sys.executable, "-c", CODE, str(repeats)], env=env, capture_output=True, text=True, check=True)
    return json.loads(p.stdout.strip().splitlines()[-1])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", type=Path, required=True, help="python/ folder of the checkout to compare with")
    ap.add_argument("--rounds", type=int, default=3, help="alternations of baseline and this checkout")
    ap.add_argument("--repeats", type=int, default=3, help="timed fits per process (best kept)")
    ap.add_argument("--out", type=Path, default=HERE / "results")
    args = ap.parse_args()
    ours = HERE.parent / "python"
    load_start = open("/proc/loadavg").read().split()[:3]
    runs: dict[str, list] = {"baseline": [], "this": []}
    for _ in range(args.rounds):
        for name, path in (("baseline", args.baseline), ("this", ours)):
            runs[name].append(run_one(path, args.repeats))
            print(name, runs[name][-1], flush=True)
    w = runs["this"][0]["windows"]
    best = {n: {k: min(r[k] for r in rs) / w * 1e6 for k in ("wall", "cpu")} for n, rs in runs.items()}
    same = len({r["digest"] for rs in runs.values() for r in rs}) == 1
    load = open("/proc/loadavg").read().split()[:3]
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    res = {
        "date": dt.datetime.now(dt.UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "commit": commit,
        "baseline": str(args.baseline),
        "load_at_start": load_start,
        "load_at_end": load,
        "windows": w,
        "best_us_per_window": best,
        "ratio_wall": best["baseline"]["wall"] / best["this"]["wall"],
        "ratio_cpu": best["baseline"]["cpu"] / best["this"]["cpu"],
        "same_numbers": same,
        "runs": runs,
    }
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "fit_kernel.json").write_text(json.dumps(res, indent=1), encoding="utf-8")
    b, t = best["baseline"], best["this"]
    md = [
        "# The per-window noise fit in the Rust core: this checkout against a baseline (issue 30 item 1)",
        "",
        f"`python benches/bench_fit_kernel.py --baseline {args.baseline}` — {res['date']}, commit {commit}, "
        f"2 CPUs shared with other workers, load {load_start} at the start, {load} at the end. fit(davar(y, 100, window=401, hop=10)) of "
        f"10⁶ samples, {w:,} windows, five terms on 6 τ; fresh processes alternating, {args.rounds} each, "
        f"best of {args.repeats} fits per process.",
        "",
        "| | baseline | this checkout | ratio |",
        "|---|---|---|---|",
        f"| wall µs per window | {b['wall']:.2f} | {t['wall']:.2f} | {res['ratio_wall']:.2f}× |",
        f"| CPU µs per window (all threads) | {b['cpu']:.2f} | {t['cpu']:.2f} | {res['ratio_cpu']:.2f}× |",
        "",
        f"Same θ and χ²/dof bit for bit in every process: {same}.",
        "",
    ]
    (args.out / "fit_kernel.md").write_text("\n".join(md), encoding="utf-8")
    print("\n".join(md))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
