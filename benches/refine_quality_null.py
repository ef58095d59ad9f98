#!/usr/bin/env python3
"""The clipped and held checks of ``Refinement.unexplained`` on clean records, and their power.

The two checks (:mod:`allanite.model.refinement._quality`) look only at the samples as given, so they are run
here on the records alone, each at its own α (its share of ``level`` 0.05), as refine runs them:

- null: every record of ``benches/refine_false_alarms.py`` (its own seeds and counts: 613 records over eight
  mixtures, ``quantized`` among them), quantised white noise with a random walk from ½ to 50 steps of noise
  (40 records each), float32 samples on a 250 °/s bias and near zero (20 each), and the 36 ADIS16405 channels
  (quantised to 0.05 °/s and 1/300 g; skipped when ``../shared/data`` is absent) — the rate at which either
  check says anything, with its 95 % Clopper–Pearson interval, and the held check's observed/predicted ties;
- power: an ADIS-like quantised gyro (≈ 9 steps of noise per difference) and a continuous record, one sample
  in every 50, 200 or 1000 repeated; a continuous record clipped at 2σ, 3σ, 4σ.

Usage::

    python benches/refine_quality_null.py           # -> benches/results/refine_quality_null.{json,md}
    python benches/refine_quality_null.py --quick   # 3 records per mixture, to a temporary folder
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
import types
from pathlib import Path

import numpy as np

import _common
import allanite
import refine_false_alarms as fa
from allanite.model.refinement import _quality as qc
from allanite.model.refinement.levels import alpha

HERE = Path(__file__).resolve().parent
A_CLIP, A_HELD = alpha("unexplained:clipped", 0.05), alpha("unexplained:held", 0.05)


def checks(y, fs: float) -> list[dict]:
    """Both checks on ``y`` as refine runs them (one context, its memo shared)."""
    ctx = types.SimpleNamespace(
        samples=np.asarray(y, dtype=np.float64),
        fs=fs,
        curve=types.SimpleNamespace(tau=np.array([1.0 / fs])),
        unit=None,
        level=0.05,
        memo={},
    )
    return qc.clipped_check(ctx, A_CLIP) + qc.held_check(ctx, A_HELD)


def tie_ratio(y) -> float | None:
    """Observed over predicted ties (:func:`qc.expected_ties`), None where nothing is predicted."""
    c = qc.tie_counts(np.asarray(y, dtype=np.float64))
    e = qc.expected_ties(c["n1"], c["n2"])
    return None if not e or e < 20 else c["n0"] / e


def null_groups(per_mix: int | None) -> dict:
    """name -> list of (samples, fs) builders (called one at a time: the records are not all held at once)."""
    groups: dict = {}
    for mix in fa.MIXES:
        n = (80 if mix != "issue16" else 53) if per_mix is None else per_mix
        seeds = [10_000 + 1_000_003 * fa.MIXES.index(mix) + 97 * k for k in range(n)]
        groups[f"false-alarm bench: {mix}"] = [lambda s=s, m=mix: fa.record(m, s)[:2] for s in seeds]
    reps = 40 if per_mix is None else per_mix
    for sigma in (0.5, 1.0, 3.0, 10.0, 50.0):
        groups[f"quantised white + random walk, σ {sigma:g} steps"] = [
            lambda k=k, s=sigma: (_quantised(s, 3000 + k), 100.0) for k in range(reps)
        ]
    for bias in (250.0, 0.012):
        groups[f"float32 on a {bias:g} °/s bias, noise 0.01"] = [
            lambda k=k, b=bias: (_float32(b, 4000 + k), 1000.0) for k in range(reps // 2)
        ]
    return groups


def _quantised(sigma: float, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    x = sigma * rng.standard_normal(200_000) + 0.01 * sigma * np.cumsum(rng.standard_normal(200_000))
    return np.round(x)


def _float32(bias: float, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return (bias + 0.01 * rng.standard_normal(1_000_000)).astype(np.float32)


def adis_records():
    data = _common.shared_data_dir() / "adis16405"
    if not data.is_dir():
        return []
    out = []
    for k in range(1, 7):
        log = allanite.read_log(data / f"adis16405_run{k}_100Hz.csv.gz", fs=100.0)
        arr = np.asarray(log.data, dtype=np.float64)
        out += [(f"run {k} {name}", arr[:, j]) for j, name in enumerate(log.columns)]
    return out


def run_null(per_mix: int | None) -> list[dict]:
    rows = []
    for name, builders in null_groups(per_mix).items():
        fired, ratios = [], []
        for build in builders:
            y, fs = build()
            out = checks(y, fs)
            if out:
                fired.append([e["what"] for e in out])
            r = tie_ratio(y)
            if r is not None:
                ratios.append(r)
        rows.append(_null_row(name, len(builders), fired, ratios))
        _common.log(f"{name}: {len(fired)} of {len(builders)}")
    adis = adis_records()
    if adis:
        fired = [[name, [e["what"] for e in out]] for name, y in adis if (out := checks(y, 100.0))]
        ratios = [r for _n, y in adis if (r := tie_ratio(y)) is not None]
        rows.append(_null_row("ADIS16405 channels (runs 1–6, 3 gyros + 3 accelerometers)", len(adis), fired, ratios))
    return rows


def _null_row(name: str, n: int, fired: list, ratios: list) -> dict:
    lo, hi = _common.clopper_pearson(len(fired), n)
    span = [float(min(ratios)), float(max(ratios))] if ratios else None
    return {"group": name, "records": n, "fired": len(fired), "interval_95": [lo, hi], "tie_ratio": span} | {
        "what": fired[:3]
    }


def run_power() -> list[dict]:
    rows = []
    rng = np.random.default_rng(77)
    gyro = np.round(6.4 * rng.standard_normal(1_000_000)) * 0.05
    cont = rng.standard_normal(1_000_000)
    for label, base in (("ADIS-like gyro (0.05 °/s steps, ≈ 9 per difference)", gyro), ("continuous", cont)):
        for every in (50, 200, 1000):
            y = base.copy()
            idx = np.arange(every, y.size, every)
            y[idx] = y[idx - 1]
            out = [e for e in checks(y, 100.0) if e["domain"] == "held"]
            rows.append({"case": f"{label}: one sample in {every} repeated", "said": bool(out)})
            rows[-1]["what"] = out[0]["what"] if out else None
    for k in (2.0, 3.0, 4.0):
        out = [e for e in checks(np.minimum(cont, k), 100.0) if e["domain"] == "clipped"]
        rows.append({"case": f"continuous, clipped at {k:g}σ ({int(np.sum(cont >= k))} samples)", "said": bool(out)})
        rows[-1]["what"] = out[0]["what"] if out else None
    return rows


def write(res: dict, out: Path) -> None:
    lines = [
        "# Clipped and held samples: the checks of `unexplained` on clean records, and their power",
        "",
        f"Written by `benches/refine_quality_null.py` ({_common.machine_line()}; {res['seconds']:.0f} s). Each check "
        f"at its α: clipped {A_CLIP:.3g} (a quarter at each rail, half on runs of one value), held {A_HELD:.3g}. "
        "Fired: records where either says anything; tie ratio: the held check's observed over predicted ties "
        "(where it predicts ≥ 20).",
        "",
        "| records | n | fired | 95 % interval | tie ratio (min–max) |",
        "|---|---|---|---|---|",
    ]
    for r in res["null"]:
        lo, hi = r["interval_95"]
        tr = "—" if r["tie_ratio"] is None else f"{r['tie_ratio'][0]:.3f}–{r['tie_ratio'][1]:.3f}"
        lines.append(f"| {r['group']} | {r['records']} | {r['fired']} | {100 * lo:.2f}–{100 * hi:.2f} % | {tr} |")
    n, k = sum(r["records"] for r in res["null"]), sum(r["fired"] for r in res["null"])
    lo, hi = _common.clopper_pearson(k, n)
    lines += ["", f"All: {k} of {n} (95 % Clopper–Pearson {100 * lo:.2f}–{100 * hi:.2f} %).", "", "## Power", ""]
    lines += ["| case | said | words |", "|---|---|---|"]
    lines += [f"| {r['case']} | {'yes' if r['said'] else 'no'} | {r['what'] or '—'} |" for r in res["power"]]
    _common.write_results(out, "refine_quality_null", lines, res)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="3 records per group, to a temporary folder")
    args = ap.parse_args(argv)
    out = Path(tempfile.mkdtemp()) if args.quick else HERE / "results"
    t0 = time.perf_counter()
    res = {"null": run_null(3 if args.quick else None), "power": run_power()}
    res["seconds"] = time.perf_counter() - t0
    write(res, out)
    print(f"wrote {out / 'refine_quality_null.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
