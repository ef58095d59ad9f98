#!/usr/bin/env python3
"""Calibration of two checks of ``Refinement.unexplained`` on clean simulated records (issue 29, item 4).

- **Curve-only input** (an Allan curve without its samples, one τ per octave — as the real IMU curves of
  ``../shared/data/avar-curves``): the ``"allan"`` check (one-sided GLS score of one more column, the curve-only
  family with the sinusoids' nulls) and the ``"fit"`` check (the whole curve's GLS χ² once the model's fitted
  directions are refitted: two-sided), each against its bootstrap under the five-term fit, as refine runs them
  after its last step. Clean curves: random five-term mixtures — white noise always, quantisation, flicker,
  random walk and ramp each with some probability, their corners placed log-uniformly along the τ range —,
  1·10⁴–10⁶ samples at 1, 100 or 400 Hz. ``--refine K`` also runs the default ``allanite.refine(curve)`` on the
  first K of them and counts anything added or flagged.
- **The noise level along the record** (``"level"`` check, :func:`allanite.model.noise_level.level_test`): the
  Allan variance at τ₀ in blocks against its simulated null, on the clean records of
  ``refine_false_alarms.py`` (its eight mixtures) and a 2nd-order low-pass filtered one (correlated
  differences: the batch means must carry the correlation).

A p-value is (1 + #{draws ≥ statistic}) / (1 + draws); a rate at α is the share of records with p ≤ α, with its
95 % Clopper–Pearson interval. A calibrated check's rate is at most its α, at its own share of ``level`` and at
larger levels (where a few hundred records resolve a rate).

Usage::

    python benches/refine_unexplained_null.py                 # -> benches/results/refine_unexplained_null.{json,md}
    python benches/refine_unexplained_null.py --records 40    # curves; level records = 80 per mixture by default
    python benches/refine_unexplained_null.py --quick         # a few of each, to a temporary folder
"""

from __future__ import annotations

import argparse
import json
import math
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
from scipy import signal

import _common
import allanite
import refine_false_alarms as null
from allanite.model import tracing
from allanite.model.noise_level import level_test
from allanite.model.refinement.calibrated import curve_test
from allanite.model.refinement.curvefit import Curve, solve
from allanite.model.refinement.levels import LEVEL, alpha
from allanite.model.refinement.missing import allan_family

HERE = Path(__file__).resolve().parent
START = ("Q", "N", "B", "K", "R")
N_BOOT = 2000
LEVELS = (0.01, 0.05, 0.1)
TESTS = {
    "unexplained:allan (curve-only)": alpha("unexplained:allan", LEVEL),
    "unexplained:fit (curve-only)": alpha("unexplained:fit", LEVEL),
    "unexplained:level": alpha("unexplained:level", LEVEL),
}
LEVEL_MIXES = (*null.MIXES, "lowpass")


def clean_curve(seed: int):
    """A clean octave Allan curve (AllanResult, overlapping estimator) of a random five-term mixture, and its
    description."""
    rng = np.random.default_rng(seed)
    fs = float(rng.choice([1.0, 100.0, 400.0]))
    n = int(rng.choice([10_000, 100_000, 300_000, 1_000_000]))
    span = n / fs
    nw = 1e-3
    terms = {"N": nw}
    if rng.random() < 0.3:  # quantisation equal to white noise at 1–4 samples
        terms["Q"] = nw * math.sqrt(rng.uniform(1, 4) / fs / 3)
    if rng.random() < 0.6:  # flicker floor meeting white noise at 10⁻⁴…10⁻¹ of the record
        terms["B"] = nw / math.sqrt(0.4413 * span * 10 ** rng.uniform(-4, -1))
    if rng.random() < 0.6:  # random walk meeting white noise at 10⁻³…0.3 of the record
        terms["K"] = nw * math.sqrt(3) / (span * 10 ** rng.uniform(-3, math.log10(0.3)))
    if rng.random() < 0.3:  # ramp meeting white noise at 10⁻²…1 of the record
        terms["R"] = nw * math.sqrt(2 / (span * 10 ** rng.uniform(-2, 0)) ** 3)
    y = allanite.simulate(n, fs, seed=rng, **terms)
    return allanite.avar(y, fs, taus="octave"), {"fs": fs, "n": n, "terms": sorted(terms)}


def curve_p_values(res) -> dict:
    """p-values of the ``"allan"`` (curve-only family) and ``"fit"`` checks on the curve's five-term fit."""
    keep = res.avar > 0
    cur = Curve(res.tau[keep], res.m[keep].astype(np.float64), res.avar[keep], res.fs, res.n_samples + 1, "oavar")
    sol = solve(cur, START, [])
    thin = tracing.thin_indices(cur.tau)
    sub = cur.subset(thin)
    test = curve_test(cur, thin, sol, START, [], True)
    fam = allan_family(sub, START, False)
    s = test.max_statistic(sub.avar, fam)
    draws = test.null_maxima(fam, N_BOOT, seed=7919)
    chi2, null_chi2 = test.gls_chi2(sub.avar), test.null_chi2(N_BOOT, seed=7919)
    return {
        "unexplained:allan (curve-only)": float((1 + np.count_nonzero(draws >= s)) / (1 + draws.size)),
        "unexplained:fit (curve-only)": float((1 + np.count_nonzero(null_chi2 >= chi2)) / (1 + null_chi2.size)),
    }


def level_record(mix: str, seed: int):
    if mix == "lowpass":  # correlated differences: white + random walk through a 2nd-order low-pass at fs/40
        y = allanite.simulate(200_000, 100.0, N=2e-3, K=2e-5, seed=seed)
        b, a = signal.butter(2, 0.05)
        return signal.lfilter(b, a, y), 100.0
    y, fs, _ch = null.record(mix, seed)
    return y, fs


def _curve_task(k: int, refine: bool) -> tuple[dict, dict | None]:
    res, _desc = clean_curve(20_000 + 7919 * k)
    got = curve_p_values(res)
    if not refine:
        return got, None
    r = allanite.refine(res, progress=False)
    return got, {
        "alarm": bool(r.steps or r.unexplained),
        "found": r.found,
        "flagged": [u["domain"] for u in r.unexplained],
    }


def _level_task(mix: str, k: int) -> float | None:
    y, fs = level_record(mix, 90_000 + 1_000_003 * LEVEL_MIXES.index(mix) + 97 * k)
    r = level_test(y, fs, TESTS["unexplained:level"])
    return None if r is None else r["p_value"]


def run(n_curves: int, per_mix: int, n_refine: int, out: Path, processes: int = 1) -> dict:
    t0 = time.perf_counter()
    load = _common.OtherLoad().__enter__()
    p: dict[str, list] = {t: [] for t in TESTS}
    both, refined = 0, {"records": 0, "with_alarm": 0, "found": [], "flagged": []}
    with ProcessPoolExecutor(processes) as pool:
        curves = pool.map(_curve_task, range(n_curves), [k < n_refine for k in range(n_curves)])
        jobs = [(mix, k) for mix in LEVEL_MIXES for k in range(per_mix)]
        levels = pool.map(_level_task, [j[0] for j in jobs], [j[1] for j in jobs])
        for got, ref in curves:
            for t, v in got.items():
                p[t].append(v)
            both += any(v <= TESTS[t] for t, v in got.items())
            if ref is not None:
                refined["records"] += 1
                refined["with_alarm"] += ref["alarm"]
                refined["found"] += ref["found"]
                refined["flagged"] += ref["flagged"]
        by_mix: dict[str, int] = {}
        for (mix, _k), pv in zip(jobs, levels):
            p["unexplained:level"].append(1.0 if pv is None else pv)
            by_mix[mix] = by_mix.get(mix, 0) + int(pv is not None and pv <= TESTS["unexplained:level"])
    load.__exit__(None, None, None)
    tests = {
        t: {"alpha": TESTS[t], "records": len(v), "rates": _common.rejection_rates(v, (TESTS[t], *LEVELS))}
        for t, v in p.items()
    }
    tests["unexplained:level"]["by_mixture"] = by_mix
    report = {
        "level": LEVEL,
        "curves": n_curves,
        "curves_either_check_at_its_alpha": both,
        "curves_either_interval_95": _common.clopper_pearson(both, max(n_curves, 1)),
        "refine_default_on_curves": refined,
        "level_records_per_mixture": per_mix,
        "tests": tests,
        "p_values": p,
        "seconds": time.perf_counter() - t0,
        "other_load": load.fraction,
        "machine": _common.machine_info(),
    }
    out.mkdir(parents=True, exist_ok=True)
    (out / "refine_unexplained_null.json").write_text(json.dumps(report, indent=1))
    (out / "refine_unexplained_null.md").write_text(markdown(report))
    return report


def markdown(report: dict) -> str:
    lines = [
        "# Two checks of `Refinement.unexplained` on clean records",
        "",
        f"Written by `benches/refine_unexplained_null.py` ({_common.machine_line(report['machine'])}; other processes used {100 * (report['other_load'] or 0):.0f} % "
        f"of the CPUs; {report['seconds']:.0f} s). Curve-only checks on {report['curves']} clean octave curves "
        "(random five-term mixtures, 10⁴–10⁶ samples at 1/100/400 Hz, the checks on the five-term fit, "
        f"{N_BOOT} bootstrap draws)"
        + (
            f"; rates rescored at {report['rescored']} from the run's p-values at today's shares"
            if report.get("rescored")
            else ""
        )
        + f"; the level check on {report['level_records_per_mixture']} clean records of "
        f"each of {', '.join(LEVEL_MIXES)}. Rate: records with p ≤ the level, 95 % Clopper–Pearson interval.",
        "",
        "| check | α (its share of 5 %) | records | at α | at 1 % | at 5 % | at 10 % |",
        "|---|---|---|---|---|---|---|",
    ]
    for t, row in report["tests"].items():
        rates = row["rates"]
        cells = [_common.rate_cell(rates[f"{lv:g}"], count=True) for lv in (row["alpha"], *LEVELS)]
        lines.append(f"| {t} | {row['alpha']:g} | {row['records']} | " + " | ".join(cells) + " |")
    lo, hi = report["curves_either_interval_95"]
    lines += [
        "",
        f"Curve-only, either check at its α (what `unexplained` says on a clean curve's five-term fit): "
        f"{report['curves_either_check_at_its_alpha']} of {report['curves']} = "
        f"{100 * report['curves_either_check_at_its_alpha'] / max(report['curves'], 1):.2f} % "
        f"({100 * lo:.2f}–{100 * hi:.2f}; together they may spend {100 * (TESTS['unexplained:allan (curve-only)'] + TESTS['unexplained:fit (curve-only)']):.3g} %).",
    ]
    ref = report["refine_default_on_curves"]
    if ref["records"]:
        rlo, rhi = _common.clopper_pearson(ref["with_alarm"], ref["records"])
        lines.append(
            f"Default `allanite.refine(curve)` on the first {ref['records']} curves: {ref['with_alarm']} with anything "
            f"added or flagged ({100 * rlo:.1f}–{100 * rhi:.1f} %); added {sorted(set(ref['found'])) or 'nothing'}, "
            f"flagged {sorted(set(ref['flagged'])) or 'nothing'}."
        )
    lines.append(
        "Level check by mixture (rejections at its α): "
        + ", ".join(f"{k} {v}" for k, v in report["tests"]["unexplained:level"]["by_mixture"].items())
        + "."
    )
    return "\n".join(lines) + "\n"


def rescore(out: Path) -> dict:
    """Rates at today's shares from a recorded run's p-values (a share moved; the statistics did not).

    Each p-value depends on its record and its test only, not on the test's α, so a change of shares needs no new
    simulation: the rates at α, the curve-only "either check" count and the level check's mixtures are counted
    again; the run's machine, commit, load and time stay those of the recorded run, and the report says when and at
    which commit it was rescored.
    """
    report = json.loads((out / "refine_unexplained_null.json").read_text())
    p = report["p_values"]
    for t, row in report["tests"].items():
        row["alpha"] = TESTS[t]
        row["rates"] = _common.rejection_rates(p[t], (TESTS[t], *LEVELS))
    a, f = p["unexplained:allan (curve-only)"], p["unexplained:fit (curve-only)"]
    both = sum(
        x <= TESTS["unexplained:allan (curve-only)"] or y <= TESTS["unexplained:fit (curve-only)"] for x, y in zip(a, f)
    )
    report["curves_either_check_at_its_alpha"] = both
    report["curves_either_interval_95"] = _common.clopper_pearson(both, max(report["curves"], 1))
    report["rescored"] = _common.machine_info().get("git_commit")
    (out / "refine_unexplained_null.json").write_text(json.dumps(report, indent=1))
    (out / "refine_unexplained_null.md").write_text(markdown(report))
    return report


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--records", type=int, default=640, help="clean curves (default 640)")
    ap.add_argument("--level-records", type=int, default=80, help="level-check records per mixture (default 80)")
    ap.add_argument("--refine", type=int, default=100, help="curves also given to the default refine")
    ap.add_argument("--processes", type=int, default=1, help="records in this many processes (same results)")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--rescore", action="store_true", help="rates at today's shares from the recorded p-values")
    args = ap.parse_args(argv)
    if args.rescore:
        print(markdown(rescore(HERE / "results")))
        return 0
    if args.quick:
        run(8, 2, 2, Path(tempfile.mkdtemp()), args.processes)
        return 0
    rep = run(args.records, args.level_records, args.refine, HERE / "results", args.processes)
    print(markdown(rep))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
