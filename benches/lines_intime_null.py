#!/usr/bin/env python3
"""The false-alarm side of refine's in-time tests retried beside strong lone lines
(:meth:`allanite.model.refinement._in_time.TimeRemovals.outliers_beside_lines` and
:meth:`~allanite.model.refinement._in_time.TimeRemovals.drift_confirmed_beside_lines`): records with one strong
line, Gaussian noise, no spikes and no warm-up — how often outliers or a drift are taken. A second set with a
warm-up beside the line: how often the drift is kept (the confirmation's cost in power).

Each null record: 100 Hz × 10⁵ (1000 s), white noise 2·10⁻³ °/s/√Hz (σ 0.02 °/s per sample), flicker 1–5·10⁻⁴
°/s, random walk of rate 0–10⁻⁵ °/s^1.5, one line at 0.5–40 Hz (log-uniform) of amplitude 2–10× the per-sample σ,
its phase uniform (all drawn per record, seeds 0 … n−1). The warm-up set (seeds 50 000 …): the same with
0.01–0.03·e^{−t/T}, T 100–300 s. refine's removals and the sinusoid (``candidates=("outliers", "drift",
"periodic", "sinusoid")``: the in-time decisions do not depend on the curve candidates after them). The outliers'
share of ``level`` is 0.25 %, the drift's 0.375 % per test (docs/refinement.md, the levels). Clopper–Pearson 95 %
intervals. ``--base PATH``: the same records on another copy of the package (its ``python`` folder) for the
before column.

Usage::

    python benches/lines_intime_null.py --n 120 --n-warm 30 --base /tmp/base/python   # -> benches/results/lines_intime_null.{md,json}
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from scipy.stats import beta

HERE = Path(__file__).resolve().parent
CANDIDATES = ("outliers", "drift", "periodic", "sinusoid")


def record(seed: int, warm: bool):
    import allanite
    from allanite.simulation import kasdin_walter

    rng = np.random.default_rng(seed)
    fs, n = 100.0, 100_000
    t = np.arange(n) / fs
    b, k = rng.uniform(1e-4, 5e-4), rng.uniform(0.0, 1e-5)
    y = allanite.simulate(n, fs, N=2e-3, K=k, seed=rng) if k else allanite.simulate(n, fs, N=2e-3, seed=rng)
    y = y + b * kasdin_walter(4 * n, 1.0, rng)[-n:]
    f0 = float(np.exp(rng.uniform(np.log(0.5), np.log(40.0))))
    amp = 0.02 * rng.uniform(2.0, 10.0)
    y = y + amp * np.sin(2 * np.pi * f0 * t + rng.uniform(0, 2 * np.pi))
    if warm:
        y = y + rng.uniform(0.01, 0.03) * np.exp(-t / rng.uniform(100.0, 300.0))
    return y, fs


def one(seed: int, warm: bool) -> dict:
    import allanite

    y, fs = record(seed, warm)
    r = allanite.refine(y, fs, unit="deg/s", candidates=CANDIDATES, progress=False)
    effects = [s.effect for s in r.steps]
    considered = [e for v in r.considered.values() for e in v]
    beside = any("beside_lines_hz" in s.evidence for s in r.steps) or any(
        "beside_lines" in e or "beside_lines_hz" in e for e in considered
    )
    return {"seed": seed, "warm": warm, "effects": effects, "retried": beside}


def cp(k: int, n: int) -> tuple[float, float]:
    lo = 0.0 if k == 0 else float(beta.ppf(0.025, k, n - k + 1))
    hi = 1.0 if k == n else float(beta.ppf(0.975, k + 1, n - k))
    return lo, hi


def run(pythonpath: str, seeds: list, warm: bool) -> list:
    """The records refined in a fresh process on the package at ``pythonpath`` (one JSON line per record)."""
    code = (
        f"import json, sys; sys.path.insert(0, {str(HERE)!r}); import lines_intime_null as m\n"
        f"for s in {seeds!r}: print(json.dumps(m.one(s, {warm!r})), flush=True)"
    )
    env = dict(os.environ, PYTHONPATH=pythonpath)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    return [json.loads(line) for line in out.stdout.splitlines() if line.startswith("{")]


def share_row(label: str, k: int, n: int) -> str:
    lo, hi = cp(k, n)
    return f"| {label} | {k} of {n} | {k / max(n, 1):.1%} | {lo:.1%}–{hi:.1%} |"


def table(res: list, what: str) -> list:
    null = [v for v in res if not v["warm"]]
    warm = [v for v in res if v["warm"]]
    n, m = len(null), len(warm)
    return [
        f"**{what}**",
        "",
        "| | records | share | 95 % CP |",
        "|---|---|---|---|",
        share_row("null: a line found (sinusoid step)", sum("sinusoid" in v["effects"] for v in null), n),
        share_row(
            "null: a retest beside the lines ran (outliers) or undid a drift", sum(v["retried"] for v in null), n
        ),
        share_row("null: outliers taken (false alarm)", sum("outliers" in v["effects"] for v in null), n),
        share_row("null: drift taken (false alarm)", sum("drift" in v["effects"] for v in null), n),
        share_row("warm-up beside the line: drift taken (power)", sum("drift" in v["effects"] for v in warm), m),
        share_row("warm-up beside the line: outliers taken", sum("outliers" in v["effects"] for v in warm), m),
        "",
    ]


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=120)
    ap.add_argument("--n-warm", type=int, default=30)
    ap.add_argument("--base", default=None, help="the python folder of the code before the change")
    ap.add_argument("--out", default=str(HERE / "results"))
    args = ap.parse_args(argv)
    here_py = str(HERE.parent / "python")
    null_seeds, warm_seeds = list(range(args.n)), list(range(50_000, 50_000 + args.n_warm))
    t0 = time.time()
    after = run(here_py, null_seeds, False) + run(here_py, warm_seeds, True)
    before = (run(args.base, null_seeds, False) + run(args.base, warm_seeds, True)) if args.base else []
    wall = time.time() - t0
    sys.path.insert(0, str(HERE))
    import _common

    m = _common.machine_info()
    lines = [
        "# refine's in-time tests beside strong lines: their false-alarm side",
        "",
        f"Written by `benches/lines_intime_null.py` at {m['git_commit']}, {m['date_utc'][:10]}, {args.n} null "
        f"records and {args.n_warm} with a warm-up ({wall:.0f} s wall beside other processes). Records as the "
        "script's docstring says; outliers or a drift taken on a null record are false alarms.",
        "",
        *table(after, "After (this code)"),
        *(table(before, "Before (the code without the retests: " + str(args.base) + ")") if before else []),
    ]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "lines_intime_null.md").write_text("\n".join(lines) + "\n")
    (out / "lines_intime_null.json").write_text(json.dumps({"after": after, "before": before}, indent=1) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
