#!/usr/bin/env python3
"""Calibration of the line-constancy test behind ``Refinement.unexplained``'s ``"line"`` check
(:func:`allanite.model.refinement._line_constancy.line_constancy`), called alone on clean records with a
constant line, and its power on the two changing lines it must still flag.

- **Null**: per mixture, records of white, flicker, rate random walk and low-passed noise at 1–400 Hz, each
  with one constant line (amplitude log-uniform 0.01–1 × the noise's σ over its first 10⁴ samples, random
  phase) at a frequency drawn log-uniformly from the lowest the test takes (4 blocks of 20 periods) to fs/8;
  the test at the line's own frequency. A rate at α is the share of records with p ≤ α, with its 95 %
  Clopper–Pearson interval; calibrated: the interval holds α.
- **Families** (``--families``): the check's other kind of line — the strongest line of a ``"periodic"``
  family refine removed in time. Per mixture, records of white + flicker with one constant family (a square
  wave, or an AM carrier; frequencies, amplitude and phase drawn per record), each through the default
  ``allanite.refine``; for every record where a family was removed, the test's p-value at its strongest
  line on the final samples (what :func:`allanite.model.refinement._line_check.line_check` tests) and
  whether the check said anything (the p-value before, the saying after its materiality rule).
- **Power** (``--power``): the default ``allanite.refine`` of refine_blind2's "line switched on halfway" record
  and of ADIS16405 run 2 acc_y (its rising 0.57 Hz site line), with what the ``"line"`` check said.

Usage::

    python benches/line_constancy_null.py                    # -> benches/results/line_constancy_null.{json,md}
    python benches/line_constancy_null.py --records 100      # fewer records per mixture
    python benches/line_constancy_null.py --before OLD.json  # a "before" column from an earlier run's json
    python benches/line_constancy_null.py --power            # also the two refines (≈ a minute each)
    python benches/line_constancy_null.py --families 200     # the families' null, 200 records per mixture
"""

from __future__ import annotations

import argparse
import json
import math
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
from scipy import signal

import _common
import allanite
from allanite.model.refinement._line_constancy import MIN_PERIODS, line_constancy

HERE = Path(__file__).resolve().parent
LEVELS = (0.05, 0.01, 6.25e-4)  # 5 %, 1 % and the check's own α on one line (its share 0.0125 of level 0.05)
#: name -> (fs, samples, simulate's terms, low-pass (order, cutoff as a fraction of Nyquist) or None)
MIXES = {
    "white, 100 Hz × 10⁵": (100.0, 100_000, {"N": 1e-2}, None),
    "white + flicker, 100 Hz × 10⁵": (100.0, 100_000, {"N": 1e-4, "B": 1e-2}, None),
    "white + flicker + RRW, 200 Hz × 2·10⁵": (200.0, 200_000, {"N": 1e-4, "B": 1e-2, "K": 1e-3}, None),
    "white + flicker + RRW, 1 Hz × 10⁵": (1.0, 100_000, {"N": 1e-3, "B": 1e-3, "K": 3e-5}, None),
    "white + RRW, 400 Hz × 4·10⁵": (400.0, 400_000, {"N": 1e-4, "K": 1e-2}, None),
    "white + RRW low-passed (2nd order, fs/40), 100 Hz × 10⁵": (100.0, 100_000, {"N": 2e-3, "K": 2e-5}, (2, 0.05)),
    "white + flicker, 100 Hz × 10⁵, the line at 10 Hz": (100.0, 100_000, {"N": 1e-4, "B": 1e-2}, None),
}
#: mixtures whose line is at one frequency (Hz), not drawn
FIXED_F0 = {"white + flicker, 100 Hz × 10⁵, the line at 10 Hz": 10.0}


def record(mix: str, seed: int) -> tuple[np.ndarray, float, float]:
    """A clean record of ``mix`` with one constant line: (samples, fs, the line's frequency)."""
    fs, n, terms, lp = MIXES[mix]
    rng = np.random.default_rng(seed)
    y = allanite.simulate(n, fs, seed=rng, **terms)
    if lp is not None:
        b, a = signal.butter(lp[0], lp[1])
        y = signal.lfilter(b, a, y)
    f_lo = 4 * MIN_PERIODS * fs / n * 1.001
    f0 = FIXED_F0.get(mix, float(f_lo * (fs / 8 / f_lo) ** rng.uniform()))
    amp = float(np.std(y[: min(n, 10_000)])) * 10 ** rng.uniform(-2, 0)
    return y + amp * np.sin(2 * np.pi * f0 * np.arange(n) / fs + rng.uniform(0, 2 * math.pi)), fs, f0


def _p(args: tuple[str, int]) -> tuple[float, int]:
    y, fs, f0 = record(*args)
    r = line_constancy(y, fs, f0, 0.01)
    return float(r["p_value"]), int(r["blocks"])


def null(records: int, processes: int, only: str | None = None) -> dict:
    rows = {}
    for i, mix in enumerate(MIXES):
        if only and only not in mix:
            continue
        t0 = time.perf_counter()
        jobs = [(mix, 1_000_003 * i + 7919 * k) for k in range(records)]
        with ProcessPoolExecutor(processes) as ex:
            got = list(ex.map(_p, jobs, chunksize=8))
        p = np.array([g[0] for g in got])
        rows[mix] = {
            "records": records,
            "rates": _common.rejection_rates(p, LEVELS),
            "p_quantiles": {f"{q:g}": float(np.quantile(p, q)) for q in (0.01, 0.05, 0.1, 0.5)},
            "blocks_median": float(np.median([g[1] for g in got])),
            "seconds": time.perf_counter() - t0,
        }
        _common.log(f"{mix}: " + ", ".join(_common.rate_cell(r, True) for r in rows[mix]["rates"].values()))
    return rows


#: a family's tested line is "on frequency" where the removal's drift from the true line over the record moves
#: the line by at most this many of a block phasor's noise SD (A·2π·|f̂ − f|·T): beyond, the removal left a line
#: whose phase turns along the record, a real change the test should find
MAX_DRIFT_SD = 0.5
#: name -> (fs, samples, simulate's terms, the family's kind)
FAMILY_MIXES = {
    "square wave 0.5–5 Hz on white + flicker, 100 Hz × 10⁵": (100.0, 100_000, {"N": 1e-1, "B": 1e-2}, "square"),
    "AM carrier 20–60 Hz × 0.5–3 Hz on white + flicker, 400 Hz × 2·10⁵": (
        400.0,
        200_000,
        {"N": 5e-2, "B": 1e-2},
        "am",
    ),
}


def family_record(mix: str, seed: int) -> tuple[np.ndarray, float, float]:
    """A clean record of ``mix`` with one constant family: a square wave (fundamental log-uniform 0.5–5 Hz) or
    an AM carrier (20–60 Hz, modulation 0.5–3 Hz, depth 0.3–0.8), amplitude 0.3–3 × the noise's σ over its
    first 10⁴ samples, random phases: (samples, fs, the frequency of its strongest line)."""
    fs, n, terms, kind = FAMILY_MIXES[mix]
    rng = np.random.default_rng(seed)
    y = allanite.simulate(n, fs, seed=rng, **terms)
    t = np.arange(n) / fs
    amp = float(np.std(y[: min(n, 10_000)])) * 10 ** rng.uniform(-0.5, 0.5)
    if kind == "square":
        f0 = 0.5 * 10 ** rng.uniform()
        return y + amp * np.sign(np.sin(2 * np.pi * f0 * t + rng.uniform(0, 2 * math.pi))), fs, f0
    fc, fm, depth = rng.uniform(20, 60), 0.5 * 6 ** rng.uniform(), rng.uniform(0.3, 0.8)
    env = 1.0 + depth * np.cos(2 * np.pi * fm * t + rng.uniform(0, 2 * math.pi))
    return y + amp * env * np.sin(2 * np.pi * fc * t + rng.uniform(0, 2 * math.pi)), fs, fc


def _family_p(args: tuple[str, int]) -> dict:
    """refine one record; the p-value of the line check's test at each removed family's tested line (on the
    final samples, as the check sees them) and whether the check said anything."""
    from allanite.model.refinement import missing
    from allanite.model.refinement._line_check import tested_lines

    y, fs, f_true = family_record(*args)
    got: dict = {"p": [], "said": 0, "said_any": 0, "slip": None}
    check = missing.CHECKS["line"]

    def spy(ctx, a):
        for f, fam, _held in tested_lines(ctx):
            if fam is not None:
                r = line_constancy(ctx.y, ctx.fs, f, 0.01, phasors=True)
                got["p"].append(None if r is None else float(r["p_value"]))
                # how far the removal's line drifts from the true one over the record, in block-noise SDs
                slip = abs(f - f_true) * ctx.y.size / ctx.fs
                if r is not None:
                    amp = max(ctx.families[fam][2])
                    got["slip"] = amp * 2 * math.pi * slip / math.sqrt(float(np.mean(r["phasor_var"])))
        out = check(ctx, a)
        got["said"], got["said_any"] = sum("family" in u for u in out), len(out)
        return out

    missing.CHECKS["line"] = spy
    try:
        r = allanite.refine(y, fs, progress=False)
    finally:
        missing.CHECKS["line"] = check
    got["periodic"] = "periodic" in r.found
    return got


def family_null(records: int, processes: int) -> dict:
    rows = {}
    for i, mix in enumerate(FAMILY_MIXES):
        t0 = time.perf_counter()
        jobs = [(mix, 2_000_003 * i + 7919 * k) for k in range(records)]
        with ProcessPoolExecutor(processes) as ex:
            got = list(ex.map(_family_p, jobs, chunksize=4))
        p = np.array([q for g in got for q in g["p"] if q is not None])
        on = np.array([g["p"][0] for g in got if g["p"] and g["p"][0] is not None and g["slip"] <= MAX_DRIFT_SD])
        rows[mix] = {
            "records": records,
            "removed": sum(g["periodic"] for g in got),
            "tested": int(p.size),
            "untestable": sum(q is None for g in got for q in g["p"]),
            "rates": _common.rejection_rates(p, LEVELS),
            "p_quantiles": {f"{q:g}": float(np.quantile(p, q)) for q in (0.01, 0.05, 0.1, 0.5)},
            "on_frequency": int(on.size),
            "rates_on_frequency": _common.rejection_rates(on, LEVELS) if on.size else None,
            "slips": sorted(float(g["slip"]) for g in got if g["slip"] is not None)[-5:],
            "said": sum(g["said"] for g in got),
            "said_any": sum(g["said_any"] for g in got),
            "seconds": time.perf_counter() - t0,
        }
        _common.log(f"{mix}: " + ", ".join(_common.rate_cell(r, True) for r in rows[mix]["rates"].values()))
    return rows


def _line_entries(r) -> list[str]:
    from allanite.model.refinement.words import describe_region

    return [describe_region(u) for u in r.unexplained if u["domain"] == "line"]


def power() -> dict:
    import refine_blind2 as rb2

    out = {}
    case = next(c for c in rb2.CASES if "switched on halfway" in c.name)
    y, fs, _ch, _kw, _comp = case.build(np.random.default_rng(case.seed))
    t0 = time.perf_counter()
    r = allanite.refine(y, fs, unit="deg/s", progress=False)
    out[case.name] = {"found": r.found, "line": _line_entries(r), "seconds": time.perf_counter() - t0}
    path = _common.shared_data_dir() / "adis16405" / "adis16405_run2_100Hz.csv.gz"
    if path.exists():
        x = np.asarray(allanite.read_log(path, fs=100.0, columns=["acc_y"]).data, dtype=np.float64).ravel()
        t0 = time.perf_counter()
        r = allanite.refine(x, 100.0, progress=False)
        out["ADIS16405 run 2 acc_y"] = {"found": r.found, "line": _line_entries(r), "seconds": time.perf_counter() - t0}
    for k, v in out.items():
        _common.log(f"{k}: {v['line'] or 'no line entry'}")
    return out


def write(results: dict, before: dict | None, out: Path) -> None:
    lines = [
        "# The line-constancy test on clean records with a constant line",
        "",
        results.get("run_line") or f"`python benches/line_constancy_null.py` — {_common.machine_line()}.",
        "",
        "Each record: one mixture's noise plus one constant line (random phase, amplitude 0.01–1 × the noise's "
        "σ) at a frequency log-uniform from the lowest the test takes (4 blocks of 20 periods) to fs/8, tested "
        "at that frequency (`line_constancy`, called alone; in the last mixture always at 10 Hz). Rejections at α with their 95 % Clopper–Pearson "
        "interval; calibrated where the interval holds α. The check's own α on one line is 6.25·10⁻⁴.",
        "",
    ]
    head = "| mixture | blocks (median) | at 5 % | at 1 % | at 6.25·10⁻⁴ | p quantiles 1 / 5 / 10 / 50 % |"
    kept = results.get("before_cells") if not before else None  # the before columns as an earlier page wrote them
    if before or kept:
        head += " before: at 5 % | before: at 1 % |"
    lines += [head, "|" + "---|" * (head.count("|") - 1)]
    for mix, v in results["null"].items():
        q = v["p_quantiles"]
        cells = [_common.rate_cell(r, True) for r in v["rates"].values()]
        row = f"| {mix} | {v['blocks_median']:.0f} | " + " | ".join(cells)
        row += f" | {q['0.01']:.4f} / {q['0.05']:.3f} / {q['0.1']:.3f} / {q['0.5']:.2f} |"
        if kept:
            row += " " + " | ".join(kept.get(mix, ["—", "—"])) + " |"
        elif before:
            b = before["null"].get(mix)
            if b is None:
                row += " — | — |"
            else:
                row += (
                    f" {_common.rate_cell(b['rates']['0.05'], True)} | {_common.rate_cell(b['rates']['0.01'], True)} |"
                )
        lines.append(row)
    if results.get("families"):
        lines += _family_lines(results["families"], results.get("families_run_line", ""))
    if results.get("power"):
        lines += ["", "## Power: the changing lines the check must flag", ""]
        for k, v in results["power"].items():
            said = "; ".join(v["line"]) or "**nothing said**"
            lines.append(f'- *{k}* — found {", ".join(v["found"]) or "nothing"}; the `"line"` entry: {said}')
    if results.get("notes"):
        lines += ["", *results["notes"]]
    _common.write_results(out, "line_constancy_null", lines, results)


def _family_lines(rows: dict, run_line: str) -> list[str]:
    out = [
        "",
        "## Families removed in time: the strongest line of a constant family",
        "",
        run_line,
        "",
        "Each record: white + flicker with one constant family (random frequencies, amplitude 0.3–3 × the "
        "noise's σ, random phases) through the default `allanite.refine`; where a `periodic` family was removed, "
        'the line test\'s p-value at its strongest line on the final samples (the line the `"line"` check tests) '
        "and whether the check said a change (after its materiality rule, at its own α split over the lines "
        "tested). *On frequency*: the records whose removed line drifts from the true one over the record by "
        f"at most {MAX_DRIFT_SD} of a block phasor's noise SD (A·2π·|f̂ − f|·T) — the test's own null; beyond, "
        "the removal left a line whose phase turns along the record, a real change for the test to find (the "
        "largest drifts in the json's `slips`).",
        "",
        "| mixture | records | family removed | lines tested | at 5 % | at 1 % | at 6.25·10⁻⁴ | p quantiles 1 / 5 / 10 / 50 % "
        "| said: the family's line | said: any line | on frequency: lines | on frequency: at 5 % | at 1 % | at 6.25·10⁻⁴ |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for mix, v in rows.items():
        q = v["p_quantiles"]
        cells = " | ".join(_common.rate_cell(r, True) for r in v["rates"].values())
        out.append(
            f"| {mix} | {v['records']} | {v['removed']} | {v['tested']} | {cells} | "
            f"{q['0.01']:.2g} / {q['0.05']:.3f} / {q['0.1']:.3f} / {q['0.5']:.2f} | {v['said']} | {v['said_any']} | "
            f"{v['on_frequency']} | "
            + " | ".join(_common.rate_cell(r, True) for r in v["rates_on_frequency"].values())
            + " |"
        )
    return out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--records", type=int, default=400)
    ap.add_argument("--processes", type=int, default=2)
    ap.add_argument("--power", action="store_true")
    ap.add_argument("--families", type=int, default=0, help="records per family mixture (0: none)")
    ap.add_argument("--only-families", action="store_true", help="the families' null alone (keep the json's)")
    ap.add_argument("--only", help="only the mixtures whose name contains this text")
    ap.add_argument("--before", type=Path, help="an earlier run's json: its rates as a 'before' column")
    ap.add_argument("--notes", type=Path, help="a text file whose paragraphs end the page")
    ap.add_argument("--out", type=Path, default=HERE / "results")
    ap.add_argument("--from-json", type=Path, help="write the page from this run's json, computing nothing")
    a = ap.parse_args(argv)
    before = json.loads(a.before.read_text()) if a.before else None
    if a.from_json or a.only_families:
        results = json.loads((a.from_json or a.out / "line_constancy_null.json").read_text())
        if not a.from_json and "run_line" not in results:  # the null's tables keep the line of their own run
            results["run_line"] = (a.out / "line_constancy_null.md").read_text().split("\n")[2]
    else:
        results = {"null": null(a.records, a.processes, a.only)}
        write(results, before, a.out)  # the null's page first: the refines take minutes
    if a.families and not a.from_json:
        results["families"] = family_null(a.families, a.processes)
        results["families_run_line"] = f"`--families {a.families}` — {_common.machine_line()}."
    if a.power and not (a.from_json or a.only_families):
        results["power"] = power()
    if a.notes:
        results["notes"] = a.notes.read_text().strip().split("\n")
    write(results, before, a.out)


if __name__ == "__main__":
    main()
