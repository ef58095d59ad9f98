#!/usr/bin/env python3
"""False alarms with a declared filter (``refine(..., filter=...)``, r17taps): clean records — white, flicker and
rate random walk through a known digital filter, nothing else — refined with the filter declared and with the
default call. An alarm: any effect other than the bandwidth added, or ``unexplained`` non-empty. Counts with
95 % Clopper–Pearson bounds.

The records (fixed seeds, ``--records`` of them, cycling through four sensors unlike the ADIS16405): a remez FIR
decimator (2 kHz → 500 Hz, 63 taps, 0.2 dB ripple), an elliptic IIR at 200 Hz (order 4, 1 dB ripple), a Chebyshev
I IIR at 1 kHz decimated by 4 to 250 Hz (order 3, 0.5 dB), and a Bartlett (two cascaded 4-tap averages) at 100 Hz
quantised at the output; 2·10⁵ output samples each, noise levels drawn per record.

Usage::

    python benches/refine_declared_null.py [--records 40]   # -> benches/results/refine_declared_null.md/.json
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

import _common  # noqa: E402
import allanite  # noqa: E402
import refine_blind as rb  # noqa: E402

OUT = Path(__file__).resolve().parent / "results"
N_OUT = 200_000


def _bartlett():
    box = np.full(4, 0.25)
    return np.convolve(box, box), np.array([1.0])


#: (name, (b, a) maker, rate the filter runs at Hz, decimation, output quantum over the per-sample σ or 0)
SENSORS = [
    (
        "remez FIR 2 kHz → 500 Hz",
        lambda: (signal.remez(63, [0, 150, 230, 1000], [1, 0], fs=2000.0), np.ones(1)),
        2000.0,
        4,
        0.0,
    ),
    ("elliptic IIR at 200 Hz", lambda: signal.ellip(4, 1.0, 40.0, 30.0, fs=200.0), 200.0, 1, 0.0),
    ("Chebyshev I 1 kHz → 250 Hz", lambda: signal.cheby1(3, 0.5, 90.0, fs=1000.0), 1000.0, 4, 0.0),
    ("Bartlett 7 taps at 100 Hz, quantised", _bartlett, 100.0, 1, 0.5),
]


def record(i: int):
    """Record ``i``: its sensor, samples, output rate and declared filter."""
    name, make, rate, dec, quantum = SENSORS[i % len(SENSORS)]
    rng = np.random.default_rng(17_000 + i)
    b, a = make()
    n_white = 10 ** rng.uniform(-3.5, -2.5)
    x = rb.noise(
        N_OUT * dec + 2000,
        rate,
        rng,
        N=n_white,
        B=n_white * 10 ** rng.uniform(-1.5, -0.5),
        K=n_white * 10 ** rng.uniform(-3.0, -2.0),
    )
    y = signal.lfilter(b, a, x)[2000::dec][:N_OUT]
    if quantum:
        step = quantum * n_white * np.sqrt(rate)
        y = np.round(y / step) * step
    return name, y, rate / dec, {"b": b, "a": a, "rate": rate}


def alarm(r) -> bool:
    return any(e != "bandwidth" for e in r.found) or bool(r.unexplained)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--records", type=int, default=40)
    args = ap.parse_args(argv)
    rows = []
    t0 = time.time()
    with _common.OtherLoad() as load:
        for i in range(args.records):
            name, y, fs, spec = record(i)
            row = {"record": i, "sensor": name}
            for label, kw in (("declared", {"filter": spec}), ("default", {})):
                r = allanite.refine(y, fs, progress=False, **kw)
                row[label] = {
                    "found": list(r.found),
                    "unexplained": [u.get("what", "") for u in r.unexplained],
                    "alarm": alarm(r),
                }
            rows.append(row)
            print(i, name, row["declared"], row["default"]["alarm"], row["default"]["found"], flush=True)
    res = {"records": rows, "load_fraction": load.fraction or 0.0, "seconds": time.time() - t0}
    (OUT / "refine_declared_null.json").write_text(json.dumps(res, indent=1))
    write_md(res)


def write_md(res: dict) -> None:
    rows = res["records"]
    n = len(rows)
    md = [
        "# False alarms with a declared filter (`refine(..., filter=...)`)",
        "",
        f"`python benches/refine_declared_null.py --records {n}` (other processes {100 * res['load_fraction']:.0f} % of "
        f"the CPUs; {res['seconds']:.0f} s). Clean records through a known filter; an alarm is any effect other than "
        "the bandwidth, or `unexplained` non-empty. 95 % Clopper–Pearson bounds.",
        "",
        "| sensor | records | declared: alarms | default call: alarms |",
        "|---|---|---|---|",
    ]
    for name, *_rest in SENSORS + [("all", None, None, None, None)]:
        sel = [r for r in rows if name == "all" or r["sensor"] == name]
        if not sel:
            continue
        cells = []
        for label in ("declared", "default"):
            k = sum(r[label]["alarm"] for r in sel)
            lo, hi = _common.clopper_pearson(k, len(sel))
            cells.append(f"{k} of {len(sel)} ({100 * lo:.1f}–{100 * hi:.1f} %)")
        md.append(f"| {name} | {len(sel)} | {cells[0]} | {cells[1]} |")
    md += ["", "Alarms (record: what was added or said):", ""]
    for r in rows:
        for label in ("declared", "default"):
            v = r[label]
            if v["alarm"]:
                md.append(f"- {r['record']} {r['sensor']}, {label}: found {v['found']}; unexplained {v['unexplained']}")
    md += ["", *NOTES]
    (OUT / "refine_declared_null.md").write_text("\n".join(md) + "\n")


#: What the recorded run shows (kept true to benches/results/refine_declared_null.json).
NOTES: list = [
    "Reading (the recorded run, at r18sharp f0a5218 — the sharp rippled bandwidth kinds in the default call; "
    "other helpers' runs used ~96 % of the CPUs): with the filter declared no record took anything beside the "
    "bandwidth and none said anything unexplained — 0 of 40 (95 % CP 0–8.8 %), as before. The default call alarms "
    "on 13 of 40 (18.6–49.1 %) where it alarmed on 28 of 40 (53.5–83.4 %) before the sharp kinds (78fec30–db0a328): "
    "the elliptic IIR 10 → 0 of 10, the remez FIR 5 → 1, the Chebyshev I decimated by 4 to 250 Hz 10 → 9 (its edge "
    "near the output's Nyquist: no Butterworth order agrees with its spectrum, so the sharp kinds are not searched "
    "— the gate of allanite.model.refinement._sharp), the quantised Bartlett 3 → 3 (the same records 7, 15, 39, "
    "whose kind is in the family). Stand-ins (a resonance or Gauss–Markov term added): 10 records → 2 (Chebyshev "
    "records 6 and 26). Later commits on the branch (a ripple near its range's ends marked at the edge; a sharp "
    "kind a notch's base only where chosen) were not rerun here.",
    "Rerun whole at da6740f (2026-11-28, every r18 branch merged: r18sharp's sharp kinds and r18bartlett's quantised output floor together; other processes 94 % of the CPUs): declared 0 of 40 as before; the default call alarms on **10 of 40** (12.7–41.2 %) — the elliptic 0 of 10 and the quantised Bartlett 0 of 10 (r18bartlett: its floor the quantiser's exact one; 3 of 10 at r18sharp's run, which had not that fix), the remez FIR 1 of 10, and the Chebyshev decimated by 4 still 9 of 10: its edge sits near the output's Nyquist, where no Butterworth order agrees with the spectrum, so the sharp kinds' gate stays closed and the curve is said to depart (honest; the taps declared pass). Before the r18 branches: 28 of 40.",
]


if __name__ == "__main__":
    main()
