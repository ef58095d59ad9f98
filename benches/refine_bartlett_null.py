#!/usr/bin/env python3
"""The default call on clean quantised moving-average and Bartlett sensors (r18bartlett): white, flicker and
(on half the records) rate random walk through a moving average of L taps or a Bartlett (two cascaded L-tap
averages: 2L − 1 taps) run at the output rate, then quantised at the output, nothing else — the commonest MEMS
output stage (the ADIS16405's). ``refine(y, fs)`` with default arguments. An alarm: any effect other than the
bandwidth, or ``unexplained`` non-empty. Also: whether the bandwidth is named, its kind (the filter's own, or
the sinc^k of the same process: a moving average is a boxcar/sinc¹, a Bartlett a sinc²), and its −3 dB cutoff
within 20 % of the filter's. Counts with 95 % Clopper–Pearson bounds.

Records (fixed seeds 18 000 + i, nothing tuned to one): rate f_s log-uniform 50 Hz – 2 kHz, length log-uniform
10⁵ – 10⁶ samples, L 2–16 (moving average) or 2–8 (Bartlett), quantum log-uniform 0.1 – 3 × the white noise's
per-sample SD at the filter's output (√(Σh²) of the input's: a part's LSB is set against the noise it outputs), a bias of a random fraction of the quantum (the quantiser's offset), flicker
0.03 – 0.3 × N, rate random walk on every other record.

Usage::

    python benches/refine_bartlett_null.py [--records 40] [--only 3,7] [--tag before]
    # -> benches/results/refine_bartlett_null.md/.json (with --tag: refine_bartlett_null_<tag>.json only)
    python benches/refine_bartlett_null.py --table   # the .md again, with a run tagged "before" beside it
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np
from scipy import signal

sys.path.insert(0, str(Path(__file__).resolve().parent))

import _common  # noqa: E402
import allanite  # noqa: E402
import refine_blind as rb  # noqa: E402
from allanite.model import effects  # noqa: E402

OUT = Path(__file__).resolve().parent / "results"
#: Kinds a named bandwidth may carry and still be the filter's own process (moving average = boxcar = sinc¹).
SAME = {"moving_average": ("moving_average", "boxcar"), "bartlett": ("bartlett", "sinc2")}


def record(i: int):
    """Record ``i``: (description dict, samples, f_s)."""
    rng = np.random.default_rng(18_000 + i)
    kind = "moving_average" if i % 2 == 0 else "bartlett"
    taps = int(rng.integers(2, 17)) if kind == "moving_average" else int(rng.integers(2, 9))
    fs = float(10 ** rng.uniform(math.log10(50.0), math.log10(2000.0)))
    n = int(10 ** rng.uniform(5.0, 6.0))
    quantum = float(10 ** rng.uniform(-1.0, math.log10(3.0)))
    n_white = 10 ** rng.uniform(-3.5, -2.5)
    x = rb.noise(
        n + 64,
        fs,
        rng,
        N=n_white,
        B=n_white * 10 ** rng.uniform(-1.5, -0.5),
        K=n_white * 10 ** rng.uniform(-3.0, -2.0) if (i // 2) % 2 else 0.0,
    )
    box = np.full(taps, 1.0 / taps)
    h = box if kind == "moving_average" else np.convolve(box, box)
    step = quantum * n_white * math.sqrt(fs * float(h @ h))  # the quantum over the output's white SD
    y = signal.lfilter(h, [1.0], x)[64:] + rng.uniform(-10.0, 10.0) * step
    y = np.round(y / step) * step
    cutoff = effects.filter_cutoff(kind, float(taps), fs)
    desc = {"record": i, "kind": kind, "L": taps, "fs": fs, "n": n, "quantum": quantum, "cutoff": cutoff}
    return desc, y, fs


def judge(desc: dict, r) -> dict:
    bw = next((s for s in r.steps if s.effect == "bandwidth"), None)
    got = {
        "found": list(r.found),
        "unexplained": [u.get("what", "") for u in r.unexplained],
        "alarm": any(e != "bandwidth" for e in r.found) or bool(r.unexplained),
        "named": bw is not None,
    }
    if bw is not None:
        kind = str(bw.params.get("filter"))
        got |= {
            "filter": kind,
            "taps": bw.params.get("taps"),
            "cutoff_found": float(bw.params["cutoff"]),
            "floor": bw.params.get("floor"),
            "kind_right": kind in SAME[desc["kind"]],
            "cutoff_right": abs(float(bw.params["cutoff"]) / desc["cutoff"] - 1.0) <= 0.2,
        }
    return got


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--records", type=int, default=40)
    ap.add_argument("--only", default="", help="comma-separated record numbers")
    ap.add_argument("--tag", default="", help="write results/refine_bartlett_null_<tag>.json only")
    ap.add_argument(
        "--table",
        action="store_true",
        help="only write the .md from results/refine_bartlett_null.json (and _before.json beside it, if there)",
    )
    args = ap.parse_args(argv)
    if args.table:
        before = OUT / "refine_bartlett_null_before.json"
        write_md(
            json.loads((OUT / "refine_bartlett_null.json").read_text()),
            json.loads(before.read_text()) if before.exists() else None,
        )
        return
    which = [int(s) for s in args.only.split(",") if s] or list(range(args.records))
    rows = []
    t0 = time.time()
    with _common.OtherLoad() as load:
        for i in which:
            desc, y, fs = record(i)
            r = allanite.refine(y, fs, progress=False)
            rows.append(desc | judge(desc, r))
            print(json.dumps(rows[-1]), flush=True)
    res = {"records": rows, "load_fraction": load.fraction or 0.0, "seconds": time.time() - t0}
    name = f"refine_bartlett_null_{args.tag}.json" if args.tag else "refine_bartlett_null.json"
    (OUT / name).write_text(json.dumps(res, indent=1))
    if not args.tag:
        write_md(res)


def _rate(k: int, n: int) -> str:
    lo, hi = _common.clopper_pearson(k, n)
    return f"{k} of {n} ({100 * lo:.1f}–{100 * hi:.1f} %)"


def write_md(res: dict, before: dict | None = None) -> None:
    runs = [("after", res)] + ([("before", before)] if before else [])
    md = [
        "# The default call on clean quantised moving-average / Bartlett sensors",
        "",
        f"`python benches/refine_bartlett_null.py --records {len(res['records'])}` (other processes "
        f"{100 * res['load_fraction']:.0f} % of the CPUs; {res['seconds']:.0f} s)"
        + (
            f"; before: the same records at main's library (other processes {100 * before['load_fraction']:.0f} %)"
            if before
            else ""
        )
        + ". An alarm: any effect other than "
        "the bandwidth, or `unexplained` non-empty; kind right: the filter's own or the sinc^k of the same process; "
        "cutoff within 20 %. 95 % Clopper–Pearson bounds.",
        "",
        "| run | filter | records | alarms | bandwidth named | kind right | cutoff within 20 % |",
        "|---|---|---|---|---|---|---|",
    ]
    for label, run in runs:
        for kind in ("moving_average", "bartlett", "all"):
            sel = [r for r in run["records"] if kind == "all" or r["kind"] == kind]
            n = len(sel)
            cells = [
                _rate(sum(bool(r.get(k)) for r in sel), n) for k in ("alarm", "named", "kind_right", "cutoff_right")
            ]
            md.append(f"| {label} | {kind} | {n} | " + " | ".join(cells) + " |")
    md += ["", "Records (after): alarms and misnamed kinds", ""]
    for r in res["records"]:
        if r["alarm"] or not r.get("kind_right") or not r.get("cutoff_right"):
            md.append(
                f"- {r['record']} {r['kind']} L={r['L']} fs={r['fs']:.0f} Hz n={r['n']} quantum {r['quantum']:.2f}σ: "
                f"found {r['found']} ({r.get('filter')}, cutoff {r.get('cutoff_found', float('nan')):.3g} Hz of "
                f"{r['cutoff']:.3g}); unexplained {r['unexplained']}"
            )
    md += ["", *NOTES]
    (OUT / "refine_bartlett_null.md").write_text("\n".join(md) + "\n")


#: What the recorded run shows (kept true to benches/results/refine_bartlett_null.json).
NOTES: list = [
    "Reading (r18bartlett; after at 817b141 in two processes, even and odd records, before at main's db0a328; other "
    "processes used ~95 % of the CPUs, load 13–28 on 2 cores): alarms 16 of 40 → 3 of 40, the kind right 26 → 35, "
    "the cutoff within 20 % 38 → 40. Before, the quantised output's floor was missing or wrong and a resonance, a "
    "Gauss–Markov term, a sinc⁵ or a Butterworth stood in for it; what changed: (1) the floor after the filter is the "
    "quantisation error's exact Allan variance (allanite.model._quantiser: correlated from sample to sample where the "
    "step is coarse beside the filtered rate's change), (2) where the floor is the lattice's (Δ/√(12·f_s) within 1.5 of "
    "the spectrum's), it is weighed against what the filter passes at the shortest τ and the kinds whose floor agrees "
    "compete, a Butterworth too. Left: 11 (step 2.5 output SDs: the error then correlates with the rate itself, no "
    "additive floor describes it; read as a Butterworth with the curve departing), 17 (a Gauss–Markov term beside a "
    "sinc⁵ at a fine step, 0.28 σ: the floor gate is not entered; not traced) and 22 (a resonance beside a 7-tap "
    "average at 0.38 σ, 9·10⁵ samples: not traced). Kinds still not the filter's own: sinc⁵ for three Bartletts "
    "(cutoff within 3 %), Butterworth 2 for two at steps of 2.4–2.5 σ.",
    "Rerun at da6740f (2026-11-28, every r18 branch merged — r18sharp's sharp kinds beside this floor; other processes 87 % of the CPUs, 702 s): every record's alarm, found effects, kind and cutoff verdict as above (3 of 40 alarms, 35 of 40 kinds right); the recorded JSON is the branch's run.",
]


if __name__ == "__main__":
    main()
