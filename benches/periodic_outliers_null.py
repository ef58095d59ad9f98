#!/usr/bin/env python3
"""False alarms of the line search (``"sinusoid"``/``"periodic"``) and the outlier test on null records.

Each record holds only the five IEEE-952 terms, a quantiser and a low-pass — nothing periodic, nothing
impulsive — so any line found or any outlier accepted is a false alarm. Records (``--records``, default 640;
fixed seeds):

- fs log-uniform in 1 Hz … 2 kHz, 10⁵ … 10⁶ samples (log-uniform);
- white rate noise N always; each of flicker B, random walk K (half the records), white angle Q (30 %) and a
  ramp R (20 %) at a random level that puts its part of the Allan curve inside the record's τ;
- a low-pass in 40 % of the records: a first- or second-order Butterworth at 1 … 40 % of f_s, or a moving
  average of 2 … 8 taps (a decimating MEMS part);
- quantisation in 40 %: a step of 0.03 … 2 × the differences' σ (coarse steps on a quiet record make the
  outlier test abstain: it says so, and abstaining is no alarm).

Each test runs with default arguments at its proposed share of refine's per-record level 0.05: the line
search at ``LINE_SHARE`` = 0.2 (α = 1 %; sinusoids and families share it — the targeted extension of a family
runs only after a line was found, so under the null it adds nothing), the outlier test at ``OUTLIER_SHARE`` =
0.05 (α = 0.25 %). Rates with 95 % Clopper–Pearson intervals, overall and by feature; also each record's
Bonferroni p-value (lines) and Bonferroni-over-cuts p-value (outliers), so the rate at other levels can be
read off the same records.

Usage::

    python benches/periodic_outliers_null.py            # -> benches/results/periodic_outliers_null.{json,md}
    python benches/periodic_outliers_null.py --quick    # 12 records, to a temporary folder
"""

from __future__ import annotations

import argparse
import json
import math
import os
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy import signal

import _common
import allanite
from allanite.model import outliers, periodic

HERE = Path(__file__).resolve().parent
LEVEL = 0.05
LINE_SHARE = 0.2
OUTLIER_SHARE = 0.05


def record(i: int):
    """Null record i: (samples, fs, features)."""
    rng = np.random.default_rng(20_260 + i)
    fs = float(10 ** rng.uniform(0.0, math.log10(2000.0)))
    n = int(10 ** rng.uniform(5.0, 6.0))
    length = n / fs
    kw = {"N": 1.0}
    feats = ["N"]
    # each slow term crosses N somewhere between 10 samples and a tenth of the record
    tau_x = 10 ** rng.uniform(math.log10(10.0 / fs), math.log10(length / 10.0))
    if rng.random() < 0.5:
        kw["B"] = math.sqrt(1.0 / tau_x / 0.4413)
        feats.append("B")
    if rng.random() < 0.5:
        kw["K"] = math.sqrt(3.0 / tau_x**2) * 10 ** rng.uniform(-0.5, 0.5)
        feats.append("K")
    if rng.random() < 0.3:
        kw["Q"] = 10 ** rng.uniform(-1.0, 0.5) / math.sqrt(fs)
        feats.append("Q")
    if rng.random() < 0.2:
        kw["R"] = math.sqrt(2.0 / tau_x**3) * 10 ** rng.uniform(-1.0, 0.0)
        feats.append("R")
    pad = 4096  # filters start from rest: their transient is simulated and cut off
    y = allanite.simulate(n + pad, fs, seed=rng, **kw)
    if rng.random() < 0.4:
        kind = rng.integers(3)
        if kind < 2:
            fc = 10 ** rng.uniform(-2.0, math.log10(0.4))
            sos = signal.butter(int(kind) + 1, 2 * fc, output="sos")
            y = signal.sosfilt(sos, y)
            feats.append(f"butter{int(kind) + 1}")
        else:
            taps = int(rng.integers(2, 9))
            y = np.convolve(y, np.full(taps, 1.0 / taps), mode="full")[: y.size]  # causal, as a sensor's
            feats.append("moving average")
    y = y[pad:]
    if rng.random() < 0.4:
        lsb = float(np.std(np.diff(y[:20_000]))) * 10 ** rng.uniform(math.log10(0.03), math.log10(2.0))
        y = np.round(y / lsb) * lsb
        feats.append("quantised")
    return y, fs, feats


def run(records: int, out: Path) -> dict:
    rows = []
    t_all = time.perf_counter()
    for i in range(records):
        y, fs, feats = record(i)
        t0 = time.process_time()
        ps = periodic.periodic_search(y, fs, LEVEL * LINE_SHARE)
        t1 = time.process_time()
        ot = outliers.outlier_test(y, fs, LEVEL * OUTLIER_SHARE)
        t2 = time.process_time()
        p_out = min(1.0, min((c["p_value"] for c in ot["cuts"]), default=1.0) * len(outliers.CUTS))
        p_gauss = min(1.0, min((c["p_gaussian"] for c in ot["cuts"]), default=1.0) * len(outliers.CUTS))
        found = [round(float(ln["f"]), 6) for ln in ps["lines"]]
        rows.append(
            {
                "record": i,
                "fs": fs,
                "n": int(y.size),
                "features": feats,
                "lines_found": found,
                "families": len(ps["families"]),
                "lines_p": ps["p_value"],  # the record's Bonferroni p-value of the line search
                "outliers": bool(ot["accepted"]),
                "outliers_p": p_out,
                "outliers_p_gaussian": p_gauss,
                "outliers_abstained": ot.get("note"),
                "cpu_lines_s": t1 - t0,
                "cpu_outliers_s": t2 - t1,
            }
        )
        if found or ot["accepted"]:
            _common.log(f"record {i}: lines {found}, outliers {ot['accepted']} ({feats}, fs {fs:.3g}, n {y.size})")
        if (i + 1) % 50 == 0:
            _common.log(f"{i + 1} records, {time.perf_counter() - t_all:.0f} s")
    report = summarize(rows)
    report["seconds"] = time.perf_counter() - t_all
    report["machine"] = _common.machine_info()
    report["loadavg_end"] = list(os.getloadavg())
    out.mkdir(parents=True, exist_ok=True)
    (out / "periodic_outliers_null.json").write_text(json.dumps({"summary": report, "records": rows}, indent=1))
    (out / "periodic_outliers_null.md").write_text(markdown(report))
    return report


def _rate(k, n):
    lo, hi = _common.clopper_pearson(k, n)
    return {"alarms": k, "records": n, "rate": k / n if n else float("nan"), "ci95": [lo, hi]}


def summarize(rows) -> dict:
    n = len(rows)
    s = {
        "level": LEVEL,
        "alpha": {"lines": LEVEL * LINE_SHARE, "outliers": LEVEL * OUTLIER_SHARE},
        "lines": _rate(sum(bool(r["lines_found"]) for r in rows), n),
        "outliers": _rate(sum(r["outliers"] for r in rows), n),
        "either": _rate(sum(bool(r["lines_found"]) or r["outliers"] for r in rows), n),
        "outliers_abstained": sum(r["outliers_abstained"] is not None for r in rows),
        "by_feature": {},
        "at_other_levels": {},
    }
    for feat in ("B", "K", "Q", "R", "butter1", "butter2", "moving average", "quantised"):
        sub = [r for r in rows if feat in r["features"]]
        s["by_feature"][feat] = {
            "lines": _rate(sum(bool(r["lines_found"]) for r in sub), len(sub)),
            "outliers": _rate(sum(r["outliers"] for r in sub), len(sub)),
        }
    for band, lo, hi in (("fs < 10 Hz", 0, 10), ("10–200 Hz", 10, 200), ("fs ≥ 200 Hz", 200, 1e9)):
        sub = [r for r in rows if lo <= r["fs"] < hi]
        s["by_feature"][band] = {
            "lines": _rate(sum(bool(r["lines_found"]) for r in sub), len(sub)),
            "outliers": _rate(sum(r["outliers"] for r in sub), len(sub)),
        }
    for a in (0.005, 0.01, 0.02, 0.05):
        s["at_other_levels"][str(a)] = {
            "lines": _rate(sum(r["lines_p"] <= a for r in rows), n),
            "outliers": _rate(sum(r["outliers_p"] <= a for r in rows), n),
            "outliers_exact_gaussian_null": _rate(sum(r["outliers_p_gaussian"] <= a for r in rows), n),
        }
    s["cpu_s_median"] = {
        "lines": float(np.median([r["cpu_lines_s"] for r in rows])),
        "outliers": float(np.median([r["cpu_outliers_s"] for r in rows])),
    }
    return s


def _pct(r) -> str:
    lo, hi = r["ci95"]
    return f"{r['alarms']} / {r['records']} = {100 * r['rate']:.2f} % [{100 * lo:.2f}, {100 * hi:.2f}]"


def markdown(s) -> str:
    m = s["machine"]
    lines = [
        "# False alarms of the line search and the outlier test on null records",
        "",
        "Written by `benches/periodic_outliers_null.py` (records described in its docstring: fs 1 Hz – 2 kHz, "
        "10⁵–10⁶ samples, Q/N/B/K/R mixtures, low-passes, quantisers). A record with any line found, or with "
        "outliers accepted, is a false alarm. Rates: alarms / records [95 % Clopper–Pearson].",
        "",
        f"Machine: {m.get('cpu_model', '?')}, {m.get('git_commit')}; load average at start "
        f"{m.get('loadavg_start')}, at end {s.get('loadavg_end')}; {s['seconds']:.0f} s in all; median "
        f"CPU per record: lines {s['cpu_s_median']['lines']:.2f} s, outliers {s['cpu_s_median']['outliers']:.2f} s.",
        "",
        "| test | share of level | α per record | false alarms |",
        "|---|---|---|---|",
        f"| lines (`sinusoid`, `periodic`) | {LINE_SHARE} | {100 * s['alpha']['lines']:.2f} % | {_pct(s['lines'])} |",
        f"| outliers | {OUTLIER_SHARE} | {100 * s['alpha']['outliers']:.2f} % | {_pct(s['outliers'])} |",
        f"| either | {LINE_SHARE + OUTLIER_SHARE} | {100 * (s['alpha']['lines'] + s['alpha']['outliers']):.2f} % "
        f"| {_pct(s['either'])} |",
        "",
        f"The outlier test abstained on {s['outliers_abstained']} records (quantisation too coarse for its "
        "Gaussian-lattice model: the samples' standard deviation in a block is below 0.7 step).",
        "",
        "## By feature",
        "",
        "| records with | lines | outliers |",
        "|---|---|---|",
    ]
    for feat, r in s["by_feature"].items():
        lines.append(f"| {feat} | {_pct(r['lines'])} | {_pct(r['outliers'])} |")
    lines += [
        "",
        "## The same records at other levels (each record's Bonferroni p-value)",
        "",
        "| α | lines | outliers | outliers against an exact Gaussian null (count vs λ, not 2λ) |",
        "|---|---|---|---|",
    ]
    for a, r in s["at_other_levels"].items():
        lines.append(
            f"| {100 * float(a):g} % | {_pct(r['lines'])} | {_pct(r['outliers'])} "
            f"| {_pct(r['outliers_exact_gaussian_null'])} |"
        )
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--records", type=int, default=640)
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args(argv)
    out = a.out or (Path(tempfile.mkdtemp()) if a.quick else HERE / "results")
    report = run(12 if a.quick else a.records, out)
    print(markdown(report))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
