#!/usr/bin/env python3
"""The line search and the outlier test on the six ADIS16405 static runs, with default arguments.

For each run and gyro axis (10⁶ samples at 100 Hz, °/s, LSB 0.05 °/s): every line found at the line search's
α = 1 % (frequency, PSD ratio over its threshold), the families and lone sinusoids they make (fundamentals with
their ±1σ, lines, RMS), and the outlier test at α = 0.25 % (counts of difference clusters beyond 4–7 σ against
the Gaussian expectation; when accepted, the flagged samples' times, the cut and the share). The ADIS logs have
a weak 0.54–0.57 Hz site line (a wandering one: longer segments do not sharpen it) and a ~19–22 Hz pair on z;
run 4 was bumped (all three gyros at once at 117.1 s and 4045–4046 s).

Usage::

    python benches/periodic_outliers_measured.py         # -> benches/results/periodic_outliers_measured.{json,md}
    python benches/periodic_outliers_measured.py --quick # run 1 only, to a temporary folder
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from pathlib import Path

import numpy as np

import _common
import allanite
from allanite.model import outliers, periodic
from periodic_outliers_null import LEVEL, LINE_SHARE, OUTLIER_SHARE

HERE = Path(__file__).resolve().parent
FS = 100.0
AXES = ("gyro_x", "gyro_y", "gyro_z")


def one(y: np.ndarray) -> dict:
    t0 = time.process_time()
    ps = periodic.periodic_search(y, FS, LEVEL * LINE_SHARE)
    t1 = time.process_time()
    ot = outliers.outlier_test(y, FS, LEVEL * OUTLIER_SHARE)
    t2 = time.process_time()
    row = {
        "lines": [
            {"f": float(ln["f"]), "ratio": float(ln["psd_ratio"]), "threshold": float(ln["threshold"])}
            for ln in ps["lines"]
        ],
        "line_p_value": float(ps["p_value"]),
        "families": [
            {
                "fundamentals": [float(g) for g in f.gens],
                "sd": [float(s) for s in f.gens_sd],
                "lines": int(f.coefs.shape[0]),
                "rms": f.rms,
            }
            for f in ps["families"]
        ],
        "sinusoids": [
            {"f0": float(s.gens[0]), "sd": float(s.gens_sd[0]), "amplitude": float(s.amplitudes[0])}
            for s in ps["sinusoids"]
        ],
        "outliers": {
            "accepted": bool(ot["accepted"]),
            "cuts": [{k: c[k] for k in ("c", "count", "expected", "p_value")} for c in ot["cuts"]],
            "note": ot.get("note"),
        },
        "cpu_s": {"lines": t1 - t0, "outliers": t2 - t1},
    }
    if ot["accepted"]:
        at = np.flatnonzero(ot["flags"])
        row["outliers"].update(
            cut=ot["cut"], rate=ot["rate"], threshold=ot["threshold"], flagged_s=[float(i / FS) for i in at]
        )
    return row


def run(runs, out: Path) -> dict:
    data = _common.shared_data_dir() / "adis16405"
    rows = {}
    for k in runs:
        path = data / f"adis16405_run{k}_100Hz.csv.gz"
        if not path.is_file():
            raise SystemExit(f"{path} not found (set ALLANITE_SHARED_DATA)")
        y = allanite.read_log(path, fs=FS, columns=list(AXES), unit="deg/s").data
        for j, ax in enumerate(AXES):
            rows[f"run{k} {ax}"] = one(y[:, j])
            _common.log(f"run {k} {ax}: {rows[f'run{k} {ax}']['cpu_s']}")
    rep = {"rows": rows, "machine": _common.machine_info(), "loadavg_end": list(os.getloadavg())}
    out.mkdir(parents=True, exist_ok=True)
    (out / "periodic_outliers_measured.json").write_text(json.dumps(rep, indent=1))
    (out / "periodic_outliers_measured.md").write_text(markdown(rep))
    return rep


def _times(ts) -> str:
    """Flagged times grouped into events (gaps > 1 s)."""
    if not ts:
        return "—"
    groups, start, last, count = [], ts[0], ts[0], 1
    for t in ts[1:]:
        if t - last > 1.0:
            groups.append((start, last, count))
            start, count = t, 0
        last = t
        count += 1
    groups.append((start, last, count))
    return "; ".join(f"{a:.2f} s" + (f"–{b:.2f} s" if b > a else "") + f" ({c})" for a, b, c in groups)


def markdown(rep) -> str:
    m = rep["machine"]
    lines = [
        "# Line search and outlier test on the ADIS16405 runs (default arguments)",
        "",
        "Written by `benches/periodic_outliers_measured.py`. Lines at α = 1 % (refine's line share), outliers at "
        f"α = 0.25 % (the proposed outlier share). {m.get('cpu_model')}, {m.get('git_commit')}, load average "
        f"{m.get('loadavg_start')} → {rep['loadavg_end']}.",
        "",
        "| record | lines (Hz: ratio/threshold) | families | sinusoids (f0 ± σ Hz, amplitude °/s) "
        "| outliers: clusters beyond 4/5/6/7 σ (Gaussian expectation) | flagged (events) | CPU s lines / outliers |",
        "|---|---|---|---|---|---|---|",
    ]
    for name, r in rep["rows"].items():
        ls = ", ".join(f"{ln['f']:.3f}: {ln['ratio'] / ln['threshold']:.2f}" for ln in r["lines"]) or "—"
        fams = "; ".join(
            ", ".join(f"{g:.4g}" for g in f["fundamentals"]) + f" ({f['lines']} lines, RMS {f['rms']:.3g})"
            for f in r["families"]
        )
        sins = "; ".join(f"{s['f0']:.4f} ± {s['sd']:.1g}, {s['amplitude']:.3g}" for s in r["sinusoids"]) or "—"
        o = r["outliers"]
        cuts = ", ".join(f"{c['count']} ({c['expected']:.2g})" for c in o["cuts"])
        flagged = f"{o['rate'] * 1e6:.0f} ppm at {o['cut']:g} σ: {_times(o['flagged_s'])}" if o["accepted"] else "none"
        cpu = f"{r['cpu_s']['lines']:.1f} / {r['cpu_s']['outliers']:.2f}"
        lines.append(f"| {name} | {ls} | {fams or '—'} | {sins} | {cuts} | {flagged} | {cpu} |")
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args(argv)
    out = a.out or (Path(tempfile.mkdtemp()) if a.quick else HERE / "results")
    rep = run([1] if a.quick else range(1, 7), out)
    print(markdown(rep))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
