#!/usr/bin/env python3
"""Which bandwidth kind holds an equiripple FIR decimator's Allan curve, and what a sharp (raised-cosine) kind would
add (r14fir) — measured before adding one.

``benches/refine_blind11.py``'s row "MEMS decimated 8 kHz → 1 kHz by a 95-tap equiripple FIR (1.3 dB passband
ripple to 300 Hz, −3 dB at 327 Hz)" names the roll-off (butterworth3) but leaves the curve departing at τ 1–129 ms.
The question asked: is the FIR too *sharp* for the family (single pole, Butterworth 2–6, moving average, Bartlett,
boxcar, sinc^k), so that a brick-wall kind with a raised-cosine transition would hold it?

For each remez FIR (several pass/stop edges, tap counts, decimations and passband weights: ripple from 1.3 dB down
to 0.03 dB) the *exact* Allan variance of white noise through it, decimated, is computed from the output's
autocorrelation (r_out(l) = Σ_k h_k·h_{k+D·l}, the Allan kernel summed by prefix sums), checked against the
overlapping AVAR of 2·10⁶ simulated output samples for one design. Each kind is then fitted to it: the kind's
column (unit DC gain) and white angle noise (∝ 1/m²) by non-negative least squares, with each τ weighted by the
relative spread √(m/n) of a 10⁶-sample record's estimate (the overlapping estimator's order for white noise), the
kind's cutoff on a 1 Hz-step grid. The raised-cosine kind (power response 1 to f_c(1−β), ½(1+cos) to 0 at
f_c(1+β); half power at f_c) is the closed-form pulse r(l) = 2x·sinc(2xl)·cos(2πβxl)/(1 − (4βxl)²), x = f_c/f_s,
written here only (not in the package). Reported: each kind's best weighted χ² (the sum of squares at 10⁶
samples; ≈ the number of τ, 73, for a kind that holds the curve) and largest relative misfit over τ = 1–2000
samples. Everything scales with f_s (the output rates here are 1 kHz and 500 Hz; 100 Hz–2 kHz are the same
numbers at scaled cutoffs).

With ``--refine`` the blind11 row itself is refined again (its seed, noise, rates and judge:
``refine_blind11.run_case``) with the FIR swapped for other designs of :data:`REFINE_DESIGNS` — the same 95 taps
and edges at a lower passband ripple, and a sharper 191-tap FIR — to see what refine makes of each with the
family as it is.

Usage::

    python benches/r14fir.py            # -> benches/results/r14fir.md/.json
    python benches/r14fir.py --refine   # and the blind11 row's FIR variants through refine (≈ 4 min each)
    python benches/r14fir.py --md       # the .md again from the recorded .json
"""

from __future__ import annotations

import json
import math
import os
import sys
import time
from pathlib import Path

import numpy as np
from scipy import signal

from allanite import avar
from allanite.model.effects import filter_autocorrelation

OUT = Path(__file__).resolve().parent / "results"
N_REC = 1_000_000  # the record length the weights stand for (the blind11 row's)
M = np.unique(np.round(np.geomspace(1, 2000, 80)))
#: (taps, input rate, decimation, pass edge, stop edge, weights (pass, stop)) — the blind11 row first
DESIGNS = [
    (95, 8000.0, 8, 300.0, 450.0, (1.0, 30.0)),
    (95, 8000.0, 8, 300.0, 450.0, (3.0, 10.0)),
    (95, 8000.0, 8, 300.0, 450.0, (10.0, 1.0)),
    (191, 8000.0, 8, 300.0, 400.0, (10.0, 1.0)),
    (127, 8000.0, 8, 250.0, 400.0, (5.0, 1.0)),
    (63, 8000.0, 8, 200.0, 450.0, (5.0, 1.0)),
    (95, 2000.0, 4, 150.0, 230.0, (10.0, 1.0)),
    (255, 8000.0, 16, 150.0, 220.0, (10.0, 1.0)),
]
#: (taps, pass edge, stop edge, weights) of the blind11 row's FIR in ``--refine`` (its first: the row as it is)
REFINE_DESIGNS = [
    (95, 300.0, 450.0, (1.0, 30.0)),
    (95, 300.0, 450.0, (3.0, 10.0)),
    (95, 300.0, 450.0, (10.0, 1.0)),
    (191, 300.0, 400.0, (10.0, 1.0)),
    (63, 200.0, 450.0, (5.0, 1.0)),
]
KINDS = ("butterworth2", "butterworth3", "butterworth4", "butterworth5", "butterworth6", "single_pole")
BETAS = (0.05, 0.1, 0.2, 0.35, 0.5)


def prefix_avar(r: np.ndarray, m: np.ndarray) -> np.ndarray:
    """σ²(m)/σ_w² of samples with autocorrelation r (lags ≥ 0, two-sided sum 1): (1/2m²)·Σ_l A_m(l)·w_l·r(l)."""
    wr = 2.0 * r
    wr[0] = r[0]
    s0 = np.concatenate([[0.0], np.cumsum(wr)])
    s1 = np.concatenate([[0.0], np.cumsum(np.arange(r.size) * wr)])
    mi = m.astype(np.int64)
    mid = np.minimum(mi + 1, r.size)
    end = np.maximum(np.minimum(2 * mi, r.size), mid)
    s = 2.0 * m * s0[mid] - 3.0 * s1[mid] - 2.0 * m * (s0[end] - s0[mid]) + (s1[end] - s1[mid])
    return s / (2.0 * m * m)


def fir_r(taps: np.ndarray, dec: int) -> np.ndarray:
    """Autocorrelation of white noise through ``taps``, kept every ``dec``-th sample, normalised to unit sum."""
    rh = np.correlate(taps, taps, "full")[taps.size - 1 :]
    r = rh[::dec].copy()
    return r / (r[0] + 2.0 * r[1:].sum())


def raised_cosine_r(fc: float, beta: float, fs: float) -> np.ndarray:
    """The raised-cosine (in power) low-pass's autocorrelation, unit sum; f_c(1 + β) ≤ f_s/2."""
    x = fc / fs
    lags = np.arange(int(math.ceil(400.0 / (beta * x))) + 1, dtype=np.float64)
    den = 1.0 - (4.0 * beta * x * lags) ** 2
    at_pole = np.abs(den) < 1e-9
    r = 2.0 * x * np.sinc(2.0 * x * lags) * np.cos(2.0 * np.pi * beta * x * lags) / np.where(at_pole, 1.0, den)
    r[at_pole] = 2.0 * x * math.pi / 4.0 * np.sinc(1.0 / (2.0 * beta))
    return r / (r[0] + 2.0 * r[1:].sum())


def fit(col: np.ndarray, truth: np.ndarray) -> tuple[float, float]:
    """(weighted χ², largest |relative misfit|) of the non-negative fit of (col, 1/m²) to ``truth``."""
    from scipy.optimize import nnls

    sd = np.sqrt(M / N_REC) * truth
    a = np.column_stack([col, 1.0 / M**2]) / sd[:, None]
    theta, _res = nnls(a, truth / sd)
    model = a @ theta * sd
    return float((((model - truth) / sd) ** 2).sum()), float(np.max(np.abs(model / truth - 1.0)))


def best(make, cutoffs) -> dict:
    """The cutoff whose column fits best, and its (χ², misfit)."""
    rows = [(fc, *fit(make(fc), TRUTH[0])) for fc in cutoffs]
    fc, chi2, mis = min(rows, key=lambda r: r[1])
    return {"cutoff": float(fc), "chi2": chi2, "max_misfit": mis}


TRUTH: list = [None]


def design_row(spec) -> dict:
    ntap, fs_in, dec, fp, fst, w = spec
    taps = signal.remez(ntap, [0, fp, fst, fs_in / 2], [1, 0], weight=list(w), fs=fs_in)
    f, h = signal.freqz(taps, worN=2**15, fs=fs_in)
    g = np.abs(h)
    ripple = float(np.ptp(20 * np.log10(g[f <= fp])))
    k = int(np.argmax((f > fp) & (g < 1 / math.sqrt(2))))
    cut = float(np.interp(1 / math.sqrt(2), [g[k], g[k - 1]], [f[k], f[k - 1]]))
    fs = fs_in / dec
    TRUTH[0] = prefix_avar(fir_r(taps, dec), M)
    grid = np.arange(math.floor(0.8 * cut), min(math.ceil(1.25 * cut), 0.5 * fs) + 1.0, 1.0)
    fits = {}
    for kind in KINDS:
        fits[kind] = best(lambda fc, kind=kind: prefix_avar(filter_autocorrelation(kind, fc, fs), M), grid)
    for beta in BETAS:
        ok = grid[grid * (1 + beta) <= fs / 2]
        fits[f"raised_cosine β={beta:g}"] = best(
            lambda fc, beta=beta: prefix_avar(raised_cosine_r(fc, beta, fs), M), ok
        )
    name = f"{ntap} taps, {fs_in:g} → {fs:g} Hz, pass {fp:g} / stop {fst:g} Hz, weights {w[0]:g}:{w[1]:g}"
    return {"design": name, "ripple_db": ripple, "cutoff_3db": cut, "fits": fits}


def simulated_check(n: int = 2_000_000, seed: int = 14) -> dict:
    """The exact reference against the overlapping AVAR of simulated white noise through the blind11 row's FIR."""
    ntap, fs_in, dec, fp, fst, w = DESIGNS[0]
    taps = signal.remez(ntap, [0, fp, fst, fs_in / 2], [1, 0], weight=list(w), fs=fs_in)
    rng = np.random.default_rng(seed)
    x = rng.standard_normal(n * dec)
    y = signal.lfilter(taps, 1.0, x)[ntap::dec]
    ms = np.array([1, 2, 3, 4, 6, 8, 16, 64, 256], dtype=np.float64)
    res = avar(y, fs_in / dec, taus=ms / (fs_in / dec)).with_confidence(alpha=0)  # white-noise EDF: approximate
    rh = np.correlate(taps, taps, "full")[taps.size - 1 :]
    exact = prefix_avar(rh[::dec].copy(), ms)  # σ_w² = 1 per input sample: r unnormalised
    lo, hi = res.ci_low, res.ci_high
    rows = []
    for j, m in enumerate(ms):
        row = {"m": int(m), "measured": float(res.avar[j]), "exact": float(exact[j])}
        row["ratio"] = row["measured"] / row["exact"]
        row["covered"] = bool(lo[j] <= exact[j] <= hi[j])
        rows.append(row)
    return {"n": n, "seed": seed, "rows": rows}


def refine_rows() -> list:
    """The blind11 row refined with each of :data:`REFINE_DESIGNS` in place of its FIR (its truth the design's
    own −3 dB frequency), judged by the suite's own judge."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import refine_blind11 as rb11

    case = next(c for c in rb11.CASES if "equiripple" in c.name)
    saved = (rb11.FIR_TAPS, rb11.FIR_PASS, rb11.FIR_STOP, rb11._fir_taps, case.injected[0].truth["cutoff"])
    rows = []
    try:
        for ntap, fp, fst, w in REFINE_DESIGNS:
            rb11.FIR_TAPS, rb11.FIR_PASS, rb11.FIR_STOP = ntap, fp, fst
            rb11._fir_taps = lambda n=ntap, a=fp, b=fst, w=w: signal.remez(
                n, [0, a, b, rb11.FIR_FS_IN / 2], [1, 0], weight=list(w), fs=rb11.FIR_FS_IN
            )
            case.injected[0].truth["cutoff"] = rb11._fir_cutoff()
            v = rb11.run_case(case)
            rows.append(
                {
                    "design": f"{ntap} taps, pass {fp:g} / stop {fst:g} Hz, weights {w[0]:g}:{w[1]:g}",
                    "ripple_db": rb11._fir_ripple_db(),
                    "cutoff_3db": case.injected[0].truth["cutoff"],
                    "steps": v.get("steps"),
                    "param_errors": v.get("param_errors"),
                    "chi2_dof": v.get("chi2_dof"),
                    "unexplained": [
                        f"{u.get('what')} (τ {u['tau'][0]:.3g}–{u['tau'][1]:.3g} s)" if u.get("tau") else u.get("what")
                        for u in v.get("unexplained") or []
                    ],
                    "passed": v.get("passed"),
                }
            )
            print(rows[-1], flush=True)
    finally:
        rb11.FIR_TAPS, rb11.FIR_PASS, rb11.FIR_STOP, rb11._fir_taps, case.injected[0].truth["cutoff"] = saved
    return rows


def _step(st: dict) -> str:
    """One named step: a bandwidth's kind and cutoff, another effect's parameters."""
    par = st["params"]
    if st["effect"] == "bandwidth":
        return f"bandwidth ({par.get('filter')} {par.get('cutoff', math.nan):.0f} Hz)"
    return f"{st['effect']} (" + ", ".join(f"{k} {v:.3g}" for k, v in par.items() if isinstance(v, float)) + ")"


def refine_md(rows: list) -> list:
    md = [
        "",
        "The blind11 row (its seed, noise and judge) refined with its FIR swapped (`--refine`):",
        "",
        "| FIR | ripple dB | −3 dB Hz | named | error | χ²/dof | unexplained | passed |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        named = "; ".join(_step(st) for st in r["steps"] or [])
        err = ", ".join(f"{k} {100 * e:+.1f} %" for k, e in (r["param_errors"] or {}).items())
        chi = " → ".join(f"{c:.3g}" for c in r["chi2_dof"] or [])
        left = "; ".join(r["unexplained"]) or "none"
        md.append(
            f"| {r['design']} | {r['ripple_db']:.2f} | {r['cutoff_3db']:.0f} | {named} | {err} | {chi} | {left} | "
            f"{'✓' if r['passed'] else '✗'} |"
        )
    return md


#: What the recorded run shows (kept true to benches/results/r14fir.json).
NOTES = [
    "",
    "Reading (the recorded run):",
    "",
    "- *The blind11 row fails on its passband ripple, not on its steepness.* Its FIR's power gain is 1.150 at DC, "
    "0.865 at 150 Hz and 0.858 at 300 Hz (1.3 dB ripple; the passband's mean power 1.035, 10 % below DC). The Allan "
    "curve at τ ≥ 10 samples sees the DC gain, at τ of 1–5 samples the passband's mean: every kind — the "
    "Butterworths 2–6 and a raised cosine of any width β = 0.05–0.5 alike — leaves a largest misfit of 9.7–10 % "
    "(weighted χ² 6.6·10³–1.05·10⁴ against 73 τ; the single pole 32 %), and refine's reading (butterworth3 at 309 Hz, the curve departing "
    "at τ 1–129 ms) is what the family can do. At 0.54 dB of ripple the same holds (misfit 4.6–6.4 %; refine adds "
    "an 81 Hz resonance of q 4 as a stand-in for the ripple, and still says the curve departs).",
    "- *Sharp low-ripple FIRs are held by the Butterworths about as well as by a raised cosine, and only "
    "marginally.* The same 95 taps and edges at 0.08 dB of ripple, and a 191-tap FIR flat to 300 Hz and down by "
    "400 Hz (0.03 dB), each pass the row's own judge through refine on its seed 1103 (butterworth3 at 372 Hz, "
    "+1.0 %; butterworth6 at 344 Hz, −0.3 %; nothing unexplained). On two more seeds (2211, 3307; `refine_rows` "
    "with the case's seed changed, a diagnostic not in the JSON) the 95-tap one passes on neither (butterworth3 "
    "372 Hz, then butterworth2 372 Hz; the curve departs at τ 3–47 ms, χ²/dof 3.35; τ 1–39 ms, 11.3) and the "
    "191-tap one on 2211 only (butterworth6 345 Hz, χ²/dof 1.00; on 3307 342.5 Hz, departs at τ 3 ms): 3 of 6. On "
    "the exact curves the best raised cosine fits no better than the best Butterworth beyond a few χ² points "
    "(95 taps 0.08 dB: butterworth3 40.7, β 0.2 42.6; 191 taps: butterworth6 2.9, β 0.1 6.0; 127 taps: "
    "butterworth5 10.6, β 0.2 8.5; 63 taps with a broad 200–450 Hz transition: butterworth3 72, β 0.35 69) — so "
    "the misses at 10⁶ samples are not the steepness either; the kind would not turn them.",
    "- *A broad-transition 63-tap FIR (0.08 dB) still leaves a small misfit*: refine names butterworth3 at 301 Hz "
    "(−1.1 %) and says the curve departs at τ 3–5 ms; no kind tried here (raised cosine included) fits it "
    "better (largest misfit 0.93 % for both).",
    "- Hence no raised-cosine kind is added to the bandwidth family: it would widen every bandwidth search and the "
    "tests' family for no reading it changes on these designs. What would hold a rippled FIR exactly is its own taps (a kind whose "
    "autocorrelation is r(l) = Σ h_k·h_{k+D·l}, as this bench computes it), which the user of a part knows from its "
    "data sheet — not something to infer from an Allan curve.",
]


def main() -> None:
    if "--md" in sys.argv[1:]:  # the table again from the recorded JSON (no computation)
        write_md(json.loads((OUT / "r14fir.json").read_text()))
        return
    t0 = time.time()
    rows = [design_row(d) for d in DESIGNS]
    check = simulated_check()
    refined = refine_rows() if "--refine" in sys.argv[1:] else None
    load = os.getloadavg()[0]
    out = {"rows": rows, "check": check, "refined": refined, "load": load, "seconds": time.time() - t0}
    OUT.mkdir(exist_ok=True)
    (OUT / "r14fir.json").write_text(json.dumps(out, indent=1))
    write_md(out)


def write_md(out: dict) -> None:
    rows, check, refined, load = out["rows"], out["check"], out["refined"], out["load"]
    cols = list(rows[0]["fits"])
    md = [
        "# Equiripple FIR decimators: which bandwidth kind holds the Allan curve (r14fir)",
        "",
        f"`python benches/r14fir.py` (load {load:.1f}; {out['seconds']:.0f} s). Each cell: the kind's best weighted "
        "χ² at 10⁶ samples (73 τ) / its largest relative misfit over τ = 1–2000 samples (white angle noise free "
        "beside it). Raised cosine: a brick wall with a raised-cosine transition of relative half-width β.",
        "",
        "| design | ripple dB | −3 dB Hz | " + " | ".join(cols) + " |",
        "|" + "---|" * (3 + len(cols)),
    ]
    for r in rows:
        cells = [f"{r['fits'][c]['chi2']:.3g} / {100 * r['fits'][c]['max_misfit']:.2g} %" for c in cols]
        md.append(f"| {r['design']} | {r['ripple_db']:.2f} | {r['cutoff_3db']:.0f} | " + " | ".join(cells) + " |")
    md += [
        "",
        f"Exact reference against simulation (blind11's FIR, {check['n']} output samples, seed {check['seed']}):",
        "",
    ]
    md += ["| m | measured | exact | ratio | in 95 % CI (white-noise EDF) |", "|---|---|---|---|---|"]
    for c in check["rows"]:
        md.append(f"| {c['m']} | {c['measured']:.5g} | {c['exact']:.5g} | {c['ratio']:.4f} | {c['covered']} |")
    if refined is not None:
        md += refine_md(refined)
    md += NOTES
    (OUT / "r14fir.md").write_text("\n".join(md) + "\n")
    print("\n".join(md))


if __name__ == "__main__":
    sys.exit(main())
