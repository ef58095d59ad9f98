#!/usr/bin/env python3
"""``allanite.refine`` on filtered, quantised white noise: the filter named, its white floor found, nothing invented.

A digital sensor quantises its rate output after its filter: a step Δ adds white rate noise of Δ²/12 per sample
(Allan variance Δ²·τ0/(12τ), floor = Δ·√(τ0/12) in N's units). Beside a Butterworth the bandwidth effect keeps
N's column as that floor (``floor``); beside a single pole or a moving average only where the spectrum above
f_s/4 shows a floor the fit agrees with (docs/refinement.md).
Cases: Butterworths of order 2–6 at f_s/5, a single pole at f_s/10, a 4-tap moving average, and no filter; at
f_s = 200, 1000 and 2000 Hz; quantised at none, ½ and 1 σ of the white noise before the filter (Δ = step·N·√f_s);
white noise N = 4·10⁻³ °/√s plus rate random walk K = 2·10⁻⁵, 4·10⁵ samples, one seed per case. Default call
``refine(y, fs)``.

Judged: the effects found are the bandwidth alone (nothing for no filter) — no resonance or other stand-in —,
its cutoff within 3 % and, for a Butterworth, its order. The floor found is reported beside the truth (not judged:
the Allan curve splits the white part between the floor and white angle noise loosely).

Usage::

    python benches/refine_white_floor.py            # -> benches/results/refine_white_floor.{json,md}
    python benches/refine_white_floor.py --quick    # the 2 kHz cases only, to a temporary folder
"""

from __future__ import annotations

import argparse
import math
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy import signal

import _common
import allanite
from allanite.model.effects import filter_cutoff

HERE = Path(__file__).resolve().parent
N, K, SAMPLES = 4e-3, 2e-5, 400_000
FILTERS = ("butterworth2", "butterworth3", "butterworth4", "butterworth5", "butterworth6", "single_pole", "ma4", "none")
RATES = (200.0, 1000.0, 2000.0)
STEPS = (0.0, 0.5, 1.0)


def truth(filt: str, fs: float) -> tuple[str | None, float | None]:
    """(kind refine should name, its −3 dB cutoff in Hz) of a case's filter."""
    if filt.startswith("butterworth"):
        return filt, 0.2 * fs
    if filt == "single_pole":
        return filt, 0.1 * fs
    if filt == "ma4":
        return "moving_average", filter_cutoff("moving_average", 4, fs)
    return None, None


def record(filt: str, fs: float, step: float, seed: int) -> np.ndarray:
    """White noise plus rate random walk through ``filt``, rounded to ``step`` white-noise σ."""
    rng = np.random.default_rng(seed)
    y = allanite.simulate(SAMPLES, fs, N=N, K=K, seed=rng)
    if filt.startswith("butterworth"):
        y = signal.sosfilt(signal.butter(int(filt[-1]), 0.2 * fs, fs=fs, output="sos"), y)
    elif filt == "single_pole":
        a = math.exp(-2.0 * math.pi * 0.1)
        y = signal.lfilter([1.0 - a], [1.0, -a], y)
    elif filt == "ma4":
        y = signal.lfilter(np.full(4, 0.25), [1.0], y)
    if step:
        lsb = step * N * math.sqrt(fs)
        y = np.round(y / lsb) * lsb
    return y


def run_case(filt: str, fs: float, step: float, seed: int) -> dict:
    """One case: refine's answer and its verdict."""
    y = record(filt, fs, step, seed)
    t0 = time.process_time()
    r = allanite.refine(y, fs)
    cpu = time.process_time() - t0
    kind, cut = truth(filt, fs)
    bw = [s for s in r.steps if s.effect == "bandwidth"]
    p = (bw[0].final_params or bw[0].params) if bw else {}
    named = str(p.get("filter", "")) or None
    cut_err = p["cutoff"] / cut - 1.0 if bw and cut else None
    others = [s.effect for s in r.steps if s.effect != "bandwidth"]
    ok_kind = named == kind if kind is None or kind.startswith("butterworth") else named is not None
    passed = (not others) and ok_kind and (cut_err is None or abs(cut_err) <= 0.03) and (bool(bw) == (kind is not None))
    return {
        "filter": filt,
        "fs": fs,
        "step": step,
        "seed": seed,
        "named": named,
        "cutoff": p.get("cutoff"),
        "cutoff_error": cut_err,
        "floor": p.get("floor"),
        "floor_true": step * N / math.sqrt(12.0),
        "others": others,
        "chi2_dof": r.fit.chi2_dof,
        "unexplained": len(r.unexplained),
        "passed": bool(passed),
        "cpu_seconds": cpu,
    }


def _pct(x) -> str:
    return "—" if x is None else f"{100 * x:+.1f} %"


def _floor(x) -> str:
    return "—" if x is None else f"{x:.2e}"


#: What the table shows (kept true to the recorded run).
NOTES = [
    "The same 72 records at main before the floor (7a5967f, this script run against it): 52 of 72. With the floor "
    "beside a Butterworth: no Butterworth record gains a stand-in (main: a resonance on the quantised 3rd order at "
    "200 Hz and the 4th at 1 kHz), 5 unexplained regions over the 45 Butterworth records (main 9), the order right "
    "in 38 of 45 (main 36; the spectrum above f_s/4 now prefers the 5th and 6th orders with their floor where main "
    "read the 4th plus white angle noise, but takes the 6th for the 5th at ½ σ at 1 and 2 kHz, which main had "
    "right), cutoffs within 3 % throughout (median |error| 0.70 %, main 0.61 %), χ²/dof median 0.63 on the "
    "quantised ones (main 0.63).",
    "",
    "The floor on the Allan curve: within 20 % of the truth in 9 of the 30 quantised Butterworth records, 0 in 14 "
    "— white angle noise (Q) took the white part there, the two being nearly one column at the shortest τ. The "
    "step's `evidence['psd_white']` (the spectrum's split, added after this run; no decision uses it) pins it: "
    "0.001148 for 0.001155 on `tests/test_refine_white_floor.py`'s 4th order.",
    "",
    "Beside a single pole or a moving average the floor is in the model only where the spectrum above f_s/4 "
    "shows one (≥ 0.05·N beside the kind found without it) and the Allan curve's fit agrees with it within 1.5× "
    "(`_rolloff.floor_choice`; offered everywhere it moved ADIS16405 run 5 gyro_y's boxcar 1.41 → 1.61 samples and "
    "gave run 1 gyro_z a second resonance — the four-record ADIS subset of `refine_measured.py` is now as before, "
    "field for field). Rerun at that change against the run above (647c48b): 61 of 72 for 56, no row that passed "
    "fails, every Butterworth and unfiltered row as before. The quantised single poles at 200 Hz/1 σ (+7.8 % and a "
    "resonance → +2.0 %) and 2 kHz/1 σ (+6.9 → −2.0 %) pass, 2 kHz/½ σ +1.7 → −0.6 %; the quantised 4-tap "
    "averages at 200 Hz/1 σ, 1 kHz/½ σ and 1 kHz/1 σ lose their resonance (cutoffs +0.4, −2.6, +2.7 %). The floor "
    "found lies within 20 % of the truth in 5 of those 6 records (−15, +4, +2 %; −15, +0.1 %; 1 kHz/1 σ −29 %). "
    "Left: the single poles at 200 Hz/½ σ (+3.6 %) and 1 kHz/1 σ (+9.7 %), where the spectrum shows the floor "
    "(0.67 and 0.48 of the truth beside the pole found without it) but white angle noise takes it on the Allan "
    "curve (the fit's floor 0 and 5·10⁻⁵: refused), and the 4-tap average at 2 kHz/1 σ, read since the sinc^k "
    "kinds (r7cic, after 647c48b) as a sinc⁵ of 1.78 samples (+0.5 %) beside a 702 Hz resonance — its floor "
    "tried, the fit's 0. The unfiltered single pole at 1 kHz stays a pole after a 1.2-sample boxcar (+4.3 %).",
]


def page(rows: list) -> list:
    """The results page's lines."""
    n_pass = sum(r["passed"] for r in rows)
    lines = [
        "# refine on filtered, quantised white noise (the bandwidth's white floor)",
        "",
        f"Written by `benches/refine_white_floor.py`, {_common.machine_line()}.",
        "",
        f"**Passed: {n_pass} of {len(rows)}** (the bandwidth alone — nothing for no filter —, cutoff within 3 %, "
        "a Butterworth's order). Floor: what refine found after the filter (— where none is in the model), the "
        "truth Δ·√(τ0/12).",
        "",
        "| filter | f_s (Hz) | step (σ) | named | cutoff error | floor found | floor true | other effects | "
        "χ²/dof | unexplained | pass |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['filter']} | {r['fs']:g} | {r['step']:g} | {r['named'] or '—'} | {_pct(r['cutoff_error'])} | "
            f"{_floor(r['floor'])} | {_floor(r['floor_true'])} | {', '.join(r['others']) or 'none'} | "
            f"{r['chi2_dof']:.2f} | {r['unexplained']} | {'✓' if r['passed'] else '✗'} |"
        )
    return lines + [""] + NOTES


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="the 2 kHz cases only, to a temporary folder")
    ap.add_argument("--out", default=None, help="results folder (default benches/results)")
    args = ap.parse_args(argv)
    rates = (2000.0,) if args.quick else RATES
    out = Path(args.out) if args.out else (Path(tempfile.mkdtemp()) if args.quick else HERE / "results")
    rows = []
    for i, (filt, fs, step) in enumerate((f, r, s) for f in FILTERS for r in rates for s in STEPS):
        rows.append(run_case(filt, fs, step, 2000 + i))
        _common.log(f"{filt} {fs:g} Hz step {step:g}: {rows[-1]['named']} {_pct(rows[-1]['cutoff_error'])}")
    _common.write_results(out, "refine_white_floor", page(rows), rows)
    _common.log(f"wrote {out / 'refine_white_floor.md'}")


if __name__ == "__main__":
    main()
