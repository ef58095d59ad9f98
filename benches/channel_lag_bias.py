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
import sys
import time
from pathlib import Path

import numpy as np

import _coverage_summary
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


def summary(rows: list) -> dict:
    """Per case: records, acceptances, the optional terms kept, and per parameter the error's median (95 % CI),
    mean and s.d., the 68 % interval's coverage and median half-width (:func:`_coverage_summary.summary`)."""
    return _coverage_summary.summary(rows, _params, kept=("quadratic", "rate_coefficient", "lag_s"), centre=True)


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


#: What the recorded page shows (kept true to it).
NOTES = [
    "**Replicas.** On the failing rows' own records (`--own-seed`: the blind builder at its seed, regressed whole "
    "and block-averaged to the replica's rate) the estimates agree: blind5's FOG lag 475.2 s whole (2 kHz × 10⁷, "
    "27 s CPU) and 476.6 s averaged to 10 Hz (0.6 s), coefficient 1.783 and 1.798·10⁻⁴; blind8's rate coefficient "
    "2.652 whole and 2.653 at 0.5 Hz, coefficient 1.170 and 1.170·10⁻⁴.",
    "**Bias or scatter: scatter.** blind5's lag: median −1.1 % (95 % CI −7.4 … +8.4 %), sd 13.3 % — the row's "
    "−20.8 % is a 1.6σ draw; its coefficient median −0.2 % (sd 17 %). blind8's rate coefficient: +3.1 % "
    "(−5.8 … +12.7 %) on these 40 seeds, sd 15.9 %; on 80 more (seeds 41–120) +6.4 % (+2.6 … +10.4 %), sd 13.1 %, "
    "kept on 54 of 80, coverage 38 of 54 (70 %) — a few per cent high where it is kept (its test passes on the "
    "larger estimates), the row's +32.6 % a 2σ draw. One record carries the lag to ±13 % and the dT/dt coefficient "
    "to ±15 %: the judge's 20 % is 1.5σ and 1.3σ of that. The rows that pass stay unbiased (fog900 +1.3 %, the 300 s "
    "lag −0.5 %, the lead +1.1 / +1.3 %).",
    "**The intervals (the change, r12lag).** Before (the code at e849a13, same 200 records): blind5's coefficient "
    "12 of 40 covered (median half-width 4.7 % for a scatter of 17 %: the lag's error left out), its lag 33 of 33 "
    "(±54 %: the grid's profile at the lag-0 fit's noise); the 300 s lag's coefficient 22/40, its lags 12/12 and "
    "26/27 (±29 %, ±32 %); fog900's profiled lag 27/35 (±50 %). After: the coefficient with the lag free "
    "(`allanite.model._lag_time.cov_beside_lag`) 21/40 (±10.2 %; among the 33 with a kept lag 18, their errors "
    "1.12× their half-widths in rms), the lag from its profile in time at the refitted noise 19/33 (±11.6 %); the "
    "300 s lag's 23/40, 7/12, 19/27 (±14 %, ±18 %); fog900's profiled lag 26/35 (±47 %). Every estimate and "
    "decision identical on all 200 records (which terms kept, the lag, the coefficients, the removal's lag), so "
    "the channel tests' false alarms cannot move. Left: blind5's coefficient still below 68 % (21/40, CP 36–68 %): "
    "on 7 records the lag is only profiled or the d(ch)/dt term takes its place (the one such record 5.2 half-widths "
    "off), and the errors have heavier tails than the Fisher interval's.",
    "**The blind rows** (`--case`, at the change): blind5's FOG exactly as recorded (lag 475.2 s, −20.8 %; "
    "coefficient −10.9 %; χ²/dof 1.9 → 1.02, held out 5.06 → 1.24 %; ✗, 101 s CPU). Its intervals (`--own-seed`, "
    "the whole record): the lag 416–532 s (was 338–711 s), the coefficient 1.60–1.97·10⁻⁴ (was 1.69–1.88·10⁻⁴) — "
    "neither holds the truth: at ±12 % the row's lag is a 1.8σ draw, and 14 of the 33 replicas' kept lags are outside theirs "
    "too. The regression on 10⁷ samples 27 → 36 s CPU (the profile in time, ≈ 10 transforms). blind8's 48 h "
    "row as recorded (no lag used: nothing changes there; rate coefficient +32.6 %, ✗).",
]


NOTES.append(
    "**The table now (r13cover, rerun whole on this branch; the paragraphs above describe r12lag's change).** The "
    "intervals' covariance is the GLS sandwich at the restricted noise — the noise refitted with the power the "
    "coefficients and the lag's direction took from the cycle's bands given back, the score's variance exact at the "
    'record\'s edges (`allanite.model._gls_cov`, docs/channels.md "Intervals that cover"); every estimate and '
    "decision as before on all 200 records. fog600's coefficient 21 → 28 of 40, its lag 19 → 22 of 33, daily's rate "
    "coefficient 18 → 20 of 32; before → after on these seeds and four more cases, with 95 % coverage and widths: "
    "`channel_interval_coverage.md`."
)


def page(summ: dict) -> str:
    return (
        "\n\n".join(
            [
                "# A channel coupling's lag and d(ch)/dt coefficient: bias, scatter and coverage",
                "`python benches/channel_lag_bias.py` (40 seeds per case; `allanite.model.channels.regress_channel` on "
                "each record; ≈ 0.5 s CPU per record). The 68 % intervals are the regression's own.",
                table(summ),
                *NOTES,
            ]
        )
        + "\n"
    )


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
    (args.out / f"{stem}.md").write_text(page(summ))
    print(table(summ))
    return 0


if __name__ == "__main__":
    sys.exit(main())
