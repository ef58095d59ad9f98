#!/usr/bin/env python3
"""``allanite.refine`` on measured data: the six ADIS16405 runs and the real IMU Allan curves.

For each record (ADIS: 3 gyro axes × 6 runs, 10⁶ samples at 100 Hz, °/s; avar-curves: every gyro/accel
channel of the KVH1750, IMAR, LN200, NavChip and ADIS curves shipped with the R package ``avar``, units as
stored there): the five-term model's residual (χ²/dof, RMS z, RMS ADEV error), the effects ``refine``
traced it to with their parameters and intervals, and the error before and after (in-sample and held-out).
Nothing is tuned per record: every call is ``refine(x, fs)`` / ``refine(curve)`` with default arguments, all τ
(the sensors' bandwidth is a candidate effect), every gyro and accelerometer channel. The time of each ADIS
refine (10⁶ samples) is recorded with the machine's load average.

Usage::

    python benches/refine_measured.py            # -> benches/results/refine.{json,md}
    python benches/refine_measured.py --quick    # one ADIS axis and one curve, to a temporary folder
    python benches/refine_measured.py --processes 4   # the ADIS channels in 4 processes (same rows)
    python benches/refine_measured.py --only "run 3 acc_x" --only "run 4 acc_z" --out /tmp/r   # some records
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

import _common
import allanite
from _common import load_avar_curve
from allanite.model.effects import format_param
from allanite.model.refinement.words import describe_region

HERE = Path(__file__).resolve().parent

AXES = ["gyro_x", "gyro_y", "gyro_z", "acc_x", "acc_y", "acc_z"]


def summarize(name, r) -> dict:
    s0 = r.start
    row = {
        "record": name,
        "start_chi2_dof": s0.chi2_dof,
        "start_rms_z": float(np.sqrt(np.mean(s0.z**2))),
        "start_rms_adev_pct": r.rms_adev_pct(s0),
        "start_heldout_rms_adev_pct": r.start_heldout_rms_adev_pct,
        "final_chi2_dof": r.fit.chi2_dof,
        "final_rms_adev_pct": r.rms_adev_pct(r.fit),
        "steps": [],
        "unexplained": [_jsonable(u) | {"text": describe_region(u)} for u in r.unexplained],
        "still_missing": r.missing_sentences(),
    }
    for st in r.steps:
        step = {
            "effect": st.effect,
            "params": _jsonable(st.params),
            "intervals": _jsonable(st.intervals),
            "final_params": _jsonable(st.final_params),
            "final_intervals": _jsonable(st.final_intervals),
            "before": st.before,
            "after": st.after,
            "evidence": _jsonable(st.evidence),
        }
        row["steps"].append(step)
    return row


def _jsonable(v):
    if isinstance(v, dict):
        return {k: _jsonable(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_jsonable(x) for x in v]
    if isinstance(v, (np.floating, np.integer)):
        return v.item()
    return v


def _adis_row(k: int, ax: str) -> dict:
    """One ADIS channel refined with the default call, its row with the time and the load it ran under."""
    path = _common.shared_data_dir() / "adis16405" / f"adis16405_run{k}_100Hz.csv.gz"
    log = allanite.read_log(path, fs=100.0, columns=[ax])
    x = np.asarray(log.data, dtype=np.float64).ravel()
    load = os.getloadavg()[0]
    t0 = time.perf_counter()
    r = allanite.refine(x, 100.0, progress=False)
    row = summarize(f"ADIS16405 run {k} {ax}", r)
    row["seconds"] = time.perf_counter() - t0
    row["load_1min"] = load
    print(
        f"{row['record']}: χ²/dof {row['start_chi2_dof']:.2f} → {row['final_chi2_dof']:.2f}, "
        f"found {[s['effect'] for s in row['steps']]}",
        flush=True,
    )
    return _jsonable(row)


def run(quick: bool, out: Path, processes: int = 1, only=None) -> dict:
    """Refine every record (``only``: the records whose name contains one of these texts) and write the
    results to ``out``."""
    rows: dict = {"adis": [], "curves": []}
    data = _common.shared_data_dir()
    runs = [1] if quick else range(1, 7)
    jobs = [(k, ax) for k in runs for ax in (AXES[:1] if quick else AXES)]
    if only:
        jobs = [(k, ax) for k, ax in jobs if any(t in f"ADIS16405 run {k} {ax}" for t in only)]
    if processes > 1:  # the records are independent: in that many processes, rows kept in order
        with ProcessPoolExecutor(processes) as pool:
            rows["adis"] = list(pool.map(_adis_row, *zip(*jobs)))
    else:
        rows["adis"] = [_adis_row(k, ax) for k, ax in jobs]
    files = sorted((data / "avar-curves").glob("*_av.csv"))
    for f in files[:1] if quick else files:
        cur = load_avar_curve(f)
        for ch, res in cur["channels"].items():
            if only and not any(t in f"{cur['sensor']} {ch}" for t in only):
                continue
            try:
                r = allanite.refine(res)
            except allanite.AllaniteError as exc:
                rows["curves"].append({"record": f"{cur['sensor']} {ch}", "error": str(exc)})
                continue
            row = summarize(f"{cur['sensor']} {ch}", r)
            rows["curves"].append(row)
            print(
                f"{row['record']}: χ²/dof {row['start_chi2_dof']:.2f} → {row['final_chi2_dof']:.2f}, "
                f"found {[s['effect'] for s in row['steps']]}",
                flush=True,
            )
    out.mkdir(parents=True, exist_ok=True)
    (out / "refine.json").write_text(json.dumps(rows, indent=1, default=float))
    write_md(rows, out / "refine.md")
    return rows


def _fmt_params(st):
    """Parameters at acceptance with their intervals; where the final joint refit changed one, its final value
    after "→ final:" (units: the table's header)."""
    out = "; ".join(format_param(k, v, st["intervals"].get(k), "", 3) for k, v in st["params"].items())
    fp, fi = st.get("final_params") or {}, st.get("final_intervals") or {}
    changed = [k for k, v in fp.items() if v != st["params"].get(k) or fi.get(k) != st["intervals"].get(k)]
    if changed:
        out += " → final: " + "; ".join(format_param(k, fp[k], fi.get(k), "", 3) for k in changed)
    w = (st.get("evidence") or {}).get("window_levels")
    if w:  # a change point: what found it (its before = after on the record's curve), without → with it
        ho = st["evidence"].get("heldout_test") or {}
        out += (
            f" (windows' levels: χ²/dof {w['before']['chi2_dof']:.2f} → {w['after']['chi2_dof']:.2f}, RMS ADEV "
            f"{w['before']['rms_adev_pct']:.1f} → {w['after']['rms_adev_pct']:.1f} %; held out per segment "
            f"{_ho({'heldout_rms_adev_pct': ho.get('before')})} → {_ho({'heldout_rms_adev_pct': ho.get('after')})} %)"
        )
    return out


def _ho(d):
    v = d.get("heldout_rms_adev_pct")
    return "n/a" if v is None else f"{v:.1f}"


def write_md(rows, path: Path) -> None:
    L = [
        "# `refine` on measured data",
        "",
        "Written by `benches/refine_measured.py`. Per record: the five-term model's residual, what it was traced to, "
        "the parameters added (input unit's base form: σ and amplitude in the rate unit — °/s for gyros, g for "
        'accelerometers —, T_c and t in s, f0 and cutoff in Hz; at acceptance, and after "→ final:" what the '
        "final joint refit changed) and the error before → after on the record's Allan curve (each step's before "
        "is the previous step's after): χ²/dof on the calibrated tests' covariance (generalised least squares on their thinned τ, `Refinement.start_errors`/`final_errors`; the five-term column is the plain fit's own, EDF-weighted), RMS of the ADEV error in % (4 τ per "
        "octave whose estimate is within ±10 %) in-sample and held out (8 alternate blocks: fit on the odd ones, "
        "predict the even ones' curve and back; n/a for curves without samples). Default call `refine(x, 100.0)` "
        "/ `refine(curve)`: all τ. Change points are tested on 16 non-overlapping windows (ADIS only); a change "
        "of noise level leaves the record's curve model as it is (the curve of a record whose level steps is the "
        "length-weighted mean of its segments' curves, a model of the same terms), so on the chain its before and "
        "after are the same numbers; in brackets what found it, each change point without → with it (the earlier "
        "ones in both): the windows' Allan variances about piecewise levels, and held out per segment. A spectral "
        "line's amplitude (its power in the spectrum) and f0 are measured in the samples and held in every fit "
        "of the curve, the final joint refit included.",
        "",
        "| record | five-term χ²/dof | RMS ADEV err (held out) | traced to | parameters | χ²/dof before → after "
        "| RMS ADEV err before → after | held-out err before → after |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for group in ("adis", "curves"):
        for row in rows[group]:
            if "error" in row:
                L.append(f"| {row['record']} | — | — | not fitted: {row['error']} | | | | |")
                continue
            if not row["steps"]:
                L.append(
                    f"| {row['record']} | {row['start_chi2_dof']:.2f} | {row['start_rms_adev_pct']:.1f} % "
                    f"({_ho({'heldout_rms_adev_pct': row['start_heldout_rms_adev_pct']})}) | nothing added | | | | |"
                )
            for i, st in enumerate(row["steps"]):
                head = (
                    f"| {row['record']} | {row['start_chi2_dof']:.2f} | {row['start_rms_adev_pct']:.1f} % "
                    f"({_ho({'heldout_rms_adev_pct': row['start_heldout_rms_adev_pct']})}) "
                    if i == 0
                    else "| | | "
                )
                L.append(
                    head + f"| {st['effect']} | {_fmt_params(st)} | {st['before']['chi2_dof']:.2f} → "
                    f"{st['after']['chi2_dof']:.2f} | {st['before']['rms_adev_pct']:.1f} → "
                    f"{st['after']['rms_adev_pct']:.1f} % | {_ho(st['before'])} → {_ho(st['after'])} |"
                )
            if row.get("unexplained"):  # what the final model still misses, in the report's words
                L.append(f"| | | | still missing | {'; '.join(u['text'] for u in row['unexplained'])} | | | |")
    n_adis = len(rows["adis"])
    found = {}
    for row in rows["adis"] + rows["curves"]:
        for st in row.get("steps", []):
            found[st["effect"]] = found.get(st["effect"], 0) + 1
    secs = [row["seconds"] for row in rows["adis"] if "seconds" in row]
    loads = [row["load_1min"] for row in rows["adis"] if "load_1min" in row]
    if secs:
        L += [
            "",
            f"Time of one default `refine` on a 10⁶-sample ADIS channel: median {np.median(secs):.1f} s, max "
            f"{max(secs):.1f} s (1-minute load average {min(loads):.1f}–{max(loads):.1f} on 2 cores, shared).",
        ]
    L += [
        "",
        f"Effects found over {n_adis} ADIS channels and {len(rows['curves'])} curve channels: "
        + (", ".join(f"{k} × {v}" for k, v in sorted(found.items())) or "none")
        + ".",
        "",
    ]
    path.write_text("\n".join(L))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", type=Path)
    ap.add_argument("--processes", type=int, default=1, help="refine the ADIS channels in this many processes")
    ap.add_argument(
        "--only",
        action="append",
        metavar="TEXT",
        help='only the records whose name contains TEXT (repeatable; e.g. "run 3 acc_x", "acc_", "KVH")',
    )
    a = ap.parse_args(argv)
    out = a.out or (Path(tempfile.mkdtemp()) if a.quick or a.only else HERE / "results")
    run(a.quick, out, a.processes, a.only)
    print(f"wrote {out / 'refine.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
