#!/usr/bin/env python3
"""Do a channel regression's intervals cover? The 68.3 % and 95 % coverage and the median half-widths of every
parameter ``allanite.model.channels.regress_channel`` reports (coefficient, lag_s, rate_coefficient; a lag only
profiled for the removal too), over seeded replicas, before and after a change of the interval code (r13cover).

Cases: the five of ``benches/channel_lag_bias.py`` (blind5's FOG through a 600 s lag, blind8's daily cycle on T
and dT/dt, blind3's 900 s FOG, the tests' 300 s lag, blind5's dT/dt lead); ``benches/channel_swing_interval.py``'s
temperature swinging once (40 Hz × 4·10⁵, the level term alone); and three unlike them — a 50 Hz MEMS-like gyro
with a chamber cycling every 1000 s through a 150 s lag (``mems50``), a 5 Hz record whose temperature is a random
walk through the housing's lag (``walk5``, the level term alone where nothing else is kept), and a 200 Hz record
of 10 min whose temperature cycles twice with a d(ch)/dt lead (``fast200``).

The 68 % intervals are the regression's own; the 95 % ones of the coefficients are the same ±t_ν·se scaled to
t_ν's 97.5 % quantile (ν the one each interval uses; the point estimate and every decision depend on the
intervals' level through the profiled lag's use, so the regression is not rerun at 95 %); a lag's interval is a
profile likelihood's, reported at 68 % only. Coverage with its binomial 95 % Clopper–Pearson interval.

Usage::

    python benches/channel_interval_coverage.py --tag after            # -> results/channel_interval_coverage_after.json
    python benches/channel_interval_coverage.py --page                 # both tags -> results/channel_interval_coverage.md
    python benches/channel_interval_coverage.py --case mems50 --seeds 4 --tag try --out /tmp
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
from scipy.stats import t as t_dist

import _coverage_summary
import channel_lag_bias as clb
import channel_swing_interval as csi
import refine_blind as rb
from allanite.model.channels import regress_channel

sensors = rb.sensors
HERE = Path(__file__).resolve().parent
Q68, Q95 = (1.0 - 0.683) / 2.0, 0.025


def _swing(fs, n, rng):
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2e-3, B=2e-4, K=5e-6)
    temp = 10.0 + 30.0 * (0.5 - 0.5 * np.cos(2 * np.pi * t / 20_000.0)) + 0.5 * csi.rb10._weather(n, fs, rng, 300.0)
    return y + csi.C * (temp - temp.mean()), temp + 0.01 * rng.standard_normal(n)


def _mems50(fs, n, rng):
    """50 Hz × 2·10⁵ (4000 s): N 4·10⁻³, B 4·10⁻⁴, K 3·10⁻⁵; a chamber cycling 0–50 °C every 1000 s (plus a little
    wander) reaching the rate through 150 s at 1·10⁻³ per °C."""
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=4e-3, B=4e-4, K=3e-5)
    temp = 25.0 + 25.0 * np.sin(2 * np.pi * t / 1000.0 + rng.uniform(0, 2 * np.pi))
    temp = temp + 2.0 * csi.rb10._weather(n, fs, rng, 200.0)
    drive = sensors.first_order_lag(temp, fs, 150.0)
    return y + 1e-3 * (drive - drive.mean()), temp + 0.02 * rng.standard_normal(n)


def _walk5(fs, n, rng):
    """5 Hz × 6·10⁴ (12 000 s): N 1·10⁻³, B 1·10⁻⁴, K 2·10⁻⁶; the temperature a random walk through the housing's
    lag (``tests/sensors.py``'s ``walk``, 15–30 °C) at 2·10⁻⁴ per °C."""
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=1e-3, B=1e-4, K=2e-6)
    temp = sensors.temperature_profile(t, "walk", rng, lo=15.0, hi=30.0)
    return y + 2e-4 * (temp - temp.mean()), temp + 0.01 * rng.standard_normal(n)


def _fast200(fs, n, rng):
    """200 Hz × 1.2·10⁵ (600 s): N 2·10⁻³, B 3·10⁻⁴, K 2·10⁻⁵; the temperature cycling twice 30–40 °C with a
    d(ch)/dt lead: 5·10⁻⁴ per °C and 0.3 per °C/s."""
    return clb._cycle(fs, n, rng, dict(N=2e-3, B=3e-4, K=2e-5), 30.0, 40.0, 5e-4, rate=0.3)


#: name -> (what, fs, n, builder(fs, n, rng) -> (y, temp), truth, regress_channel's terms or None for all)
CASES = {k: (*v, None) for k, v in clb.CASES.items()} | {
    "swing": ("channel_swing_interval: one half-cosine 10 → 40 °C, level term alone", 40.0, 400_000, _swing,
              {"coefficient": csi.C}, ()),
    "mems50": (_mems50.__doc__.split("\n")[0], 50.0, 200_000, _mems50, {"coefficient": 1e-3, "lag_s": 150.0}, None),
    "walk5": (_walk5.__doc__.split("\n")[0], 5.0, 60_000, _walk5, {"coefficient": 2e-4}, None),
    "fast200": (_fast200.__doc__.split("\n")[0], 200.0, 120_000, _fast200,
                {"coefficient": 5e-4, "rate_coefficient": 0.3}, None),
}  # fmt: skip


def _dof(r, k: str) -> float:
    return float(r.test["in_phase"]["dof"] if k == "coefficient" else r.terms[k]["dof"])


def _entry(value: float, truth: float, lo: float, hi: float) -> dict:
    return {
        "value": value,
        "error": value / truth - 1.0,
        "covered": bool(lo <= truth <= hi),
        "width": (hi - lo) / 2.0 / abs(value),
    }


def one(case: str, seed: int) -> dict:
    _, fs, n, build, truth, terms = CASES[case]
    y, temp = build(fs, n, np.random.default_rng(seed))
    t0 = time.process_time()
    kw = {} if terms is None else {"terms": terms}
    r = regress_channel(y, temp, fs, name="temp", **kw)
    row = {"case": case, "seed": seed, "cpu_s": time.process_time() - t0, "accepted": r.accepted}
    row["kept"] = sorted(k for k in r.params if k != "coefficient")
    row["removal_lag_s"] = r.removal_lag_s
    for k, v in truth.items():
        if k not in r.params:
            continue
        lo, hi = r.intervals[k]
        row[k] = _entry(r.params[k], v, lo, hi)
        if k != "lag_s":
            dof = _dof(r, k)
            half = (hi - lo) / 2.0 * float(t_dist.isf(Q95, dof) / t_dist.isf(Q68, dof))
            row[k]["covered95"] = bool(abs(r.params[k] - v) <= half)
            row[k]["dof"] = dof
    prof = r.terms.get("lag_s", {}).get("profiled")
    if "lag_s" in truth and "lag_s" not in r.params and prof is not None and r.removal_lag_s is not None:
        row["profiled_lag_s"] = _entry(r.removal_lag_s, truth["lag_s"], *prof["interval"])
    return row


def _params(case: str) -> list:
    keys = list(CASES[case][4])
    return keys + (["profiled_lag_s"] if "lag_s" in keys else [])


def summary(rows: list) -> dict:
    """Per case: records, acceptances, and per parameter the error's s.d., the 68 % interval's median half-width
    and the 68 % and 95 % intervals' coverage (:func:`_coverage_summary.summary`)."""
    return _coverage_summary.summary(rows, _params)


def _cov(c) -> str:
    k, n, lo, hi = c
    return f"{k}/{n} = {k / n:.0%} ({lo:.0%}–{hi:.0%})"


def table(before: dict, after: dict) -> str:
    lines = [
        "| case | parameter | records (before / after) | sd of the error | 68 % half-width, median: before → after "
        "| 68 % coverage before | 68 % coverage after | 95 % coverage before | 95 % coverage after |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for case in after:
        for k in _params(case):
            b, a = before.get(case, {}).get(k), after[case].get(k)
            if a is None and b is None:
                continue
            nb, na = (b["n"] if b else 0), (a["n"] if a else 0)
            sd = f"{a['sd_error']:.1%}" if a else "—"
            hw = f"{b['median_half_width']:.1%} → {a['median_half_width']:.1%}" if a and b else "—"
            cells = [_cov(x["coverage"]) if x else "—" for x in (b, a)]
            cells += [_cov(x["coverage95"]) if x and "coverage95" in x else "—" for x in (b, a)]
            lines.append(f"| {case} | {k} | {nb} / {na} | {sd} | {hw} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


#: What the recorded page says beyond its table (kept true to it; written after the runs).
NOTES: list[str] = [
    "**Same estimates.** On all 360 records every estimate and decision is identical before and after (which terms "
    "are kept, the lag, every coefficient, the removal's lag): only the intervals changed, so no test's false-alarm "
    "rate can move. 'Before' reproduces `channel_lag_bias.md`'s recorded rows exactly (e.g. fog600's 21/40 and "
    "19/33, daily's 18/32).",
    "**Why they were narrow** (diagnosed on 40–60 replicas a case, `allanite.model._gls_cov`'s docstring): the noise "
    "refitted beside the coefficients lay 0.87× (±0.02) and 0.83× (±0.02) of the noise-only fit in the cycle's band "
    "(fog600, lag300) — the coefficients and the lag's direction take their own share of that band's power and the "
    "noise fit follows it down (the ML variance's RSS/n); given that share back (the restricted noise) it read 1.05× "
    "and 0.99×. A swinging channel's score variance, exact at the record's edges, was 1.5× Whittle's (median of 60 "
    "records of a 4 Hz replica of `swing`). A cycling channel without a lag already covered (a 2 Hz cycle 30/40, "
    "fog900 34/40): there the fix widens by 1–4 %.",
    "**Widths.** The median 68 % half-width grows 1–11 % where the intervals covered or nearly (fog900 8.9 → 9.0 %, "
    "lead 7.5 → 8.1 %, walk5 5.7 → 6.3 %, fast200 6.9 → 7.3 %), 14–18 % where they did not (fog600's coefficient "
    "10.2 → 11.6 %, daily's rate coefficient 13.1 → 15.4 %); the swing's 1.7× (its ν is 2–4). The swing now "
    "over-covers (31/40 here, 74/90 in `channel_swing_interval.md`): the exact edge variance and t_ν at ν ≈ 3 "
    "together are somewhat conservative there.",
    "**Left: mems50's coefficient is a model choice, not an interval.** On 18 of its 40 records the d(ch)/dt term is "
    "kept in place of the 150 s lag (ωT = 0.94 on the 1000 s cycle) and the coefficient then reads −46 % (median; "
    "c/(1 + (ωT)²) is −47 %), the rate model's in-phase part, with a ±3 % interval: none of the 18 covers the lag "
    "model's truth, before or after. On the 22 with the lag kept the coefficient covers 14 → 15 of 22, the lag 14 of "
    "22. Which of the two describes the phase is `allanite.model._coupling._lag_or_rate`'s (r11lagrate), not changed "
    "here. Still under 68 % within its Clopper–Pearson interval: lag300's coefficient (23/40, 95 % 40/40), fast200's "
    "coefficient (25/40). "
    "Since r14lagrate (the lag weighed on the channel lagged in time, `benches/results/r14lagrate.md`) the lag is "
    "kept on all 40: the coefficient covers 26/40 (68 %) and 40/40 (95 %), the sd of its error 1.4 %.",
    "**Cost** (`--cost`, one record a case, the interval code against the inverse Fisher information at the fitted "
    "noise alternated three times in one process, load ≈ 17–20 on 2 cores): `regress_channel`'s CPU × 1.03–1.21 "
    "(fog600 1.03, mems50 1.05, daily 1.06, lag300 1.08, lead 1.09, fog900 1.09, fast200 1.12, swing 1.21) and "
    "× 1.40 on walk5's 0.07 s (`channel_interval_coverage_cost.json`).",
]


def page(before: dict, after: dict, meta: dict) -> str:
    head = [
        "# A channel regression's intervals: coverage before and after r13cover",
        "`python benches/channel_interval_coverage.py` (its docstring: the cases, how the 95 % intervals are read). "
        f"{meta.get('seeds', '?')} seeds per case (seeds {meta.get('first_seed', 1)}…); 'before' is main at "
        f"{meta.get('before_commit', '?')}, 'after' this branch at {meta.get('after_commit', '?')}; "
        f"load average {meta.get('load', '?')} on 2 cores while they ran.",
    ]
    return "\n\n".join([*head, table(before, after), *NOTES]) + "\n"


def cost(cases, repeats: int = 3) -> dict:
    """CPU of ``regress_channel`` on each case's first record with the intervals' covariance as it is, over the
    same with it replaced by the inverse Fisher information at the fitted noise (the code before r13cover), the
    two alternated ``repeats`` times in this one process: the ratio of their medians."""
    import allanite.model._lag_time as lag_time
    import allanite.model.channels as channels

    def fisher(bands, design, fit):
        s = fit["s"]
        return np.linalg.inv(2.0 * design.gram(bands, 1.0 / s)[0]), {"s": s, "amounts": fit.get("amounts")}

    real = (channels.interval_cov, lag_time.interval_cov)
    out = {}
    for case in cases:
        _, fs, n, build, _, terms = CASES[case]
        y, temp = build(fs, n, np.random.default_rng(1))
        kw = {} if terms is None else {"terms": terms}
        times: dict = {"now": [], "fisher": []}
        for _ in range(repeats):
            for label, fn in (("now", real), ("fisher", (fisher, fisher))):
                channels.interval_cov, lag_time.interval_cov = fn
                t0 = time.process_time()
                regress_channel(y, temp, fs, name="temp", **kw)
                times[label].append(time.process_time() - t0)
        channels.interval_cov, lag_time.interval_cov = real
        out[case] = {k: float(np.median(v)) for k, v in times.items()}
        out[case]["ratio"] = out[case]["now"] / out[case]["fisher"]
        print(case, out[case], flush=True)
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--case", action="append", choices=sorted(CASES), help="run only these cases (repeatable)")
    p.add_argument("--seeds", type=int, default=40)
    p.add_argument("--first-seed", type=int, default=1)
    p.add_argument("--out", type=Path, default=HERE / "results")
    p.add_argument("--tag", default="after", help="the JSON's suffix: before or after")
    p.add_argument("--page", action="store_true", help="only write the page from the before and after JSONs")
    p.add_argument("--meta", default="{}", help="JSON merged into the page's header fields")
    p.add_argument("--cost", action="store_true", help="only the CPU ratio of the interval code (one record a case)")
    args = p.parse_args(argv)
    stem = args.out / "channel_interval_coverage"
    if args.cost:
        Path(f"{stem}_cost.json").write_text(json.dumps(cost(args.case or list(CASES)), indent=1))
        return 0
    if args.page:
        runs = {t: json.loads(Path(f"{stem}_{t}.json").read_text()) for t in ("before", "after")}
        meta = runs["after"].get("meta", {}) | json.loads(args.meta)
        text = page(summary(runs["before"]["rows"]), summary(runs["after"]["rows"]), meta)
        Path(f"{stem}.md").write_text(text)
        print(text)
        return 0
    rows = []
    for case in args.case or list(CASES):
        for seed in range(args.first_seed, args.first_seed + args.seeds):
            rows.append(one(case, seed))
            print(json.dumps(rows[-1]), flush=True)
    meta = {"seeds": args.seeds, "first_seed": args.first_seed}
    args.out.mkdir(parents=True, exist_ok=True)
    Path(f"{stem}_{args.tag}.json").write_text(json.dumps({"rows": rows, "meta": meta}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
