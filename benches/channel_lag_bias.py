#!/usr/bin/env python3
"""Is a channel coupling's lag / d(ch)/dt coefficient biased, or only scattered — and are its 68 % intervals
honest? (r12lag: two blind rows fail on one parameter of the channel regression, ``refine_blind5.md``'s 600 s
FOG lag at −20.8 % and ``refine_blind8.md``'s 48 h dT/dt coefficient at +32.6 %.)

Each case is a cheaper replica of a blind or test record: the same noise terms (N, B, K — the same PSD at the
low frequencies where the coupling's information is, the cycle's), the same temperature profile over the same
span and the same coupling, at a lower sampling rate. Per seed, ``allanite.model.channels.regress_channel`` (what
refine's regression step runs) on the rate and the logged channel; per case over the seeds: the median error of
each true parameter with its 95 % order-statistic interval, and the share of records whose 68.3 % interval holds
the truth (coverage; binomial 95 % Clopper–Pearson interval), and how often each term was kept.

Cases: blind5's 2 kHz FOG through a 600 s lag (10 Hz × 5·10⁴), blind8's 48 h daily cycle on T and dT/dt
(0.5 Hz × 86 400) — the two failing rows — and three that pass today: blind3's 900 s FOG (1 Hz × 10⁵, native),
``tests/sensors.py``'s 300 s lag (1 Hz × 3·10⁴) and blind5's dT/dt lead (2 Hz × 4·10⁴).

Usage::

    python benches/channel_lag_bias.py                     # -> benches/results/channel_lag_bias.{json,md}
    python benches/channel_lag_bias.py --seeds 4 --case fog600 --out DIR
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np
from scipy.stats import beta

import refine_blind as rb
from allanite.model.channels import regress_channel

sensors = rb.sensors
HERE = Path(__file__).resolve().parent


def _cycle(fs, n, rng, noise, lo, hi, coef, lag=None, rate=None, profile="cycle"):
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, **noise)
    temp = sensors.temperature_profile(t, profile, rng, lo=lo, hi=hi)
    drive = sensors.first_order_lag(temp, fs, lag) if lag else temp
    comp = coef * (drive - drive.mean())
    if rate:
        comp = comp + rate * np.gradient(temp, 1.0 / fs)
    return y + comp, temp + 0.01 * rng.standard_normal(n)


def _daily(fs, n, rng):
    """blind8's 48 h row (``refine_blind8._daily``) at ``fs``."""
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2e-3, B=2e-4, K=2e-6)
    weather = sensors.first_order_lag(np.cumsum(rng.standard_normal(n)), fs, 3600.0)
    weather = 1.5 * weather / max(np.ptp(weather), 1e-300)
    temp = 23.0 + 5.0 * np.sin(2 * np.pi * t / 86_400.0 - 2.0) + weather
    comp = 1.3e-4 * (temp - temp.mean()) + 2.0 * np.gradient(temp, 1.0 / fs)
    return y + comp, temp + 0.01 * rng.standard_normal(n)


#: name -> (what, fs, n, builder(fs, n, rng) -> (y, temp), truth)
CASES = {
    "fog600": (
        "blind5: 2 kHz tactical FOG × 10⁷ (5000 s), T through a 600 s lag — at 10 Hz × 5·10⁴",
        10.0,
        50_000,
        lambda fs, n, rng: _cycle(fs, n, rng, dict(N=8e-4, B=1.4e-4, K=2e-6), 20.0, 45.0, 2e-4, lag=600.0),
        {"coefficient": 2e-4, "lag_s": 600.0},
    ),
    "daily": (
        "blind8: 48 h at 5 Hz, daily cycle ±5 °C plus weather, T and dT/dt — at 0.5 Hz × 86 400",
        0.5,
        86_400,
        _daily,
        {"coefficient": 1.3e-4, "rate_coefficient": 2.0},
    ),
    "fog900": (
        "blind3: FOG-like 1 Hz × 10⁵, T through a 900 s lag (native)",
        1.0,
        100_000,
        lambda fs, n, rng: _cycle(fs, n, rng, dict(N=2e-7, B=1e-7, K=2e-8), 15.0, 35.0, 6e-7, lag=900.0),
        {"coefficient": 6e-7, "lag_s": 900.0},
    ),
    "lag300": (
        "tests/sensors.py: T through a 300 s lag, 10 Hz × 3·10⁵ (30 000 s) — at 1 Hz × 3·10⁴",
        1.0,
        30_000,
        lambda fs, n, rng: _cycle(fs, n, rng, dict(N=2e-3, B=5e-4, K=1e-5), 5.0, 20.0, 1e-3, lag=300.0),
        {"coefficient": 1e-3, "lag_s": 300.0},
    ),
    "lead": (
        "blind5: cycling 10–40 °C, T and dT/dt (a lead), 50 Hz × 10⁶ (20 000 s) — at 2 Hz × 4·10⁴",
        2.0,
        40_000,
        lambda fs, n, rng: _cycle(fs, n, rng, dict(N=3e-3, B=5e-4, K=1e-5), 10.0, 40.0, 2e-4, rate=0.1),
        {"coefficient": 2e-4, "rate_coefficient": 0.1},
    ),
}


def one(case: str, seed: int) -> dict:
    _, fs, n, build, truth = CASES[case]
    y, temp = build(fs, n, np.random.default_rng(seed))
    t0 = time.process_time()
    r = regress_channel(y, temp, fs, name="temp")
    row = {"case": case, "seed": seed, "cpu_s": time.process_time() - t0, "accepted": r.accepted}
    row["kept"] = sorted(k for k in r.params if k != "coefficient")
    row["removal_lag_s"] = r.removal_lag_s
    prof = r.terms.get("lag_s", {}).get("profiled")
    if "lag_s" in truth and "lag_s" not in r.params and prof is not None and r.removal_lag_s is not None:
        lo, hi = prof["interval"]
        v = truth["lag_s"]
        row["profiled_lag_s"] = {
            "value": r.removal_lag_s,
            "error": r.removal_lag_s / v - 1.0,
            "covered": bool(lo <= v <= hi),
            "width": (hi - lo) / 2.0 / r.removal_lag_s,
        }
    for k, v in truth.items():
        if k in r.params:
            lo, hi = r.intervals[k]
            row[k] = {"value": r.params[k], "error": r.params[k] / v - 1.0, "covered": bool(lo <= v <= hi)}
            row[k]["width"] = (hi - lo) / 2.0 / abs(r.params[k])
    return row


def _params(case: str) -> list:
    """The truth's parameters, and for a lag the profiled one the removal used where the lag was not kept."""
    keys = list(CASES[case][4])
    return keys + (["profiled_lag_s"] if "lag_s" in keys else [])


#: The failing blind rows at their own seeds: (module, builder, seed, the replica's case, block length to it).
OWN_SEED = {"fog600": ("refine_blind5", "_fog_lag", 503, 200), "daily": ("refine_blind8", "_daily", 803, 10)}


def own_seed(case: str) -> dict:
    """The blind row's own record (its builder, its seed) regressed whole, and block-averaged to the replica's
    rate (the mean of each block: the same noise below the new Nyquist, the same cycle): the replica is fair when
    the two give the same estimate."""
    import importlib

    mod, fn, seed, k = OWN_SEED[case]
    y, fs, chans, _, _ = getattr(importlib.import_module(mod), fn)(np.random.default_rng(seed))
    temp = chans["temp"]
    out = {}
    for label, yy, tt, f in (("whole", y, temp, fs), ("averaged", *(_blocks(a, k) for a in (y, temp)), fs / k)):
        t0 = time.process_time()
        r = regress_channel(yy, tt, f, name="temp")
        out[label] = {"fs": f, "params": r.params, "intervals": r.intervals, "cpu_s": time.process_time() - t0}
        out[label]["removal_lag_s"] = r.removal_lag_s
        del r
    return out


def _blocks(a: np.ndarray, k: int) -> np.ndarray:
    m = a.size // k
    return a[: m * k].reshape(m, k).mean(axis=1)


def _median_ci(x: np.ndarray) -> tuple[float, float, float]:
    """Median and its 95 % order-statistic interval (binomial ranks)."""
    x = np.sort(x)
    n = x.size
    k = int(max(0, math.floor(n / 2 - 0.98 * math.sqrt(n))))
    return float(np.median(x)), float(x[k]), float(x[min(n - 1, n - 1 - k)])


def _cp(k: int, n: int) -> tuple[float, float]:
    lo = 0.0 if k == 0 else float(beta.ppf(0.025, k, n - k + 1))
    hi = 1.0 if k == n else float(beta.ppf(0.975, k + 1, n - k))
    return lo, hi


def summary(rows: list) -> dict:
    out = {}
    for case in dict.fromkeys(r["case"] for r in rows):
        rs = [r for r in rows if r["case"] == case]
        s: dict = {"records": len(rs), "accepted": sum(r["accepted"] for r in rs)}
        s["kept"] = {k: sum(k in r["kept"] for r in rs) for k in ("quadratic", "rate_coefficient", "lag_s")}
        for k in _params(case):
            have = [r[k] for r in rs if k in r]
            if not have:
                continue
            err = np.array([h["error"] for h in have])
            cov = sum(h["covered"] for h in have)
            s[k] = {
                "n": len(have),
                "median_error": _median_ci(err),
                "mean_error": float(err.mean()),
                "sd_error": float(err.std(ddof=1)) if err.size > 1 else float("nan"),
                "coverage": (cov, len(have), *_cp(cov, len(have))),
                "median_half_width": float(np.median([h["width"] for h in have])),
            }
        s["cpu_s"] = float(np.median([r["cpu_s"] for r in rs]))
        out[case] = s
    return out


def table(summ: dict) -> str:
    lines = [
        "| case | records | accepted | kept (quadratic / d(ch)/dt / lag) | parameter | median error (95 % CI) "
        "| mean ± sd | 68 % interval's median half-width | 68 % coverage (95 % CI) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for case, s in summ.items():
        kept = " / ".join(str(s["kept"][k]) for k in ("quadratic", "rate_coefficient", "lag_s"))
        for k in _params(case):
            if k not in s:
                lines.append(f"| {case} | {s['records']} | {s['accepted']} | {kept} | {k} | not kept | — | — | — |")
                continue
            m, lo, hi = s[k]["median_error"]
            c, n, clo, chi = s[k]["coverage"]
            lines.append(
                f"| {case} | {s['records']} | {s['accepted']} | {kept} | {k} ({s[k]['n']}) | {m:+.1%} ({lo:+.1%} … {hi:+.1%}) "
                f"| {s[k]['mean_error']:+.1%} ± {s[k]['sd_error']:.1%} | {s[k]['median_half_width']:.1%} | {c}/{n} = {c / n:.0%} ({clo:.0%}–{chi:.0%}) |"
            )
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--case", action="append", choices=sorted(CASES), help="run only these cases (repeatable)")
    p.add_argument("--seeds", type=int, default=24, help="seeds per case (default 24)")
    p.add_argument("--first-seed", type=int, default=1)
    p.add_argument("--out", type=Path, default=HERE / "results", help="folder for channel_lag_bias.{json,md}")
    p.add_argument("--tag", default="", help="suffix of the output files' stem")
    p.add_argument("--own-seed", action="store_true", help="only the failing rows' own records, whole and averaged")
    args = p.parse_args(argv)
    if args.own_seed:
        own = {c: own_seed(c) for c in args.case or list(OWN_SEED)}
        print(json.dumps(own, indent=1, default=float))
        args.out.mkdir(parents=True, exist_ok=True)
        (args.out / f"channel_lag_bias_own_seed{args.tag}.json").write_text(json.dumps(own, indent=1, default=float))
        return 0
    rows = []
    for case in args.case or list(CASES):
        for seed in range(args.first_seed, args.first_seed + args.seeds):
            rows.append(one(case, seed))
            print(json.dumps(rows[-1]), flush=True)
    summ = summary(rows)
    stem = "channel_lag_bias" + args.tag
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / f"{stem}.json").write_text(json.dumps({"rows": rows, "summary": summ}, indent=1))
    print(table(summ))
    return 0


if __name__ == "__main__":
    sys.exit(main())
