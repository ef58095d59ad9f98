#!/usr/bin/env python3
"""The default call on clean records through sharp rippled digital filters it was not given (r18sharp): elliptic,
Chebyshev I and II IIRs and equiripple (remez) and Kaiser-window FIR decimators, at rates, cutoffs, orders, ripples,
decimations and lengths drawn per record — unlike the designs of ``benches/refine_declared_null.py`` and unlike the
sharp kinds' own fixed designs (:mod:`allanite.model._sharp`: an elliptic of order 4 or 6, 40 or 60 dB). White,
flicker and rate random walk noise through the filter, nothing else; some outputs quantised. An alarm: any effect
other than the bandwidth added, or ``unexplained`` non-empty; a stand-in: a resonance, Gauss–Markov term or
sinusoid added. Counts with 95 % Clopper–Pearson bounds; the kind the bandwidth step named, per record.

Usage::

    python benches/refine_sharp.py [--records 24] [--only 3 --only 7] [--out DIR]
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
FAMILIES = ("ellip", "cheby1", "cheby2", "remez", "kaiser")
STAND_INS = ("resonance", "gauss_markov", "sinusoid")


def _design(family: str, rng, rate: float, fc: float):
    """(b, a, words) of one filter of ``family`` at ``rate`` Hz with its passband edge at ``fc`` Hz."""
    if family in ("ellip", "cheby1", "cheby2"):
        order = int(rng.integers(3, 9))
        rp = float(np.round(10 ** rng.uniform(-1.0, 0.3), 2))  # 0.1–2 dB
        rs = float(np.round(rng.uniform(35.0, 80.0)))
        if family == "ellip":
            b, a = signal.ellip(order, rp, rs, fc, fs=rate)
            return b, a, f"elliptic order {order}, {rp} dB / {rs:.0f} dB"
        if family == "cheby1":
            b, a = signal.cheby1(order, rp, fc, fs=rate)
            return b, a, f"Chebyshev I order {order}, {rp} dB"
        b, a = signal.cheby2(order, rs, min(1.6 * fc, 0.49 * rate), fs=rate)
        return b, a, f"Chebyshev II order {order}, {rs:.0f} dB stop band"
    taps = int(rng.integers(24, 96)) | 1
    edge = min(fc * rng.uniform(1.3, 1.8), 0.49 * rate)
    if family == "remez":
        b = signal.remez(taps, [0, fc, edge, rate / 2.0], [1, 0], fs=rate)
        return b, np.ones(1), f"remez {taps} taps, {fc:.4g}/{edge:.4g} Hz"
    b = signal.firwin(taps, 0.5 * (fc + edge), window=("kaiser", float(rng.uniform(4.0, 9.0))), fs=rate)
    return b, np.ones(1), f"Kaiser FIR {taps} taps, {0.5 * (fc + edge):.4g} Hz"


def record(i: int):
    """Record ``i``: (words, samples, output rate Hz) — its filter, rate, cutoff, decimation and noise drawn from
    a seed of its own."""
    rng = np.random.default_rng(18_500 + i)
    family = FAMILIES[i % len(FAMILIES)]
    fs = float(rng.choice([50.0, 100.0, 200.0, 400.0, 1000.0, 3200.0]))
    dec = int(rng.choice([1, 1, 2, 4, 8]))
    rate = fs * dec
    fc = float(fs * rng.uniform(0.06, 0.38))  # the passband edge, below the output's Nyquist
    b, a, words = _design(family, rng, rate, fc)
    n_out = int(rng.choice([100_000, 200_000, 400_000]))
    n_white = 10 ** rng.uniform(-4.0, -2.0)
    x = rb.noise(
        n_out * dec + 4000,
        rate,
        rng,
        N=n_white,
        B=n_white * 10 ** rng.uniform(-1.5, -0.5),
        K=n_white * 10 ** rng.uniform(-3.0, -2.0),
    )
    y = signal.lfilter(b, a, x)[4000::dec][:n_out]
    quantised = rng.uniform() < 0.25
    if quantised:
        step = 0.5 * n_white * np.sqrt(fs)
        y = np.round(y / step) * step
    what = f"{words} at {rate:g} Hz" + (f" → {fs:g} Hz" if dec > 1 else "") + f", {n_out} samples"
    return what + (", quantised" if quantised else ""), y, fs


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--records", type=int, default=24)
    ap.add_argument("--only", type=int, action="append", help="record number (repeatable)")
    ap.add_argument("--out", type=Path, default=OUT)
    args = ap.parse_args(argv)
    rows = []
    t0 = time.time()
    with _common.OtherLoad() as load:
        for i in args.only or range(args.records):
            what, y, fs = record(i)
            r = allanite.refine(y, fs, progress=False)
            bw = next((s.final_params or s.params for s in r.steps if s.effect == "bandwidth"), {})
            row = {
                "record": i,
                "filter": what,
                "found": list(r.found),
                "unexplained": [u.get("what", "") for u in r.unexplained],
                "kind": str(bw.get("filter", "")),
                "ripple": bw.get("ripple"),
                "alarm": any(e != "bandwidth" for e in r.found) or bool(r.unexplained),
                "stand_in": any(e in STAND_INS for e in r.found),
            }
            rows.append(row)
            print(i, what, row["kind"], row["ripple"], row["found"], row["unexplained"], flush=True)
    res = {"records": rows, "load_fraction": load.fraction or 0.0, "seconds": time.time() - t0}
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "refine_sharp.json").write_text(json.dumps(res, indent=1))
    write_md(res, args.out)


def write_md(res: dict, out: Path) -> None:
    rows = res["records"]
    n = len(rows)
    k_alarm = sum(r["alarm"] for r in rows)
    k_stand = sum(r["stand_in"] for r in rows)
    cp = [_common.clopper_pearson(k, n) for k in (k_alarm, k_stand)]
    md = [
        "# The default call on sharp rippled filters it was not given",
        "",
        f"`python benches/refine_sharp.py --records {n}` (other processes {100 * res['load_fraction']:.0f} % of the "
        f"CPUs; {res['seconds']:.0f} s). Clean records through a drawn filter; an alarm is any effect other than the "
        "bandwidth, or `unexplained` non-empty; a stand-in a resonance, Gauss–Markov term or sinusoid added.",
        "",
        f"Alarms: {k_alarm} of {n} ({100 * cp[0][0]:.1f}–{100 * cp[0][1]:.1f} %); stand-ins: {k_stand} of {n} "
        f"({100 * cp[1][0]:.1f}–{100 * cp[1][1]:.1f} %).",
        "",
        "| record | filter | kind named | ripple dB | found | unexplained |",
        "|---|---|---|---|---|---|",
    ]
    for r in rows:
        rip = "" if r["ripple"] is None else f"{r['ripple']:+.3g}"
        md.append(
            f"| {r['record']} | {r['filter']} | {r['kind']} | {rip} | {', '.join(r['found'])} | "
            f"{'; '.join(r['unexplained'])} |"
        )
    md += ["", *NOTES]
    (out / "refine_sharp.md").write_text("\n".join(md) + "\n")


#: What the recorded run shows (kept true to benches/results/refine_sharp.json).
NOTES: list = [
    "Reading (the recorded run at f0a5218, the sharp kinds' search gate and grids as committed; the same 24 records "
    "at main db0a328, before the sharp kinds, in brackets; other helpers' runs shared the 2 cores, load 15–28): "
    "alarms 12 of 24 (50 %, 95 % CP 29–71 %) [17 of 24, 49–87 %]; stand-ins 5 of 24 (7–42 %) [9 of 24, 19–59 %]. "
    "Named a sharp kind on 10 records, 6 of them now clean (records 5, 10, 11, 13, 15, 23: an elliptic of order 4 "
    "and 1.69 dB read +1.6 dB, order 3 and 0.35 dB −0.368, order 3 and 0.24 dB −0.234, a Chebyshev I of order 6 and "
    "0.17 dB +0.168 — the sign of the ripple is the order's parity —, two remez FIRs +0.0975 and +0.511), the "
    "stand-ins gone on 4 (0, 1, 5, 23; 0 and 1 still say the curve departs: an order-7 elliptic with a 35 dB stop "
    "band and an order-8 Chebyshev I, shapes the fixed designs hold only roughly). The Butterworth-like filters "
    "(Chebyshev II, Kaiser FIRs: 2, 7, 9, 12, 17, 19) keep their kind and verdict. Not reached (the gate stays "
    "closed: no Butterworth order agrees with their spectrum): records 6, 14, 20, 21 (boxcar or sinc² named, the "
    "curve departs) and the stand-ins of 4, 8, 18, 20, 22 — as before. Commits after f0a5218 (the ripple's "
    "interval; a ripple within two Brent steps of 0.05 or 3 dB marked at the edge; a sharp kind a notch's base "
    "only where chosen) leave every kind named here as it is (no named ripple lies near either end, no notch was "
    "named); the table was not rerun after them.",
]


if __name__ == "__main__":
    main()
