#!/usr/bin/env python3
"""False alarms of the words that tie a line's amplitude to a channel (``unexplained``'s ``"line"`` entry, "it
follows 'temp'": :mod:`allanite.model.refinement._line_channel`) and of the channel checks, on whole refines of
null records — lines of constant amplitude beside a temperature the rate follows through a term refine models.

Records, each with a seed of its own: white noise with flicker (B) and rate random walk (K); 20 Hz × 2·10⁴
samples (1000 s); a 15–35 °C temperature cycling three times, warming once or wandering
(``tests/sensors.temperature_profile``) with 0.01 °C of sensor noise, the rate coupled to it linearly, with a
quadratic, or through a first-order lag of 60 s; a line of constant amplitude (1–4 Hz, 0.6–1.2 × the white
noise's σ per sample). Counted: records whose ``unexplained`` holds a ``"line"`` entry, one with the new words
(``"follows"``), a ``"channels"`` entry (the coupling or its shape), and any entry at all, and records whose accepted
sinusoid took a gain on the channel (``"gain"``: :mod:`allanite.model.refinement._line_gain`, at its conditional
share ``levels.alpha("sinusoid:gain")`` over the lines offered); 95 % Clopper–Pearson intervals. The words are tested only where the line check fires, at its α (``levels.alpha("unexplained:line")``
per line, split over the channels): their share is at most the line check's.

``--gain``: the line's gain option alone (its F test at ``levels.alpha("sinusoid:gain")`` and its held-out blocks)
on ``--records`` records, no refine.

``--calibration``: the statistic itself on ``--records`` records (white + flicker + random walk, a constant line,
the same temperatures), counted at 5 %, 1 % and 0.1 % against its F(1, d₂) reference (no refine).

Usage::

    python benches/line_channel_null.py --records 120                 # whole refines, ~5 min CPU
    python benches/line_channel_null.py --records 1000 --calibration  # the statistic alone, ~2 min CPU
    python benches/line_channel_null.py --records 1000 --gain         # the line's gain option alone
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
from scipy import signal, stats

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import allanite
import sensors
from allanite.model.refinement._line_channel import _one, block_means
from allanite.model.refinement._line_constancy import line_constancy
from allanite.model.refinement._line_gain import line_gain
from allanite.model.refinement.levels import alpha
from channel_turnover_null import _cp

KINDS = ("cycle", "swing", "walk")
COUPLINGS = ("linear", "quadratic", "lag")
LEVELS = (0.05, 0.01, 0.001)


def _record(seed: int):
    """(temperature kind, coupling, samples, fs, temperature) of null record ``seed``."""
    rng = np.random.default_rng(7000 + seed)
    kind, coupling = KINDS[seed % 3], COUPLINGS[seed // 3 % 3]
    fs, n = 20.0, 20_000
    t = np.arange(n) / fs
    y = allanite.simulate(n, fs, seed=rng, N=1e-3, B=2e-4, K=1e-5)
    temp = sensors.temperature_profile(t, kind, rng, lo=15.0, hi=35.0)
    if coupling == "lag":
        a = np.exp(-1.0 / (60.0 * fs))
        drive = signal.lfilter([1 - a], [1, -a], temp - temp[0]) + temp[0]
    else:
        drive = temp
    dev = drive - drive.mean()
    y = y + 2e-4 * dev + (3e-6 * (dev**2 - np.mean(dev**2)) if coupling == "quadratic" else 0.0)
    f0, amp = rng.uniform(1.0, 4.0), rng.uniform(0.6, 1.2) * 1e-3 * np.sqrt(fs)
    y = y + amp * np.sin(2 * np.pi * f0 * t + rng.uniform(0, 2 * np.pi))
    return kind, coupling, y, fs, temp + 0.01 * rng.standard_normal(n), f0


def _refines(records: int, start: int = 0) -> dict:
    keys = ("line", "follows", "channels", "any", "sinusoid", "gain")
    counts = {c: {k: 0 for k in ("records",) + keys} for c in COUPLINGS}
    said = []
    for seed in range(start, start + records):
        _kind, coupling, y, fs, temp, _f0 = _record(seed)
        r = allanite.refine(y, fs, channels={"temp": temp}, progress=False)
        un = r.unexplained
        c = counts[coupling]
        c["records"] += 1
        c["line"] += any(u["domain"] == "line" for u in un)
        c["follows"] += any(u["domain"] == "line" and "follows" in u for u in un)
        c["channels"] += any(u["domain"] == "channels" for u in un)
        c["any"] += bool(un)
        c["sinusoid"] += "sinusoid" in r.found
        gains = [st.params["gain"] for st in r.steps if st.effect == "sinusoid" and "gain" in st.params]
        c["gain"] += bool(gains)
        said += [(seed, u["domain"], u.get("what", "")) for u in un]
        print(
            json.dumps(
                {"seed": seed, "coupling": coupling, "found": list(r.found), "gains": gains}
                | {"said": said[-len(un) :] if un else []},
                ensure_ascii=False,
            ),
            file=sys.stderr,
            flush=True,
        )
    return {"counts": counts, "said": said}


def _gain(records: int) -> dict:
    """The line's gain option alone (:func:`._line_gain.line_gain` at its conditional α, one line offered) on
    null records: the rate at which a constant line takes a gain on the channel."""
    a = alpha("sinusoid:gain", 0.05)
    hits = 0
    for seed in range(records):
        _kind, _c, y, fs, temp, f0 = _record(seed)
        g = line_gain(y, fs, f0, {"temp": temp}, a)
        hits += g is not None
        print(json.dumps({"seed": seed, "gain": None if g is None else g["gain"]}), file=sys.stderr, flush=True)
    return {"alpha": a, "gains": [hits, records, _cp(hits, records)]}


def _calibration(records: int) -> dict:
    hits = [0] * len(LEVELS)
    for seed in range(records):
        _kind, _c, y, fs, temp, f0 = _record(seed)
        r = line_constancy(y, fs, f0, 0.01, phasors=True)
        xk = block_means(temp, np.round(np.asarray(r["edges_s"]) * fs).astype(int))
        one = _one(np.asarray(r["phasors"]), np.asarray(r["phasor_unit"]), r["noise_level"], r["noise_dof"], xk, 0.01)
        p = float(stats.f.sf(one["statistic"], 1, r["noise_dof"])) if one else 1.0
        hits = [h + (p < lv) for h, lv in zip(hits, LEVELS)]
        print(json.dumps({"seed": seed, "p": p}), file=sys.stderr, flush=True)
    return {f"p<{lv}": [h, records, _cp(h, records)] for lv, h in zip(LEVELS, hits)}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--records", type=int, default=120)
    ap.add_argument("--calibration", action="store_true", help="the statistic alone against its F reference")
    ap.add_argument("--gain", action="store_true", help="the line's gain option alone at its conditional share")
    ap.add_argument("--start", type=int, default=0, help="the first record's seed (a run split over processes)")
    args = ap.parse_args(argv)
    t0 = time.process_time()
    out: dict = {"alpha_line": alpha("unexplained:line", 0.05)}
    if args.calibration:
        out["calibration"] = _calibration(args.records)
    elif args.gain:
        out["gain"] = _gain(args.records)
    else:
        out |= _refines(args.records, args.start)
        total = {k: sum(c[k] for c in out["counts"].values()) for k in out["counts"]["linear"]}
        out["all"] = {k: [v, _cp(v, total["records"])] for k, v in total.items()}
    out["cpu_s"] = round(time.process_time() - t0, 1)
    print(json.dumps(out, default=float, ensure_ascii=False))


if __name__ == "__main__":
    main()
