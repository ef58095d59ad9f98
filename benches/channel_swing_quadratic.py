#!/usr/bin/env python3
"""The linear coefficient of a channel regression beside a quadratic, the channel going through its range once:
bias or scatter? Replicas over seeds of two blind rows that fail on it (their builders, their noise, their truth),
by :func:`allanite.model.channels.regress_channel` — the estimator refine's regression step reports at acceptance.

- ``b4``: ``benches/refine_blind4.py``'s automotive gyro started cold (−10 → 40 °C, a swing of time constant
  100 s in 2500 s), 2.5·10⁻⁴ per °C and 5·10⁻⁵ per °C², 400 Hz × 10⁶;
- ``b10``: ``benches/refine_blind10.py``'s float32 gyro, T 10 → 40 → 10 °C once over 10⁴ s, 5·10⁻⁵ per °C and
  1.5·10⁻⁵ per °C², 400 Hz × 4·10⁶.

Per seed: the coefficient's and the quadratic's relative errors (the truth the suites' own: the slope at the mean
of T over the record), whether the 68.3 % interval holds the truth, its half-width; on the first ``--linear`` seeds
the same record with its noise scaled by 0.1 — an estimate whose error is the noise's projection (no systematic
part) reads an error 0.1× as large.

Usage::

    python benches/channel_swing_quadratic.py                        # -> benches/results/channel_swing_quadratic.*
    python benches/channel_swing_quadratic.py --case b4 --seeds 40 --out DIR
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

import _common
import refine_blind4 as b4
import refine_blind10 as b10
from allanite.model.channels import regress_channel

HERE = Path(__file__).resolve().parent
CASES = {
    "b4": (b4._cold_start, 2.5e-4, 5e-5, 1000),
    "b10": (b10._float32_quadratic, b10.F32_C, b10.F32_Q, 2000),
}


def _one(y, temp, fs, c, q) -> dict:
    r = regress_channel(y, temp, fs, name="temp")
    p, iv = r.params, r.intervals
    out = {"accepted": r.accepted, "keys": sorted(p)}
    if "coefficient" in p:
        lo, hi = iv["coefficient"]
        out |= {"c_err": p["coefficient"] / c - 1, "covered": bool(lo <= c <= hi), "half_width": (hi - lo) / 2 / c}
    if "quadratic" in p:
        out |= {"q_err": p["quadratic"] / q - 1, "t_ref": r.terms["quadratic"].get("t_ref")}
    return out


def run(case: str, seeds: int, linear: int) -> dict:
    build, c, q, first = CASES[case]
    rows = []
    for seed in range(first, first + seeds):
        y, fs, chans, _, comp = build(np.random.default_rng(seed))
        y = np.asarray(y, dtype=np.float64)
        row = {"seed": seed} | _one(y, chans["temp"], fs, c, q)
        if seed < first + linear:
            row["scaled"] = _one(comp + 0.1 * (y - comp), chans["temp"], fs, c, q)
        rows.append(row)
    return {"case": case, "truth": {"coefficient": c, "quadratic": q}, "rows": rows}


def summary(res: dict) -> dict:
    rows = [r for r in res["rows"] if "c_err" in r]
    e = np.array([r["c_err"] for r in rows])
    eq = np.array([r["q_err"] for r in rows if "q_err" in r])
    k = sum(r["covered"] for r in rows)
    lin = [r["scaled"]["c_err"] / r["c_err"] for r in res["rows"] if "scaled" in r and "c_err" in r["scaled"]]
    return {
        "n": len(rows),
        "median": float(np.median(e)),
        "mean": float(np.mean(e)),
        "se_mean": float(np.std(e, ddof=1) / np.sqrt(e.size)),
        "sd": float(np.std(e, ddof=1)),
        "within_20pct": int(np.sum(np.abs(e) <= 0.2)),
        "covered": k,
        "coverage_cp95": _common.clopper_pearson(k, len(rows)),
        "half_width_median": float(np.median([r["half_width"] for r in rows])),
        "q_median": float(np.median(eq)) if eq.size else None,
        "q_sd": float(np.std(eq, ddof=1)) if eq.size > 1 else None,
        "scaled_ratio": lin,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--case", choices=tuple(CASES), action="append")
    ap.add_argument("--seeds", type=int, default=40)
    ap.add_argument("--linear", type=int, default=3)
    ap.add_argument("--out", type=Path, default=HERE / "results")
    args = ap.parse_args()
    out = {}
    for case in args.case or tuple(CASES):
        t0 = time.process_time()
        res = run(case, args.seeds, args.linear)
        out[case] = res | {"summary": summary(res), "cpu_s": time.process_time() - t0}
        print(case, json.dumps(out[case]["summary"]), flush=True)
    _common.write_results(args.out, "channel_swing_quadratic", page(out), out)


def page(out: dict) -> list:
    """The results page's table: one line per case."""
    lines = [
        "# The linear coefficient beside a quadratic, the channel through its range once: replicas over seeds",
        "",
        f"`python benches/channel_swing_quadratic.py`, {_common.machine_line()}.",
        "",
        "| case | seeds | coefficient error: median, mean ± s.e., s.d. | within 20 % | 68.3 % interval holds the truth "
        "(95 % CP) | median half-width | quadratic error: median, s.d. | error at 0.1× the noise / error |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for case, res in out.items():
        s = res["summary"]
        lo, hi = s["coverage_cp95"]
        ratios = ", ".join(f"{v:.3f}" for v in s["scaled_ratio"]) or "—"
        q = f"{s['q_median']:+.1%}, {s['q_sd']:.1%}" if s["q_sd"] is not None else "—"
        lines.append(
            f"| {case} | {s['n']} | {s['median']:+.1%}, {s['mean']:+.1%} ± {s['se_mean']:.1%}, {s['sd']:.1%} | "
            f"{s['within_20pct']} of {s['n']} | {s['covered']} of {s['n']} ({lo:.0%}–{hi:.0%}) | "
            f"{s['half_width_median']:.1%} | {q} | {ratios} |"
        )
    return lines


if __name__ == "__main__":
    main()
