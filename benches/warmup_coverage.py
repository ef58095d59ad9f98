#!/usr/bin/env python3
"""Do the warm-up's intervals cover? (issue 29, item 6)

Records of ADIS16405-like noise — the five noise terms that ``refine`` fits to ADIS16405 run 4, x gyro (its final
model, and the plain five-term fit with the shortest τ cut) — plus a warm-up 0.08 °/s·e^{−t/1500 s}, 10⁶ samples
at 100 Hz. Each record's warm-up is fitted as ``refine`` fits it (:func:`allanite.model.warmup.warmup_fit`: GLS on
500 block means against the noise terms of the record with the warm-up removed), by the same GLS against the true
noise terms (the oracle: what knowing the noise would give) and by the former ordinary least squares with a free
ramp (:func:`allanite.model.tracing.drift_fit`). Reported: how often the 68.3 % interval of T holds the truth (with
its Clopper–Pearson 95 % bounds), the median |T error| and the median T error; and the Cramér–Rao bound of T
(:func:`allanite.model.warmup.warmup_crlb`) with the warm-up amplitude at which it would allow a median |T error|
of 20 %.

Usage::

    python benches/warmup_coverage.py              # -> benches/results/warmup_coverage.{json,md}
    python benches/warmup_coverage.py --records 20 # fewer records, to a temporary folder
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np

import _common
import allanite
from allanite.model import tracing
from allanite.model.warmup import noise_terms, warmup_crlb, warmup_fit

HERE = Path(__file__).resolve().parent
FS, N_SAMPLES, A0, T0 = 100.0, 1_000_000, 0.08, 1500.0
#: Median |error| of a normal estimate over its standard deviation.
MEDIAN_ABS_NORMAL = 0.6745

#: Noise terms (°/s base form) fitted to ADIS16405 run 4 x: refine's final model's five-term part (it also holds a
#: sensor bandwidth, a 0.55 Hz site line and a Gauss–Markov term), and the plain fit with tau_range="auto".
NOISES = {
    "ADIS run 4 x, refine's final model (N 0.0415 °/√s, B 0.00714 °/s, R 6.7e-6 °/s²)": {
        "N": 0.0415,
        "B": 0.00714,
        "R": 6.68e-6,
    },
    "ADIS run 4 x, five terms, tau_range='auto' (N 0.0414, B 0.0101, K 3.36e-4 °/s^1.5)": {
        "N": 0.04139,
        "B": 0.01008,
        "K": 3.358e-4,
    },
}


def run(noise: dict, records: int) -> dict:
    t = np.arange(N_SAMPLES) / FS
    rows: dict = {"gls": [], "oracle": [], "ols": []}
    for s in range(records):
        y = allanite.simulate(N_SAMPLES, FS, seed=7000 + s, **noise) + A0 * np.exp(-t / T0)
        g = warmup_fit(y, FS, noise_terms(y, FS), refit_noise=lambda z: noise_terms(z, FS))
        o = tracing.drift_fit(y, FS)
        for key, d in (("gls", g), ("oracle", warmup_fit(y, FS, noise)), ("ols", o)):
            lo, hi = d["T_interval"]
            rows[key].append({"T": d["T"], "lo": lo, "hi": hi, "amplitude": d["amplitude"]})
    out = {}
    for key, rs in rows.items():
        k = sum(r["lo"] <= T0 <= r["hi"] for r in rs)
        err = np.array([r["T"] / T0 - 1 for r in rs])
        out[key] = {
            "coverage": k / len(rs),
            "coverage_95": _common.clopper_pearson(k, len(rs)),
            "median_abs_T_error": float(np.median(np.abs(err))),
            "mean_T_error": float(np.mean(err)),
            "median_T_error": float(np.median(err)),
            "median_abs_amplitude_error": float(np.median([abs(r["amplitude"] / A0 - 1) for r in rs])),
            "records": rs,
        }
    return out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--records", type=int, default=60)
    args = ap.parse_args(argv)
    out = HERE / "results" if args.records >= 50 else Path(tempfile.mkdtemp())
    t0 = time.perf_counter()
    with _common.OtherLoad() as load:
        results = {name: run(noise, args.records) for name, noise in NOISES.items()}
    m = _common.machine_info()
    bounds = {name: warmup_crlb(N_SAMPLES / FS, A0, T0, noise) for name, noise in NOISES.items()}
    longer = {name: warmup_crlb(10 * N_SAMPLES / FS, A0, T0, noise) for name, noise in NOISES.items()}
    lines = [
        "# Warm-up intervals: coverage (issue 29, item 6)",
        "",
        f"`python benches/warmup_coverage.py`: {args.records} records per noise, 10⁶ samples at 100 Hz + "
        f"{A0} °/s·e^(−t/{T0:g} s); {m['cpu_model']}, allanite at {m['git_commit']}, {m['date_utc'][:10]}, "
        f"{time.perf_counter() - t0:.0f} s, other processes {load.fraction or 0:.0%} of the CPUs. Target: 68 % "
        "coverage of T within 55–80 %, median |T error| ≤ 20 %.",
        "",
        "| noise | fit | coverage of T (68.3 % interval) | 95 % bounds | median \\|T error\\| | median T error | "
        "mean T error | median \\|a error\\| |",
        "|---|---|---|---|---|---|---|---|",
    ]
    labels = (
        ("gls", "GLS against the record's noise (refine)"),
        ("oracle", "GLS against the true noise (oracle)"),
        ("ols", "former OLS with a free ramp"),
    )
    for name, res in results.items():
        for key, label in labels:
            r = res[key]
            lo, hi = r["coverage_95"]
            lines.append(
                f"| {name} | {label} | {r['coverage']:.0%} | {lo:.0%}–{hi:.0%} | {r['median_abs_T_error']:.1%} | "
                f"{r['median_T_error']:+.1%} | {r['mean_T_error']:+.1%} | {r['median_abs_amplitude_error']:.1%} |"
            )
    lines += [
        "",
        "Cramér–Rao bound of T (inverse Fisher information of (c, a, T) from 500 block means under the true noise "
        "terms, the ramp R·t a free column where R > 0; the noise's own estimate does not raise it, its Fisher "
        "information being orthogonal to the mean's): no unbiased estimator has a smaller standard deviation. "
        f"Median |T error| at the bound = {MEDIAN_ABS_NORMAL}·sd (normal). Amplitude for 20 %: the bound scales "
        "as 1/a.",
        "",
        "| noise | sd(T)/T ≥ | median \\|T error\\| ≥ | sd(a)/a ≥ | a for median \\|T error\\| 20 % | "
        "sd(T)/T ≥ on a 10× longer record |",
        "|---|---|---|---|---|---|",
    ]
    for name, b in bounds.items():
        med = MEDIAN_ABS_NORMAL * b["T_rel"]
        lines.append(
            f"| {name} | {b['T_rel']:.1%} | {med:.1%} | {b['amplitude_rel']:.1%} | {A0 * med / 0.2:.3g} °/s | "
            f"{longer[name]['T_rel']:.1%} |"
        )
    results["crlb"] = bounds
    (out / "warmup_coverage.md").write_text("\n".join(lines) + "\n")
    (out / "warmup_coverage.json").write_text(json.dumps(results, indent=1))
    print("\n".join(lines))
    print(f"wrote {out / 'warmup_coverage.md'}")


if __name__ == "__main__":
    main()
