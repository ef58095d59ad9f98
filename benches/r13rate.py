#!/usr/bin/env python3
"""The level term's own test (r13rate; docs/channels.md, "The level term"): how often a channel regression names a
level coefficient that is not there, and keeps one that is, over seeds of the blind rows' own generators.

Per seed, ``allanite.model.channels.regress_channel`` (what refine's regression step runs) at refine's α on the
rate and the logged channel of:

- ``grad`` — blind9's FOG on dT/dt only (0.025 °/s per °C/s, no level term), chamber ramping 10–40 °C, 200 Hz × 10⁶;
- ``daily_null`` — blind8's 48 h at 5 Hz, daily cycle plus weather, the rate on dT/dt only (2 °/s per °C/s);
- ``daily`` — the same with the level term too (1.3·10⁻⁴ °/s per °C): blind8's row, the power;
- ``turnover`` — blind7's turnover gyro (4·10⁻⁵ °/s per °C² × (T − 25 °C)², T 15–35 °C, 20 Hz × 10⁶).

Per case: how often the level term (``coefficient``) is kept, with its Clopper–Pearson 95 % interval, how often the
other true terms are, the level test's p-values (their spread under a null: uniform), and each true parameter's
median error. Where the truth has no level term a kept one is a false claim (its test at 2 % of the level, 0.1 %);
before r13rate it was kept on every record whose coupling was accepted.

Usage::

    python benches/r13rate.py                     # -> benches/results/r13rate.{json,md}
    python benches/r13rate.py --seeds 4 --case grad --out DIR
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np
from scipy.stats import beta

import refine_blind7 as rb7
import refine_blind8 as rb8
import refine_blind9 as rb9
from allanite.model.channels import ALPHA, regress_channel

HERE = Path(__file__).resolve().parent
SEED0 = 10_000


def _daily_null(rng):
    """blind8's 48 h record with the rate on dT/dt only."""
    keep = rb8.DAY_C
    rb8.DAY_C = 0.0
    try:
        return rb8._daily(rng)
    finally:
        rb8.DAY_C = keep


#: name → (generator, truth, what)
CASES = {
    "grad": (rb9._gradient, {"rate_coefficient": rb9.GRAD_R}, "blind9's FOG on dT/dt only, 200 Hz × 10⁶"),
    "daily_null": (_daily_null, {"rate_coefficient": rb8.DAY_R}, "blind8's 48 h, dT/dt only, 5 Hz × 864 000"),
    "daily": (
        rb8._daily,
        {"coefficient": rb8.DAY_C, "rate_coefficient": rb8.DAY_R},
        "blind8's 48 h, T and dT/dt, 5 Hz × 864 000",
    ),
    "turnover": (rb7._turnover, {"quadratic": rb7.TURN_Q}, "blind7's turnover gyro, 20 Hz × 10⁶"),
}


def one(case: str, seed: int) -> dict:
    build, _truth, _what = CASES[case]
    y, fs, chans, _kw, _comp = build(np.random.default_rng(SEED0 + seed))
    ((name, ch),) = chans.items()
    r = regress_channel(y, ch, fs, name=name, alpha=ALPHA, level=0.05)
    lv = r.terms.get("coefficient", {})
    return {
        "seed": SEED0 + seed,
        "accepted": r.accepted,
        "params": r.params,
        "intervals": r.intervals,
        "level_test": {k: lv.get(k) for k in ("statistic", "threshold", "dof", "p_value", "bartlett", "kept")},
        "coupling_bartlett": r.test.get("bartlett"),
    }


def _cp(k: int, n: int) -> tuple[float, float]:
    lo = 0.0 if k == 0 else float(beta.ppf(0.025, k, n - k + 1))
    hi = 1.0 if k == n else float(beta.ppf(0.975, k + 1, n - k))
    return lo, hi


def summary(case: str, rows: list) -> dict:
    n_all = len(rows)
    truth = CASES[case][1]
    rows = [r for r in rows if r["accepted"]]  # a regression not accepted reports nothing (its params unused)
    n = len(rows)
    k_level = sum("coefficient" in r["params"] for r in rows)
    ps = [r["level_test"]["p_value"] for r in rows if r["level_test"].get("p_value") is not None]
    out = {
        "records": n_all,
        "accepted": n,
        "level_kept": k_level,
        "level_kept_cp95": _cp(k_level, n),
        "level_tested": len(ps),
        "level_p_below": {str(a): sum(p < a for p in ps) for a in (0.001, 0.01, 0.05, 0.5)},
        "terms_kept": {k: sum(k in r["params"] for r in rows) for k in truth},
        "median_error": {},
    }
    for k, v in truth.items():
        e = [r["params"][k] / v - 1.0 for r in rows if k in r["params"]]
        out["median_error"][k] = float(np.median(e)) if e else None
    return out


def write(res: dict, out: Path, load: tuple) -> None:
    out.mkdir(parents=True, exist_ok=True)
    res["load"] = list(load)
    (out / "r13rate.json").write_text(json.dumps(res, indent=1, default=str))
    lines = [
        "# The level term's own test over seeds (`benches/r13rate.py`)",
        "",
        f"`regress_channel` at refine's α on each row's own generator, seeds {SEED0}…; load average at the start "
        f"{load[0]:.1f}, at the end {load[1]:.1f} (other processes ran beside it: the seconds are not a cost).",
        "",
        "| case | truth | records | accepted | level term kept, of accepted (CP 95 %) | level test p < 0.001 / 0.01 / 0.05 / 0.5 "
        "(of tested) | true terms kept | median error |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for case, s in res["summaries"].items():
        _b, truth, what = CASES[case]
        lo, hi = s["level_kept_cp95"]
        pb = s["level_p_below"]
        err = ", ".join(f"{k} {100 * v:+.1f} %" for k, v in s["median_error"].items() if v is not None)
        kept = ", ".join(f"{k} {v}" for k, v in s["terms_kept"].items())
        lines.append(
            f"| {what} | {', '.join(f'{k} {v:g}' for k, v in truth.items())} | {s['records']} | {s['accepted']} | "
            f"{s['level_kept']} ({100 * lo:.0f}–{100 * hi:.0f} %) | {pb['0.001']} / {pb['0.01']} / {pb['0.05']} / "
            f"{pb['0.5']} (of {s['level_tested']}) | {kept} | {err} |"
        )
    lines += ["", *res.get("notes", [])]
    (out / "r13rate.md").write_text("\n".join(lines) + "\n")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--case", default=None, help="only this case")
    ap.add_argument("--out", type=Path, default=HERE / "results")
    ap.add_argument("--rewrite", action="store_true", help="summaries and page again from the JSON in --out")
    a = ap.parse_args(argv)
    if a.rewrite:
        res = json.loads((a.out / "r13rate.json").read_text())
        res["summaries"] = {case: summary(case, rows) for case, rows in res["cases"].items()}
        write(res, a.out, tuple(res.get("load", [float("nan")] * 2)))
        return
    load0 = os.getloadavg()[0]
    res: dict = {"seeds": a.seeds, "cases": {}, "summaries": {}}
    for case in [c for c in CASES if a.case is None or c == a.case]:
        rows = []
        for s in range(a.seeds):
            t0 = time.time()
            rows.append(one(case, s) | {"seconds": time.time() - t0})
            print(case, s, rows[-1]["params"], rows[-1]["level_test"].get("p_value"), flush=True, file=sys.stderr)
        res["cases"][case] = rows
        res["summaries"][case] = summary(case, rows)
        print(case, res["summaries"][case], flush=True)
    write(res, a.out, (load0, os.getloadavg()[0]))


if __name__ == "__main__":
    main()
