#!/usr/bin/env python3
"""False alarms and power of `refine`'s regression test on another channel (issue 16's calibrated acceptance).

`refine(..., channels={...})` accepts a regression when |c| / SE exceeds the two-sided t quantile (7 dof) at
the regression's share of the per-record level, Bonferroni-split over the channels (0.375 % for one channel at
the default level 0.05); the dof are the blocks' effective number − 1 (Satterthwaite, ≤ 7). This bench draws null records — gyro noise independent of the channel — and counts how
often the statistic crosses that threshold, for the estimator `refine` uses (`regression_fit`: the coefficient
pooled within 8 blocks, each block de-meaned, SE from the batch means of the blocks' scores) and for the one it
replaced (the whole-record coefficient with the scatter of the 8 per-block coefficients as its error). Then it
measures both on a record that does carry a coupling.

Null records (``--records``, default 300; 4·10⁵ samples at 100 Hz, 4000 s): white rate noise N = 2e-3 with, in
turn, a random walk of rate (K = 2e-5), flicker (B = 1e-3) and a Gauss–Markov term (3e-3, 10 s); channels in
turn: a ±1 g multi-position profile (a turn every 200–600 s) plus white noise, white noise, a random walk.
Power: the same noise plus 0.01 °/s/g × the multi-position profile.

Usage::

    python benches/regression_null.py                 # -> benches/results/regression_null.{json,md} (~2 min)
    python benches/regression_null.py --quick --out DIR
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np
from scipy.stats import poisson
from scipy.stats import t as t_dist

import allanite
from _common import log, machine_info
from allanite.model.tracing import regression_fit

HERE = Path(__file__).resolve().parent
FS = 100.0
N = 400_000
BLOCKS = 8
ALPHA = 0.075 * 0.05  # refine's TIME_SHARE × LEVEL, one channel
CHANNELS = ("multi-position", "white", "random walk")


def per_block_coefficients(y, x, blocks=BLOCKS):
    """The replaced estimator: whole-record coefficient, SE from the scatter of per-block coefficients."""
    yc, xc = y - y.mean(), x - x.mean()
    coef = float(yc @ xc) / float(xc @ xc)
    per = y.size // blocks
    parts = []
    for j in range(blocks):
        sl = slice(j * per, (j + 1) * per)
        cj = x[sl] - x[sl].mean()
        d = float(cj @ cj)
        if d > 0:
            parts.append(float((y[sl] - y[sl].mean()) @ cj) / d)
    return coef, float(np.std(parts, ddof=1) / math.sqrt(len(parts)))


def tumble(rng, n):
    edges = np.cumsum(rng.uniform(200, 600, size=n // 20_000 + 2) * FS).astype(int)
    return np.where(np.searchsorted(edges, np.arange(n), side="right") % 2 == 0, 1.0, -1.0)


def channel(kind, rng, n):
    if kind == "multi-position":
        return tumble(rng, n) + 0.01 * rng.normal(size=n)
    if kind == "white":
        return rng.normal(size=n)
    return np.cumsum(rng.normal(size=n)) * 1e-3


def noise(i, n):
    return allanite.simulate(
        n,
        FS,
        N=2e-3,
        K=2e-5 if i % 2 else 0.0,
        B=1e-3 if i % 5 == 0 else 0.0,
        gauss_markov=[(3e-3, 10.0)] if i % 4 == 0 else (),
        seed=1000 + i,
    )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--records", type=int, default=300)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", type=Path, default=HERE / "results")
    args = ap.parse_args(argv)
    records = 30 if args.quick else args.records
    thr = float(t_dist.isf(ALPHA / 2, BLOCKS - 1))
    rng = np.random.default_rng(0)
    rows = []
    for i in range(records):
        kind = CHANNELS[i % 3]
        x = channel(kind, rng, N)
        y = noise(i, N)
        r = regression_fit(y, x, BLOCKS)
        c_old, se_old = per_block_coefficients(y, x)
        rows.append(
            {
                "kind": kind,
                "t": abs(r["coefficient"]) / r["se"],
                "threshold": float(t_dist.isf(ALPHA / 2, r["dof"])),
                "t_replaced": abs(c_old) / se_old,
                "threshold_replaced": thr,
            }
        )
        if i % 50 == 49:
            log(f"{i + 1} null records")
    # power: 0.01 °/s/g on a multi-position profile, in the same kinds of noise
    power = []
    for i in range(12 if not args.quick else 3):
        prng = np.random.default_rng(50 + i)
        tb = tumble(prng, N)
        acc = tb + 2e-3 * prng.normal(size=N)
        y = noise(i, N) + 0.01 * tb
        r = regression_fit(y, acc, BLOCKS)
        c_old, se_old = per_block_coefficients(y, acc)
        power.append(
            {
                "t": abs(r["coefficient"]) / r["se"],
                "threshold": float(t_dist.isf(ALPHA / 2, r["dof"])),
                "t_replaced": abs(c_old) / se_old,
                "threshold_replaced": thr,
                "coefficient": r["coefficient"],
            }
        )
    summary = {}
    for key, th in (("t", "threshold"), ("t_replaced", "threshold_replaced")):
        hits = [r[key] > r[th] for r in rows]
        summary[key] = {
            "false_alarms": int(sum(hits)),
            "rate": float(np.mean(hits)),
            "by_channel": {k: float(np.mean([r[key] > r[th] for r in rows if r["kind"] == k])) for k in CHANNELS},
            "power": float(np.mean([p[key] > p[th] for p in power])),
            "median_t_coupled": float(np.median([p[key] for p in power])),
        }
    report = {
        "records": records,
        "threshold": thr,
        "alpha": ALPHA,
        "summary": summary,
        "null": rows,
        "power": power,
        "machine": machine_info(),
    }
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "regression_null.json").write_text(json.dumps(report, indent=1) + "\n")
    s, o = summary["t"], summary["t_replaced"]
    lines = [
        "# The regression test on another channel: false alarms and power — `benches/regression_null.py`",
        "",
        f"{records} null records (4·10⁵ samples, 100 Hz; white noise with random walk, flicker or Gauss–Markov in "
        "turn; channels a ±1 g multi-position profile, white noise or a random walk, in turn), two-sided "
        f"α = {ALPHA:.5f} (refine's regression share of the 0.05 level): |t| beyond the t quantile with the "
        f"blocks' effective number − 1 dof for `regression_fit` (≤ 7), with 7 dof ({thr:.2f}) for the replaced one. "
        f"Power: {len(power)} records with 0.01 °/s/g on a multi-position profile.",
        "",
        "| estimator | false alarms | rate (allowed "
        + f"{100 * ALPHA:.3f} %)"
        + " | multi-position / white / random walk | power at 0.01 °/s/g | median t, coupled |",
        "|---|---|---|---|---|---|",
        f"| within 8 blocks, SE from the blocks' scores (`regression_fit`, used by refine) | {s['false_alarms']} "
        f"| {100 * s['rate']:.2f} % | "
        + " / ".join(f"{100 * s['by_channel'][k]:.1f} %" for k in CHANNELS)
        + f" | {100 * s['power']:.0f} % | {s['median_t_coupled']:.1f} |",
        f"| whole record, SE from the per-block coefficients (replaced) | {o['false_alarms']} | {100 * o['rate']:.2f} % | "
        + " / ".join(f"{100 * o['by_channel'][k]:.1f} %" for k in CHANNELS)
        + f" | {100 * o['power']:.0f} % | {o['median_t_coupled']:.1f} |",
        "",
        f"At the allowed rate {records * ALPHA:.2f} false alarms are expected in {records} records; a Poisson count "
        f"of that mean reaches {s['false_alarms']} or more with probability {poisson.sf(s['false_alarms'] - 1, records * ALPHA):.2g} "
        f"(within blocks) and {o['false_alarms']} or more with probability "
        f"{poisson.sf(o['false_alarms'] - 1, records * ALPHA):.2g} (replaced).",
    ]
    (args.out / "regression_null.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
