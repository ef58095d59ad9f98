#!/usr/bin/env python3
"""A lagged channel's coupling and the coupling's first test: the channel alone (lag 0, F(1, ν), the test before)
against the channel and its quadrature (2·F(2, ν), :func:`allanite.model._coupling.coupling_test`) — power on
lagged couplings, false alarms on null records.

Power: 10 Hz × 5·10⁴ records (5000 s), FOG-like noise (white 8·10⁻⁴, flicker 1.4·10⁻⁴, rate random walk
2·10⁻⁶ — ``benches/refine_blind5.py``'s FOG at 10 Hz), a chamber temperature cycling 20–45 °C three times
(period P = 1667 s, ``tests/sensors.py``'s ``"cycle"``, logged with 0.01 °C of noise), the rate following it
at 2·10⁻⁴ per °C through a first-order lag of 0, 0.1, 0.3, 1, 2.26 (600 s, blind5's FOG) and 3 × P/2π; 12
seeds each. Per record ``regress_channel`` at refine's share (α = 0.375 %): accepted by each test, and what the
optional terms then report (the lag kept, a d(ch)/dt term kept, the coefficient's error).

Null: records with no coupling — (a) the channel a cycling or a random-walk temperature (alternately), the noise
white plus flicker, white plus random walk, or all three (in turn), 10 Hz × 5·10⁴; (b) the null records of
``benches/channel_regression.py`` (random-walk, cycling, flicker, warm-up, heater-step, multi-position and white
channels; 1 Hz × 25 h and 100 Hz × 2·10⁵; N + B + K, N + B, N + K, N + B + K + GM), every channel through
``regress_channel`` whatever its route. Both tests' p-values; rejection rates at 5 %, 1 % and the test's α with
95 % Clopper–Pearson intervals.

Usage::

    python benches/channel_lag_first_test.py                 # -> benches/results/channel_lag_first_test.{json,md}
    python benches/channel_lag_first_test.py --seeds 3 --null 30 --out DIR
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

import _common
import channel_regression as cr
import refine_blind as rb
from allanite.model import channels
from allanite.model.refinement.levels import LEVEL, alpha

sensors = rb.sensors
HERE = Path(__file__).resolve().parent
FS, N = 10.0, 50_000
COEF = 2e-4
#: the cycle's period over 2π (s): the lag's unit
UNIT = (N - 1) / FS / 3.0 / (2.0 * math.pi)
LAGS = (0.0, 0.1, 0.3, 1.0, 600.0 / UNIT, 3.0)
FOG = {"N": 8e-4, "B": 1.4e-4, "K": 2e-6}
NULL_MIXES = ({"N": 8e-4, "B": 3e-4}, {"N": 8e-4, "K": 4e-6}, {"N": 8e-4, "B": 1.4e-4, "K": 2e-6})


def lagged_record(mult: float, seed: int):
    """(rate, logged temperature) with the coupling through a lag of ``mult`` × P/2π."""
    rng = np.random.default_rng(seed)
    t = np.arange(N) / FS
    y = rb.noise(N, FS, rng, **FOG)
    temp = sensors.temperature_profile(t, "cycle", rng, lo=20.0, hi=45.0)
    sensor = sensors.first_order_lag(temp, FS, mult * UNIT) if mult else temp
    return y + COEF * (sensor - sensor.mean()), temp + 0.01 * rng.standard_normal(N)


def null_record(seed: int):
    """(rate, logged temperature) without coupling: a cycling or random-walk channel, flicker / random walk noise."""
    rng = np.random.default_rng(10_000 + seed)
    t = np.arange(N) / FS
    y = rb.noise(N, FS, rng, **NULL_MIXES[seed % 3])
    temp = sensors.temperature_profile(t, ("cycle", "walk")[(seed // 3) % 2], rng, lo=20.0, hi=45.0)
    return y, temp + 0.01 * rng.standard_normal(N)


def power(seeds: int) -> list:
    a = alpha("regression", LEVEL)
    rows = []
    for mult in LAGS:
        for seed in range(seeds):
            y, temp = lagged_record(mult, seed)
            r = channels.regress_channel(y, temp, FS, name="temp", alpha=a, level=LEVEL)
            ip = r.test["in_phase"]
            rows.append(
                {
                    "lag_s": mult * UNIT,
                    "seed": seed,
                    "accepted": bool(r.accepted),
                    "in_phase_accepted": bool(ip["statistic"] > ip["threshold"]),
                    "statistic": r.test["statistic"],
                    "threshold": r.test["threshold"],
                    "in_phase_statistic": ip["statistic"],
                    "in_phase_threshold": ip["threshold"],
                    "phase_deg": r.test["phase_deg"],
                    "coefficient_error": r.params["coefficient"] / COEF - 1.0 if r.accepted else None,
                    "lag_kept": r.params.get("lag_s"),
                    "rate_kept": "rate_coefficient" in r.params,
                    "removal_lag_s": r.removal_lag_s,
                }
            )
        _common.log(f"lag {mult * UNIT:.1f} s done")
    return rows


def null(records: int, suite: bool = False) -> dict:
    """Both tests' p-values on ``records`` null records: this bench's (10 Hz × 5·10⁴), or with ``suite``
    ``benches/channel_regression.py``'s."""
    a = alpha("regression", LEVEL)
    p_new, p_old, kinds = [], [], []
    for seed in range(records):
        if suite:
            kind, fs, _, y, temp = cr.record(seed)
        else:
            kind, fs, (y, temp) = "", FS, null_record(seed)
        r = channels.regress_channel(y, temp, fs, name="temp", alpha=a, level=LEVEL, terms=())
        p_new.append(r.test["p_value"])
        p_old.append(r.test["in_phase"]["p_value"])
        kinds.append(kind)
    levels = (0.05, 0.01, a)
    return {
        "records": records,
        "kinds": kinds,
        "alpha": a,
        "quadrature": _common.rejection_rates(p_new, levels),
        "in_phase": _common.rejection_rates(p_old, levels),
        "p_quadrature": p_new,
        "p_in_phase": p_old,
    }


def _power_lines(rows: list) -> list:
    lines = [
        "| lag (s) | lag × 2π/P | accepted: channel alone (before) | channel + quadrature (now) | median 2Δℓ / "
        "threshold, before | now | median phase (°) | lag kept | d(ch)/dt kept | median coefficient error |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for mult in LAGS:
        sel = [r for r in rows if abs(r["lag_s"] - mult * UNIT) < 1e-9]
        errs = [r["coefficient_error"] for r in sel if r["coefficient_error"] is not None]
        med = lambda k: float(np.median([r[k] for r in sel]))  # noqa: E731
        lines.append(
            f"| {mult * UNIT:.0f} | {mult:.2g} | {sum(r['in_phase_accepted'] for r in sel)} of {len(sel)} | "
            f"{sum(r['accepted'] for r in sel)} of {len(sel)} | {med('in_phase_statistic'):.1f} / "
            f"{med('in_phase_threshold'):.1f} | {med('statistic'):.1f} / {med('threshold'):.1f} | "
            f"{med('phase_deg'):.0f} | {sum(r['lag_kept'] is not None for r in sel)} | "
            f"{sum(r['rate_kept'] for r in sel)} | {np.median(errs) if errs else float('nan'):+.1%} |"
        )
    return lines


def _null_lines(nl: dict) -> list:
    lines = ["| test | p ≤ 5 % | p ≤ 1 % | p ≤ α = {:.3g} |".format(nl["alpha"]), "|---|---|---|---|"]
    for key, name in (
        ("in_phase", "channel alone, F(1, ν) (before)"),
        ("quadrature", "channel + quadrature, 2·F(2, ν)"),
    ):
        cells = " | ".join(_common.rate_cell(v, count=True) for v in nl[key].values())
        lines.append(f"| {name} | {cells} |")
    return lines


def write(res: dict, out: Path) -> None:
    nl, ns = res["null"], res["null_suite"]
    lines = [
        "# A lagged channel's coupling: the first test with the channel's quadrature",
        "",
        f"`python benches/channel_lag_first_test.py`, {_common.machine_line()}; {res['seconds']:.0f} s.",
        "",
        "## Power (10 Hz × 5·10⁴, FOG-like noise, 20–45 °C cycling three times, 2·10⁻⁴ per °C through a lag; "
        f"P/2π = {UNIT:.0f} s)",
        "",
        *_power_lines(res["power"]),
        "",
        "The optional terms: a lag and a d(ch)/dt term weighed by their likelihoods where the d(ch)/dt term passes, "
        'the phase\'s sign deciding within `LAG_MARGIN` (docs/channels.md, "A lag or a d(ch)/dt term"); the '
        "coefficient is the in-phase one where a d(ch)/dt term is kept.",
        "",
        f"## Null ({nl['records']} records, no coupling: cycling / random-walk channels; white + flicker, white + "
        "random walk, all three)",
        "",
        *_null_lines(nl),
        "",
        f"## Null, `benches/channel_regression.py`'s records ({ns['records']}: random-walk, cycling, flicker, "
        "warm-up, heater-step, multi-position and white channels; 1 Hz × 25 h and 100 Hz × 2·10⁵; four noise mixes)",
        "",
        *_null_lines(ns),
        "",
        "Rates with their 95 % Clopper–Pearson intervals.",
    ]
    _common.write_results(out, "channel_lag_first_test", lines, res)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", type=int, default=12)
    ap.add_argument("--null", type=int, default=2000)
    ap.add_argument("--null-suite", type=int, default=2000)
    ap.add_argument("--out", type=Path, default=HERE / "results")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    res = {"power": power(args.seeds), "null": null(args.null), "null_suite": null(args.null_suite, suite=True)}
    res["seconds"] = time.perf_counter() - t0
    write(res, args.out)
    print("\n".join(_power_lines(res["power"])))
    print("\n".join(_null_lines(res["null"]) + _null_lines(res["null_suite"])))


if __name__ == "__main__":
    main()
