#!/usr/bin/env python3
"""Calibration of the ``"mean"`` and ``"steps"`` checks of ``Refinement.unexplained`` (steps of the mean; issue 29).

``"mean"``: its test alone — the best single split of 48 block means against its null simulated from the model
refitted without the located step (:mod:`allanite.model.refinement._mean_step`) — on clean records, where
refitting without a step that is not there lowers K: the place false alarms would hide. ``"steps"``: its test
alone — the block means' largest increment over their robust scale at three lengths
(:mod:`allanite.model.refinement._mean_steps`), its null under the final model with its slow terms at the upper
end. The gate that follows each in refine (the step moving the Allan deviation by more than the final model's
held-out error) is left off, so these rates bound the checks' from above.

Clean records (a fixed seed each): white noise always, flicker (stationary: Kasdin–Walter over 4× the record,
its tail) and rate random walk always, their corners placed log-uniformly along the record; a quarter with
quantisation, a fifth through a 2nd-order Butterworth low-pass at fs/8…fs/40 (the final model then holds its
bandwidth effect, as refine's would), a tenth with a rate ramp, a fifth with a Gauss–Markov term (not in the final
model); fs 1, 50, 100, 400 or 1000 Hz, 10⁵, 3·10⁵ or 10⁶ samples. The final model is the five-term fit of refine's
dense curve (300 τ) plus that bandwidth.

A p-value is (1 + #{draws ≥ statistic}) / (1 + draws) over :data:`N_BOOT` draws of the mean check's refitted null
and 2/α draws of the steps check's; a rate at α is the share of records with p ≤ α, with its 95 % Clopper–Pearson
interval.

``--power K``: the checks' power instead, on K records per cell of blind2's bias-step noise (white 2·10⁻³, flicker
3·10⁻⁴, random walk 2·10⁻⁶; 50 Hz × 2·10⁵ samples = 4000 s) with a step of d at 0.2 or 0.55 of the record: each
test alone at its α, and the mean check with the gate at a held-out error of 3 % (a typical final model's); the
split's error.

Usage::

    python benches/refine_mean_step_null.py                  # 300 records -> benches/results/refine_mean_step_null.{json,md}
    python benches/refine_mean_step_null.py --records 40 --out /tmp/x
    python benches/refine_mean_step_null.py --power 15       # -> benches/results/refine_mean_step_power.{json,md}
    python benches/refine_mean_step_null.py --blind3 6       # -> benches/results/refine_mean_steps_blind3.{json,md}
"""

from __future__ import annotations

import argparse
import math
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
from scipy import signal

import _common
import allanite
from allanite.estimators.grid import tau_grid
from allanite.model.refinement import _mean_step as ms
from allanite.model.refinement import _mean_steps as mss
from allanite.model.refinement.curvefit import Curve, solve, theta_terms, upper_theta
from allanite.model.refinement.levels import LEVEL, alpha
from allanite.model.refinement.missing import MissingContext
from allanite.simulation import kasdin_walter

HERE = Path(__file__).resolve().parent
START = ("Q", "N", "B", "K", "R")
N_BOOT = 8000
ALPHA = alpha("unexplained:mean", LEVEL)
STEPS_ALPHA = alpha("unexplained:steps", LEVEL)
LEVELS = (ALPHA, 0.01, 0.05)


def clean_record(seed: int) -> tuple[np.ndarray, float, list, dict]:
    """A clean record, its rate, the final model's effects (a low-pass's bandwidth) and its description."""
    rng = np.random.default_rng(seed)
    fs = float(rng.choice([1.0, 50.0, 100.0, 400.0, 1000.0]))
    n = int(rng.choice([100_000, 300_000, 1_000_000]))
    span, nw = n / fs, 1e-3
    terms = {"N": nw}
    # flicker floor meeting white noise at 10⁻⁴…10⁻¹ of the record; random walk at 10⁻³…1 of it
    b = nw / math.sqrt(0.4413 * span * 10 ** rng.uniform(-4, -1))
    terms["K"] = nw * math.sqrt(3) / (span * 10 ** rng.uniform(-3, 0))
    if rng.random() < 0.25:
        terms["Q"] = nw * math.sqrt(rng.uniform(1, 4) / fs / 3)
    if rng.random() < 0.1:
        terms["R"] = nw * math.sqrt(2 / (span * 10 ** rng.uniform(-1, 0)) ** 3)
    y = allanite.simulate(n, fs, seed=rng, **terms)
    y = y + b * kasdin_walter(4 * n, 1.0, rng)[-n:]  # allanite.simulate's flicker, stationary
    effects: list = []
    desc = {"fs": fs, "n": n, "terms": sorted([*terms, "B"])}
    if rng.random() < 0.2:
        frac = float(rng.uniform(1 / 40, 1 / 8))
        bb, aa = signal.butter(2, 2 * frac)
        y = signal.lfilter(bb, aa, y)
        effects = [("bandwidth:butterworth2", frac * fs)]
        desc["lowpass_hz"] = frac * fs
    if rng.random() < 0.2:  # a Gauss–Markov term, 1–10× the white noise's Allan deviation at its correlation time
        tc = span * 10 ** rng.uniform(-3, -1)
        sigma = nw / math.sqrt(tc) * rng.uniform(1.0, 10.0)
        y = y + allanite.simulate(n, fs, gauss_markov=[(sigma, tc)], seed=rng)
        desc["gm_tc_s"] = tc
    return y, fs, effects, desc


def context(y: np.ndarray, fs: float, effects: list) -> MissingContext:
    """The final state refine's check would see: its dense curve, the five terms (+ effects) fitted."""
    grid = tau_grid(y.size, fs, "exp", points=300, m_max=max(1, y.size // 9))
    res = allanite.avar(y, fs, taus=grid)
    keep = res.avar > 0
    cur = Curve(res.tau[keep], res.m[keep].astype(np.float64), res.avar[keep], fs, res.n_samples + 1, res.estimator)
    sol = solve(cur, START, effects)
    return MissingContext(cur, np.arange(cur.tau.size), sol, START, effects, y, fs, LEVEL, True)


def _p_value(n: int, fs: float, theta, statistic: float) -> float:
    draws = ms.null_statistics(n, fs, START, theta, N_BOOT)
    return float((1 + np.count_nonzero(draws >= statistic)) / (1 + draws.size))


def task(k: int) -> dict:
    y, fs, effects, desc = clean_record(70_000 + 7919 * k)
    ctx = context(y, fs, effects)
    loc, sol, dep = ms.located(ctx)
    p = max(_p_value(y.size, fs, theta, loc["statistic"]) for theta in loc["thetas"])
    # the null before the profile: flicker and random walk at their upper ends at once (a corner the curve
    # need not allow), for the before/after of the change
    corner = upper_theta(loc["curve"], sol, START, effects, theta_terms(sol, START, effects))
    p_corner = _p_value(y.size, fs, corner, loc["statistic"])
    # the steps check's test (its first round), its null under the final model with its slow terms raised
    theta = upper_theta(ctx.curve, ctx.sol, START, effects, theta_terms(ctx.sol, START, effects))
    null = mss.null_ratios(y.size, fs, START, theta, STEPS_ALPHA)
    stat = mss.step_down(np.asarray(y, dtype=np.float64), null)[1]["statistic"]
    p_steps = float((1 + np.count_nonzero(null["draws"] >= stat)) / (1 + null["n_boot"]))
    k_true = float(ctx.sol.theta[START.index("K")])
    return desc | {
        "p": p,
        "p_corner": p_corner,
        "p_steps": p_steps,
        "steps_statistic": stat,
        "steps_threshold": null["threshold"],
        "statistic": loc["statistic"],
        "t_step_frac": loc["index"] / y.size,
        "K_fit": math.sqrt(max(k_true, 0.0)),
        "K_null": math.sqrt(max(max(float(t[START.index("K")]) for t in loc["thetas"]), 0.0)),
        "departure_pct": float(dep.max()),
    }


def run(records: int, out: Path, processes: int) -> dict:
    t0 = time.perf_counter()
    load = _common.OtherLoad().__enter__()
    with ProcessPoolExecutor(processes) as pool:
        rows = list(pool.map(task, range(records)))
    load.__exit__(None, None, None)
    p = [r["p"] for r in rows]
    report = {
        "level": LEVEL,
        "alpha": ALPHA,
        "records": records,
        "n_boot": N_BOOT,
        "rates": _common.rejection_rates(p, LEVELS),
        "steps_alpha": STEPS_ALPHA,
        "rates_corner": _common.rejection_rates([r["p_corner"] for r in rows], LEVELS),
        "rates_steps": _common.rejection_rates([r["p_steps"] for r in rows], (STEPS_ALPHA, 0.01, 0.05)),
        "by_group": _groups(rows),
        "rows": rows,
        "seconds": time.perf_counter() - t0,
        "other_load": load.fraction,
        "machine": _common.machine_info(),
    }
    out.mkdir(parents=True, exist_ok=True)
    _common.write_results(out, "refine_mean_step_null", markdown(report), report)
    return report


def _groups(rows: list) -> dict:
    """Rejections at 5 % by record kind (a low-pass, quantisation, a ramp, the rest) and by length."""
    kinds = {
        "low-pass": lambda r: "lowpass_hz" in r,
        "quantisation": lambda r: "Q" in r["terms"],
        "ramp": lambda r: "R" in r["terms"],
        "Gauss–Markov": lambda r: "gm_tc_s" in r,
        "N + B + K only": lambda r: r["terms"] == ["B", "K", "N"] and "lowpass_hz" not in r and "gm_tc_s" not in r,
        **{f"{n:g} samples": (lambda r, n=n: r["n"] == n) for n in (100_000, 300_000, 1_000_000)},
    }
    out = {}
    for name, sel in kinds.items():
        ps = [r["p"] for r in rows if sel(r)]
        out[name] = {"records": len(ps), "at_5pct": int(sum(v <= 0.05 for v in ps))}
        out[name]["steps_at_5pct"] = int(sum(r["p_steps"] <= 0.05 for r in rows if sel(r)))
    return out


def markdown(report: dict) -> list[str]:
    lines = [
        '# The `"mean"` and `"steps"` checks of `Refinement.unexplained` on clean records',
        "",
        f"Written by `benches/refine_mean_step_null.py` ({_common.machine_line(report['machine'])}; other processes "
        f"used {100 * (report['other_load'] or 0):.0f} % of the CPUs; {report['seconds']:.0f} s). Each check's test "
        f"alone (its gate — the step moving the Allan deviation beyond the held-out error — off) on "
        f"{report['records']} clean records: white + stationary flicker + rate random walk, a quarter with "
        "quantisation, a fifth through a 2nd-order low-pass (the final model holding its bandwidth), a tenth with a "
        "ramp, a fifth with a Gauss–Markov term (correlation time 10⁻³–10⁻¹ of the record, 1–10× the white "
        "noise's Allan deviation there; not in the final model); 1–1000 Hz, 10⁵–10⁶ samples. `mean`: one split, "
        "its null from the five-term model refitted without the located step, profiled over what the curve allows "
        "(each slow term at its upper end, the others refitted there; p the largest over those models; before "
        f"2026-11-27 both slow terms at their upper ends at once, its row below), p over {report['n_boot']} draws. "
        "`steps`: the block means' largest increment over their robust scale (3 block lengths), its null under "
        "the final model with its slow terms at the upper end, p over 2/α draws. Rate: records with p ≤ the level, 95 % Clopper–Pearson interval.",
        "",
        "| check | α (its share of 5 %) | records | at α | at 1 % | at 5 % |",
        "|---|---|---|---|---|---|",
    ]
    cells = [_common.rate_cell(report["rates"][f"{lv:g}"], count=True) for lv in LEVELS]
    lines.append(f"| unexplained:mean | {report['alpha']:g} | {report['records']} | " + " | ".join(cells) + " |")
    if "rates_corner" in report:
        cells = [_common.rate_cell(report["rates_corner"][f"{lv:g}"], count=True) for lv in LEVELS]
        lines.append(
            f"| (mean, its null before 2026-11-27: flicker and random walk at their upper ends at once) | "
            f"{report['alpha']:g} | {report['records']} | " + " | ".join(cells) + " |"
        )
    cells = [
        _common.rate_cell(report["rates_steps"][f"{lv:g}"], count=True) for lv in (report["steps_alpha"], 0.01, 0.05)
    ]
    lines.append(f"| unexplained:steps | {report['steps_alpha']:g} | {report['records']} | " + " | ".join(cells) + " |")
    lines += ["", "At 5 %, by kind of record:", "", "| records | n | mean at 5 % | steps at 5 % |", "|---|---|---|---|"]
    for name, g in report["by_group"].items():
        lines.append(f"| {name} | {g['records']} | {g['at_5pct']} | {g['steps_at_5pct']} |")
    ratio = np.array([r["K_null"] / max(r["K_fit"], 1e-300) for r in report["rows"] if r["K_fit"] > 0])
    if ratio.size:
        lines += [
            "",
            f"The null's K over the five-term fit's K (records where the fit has K): median {np.median(ratio):.3g}, "
            f"5th percentile {np.quantile(ratio, 0.05):.3g}.",
        ]
    return lines


POWER_STEPS = (1e-3, 2e-3, 3e-3, 5e-3)
POWER_AT = (0.2, 0.55)
POWER_N, POWER_FS = 200_000, 50.0


def power_task(job: tuple) -> dict:
    d, at, k = job
    rng = np.random.default_rng(50_000 + 1009 * k + int(1e6 * d) + int(100 * at))
    y = allanite.simulate(POWER_N, POWER_FS, N=2e-3, K=2e-6, seed=rng)
    y = y + 3e-4 * kasdin_walter(4 * POWER_N, 1.0, rng)[-POWER_N:]
    y[int(at * POWER_N) :] += d
    ctx = context(y, POWER_FS, [])
    loc, _sol, dep = ms.located(ctx)
    thr = ms.profile_threshold(POWER_N, POWER_FS, START, loc["thetas"], ALPHA)
    rejected = loc["statistic"] > thr
    theta = upper_theta(ctx.curve, ctx.sol, START, [], theta_terms(ctx.sol, START, []))
    null = mss.null_ratios(POWER_N, POWER_FS, START, theta, STEPS_ALPHA)
    steps = mss.step_down(np.asarray(y, dtype=np.float64), null)[1]["statistic"] > null["threshold"]
    return {
        "steps_rejected": bool(steps),
        "d": d,
        "at": at,
        "rejected": bool(rejected),
        "said_at_3pct": bool(rejected and float(dep.max()) > 3.0),
        "t_error_frac": abs(loc["index"] / POWER_N - at),
        "d_est": loc["d"],
    }


def run_power(per_cell: int, out: Path, processes: int) -> dict:
    t0 = time.perf_counter()
    jobs = [(d, at, k) for d in POWER_STEPS for at in POWER_AT for k in range(per_cell)]
    load = _common.OtherLoad().__enter__()
    with ProcessPoolExecutor(processes) as pool:
        rows = list(pool.map(power_task, jobs))
    load.__exit__(None, None, None)
    report = {"alpha": ALPHA, "per_cell": per_cell, "rows": rows, "seconds": time.perf_counter() - t0}
    report |= {"other_load": load.fraction, "machine": _common.machine_info()}
    lines = [
        '# The `"mean"` and `"steps"` checks\' power on a bias step',
        "",
        f"Written by `benches/refine_mean_step_null.py --power {per_cell}` ({_common.machine_line(report['machine'])}; "
        f"other processes used {100 * (report['other_load'] or 0):.0f} % of the CPUs; {report['seconds']:.0f} s). "
        "blind2's bias-step noise (white 2·10⁻³ °/s/√Hz, stationary flicker 3·10⁻⁴, random walk 2·10⁻⁶) at 50 Hz × "
        f"2·10⁵ samples (4000 s), a step of d at a share of the record; {per_cell} records per cell (fixed seeds). "
        f"Rejected: the test alone at its α ({ALPHA:g}); said: rejected and the step moving the Allan deviation by "
        "more than 3 % (a typical final model's held-out error); split error: median |located − true| as a share "
        "of the record, over the rejected records. `steps` rejected: the several-step check's test alone at its "
        f"α ({STEPS_ALPHA:g}), its null under the five-term fit with its slow terms at the upper end.",
        "",
        "| d (°/s) | at | rejected | 95 % CP | said (3 %) | split error (median) | `steps` rejected |",
        "|---|---|---|---|---|---|---|",
    ]
    for d in POWER_STEPS:
        for at in POWER_AT:
            cell = [r for r in rows if r["d"] == d and r["at"] == at]
            k = sum(r["rejected"] for r in cell)
            lo, hi = _common.clopper_pearson(k, len(cell))
            said = sum(r["said_at_3pct"] for r in cell)
            errs = [r["t_error_frac"] for r in cell if r["rejected"]]
            err = f"{100 * float(np.median(errs)):.2f} %" if errs else "—"
            st = sum(r["steps_rejected"] for r in cell)
            lines.append(
                f"| {d:g} | {at:g} | {k} of {len(cell)} | {100 * lo:.0f}–{100 * hi:.0f} % | {said} | {err} | {st} |"
            )
    out.mkdir(parents=True, exist_ok=True)
    _common.write_results(out, "refine_mean_step_power", lines, report)
    return report


def blind3_task(seed: int) -> dict:
    """blind3's bias-steps record (its generator, seeded ``seed``), refined with the default call."""
    import refine_blind3  # noqa: PLC0415 — only this mode needs the suite

    y, fs, *_ = refine_blind3._bias_steps(np.random.default_rng(seed))
    r = allanite.refine(y, fs, unit="deg/s", progress=False)
    said = [u for u in r.unexplained if u["domain"] == "steps"]
    row: dict = {"seed": seed, "added": [s.effect for s in r.steps], "domains": [u["domain"] for u in r.unexplained]}
    if said:
        row |= {k: said[0][k] for k in ("steps", "statistic", "threshold", "what")}
    return row


def run_blind3(records: int, out: Path, processes: int) -> dict:
    t0 = time.perf_counter()
    with ProcessPoolExecutor(processes) as pool:
        rows = list(pool.map(blind3_task, [1001 + k for k in range(records)]))
    report = {"rows": rows, "seconds": time.perf_counter() - t0, "machine": _common.machine_info()}
    lines = [
        '# The `"steps"` check on blind3\'s bias-steps configuration, more records',
        "",
        f"Written by `benches/refine_mean_step_null.py --blind3 {records}` ({_common.machine_line(report['machine'])}; "
        f"{report['seconds']:.0f} s). `benches/refine_blind3.py`'s bias-steps record (its noise N 3·10⁻³, B 3·10⁻⁴, "
        "K 10⁻⁶ at 20 Hz × 6·10⁵; +2.5, −4, +3·10⁻³ °/s at 6000, 15000, 24000 s) with other "
        "seeds, default `refine`: what `unexplained` says, the check's statistic over its threshold and the steps it "
        "located (t s, size °/s).",
        "",
        "| seed | added | unexplained | statistic / threshold | steps located |",
        "|---|---|---|---|---|",
    ]
    for r in rows:
        ratio = f"{r['statistic']:.3g} / {r['threshold']:.3g}" if "statistic" in r else "—"
        steps = "; ".join(f"{t:.6g} s, {d:.2g}" for t, d in r.get("steps", [])) or "—"
        lines.append(
            f"| {r['seed']} | {', '.join(r['added']) or 'nothing'} | {', '.join(r['domains']) or 'none'} | {ratio} "
            f"| {steps} |"
        )
    said = sum("statistic" in r for r in rows)
    lines += ["", f"Said in {said} of {len(rows)}."]
    out.mkdir(parents=True, exist_ok=True)
    _common.write_results(out, "refine_mean_steps_blind3", lines, report)
    return report


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--records", type=int, default=300)
    ap.add_argument("--processes", type=int, default=1)
    ap.add_argument("--power", type=int, default=0, help="the power table instead, this many records per cell")
    ap.add_argument("--blind3", type=int, default=0, help="blind3's bias-steps record with this many other seeds")
    ap.add_argument("--out", default=None, help="results folder (default benches/results)")
    args = ap.parse_args(argv)
    out = Path(args.out) if args.out else HERE / "results"
    if args.blind3:
        run_blind3(args.blind3, out, args.processes)
        print((out / "refine_mean_steps_blind3.md").read_text())
        return
    if args.power:
        run_power(args.power, out, args.processes)
        print((out / "refine_mean_step_power.md").read_text())
        return
    rep = run(args.records, out, args.processes)
    print("\n".join(markdown(rep)))


if __name__ == "__main__":
    main()
