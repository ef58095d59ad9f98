#!/usr/bin/env python3
"""The held-out error of a regression step on replicas: is a rise after a correct removal the scoring's noise?

Two blind rows name the right channel with the right coefficient and still fail because the chain's held-out RMS
ADEV error rises after the removal: ``benches/refine_blind10.py``'s humidity (three channels, the bias on the
humidity only) and ``benches/refine_blind6.py``'s temperature read at 1 Hz and held. This bench rebuilds each
row's record on its suite seed and on replicas (the same generator, other seeds) and scores, as refine's chain
does for a first removal (:class:`allanite.model.refinement._run.RunState`'s split, ``Split.corrected`` then
``Split.predict``: the removal refitted on each held-in part, the model fitted on its corrected curve predicting
the held-out part's raw curve with the held-out part's change added back):

- ``before``: the five terms alone (the chain's start);
- ``after``: the regression as refine fits it (``channels.regress_channel`` on the named channel, refitted on
  each held-in part); ``after_true``: the injected component itself removed (no estimate at all);
- ``noise_only``: the record less the injected component, its own split's five-term score — the held-out
  error's scatter where there is nothing to remove;
- ``step_old``: the step's own held-out test as ``Split.error`` scored a slow regression before r13heldout
  (the held-out part's *corrected* curve as the target, its relative error on that curve's scale); the step's
  test now is ``after`` (the same curve as ``before``).

Per row: how often the held-out error rises after the regression (95 % Clopper–Pearson), where the suite
seed's ``before`` ranks among the replicas', and the paired change's spread.

Usage::

    python benches/r13heldout.py                   # -> benches/results/r13heldout.{json,md}
    python benches/r13heldout.py --replicas 4 --out DIR
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

import _common
import refine_blind6 as rb6
import refine_blind10 as rb10
from allanite.analysis import avar
from allanite.model import channels
from allanite.model.refinement._inputs import tau_grid
from allanite.model.refinement._run import RunState
from allanite.model.refinement.curvefit import design, solve
from allanite.model.refinement.scoring import rms_adev_pct

HERE = Path(__file__).resolve().parent
START = ("Q", "N", "B", "K", "R")
#: (suite, the row's name contains, the coupled channel)
ROWS = ((rb10, "three channels", "humidity"), (rb6, "temperature read at 1 Hz and held", "temp"))
#: replica seeds: REPLICA_BASE + k (none is a suite's seed)
REPLICA_BASE = 70_000


def _state(y: np.ndarray, fs: float) -> RunState:
    """refine's run state on ``y`` with its default τ grid (``_inputs.inputs``), the chain's split in it."""
    grid = tau_grid(y.size, fs, "exp", points=300, m_max=y.size // 9)
    return RunState(y, avar(y, fs, taus=grid), START, None, 0.01, None)


def _old_step_test(split, refit) -> float:
    """The step's own held-out test of a removal not ``on_raw`` as ``Split.error`` took it before r13heldout:
    the model fitted on the held-in part's corrected curve predicting the held-out part's *corrected* curve."""
    errs = []
    for f, h in ((0, 1), (1, 0)):
        yf, yh = split.part(f), split.part(h)
        g = refit(yf, split.idx[f])
        cf, ch = split.curve(yf - g(split.idx[f])), split.curve(yh - g(split.idx[h]))
        a_h, _ = design(ch, START, [])
        pred = np.maximum(a_h @ solve(cf, START, []).theta, 1e-300)
        errs.append(rms_adev_pct(ch.avar[split.scored], pred[split.scored]))
    return float(np.mean(errs))


def score(case, name: str, seed: int) -> dict:
    """One record of ``case`` on ``seed``: the chain's held-out error before → after (estimated, true) and the
    noise alone's."""
    y, fs, chans, _kw, comp = case.build(np.random.default_rng(seed))
    run = _state(y, fs)
    split = run.split0
    r = channels.regress_channel(y, chans[name], fs, name=name)
    est = lambda z, idx: r.refit(z, idx, chans[name])  # noqa: E731
    true = lambda z, idx: lambda i: comp[np.asarray(i)]  # noqa: E731
    before = split.predict(run.raw, START, [])
    after = split.predict(split.corrected(run.raw, est, False), START, [])
    after_true = split.predict(split.corrected(run.raw, true, False), START, [])
    step_new = split.error(START, [], remove=est, on_raw=False)
    noise = _state(y - comp, fs)
    return {
        "seed": seed,
        "accepted": bool(r.accepted),
        "coefficient_error": r.params["coefficient"] / case.injected[0].truth["coefficient"] - 1.0,
        "before": before,
        "after": after,
        "after_true": after_true,
        "step_new": step_new,
        "step_old": _old_step_test(split, est),
        "noise_only": noise.split0.predict(noise.raw, START, []),
    }


def summary(rows: list) -> dict:
    """The suite seed's row (first) against its replicas."""
    suite, reps = rows[0], rows[1:]
    rises = sum(r["after"] >= r["before"] for r in reps)
    rises_true = sum(r["after_true"] >= r["before"] for r in reps)
    d = np.array([r["after"] - r["before"] for r in reps])
    befores = np.array([r["before"] for r in reps])
    return {
        "replicas": len(reps),
        "rises": rises,
        "rises_cp95": _common.clopper_pearson(rises, len(reps)),
        "rises_true": rises_true,
        "rises_true_cp95": _common.clopper_pearson(rises_true, len(reps)),
        "change_median": float(np.median(d)),
        "change_sd": float(np.std(d, ddof=1)),
        "before_median": float(np.median(befores)),
        "before_range": (float(befores.min()), float(befores.max())),
        "suite_before_below": int(np.sum(befores < suite["before"])),
        "noise_only_range": (float(min(r["noise_only"] for r in reps)), float(max(r["noise_only"] for r in reps))),
        "step_equals_chain": all(abs(r["step_new"] - r["after"]) < 1e-12 for r in rows),
    }


def _row_lines(label: str, rows: list, s: dict) -> list:
    n = s["replicas"]
    lo, hi = s["rises_cp95"]
    lo_t, hi_t = s["rises_true_cp95"]
    su = rows[0]
    lines = [
        f"### {label}",
        "",
        f"Suite seed {su['seed']}: held out {su['before']:.3g} → {su['after']:.3g} % (the true component removed: "
        f"{su['after_true']:.3g} %; the noise alone {su['noise_only']:.3g} %), coefficient "
        f"{100 * su['coefficient_error']:+.1f} %; the step's own test {su['before']:.3g} → {su['step_old']:.3g} % "
        f"before r13heldout, {su['step_new']:.3g} % now. Its `before` is above {s['suite_before_below']} of the "
        f"{n} replicas' (their range {s['before_range'][0]:.3g}–{s['before_range'][1]:.3g} %, median "
        f"{s['before_median']:.3g} %).",
        "",
        f"Replicas: the held-out error rises after the regression on **{s['rises']} of {n}** (95 % CP "
        f"{100 * lo:.0f}–{100 * hi:.0f} %), after the true component on {s['rises_true']} of {n} "
        f"({100 * lo_t:.0f}–{100 * hi_t:.0f} %); after − before median {s['change_median']:+.2f} points, SD "
        f"{s['change_sd']:.2f}; the noise alone scores {s['noise_only_range'][0]:.3g}–{s['noise_only_range'][1]:.3g} %. "
        f"The step's own test equals the chain's first step on every record: {s['step_equals_chain']}.",
        "",
        "| seed | coefficient | before % | after % | after (true) % | noise alone % | step's test before r13heldout % |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['seed']} | {100 * r['coefficient_error']:+.1f} % | {r['before']:.3g} | {r['after']:.3g} | "
            f"{r['after_true']:.3g} | {r['noise_only']:.3g} | {r['step_old']:.3g} |"
        )
    return lines + [""]


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--replicas", type=int, default=15)
    ap.add_argument("--out", type=Path, default=HERE / "results")
    args = ap.parse_args(argv)
    load0, t0 = os.getloadavg()[0], time.time()
    results, lines = {}, []
    for suite, sub, name in ROWS:
        case = next(c for c in suite.CASES if sub in c.name)
        rows = []
        for seed in [case.seed] + [REPLICA_BASE + k for k in range(args.replicas)]:
            rows.append(score(case, name, seed))
            _common.log(f"{sub} {seed}: {rows[-1]['before']:.3g} → {rows[-1]['after']:.3g} %")
        results[case.name] = {"rows": rows, "summary": summary(rows)}
        lines += _row_lines(f"{suite.__name__}: {case.name}", rows, results[case.name]["summary"])
    head = [
        "# The held-out error of a regression step on replicas (r13heldout)",
        "",
        f"{_common.machine_line()}; load {load0:.1f} → {os.getloadavg()[0]:.1f}, {time.time() - t0:.0f} s wall. "
        "Written by `benches/r13heldout.py` (its docstring says what each column is).",
        "",
    ]
    _common.write_results(args.out, "r13heldout", head + lines, results)


if __name__ == "__main__":
    main()
