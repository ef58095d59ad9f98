#!/usr/bin/env python3
"""Noise-level change points whose louder segments carry a noise outside the five terms (band noise switched on
and off): how often refine finds the change points and says nothing of a departure the louder segments alone
carry (``model/refinement/_segments.py``), on records unlike blind7's pump, and its false alarms on clean records.

One refine call per record gives both sides: the departures the change points take
(``evidence["explains"]`` on their steps) are exactly what ``unexplained`` said before that split, every step
and every other check being the same. So "before" is the call's ``unexplained`` plus those regions, "after" its
``unexplained``.

Cases (``--power K``, K seeds each; true change times found when one lies within 2 % of the record):

- ``double``: 50 Hz × 10⁶, N + B, the white level doubles at a random t0 in 30–70 % of the record (one change;
  the whole curve stays in the family: nothing to take);
- ``vib50``: 400 Hz × 1.2·10⁶, N + B + K, two bursts of band noise 50–80 Hz (3× the white PSD there) of 180 s;
- ``vib1k``: 4 kHz × 2.4·10⁶, N + B, two bursts of 100 Hz–1 kHz (≈ 3× the white PSD) of 60 s;
- ``guard``: ``double`` plus a band noise 10–20 Hz on the whole record (3× the white PSD): a departure the quiet
  segment carries too, which must stay said.

Nulls (``--null K``): K records per mixture of ``refine_false_alarms.record`` (its first K seeds of each of its
8 mixtures: white, flicker- and random-walk-dominated, quantised, 1 Hz with a channel, 2 kHz, two channels); a
record's alarm: any step or anything unexplained, before and after (Clopper–Pearson 95 %).

Usage::

    python benches/r14pump.py --power 10 --null 25      # -> benches/results/r14pump.{json,md}
    python benches/r14pump.py --power 2 --null 1 --out /tmp/x
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

import _common
import allanite
import refine_blind4 as rb4
import refine_false_alarms as rfa

HERE = Path(__file__).resolve().parent


def _bursts(rng, n_s: float, length_s: float, k: int) -> list:
    """``k`` non-overlapping stretches of ``length_s`` within (5 %, 95 %) of a record of ``n_s`` seconds."""
    while True:
        starts = np.sort(rng.uniform(0.05 * n_s, 0.95 * n_s - length_s, k))
        if k == 1 or np.min(np.diff(starts)) > 2 * length_s:
            return [(float(a), float(a + length_s)) for a in starts]


def build(case: str, seed: int):
    """(samples, fs, true change times) of one record of ``case``."""
    rng = np.random.default_rng(seed)
    if case in ("double", "guard"):
        fs, n, nw = 50.0, 1_000_000, 1e-3
        y = allanite.simulate(n, fs, N=nw, B=2e-4, seed=rng)
        i0 = int(rng.uniform(0.3, 0.7) * n)
        y[i0:] += np.sqrt(3.0) * nw * np.sqrt(fs) * rng.standard_normal(n - i0)  # white PSD ×4: ADEV ×2
        if case == "guard":
            y += rb4._band_noise(n, fs, rng, 10.0, 20.0, np.sqrt(3.0 * nw**2 * 10.0))
        return y, fs, [i0 / fs]
    if case == "vib50":
        fs, n, nw, band = 400.0, 1_200_000, 5e-3, (50.0, 80.0)
        y = allanite.simulate(n, fs, N=nw, B=1e-3, K=1e-5, seed=rng)
        on = _bursts(rng, n / fs, 180.0, 2)
    elif case == "vib1k":
        fs, n, nw, band = 4000.0, 2_400_000, 2e-3, (100.0, 1000.0)
        y = allanite.simulate(n, fs, N=nw, B=5e-4, seed=rng)
        on = _bursts(rng, n / fs, 60.0, 2)
    else:
        raise ValueError(f"case {case!r}: one of double, guard, vib50, vib1k")
    rms = np.sqrt(3.0 * nw**2 * (band[1] - band[0]))  # 3× the white PSD (one-sided N²) in the band
    b = rb4._band_noise(n, fs, rng, band[0], band[1], rms)
    t = np.arange(n) / fs
    mask = np.zeros(n, dtype=bool)
    for a, e in on:
        mask |= (t >= a) & (t < e)
    return y + np.where(mask, b, 0.0), fs, [s for ab in on for s in ab]


def _allan(regions) -> list:
    return [[float(r["tau"][0]), float(r["tau"][1]), r["what"]] for r in regions if r.get("domain") == "allan"]


def one(case: str, seed: int) -> dict:
    y, fs, truth = build(case, seed)
    t0 = time.perf_counter()
    r = allanite.refine(y, fs, progress=False)
    secs = time.perf_counter() - t0
    cps = [s for s in r.steps if s.effect == "change_point"]
    found_t = [float(s.params["t"]) for s in cps]
    dur = y.size / fs
    hit = sum(any(abs(t - f) <= 0.02 * dur for f in found_t) for t in truth)
    taken = cps[0].evidence.get("explains", []) if cps else []
    return {
        "case": case,
        "seed": seed,
        "truth_t": truth,
        "found_t": found_t,
        "hits": hit,
        "others": [s.effect for s in r.steps if s.effect != "change_point"],
        "allan_after": _allan(r.unexplained),
        "allan_before": _allan(list(r.unexplained) + list(taken)),
        "unexplained_after": [u["domain"] for u in r.unexplained],
        "largest_ratio": [s.evidence.get("adev_ratio", {}).get("largest") for s in cps],
        "seconds": secs,
    }


def null_one(mix: str, k: int) -> dict:
    y, fs, channels = rfa.record(mix, 10_000 + 1_000_003 * rfa.MIXES.index(mix) + 97 * k)
    r = allanite.refine(y, fs, channels=channels, progress=False)
    cps = [s for s in r.steps if s.effect == "change_point"]
    taken = cps[0].evidence.get("explains", []) if cps else []
    return {
        "mix": mix,
        "k": k,
        "after": bool(r.steps or r.unexplained),
        "before": bool(r.steps or r.unexplained or taken),
        "found": list(r.found),
        "unexplained": [u["domain"] for u in r.unexplained],
    }


def _power_md(rows: list) -> list:
    lines = [
        "| case | records | true times found | records with every change found | an Allan departure said before → after | other steps | mean s |",
        "|---|---|---|---|---|---|---|",
    ]
    for case in dict.fromkeys(r["case"] for r in rows):
        rs = [r for r in rows if r["case"] == case]
        found = sum(r["hits"] for r in rs)
        n_true = sum(len(r["truth_t"]) for r in rs)
        every = sum(r["hits"] == len(r["truth_t"]) and len(r["found_t"]) == len(r["truth_t"]) for r in rs)
        before = sum(bool(r["allan_before"]) for r in rs)
        after = sum(bool(r["allan_after"]) for r in rs)
        others = sum(bool(r["others"]) for r in rs)
        secs = np.mean([r["seconds"] for r in rs])
        lines.append(
            f"| {case} | {len(rs)} | {found} of {n_true} | {every} | {before} → {after} | {others} | {secs:.1f} |"
        )
    return lines


def _null_md(rows: list) -> list:
    n = len(rows)
    lines = ["| alarms | records | with an alarm | rate | 95 % CP |", "|---|---|---|---|---|"]
    for side in ("before", "after"):
        k = sum(r[side] for r in rows)
        lo, hi = _common.clopper_pearson(k, n)
        lines.append(f"| {side} | {n} | {k} | {100 * k / n:.1f} % | {100 * lo:.1f}–{100 * hi:.1f} % |")
    return lines


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--power", type=int, default=10, help="seeds per case")
    ap.add_argument("--null", type=int, default=25, help="records per null mixture")
    ap.add_argument("--cases", nargs="*", default=["double", "vib50", "vib1k", "guard"])
    ap.add_argument("--out", type=Path, default=HERE / "results")
    args = ap.parse_args(argv)
    load = _common.OtherLoad().__enter__()
    t_all = time.perf_counter()
    power = []
    for case in args.cases:
        for seed in range(args.power):
            power.append(one(case, 7100 + seed))
            print(json.dumps(power[-1], default=str), flush=True)
    nulls = []
    for mix in rfa.MIXES:
        for k in range(args.null if mix != "issue16" else args.null * 2 // 3):
            nulls.append(null_one(mix, k))
            print(json.dumps(nulls[-1]), flush=True)
    load.__exit__(None, None, None)
    report = {"power": power, "null": nulls, "other_load": load.fraction, "seconds": time.perf_counter() - t_all}
    report["machine"] = _common.machine_info()
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "r14pump.json").write_text(json.dumps(report, indent=1, default=str))
    md = ["# Band noise switched on and off: change points and the departures their louder segments carry", ""]
    md += ["Written by `benches/r14pump.py` (its docstring says what each case is and how before/after are read).", ""]
    md += _power_md(power) + [""] + _null_md(nulls) if nulls else _power_md(power)
    md += ["", f"Other processes used {100 * (load.fraction or 0):.0f} % of the CPUs during the run."]
    (args.out / "r14pump.md").write_text("\n".join(md) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
