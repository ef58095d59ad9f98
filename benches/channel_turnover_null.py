#!/usr/bin/env python3
"""False alarms of the channel regression with the quadratic's own test run where the coupling's fails (a turnover
temperature, docs/channels.md): null records — the rate does not follow the temperature — counted by what accepted
the coupling, the channel's own test (as before) or the quadratic (new).

Records, each with a seed of its own: white noise with, in turn, rate random walk, bias instability or a
Gauss–Markov term; 1, 20 or 100 Hz; 8000, 20 000 or 40 000 samples; a 15–35 °C temperature cycling three times,
warming once or wandering (``tests/sensors.temperature_profile``) with 0.01 °C of sensor noise. Prints one JSON
line (counts per temperature kind: records, the channel's test, the quadratic's) and the 95 % Clopper–Pearson
intervals; writes nothing.

Usage::

    python benches/channel_turnover_null.py --records 600     # ~10 min CPU
    python benches/channel_turnover_null.py --records 600 --kind swing   # its 200 warm-ups only
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
from scipy.stats import beta

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import allanite
import sensors
from allanite.model.channels import regress_channel

KINDS = ("cycle", "swing", "walk")


def _record(seed: int):
    rng = np.random.default_rng(1000 + seed)
    kind = KINDS[seed % 3]
    fs = (1.0, 20.0, 100.0)[seed % 5 % 3]
    n = (8000, 20000, 40000)[seed % 7 % 3]
    noise = [dict(N=1e-3, K=2e-5), dict(N=1e-3, B=3e-4), dict(N=1e-3, gauss_markov=[(5e-3, n / fs / 20)])]
    y = allanite.simulate(n, fs, seed=rng, **noise[seed // 3 % 3])
    temp = sensors.temperature_profile(np.arange(n) / fs, kind, rng, lo=15.0, hi=35.0)
    return kind, y, temp + 0.01 * rng.standard_normal(n), fs


def _cp(k: int, n: int) -> tuple[float, float]:
    lo = float(beta.ppf(0.025, k, n - k + 1)) if k > 0 else 0.0
    hi = float(beta.ppf(0.975, k + 1, n - k)) if k < n else 1.0
    return lo, hi


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--records", type=int, default=600)
    ap.add_argument("--kind", choices=KINDS, default=None, help="only the records of this temperature kind")
    args = ap.parse_args(argv)
    counts = {k: [0, 0, 0] for k in KINDS}
    t0 = time.process_time()
    for seed in range(args.records):
        if args.kind is not None and KINDS[seed % 3] != args.kind:
            continue
        kind, y, temp, fs = _record(seed)
        by = regress_channel(y, temp, fs, name="temp").test.get("accepted_by")
        c = counts[kind]
        c[0], c[1], c[2] = c[0] + 1, c[1] + (by == "channel"), c[2] + (by == "quadratic")
    total = [sum(c[i] for c in counts.values()) for i in range(3)]
    print(json.dumps({"kinds": counts, "all": total, "cpu_s": round(time.process_time() - t0, 1)}))
    for name, c in list(counts.items()) + [("all", total)]:
        before, after = _cp(c[1], c[0]), _cp(c[1] + c[2], c[0])
        print(f"{name}: the channel's test {c[1]} of {c[0]} {before}; with the quadratic {c[1] + c[2]} {after}")


if __name__ == "__main__":
    main()
