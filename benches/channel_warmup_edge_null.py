#!/usr/bin/env python3
"""Why a temperature warming once is over-rejected by the channel's test (docs/channels.md, "A turnover temperature"):
the coupling's statistic on null records under the *true* noise spectrum — no noise fit, no bootstrap.

``benches/channel_turnover_null.py`` counts 4 of 200 null records with a warm-up channel accepted by the channel's
own test (nominal 0.375 %), none of 400 with a cycling or wandering one. Here the pair's 2Δℓ (the channel and its
quadrature against no coupling, both at a fixed noise PSD) is computed with the noise's band levels set to their
mean over 200 other records of the same noise — the PSD Whittle's likelihood would need to be exact. If the law of
the statistic were Whittle's, its mean would be 2 (χ²₂) whatever the channel. Rows: the noise (white; white and
flicker; white and rate random walk) × the channel (the warm-up of ``tests/sensors.temperature_profile``, most of
its change in the first eighth of the record; the same warm-up starting at 40 % of the record; a cycling one), with
the 1 % Tukey taper the module uses and with a 10 % one. 20 Hz × 8000 samples, 150 records per row. The last
three columns: the same statistic over the tests' edge factor (:func:`allanite.model._edge.edge_factor`, at the
record's own null fit, as ``regress_channel`` computes it) — the exact null variance of the scores at the record's
edges against Whittle's; the law restored, its mean is 2 or below. Prints a Markdown table; writes nothing.

Usage::

    python benches/channel_warmup_edge_null.py                # ≈ 10 s CPU
    python benches/channel_warmup_edge_null.py --records 60
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import allanite
import sensors
from allanite.model import _whittle as wh
from allanite.model._edge import edge_factor
from allanite.model.channels import channel_bands

FS, N = 20.0, 8000
NOISES = {
    "white": {"N": 1e-3},
    "white + flicker": {"N": 1e-3, "B": 3e-4},
    "white + random walk": {"N": 1e-3, "K": 2e-5},
}
CHI2_2_AT_ALPHA = 11.17  # χ²₂'s point at the channel test's 0.375 %


def _bands(y, temp):
    """Band sums as regress_channel forms them (read back, signal bands, the three regressors)."""
    return channel_bands(y, temp, FS)[-1]


def _channel(kind: str, rng) -> np.ndarray:
    t = np.arange(N) / FS
    if kind == "warm-up at the start":
        x = sensors.temperature_profile(t, "swing", rng, lo=15.0, hi=35.0)
    elif kind == "warm-up from 40 %":
        late = np.clip(t - 0.4 * t[-1], 0.0, None)
        x = 15.0 + 20.0 * np.where(late > 0, 1.0 - np.exp(-late / (t[-1] / 25.0)), 0.0)
    else:
        x = sensors.temperature_profile(t, "cycle", rng, lo=15.0, hi=35.0)
    return x + 0.01 * rng.standard_normal(N)


def _row(noise: dict, kind: str, taper: float, records: int) -> np.ndarray:
    wh.TAPER = taper
    mean_q = sum(wh.spectra(allanite.simulate(N, FS, seed=90_000 + r, **noise), [], FS).q for r in range(200)) / 200
    stats = []
    for seed in range(records):
        rng = np.random.default_rng(7000 + seed)
        y = allanite.simulate(N, FS, seed=rng, **noise)
        b = _bands(y, _channel(kind, rng))
        s = mean_q / b.m
        one = np.ones(b.m.size)
        pair = wh.Design([0, 0], [one, -1j * one])
        f0 = wh.joint_fit(b, wh.Design([], []), fixed_s=s)
        f1 = wh.joint_fit(b, pair, fixed_s=s)
        # the test's edge factor, at the record's own null fit as regress_channel computes it
        factor = edge_factor(b, wh.joint_fit(b, wh.Design([], [])), pair, np.eye(2))["factor"]
        stats.append((2.0 * (f1["loglik"] - f0["loglik"]), factor))
    return np.asarray(stats)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--records", type=int, default=150)
    args = ap.parse_args(argv)
    t0 = time.process_time()
    print(
        "| noise | channel | taper | mean 2Δℓ (χ²₂: 2) | above χ²₂'s 0.375 % point "
        "| mean 2Δℓ / edge factor | above it with the factor | median factor |"
    )
    print("|---|---|---|---|---|---|---|---|")
    rows = [(nz, kind, 0.01) for nz in NOISES for kind in ("warm-up at the start", "cycling")]
    rows += [("white", "warm-up from 40 %", 0.01), ("white", "warm-up at the start", 0.10)]
    for nz, kind, taper in rows:
        st, fac = _row(NOISES[nz], kind, taper, args.records).T
        k, k_f = int(np.sum(st > CHI2_2_AT_ALPHA)), int(np.sum(st / fac > CHI2_2_AT_ALPHA))
        print(
            f"| {nz} | {kind} | {100 * taper:.0f} % | {st.mean():.2f} | {k} of {st.size} | {np.mean(st / fac):.2f} "
            f"| {k_f} of {st.size} | {np.median(fac):.2f} |",
            flush=True,
        )
    wh.TAPER = 0.01
    print(f"\nCPU {time.process_time() - t0:.0f} s")


if __name__ == "__main__":
    main()
