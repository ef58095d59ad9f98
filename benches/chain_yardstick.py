#!/usr/bin/env python3
"""The chain's yardsticks after a true removal: does the truth score at least as well as the absorbed start?

Five blind rows remove the right coupling with the right coefficient and fail only on the chain's "falling"
clauses: the five terms at the start took the coupling into their slow terms (a rate random walk K, a flicker
B), and the model with the true component removed reads a higher χ²/dof or RMS ADEV error in sample, or a higher
held-out error. This bench rebuilds four such rows' records on their suite seed and on replicas (the same
generator, other seeds) and scores, as refine's chain does (:class:`allanite.model.refinement._run.RunState`,
``chain``):

- ``start``: the five terms fitted on the record's curve (the chain's first ``before``);
- ``truth``: the injected component itself removed (its exact change of the curve added back, one fitted number
  as a regression coefficient counts; held out, the component removed from both parts: the chain's ``after``
  of a perfect removal);
- null arm, on the record less its component (nothing left to remove): ``null_start`` its five terms, and
  ``spurious`` a least-squares coupling to the same channel removed (refitted on each held-in part held out) —
  what a false regression would leave. A yardstick that rewards it is one that rewards fitting noise.

The yardsticks, each compared start → truth (and null start → spurious):

- today's chain: ``chi2_dof`` (the GLS χ² under each model's own covariance, per dof), ``rms_adev_pct``,
  ``heldout_rms_adev_pct``;
- ``deviance`` (the chain's own key since r16heldout, :func:`allanite.model.refinement.scoring.settle_chi2`):
  χ² + ln det Σ on the same thinned τ under the same covariance — −2 ln L of the Gaussian density of the
  estimates less n ln 2π, which every model of one record shares. χ² alone is not a likelihood when the
  covariance moves with the model: a model that puts a coupling into K widens its own long-τ variances and so
  shrinks its own χ²; ln det Σ charges it for that width;
- ``aic`` (the chain's key too): deviance + 2 × the numbers fitted (the terms in use, plus one per removal);
- ``chi2_common``: both residuals under one covariance (the start's);
- ``heldout_deviance``: the held-out part's curve under the held-in model's predictive density (the exact
  covariance of its estimates under the held-in fit's five terms): χ² + ln det Σ, mean of both ways — the log
  score, a proper scoring rule, where the RMS relative error is not.

Per case and yardstick: on how many records the truth scores lower than the start (95 % Clopper–Pearson) and
the spurious removal lower than the null start.

Usage::

    python benches/chain_yardstick.py                     # -> benches/results/chain_yardstick.{json,md}
    python benches/chain_yardstick.py --replicas 4 --out DIR
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np
from scipy.linalg import solve_triangular

import _common
import refine_blind6 as rb6
import refine_blind9 as rb9
import refine_blind10 as rb10
import refine_blind12 as rb12
from allanite.analysis import avar
from allanite.model import tracing
from allanite.model.refinement._inputs import tau_grid
from allanite.model.refinement._run import RunState
from allanite.model.refinement.calibrated import curve_test
from allanite.model.refinement.curvefit import design, solve, theta_terms

HERE = Path(__file__).resolve().parent
START = ("Q", "N", "B", "K", "R")
#: (suite, the row's name contains, the coupled channel, seeds scored besides the suite's and the replicas: the
#: battery's +100 and +200, where refine's held-out error rose)
ROWS = (
    (rb12, "g-sensitive", "acc_z", ()),
    (rb12, "battery", "vbat", (1312, 1412)),
    (rb9, "dT/dt only", "temp", ()),
    (rb10, "three channels", "humidity", ()),
    (rb6, "temperature read at 1 Hz and held", "temp", ()),
)
#: replica seeds: REPLICA_BASE + k (none is a suite's seed)
REPLICA_BASE = 71_000
KEYS = ("chi2_dof", "rms_adev_pct", "heldout_rms_adev_pct", "deviance", "aic", "chi2_common", "heldout_deviance")


def _state(y: np.ndarray, fs: float) -> RunState:
    """refine's run state on ``y`` with its default τ grid (``_inputs.inputs``), the chain's split in it."""
    grid = tau_grid(y.size, fs, "exp", points=300, m_max=y.size // 9)
    return RunState(y, avar(y, fs, taus=grid), START, None, 0.01, None)


def _heldout_deviance(split, parts) -> float:
    """The held-out part's scored estimates under the held-in model's predictive Gaussian density (exact
    covariance of the five terms fitted on the held-in part's corrected curve): χ² + ln det Σ, both ways' mean."""
    sc, out = split.scored, []
    for h, p in zip((1, 0), parts):
        ch = split.curves[h]
        sol = solve(p["cf"], START, [])
        a_h, _ = design(ch, START, [])
        resid = (ch.avar - (a_h @ sol.theta + p["extra"]))[sc]
        cov = tracing.exact_covariance(
            split.m[sc].astype(np.int64), split.size, split.fs, START, theta_terms(sol, START, [])
        )
        chol = np.linalg.cholesky(cov)
        w = solve_triangular(chol, resid, lower=True)
        out.append(float(w @ w) + 2.0 * float(np.sum(np.log(np.diag(chol)))))
    return float(np.mean(out))


def _score(run: RunState, comp, fitted: int, refit) -> tuple[dict, dict]:
    """(start, after) of removing ``comp`` (``fitted`` numbers; ``refit(z, idx)`` its held-out refit) from
    ``run``'s record, under every yardstick."""
    y = run.y0
    res = avar(y - comp, run.fs, taus=run.result0.tau)
    curve, _ = run.build(res, None)
    sol = solve(curve, START, [])
    parts = run.split0.corrected(run.raw, refit, False)
    after = run.chain(sol, [], curve, fitted, parts)
    common = curve_test(run.curve0, run.thin, run.start_sol, START, [], run.exact)
    resid = [(run.curve0.avar - run.start_sol.model)[run.thin], (curve.avar - sol.model)[run.thin]]
    out = []
    for state, r, parts_i in zip((run.state, after), resid, (run.raw, parts)):
        m = dict(state[0])  # the chain's own keys, its deviance and AIC (scoring.settle_chi2) among them
        m["chi2_common"] = float(np.sum(solve_triangular(common.chol, r, lower=True) ** 2))
        m["heldout_deviance"] = _heldout_deviance(run.split0, parts_i)
        m["terms"] = [float(v) for v in state[2]]
        out.append({k: m[k] for k in (*KEYS, "terms")})
    # which τ carry the RMS ADEV error: inside and outside the scored τ where the component is ≥ 5 % of the curve
    sc = run.scored
    share = (run.curve0.avar - curve.avar)[sc] / run.curve0.avar[sc]
    models = (run.start_sol.model[sc], (sol.model + run.curve0.avar - curve.avar)[sc])
    for o, model in zip(out, models):
        err = np.sqrt(run.curve0.avar[sc] / np.maximum(model, 1e-300)) - 1.0
        band = share >= 0.05
        o["rms_where_component"] = float(100 * np.sqrt(np.mean(err[band] ** 2))) if band.any() else None
        o["rms_elsewhere"] = float(100 * np.sqrt(np.mean(err[~band] ** 2))) if (~band).any() else None
        o["component_tau"] = (
            [float(run.curve0.tau[sc][band].min()), float(run.curve0.tau[sc][band].max())] if band.any() else None
        )
    return out[0], out[1]


def _ols(chan: np.ndarray):
    """A least-squares coupling to the centred channel, fitted on samples ``z`` at indices ``idx``."""
    c = chan - chan.mean()

    def refit(z, idx):
        x = c[np.asarray(idx)]
        b = float((x @ (z - z.mean())) / (x @ x))
        return lambda i: b * c[np.asarray(i)]

    return refit


def score(case, name: str, seed: int) -> dict:
    """One record of ``case`` on ``seed``: start → truth, and on the noise alone start → spurious removal."""
    y, fs, chans, _kw, comp = case.build(np.random.default_rng(seed))
    run = _state(y, fs)
    start, truth = _score(run, comp, 1, lambda z, idx: lambda i: comp[np.asarray(i)])
    noise = y - comp
    run_n = _state(noise, fs)
    refit = _ols(np.asarray(chans[name], dtype=np.float64))
    spur = refit(noise, np.arange(noise.size))(np.arange(noise.size))
    null_start, spurious = _score(run_n, spur, 1, refit)
    return {"seed": seed, "start": start, "truth": truth, "null_start": null_start, "spurious": spurious}


def summary(rows: list) -> dict:
    """Per yardstick: records where the truth scores below the start, and the spurious removal below the null
    start (95 % Clopper–Pearson)."""
    n, out = len(rows), {}
    for k in KEYS:
        t = sum(r["truth"][k] < r["start"][k] for r in rows)
        s = sum(r["spurious"][k] < r["null_start"][k] for r in rows)
        d = np.array([r["truth"][k] - r["start"][k] for r in rows])
        out[k] = {
            "truth_lower": t,
            "truth_lower_cp95": _common.clopper_pearson(t, n),
            "spurious_lower": s,
            "spurious_lower_cp95": _common.clopper_pearson(s, n),
            "truth_minus_start_median": float(np.median(d)),
        }
    return {"records": n, "by_key": out}


def _band(b) -> str:
    return "none" if b is None else f"{b[0]:.3g}–{b[1]:.3g} s"


def _pct(v) -> str:
    return "–" if v is None else f"{v:.3g}"


def _row_lines(label: str, rows: list, s: dict, named: int) -> list:
    lines = [f"### {label}", ""]
    for i, su in enumerate(rows[:named]):
        lines += [
            f"{'Suite seed' if i == 0 else 'Seed'} {su['seed']}, start → truth: "
            + ", ".join(f"{k} {su['start'][k]:.4g} → {su['truth'][k]:.4g}" for k in KEYS)
            + f"; the five terms √θ (Q N B K R) {np.round(su['start']['terms'], 7).tolist()} → "
            f"{np.round(su['truth']['terms'], 7).tolist()}; RMS ADEV error where the component is ≥ 5 % of the curve "
            f"(τ {_band(su['truth']['component_tau'])}) {_pct(su['start']['rms_where_component'])} → "
            f"{_pct(su['truth']['rms_where_component'])} %, elsewhere {_pct(su['start']['rms_elsewhere'])} → "
            f"{_pct(su['truth']['rms_elsewhere'])} %.",
            "",
        ]
    return lines + _table(s, median=True, digits=0)


def _table(s: dict, median: bool, digits: int) -> list:
    """The yardsticks' table of summary ``s``: truth below the start and a false removal below its null start,
    each with its Clopper–Pearson interval (``digits`` decimals), and the median truth − start where ``median``."""
    n = s["records"]
    mid = " median truth − start |" if median else ""
    lines = [
        f"| yardstick | truth < start (of {n}) | 95 % CP |{mid} spurious < null start (of {n}) | 95 % CP |",
        "|---|---|---|---|---|---|" if median else "|---|---|---|---|---|",
    ]
    for k in KEYS:
        b = s["by_key"][k]
        (lo, hi), (lo_s, hi_s) = b["truth_lower_cp95"], b["spurious_lower_cp95"]
        med = f" {b['truth_minus_start_median']:+.3g} |" if median else ""
        lines.append(
            f"| {k} | {b['truth_lower']} | {100 * lo:.{digits}f}–{100 * hi:.{digits}f} % |{med} {b['spurious_lower']} | "
            f"{100 * lo_s:.{digits}f}–{100 * hi_s:.{digits}f} % |"
        )
    return lines + [""]


#: What the recorded run shows (kept true to it; the held-out per-τ numbers from a /tmp driver on b66101d).
NOTES = [
    "### What the run shows",
    "",
    "- **In sample, why the truth reads worse.** The start takes the coupling into its slow terms (g-sensitive "
    "1201: K 1.2·10⁻⁴ and B 0, against K 0 and B 3.0·10⁻⁴ with the true component removed; the truth's generator "
    "B 3·10⁻⁴, K 10⁻⁵). Under one covariance (the start's) the two residuals are alike (χ² 63.15 → 62.96): the "
    "rise of χ²/dof 1.05 → 1.21 is the covariance moving with the model — the start's K widens its own long-τ "
    "variances (ln det Σ larger by 41) — and one degree of freedom fewer for the removal's coefficient. The RMS "
    "ADEV error's rise sits where the component is ≥ 5 % of the curve (3.93 → 5.31 % there, 1.77 → 1.93 % "
    "elsewhere): it weighs ~50 correlated τ alike, and the start's five numbers bend to the sum of the noise's "
    "own excursion and the coupling's shape, which no five-term fit of the noise alone can. Unweighted and "
    "in-sample, it prefers the truth on 65 of 127 records — a coin.",
    "- **The deviance and the AIC.** With ln det Σ the absorbed start pays for the width it claims: the truth reads "
    "a lower AIC on all 127 records (97.1–100 %), and a least-squares coupling to the same channel removed from "
    "the record less its component (a false removal) lowers it on 11 of 127 (4.4–15.0 %) — no more often than "
    "today's χ²/dof (12 of 127), which prefers the truth on only 96. The deviance without the 2 per number "
    "rewards the false removal on 61 of 127: the penalty is needed. One covariance for both (the start's, "
    "`chi2_common`) prefers the truth on 126 but the false removal on 50.",
    "- **Held out, no yardstick tried separates them.** The held-out RMS error prefers the truth on 97 of 127 "
    "and the false removal on 60 of 127; the held-out predictive deviance on 115 and 57. Interleaved blocks share "
    "a record's slow structure, and a removal's held-out change is computed on the held-out part's own channel "
    "samples, so a coupling fitted to chance correlation on one part carries to the other. Where a true removal "
    "reads worse held out, the two parts' components differ: the battery on seed 1312 (held out 1.31 → 5.02 %), "
    "predicting part 0 from part 1, the component is 26–53 % of part 1's curve at τ 49–99 s and 9–15 % of part "
    "0's; the start, fitted on part 1's noise plus its larger component, lands within ±5 % of part 0, whose noise "
    "runs 12–26 % above part 1's there — the truth, each part's component exactly accounted for, shows that "
    "disagreement of the noise itself. Scored "
    "only where the parts' noise curves agree (not their raw curves), it still reads 1.30 → 3.86 %: not the "
    "scored τ's selection.",
    "",
]


def _pooled_lines(results: dict) -> list:
    """Every case's records together."""
    rows = [r for v in results.values() for r in v["rows"]]
    return ["### All records", "", *_table(summary(rows), median=False, digits=1)]


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--replicas", type=int, default=20)
    ap.add_argument("--out", type=Path, default=HERE / "results")
    args = ap.parse_args(argv)
    load0, t0 = os.getloadavg()[0], time.time()
    results, lines = {}, []
    for suite, sub, name, extra in ROWS:
        case = next(c for c in suite.CASES if sub in c.name)
        rows = []
        for seed in [case.seed, *extra] + [REPLICA_BASE + k for k in range(args.replicas)]:
            rows.append(score(case, name, seed))
            r = rows[-1]
            _common.log(f"{sub} {seed}: " + ", ".join(f"{k} {r['start'][k]:.4g}→{r['truth'][k]:.4g}" for k in KEYS))
        results[case.name] = {"rows": rows, "summary": summary(rows)}
        lines += _row_lines(f"{suite.__name__}: {case.name}", rows, results[case.name]["summary"], 1 + len(extra))
    lines += _pooled_lines(results) + NOTES
    head = [
        "# The chain's yardsticks after a true removal (r16heldout)",
        "",
        f"{_common.machine_line()}; load {load0:.1f} → {os.getloadavg()[0]:.1f}, {time.time() - t0:.0f} s wall. "
        "Written by `benches/chain_yardstick.py` (its docstring says what each yardstick is). Records: the suite "
        "seed (and the named seeds) and the replicas.",
        "",
    ]
    _common.write_results(args.out, "chain_yardstick", head + lines, results)


if __name__ == "__main__":
    main()
