#!/usr/bin/env python3
"""What ``allanite.refine`` says of random telegraph (burst) noise against a Gaussian process of the same spectrum.

``benches/refine_blind11.py``'s burst row (a 0.02 °/s high state visited for 5 s every 200 s on average, beside
white, flicker and rate random walk at 100 Hz × 10⁶) took false change points and said a step of the mean on its
seed. This bench asks how often, over seeds: each record is refined with the default call twice — with the
telegraph, and with its Gaussian twin (a first-order Gauss–Markov process of the telegraph's σ = h·√(p(1 − p)) and
T_c = 1/(1/T_low + 1/T_high), the same spectrum) on the same seed's noise — and the change points taken, the steps of
the mean said in ``unexplained`` and whether the Gauss–Markov term was named are counted. A stationary process has no
change points and no steps: every one counted on either kind is a false one.

Usage::

    python benches/refine_telegraph.py                 # 10 seeds of each -> benches/results/refine_telegraph.{md,json}
    python benches/refine_telegraph.py --seeds 3 --out /tmp/x
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np
from scipy.signal import lfilter

import allanite
import refine_blind as rb
import refine_blind11 as b11

HERE = Path(__file__).resolve().parent
FS, N = 100.0, 1_000_000


def record(kind: str, seed: int) -> np.ndarray:
    """The burst row's noise on ``seed`` plus the telegraph (``kind`` "telegraph") or its Gaussian twin."""
    rng = np.random.default_rng(seed)
    y = rb.noise(N, FS, rng, N=2e-3, B=2e-4, K=5e-6)
    if kind == "telegraph":
        return y + b11._telegraph(N, FS, rng)
    gm = b11._burst_gm()
    a = math.exp(-1.0 / (FS * gm["tc"]))
    w = rng.standard_normal(N + 20_000) * gm["sigma"] * math.sqrt(1 - a * a)
    return y + lfilter([1.0], [1.0, -a], w)[20_000:]


def one(kind: str, seed: int) -> dict:
    t0 = time.process_time()
    r = allanite.refine(record(kind, seed), FS, unit="deg/s", progress=False)
    effects = [st.effect for st in r.steps]
    said = [u["what"] for u in r.unexplained]
    return {
        "kind": kind,
        "seed": seed,
        "effects": effects,
        "change_points": effects.count("change_point"),
        "gauss_markov": "gauss_markov" in effects,
        "mean_steps_said": sum("mean steps" in w for w in said),
        "unexplained": len(said),
        "cpu_s": time.process_time() - t0,
    }


def write(rows: list, out: Path, seeds: int) -> None:
    out.mkdir(parents=True, exist_ok=True)
    (out / "refine_telegraph.json").write_text(json.dumps(rows, indent=1))
    load = os.getloadavg()[0]
    lines = [
        "# refine on random telegraph noise and on its Gaussian twin (issue 29)",
        "",
        f"`python benches/refine_telegraph.py`, {platform.processor() or platform.machine()}, "
        f"{os.cpu_count()} CPUs, {time.strftime('%Y-%m-%d')}, 1-minute load {load:.1f} at the end. "
        f"{seeds} seeds (5000 …) of `benches/refine_blind11.py`'s burst row's noise (100 Hz × 10⁶; white 2·10⁻³, "
        "flicker 2·10⁻⁴, random walk 5·10⁻⁶), plus the telegraph (0.02 °/s, mean dwell 200 s low, 5 s high) or its "
        "Gaussian twin of the same spectrum; the default call. Every change point and every step of the mean is false.",
        "",
        "| kind | records | with a change point | change points | with a step of the mean said | Gauss–Markov named "
        "| telegraph named |",
        "|---|---|---|---|---|---|---|",
    ]
    for kind in ("telegraph", "gaussian"):
        rs = [r for r in rows if r["kind"] == kind]
        lines.append(
            f"| {kind} | {len(rs)} | {sum(r['change_points'] > 0 for r in rs)} | {sum(r['change_points'] for r in rs)} "
            f"| {sum(r['mean_steps_said'] > 0 for r in rs)} | {sum(r['gauss_markov'] for r in rs)} "
            f"| {sum('telegraph' in r['effects'] for r in rs)} |"
        )
    lines += [
        "",
        "| kind | seed | effects | steps of the mean said | unexplained entries | CPU s |",
        "|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['kind']} | {r['seed']} | {', '.join(r['effects']) or 'nothing'} | {r['mean_steps_said']} "
            f"| {r['unexplained']} | {r['cpu_s']:.1f} |"
        )
    lines += ["", *NOTES]
    (out / "refine_telegraph.md").write_text("\n".join(lines) + "\n")


#: What the table shows (kept true to the recorded run).
NOTES: list = [
    "**First run** (main at 1792669, the machine otherwise idle). On the telegraph, refine took false change points on 4 of 10 records (8 in all) and said a step of the mean on 9 of 10. On the Gaussian twin of the same spectrum it did neither on any of the 10 records. It named the Gauss–Markov term on 8 of 10 telegraph records and 10 of 10 twins; on the other two telegraph records it added nothing and said 4 things. Cause, as in blind11's notes: the telegraph's few long visits to its high state make 625 s windows differ far more than a Gaussian process's do, and a long visit reads as a step of the mean. The change-point and mean-step tests are calibrated on Gaussian records of the fitted model. Not fixed: a telegraph effect, or those tests calibrated on a telegraph null, is open in issue 29.",
    "",
    "**Rerun at 481cfea (r16burst: the `telegraph` removal, docs/refinement.md \"Random telegraph noise\"; the table above; other helpers' runs shared the 2 cores, load 10–13, so the CPU column is not a cost measurement).** On the telegraph, the telegraph was named on 10 of 10 records, with no change point, no step of the mean and nothing unexplained on any; the Gauss–Markov term is no longer added (the telegraph was the bump). The twins are as at the first run: the Gauss–Markov term alone on 10 of 10, nothing else (the telegraph's kurtosis test below its threshold on each). Before → after, telegraph records: with a change point 4 → 0 of 10, a step of the mean said 9 → 0 of 10.",
]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--out", type=Path, default=HERE / "results")
    a = ap.parse_args(argv)
    rows = []
    for kind in ("telegraph", "gaussian"):
        for seed in range(5000, 5000 + a.seeds):
            rows.append(one(kind, seed))
            print(json.dumps(rows[-1]), flush=True)
    write(rows, a.out, a.seeds)
    print(f"wrote {a.out / 'refine_telegraph.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
