"""A line of few cycles under red noise: the slow-line test's second reading (the noise refitted beside the line,
calibrated by a parametric bootstrap, :mod:`allanite.model.slowline`) before → after.

- **Power** — over seeds, per case and amplitude (1×, 2×, 4× a base amplitude), the share of records the test
  (at α, its share of ``level``) finds the line on, and the CPU seconds the test took on each.
  (a) a clock at 1 Hz × 5 d, a daily line under flicker FM; (b) a 100 Hz gyro × 4 h, a 1 h thermal cycle — the
  two the test said nothing on; (c) a 0.5 Hz tiltmeter × 2·10⁵ (blind10's noise and settling drift, its daily line
  at a quarter of blind10's 0.6 µrad as 1×), where the test already found it (the α/2 split must not lose it).
  Seeds and cases as round r14slowred's (``benches/results/r14slowred.md`` on that branch): the rows compare.
- **False alarms** (``--part fa``) — ``refine_false_alarms.py``'s clean records (its mixtures and seeds), the test
  alone as refine runs it: accepted at α, how often the bootstrap ran, CPU.
- **Nulls** — red-noise records (``r13slowline.NULLS``'s flicker- and random-walk-dominated kinds): rejected at α,
  the p-value (``calibrate=True``: every reading's draws, the bootstrap too) at 0.01 and 0.05 with Clopper–Pearson
  95 % intervals (uniformity of p), and the CPU seconds of the test as refine runs it (``calibrate=False``).

The library measured is the one on ``PYTHONPATH`` (``/work/main/python`` for before). Each run is merged under
``--label`` into ``benches/results/r17slowboot.json`` (part by part, so runs can be split over processes); the .md
shows every label.

Usage::

    PYTHONPATH=python python3 benches/r17slowboot.py --label after --part power --cases clock
    PYTHONPATH=python python3 benches/r17slowboot.py --label after --part nulls --kinds clock,gyro --records 40
"""

from __future__ import annotations

import argparse
import fcntl
import json
import os
import subprocess
import time
from pathlib import Path

import numpy as np

import r13slowline as r13
import refine_blind as rb
from _common import clopper_pearson
from allanite._blas import one_thread
from allanite.model import slowline as sl

ALPHA = r13.ALPHA
OUT = Path(__file__).parent / "results"

#: Power cases: name → (fs, n, noise keywords, period s, 1× amplitude, a settling drift (amplitude, T s) or None).
CASES = {
    "clock 1 Hz × 5 d, daily line, flicker FM": (1.0, 432_000, {"N": 1.0, "B": 0.01}, 86_400.0, 0.02, None),
    "gyro 100 Hz × 4 h, 1 h thermal cycle": (100.0, 1_440_000, {"N": 2e-3, "B": 3e-4, "K": 1e-5}, 3600.0, 4e-4, None),
    "tiltmeter 0.5 Hz × 2·10⁵, daily line + settling": (
        0.5,
        200_000,
        {"N": 0.05, "B": 0.01, "K": 2e-5},
        86_400.0,
        0.15,
        (2.0, 40_000.0),
    ),
}
#: Null kinds (r13slowline.NULLS) dominated by flicker or random walk.
RED_NULLS = [k for k in r13.NULLS if not k.startswith("white only")]


def _timed(y: np.ndarray, fs: float, calibrate: bool = False) -> tuple[dict, float]:
    t0 = time.process_time()
    r = sl.slow_line_test(y, fs, ALPHA, calibrate=calibrate)
    return r, time.process_time() - t0


def _power_row(name: str, mult: float, seeds: int) -> dict:
    fs, n, kw, period, amp1, drift = CASES[name]
    amp, length = amp1 * mult, n / fs
    found, cpu, p = 0, [], []
    for s in range(seeds):
        rng = np.random.default_rng(9_000 + 37 * s + len(name))  # r14slowred's seeds
        t = np.arange(n) / fs
        e = rb.noise(n, fs, rng, **kw)
        if drift is not None:
            e = e + drift[0] * np.exp(-t / drift[1])
        y = e + amp * np.sin(2 * np.pi * t / period + rng.uniform(0, 2 * np.pi))
        r, c = _timed(y, fs)
        found += int(r["accepted"])
        cpu.append(c)
        p.append(r["p_value"])
    print(name, mult, found, f"cpu median {np.median(cpu):.2f}", flush=True)
    return {
        "amplitude": amp,
        "mult": mult,
        "seeds": seeds,
        "cycles": length / period,
        "found": found,
        "cpu": cpu,
        "p": p,
    }


def _null_row(name: str, records: int, start: int, calibrate: bool) -> dict:
    fs, n, kw = r13.NULLS[name]
    p, acc, cpu = [], 0, []
    for i in range(start, start + records):
        rng = np.random.default_rng(7_000 + 101 * i + len(name))  # r13slowline's seeds
        y = rb.noise(n, fs, rng, **kw)
        r, c = _timed(y, fs, calibrate)
        acc += int(r["accepted"])
        cpu.append(c)
        p.append(r["p_value"])
    print(name, start, "accepted", acc, "smallest p", sorted(v for v in p if v is not None)[:3], flush=True)
    return {"records": records, "start": start, "accepted": acc, "p_values": p, "cpu": cpu}


def _fa_row(mix: str, per_mix: int) -> dict:
    """The test alone (as refine runs it, ``calibrate=False``) on ``refine_false_alarms.py``'s clean records of
    ``mix`` (its seeds, its first ``per_mix`` records): accepted at α, the second reading's bootstrap run, CPU."""
    import refine_false_alarms as rfa

    acc, boot, cpu, p = 0, 0, [], []
    n = per_mix if mix != "issue16" else max(2, per_mix * 2 // 3)
    for k in range(n):
        y, fs, _channels = rfa.record(mix, 10_000 + 1_000_003 * rfa.MIXES.index(mix) + 97 * k)
        r, c = _timed(np.asarray(y, dtype=np.float64), fs)
        cpu.append(c)
        if r is None:
            continue
        acc += int(r["accepted"])
        boot += int(bool((r.get("readings") or {}).get("refit", {}).get("bootstrap")))
        p.append(r["p_value"])
    print(mix, "accepted", acc, "bootstrapped", boot, f"cpu median {np.median(cpu):.2f}", flush=True)
    return {"records": n, "accepted": acc, "bootstrapped": boot, "cpu": cpu, "p_values": p}


def _merge(label: str, part: str, rows: dict, meta: dict) -> dict:
    """``rows`` merged into the results file under ``label`` → ``part`` (locked: runs split over processes)."""
    path = OUT / "r17slowboot.json"
    with open(OUT / ".r17slowboot.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        res = json.loads(path.read_text()) if path.exists() else {}
        run = res.setdefault(label, {})
        run.setdefault("runs", []).append(meta)
        for k, v in rows.items():
            old = run.setdefault(part, {}).get(k)
            if (
                part.startswith("nulls") and old is not None and old["start"] != v["start"]
            ):  # a further slice of records
                v = {key: old[key] + v[key] for key in ("records", "accepted", "p_values", "cpu")} | {"start": -1}
            run[part][k] = v
        path.write_text(json.dumps(res, indent=1))
    return res


def _cp(k: int, n: int) -> str:
    lo, hi = clopper_pearson(k, n)
    return f"{k}/{n} ({100 * lo:.1f}–{100 * hi:.1f} %)"


#: What the tables do and do not say.
NOTES = [
    "## Notes",
    "",
    "- `before` is main's test (the first reading alone, at α) on the same seeds, run from this script with "
    "`PYTHONPATH=/work/main/python`; the commit in its line is this worktree's, not the library's.",
    '- "as refine runs it": `calibrate=False`, so a p-value is computed only where a statistic passes one '
    "frequency's bound (and the bootstrap only where the ratio passes the maximum law's quantile): its p ≤ 0.05 "
    'column undercounts. Uniformity of p is read from the "every p computed" table (`--calibrate`, the bootstrap '
    "on every record; 7 s CPU a record, so fewer records).",
    "- Other helpers' benches and tests shared the 2 cores (load 5–14): CPU seconds are the test's own process time "
    "on one BLAS thread, comparable within a table, not idle timings.",
    "",
]


def _null_table(rows: dict, title: str) -> list[str]:
    lines = [
        f"Red-noise nulls, the test {title}:",
        "",
        f"| null | accepted at α {ALPHA:g} | p ≤ 0.01 | p ≤ 0.05 | CPU s median (max) |",
        "|---|---|---|---|---|",
    ]
    tot, cpu_all = [0, 0, 0, 0], []
    for name, r in rows.items():
        p = np.array([1.0 if v is None else v for v in r["p_values"]])
        c = [r["accepted"], int(np.count_nonzero(p <= 0.01)), int(np.count_nonzero(p <= 0.05))]
        tot = [tot[0] + r["records"]] + [a + b for a, b in zip(tot[1:], c, strict=True)]
        cpu_all += r["cpu"]
        cells = " | ".join(_cp(k, r["records"]) for k in c)
        lines.append(f"| {name} | {cells} | {np.median(r['cpu']):.2f} ({max(r['cpu']):.2f}) |")
    cells = " | ".join(f"**{_cp(k, tot[0])}**" for k in tot[1:])
    return lines + [f"| all | {cells} | {np.median(cpu_all):.2f} ({max(cpu_all):.2f}) |", ""]


def _md(res: dict) -> list[str]:
    lines = ["# A line of few cycles under red noise: the bootstrap-calibrated second reading (r17slowboot)", ""]
    lines += [f"α of the test = {ALPHA:g} (level 0.05 × 0.008). CPU: the test alone, one BLAS thread.", ""]
    for label, run in res.items():
        lines += [f"## {label}", ""] + [
            f"- {m['part']} at {m['commit']}, load {m['load_start']} → {m['load_end']}" for m in run["runs"]
        ]
        lines.append("")
        if run.get("power"):
            lines += ["| case | cycles | amplitude | found | CPU s median (max) |", "|---|---|---|---|---|"]
            for key in sorted(run["power"]):
                r = run["power"][key]
                cpu = f"{np.median(r['cpu']):.2f} ({max(r['cpu']):.2f})"
                name = key.rsplit(" @ ", 1)[0]
                lines.append(
                    f"| {name} | {r['cycles']:.1f} | {r['amplitude']:g} ({r['mult']:g}×) | "
                    f"{_cp(r['found'], r['seeds'])} | {cpu} |"
                )
            lines.append("")
        for part, title in (("nulls", "as refine runs it (p where computed)"), ("nulls_p", "every p computed")):
            if run.get(part):
                lines += _null_table(run[part], title)
        if run.get("fa"):
            lines += [
                "refine_false_alarms.py's clean records, the test alone as refine runs it (p only where computed):",
                "",
                f"| mixture | accepted at α {ALPHA:g} | bootstrap run | CPU s median (max) |",
                "|---|---|---|---|",
            ]
            acc = tot = 0
            for mix, r in run["fa"].items():
                acc, tot = acc + r["accepted"], tot + r["records"]
                cpu = f"{np.median(r['cpu']):.2f} ({max(r['cpu']):.2f})"
                lines.append(f"| {mix} | {_cp(r['accepted'], r['records'])} | {r.get('bootstrapped', '—')} | {cpu} |")
            lines += [f"| all | **{_cp(acc, tot)}** | | |", ""]
    return lines + NOTES


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--label", required=True)
    ap.add_argument("--part", choices=("power", "nulls", "fa", "table"), required=True)
    ap.add_argument("--per-mix", type=int, default=40, help="refine_false_alarms records per mixture (part fa)")
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--mults", default="1,2,4")
    ap.add_argument("--cases", default="", help="substrings of the power cases to run (default all)")
    ap.add_argument("--kinds", default="", help="substrings of the null kinds to run (default all red kinds)")
    ap.add_argument("--records", type=int, default=40, help="null records per kind")
    ap.add_argument("--start", type=int, default=0, help="the first null record's index (to split a kind)")
    ap.add_argument("--calibrate", action="store_true", help="nulls: every p-value computed (part nulls_p)")
    args = ap.parse_args(argv)
    commit = subprocess.run(["git", "describe", "--always", "--dirty"], capture_output=True, text=True).stdout.strip()
    meta = {"part": args.part, "commit": commit, "load_start": [round(v, 1) for v in os.getloadavg()]}
    rows: dict = {}
    with one_thread():
        if args.part == "power":
            names = [k for k in CASES if not args.cases or any(c in k for c in args.cases.split(","))]
            for k in names:
                for m in (float(v) for v in args.mults.split(",")):
                    rows[f"{k} @ {m:g}"] = _power_row(k, m, args.seeds)
        elif args.part == "nulls":
            kinds = [k for k in RED_NULLS if not args.kinds or any(c in k for c in args.kinds.split(","))]
            rows = {k: _null_row(k, args.records, args.start, args.calibrate) for k in kinds}
        elif args.part == "fa":
            import refine_false_alarms as rfa

            rows = {m: _fa_row(m, args.per_mix) for m in rfa.MIXES}
    meta["load_end"] = [round(v, 1) for v in os.getloadavg()]
    part = "nulls_p" if args.part == "nulls" and args.calibrate else args.part
    meta["part"] = part
    res = _merge(args.label, part, rows, meta) if rows else json.loads((OUT / "r17slowboot.json").read_text())
    (OUT / "r17slowboot.md").write_text("\n".join(_md(res)) + "\n")
    print("\n".join(_md({args.label: res[args.label]})))


if __name__ == "__main__":
    main()
