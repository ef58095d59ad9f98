#!/usr/bin/env python3
"""False-alarm rate of ``allanite.refine`` with default arguments on clean simulated records.

A clean record holds only terms of the starting model (Q, N, B, K, R) — anything ``refine`` adds is a false
alarm. Mixtures (per record the probability that *anything* is added is counted; the default level is 5 %):

- ``white``: white rate noise only (N);
- ``flicker``: flicker-dominated (B ≫ N over most of the curve);
- ``quantized``: white rate + random walk, quantized to an LSB of ½σ (like the ADIS16405's 0.05 °/s on
  ≈ 0.45 °/s of noise) — quantization of the rate is white and belongs to N;
- ``with_K``: N + B + K;
- ``issue16``: the starting model of issue 16 (N 0.05 °/√h, B 0.5 °/h, K 2 °/h^1.5), 5·10⁵ samples.

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
from scipy.stats import beta

import _common
import allanite

HERE = Path(__file__).resolve().parent
FS = 100.0
H = 3600.0


def record(mix: str, seed: int) -> np.ndarray:
    if mix == "white":
        return allanite.simulate(200_000, FS, N=2e-3, seed=seed)
    if mix == "flicker":
        return allanite.simulate(200_000, FS, N=2e-4, B=2e-3, seed=seed)
    if mix == "quantized":
        y = allanite.simulate(200_000, FS, N=2e-3, K=2e-5, seed=seed)
        lsb = 0.5 * 2e-3 * np.sqrt(FS)
        return np.round(y / lsb) * lsb
    if mix == "with_K":
        return allanite.simulate(200_000, FS, N=2e-3, B=5e-4, K=5e-5, seed=seed)
    if mix == "issue16":
        return allanite.simulate(500_000, FS, N=0.05 / 60, B=0.5 / H, K=2 / H**1.5, seed=seed)
    raise ValueError(mix)


MIXES = ("white", "flicker", "quantized", "with_K", "issue16")


def clopper_pearson(k: int, n: int, level: float = 0.95) -> tuple[float, float]:
    """Exact binomial interval of a rate k/n."""
    a = (1 - level) / 2
    lo = beta.ppf(a, k, n - k + 1) if k > 0 else 0.0
    hi = beta.isf(a, k + 1, n - k) if k < n else 1.0
    return float(lo), float(hi)


def run(per_mix: int, out: Path) -> dict:
    rows = {}
    t_all = time.perf_counter()
    for mix in MIXES:
        n = per_mix if mix != "issue16" else max(2, per_mix * 2 // 3)
        found = Counter()
        alarms = 0
        secs = []
        for k in range(n):
            y = record(mix, 10_000 + 97 * k)
            t0 = time.perf_counter()
            r = allanite.refine(y, FS)
            secs.append(time.perf_counter() - t0)
            alarms += bool(r.steps)
            found.update(r.found)
        rows[mix] = {
            "records": n,
            "records_with_alarm": alarms,
            "rate": alarms / n,
            "effects": dict(found),
            "mean_s": float(np.mean(secs)),
        }
        print(mix, rows[mix], flush=True)
    total = sum(r["records"] for r in rows.values())
    alarms = sum(r["records_with_alarm"] for r in rows.values())
    report = {
        "level": 0.05,
        "mixtures": rows,
        "records": total,
        "records_with_alarm": alarms,
        "rate": alarms / total,
        "rate_interval_95": clopper_pearson(alarms, total),
        "seconds": time.perf_counter() - t_all,
        "machine": _common.machine_info(),
    }
    out.mkdir(parents=True, exist_ok=True)
    (out / "refine_false_alarms.json").write_text(json.dumps(report, indent=1))
    lines = [
        "# `refine` false alarms on clean records (default arguments)",
        "",
        "Written by `benches/refine_false_alarms.py`. Level 5 % per record (anything added = a false alarm).",
        "",
        "| mixture | records | with an alarm | rate | effects added | mean time per refine |",
        "|---|---|---|---|---|---|",
    ]
    for mix, r in rows.items():
        eff = ", ".join(f"{k} × {v}" for k, v in r["effects"].items()) or "—"
        lines.append(
            f"| {mix} | {r['records']} | {r['records_with_alarm']} | {100 * r['rate']:.1f} % | {eff} | {r['mean_s']:.2f} s |"
        )
    lo, hi = clopper_pearson(alarms, total)
    lines += [
        "",
        f"All: {alarms} of {total} records = {100 * alarms / total:.1f} % "
        f"(95 % Clopper–Pearson interval {100 * lo:.1f}–{100 * hi:.1f} %).",
    ]
    (out / "refine_false_alarms.md").write_text("\n".join(lines) + "\n")
    return report


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--per-mix", type=int, default=30)
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args(argv)
    out = a.out or (Path(tempfile.mkdtemp()) if a.quick else HERE / "results")
    run(2 if a.quick else a.per_mix, out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
