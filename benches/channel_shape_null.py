#!/usr/bin/env python3
"""False alarms of ``unexplained``'s check of a coupling's shape (:func:`allanite.model._shape.shape_test`: steps of
the rate at the channel's quantiles beyond its kept terms) on null records — the rate does not follow the
temperature — and its power on a coupling no term models.

Null records: ``benches/channel_turnover_null.py``'s (white noise with rate random walk, bias instability or a
Gauss–Markov term; 1, 20 or 100 Hz; 8000–40 000 samples; a 15–35 °C temperature cycling, warming once or
wandering, 0.01 °C of sensor noise), the check run on the record as it is (the kept terms: the channel alone).
Counted per temperature kind at several levels (the p value below α), with 95 % Clopper–Pearson intervals: the
check's own α (``levels.UNEXPLAINED_SHARES["channel_shape"]`` of level 5 %, run with ``exact=True`` so that every
record's p value is read) is too small to see in a few hundred records, so its calibration is shown at 5 %, 1 % and 0.1 %, where it can be.

``--power``: the same records with a staircase (+s at 20 °C and 30 °C, less its straight line in T: what a removed
linear coupling leaves) or a quadratic left in them, s in multiples of the noise's per-sample σ; counted at the
check's own α.

Usage::

    python benches/channel_shape_null.py --records 600            # ~7 min CPU
    python benches/channel_shape_null.py --records 150 --power --size 0.3   # ~2 min CPU
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

from allanite.model._shape import shape_test
from allanite.model.refinement.levels import alpha
from channel_turnover_null import KINDS, _cp, _record

LEVELS = (0.05, 0.01, 0.001)


def _left(temp: np.ndarray, comp: np.ndarray) -> np.ndarray:
    """``comp`` less its least-squares straight line in ``temp`` (what a linear coupling's removal leaves)."""
    a = np.c_[np.ones(temp.size), temp]
    return comp - a @ np.linalg.lstsq(a, comp, rcond=None)[0]


def _shapes(temp: np.ndarray, size: float) -> dict:
    stair = size * ((temp > 20.0).astype(float) + (temp > 30.0))
    quad = size * ((temp - 25.0) / 10.0) ** 2
    return {"stair": _left(temp, stair), "quadratic": _left(temp, quad)}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--records", type=int, default=300)
    ap.add_argument("--power", action="store_true", help="a staircase or a quadratic left in the records")
    ap.add_argument("--size", type=float, default=0.3, help="--power: the shape's size over the noise's σ")
    args = ap.parse_args(argv)
    a_check = alpha("unexplained:channel_shape", 0.05)
    t0 = time.process_time()
    if args.power:
        hits = {k: {s: [0, 0] for s in ("stair", "quadratic")} for k in KINDS}
        for seed in range(args.records):
            kind, y, temp, fs = _record(seed)
            for name, comp in _shapes(temp, args.size * 1e-3 * np.sqrt(fs)).items():
                r = shape_test(y + comp, temp, fs, a_check)
                hits[kind][name][0] += 1
                hits[kind][name][1] += r["fired"]
        print(json.dumps({"alpha": a_check, "size": args.size, "power": hits, "cpu_s": time.process_time() - t0}))
        return
    counts = {k: [0] + [0] * (len(LEVELS) + 1) for k in KINDS}
    for seed in range(args.records):
        kind, y, temp, fs = _record(seed)
        r = shape_test(y, temp, fs, a_check, exact=True)
        c = counts[kind]
        c[0] += 1
        for i, lv in enumerate(LEVELS):
            c[1 + i] += r["p_value"] < lv
        c[-1] += r["fired"]
    total = [sum(c[i] for c in counts.values()) for i in range(len(LEVELS) + 2)]
    print(json.dumps({"alpha": a_check, "kinds": counts, "all": total, "cpu_s": round(time.process_time() - t0, 1)}))
    for name, c in list(counts.items()) + [("all", total)]:
        cells = [
            f"p<{lv}: {c[1 + i]}/{c[0]} {tuple(round(v, 4) for v in _cp(c[1 + i], c[0]))}"
            for i, lv in enumerate(LEVELS)
        ]
        print(f"{name}: " + "; ".join(cells) + f"; fired at α={a_check:.3g}: {c[-1]}/{c[0]} {_cp(c[-1], c[0])}")


if __name__ == "__main__":
    main()
