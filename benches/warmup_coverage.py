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


def median_ci(x: np.ndarray, level: float = 0.95, draws: int = 4000) -> tuple[float, float]:
    """Bootstrap ``level`` interval of the median of ``x`` over the records (percentile, a fixed seed)."""
    rng = np.random.default_rng(0)
    meds = np.median(x[rng.integers(0, x.size, (draws, x.size))], axis=1)
    return float(np.quantile(meds, (1 - level) / 2)), float(np.quantile(meds, (1 + level) / 2))


def fits(y: np.ndarray, noise: dict) -> dict:
    """The warm-up of one record by each fit compared (the table's rows)."""
    t = np.arange(y.size) / FS
    n_y = noise_terms(y, FS)
    # before: the refit noise's own R decided whether a ramp is a free column
    first = warmup_fit(y, FS, n_y)
    before = warmup_fit(y, FS, noise_terms(y - first["amplitude"] * np.exp(-t / first["T"]), FS))
    return {
        "gls": warmup_fit(y, FS, n_y, refit_noise=lambda z: noise_terms(z, FS)),
        "before": before,
        "oracle": warmup_fit(y, FS, noise),
        "ols": tracing.drift_fit(y, FS),
    }


def run(noise: dict, records: int, amplitude: float = A0) -> dict:
    t = np.arange(N_SAMPLES) / FS
    rows: dict = {"gls": [], "before": [], "oracle": [], "ols": []}
    for s in range(records):
        y = allanite.simulate(N_SAMPLES, FS, seed=7000 + s, **noise) + amplitude * np.exp(-t / T0)
        for key, d in fits(y, noise).items():
            lo, hi = d["T_interval"]
            rows[key].append({"T": d["T"], "lo": lo, "hi": hi, "amplitude": d["amplitude"], "ramp": d.get("ramp")})
    out = {}
    for key, rs in rows.items():
        k = sum(r["lo"] <= T0 <= r["hi"] for r in rs)
        err = np.array([r["T"] / T0 - 1 for r in rs])
        out[key] = {
            "coverage": k / len(rs),
            "coverage_95": _common.clopper_pearson(k, len(rs)),
            "median_abs_T_error": float(np.median(np.abs(err))),
            "median_abs_T_error_95": median_ci(np.abs(err)),
            "mean_abs_log_T_error": float(np.mean(np.abs(np.log1p(err)))),
            "mean_T_error": float(np.mean(err)),
            "median_T_error": float(np.median(err)),
            "median_abs_amplitude_error": float(np.median([abs(r["amplitude"] / amplitude - 1) for r in rs])),
            "ramp_fitted": float(np.mean([bool(r["ramp"]) for r in rs])) if rs[0]["ramp"] is not None else None,
            "records": rs,
        }
    return out


def cases() -> list[tuple[str, dict, float]]:
    """(noise name, noise terms, warm-up amplitude °/s): the issue's amplitude on both noises, and twice it on
    refine's final model (where the bound allows a median |T error| of 20 %)."""
    out = [(name, noise, A0) for name, noise in NOISES.items()]
    name = next(iter(NOISES))
    return out[:1] + [(name, NOISES[name], 2 * A0)] + out[1:]


LABELS = (
    ("gls", "GLS against the record's noise, ramp by the block means' likelihood (refine)"),
    ("before", "the same, ramp where the fitted R > 0 (refine before)"),
    ("oracle", "GLS against the true noise (oracle)"),
    ("ols", "former OLS with a free ramp"),
)


def table(results: dict) -> list[str]:
    lines = [
        "| noise | a (°/s) | fit | coverage of T (68.3 % interval) | 95 % bounds | median \\|T error\\| [95 %] | "
        "mean \\|ln(T̂/T)\\| | median T error | mean T error | median \\|a error\\| | ramp fitted |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for (name, a), res in results.items():
        for key, label in LABELS:
            r = res[key]
            lo, hi = r["coverage_95"]
            mlo, mhi = r["median_abs_T_error_95"]
            ramp = "" if r["ramp_fitted"] is None else f"{r['ramp_fitted']:.0%}"
            lines.append(
                f"| {name} | {a:g} | {label} | {r['coverage']:.0%} | {lo:.0%}–{hi:.0%} | "
                f"{r['median_abs_T_error']:.1%} [{mlo:.0%}, {mhi:.0%}] | {r['mean_abs_log_T_error']:.3f} | "
                f"{r['median_T_error']:+.1%} | {r['mean_T_error']:+.1%} | {r['median_abs_amplitude_error']:.1%} | "
                f"{ramp} |"
            )
    return lines


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--records", type=int, default=60)
    args = ap.parse_args(argv)
    out = HERE / "results" if args.records >= 50 else Path(tempfile.mkdtemp())
    t0 = time.perf_counter()
    with _common.OtherLoad() as load:
        results = {(name, a): run(noise, args.records, a) for name, noise, a in cases()}
    m = _common.machine_info()
    bounds = {name: warmup_crlb(N_SAMPLES / FS, A0, T0, noise) for name, noise in NOISES.items()}
    longer = {name: warmup_crlb(10 * N_SAMPLES / FS, A0, T0, noise) for name, noise in NOISES.items()}
    lines = [
        "# Warm-up intervals: coverage (issue 29, item 6)",
        "",
        f"`python benches/warmup_coverage.py`: {args.records} records per row (seeds 7000…), 10⁶ samples at "
        f"100 Hz + a·e^(−t/{T0:g} s); {m['cpu_model']}, allanite at {m['git_commit']}, {m['date_utc'][:10]}, "
        f"{time.perf_counter() - t0:.0f} s, other processes {load.fraction or 0:.0%} of the CPUs. Target: 68 % "
        f"coverage of T within 55–80 %, median |T error| ≤ 20 % (at a = {A0} °/s). The median's interval: "
        "a bootstrap over the records. Ramp fitted: the share of records whose fit had a free rate-ramp column.",
        "",
        *table(results),
        "",
        "Cramér–Rao bound of T (inverse Fisher information of (c, a, T) from 500 block means under the true noise "
        "terms, the ramp R·t a free column where R > 0; the noise's own estimate does not raise it, its Fisher "
        "information being orthogonal to the mean's): no unbiased estimator has a smaller standard deviation. "
        f"Median |T error| at the bound = {MEDIAN_ABS_NORMAL}·sd (normal). Amplitude for 20 %: the bound scales "
        f"as 1/a. At a = {A0} °/s.",
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
    dump = {f"{name} | a={a:g}": res for (name, a), res in results.items()}
    dump["crlb"] = bounds
    (out / "warmup_coverage.md").write_text("\n".join(lines) + "\n")
    (out / "warmup_coverage.json").write_text(json.dumps(dump, indent=1))
    print("\n".join(lines))
    print(f"wrote {out / 'warmup_coverage.md'}")


if __name__ == "__main__":
    main()
