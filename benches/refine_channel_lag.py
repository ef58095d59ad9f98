#!/usr/bin/env python3
"""A slow channel through a lag: does refine's chain of held-out errors fall when the coupling is removed?
(issue 29 item 1; ``benches/results/refine_blind3.md``'s FOG row rose 2.13 → 2.76 %.)

Each record: rate noise + 6·10⁻⁷ rad/s per °C × the temperature through a first-order lag of T (0 = none), the
temperature logged with 0.01 °C of noise (``tests/sensors.py``'s cycling profile, 15–35 °C, three cycles plus
wander). Noise: FOG-like (white 2·10⁻⁷, flicker 10⁻⁷, rate random walk 2·10⁻⁸ — the random walk dominates),
white-dominated and flicker-dominated. 1 Hz × 10⁵ with T = 0, 100, 300, 900, 2000 s (4 seeds), 10 Hz × 10⁶ with
T = 0, 300, 2000 s (2 seeds), the other noises at 1 Hz × 10⁵ with T = 0 and 900 s (2 seeds).

Per record, a default ``allanite.refine(y, fs, unit="rad/s", channels={"temp": T})`` twice: as it is — a lag the
lag's test cannot resolve is profiled for the removal where the profile prefers it to none
(``allanite.model.channels``, docs/channels.md "A lag not resolved") — and with that profile switched off (the
removal at lag 0 unless the test keeps a lag: the behaviour before). The regression step's held-out error
before → after, its coefficient's error and the lag the removal used.

Usage::

    python benches/refine_channel_lag.py               # -> benches/results/refine_channel_lag.{json,md} (~10 min)
    python benches/refine_channel_lag.py --quick --out DIR
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import _common
import allanite
import refine_blind as rb
from allanite.model import channels

sensors = rb.sensors
HERE = Path(__file__).resolve().parent
COEF = 6e-7
NOISES = {
    "FOG (random walk)": dict(N=2e-7, B=1e-7, K=2e-8),
    "white": dict(N=2e-6, B=1e-8, K=1e-10),
    "flicker": dict(N=2e-7, B=5e-7, K=1e-9),
}
FOG = "FOG (random walk)"
CASES = (
    [(1.0, 100_000, FOG, lag, s) for lag in (0, 100, 300, 900, 2000) for s in (1, 2, 3, 4)]
    + [(10.0, 1_000_000, FOG, lag, s) for lag in (0, 300, 2000) for s in (1, 2)]
    + [(1.0, 100_000, nz, lag, s) for nz in ("white", "flicker") for lag in (0, 900) for s in (1, 2)]
)
QUICK = [(1.0, 100_000, FOG, 900, 1), (1.0, 100_000, FOG, 0, 1)]


def record(fs: float, n: int, noise: str, lag: float, seed: int):
    """(rate, logged temperature, the coupling's true component)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, **NOISES[noise])
    temp = sensors.temperature_profile(t, "cycle", rng, lo=15.0, hi=35.0)
    sensor = sensors.first_order_lag(temp, fs, lag) if lag else temp
    comp = COEF * (sensor - sensor.mean())
    return y + comp, temp + 0.01 * rng.standard_normal(n), comp


def _step(y, fs, temp) -> dict:
    r = allanite.refine(y, fs, unit="rad/s", channels={"temp": temp}, progress=False)
    st = next((s for s in r.steps if s.effect == "regression"), None)
    if st is None:
        return {"found": list(r.found)}
    return {
        "found": list(r.found),
        "coefficient_error": st.params["coefficient"] / COEF - 1.0,
        "lag_kept": st.params.get("lag_s"),
        "rate_term": "rate_coefficient" in st.params,
        "removal_lag_s": st.evidence.get("removal_lag_s", st.params.get("lag_s")),
        "heldout": [st.before["heldout_rms_adev_pct"], st.after["heldout_rms_adev_pct"]],
    }


def one(case) -> dict:
    fs, n, noise, lag, seed = case
    y, temp, comp = record(fs, n, noise, lag, seed)
    row: dict = {"fs": fs, "n": n, "noise": noise, "lag": lag, "seed": seed}
    row["profiled"] = _step(y, fs, temp)
    keep = channels._removal_lag
    channels._removal_lag = lambda *a, **k: None  # the removal at lag 0 unless the test keeps a lag
    try:
        row["lag0"] = _step(y, fs, temp)
    finally:
        channels._removal_lag = keep
    return row


def _cell(v: dict) -> str:
    if "heldout" not in v:
        return "no regression"
    b, a = v["heldout"]
    mark = " ↑" if a >= b else ""
    return f"{b:.2f} → {a:.2f}{mark}"


def _lag(v: dict) -> str:
    if v.get("lag_kept"):
        return f"{v['lag_kept']:.0f} (kept)"
    if v.get("rate_term"):
        return "d/dt term"
    return f"{v['removal_lag_s']:.0f}" if v.get("removal_lag_s") else "—"


#: What the recorded table shows (kept true to it).
NOTES = [
    "Lag 0 and 100 s: the profile was used on 1 record of 14 (flicker, no lag: 128 s; held out 1.22 → 1.25 %, "
    "coefficient +3.5 → +3.6 %), elsewhere nothing changed. 300 s: used on 4 of 6, held out within ±0.7 points "
    "either way. 900 and 2000 s at 1 Hz: the coefficient's error −11.6, −2.1, −7.6, −1.0 / −21.3, −11.7, −17.2, "
    "−10.6 % at lag 0 and −7.3, +0.5, −6.2, +0.4 / −5.7, −0.1, −14.2, −2.0 % with the lag profiled; the held-out "
    "error lower on 7 of 8 — not on 900 s seed 3 (1.17 → 2.87 %; the profile found 297 s) — and the one rise "
    "(2000 s seed 4, 2.62 → 5.36 %) gone. With rate random walk dominating 10⁵ s the held-out error is itself "
    "noisy: the better removal does not win on every record, and at 10 Hz × 10⁶ / 2000 s seed 1 the lag-0 removal "
    "reads lower (1.98 against 2.79 %) though its coefficient is further off (−19.1 against −11.6 %). Where the "
    "lag's test keeps the lag (white noise at 900 s; 10 Hz at 2000 s seed 2) or a d(ch)/dt term, nothing changes.",
    "",
]


def markdown(rows: list, m: dict, load: float, seconds: float) -> list:
    rises = {
        k: sum(1 for r in rows if "heldout" in r[k] and r[k]["heldout"][1] >= r[k]["heldout"][0])
        for k in ("lag0", "profiled")
    }
    lines = [
        "# A slow channel through a lag: refine's held-out error with the lag profiled for the removal",
        "",
        f"`python benches/refine_channel_lag.py`, {_common.machine_line(m)}; other processes used {load:.0%} of the "
        f"CPUs; {seconds:.0f} s.",
        "",
        f"**The regression step's held-out error rose on {rises['lag0']} of {len(rows)} records with the removal at "
        f"lag 0 (the behaviour before), on {rises['profiled']} with the lag profiled.** Each record: a default "
        '`refine(y, fs, unit="rad/s", channels={"temp": T})`; 6·10⁻⁷ rad/s per °C through a first-order lag '
        "of T (0: none); the step's held-out RMS ADEV error (%) before → after (↑: rose), its coefficient's error, "
        "and the lag the removal took (kept: claimed by the lag's test; a number alone: profiled, not resolved).",
        "",
        "| fs × n | noise | true lag s | seed | held out, lag 0 | held out, profiled | coefficient, lag 0 | "
        "coefficient, profiled | lag used s |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        a, b = r["lag0"], r["profiled"]
        ce = [f"{100 * v['coefficient_error']:+.1f} %" if "coefficient_error" in v else "—" for v in (a, b)]
        lines.append(
            f"| {r['fs']:g} Hz × {r['n']:.0e} | {r['noise']} | {r['lag']} | {r['seed']} | {_cell(a)} | {_cell(b)} | "
            f"{ce[0]} | {ce[1]} | {_lag(b)} |"
        )
    return lines + ["", *NOTES]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="two records only")
    ap.add_argument(
        "--out", type=Path, default=None, help="results folder (default benches/results; --quick: a temporary one)"
    )
    a = ap.parse_args(argv)
    t0 = time.perf_counter()
    m = _common.machine_info()
    rows = []
    with _common.OtherLoad() as load:
        for case in QUICK if a.quick else CASES:
            rows.append(one(case))
            print(rows[-1], flush=True)
    out = a.out or (Path(tempfile.mkdtemp()) if a.quick else HERE / "results")
    out.mkdir(parents=True, exist_ok=True)
    lines = markdown(rows, m, load.fraction or 0.0, time.perf_counter() - t0)
    _common.write_results(out, "refine_channel_lag", lines, {"machine": m, "rows": rows})
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
