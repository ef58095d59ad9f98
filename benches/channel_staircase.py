#!/usr/bin/env python3
"""The channel regression on temperature channels as IMUs log them — quantised in value, held in time — its false
alarms: the coupling's on channels the rate does not follow, and each optional term's (quadratic, d(ch)/dt, lag)
on channels it follows with no such term.

Records of 10⁵ samples at 10 Hz (10⁴ s): white noise 0.01 °/s per sample with, in turn, a random walk or flicker;
the temperature a slow sine (period 2000–8000 s, ±5 °C) plus a little wander, written in turn as a 0.5 °C or
0.125 °C staircase, at 1/16 °C read every 10 s and held, or at 1/16 °C with 0.3 °C of noise. ``null``: the rate
does not follow it; ``coupled``: the rate follows the true (smooth) temperature at 0.002 °/s per °C, no lag, no
other term. Each record's regression by :func:`allanite.model.channels.regress_channel` at refine's shares.
Rates with Clopper–Pearson 95 % bounds; the form read from the channel is listed per kind.

Usage::

    python benches/channel_staircase.py              # -> benches/results/channel_staircase.{json,md}
    python benches/channel_staircase.py --records 10 --out DIR
"""

from __future__ import annotations

import argparse
import json
import subprocess
import time
from pathlib import Path

import numpy as np

import _common
from allanite.model import channels

HERE = Path(__file__).resolve().parent
KINDS = ("staircase 0.5 °C", "staircase 0.125 °C", "1/16 °C held 10 s", "1/16 °C, noise 0.3 °C")
NOISES = ({"K": 1e-5}, {"B": 5e-4})
FS, N, COEF = 10.0, 100_000, 0.002


def _written(temp: np.ndarray, kind: str, rng) -> np.ndarray:
    if kind == "staircase 0.5 °C":
        return np.round(temp / 0.5) * 0.5
    if kind == "staircase 0.125 °C":
        return np.round(temp * 8) / 8
    if kind == "1/16 °C held 10 s":
        return np.repeat(np.round(temp[::100] * 16) / 16, 100)[: temp.size]
    return np.round((temp + 0.3 * rng.standard_normal(temp.size)) * 16) / 16


def record(seed: int, kind: str, coupled: bool):
    """(rate, the channel as written) of record ``seed``."""
    rng = np.random.default_rng(seed)
    t = np.arange(N) / FS
    period = float(rng.uniform(2000.0, 8000.0))
    wander = np.cumsum(rng.standard_normal(N)) * 2e-3
    temp = 25.0 + 5.0 * np.sin(2 * np.pi * t / period + rng.uniform(0, 2 * np.pi)) + wander
    noise = NOISES[seed % len(NOISES)]
    y = 0.01 * rng.standard_normal(N)
    if "K" in noise:
        y += noise["K"] * np.cumsum(rng.standard_normal(N)) / np.sqrt(FS)
    else:
        f = np.fft.rfftfreq(4 * N, 1 / FS)
        spec = np.zeros(f.size, dtype=complex)
        spec[1:] = (rng.standard_normal(f.size - 1) + 1j * rng.standard_normal(f.size - 1)) / np.sqrt(f[1:])
        fl = np.fft.irfft(spec, 4 * N)[:N]
        y += noise["B"] * fl / np.std(np.diff(fl)) * 0.05
    if coupled:
        y += COEF * temp
    return y, _written(temp, kind, rng)


def run(records: int) -> dict:
    out: dict = {}
    for kind in KINDS:
        for coupled in (False, True):
            counts = {"coupling": 0, "quadratic": 0, "rate_coefficient": 0, "lag_s": 0}
            errs, forms = [], set()
            for seed in range(records):
                y, ch = record(1000 + seed, kind, coupled)
                r = channels.regress_channel(y, ch, FS, name="temp")
                forms.add(getattr(getattr(r, "form", None), "words", lambda fs: "—")(FS))
                counts["coupling"] += int(r.accepted)
                for k in ("quadratic", "rate_coefficient", "lag_s"):
                    counts[k] += int(k in r.params)
                if coupled and r.accepted:
                    errs.append(r.params["coefficient"] / COEF - 1.0)
            key = f"{kind} | {'coupled' if coupled else 'null'}"
            out[key] = {
                "records": records,
                "counts": counts,
                "bounds": {k: _common.clopper_pearson(v, records) for k, v in counts.items()},
                "median_coefficient_error": float(np.median(errs)) if errs else None,
                "forms": sorted(forms),
            }
            print(key, counts, out[key]["median_coefficient_error"], flush=True)
    return out


def markdown(res: dict, meta: str) -> str:
    rows = [
        "| channel | rate | records | coupling accepted | quadratic kept | d(ch)/dt kept | lag kept | "
        "median coefficient error | form read |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for key, v in res.items():
        kind, mode = key.split(" | ")
        c, b = v["counts"], v["bounds"]
        cells = [f"{c[k]} ({100 * b[k][1]:.0f} %)" for k in ("coupling", "quadratic", "rate_coefficient", "lag_s")]
        med = v["median_coefficient_error"]
        rows.append(
            f"| {kind} | {mode} | {v['records']} | "
            + " | ".join(cells)
            + f" | {'—' if med is None else f'{100 * med:+.1f} %'} | {'; '.join(v['forms'])} |"
        )
    return (
        "# The channel regression on quantised and held temperature channels\n\n"
        + meta
        + "\n\nCounts of records, with the Clopper–Pearson 95 % upper bound in brackets. `null`: the rate does not "
        "follow the channel (the coupling's test at its share, α 0.375 %); `coupled`: the rate follows the smooth "
        "temperature at 0.002 °/s per °C and nothing else (each optional term kept is a false alarm at its share, "
        "0.1 %).\n\n" + "\n".join(rows) + "\n"
    )


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--records", type=int, default=20)
    ap.add_argument("--out", default=str(HERE / "results"))
    args = ap.parse_args(argv)
    rev = subprocess.run(["git", "describe", "--always", "--dirty"], capture_output=True, text=True, cwd=HERE)
    t0 = time.process_time()
    res = run(args.records)
    meta = f"Code at {rev.stdout.strip() or '?'}, {args.records} records per row; CPU {time.process_time() - t0:.0f} s"
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "channel_staircase.json").write_text(json.dumps({"meta": meta, "results": res}, indent=1))
    (out / "channel_staircase.md").write_text(markdown(res, meta))
    print(f"wrote {out / 'channel_staircase.md'}")


if __name__ == "__main__":
    main()
