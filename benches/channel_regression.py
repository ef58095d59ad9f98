#!/usr/bin/env python3
"""Regressions on slow channels (issue 29 item 1): false alarms, power and cost of
`allanite.model.channels.regress_channel` beside the within-block test it takes over from on slow channels.

A channel is *slow* (`channels.is_slow`) when ≥ 50 % of its variance lies between the means of 8 blocks in time;
slow channels are tested by `regress_channel` (Whittle GLS, F(1, ν)), the others as before by the within-block t
test (`tracing.regression_fit`). Sections:

1. **Null, coupling** (``--records``, default 600): gyro noise independent of the channel — N + B + K, N + B,
   N + K, N + B + K + a Gauss–Markov term in turn — at 1 Hz (25 h) and 100 Hz (2·10⁵ samples) in turn; channels
   in turn: a random-walk temperature, a cycling one (an HVAC cycle of 0.5–2 h, a daily swing, a random walk),
   a flicker one (Kasdin–Walter α = 1), a warm-up (5 → 20 °C, a logistic at a random time), two heater steps
   (the issue's kind), a ±1 g multi-position profile and white noise (fast). The coupling's test at 0.375 %
   (refine's time-domain share of the 5 % level); rates with 95 % Clopper–Pearson intervals — routed (slow →
   Whittle, fast → within blocks), the Whittle test on every channel, the within-block test on every channel.
2. **Null, optional terms** (``--records``): the same slow channels with a real linear coupling (no lag, no
   d(ch)/dt, no square): how often each optional term is kept at its share (0.1 % each).
3. **Power**: the issue's temperature case (25 h at 1 Hz, 10-min block means r ≥ 0.99, 0.45 mrad/s per °C over
   5–20 °C, N 1.5 mrad/s/√Hz, B, K), a lag of 600 s and a d(ch)/dt term (never both), and temperatures at 100 Hz
   and 1 kHz, 10⁵–10⁷ samples.
4. **Cost**: a default `allanite.refine` on 10⁶ samples with a slow channel against the same without it (the
   issue's budget: ≤ 8 s with a channel where 3.3 s without), and `regress_channel` alone.

Usage::

    python benches/channel_regression.py            # -> benches/results/channel_regression.{json,md} (~15 min)
    python benches/channel_regression.py --quick --out DIR
"""

from __future__ import annotations

import argparse
import json
import math
import os
import time
from pathlib import Path

import numpy as np
from scipy.stats import chi2
from scipy.stats import t as t_dist

import _common
import allanite
from allanite.model.channels import ALPHA, TERM_SHARE, heldout_ratio, is_slow, lagged, regress_channel, slow_share
from allanite.model.tracing import regression_fit
from allanite.simulation import kasdin_walter

HERE = Path(__file__).resolve().parent
LEVEL = 0.05
KINDS = ("random walk", "cycling", "flicker", "warm-up", "heater steps", "multi-position", "white")
SLOW_KINDS = ("random walk", "cycling", "flicker", "warm-up", "heater steps")
NOISES = (
    {"N": 1.5e-3, "B": 1e-4, "K": 3e-6},
    {"N": 1.5e-3, "B": 3e-4},
    {"N": 1.5e-3, "K": 1e-5},
    {"N": 1.5e-3, "B": 1e-4, "K": 3e-6, "gauss_markov": [(5e-4, 300.0)]},
)
SETUPS = ((1.0, 90_000), (100.0, 200_000))


def temperature(kind: str, n: int, fs: float, rng) -> np.ndarray:
    """A channel of ``kind`` (°C for the temperatures, g for the multi-position profile)."""
    t = np.arange(n) / fs
    span = n / fs
    walk = np.cumsum(rng.normal(size=n)) / math.sqrt(n)  # ≈ unit wander over the record
    if kind == "random walk":
        return 15.0 + 3.0 * walk
    if kind == "cycling":
        period = rng.uniform(0.02, 0.1) * span
        return 15 + 1.5 * np.sin(2 * np.pi * t / period + rng.uniform(0, 6)) + 3 * np.sin(2 * np.pi * t / span) + walk
    if kind == "flicker":
        return 15.0 + 2.0 * kasdin_walter(n, 1.0, rng) / math.sqrt(math.log(n))
    if kind == "warm-up":
        return (
            5 + 15 / (1 + np.exp(-(t - rng.uniform(0.1, 0.8) * span) / (rng.uniform(0.01, 0.05) * span))) + 0.2 * walk
        )
    if kind == "heater steps":
        return heater_steps(t, span, rng)
    if kind == "multi-position":
        edges = np.cumsum(rng.uniform(0.02, 0.06, size=200) * span * fs).astype(int)
        return np.where(np.searchsorted(edges, np.arange(n), side="right") % 2 == 0, 1.0, -1.0) + 2e-3 * rng.normal(
            size=n
        )
    return rng.normal(size=n)


def heater_steps(t, span, rng, measured_noise=0.02):
    """5 → 12 → 20 °C: two first-order rises (≈ 40 min) at random times, a slow wander, the sensor's noise and
    0.01 °C resolution — a temperature that moves within one or two of 8 blocks."""
    t1, t2 = rng.uniform(0.1, 0.3) * span, rng.uniform(0.5, 0.7) * span
    tc = rng.uniform(0.015, 0.03) * span
    rise = 7 * (1 - np.exp(-np.maximum(t - t1, 0) / tc)) + 8 * (1 - np.exp(-np.maximum(t - t2, 0) / tc))
    walk = np.cumsum(rng.normal(size=t.size)) / math.sqrt(t.size)
    true = 5 + rise + 0.1 * walk
    return true, np.round(true + measured_noise * rng.normal(size=t.size), 2)


def block_test(y, ch, alpha):
    r = regression_fit(y, ch, 8)
    tt = abs(r["coefficient"]) / r["se"] if r["se"] > 0 else 0.0
    return tt > t_dist.isf(alpha / 2, r["dof"]), tt, float(t_dist.isf(alpha / 2, r["dof"])), r["dof"]


def record(i, coupled=False):
    fs, n = SETUPS[(i // len(KINDS)) % len(SETUPS)]
    kind = KINDS[i % len(KINDS)]
    noise = NOISES[(i // (len(KINDS) * len(SETUPS))) % len(NOISES)]
    rng = np.random.default_rng(10_000 + i)
    ch = temperature(kind, n, fs, rng)
    if isinstance(ch, tuple):
        ch = ch[1]
    y = allanite.simulate(n, fs, seed=20_000 + i, **noise)
    if coupled:
        # a linear coupling the test finds surely: 5 mrad/s rms
        y = y + 5e-3 / np.std(ch) * (ch - ch.mean())
    return kind, fs, n, y, ch


def null_main(records):
    rows = []
    for i in range(records):
        kind, fs, n, y, ch = record(i)
        slow = is_slow(ch)
        w = regress_channel(y, ch, fs, terms=())
        b, tt, thr, dof = block_test(y, ch, ALPHA)
        rows.append(
            {
                "kind": kind,
                "fs": fs,
                "slow": bool(slow),
                "whittle": bool(w.accepted),
                "block": bool(b),
                "routed": bool(w.accepted if slow else b),
                "lr": w.test["statistic"],
                "whittle_chi2": bool(w.test["statistic"] > chi2.isf(ALPHA, 1)),
                "lr_threshold": w.test["threshold"],
                "nu": w.test["dof"],
                "block_t": tt,
                "block_dof": dof,
            }
        )
        if i % 100 == 99:
            _common.log(f"null coupling: {i + 1} records")
    return rows


def null_terms(records):
    rows = []
    i = 0
    while len(rows) < records:
        kind, fs, n, y, ch = record(i, coupled=True)
        i += 1
        if kind not in SLOW_KINDS:
            continue
        r = regress_channel(y, ch, fs, level=LEVEL)
        rows.append({"kind": kind, "fs": fs, "accepted": r.accepted} | {k: bool(v["kept"]) for k, v in r.terms.items()})
        if len(rows) % 100 == 0:
            _common.log(f"null optional terms: {len(rows)} records")
    return rows


def block_r(y, ch, fs):
    per = int(600 * fs)
    k = y.size // per
    return float(np.corrcoef(y[: k * per].reshape(k, per).mean(1), ch[: k * per].reshape(k, per).mean(1))[0, 1])


def issue_case(seed):
    """The issue's temperature: 25 h at 1 Hz, heater steps 5 → 20 °C, 0.45 mrad/s per °C (true temperature;
    the logged one has 0.02 °C of noise and 0.01 °C resolution)."""
    fs, n = 1.0, 90_000
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    true, logged = heater_steps(t, n / fs, rng)
    y = allanite.simulate(n, fs, N=1.5e-3, B=1e-4, K=3e-6, seed=100 + seed) + 4.5e-4 * (true - true.mean())
    return y, logged, fs


def lag_or_rate_case(seed, kind, fs=1.0, n=90_000):
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    span = n / fs
    true = 12 + 1.5 * np.sin(2 * np.pi * t / (span / 37.5) + 1) + 4 * np.sin(2 * np.pi * t / span)
    true = true + np.cumsum(rng.normal(size=n)) * 0.01 * math.sqrt(90_000 / n)
    logged = np.round(true + 0.02 * rng.normal(size=n), 2)
    y = allanite.simulate(n, fs, N=1.5e-3, B=1e-4, K=3e-6, seed=200 + seed)
    if kind == "lag":
        y = y + 4.5e-4 * lagged(true - true.mean(), 600.0, fs)
    elif kind == "rate":
        y = y + 4.5e-4 * (true - true.mean()) + 0.1 * np.gradient(true) * fs
    else:
        y = y + 4.5e-4 * (true - true.mean())
    return y, logged, fs


def fast_case(seed, fs, n, coef):
    """A temperature at 100 Hz or 1 kHz: a random walk and a 30-min cycle (°C), N + B + K noise (°/s)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    true = (
        20
        + 0.5 * np.sin(2 * np.pi * t / 1800.0 + rng.uniform(0, 6))
        + 0.3 * np.cumsum(rng.normal(size=n)) / math.sqrt(n)
    )
    logged = np.round(true + 0.01 * rng.normal(size=n), 3)
    y = allanite.simulate(n, fs, N=2e-3, B=5e-4, K=2e-5, seed=300 + seed) + coef * (true - true.mean())
    return y, logged, fs, coef


def adev_ratio(y, comp, fs):
    """Largest ADEV(component)/ADEV(rest) over octave τ: how far the effect stands above the noise."""
    a = allanite.avar(y - comp, fs)
    b = allanite.avar(comp, fs, taus=a.tau)
    return float(np.nanmax(np.sqrt(b.avar / a.avar)))


def power():
    out = []

    def one(case, y, ch, fs, truth, named=None):
        t0 = time.perf_counter()
        r = regress_channel(y, ch, fs)
        sec = time.perf_counter() - t0
        b, tt, thr, dof = block_test(y, ch, ALPHA)
        err = {k: r.params[k] / v - 1 for k, v in truth.items() if k in r.params}
        covered = {k: bool(r.intervals[k][0] <= v <= r.intervals[k][1]) for k, v in truth.items() if k in r.params}
        kept = [k for k in ("quadratic", "rate_coefficient", "lag_s") if k in r.params]
        ok = r.accepted and all(abs(e) < 0.2 for e in err.values()) and len(err) == len(truth)
        ok = ok and (kept == ([named] if named else []))
        out.append(
            {
                "case": case,
                "n": int(y.size),
                "fs": fs,
                "slow_share": slow_share(ch),
                "found": bool(ok),
                "accepted": bool(r.accepted),
                "kept": kept,
                "params": r.params,
                "intervals": {k: list(v) for k, v in r.intervals.items()},
                "errors": err,
                "covered_68": covered,
                "lr": r.test["statistic"],
                "lr_threshold": r.test["threshold"],
                "nu": r.test["dof"],
                "block_t": tt,
                "block_threshold": thr,
                "block_dof": dof,
                "block_found": bool(b),
                "heldout_ratio": heldout_ratio(y, ch, fs, r),
                "seconds": sec,
            }
        )
        return r

    for seed in range(20):
        y, ch, fs = issue_case(seed)
        one("issue: heater steps, 25 h at 1 Hz", y, ch, fs, {"coefficient": 4.5e-4})
        out[-1]["block_r"] = block_r(y, ch, fs)
    for seed in range(10):
        one("lag 600 s, 25 h at 1 Hz", *lag_or_rate_case(seed, "lag"), {"coefficient": 4.5e-4, "lag_s": 600.0}, "lag_s")
        one(
            "d(ch)/dt 0.1 per °C/s, 25 h at 1 Hz",
            *lag_or_rate_case(seed, "rate"),
            {"coefficient": 4.5e-4, "rate_coefficient": 0.1},
            "rate_coefficient",
        )
    for fs, n, seeds in ((100.0, 100_000, 5), (100.0, 1_000_000, 3), (1000.0, 1_000_000, 3), (1000.0, 10_000_000, 1)):
        for seed in range(seeds):
            y, ch, fs_, coef = fast_case(seed, fs, n, 1e-2)
            one(f"temperature at {fs:g} Hz, {n:.0e} samples", y, ch, fs_, {"coefficient": coef})
            if seed == 0:
                out[-1]["adev_ratio"] = adev_ratio(y, coef * (ch - ch.mean()), fs)
        _common.log(f"power at {fs:g} Hz × {n}")
    return out


def cost():
    """A default refine on 10⁶ samples (100 Hz) with a slow channel (heater steps, 2.8 h) and without it, and
    regress_channel alone on the same record."""
    fs, n = 100.0, 1_000_000
    rng = np.random.default_rng(7)
    true, logged = heater_steps(np.arange(n) / fs, n / fs, rng)
    y = allanite.simulate(n, fs, N=2e-3, B=5e-4, K=2e-5, seed=8) + 0.01 * (true - true.mean())
    best_r, _, _ = _common.timed(lambda: regress_channel(y, logged, fs), 3)
    best_f, _, _ = _common.timed(lambda: allanite.refine(y, fs), 1)
    best_c, _, rc = _common.timed(lambda: allanite.refine(y, fs, channels={"temp": logged}), 1)
    return {
        "regress_channel_s": best_r,
        "refine_without_channel_s": best_f,
        "refine_with_channel_s": best_c,
        "ratio": best_c / best_f,
        "found_with_channel": list(rc.found),
        "loadavg_end": list(os.getloadavg()),
    }


def _rate(rows, key, sel=lambda r: True):
    use = [r for r in rows if sel(r)]
    k = sum(bool(r.get(key, False)) for r in use)
    lo, hi = _common.clopper_pearson(k, len(use))
    return {"records": len(use), "alarms": k, "rate": k / max(1, len(use)), "ci95": (lo, hi)}


def _fmt(r):
    return (
        f"{r['alarms']}/{r['records']} = {100 * r['rate']:.2f} % [{100 * r['ci95'][0]:.2f}, {100 * r['ci95'][1]:.2f}]"
    )


def summarize(main_rows, term_rows, pw, cst, records):
    s = {"alpha": ALPHA, "term_alpha": {k: v * LEVEL for k, v in TERM_SHARE.items()}}
    s["null"] = {key: _rate(main_rows, key) for key in ("routed", "whittle", "block", "whittle_chi2")}
    s["null_by_kind"] = {
        k: {key: _rate(main_rows, key, lambda r, k=k: r["kind"] == k) for key in ("routed", "whittle", "block")}
        | {"slow_share_routed": float(np.mean([r["slow"] for r in main_rows if r["kind"] == k] or [0]))}
        for k in KINDS
    }
    s["null_terms"] = {k: _rate(term_rows, k) for k in ("quadratic", "rate_coefficient", "lag_s")}
    s["null_terms_accepted"] = _rate(term_rows, "accepted")
    cases = {}
    for p in pw:
        c = cases.setdefault(p["case"], [])
        c.append(p)
    s["power"] = {
        k: {
            "records": len(v),
            "found": sum(p["found"] for p in v),
            "accepted": sum(p["accepted"] for p in v),
            "routed_slow": sum(p["slow_share"] >= 0.5 for p in v),
            "block_found": sum(p["block_found"] for p in v),
            "max_abs_error": {e: max(abs(p["errors"].get(e, math.inf)) for p in v) for e in v[0]["errors"]},
            "median_lr_over_threshold": float(np.median([p["lr"] / p["lr_threshold"] for p in v])),
            "median_block_t_over_threshold": float(np.median([p["block_t"] / p["block_threshold"] for p in v])),
            "median_heldout_ratio": float(np.median([p["heldout_ratio"] for p in v])),
            "covered_68": {e: sum(p["covered_68"].get(e, False) for p in v) for e in v[0]["errors"]},
            "median_seconds": float(np.median([p["seconds"] for p in v])),
            "min_block_r": min((p.get("block_r", math.nan) for p in v), default=math.nan),
            "adev_ratio": v[0].get("adev_ratio"),
        }
        for k, v in cases.items()
    }
    s["cost"] = cst
    return s


def _load(v) -> str:
    return "?" if not v else "[" + ", ".join(f"{x:.1f}" for x in v) + "]"


def markdown(s, records, machine):
    a = 100 * s["alpha"]
    lines = [
        "# Regressions on slow channels — `benches/channel_regression.py`",
        "",
        f"Machine: {machine.get('cpu_model', '?')} ({machine.get('cpus_usable', '?')} usable CPUs), load average "
        f"(1, 5, 15 min) at the start {_load(machine.get('loadavg_start'))} and at the end "
        f"{_load(machine.get('loadavg_end'))} (other workers share the machine), commit {machine.get('git_commit', '?')}.",
        "",
        f"## False alarms of the coupling's test ({records} null records, level {a:.3f} % each)",
        "",
        "Gyro noise independent of the channel (N + B + K, N + B, N + K, N + B + K + GM in turn; 1 Hz × 25 h and "
        "100 Hz × 2·10⁵ in turn). Rates with 95 % Clopper–Pearson intervals. *Routed*: slow channels "
        "(≥ 50 % of the variance between 8 block means) by `regress_channel`, the others within blocks — what "
        "refine does.",
        "",
        "| channel | routed slow | routed | `regress_channel` on every record | within blocks on every record |",
        "|---|---|---|---|---|",
    ]
    for k, v in s["null_by_kind"].items():
        lines.append(
            f"| {k} | {100 * v['slow_share_routed']:.0f} % | {_fmt(v['routed'])} | {_fmt(v['whittle'])} | {_fmt(v['block'])} |"
        )
    n = s["null"]
    lines += [
        f"| **all** | | **{_fmt(n['routed'])}** | {_fmt(n['whittle'])} | {_fmt(n['block'])} |",
        "",
        f"`regress_channel` with χ²₁ instead of F(1, ν) (the noise level taken as known): {_fmt(n['whittle_chi2'])}.",
        "",
        f"## Optional terms on records with a real linear coupling only ({s['null_terms_accepted']['records']} slow "
        f"channels; each term at {100 * LEVEL * TERM_SHARE['quadratic']:.2f} %)",
        "",
        f"Coupling accepted: {_fmt(s['null_terms_accepted'])}. Kept although absent:",
        "",
        "| term | kept |",
        "|---|---|",
    ]
    for k, v in s["null_terms"].items():
        lines.append(f"| `{k}` | {_fmt(v)} |")
    lines += [
        "",
        "## Power",
        "",
        "Found = accepted, every parameter within 20 % and exactly the injected optional term kept (none for a plain "
        "coupling). LR/thr: the likelihood ratio over its F(1, ν) threshold; block t/thr: the within-block test "
        "it replaces on slow channels (t over its Satterthwaite-dof quantile). Held-out: even ↔ odd DFT bins.",
        "",
        "| case | records | routed slow | accepted | found | largest |error| | truth in the 68 % interval | "
        "median LR/thr | within blocks: found, median t/thr | median held-out ratio | median time |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for k, v in s["power"].items():
        errs = ", ".join(f"{e} {100 * x:.1f} %" for e, x in v["max_abs_error"].items())
        extra = ""
        if not math.isnan(v["min_block_r"]):
            extra = f" (10-min block means r ≥ {v['min_block_r']:.3f})"
        if v["adev_ratio"]:
            extra = f" (ADEV effect/noise up to {v['adev_ratio']:.1f}×)"
        cov = ", ".join(f"{e} {c}/{v['records']}" for e, c in v["covered_68"].items())
        lines.append(
            f"| {k}{extra} | {v['records']} | {v['routed_slow']} | {v['accepted']} | {v['found']} | {errs} | {cov} | "
            f"{v['median_lr_over_threshold']:.1f} | "
            f"{v['block_found']}, {v['median_block_t_over_threshold']:.2f} | {v['median_heldout_ratio']:.3f} | "
            f"{v['median_seconds']:.2f} s |"
        )
    c = s["cost"]
    lines += [
        "",
        "## Cost",
        "",
        "A default `refine` on 10⁶ samples (100 Hz, 2.8 h) with a slow channel (heater steps, 0.01 per °C): "
        f"{c['refine_with_channel_s']:.2f} s (found {', '.join(c['found_with_channel']) or 'nothing'}); without the "
        f"channel {c['refine_without_channel_s']:.2f} s — ratio {c['ratio']:.2f}; `regress_channel` alone (every "
        f"optional term) {c['regress_channel_s']:.2f} s (best of 3). One run each; load average after them "
        f"{_load(c['loadavg_end'])} on 2 CPUs shared with other workers: the ratio is the number to read.",
    ]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--records", type=int, default=600)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", type=Path, default=HERE / "results")
    a = ap.parse_args(argv)
    records = 14 if a.quick else a.records
    t0 = time.perf_counter()
    machine = _common.machine_info()
    main_rows = null_main(records)
    term_rows = null_terms(records // 2 if a.quick else records)
    pw = power() if not a.quick else []
    cst = (
        cost()
        if not a.quick
        else {
            "regress_channel_s": 0.0,
            "refine_without_channel_s": 1.0,
            "refine_with_channel_s": 0.0,
            "ratio": 0.0,
            "found_with_channel": [],
            "loadavg_end": [0.0],
        }
    )
    s = summarize(main_rows, term_rows, pw, cst, records)
    machine["loadavg_end"] = list(os.getloadavg())
    report = {
        "summary": s,
        "null": main_rows,
        "null_terms": term_rows,
        "power": pw,
        "machine": machine,
        "seconds": time.perf_counter() - t0,
    }
    a.out.mkdir(parents=True, exist_ok=True)
    (a.out / "channel_regression.json").write_text(json.dumps(report, indent=1, default=float) + "\n")
    md = markdown(s, records, machine)
    (a.out / "channel_regression.md").write_text(md)
    print(md)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
