"""A static curve's noise-model fit: the Rust core's kernel (``_corefit.fit_curve``) against the Python iteration
(``fit_core``), alternating in fresh processes of this checkout (issue 30 item 2).

``allanite.fit(allanite.avar(x, 100))`` on ADIS16405 run 1's three gyros with ``tau_range="auto"`` (the report's
call: up to five τ cuts per axis) and with the default τ, and on four simulated curves (ADIS-like, clock-like,
flicker-dominated, a term at zero). Each process fits once cold — the first call, with whatever it imports
(the reference's NNLS loads scipy.optimize) — and then ``--repeats`` times warm (best kept); CPU time of this
process (all threads), wall time, and the largest relative difference of the coefficients between the paths.
A shared machine's load inflates wall times most; the CPU ratio is the comparison to read there.

    python benches/bench_static_fit.py [--rounds 3] [--repeats 5] [--out benches/results]
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import os
import subprocess
import sys
from pathlib import Path

import _common

HERE = Path(__file__).resolve().parent

CODE = r"""
import json, sys, time
import numpy as np
import allanite
from allanite.model import _fitcore, fitting
path, case, which, repeats = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
if which == "python":
    fitting.fit_curve = _fitcore.fit_core  # the reference: fit_core's own iteration
if case in ("adis_auto", "adis_default"):
    x = allanite.read_log(path, fs=100.0, columns=["gyro_x", "gyro_y", "gyro_z"]).data
    kw = {"tau_range": "auto"} if case == "adis_auto" else {}
else:
    sims = {"adis_like": dict(Q=3.5e-4, N=2e-3, B=1e-3, K=6e-5), "clock_like": dict(Q=1e-3, N=1e-4, B=1e-5, K=1e-7),
            "flicker": dict(N=1e-4, B=1e-2), "term_at_zero": dict(N=1e-2, K=1e-4)}
    x = allanite.simulate(1_000_000, 100.0, seed=7, **sims[case])
    kw = {}
st = allanite.avar(x, 100.0)
def once():
    t, c = time.perf_counter(), time.process_time()
    f = allanite.fit(st, **kw)
    return f, time.perf_counter() - t, time.process_time() - c
f, cold_wall, cold_cpu = once()
warm = [once()[1:] for _ in range(repeats)]
fits = f if isinstance(f, list) else [f]
print(json.dumps({
    "cold_wall": cold_wall, "cold_cpu": cold_cpu,
    "warm_wall": min(w for w, _ in warm), "warm_cpu": min(c for _, c in warm),
    "curves": len(fits),
    "values": [[f.coefficients[t].value for t in f.terms] for f in fits],
}))
"""

CASES = ("adis_auto", "adis_default", "adis_like", "clock_like", "flicker", "term_at_zero")


def run_one(path: Path, case: str, which: str, repeats: int) -> dict:
    env = dict(os.environ, PYTHONPATH=str(HERE.parent / "python"))
    p = subprocess.run(
        [sys.executable, "-c", CODE, str(path), case, which, str(repeats)],
        env=env,
        capture_output=True,
        text=True,
        check=True,
    )
    return json.loads(p.stdout.strip().splitlines()[-1])


def _rel(a, b) -> float:
    a, b = [v for r in a for v in r], [v for r in b for v in r]
    return max((abs(u - v) / abs(v) if v else abs(u)) for u, v in zip(a, b))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=3, help="alternations of the two paths")
    ap.add_argument("--repeats", type=int, default=5, help="warm fits per process (best kept)")
    ap.add_argument("--out", type=Path, default=HERE / "results")
    args = ap.parse_args()
    data = _common.shared_data_dir() / "adis16405" / "adis16405_run1_100Hz.csv.gz"
    cases = CASES if data.is_file() else CASES[2:]
    load_start = open("/proc/loadavg").read().split()[:3]
    rows = {}
    for case in cases:
        runs: dict[str, list] = {"python": [], "core": []}
        for _ in range(args.rounds):
            for which in ("python", "core"):
                runs[which].append(run_one(data, case, which, args.repeats))
        best = {w: {k: min(r[k] for r in rs) for k in ("cold_cpu", "warm_cpu", "warm_wall")} for w, rs in runs.items()}
        rows[case] = {
            "curves": runs["core"][0]["curves"],
            "best": best,
            "ratio_cold_cpu": best["python"]["cold_cpu"] / best["core"]["cold_cpu"],
            "ratio_warm_cpu": best["python"]["warm_cpu"] / best["core"]["warm_cpu"],
            "max_rel_diff_coefficients": _rel(runs["core"][0]["values"], runs["python"][0]["values"]),
        }
        print(case, json.dumps(rows[case]), flush=True)
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    res = {
        "date": dt.datetime.now(dt.UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "commit": commit,
        "load_at_start": load_start,
        "load_at_end": open("/proc/loadavg").read().split()[:3],
        "rounds": args.rounds,
        "repeats": args.repeats,
        "rows": rows,
    }
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "static_fit.json").write_text(json.dumps(res, indent=1) + "\n")
    (args.out / "static_fit.md").write_text(_table(res))
    return 0


def _table(res: dict) -> str:
    lines = [
        "# A static curve's noise-model fit: the Rust core's kernel against the Python iteration",
        "",
        f"`python benches/bench_static_fit.py` — {res['date']}, commit {res['commit']}, load "
        f"{' '.join(res['load_at_start'])} → {' '.join(res['load_at_end'])} on 2 cores; {res['rounds']} fresh "
        f"processes per path, alternating; best CPU (this process, all threads) of each. Cold: the first fit in a "
        f"fresh process, with what it imports; warm: best of {res['repeats']} more.",
        "",
        "| curve | fits | cold CPU python → core (s) | × | warm CPU python → core (ms) | × | largest coefficient difference |",
        "|---|---|---|---|---|---|---|",
    ]
    names = {
        "adis_auto": "ADIS run 1, 3 gyros, tau_range='auto' (the report's)",
        "adis_default": "ADIS run 1, 3 gyros, default τ",
        "adis_like": "simulated ADIS-like (Q, N, B, K)",
        "clock_like": "simulated clock-like",
        "flicker": "simulated flicker-dominated",
        "term_at_zero": "simulated N + K (Q, B at zero)",
    }
    for case, r in res["rows"].items():
        b = r["best"]
        lines.append(
            f"| {names[case]} | {r['curves']} | {b['python']['cold_cpu']:.3f} → {b['core']['cold_cpu']:.3f} | "
            f"{r['ratio_cold_cpu']:.1f} | {1e3 * b['python']['warm_cpu']:.1f} → {1e3 * b['core']['warm_cpu']:.1f} | "
            f"{r['ratio_warm_cpu']:.1f} | {r['max_rel_diff_coefficients']:.1e} |"
        )
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    sys.exit(main())
