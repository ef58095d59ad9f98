"""The slow-line test's bootstrap with analytic gradients (round r18boot): the test's every output before → after,
record by record, on ``benches/r17slowboot.py``'s records.

- ``--part nulls_p``: its red-noise nulls (``r13slowline.NULLS``, 32 a kind, its seeds), ``calibrate=True`` (every
  reading's draws, the bootstrap on every record): both readings' statistic, threshold and p-value, the bootstrap's
  offset and slope, the decision and the CPU seconds of the test alone.
- ``--part power``: its power cases (20 seeds a case and amplitude multiple), the test as refine runs it.
- ``--part rescale``: the record's two statistics on y·(1 + ε), ε = 0, ±10⁻⁹, 10⁻⁶ — mathematically the same
  statistics (every fit is scale-free); how far the library's own optimisers move them is the tolerance a change
  of optimiser is judged by.
- ``--part table``: ``benches/results/r18boot.md`` from the labels' rows (``before`` against ``after``).

The library measured is the one on ``PYTHONPATH`` (before: main's copy, e.g. ``/tmp/r18boot/main/python``). Rows go
to ``benches/results/r18boot_<label>_<part>.jsonl`` (one line a record, resumable; runs can be split by ``--only``).

Usage::

    PYTHONPATH=/tmp/r18boot/main/python python3 benches/r18boot.py --label before --part nulls_p --only clock
    PYTHONPATH=python python3 benches/r18boot.py --label after --part power
    PYTHONPATH=python python3 benches/r18boot.py --part table
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import numpy as np

import r13slowline as r13
import r17slowboot as b
import refine_blind as rb
from _common import clopper_pearson
from allanite._blas import one_thread
from allanite.model import slowline as sl

OUT = Path(__file__).parent / "results"


def _path(label: str, part: str) -> Path:
    return OUT / f"r18boot_{label}_{part}.jsonl"


def _row(key: str, y: np.ndarray, fs: float, calibrate: bool) -> dict:
    t0 = time.process_time()
    r = sl.slow_line_test(y, fs, b.ALPHA, calibrate=calibrate)
    cpu = time.process_time() - t0
    return {"key": key, "cpu": cpu, "accepted": r["accepted"], "p": r["p_value"], "reading": r["reading"]} | {
        "readings": r["readings"],
        "f0": r["f0"],
        "amplitude": r["amplitude"],
    }


def _records(part: str, only: list[str]):
    """(key, y, fs) of a part's records, those whose key holds one of ``only`` (all when empty)."""
    if part == "nulls_p":
        for name in b.RED_NULLS:
            fs, n, kw = r13.NULLS[name]
            for i in range(32):
                key = f"{name}#{i}"
                if not only or any(s in key for s in only):
                    yield (
                        key,
                        (
                            lambda i=i, name=name, n=n, fs=fs, kw=kw: rb.noise(
                                n, fs, np.random.default_rng(7_000 + 101 * i + len(name)), **kw
                            )
                        ),
                        fs,
                    )
    elif part == "power":
        for name, (fs, n, kw, period, amp1, drift) in b.CASES.items():
            for mult in (1.0, 2.0, 4.0):
                for s in range(20):
                    key = f"{name}@{mult:g}#{s}"
                    if not only or any(o in key for o in only):
                        yield key, (lambda name=name, s=s, mult=mult: _power_y(name, s, mult)), fs


def _power_y(name: str, s: int, mult: float) -> np.ndarray:
    fs, n, kw, period, amp1, drift = b.CASES[name]
    rng = np.random.default_rng(9_000 + 37 * s + len(name))  # r14slowred's seeds, as r17slowboot.py
    t = np.arange(n) / fs
    e = rb.noise(n, fs, rng, **kw)
    if drift is not None:
        e = e + drift[0] * np.exp(-t / drift[1])
    return e + amp1 * mult * np.sin(2 * np.pi * t / period + rng.uniform(0, 2 * np.pi))


def _rescaled(key: str, y: np.ndarray, fs: float) -> dict:
    """The first reading's scan maximum and the second's ratio of y·(1 + ε) (the fits' own reproducibility)."""
    n = y.size
    length = n / fs
    freqs = np.arange(sl.SCAN_CYCLES / length, 18.0 / length + 1e-12 / length, sl.STEP_CYCLES / length)
    out = {"key": key, "eps": [0.0, 1e-9, -1e-9, 1e-6], "chi": [], "lr": []}
    for eps in out["eps"]:
        z, t, _tb = sl._block_means(y * (1.0 + eps), fs, sl.BLOCKS)
        x0 = sl._nuisance(t, length)
        whole = sl._whole(z, t, x0, freqs)
        out["chi"].append(float(whole["chi"].max()))
        out["lr"].append(float(sl._ratio(z, t, x0, freqs, whole)["lr"]))
    return out


def run(label: str, part: str, only: list[str]) -> None:
    src = "power" if part == "rescale" else part
    path = _path(label, part)
    done = {json.loads(line)["key"] for line in path.open()} if path.exists() else set()
    with one_thread():
        for key, make, fs in _records(src, only):
            if key in done:
                continue
            y = make()
            row = _rescaled(key, y, fs) if part == "rescale" else _row(key, y, fs, part == "nulls_p")
            with path.open("a") as fh:
                fh.write(json.dumps(row) + "\n")
            print(key, json.dumps({k: v for k, v in row.items() if k not in ("key", "readings")}), flush=True)


def _load(label: str, part: str) -> dict:
    path = _path(label, part)
    return {json.loads(line)["key"]: json.loads(line) for line in path.open()} if path.exists() else {}


def _cp(k: int, n: int) -> str:
    lo, hi = clopper_pearson(k, n)
    return f"{k}/{n} ({100 * lo:.1f}–{100 * hi:.1f} %)"


def _diffs(a: dict, c: dict) -> dict:
    """Per quantity the largest |before − after| over the records both have (and where), where both computed it."""
    worst: dict = {}

    def put(q: str, u, v, key: str) -> None:
        if u is None or v is None:
            if (u is None) != (v is None):
                worst.setdefault(q + " computed on one side only", []).append(key)
            return
        d = abs(u - v)
        if d >= worst.get(q, (-1.0, ""))[0]:
            worst[q] = (d, key)

    for key in a.keys() & c.keys():
        x, y = a[key], c[key]
        for rd in sl.READINGS:
            for q in ("statistic", "threshold", "p_value"):
                put(f"{rd}.{q}", x["readings"][rd][q], y["readings"][rd][q], key)
        bx, by = x["readings"]["refit"]["bootstrap"], y["readings"]["refit"]["bootstrap"]
        for q in ("offset", "slope"):
            put(f"bootstrap.{q}", bx and bx[q], by and by[q], key)
        put("p (Bonferroni)", x["p"], y["p"], key)
    return worst


def _part_lines(part: str, title: str) -> list[str]:
    a, c = _load("before", part), _load("after", part)
    keys = sorted(a.keys() & c.keys())
    if not keys:
        return []
    boot = sum(1 for k in keys if a[k]["readings"]["refit"]["bootstrap"] and c[k]["readings"]["refit"]["bootstrap"])
    flips = [k for k in keys if a[k]["accepted"] != c[k]["accepted"]]
    acc = (sum(a[k]["accepted"] for k in keys), sum(c[k]["accepted"] for k in keys))
    cpu = [sum(d[k]["cpu"] for k in keys if d[k]["readings"]["refit"]["bootstrap"]) for d in (a, c)]
    lines = [f"### {title}", "", f"{len(keys)} records both ran ({boot} with the bootstrap on both sides).", ""]
    lines += [
        f"- decisions: accepted {_cp(acc[0], len(keys))} → {_cp(acc[1], len(keys))}; differ on "
        f"**{len(flips)}** {flips if flips else ''}"
    ]
    if part == "nulls_p":
        for lev in (0.01, 0.05):
            k0, k1 = (sum(1 for k in keys if d[k]["p"] is not None and d[k]["p"] <= lev) for d in (a, c))
            lines.append(f"- p ≤ {lev}: {_cp(k0, len(keys))} → {_cp(k1, len(keys))}")
    if part == "nulls_p":
        lines += _whole_kinds(c)
    else:
        lines += _power_rows(c)
    if cpu[1]:
        lines.append(
            f"- CPU of the test on the records with the bootstrap on both sides: {cpu[0]:.1f} → {cpu[1]:.1f} s "
            f"(**{cpu[0] / cpu[1]:.2f}×**; test alone, one BLAS thread, shared machine)"
        )
    lines += ["", "| quantity | largest \\|before − after\\| | at |", "|---|---|---|"]
    for q, v in sorted(_diffs(a, c).items()):
        if isinstance(v, list):
            lines.append(f"| {q} | {len(v)} records | {', '.join(v[:3])} |")
        else:
            lines.append(f"| {q} | {v[0]:.3g} | {v[1]} |")
    return lines + [""]


def _whole_kinds(after: dict) -> list[str]:
    """Kinds whose 32 records all ran after, against r17slowboot.json's p-values of main's code (same seeds; its
    records 16–31 stored in another order, so only counts compare)."""
    ref = json.loads((OUT / "r17slowboot.json").read_text())["after"]["nulls_p"]
    out = []
    for name in b.RED_NULLS:
        ps = [after[k]["p"] for k in after if k.rsplit("#", 1)[0] == name]
        if len(ps) < 32 or name not in ref:
            continue
        old = ref[name]["p_values"]
        cells = [
            f"p ≤ {lev}: {sum(v is not None and v <= lev for v in old)} → {sum(v is not None and v <= lev for v in ps)}"
            for lev in (b.ALPHA, 0.01, 0.05)
        ]
        acc = sum(after[k]["accepted"] for k in after if k.rsplit("#", 1)[0] == name)
        out.append(
            f"- all 32 of {name} (before from r17slowboot.json): accepted {ref[name]['accepted']} → {acc}; "
            + "; ".join(cells)
        )
    return out


def _power_rows(after: dict) -> list[str]:
    """Per power row the records found before (r17slowboot.json, main's code, same seeds) and after, where all 20
    ran after."""
    ref = json.loads((OUT / "r17slowboot.json").read_text())["after"]["power"]
    out = []
    for row, r in ref.items():
        case, mult = row.rsplit(" @ ", 1)
        keys = [k for k in after if k.startswith(f"{case}@{mult}#")]
        if len(keys) == r["seeds"]:
            seeds = [int(k.rsplit("#", 1)[1]) for k in keys if after[k]["accepted"]]
            out.append(f"- {row}: found {_cp(r['found'], r['seeds'])} → {_cp(len(seeds), len(keys))}")
    return out


def _rescale_lines() -> list[str]:
    lines = []
    for label in ("before", "after"):
        rows = _load(label, "rescale")
        if not rows:
            continue
        spread = {q: max(max(r[q]) - min(r[q]) for r in rows.values()) for q in ("chi", "lr")}
        where = max(rows, key=lambda k: max(rows[k]["lr"]) - min(rows[k]["lr"]))
        lines.append(
            f"- {label}: over {len(rows)} records, the largest spread of the first reading's maximum over the four "
            f"scalings {spread['chi']:.3g}, of the ratio {spread['lr']:.3g} (at {where}: {rows[where]['lr']})"
        )
    return (
        ["### The statistics of y·(1 + ε), ε = 0, ±10⁻⁹, 10⁻⁶ (the same statistics mathematically)", ""] + lines + [""]
        if lines
        else []
    )


#: What the tables do and do not say.
NOTES = [
    "## Notes",
    "",
    "- Both sides ran at load 20–27 on 2 shared cores (other helpers' jobs): CPU seconds are the test's own process "
    "time on one BLAS thread; the ratio is the claim.",
    "- after ran all 160 nulls and 180 power records; before (main's copy, every output) 41 nulls and 31 power "
    "records before the round's deadline — the record-by-record tables are of those. r17slowboot.json holds main's "
    "p-values and decisions on all of them (same code, same seeds: equal on every record both have), the before of "
    "the per-kind and per-row counts.",
    "- The differences are not optimiser tolerance in the narrow sense: main's L-BFGS-B with finite-difference "
    "gradients stops at different points of a flat ridge (the white part negligible: only r₁/r₂ is determined) and "
    "falls into different local minima of the fit beside the sinusoid under a mathematically null change of the "
    "record — the rescale table: main's ratio on one clock record 16.6 at ε = 0 and −10⁻⁹, 36.1 at +10⁻⁹ and 10⁻⁶; "
    "the analytic-gradient fits give 36.1 at all four. That record (power, a real daily line of 0.02, seed 15) is "
    "the one whose decision differs: accepted after, not before — and main accepts it too at ε = 10⁻⁹ (its ratio "
    "36.05 against its bootstrap-mapped threshold 35.22, p = 0.0004).",
    "- The issue's low-pass record (refine at 100 Hz × 4·10⁵, seed 3; the test inside refine): bootstrap offset "
    "−4.72698 → −4.72718, slope 1.95110 → 1.95114, the ratio 27.31833 → 27.31835, p 0.0231 → 0.0231; refine's CPU "
    "9.8 → 5.6 s; steps equal. refine's CPU A/B: bench_slowline_boot.md.",
    "",
]


def table() -> None:
    lines = ["# The slow-line test's bootstrap with analytic gradients (r18boot): before → after, record by record", ""]
    lines += [f"α of the test = {b.ALPHA:g}. before: main's library (a copy); after: this branch.", ""]
    lines += _part_lines("nulls_p", "Red-noise nulls, every p computed (r17slowboot's nulls_p records)")
    lines += _part_lines("power", "Power records, the test as refine runs it (r17slowboot's power records)")
    lines += _rescale_lines()
    lines += NOTES
    (OUT / "r18boot.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--label", default="after")
    ap.add_argument("--part", choices=("nulls_p", "power", "rescale", "table"), required=True)
    ap.add_argument("--only", default="", help="substrings of the records' keys to run (default all)")
    args = ap.parse_args(argv)
    if args.part == "table":
        table()
        return
    print("load", [round(v, 1) for v in os.getloadavg()], "library", sl.__file__, flush=True)
    run(args.label, args.part, [s for s in args.only.split(",") if s])


if __name__ == "__main__":
    main()
