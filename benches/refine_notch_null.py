#!/usr/bin/env python3
"""False alarms of the notch after the roll-off (``model/refinement/_notch.py``): clean filtered records with no
notch, refined with the default call — how many name a notch (the bandwidth's filter ``"<kind>+notch"``), with the
95 % Clopper–Pearson interval; beside it each record's effects found, to compare with a checkout without the notch
kind (``--json`` of both, then ``--compare``).

Records, each with a seed of its own: white rate noise with, in turn, rate random walk, bias instability or a
Gauss–Markov term, through one of five low-passes — a 2nd- or 4th-order Butterworth (``scipy.signal.butter``) at
0.1, 0.15 or 0.25·f_s, a single pole at 0.1·f_s, a 3-tap moving average, or a CIC's sinc³ read at its output rate
(three 8-tap boxcars at 8·f_s, decimated) — at 100, 400 or 1000 Hz, 10⁵, 3·10⁵ or 6·10⁵ samples.

Usage::

    python benches/refine_notch_null.py --records 120 --json /tmp/after.json    # ~2.5 min CPU
    python benches/refine_notch_null.py --compare /tmp/before.json /tmp/after.json
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
from scipy import signal

sys.path.insert(0, str(Path(__file__).resolve().parent))

import allanite
from _common import clopper_pearson

FILTERS = ("butterworth2", "butterworth4", "single_pole", "moving_average3", "sinc3")


def _record(seed: int):
    """(description, samples, f_s) of null record ``seed``."""
    rng = np.random.default_rng(7000 + seed)
    kind = FILTERS[seed % len(FILTERS)]
    fs = (100.0, 400.0, 1000.0)[seed % 3]
    n = (100_000, 300_000, 600_000)[seed // 3 % 3]
    rel = (0.1, 0.15, 0.25)[seed // 9 % 3]
    noise = [dict(N=2e-3, K=1e-5), dict(N=2e-3, B=4e-4), dict(N=2e-3, gauss_markov=[(4e-3, n / fs / 50)])][seed % 7 % 3]
    if kind == "sinc3":  # at 8·f_s, three 8-tap boxcars, every 8th sample kept
        y = allanite.simulate(8 * n, 8 * fs, seed=rng, **noise)
        for _ in range(3):
            y = signal.lfilter(np.full(8, 1 / 8), [1.0], y)
        return f"{kind} {fs:g} Hz × {n}", y[::8].copy(), fs
    y = allanite.simulate(n, fs, seed=rng, **noise)
    if kind.startswith("butterworth"):
        y = signal.lfilter(*signal.butter(int(kind[-1]), rel * fs, fs=fs), y)
        kind = f"{kind} {rel:g}·f_s"
    elif kind == "single_pole":
        pole = np.exp(-2 * np.pi * 0.1)
        y = signal.lfilter([1 - pole], [1.0, -pole], y)
    else:
        y = signal.lfilter(np.full(3, 1 / 3), [1.0], y)
    return f"{kind} {fs:g} Hz × {n}", y, fs


def _gate_counter() -> list:
    """Count the pairs the notch's spectral gate lets through to the curve (``_notch._dips``), where it exists."""
    seen = [0]
    try:
        from allanite.model.refinement import _notch
    except ImportError:  # a checkout without the notch kind
        return seen
    dips = _notch._dips

    def counted(*a, **k):
        out = dips(*a, **k)
        seen[0] += len(out)
        return out

    _notch._dips = counted
    return seen


def run(records: int) -> list:
    rows = []
    gate = _gate_counter()
    for seed in range(records):
        name, y, fs = _record(seed)
        t0 = time.process_time()
        gate[0] = 0
        r = allanite.refine(y, fs, progress=False)
        filters = [str(s.params.get("filter")) for s in r.steps if s.effect == "bandwidth"]
        rows.append(
            {
                "seed": seed,
                "record": name,
                "found": list(r.found),
                "filter": filters,
                "notch": any(f.endswith("+notch") for f in filters),
                "gate_pairs": gate[0],
                "cpu_s": time.process_time() - t0,
            }
        )
        print(json.dumps(rows[-1]), flush=True)
    return rows


def summary(rows: list) -> str:
    k, n = sum(r["notch"] for r in rows), len(rows)
    lo, hi = clopper_pearson(k, n)
    gated = sum(r.get("gate_pairs", 0) > 0 for r in rows)
    return (
        f"{k} of {n} records name a notch (95 % Clopper–Pearson {lo:.3f}–{hi:.3f}); "
        f"the spectral gate let pairs through to the curve in {gated}"
    )


def compare(before: list, after: list) -> list[str]:
    """The records whose effects found or bandwidth kinds differ between two runs."""
    out = []
    for b, a in zip(before, after):
        if b["found"] != a["found"] or b["filter"] != a["filter"]:
            out.append(f"{a['record']} (seed {a['seed']}): {b['found']} {b['filter']} → {a['found']} {a['filter']}")
    return out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--records", type=int, default=120)
    ap.add_argument("--json", type=Path, help="write the rows here")
    ap.add_argument("--compare", nargs=2, type=Path, help="two --json files: before, after")
    args = ap.parse_args(argv)
    if args.compare:
        before, after = (json.loads(p.read_text()) for p in args.compare)
        print(summary(before), "|", summary(after))
        diff = compare(before, after)
        print(f"{len(diff)} of {len(after)} records differ in effects or kinds", *diff, sep="\n")
        return
    rows = run(args.records)
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))
    print(summary(rows))


if __name__ == "__main__":
    main()
