#!/usr/bin/env python3
"""False alarms and power of ``unexplained``'s ``"follows"`` check (an accepted line carried by a channel no
regression uses: :mod:`allanite.model.refinement._channel_follows`).

The check runs only once a line is accepted beside channels, so its null is a record **with a line** and a channel
that does not carry it: each record here is noise (white, flicker, rate random walk; fs 1, 10 or 100 Hz; 10⁵ or
4·10⁵ samples) plus a line at a random f0 (a sinusoid or a sawtooth's family, ≥ 40 periods), beside one channel of
five kinds that do not couple — a cycling temperature, a random walk through a thermal lag, a channel of flicker and
random walk, a smooth once-swinging temperature (no noise: its leakage only), and a temperature carrying a line of
its own at another frequency. :func:`coherence_test` is called on the record's samples at f0, as the check calls it
on the final samples with the family's component added back; the table gives how often each test and the pair
reject at three levels (refine runs the pair at α = level × 0.02 = 10⁻³ per line and channel), with 95 %
Clopper–Pearson bounds.

Power: a heater's PWM (a sawtooth temperature of random period 30–300 s through a lag of 0.1–0.5 period) reaching
the rate at random sizes, the temperature given — the pair at 10⁻³ (the check's α with one line and one channel).

Usage::

    python benches/channel_follows_null.py            # -> benches/results/channel_follows_null.{md,json}
    python benches/channel_follows_null.py --records 50 --out /tmp/x
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np
from scipy import signal

import _common
import allanite
from allanite.model.refinement._channel_follows import coherence_test

HERE = Path(__file__).resolve().parent
KINDS = ("cycle", "walk", "flicker", "swing", "own_line")
LEVELS = (0.05, 0.01, 0.001)


def _lag(x: np.ndarray, fs: float, lag_s: float) -> np.ndarray:
    a = math.exp(-1.0 / (fs * lag_s))
    return signal.lfilter([1.0 - a], [1.0, -a], x - x[0]) + x[0]


def _channel(kind: str, n: int, fs: float, f0: float, rng: np.random.Generator) -> np.ndarray:
    t = np.arange(n) / fs
    span = n / fs
    if kind == "cycle":
        return 20 + 10 * np.sin(2 * np.pi * t / (span / 3) + rng.uniform(0, 6.3)) + 0.05 * rng.standard_normal(n)
    if kind == "walk":
        return 20 + _lag(np.cumsum(rng.standard_normal(n)) * 0.02, fs, span / 200)
    if kind == "flicker":
        return allanite.simulate(n, fs, B=0.05, K=1e-3, seed=rng)
    if kind == "swing":
        return 10 + 15 * (1 - np.cos(np.pi * t / span)) / 2
    fc = f0 * rng.uniform(1.3, 3.0) if rng.random() < 0.5 else f0 / rng.uniform(1.3, 3.0)
    return 20 + 0.5 * signal.sawtooth(2 * np.pi * fc * t + rng.uniform(0, 6.3)) + 0.02 * rng.standard_normal(n)


def _record(i: int, rng: np.random.Generator) -> tuple:
    fs = float(rng.choice([1.0, 10.0, 100.0]))
    n = int(rng.choice([100_000, 400_000]))
    y = allanite.simulate(n, fs, N=2e-3, B=float(rng.uniform(0, 2e-3)), K=float(rng.uniform(0, 2e-5)), seed=rng)
    span = n / fs
    f0 = float(np.exp(rng.uniform(np.log(40 / span), np.log(0.3 * fs))))
    t = np.arange(n) / fs
    amp = 2e-3 * float(np.exp(rng.uniform(np.log(0.3), np.log(30))))
    if rng.random() < 0.5:
        y = y + amp * np.sin(2 * np.pi * f0 * t + rng.uniform(0, 6.3))
    else:
        y = y + amp * signal.sawtooth(2 * np.pi * f0 * t + rng.uniform(0, 6.3))
    kind = KINDS[i % len(KINDS)]
    return y, fs, f0, kind, _channel(kind, n, fs, f0, rng)


def null(records: int) -> list[dict]:
    rows = []
    for i in range(records):
        rng = np.random.default_rng(29_170_000 + i)
        y, fs, f0, kind, x = _record(i, rng)
        r = coherence_test(y, x, fs, f0)
        rows.append({"kind": kind, "fs": fs, "n": y.size, "f0": f0} | (r or {"skipped": True}))
    return rows


def power(records: int) -> list[dict]:
    rows = []
    for i in range(records):
        rng = np.random.default_rng(29_180_000 + i)
        fs, n = 100.0, 1_000_000
        t = np.arange(n) / fs
        period = float(np.exp(rng.uniform(np.log(30), np.log(300))))
        temp = 25 + 0.6 * signal.sawtooth(2 * np.pi * t / period + rng.uniform(0, 6.3))
        lagged = _lag(temp, fs, period * rng.uniform(0.1, 0.5))
        coef = 7e-3 * float(np.exp(rng.uniform(np.log(0.1), np.log(1.0))))
        y = allanite.simulate(n, fs, N=4e-3, B=5e-4, K=1e-5, seed=rng) + coef * (lagged - lagged.mean())
        r = coherence_test(y, temp + 0.01 * rng.standard_normal(n), fs, 1 / period)
        rows.append({"period_s": period, "coefficient": coef} | (r or {"skipped": True}))
    return rows


def _rates(rows: list[dict]) -> dict:
    run = [r for r in rows if not r.get("skipped")]
    out = {"records": len(rows), "tested": len(run)}
    for a in LEVELS:
        k_c = sum(r["p_coherence"] < a for r in run)
        k_l = sum(r["p_line"] < a for r in run)
        k_p = sum(r["p_coherence"] < a and r["p_line"] < a for r in run)
        out[str(a)] = {"coherence": k_c, "line": k_l, "pair": k_p, "pair_ci95": _common.clopper_pearson(k_p, len(run))}
    return out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--records", type=int, default=1000)
    ap.add_argument("--power", type=int, default=60)
    ap.add_argument("--out", type=Path, default=HERE / "results")
    args = ap.parse_args(argv)
    with _common.OtherLoad() as load:
        rows, pw = null(args.records), power(args.power)
    res = {"null": _rates(rows), "by_kind": {k: _rates([r for r in rows if r["kind"] == k]) for k in KINDS}}
    res["power"] = _rates(pw)
    res |= {"other_load": load.fraction, "machine": _common.machine_info()}
    lines = [
        "# The `follows` check of `unexplained`: false alarms on lines beside channels that do not carry them",
        "",
        f"Written by `benches/channel_follows_null.py` (other load {load.fraction or 0:.0%}). Each row: records the "
        "test ran on (the rest hold < 36 periods of f0), then rejections of the coherence's Beta null, the channel's "
        "line F test and the pair (what the check asks) at α; refine's α per line and channel is 10⁻³.",
        "",
        "| records | tested | α | coherence | channel's line | pair | pair 95 % CP |",
        "|---|---|---|---|---|---|---|",
    ]
    for label, r in (
        [("all null", res["null"])] + [(k, v) for k, v in res["by_kind"].items()] + [("power", res["power"])]
    ):
        for a in LEVELS:
            c = r[str(a)]
            lo, hi = c["pair_ci95"]
            lines.append(
                f"| {label} | {r['tested']} | {a:g} | {c['coherence']} | {c['line']} | {c['pair']} | "
                f"{100 * lo:.2f}–{100 * hi:.2f} % |"
            )
    lines.append("")
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "channel_follows_null.json").write_text(json.dumps(res, indent=1, default=str))
    (args.out / "channel_follows_null.md").write_text("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
