#!/usr/bin/env python3
"""Noise-shaped (sigma-delta) quantisation as a kind refine can name (``"shaped_quantisation"``, r18sdm):
sigma-delta records of other rates, lengths and orders, the blind12 row on three seeds, and null records where
plain quantisation or a low-pass is the truth — each refined with the default call.

- **Rows** (``--part rows``): the blind12 sigma-delta row (``refine_blind12.CASES``, judged as the suite judges)
  on its seed and two more; second- and third-order shaping at 100 Hz, 400 Hz and 10 Hz; a second-order modulator
  followed by its sinc³ CIC decimator (8×); and two controls (a 4-tap moving average read through a rounding
  quantiser; white angle noise over white rate noise). Each row: what was found, the shaped step's order and q
  against the truth, whether ``unexplained`` is empty.
- **Nulls** (``--part nulls``): 119 records none of which has shaped noise — ``refine_false_alarms.py``'s
  fast_2khz (Q + N + B), quantized, white, flicker and with_K records (its seeds), ``refine_declared_null.py``'s
  filtered records 0–23 (remez FIR, elliptic, Chebyshev, quantised Bartlett; the default call), white angle noise
  dominating τ0 at 100/400/1000 Hz, delta-angle counters, and moving averages of 2–4 taps beside white angle
  noise (3 taps beside Q is the one process both kinds can write: see the notes). An alarm: anything found or
  unexplained; a shaped alarm: ``shaped_quantisation`` found.

The library measured is the one on ``PYTHONPATH`` (main's for ``--label before``). Each run is merged under
``--label`` into ``benches/results/r18sdm.json``; the .md shows every label.

Usage::

    PYTHONPATH=python python3 benches/r18sdm.py --label after --part rows
    PYTHONPATH=/path/to/main/python python3 benches/r18sdm.py --label before --part nulls
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import time
from pathlib import Path

import numpy as np
from scipy import signal

sys.path.insert(0, str(Path(__file__).resolve().parent))

import _common  # noqa: E402
import allanite  # noqa: E402
import refine_blind as rb  # noqa: E402
import refine_blind12 as b12  # noqa: E402
import refine_declared_null as dn  # noqa: E402
import refine_false_alarms as fa  # noqa: E402

OUT = Path(__file__).resolve().parent / "results"


# --------------------------------------------------------------------------------------------------------------
# rows: sigma-delta records


def _shaped(n, fs, rng, order, sigma, **noise) -> np.ndarray:
    """The five terms' noise plus a modulator's quantisation error (σ in the rate unit) shaped (1 − z⁻¹)^order."""
    return rb.noise(n, fs, rng, **noise) + np.diff(sigma * rng.standard_normal(n + order), order)


def _cic(n_out, fs_out, rng, dec=8, order=2, sigma=0.05) -> np.ndarray:
    """A modulator at dec·fs_out, its shaped noise and white rate noise through a sinc³ CIC, every dec-th kept."""
    x = _shaped(n_out * dec + 64, fs_out * dec, rng, order, sigma, N=5e-3, B=5e-4)
    h = np.convolve(np.convolve(np.ones(dec), np.ones(dec)), np.ones(dec)) / dec**3
    return signal.oaconvolve(x, h, mode="valid")[::dec][:n_out]


def _ma_rounded(n, fs, rng) -> np.ndarray:
    x = rb.noise(n + 3, fs, rng, N=2e-3, K=1e-5)
    y = np.convolve(x, np.full(4, 0.25), mode="valid")[:n]
    lsb = 0.5 * 2e-3 * np.sqrt(fs)
    return np.round(y / lsb) * lsb


def _q_over_n(n, fs, rng) -> np.ndarray:
    return allanite.simulate(n, fs, Q=3e-5, N=2e-3, B=2e-4, seed=rng)


#: (name, build(rng) → (y, fs), truth: (order, q) or what it must be called, seed)
ROWS = [
    (
        "k = 2 at 100 Hz × 2·10⁵, flicker above 1 s",
        lambda g: (_shaped(200_000, 100.0, g, 2, 0.05, N=5e-3, B=1e-3), 100.0),
        (2, 0.05 / 100.0),
        1801,
    ),
    (
        "k = 3 at 400 Hz × 4·10⁵, rate random walk",
        lambda g: (_shaped(400_000, 400.0, g, 3, 0.01, N=2e-3, K=5e-5), 400.0),
        (3, 0.01 / 400.0),
        1802,
    ),
    (
        "k = 2 at 10 Hz × 10⁵, white and flicker",
        lambda g: (_shaped(100_000, 10.0, g, 2, 0.004, N=2e-3, B=5e-4), 10.0),
        (2, 0.004 / 10.0),
        1803,
    ),
    (
        "k = 2 modulator at 8 kHz, sinc³ CIC 8× to 1 kHz × 2·10⁵",
        lambda g: (_cic(200_000, 1000.0, g), 1000.0),
        "bandwidth",
        1804,
    ),
    (
        "control: 4-tap moving average, rounded (LSB ½σ), 1 kHz × 2·10⁵",
        lambda g: (_ma_rounded(200_000, 1000.0, g), 1000.0),
        "bandwidth",
        1805,
    ),
    (
        "control: white angle noise over white rate noise, 1 kHz × 2·10⁵",
        lambda g: (_q_over_n(200_000, 1000.0, g), 1000.0),
        "nothing",
        1806,
    ),
]


def _shaped_step(r) -> dict | None:
    st = next((s for s in r.steps if s.effect == "shaped_quantisation"), None)
    if st is None:
        return None
    return {
        "order": st.params["order"],
        "q": st.params["q"],
        "q_interval": list(st.intervals.get("q", ())),
        "held_out": st.evidence.get("held_out"),
        "psd_share": st.evidence.get("psd_shaped", {}).get("share"),
    }


def _row(name, y, fs, truth) -> dict:
    t0 = time.process_time()
    r = allanite.refine(y, fs, unit="deg/s", progress=False)
    sq = _shaped_step(r)
    row = {
        "name": name,
        "found": list(r.found),
        "unexplained": [u.get("what") for u in r.unexplained],
        "shaped": sq,
        "cpu_s": time.process_time() - t0,
    }
    if isinstance(truth, tuple):
        order, q = truth
        ok = sq is not None and sq["order"] == order and abs(sq["q"] / q - 1) <= 0.2
        row |= {
            "truth": {"order": order, "q": q},
            "q_error_pct": None if sq is None else 100 * (sq["q"] / q - 1),
            "covers": sq is not None and sq["q_interval"][0] <= q <= sq["q_interval"][1],
        }
        row["passed"] = bool(ok and r.found == ["shaped_quantisation"] and not r.unexplained)
    elif truth == "bandwidth":
        row["passed"] = "bandwidth" in r.found and sq is None
    else:
        row["passed"] = not r.found and sq is None
    return row


def rows_part() -> list:
    out = []
    case0 = next(c for c in b12.CASES if "sigma-delta" in c.name)
    for seed in (case0.seed, case0.seed + 100, case0.seed + 200):
        v = b12.run_case(dataclasses.replace(case0, seed=seed))
        steps = v.get("steps") or []
        out.append(
            {
                "name": f"blind12 sigma-delta, seed {seed}",
                "found": v.get("found"),
                "suite_verdict": v.get("passed"),
                "steps": steps,
                "unexplained": [u.get("what") for u in v.get("unexplained") or []],
                "chi2_dof": v.get("chi2_dof"),
                "rms_adev_pct": v.get("rms_adev_pct"),
                "heldout_rms_adev_pct": v.get("heldout_rms_adev_pct"),
            }
        )
        print(out[-1], flush=True)
    for name, build, truth, seed in ROWS:
        y, fs = build(np.random.default_rng(seed))
        out.append(_row(name, y, fs, truth))
        print(out[-1], flush=True)
    return out


# --------------------------------------------------------------------------------------------------------------
# nulls


def _q_dominant(k):
    rng = np.random.default_rng(31_000 + k)
    fs = (100.0, 1000.0, 400.0)[k % 3]
    n = 200_000
    N = 10 ** rng.uniform(-3.5, -2.5)
    Q = N * 10 ** rng.uniform(0.0, 0.7) / np.sqrt(fs)  # white angle noise 1–5× the white rate noise at τ0
    y = rb.noise(n, fs, rng, N=N, B=N * 10 ** rng.uniform(-1.5, -0.5), K=N * 10 ** rng.uniform(-3.0, -2.0))
    return f"Q-dominant {fs:g} Hz", y + allanite.simulate(n, fs, Q=Q, seed=rng), fs


def _counter(k):
    """A delta-angle counter: the angle of N + B + K (and a constant rate) counted in pulses, read as rate."""
    rng = np.random.default_rng(32_000 + k)
    fs = (100.0, 500.0)[k % 2]
    n = 200_000
    N = 10 ** rng.uniform(-3.5, -2.5)
    y = rb.noise(n, fs, rng, N=N, B=N * 0.1, K=N * 1e-3) + 0.3
    pulse = N * np.sqrt(fs) / fs * 10 ** rng.uniform(0.0, 0.5)  # angle per count: 1–3× the white noise's per sample
    counts = np.diff(np.floor(np.cumsum(y) / fs / pulse), prepend=0.0)
    return f"counter {fs:g} Hz", counts * pulse * fs, fs


def _ma_plus_q(k):
    """White noise through a moving average of 2–4 taps plus white angle noise."""
    rng = np.random.default_rng(33_000 + k)
    fs, n = 200.0, 200_000
    taps = 2 + k % 3
    N = 10 ** rng.uniform(-3.5, -2.5)
    x = rb.noise(n + taps, fs, rng, N=N, B=N * 0.1, K=N * 1e-3)
    y = np.convolve(x, np.full(taps, 1.0 / taps), mode="valid")[:n]
    Q = N * 10 ** rng.uniform(-0.3, 0.5) / np.sqrt(fs)
    return f"MA{taps} + Q", y + allanite.simulate(n, fs, Q=Q, seed=rng), fs


def _fa(mix, k):
    y, fs, _ch = fa.record(mix, 10_000 + 1_000_003 * fa.MIXES.index(mix) + 97 * k)
    return mix, y, fs


NULLS: list = (
    [
        ("fa:" + mix, lambda mix=mix, k=k: _fa(mix, k))
        for mix, cnt in (("fast_2khz", 16), ("quantized", 16), ("white", 8), ("flicker", 8), ("with_K", 8))
        for k in range(cnt)
    ]
    + [("declared_default", lambda i=i: dn.record(i)[:3]) for i in range(24)]
    + [("q_dominant", lambda k=k: _q_dominant(k)) for k in range(20)]
    + [("counter", lambda k=k: _counter(k)) for k in range(10)]
    + [("ma_plus_q", lambda k=k: _ma_plus_q(k)) for k in range(9)]
)


def null_row(i: int) -> dict:
    group, make = NULLS[i]
    name, y, fs = make()
    t0 = time.time()
    r = allanite.refine(y, fs, progress=False)
    params = [{k: (v if isinstance(v, (int, float, str)) else str(v)) for k, v in s.params.items()} for s in r.steps]
    return {
        "i": i,
        "group": group,
        "name": name,
        "found": list(r.found),
        "params": params,
        "unexplained": [u.get("domain") for u in r.unexplained],
        "secs": time.time() - t0,
    }


def nulls_part(start: int, stop: int) -> list:
    return [null_row(i) for i in range(start, min(stop, len(NULLS)))]


# --------------------------------------------------------------------------------------------------------------


def _merge(label: str, part: str, rows: list, load: float) -> dict:
    path = OUT / "r18sdm.json"
    res = json.loads(path.read_text()) if path.exists() else {}
    res.setdefault(label, {})[part] = {"rows": rows, "other_load": load}
    path.write_text(json.dumps(res, indent=1, default=str))
    return res


def _null_table(res: dict) -> list:
    lines = [
        "| label | group | records | anything found or unexplained | besides a bandwidth | shaped_quantisation "
        "found | 95 % Clopper–Pearson (shaped) |",
        "|---|---|---|---|---|---|---|",
    ]
    for label, parts in res.items():
        rows = parts.get("nulls", {}).get("rows", [])
        for g in sorted({r["group"] for r in rows}) + ["all"]:
            sel = [r for r in rows if g == "all" or r["group"] == g]
            alarms = sum(bool(r["found"] or r["unexplained"]) for r in sel)
            other = sum(bool([e for e in r["found"] if e != "bandwidth"] or r["unexplained"]) for r in sel)
            shaped = sum("shaped_quantisation" in r["found"] for r in sel)
            lo, hi = _common.clopper_pearson(shaped, len(sel))
            lines.append(
                f"| {label} | {g} | {len(sel)} | {alarms} | {other} | {shaped} | {100 * lo:.1f}–{100 * hi:.1f} % |"
            )
    return lines


def _num(v, fmt=".3g") -> str:
    return "—" if v is None else format(v, fmt)


def _pair(v) -> str:
    return "—" if not v or v[0] is None else f"{_num(v[0])} → {_num(v[1])}"


def _row_line(label: str, row: dict) -> str:
    sq = row.get("shaped")
    steps = row.get("steps")
    if sq is None and steps:
        st = next((s for s in steps if s.get("effect") == "shaped_quantisation"), None)
        sq = None if st is None else st["params"]
    what = "—" if sq is None else f"order {sq['order']}, q {_num(sq['q'])}"
    if row.get("q_error_pct") is not None:
        what += f" ({row['q_error_pct']:+.2f} %, ±1 SD covers: {'yes' if row.get('covers') else 'no'})"
    verdict = row.get("passed", row.get("suite_verdict"))
    return (
        f"| {label} | {row['name']} | {', '.join(row.get('found') or []) or '—'} | {what} | "
        f"{'; '.join(row.get('unexplained') or []) or '—'} | {_pair(row.get('chi2_dof'))} | "
        f"{_pair(row.get('heldout_rms_adev_pct'))} | {'✓' if verdict else '✗'} |"
    )


def write_md(res: dict, notes: list) -> None:
    lines = [
        "# r18sdm: noise-shaped (sigma-delta) quantisation",
        "",
        "Written by `benches/r18sdm.py`.",
        "",
        "## Rows",
        "",
    ]
    lines += [
        "| label | row | found | shaped step | unexplained | χ²/dof | held-out RMS ADEV % | verdict |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for label, parts in res.items():
        lines += [_row_line(label, row) for row in parts.get("rows", {}).get("rows", [])]
    lines += [
        "",
        "Verdict: the blind12 rows as `refine_blind12.py` judges them (a clean case: nothing added); the other rows "
        "named with the right order and q within 20 %, nothing else, nothing unexplained (a CIC or a rounded average: "
        "a bandwidth, no shaped step; white angle noise: nothing).",
    ]
    lines += ["", "## Nulls", ""] + _null_table(res) + ["", "## Notes", ""] + notes
    (OUT / "r18sdm.md").write_text("\n".join(lines) + "\n")


#: What the tables show and why (kept true to the recorded runs).
NOTES: list = [
    "**Runs** (2026-11-28, 15:20–16:00 UTC): `before` is main at db0a328 (a copy of its `python/` with the compiled "
    "core), `after` this branch at its first commit's code (decisions unchanged since: later edits are words and "
    "tests). Load 15–28 on the 2 cores (four other helpers' runs beside): the CPU column of the JSON is this "
    "process's, not a cost measurement. The null rows were run through a `/tmp` copy of `null_row` and its record "
    "list (the same functions and seeds) and merged with `--from-jsonl`.",
    "",
    "**The blind12 row, judged as the suite judges** (`refine_blind12.run_case`, the judge unchanged): ✗ on all "
    "three seeds before and after. Before: a boxcar of 2.78 / 2.83 taps as a stand-in on 1204 / 1404, nothing and "
    "the curve said to depart on 1304. After: `shaped_quantisation`, order 2, q = 5.018·10⁻⁵, 5.000·10⁻⁵, "
    "4.996·10⁻⁵ (truth 5·10⁻⁵ °/s·s: the modulator's error 0.05 °/s × τ0; +0.36, +0.01, −0.08 %), nothing "
    "unexplained, χ²/dof 94 → 1.31, 96 → 1.16, 99 → 0.86. The judge fails it because the row is written as clean "
    "(`allowed=()`): the shaped noise was outside the family when the suite was written; with the kind in the "
    "family the row would be an injected `shaped_quantisation`. Judged so it would pass on 1204 and 1404 and fail "
    "on 1304, whose in-sample RMS ADEV error rises 3.25 → 3.90 % and held-out error 2.79 → 3.24 % (both RMS over "
    "every τ: beyond 1 s both models miss the parts' flicker alike and the refit's N decides the sum; at τ0 the "
    "held-out error falls 3.1 → 0.03 %).",
    "",
    "**New sigma-delta rows**: order 3 at 400 Hz and order 2 at 10 Hz named alone (q +0.39 %, +1.14 %; the 10 Hz "
    "row's ±1 SD interval [4.005, 4.086]·10⁻⁴ just misses 4·10⁻⁴); before, both read as a bandwidth plus a "
    "resonance and a curve that still departs. Order 2 at 100 Hz × 2·10⁵ is named (q +0.12 %) but a resonance "
    "follows (42 Hz, Q 8, GLS score 13.8 against 12.4 — the curve test's threshold by 11 %); on four more seeds "
    "of the same row (1811–1814) the shaped step alone is taken (q −0.28, +0.21, +0.003, −0.10 %), so it reads as "
    "that test's false alarm rather than a shape the kind lacks — not examined further. A second-order modulator "
    "behind its sinc³ CIC decimator (8×) is a `bandwidth`, before and after: the decimation filter removes the "
    "shaped noise above its cutoff, the output's spectrum falls toward f_s/2 and the guard never offers the kind.",
    "",
    "**Nulls** (119 records, none with shaped noise): every record's decision the same before and after but one — "
    "17 → 18 records with anything but a bandwidth found or unexplained (95 % Clopper–Pearson 8.5–21.9 % → "
    "9.2–22.8 %; the declared-filter records' 16 are main's sharp-filter stand-ins, unchanged), "
    "`shaped_quantisation` on 1 of 119 (0.0–4.6 %): record 117, white noise through a 3-tap moving average beside "
    "white angle noise with Q·√f_s/N = 0.83. That process is the kind's own: the 3-tap average's spectrum is "
    "2N²(1 − 8s/3 + 16s²/9) (s = sin²(πf/f_s)), and beside white angle noise 8Q²f_s·s with Q²f_s ≥ (2/3)N² every "
    "coefficient of 1, s, s² is non-negative — white rate noise, white angle noise and second-order shaped noise "
    "with the same spectrum, so the same Gaussian process; no test on the samples' second moments can tell them "
    "apart (the blind12 sigma-delta is the same identity read the other way: a 2.78-tap boxcar beside Q). Of the "
    "three 3-tap records, the one outside that region (0.65) and one inside it (0.94) stayed a bandwidth. On the "
    "other 110 (white angle noise dominating τ0 at 100/400/1000 Hz, delta-angle counters, the false-alarm "
    "suite's Q + N + B, quantised, white, flicker and with_K records, the declared-filter records' default call) "
    "`shaped_quantisation` was never found (0 of 110, 0.0–3.3 %).",
    "",
    "**With channels** (`refine_false_alarms.record`'s slow_1hz × 5, channels_100hz × 4 and issue16 × 4, their "
    "seeds, the default call with their channels; `/tmp` driver, both libraries): nothing found or unexplained on "
    "any of the 13, before and after (0 of 13, 0.0–24.7 %). Over all 132 null records `shaped_quantisation` was "
    "found once (0.02–4.1 %), on none of the 123 outside the moving-average-beside-Q group (0.0–3.0 %).",
    "",
    "**The spectrum's guard on rounded moving averages** (1 kHz × 2·10⁵, `/tmp` driver, this branch): a 3-tap "
    "average reads a shaped share of 1.0 on two seeds (its spectrum rises from its zero at f_s/3 to f_s/2, and the "
    "non-negative mix gives that rise to s²): the guard passes, the Allan-curve test scores the shaped column 0 "
    "(one-sided: the average lowers τ0, the shaping would raise it) and a boxcar of 3.01 / 2.98 taps is named; a "
    "5-tap average reads 0.0 and is a boxcar of 4.92. The guard is a guard, not a test; the docs say so.",
    "",
    "**ADIS16405** (`refine_measured.py --only` run 1 gyro_z, run 3 acc_x, run 5 gyro_y, run 6 acc_x, before and "
    "after): every field of the four rows the same (487, 712, 63 and 653 fields; the seconds and load aside).",
]


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--label", required=True)
    ap.add_argument("--part", choices=("rows", "nulls"), required=True)
    ap.add_argument("--start", type=int, default=0)
    ap.add_argument("--stop", type=int, default=len(NULLS))
    ap.add_argument("--from-jsonl", type=Path, help="null rows measured by this script's null_row, one JSON a line")
    args = ap.parse_args(argv)
    with _common.OtherLoad() as load:
        if args.from_jsonl is not None:
            rows = [json.loads(ln) for ln in args.from_jsonl.read_text().splitlines() if ln.strip()]
        else:
            rows = rows_part() if args.part == "rows" else nulls_part(args.start, args.stop)
    write_md(_merge(args.label, args.part, rows, load.fraction or 0.0), NOTES)


if __name__ == "__main__":
    main()
