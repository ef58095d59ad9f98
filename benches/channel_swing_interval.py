#!/usr/bin/env python3
"""The level coefficient of a channel that swings once (half a cosine, 10 → 40 °C over the record) against flicker
and rate random walk: its error and how often its 68 % interval covers the truth (``regress_channel``, the level
term alone). Asked by ``benches/refine_blind10.py``'s float32 case, whose level term read +18, +29 and +58 % on
three seeds, two intervals missing the truth.

40 Hz × 4·10⁵ (10⁴ s), N 2·10⁻³, B 2·10⁻⁴, K 5·10⁻⁶ °/s units, coupling 5·10⁻⁵ °/s per °C (the case's noise and
profile at a tenth of its rate). Seeds 7000 + i.

Usage::

    python benches/channel_swing_interval.py --seeds 90   # -> benches/results/channel_swing_interval.md
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from scipy.stats import beta

import refine_blind as rb
import refine_blind10 as rb10
from allanite.model.channels import regress_channel

HERE = Path(__file__).resolve().parent
FS, N, C = 40.0, 400_000, 5e-5


def one(seed: int) -> tuple[float, bool, bool]:
    """(relative error of the level coefficient, its 68 % interval covers the truth, the coupling accepted)."""
    rng = np.random.default_rng(7000 + seed)
    t = np.arange(N) / FS
    y = rb.noise(N, FS, rng, N=2e-3, B=2e-4, K=5e-6)
    temp = 10.0 + 30.0 * (0.5 - 0.5 * np.cos(2 * np.pi * t / 20_000.0)) + 0.5 * rb10._weather(N, FS, rng, 300.0)
    r = regress_channel(y + C * (temp - temp.mean()), temp + 0.01 * rng.standard_normal(N), FS, name="temp", terms=())
    lo, hi = r.intervals["coefficient"]
    return r.params["coefficient"] / C - 1, bool(lo <= C <= hi), bool(r.accepted)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", type=int, default=90)
    args = ap.parse_args(argv)
    rows = []
    for seed in range(args.seeds):
        rows.append(one(seed))
        print(seed, *rows[-1], flush=True)
    err = np.array([r[0] for r in rows])
    k, n = sum(r[1] for r in rows), len(rows)
    lo, hi = float(beta.ppf(0.025, k, n - k + 1)), float(beta.ppf(0.975, k + 1, n - k))
    text = [
        "# A channel that swings once: the level coefficient's error and its interval's coverage",
        "",
        "Written by `benches/channel_swing_interval.py` (its docstring).",
        "",
        f"- records: {n}; the coupling accepted on {sum(r[2] for r in rows)}",
        f"- relative error: mean {err.mean():+.3f} ± {err.std(ddof=1) / np.sqrt(n):.3f} (its standard error), "
        f"median {np.median(err):+.3f}, standard deviation {err.std(ddof=1):.2f}",
        f"- the 68.3 % interval covers the truth on **{k} of {n}** ({100 * k / n:.0f} %; 95 % Clopper–Pearson "
        f"{100 * lo:.0f}–{100 * hi:.0f} %)",
        "",
    ]
    (HERE / "results" / "channel_swing_interval.md").write_text("\n".join(text), encoding="utf-8")


if __name__ == "__main__":
    main()
