#!/usr/bin/env python3
"""False-alarm side of regressing a record's channels strongest first (``model/refinement/_channel_order.py``;
docs/channels.md, "Several channels: the strongest first"): records with three channels — a temperature and a
humidity sharing a cycle (anti-correlated), a supply voltage — none of which the rate follows, refined with the
regression as the only candidate. A record "alarms" when any regression is taken.

The order cannot change whether one is taken (the first round tests every channel on the same samples at its
Bonferroni share, as the given order did until one passed); this measures it, record by record, on the code
before and after (run once per code tree, ``PYTHONPATH`` naming it, then ``--compare``).

Usage::

    PYTHONPATH=<tree>/python python benches/channel_order_null.py --records 100 --json /tmp/after.json
    python benches/channel_order_null.py --compare /tmp/before.json /tmp/after.json   # -> results/channel_order_null.md
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
from scipy.stats import beta

import allanite

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))
import sensors  # noqa: E402


def record(seed: int, n: int = 8_000, fs: float = 1.0):
    """White noise and rate random walk at 1 Hz × 8000, and three channels the rate does not follow."""
    rng = np.random.default_rng(10_000 + seed)
    t = np.arange(n) / fs
    y = allanite.simulate(n, fs, N=3e-3, K=1e-5, seed=rng)
    rng.standard_normal(n)  # a spare draw: the recorded records were drawn after it

    def weather(lag):
        v = sensors.first_order_lag(np.cumsum(rng.standard_normal(n)), fs, lag)
        return (v - v.mean()) / np.ptp(v)

    cycle = np.sin(2 * np.pi * t / 2000.0 + rng.uniform(0, 6.28))
    chans = {"temp": 24 + 3 * cycle + 2 * weather(250.0), "humidity": 45 - 8 * cycle + 15 * weather(160.0)}
    return y, fs, chans | {"supply_v": 12 + 0.3 * weather(100.0)}


def run(records: int) -> list:
    out = []
    for seed in range(records):
        y, fs, chans = record(seed)
        r = allanite.refine(y, fs, channels=chans, candidates=("regression",), progress=False)
        out.append([seed, [s.params["channel"] for s in r.steps]])
        print(out[-1], flush=True)
    return out


def _cp(k: int, n: int) -> tuple[float, float]:
    lo = 0.0 if k == 0 else float(beta.ppf(0.025, k, n - k + 1))
    hi = 1.0 if k == n else float(beta.ppf(0.975, k + 1, n - k))
    return lo, hi


def compare(before: list, after: list) -> str:
    n = min(len(before), len(after))
    kb, ka = (sum(bool(r[1]) for r in x[:n]) for x in (before, after))
    same = sum(a == b for a, b in zip(before[:n], after[:n], strict=True))
    (lb, hb), (la, ha) = _cp(kb, n), _cp(ka, n)
    return "\n".join(
        [
            "# Channels regressed strongest first: the false-alarm side",
            "",
            "Written by `benches/channel_order_null.py` (its docstring: three channels the rate does not follow —",
            "a temperature and a humidity sharing a cycle, a supply voltage — 1 Hz × 8000, white noise and rate",
            'random walk; `refine(..., candidates=("regression",))`). Before: the channels in the order given',
            "(aa22876); after: strongest first (f448120). Run as a copy of this script's records before it was committed (the",
            f"records checked equal, sample for sample), {n} records each, stopped there for the session's time.",
            "",
            "| code | records | a regression taken | 95 % Clopper–Pearson |",
            "|---|---|---|---|",
            f"| before (order given) | {n} | {kb} | {100 * lb:.1f}–{100 * hb:.1f} % |",
            f"| after (strongest first) | {n} | {ka} | {100 * la:.1f}–{100 * ha:.1f} % |",
            "",
            f"The same channels taken on {same} of {n} records (record by record). The regression's share of the",
            "level is 0.375 % per record.",
            "",
        ]
    )


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--records", type=int, default=100)
    ap.add_argument("--json", default=None, help="write this code tree's decisions here")
    ap.add_argument("--compare", nargs=2, default=None, help="before.json after.json -> the results page")
    args = ap.parse_args(argv)
    if args.compare:
        before, after = (json.loads(Path(p).read_text()) for p in args.compare)
        (HERE / "results" / "channel_order_null.md").write_text(compare(before, after), encoding="utf-8")
        return
    out = run(args.records)
    if args.json:
        Path(args.json).write_text(json.dumps(out))


if __name__ == "__main__":
    main()
