#!/usr/bin/env python3
"""Clean noise plus one fixed spectral line: does the default ``refine`` add anything beyond the sinusoid?

16 seeded records: fs 100, 7.3, 400 and 1 Hz (2·10⁵, 10⁵, 4·10⁵, 5·10⁴ samples) × noise N, N + B, N + K,
N + B + K (N 2·10⁻³, B 3·10⁻⁴, K 2·10⁻⁵ in the rate unit), each with one line of fixed amplitude and phase at a
random f0 in [200/T, 0.4·fs], 2–8× the white noise's σ per sample. Anything found other than the sinusoid, and
anything ``unexplained`` says, is a false alarm; the last step's χ²/dof (on the tests' covariance) is recorded.
The check behind :func:`allanite.model.refinement.calibrated.curve_test`'s line cross term (a strong fixed line
had its Allan variance treated as noise: the estimates' covariance scaled by model/terms). Nothing tuned.

Usage::

    python benches/line_false_alarms.py                          # -> benches/results/line_false_alarms.{json,md}
    python benches/line_false_alarms.py --out /tmp/la --before benches/results/line_false_alarms_main.json
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

import allanite

HERE = Path(__file__).resolve().parent
RATES = ((100.0, 200_000), (7.3, 100_000), (400.0, 400_000), (1.0, 50_000))
N_WHITE = 2e-3
NOISES = ({"N": N_WHITE}, {"N": N_WHITE, "B": 3e-4}, {"N": N_WHITE, "K": 2e-5}, {"N": N_WHITE, "B": 3e-4, "K": 2e-5})


def record(i: int) -> dict:
    rng = np.random.default_rng(1000 + i)
    fs, n = RATES[i % 4]
    kw = NOISES[(i // 4) % 4]
    y = allanite.simulate(n, fs, seed=int(rng.integers(2**31)), **kw)
    f0 = float(rng.uniform(200 * fs / n, 0.4 * fs))
    snr = float(rng.uniform(2, 8))
    y = y + snr * N_WHITE * np.sqrt(fs) * np.sin(2 * np.pi * f0 * np.arange(n) / fs + rng.uniform(0, 6.28))
    r = allanite.refine(y, fs, unit="deg/s", progress=False)
    extra = [e for e in r.found if e != "sinusoid"] + [u["domain"] for u in r.unexplained]
    return {
        "i": i,
        "fs": fs,
        "n": n,
        "noise": "+".join(kw),
        "f0": f0,
        "snr": snr,
        "found": r.found,
        "unexplained": [u["domain"] for u in r.unexplained],
        "chi2_dof": r.steps[-1].after["chi2_dof"] if r.steps else None,
        "alarm": bool(extra),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=HERE / "results")
    ap.add_argument("--before", type=Path, default=None, help="a JSON of this bench on the code before, beside")
    args = ap.parse_args()
    rows = []
    for i in range(16):
        rows.append(record(i))
        print(rows[-1], flush=True)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "line_false_alarms.json").write_text(json.dumps(rows, indent=1))
    before = {r["i"]: r for r in json.loads(args.before.read_text())} if args.before else {}

    def cell(r):
        said = ", ".join(r["found"] + [f"unexplained: {u}" for u in r["unexplained"]])
        chi2 = "—" if r["chi2_dof"] is None else f"{r['chi2_dof']:.2f}"
        return f"{said} | {chi2} | {'alarm' if r['alarm'] else 'ok'}"

    head = "| # | fs, samples | noise | f0 (Hz) | line/σ | found | χ²/dof | |"
    if before:
        head += " before: found | χ²/dof | |"
    lines = [
        "# Clean noise + one fixed line: false alarms",
        "",
        "`python benches/line_false_alarms.py` (16 seeded records; see the script's docstring).",
        "",
        head,
        "|" + "---|" * (head.count("|") - 1),
    ]
    for r in rows:
        s = f"| {r['i']} | {r['fs']:g} Hz × {r['n']} | {r['noise']} | {r['f0']:.4g} | {r['snr']:.1f} | {cell(r)} |"
        if r["i"] in before:
            s += f" {cell(before[r['i']])} |"
        lines.append(s)
    alarms = sum(r["alarm"] for r in rows)
    tail = f"\nFalse alarms: **{alarms} of {len(rows)}**"
    if before:
        tail += f" (before: {sum(r['alarm'] for r in before.values())} of {len(before)})"
    (args.out / "line_false_alarms.md").write_text("\n".join(lines) + "\n" + tail + ".\n")
    print("wrote", args.out / "line_false_alarms.md")


if __name__ == "__main__":
    main()
