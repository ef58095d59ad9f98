#!/usr/bin/env python3
"""``allanite.refine(..., gaps="skip")`` on records with dropped samples: does filling the gaps add effects a clean
record does not have, and does a record with a sinusoid still give it?

Null: clean records (terms of the starting model only: ``white`` N; ``with_K`` N + K; ``flicker`` N + B + K) of
2^15 samples at 100 Hz, 1 % of the samples dropped in 20 equal gaps at seeded places. A false alarm is anything
added or flagged as unexplained; the same records without gaps, refined as they are, give the rate before the fill
(paired seeds). Power: N 0.01 (a per-sample σ of 0.1) + a sinusoid of amplitude 0.02 at 2.3 Hz, with the same gaps:
found, and its amplitude and f0 within 20 %?

Usage::

    python benches/refine_gaps.py            # -> benches/results/refine_gaps.{json,md}
    python benches/refine_gaps.py --quick    # 2 records per mixture, to a temporary folder
    python benches/refine_gaps.py --frac 0.05 --per-mix 7 --sines 0   # at refine's limit: refine_gaps_5pct.*
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import _common
import allanite

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))
from sensors import dropped  # noqa: E402  (the tests' simulation helpers, as refine_blind.py reads them)

FS = 100.0
SIZE = 2**15
MIXES = {"white": {"N": 0.01}, "with_K": {"N": 0.01, "K": 2e-3}, "flicker": {"N": 0.01, "B": 3e-3, "K": 5e-4}}
SINE = (0.02, 2.3)


def alarm(r) -> list[str]:
    return list(r.found) + [f"unexplained:{u['domain']}" for u in r.unexplained]


def run(per_mix: int, n_sine: int, out: Path, frac: float = 0.01) -> dict:
    rows, t0 = [], time.time()
    for mix, terms in MIXES.items():
        for seed in range(per_mix):
            y = allanite.simulate(SIZE, FS, seed=seed, **terms)
            z = dropped(y, 10_000 + seed, frac=frac)
            g = allanite.refine(z, FS, gaps="skip", progress=False)
            f = allanite.refine(y, FS, progress=False)
            rows.append(
                {
                    "mix": mix,
                    "seed": seed,
                    "gapped": alarm(g),
                    "full": alarm(f),
                    "change_pct": g.filled["curve_change_pct"],
                }
            )
    sines = []
    for seed in range(n_sine):
        y = allanite.simulate(SIZE, FS, N=0.01, sinusoid=[SINE], seed=500 + seed)
        r = allanite.refine(dropped(y, 20_000 + seed, frac=frac), FS, gaps="skip", progress=False)
        st = next((s for s in r.steps if s.effect == "sinusoid"), None)
        err = None if st is None else {k: st.params[k] / v - 1 for k, v in (("amplitude", SINE[0]), ("f0", SINE[1]))}
        sines.append({"seed": seed, "found": st is not None, "errors": err, "all": alarm(r)})
    k_g = sum(bool(r["gapped"]) for r in rows)
    k_f = sum(bool(r["full"]) for r in rows)
    ok = sum(s["found"] and max(abs(v) for v in s["errors"].values()) <= 0.2 for s in sines)
    res = {
        "null": rows,
        "null_gapped": [k_g, len(rows), _common.clopper_pearson(k_g, len(rows))],
        "null_full": [k_f, len(rows), _common.clopper_pearson(k_f, len(rows))],
        "sinusoid": sines,
        "sinusoid_within_20pct": [ok, len(sines)],
        "seconds": time.time() - t0,
        "machine": _common.machine_info(),
        "frac": frac,
    }
    _common.write_results(out, "refine_gaps" if frac == 0.01 else f"refine_gaps_{100 * frac:g}pct", page(res), res)
    return res


def page(res: dict) -> list[str]:
    k_g, n, (lo_g, hi_g) = res["null_gapped"]
    k_f, _n, (lo_f, hi_f) = res["null_full"]
    ch = [r["change_pct"] for r in res["null"]]
    worst = max(
        (max(abs(v) for v in s["errors"].values()) for s in res["sinusoid"] if s["errors"]), default=float("nan")
    )
    lines = [
        "# refine on records with dropped samples (gaps='skip')",
        "",
        f"Clean records of {SIZE} samples at {FS:g} Hz ({', '.join(MIXES)}), {100 * res['frac']:g} % dropped in 20 "
        "gaps, filled by "
        "refine(gaps='skip'); the same records without gaps for comparison. Alarm: anything added or unexplained.",
        "",
        "| records | alarms with gaps (filled) | 95 % CP | alarms without gaps | 95 % CP |",
        "|---|---|---|---|---|",
        f"| {n} | {k_g} | {100 * lo_g:.1f}–{100 * hi_g:.1f} % | {k_f} | {100 * lo_f:.1f}–{100 * hi_f:.1f} % |",
        "",
        f"The fill moved the Allan curve by {np.median(ch):.2g} % (median; largest {max(ch):.2g} %) from the curve "
        "that skips the gaps, at the τ where that keeps ≥ 90 % of the terms.",
        "",
    ]
    for r in res["null"]:
        if r["gapped"] or r["full"]:
            lines.append(f"- {r['mix']} seed {r['seed']}: with gaps {r['gapped'] or '—'}, without {r['full'] or '—'}")
    ok, m = res["sinusoid_within_20pct"]
    if m:
        lines += [
            "",
            f"Sinusoid (A {SINE[0]:g}, f0 {SINE[1]:g} Hz, on N 0.01) with the same gaps: found with amplitude and f0 "
            f"within 20 % in {ok} of {m} records (largest error {100 * worst:.2g} %).",
        ]
    lines += [
        "",
        _common.machine_line(res["machine"]) + f"; {res['seconds']:.0f} s.",
    ]
    return lines


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--per-mix", type=int, default=20)
    ap.add_argument("--sines", type=int, default=10)
    ap.add_argument("--frac", type=float, default=0.01, help="share of the samples dropped (in 20 gaps)")
    a = ap.parse_args(argv)
    out = Path(tempfile.mkdtemp()) if a.quick else HERE / "results"
    res = run(2 if a.quick else a.per_mix, 2 if a.quick else a.sines, out, a.frac)
    print("\n".join(page(res)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
