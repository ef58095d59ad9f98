#!/usr/bin/env python3
"""False-alarm rate of ``allanite.refine`` with default arguments on clean simulated records.

A clean record holds only terms of the starting model (Q, N, B, K, R) — anything ``refine`` adds, and anything it
reports as still unexplained (``Refinement.unexplained``), is a false alarm. Per record the probability that
*anything* is added or flagged is counted (the default level is 5 % per record, split between every test). Mixtures:

- ``white``: white rate noise only (N);
- ``flicker``: flicker-dominated (B ≫ N over most of the curve);
- ``quantized``: white rate + random walk, quantized to an LSB of ½σ (like the ADIS16405's 0.05 °/s on
  ≈ 0.45 °/s of noise) — quantization of the rate is white and belongs to N;
- ``with_K``: N + B + K;
- ``issue16``: the starting model of issue 16 (N 0.05 °/√h, B 0.5 °/h, K 2 °/h^1.5), 5·10⁵ samples;
- ``slow_1hz``: a 1 Hz log of 28 h (10⁵ samples), N + B + K + R, with a temperature channel that does not couple
  (a random walk through a thermal lag);
- ``fast_2khz``: 2 kHz, 10⁶ samples, Q + N + B;
- ``channels_100hz``: 100 Hz, 4·10⁵ samples, N + B + K, with two channels that do not couple: a cycling
  temperature and a channel of flicker plus random walk of its own.

Usage::

    python benches/refine_false_alarms.py            # -> benches/results/refine_false_alarms.{json,md}
    python benches/refine_false_alarms.py --quick    # 2 records per mixture, to a temporary folder
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from collections import Counter
from pathlib import Path

import numpy as np
from scipy import signal

import _common
import allanite

HERE = Path(__file__).resolve().parent
FS = 100.0
H = 3600.0


def _null_temperature(n: int, fs: float, rng: np.random.Generator, kind: str) -> np.ndarray:
    t = np.arange(n) / fs
    span = t[-1]
    wander = np.cumsum(rng.standard_normal(n))
    a = np.exp(-1.0 / (fs * span / 200.0))
    wander = signal.lfilter([1 - a], [1, -a], wander - wander[0])
    x = np.sin(2 * np.pi * t / (span / 3)) + 0.25 * wander / np.ptp(wander) if kind == "cycle" else wander
    return 5.0 + 15.0 * (x - x.min()) / np.ptp(x)


def record(mix: str, seed: int):
    """(samples, fs, channels) of a clean record of ``mix``."""
    if mix == "white":
        return allanite.simulate(200_000, FS, N=2e-3, seed=seed), FS, None
    if mix == "flicker":
        return allanite.simulate(200_000, FS, N=2e-4, B=2e-3, seed=seed), FS, None
    if mix == "quantized":
        y = allanite.simulate(200_000, FS, N=2e-3, K=2e-5, seed=seed)
        lsb = 0.5 * 2e-3 * np.sqrt(FS)
        return np.round(y / lsb) * lsb, FS, None
    if mix == "with_K":
        return allanite.simulate(200_000, FS, N=2e-3, B=5e-4, K=5e-5, seed=seed), FS, None
    if mix == "issue16":
        return allanite.simulate(500_000, FS, N=0.05 / 60, B=0.5 / H, K=2 / H**1.5, seed=seed), FS, None
    rng = np.random.default_rng(seed)
    if mix == "slow_1hz":
        y = allanite.simulate(100_000, 1.0, N=1.5e-3, B=2e-4, K=2e-6, R=2e-9, seed=rng)
        return y, 1.0, {"temp": _null_temperature(y.size, 1.0, rng, "walk")}
    if mix == "fast_2khz":
        return allanite.simulate(1_000_000, 2000.0, Q=2e-6, N=2e-3, B=5e-4, seed=rng), 2000.0, None
    if mix == "channels_100hz":
        y = allanite.simulate(400_000, FS, N=3e-3, B=1e-3, K=2e-5, seed=rng)
        other = allanite.simulate(y.size, FS, B=0.05, K=1e-3, seed=rng)
        return y, FS, {"temp": _null_temperature(y.size, FS, rng, "cycle"), "aux": other}
    raise ValueError(mix)


MIXES = ("white", "flicker", "quantized", "with_K", "issue16", "slow_1hz", "fast_2khz", "channels_100hz")


def run(per_mix: int, out: Path) -> dict:
    rows = {}
    t_all = time.perf_counter()
    load = _common.OtherLoad().__enter__()
    for mix in MIXES:
        n = per_mix if mix != "issue16" else max(2, per_mix * 2 // 3)
        found = Counter()
        flagged = Counter()
        alarms = 0
        secs = []
        for k in range(n):
            # seeds of their own per mixture: records of one seed share their white noise across mixtures
            y, fs, channels = record(mix, 10_000 + 1_000_003 * MIXES.index(mix) + 97 * k)
            t0 = time.perf_counter()
            r = allanite.refine(y, fs, channels=channels, progress=False)
            secs.append(time.perf_counter() - t0)
            alarms += bool(r.steps or r.unexplained)
            found.update(r.found)
            flagged.update(u["domain"] for u in r.unexplained)
        rows[mix] = {
            "records": n,
            "records_with_alarm": alarms,
            "rate": alarms / n,
            "effects": dict(found),
            "unexplained": dict(flagged),
            "mean_s": float(np.mean(secs)),
        }
        print(mix, rows[mix], flush=True)
    load.__exit__(None, None, None)
    total = sum(r["records"] for r in rows.values())
    alarms = sum(r["records_with_alarm"] for r in rows.values())
    report = {
        "level": 0.05,
        "mixtures": rows,
        "records": total,
        "records_with_alarm": alarms,
        "rate": alarms / total,
        "rate_interval_95": _common.clopper_pearson(alarms, total),
        "seconds": time.perf_counter() - t_all,
        "other_load": load.fraction,
        "machine": _common.machine_info(),
    }
    out.mkdir(parents=True, exist_ok=True)
    (out / "refine_false_alarms.json").write_text(json.dumps(report, indent=1))
    lines = [
        "# `refine` false alarms on clean records (default arguments)",
        "",
        "Written by `benches/refine_false_alarms.py`. Level 5 % per record (anything added, or anything reported as "
        "still unexplained, is a false alarm).",
        "",
        "| mixture | records | with an alarm | rate | effects added | unexplained flagged | mean time per refine |",
        "|---|---|---|---|---|---|---|",
    ]
    for mix, r in rows.items():
        eff = ", ".join(f"{k} × {v}" for k, v in r["effects"].items()) or "—"
        une = ", ".join(f"{k} × {v}" for k, v in r["unexplained"].items()) or "—"
        lines.append(
            f"| {mix} | {r['records']} | {r['records_with_alarm']} | {100 * r['rate']:.1f} % | {eff} | {une} | "
            f"{r['mean_s']:.2f} s |"
        )
    lo, hi = _common.clopper_pearson(alarms, total)
    lines += [
        "",
        f"All: {alarms} of {total} records = {100 * alarms / total:.1f} % "
        f"(95 % Clopper–Pearson interval {100 * lo:.1f}–{100 * hi:.1f} %); other processes used "
        f"{100 * (load.fraction or 0):.0f} % of the CPUs during the run. Every record has a seed of its own (the "
        "mixtures do not share noise draws), so the records are independent and the interval is the rate's.",
    ]
    (out / "refine_false_alarms.md").write_text("\n".join(lines) + "\n")
    return report


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--per-mix", type=int, default=80)
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args(argv)
    out = a.out or (Path(tempfile.mkdtemp()) if a.quick else HERE / "results")
    run(2 if a.quick else a.per_mix, out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
