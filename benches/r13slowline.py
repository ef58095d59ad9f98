"""A line of few cycles (3–18 in the record) tested in time: its false alarms on red-noise nulls, its power on
sensors unlike the tiltmeter it was first seen on (:func:`allanite.model.slowline.slow_line_test`, at its share of
``level``, :data:`allanite.model.refinement.levels.SLOW_LINE_SHARE`).

- **Nulls** — the test alone on records of white noise, flicker and random walk (and a rate ramp), at rates and
  lengths unlike each other: its p-value per record (from its own null draws), the rejections at its α and at
  0.01 and 0.05 (the law's shape) with Clopper–Pearson 95 % intervals.
- **Power** — over seeds, per case: found (at its α), f0 within 1 %, and the amplitude's ±1σ and ±2σ intervals'
  coverage of the truth: a clock-like 1 Hz record of 5 days with a daily line under flicker FM; a gyro at 100 Hz
  for 4 h with a 1 h thermal cycle; a 0.1 Hz record of 3 days with a 12.42 h (M2 tidal) line on a random walk
  and a rate ramp; each at two amplitudes.
- **refine** — a few seeds of each power case through :func:`allanite.refine` (its default candidates): the
  steps named and what is left unexplained.

Usage::

    python benches/r13slowline.py                 # -> benches/results/r13slowline.{json,md}
    python benches/r13slowline.py --records 10 --seeds 5 --refine 1 --out /tmp/x
    python benches/r13slowline.py --fa            # the test on refine_false_alarms.py's 613 records -> r13slowline_fa.*
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import numpy as np

import allanite
import refine_blind as rb
from _common import clopper_pearson, machine_info, machine_line
from allanite._blas import one_thread
from allanite.model.refinement.levels import LEVEL, alpha
from allanite.model.slowline import slow_line_test

ALPHA = alpha("slow_lines", LEVEL)

#: Null records: name → (fs, n, noise keywords of ``refine_blind.noise``).
NULLS = {
    "tiltmeter-like 0.5 Hz × 2·10⁵: white, flicker, random walk": (0.5, 200_000, {"N": 0.05, "B": 0.01, "K": 2e-5}),
    "clock 1 Hz × 5 d: white FM, flicker FM": (1.0, 432_000, {"N": 1.0, "B": 0.01}),
    "gyro 100 Hz × 4 h: N, B, K": (100.0, 1_440_000, {"N": 2e-3, "B": 3e-4, "K": 1e-5}),
    "logger 10 Hz × 5·10⁵: random walk dominant, a rate ramp": (10.0, 500_000, {"N": 0.01, "K": 1e-4, "R": 1e-6}),
    "white only, 1 Hz × 10⁵": (1.0, 100_000, {"N": 1.0}),
    "flicker dominant, 2 Hz × 3·10⁵": (2.0, 300_000, {"N": 0.01, "B": 0.05}),
}

#: Power cases: name → (fs, n, noise keywords, line period s, amplitudes (weak, strong)).
POWER = {
    "clock 1 Hz × 5 d, daily line under flicker FM": (1.0, 432_000, {"N": 1.0, "B": 0.01}, 86_400.0, (0.02, 0.04)),
    "gyro 100 Hz × 4 h, 1 h thermal cycle": (100.0, 1_440_000, {"N": 2e-3, "B": 3e-4, "K": 1e-5}, 3600.0, (4e-4, 8e-4)),
    "0.1 Hz × 3 d, 12.42 h tidal line on a random walk and a ramp": (
        0.1,
        25_920,
        {"N": 0.02, "K": 1e-4, "R": 1e-7},
        44_712.0,
        (0.01, 0.03),
    ),
}


def _null(name: str, records: int) -> dict:
    fs, n, kw = NULLS[name]
    p = []
    for i in range(records):
        rng = np.random.default_rng(7_000 + 101 * i + len(name))
        y = rb.noise(n, fs, rng, **kw)
        r = slow_line_test(y, fs, ALPHA, calibrate=True)
        p.append(1.0 if r is None else r["p_value"])
    p_arr = np.array(p)
    out = {"records": records, "p_values": p}
    for a in (ALPHA, 0.01, 0.05):
        k = int(np.count_nonzero(p_arr <= a))
        out[f"{a:g}"] = {"rejected": k, "rate": k / records, "cp95": clopper_pearson(k, records)}
    return out


def _power(name: str, seeds: int, amp: float) -> dict:
    fs, n, kw, period, _amps = POWER[name]
    f0 = 1.0 / period
    found = within = cov1 = cov2 = 0
    z = []
    for s in range(seeds):
        rng = np.random.default_rng(9_000 + 37 * s + len(name))
        t = np.arange(n) / fs
        y = rb.noise(n, fs, rng, **kw) + amp * np.sin(2 * np.pi * f0 * t + rng.uniform(0, 2 * np.pi))
        r = slow_line_test(y, fs, ALPHA)
        if r is None:
            continue
        found += int(r["accepted"])
        if r["accepted"]:
            within += int(abs(r["f0"] / f0 - 1.0) <= 0.01)
        zi = (r["amplitude"] - amp) / r["amplitude_sd"]
        z.append(zi)
        cov1, cov2 = cov1 + int(abs(zi) <= 1.0), cov2 + int(abs(zi) <= 2.0)
    return {
        "seeds": seeds,
        "amplitude": amp,
        "cycles": n / fs / period,
        "found": found,
        "found_cp95": clopper_pearson(found, seeds),
        "f0_within_1pct": within,
        "amp_cover_1sd": cov1,
        "amp_cover_2sd": cov2,
        "amp_z": z,
    }


def _refine(name: str, seeds: int) -> list:
    fs, n, kw, period, amps = POWER[name]
    out = []
    for s in range(seeds):
        rng = np.random.default_rng(11_000 + 37 * s + len(name))
        t = np.arange(n) / fs
        y = rb.noise(n, fs, rng, **kw) + amps[1] * np.sin(2 * np.pi * t / period + rng.uniform(0, 2 * np.pi))
        t0 = time.process_time()
        r = allanite.refine(y, fs, unit=None, progress=False)
        steps = [(st.effect, {k: v for k, v in st.params.items() if isinstance(v, float)}) for st in r.steps]
        out.append(
            {
                "seed": s,
                "steps": steps,
                "unexplained": [u.get("what") for u in r.unexplained],
                "cpu_seconds": time.process_time() - t0,
            }
        )
    return out


def _md(res: dict) -> list[str]:
    lines = [
        "# A line of few cycles tested in time (r13slowline)",
        "",
        f"α of the test = level × share = {ALPHA:g} (level {LEVEL}). {machine_line(res['machine'])}; "
        f"load average at start {res['load_start']}, at end {res['load_end']}.",
        "",
        "## Nulls (the test alone)",
        "",
        f"| record | n | rejected at α {ALPHA:g} | at 0.01 | at 0.05 |",
        "|---|---|---|---|---|",
    ]
    tot = {f"{a:g}": 0 for a in (ALPHA, 0.01, 0.05)}
    n_all = 0
    for name, r in res["nulls"].items():
        cells = []
        for a in tot:
            c = r[a]
            tot[a] += c["rejected"]
            cells.append(f"{c['rejected']} ({100 * c['cp95'][0]:.1f}–{100 * c['cp95'][1]:.1f} %)")
        n_all += r["records"]
        lines.append(f"| {name} | {r['records']} | " + " | ".join(cells) + " |")
    cells = []
    for a, k in tot.items():
        lo, hi = clopper_pearson(k, n_all)
        cells.append(f"**{k}** ({100 * lo:.2f}–{100 * hi:.2f} %)")
    lines += [f"| all | {n_all} | " + " | ".join(cells) + " |", "", "## Power (the test alone)", ""]
    lines += [
        "| case | cycles | amplitude | found | f0 within 1 % | amplitude ±1σ covers | ±2σ covers |",
        "|---|---|---|---|---|---|---|",
    ]
    for name, rows in res["power"].items():
        for r in rows:
            lo, hi = r["found_cp95"]
            lines.append(
                f"| {name} | {r['cycles']:.1f} | {r['amplitude']:g} | {r['found']}/{r['seeds']} "
                f"({100 * lo:.0f}–{100 * hi:.0f} %) | {r['f0_within_1pct']}/{r['found']} | "
                f"{r['amp_cover_1sd']}/{r['seeds']} | {r['amp_cover_2sd']}/{r['seeds']} |"
            )
    lines += ["", "## refine (default candidates), the strong amplitude", ""]
    lines += ["| case | seed | steps | unexplained | CPU s |", "|---|---|---|---|---|"]
    for name, rows in res["refine"].items():
        for r in rows:
            steps = "; ".join(
                f"{e} ({', '.join(f'{k} {v:.4g}' for k, v in p.items() if k in ('amplitude', 'f0', 'T'))})"
                for e, p in r["steps"]
            )
            un = "; ".join(str(u) for u in r["unexplained"]) or "none"
            lines.append(f"| {name} | {r['seed']} | {steps or 'nothing'} | {un} | {r['cpu_seconds']:.0f} |")
    return lines


def false_alarm_records(out: Path) -> None:
    """The test on every record of ``benches/refine_false_alarms.py`` (613, its seeds), calibrated (its p-value
    from its own draws): refine's decisions on those records move only where it accepts (nothing else changed;
    the Allan-curve test's critical draw at level 0.05 stays the 988th of 1001) -> r13slowline_fa.{json,md}."""
    import refine_false_alarms as fa

    rows = {}
    with one_thread():
        for mix in fa.MIXES:
            ps = []
            for k in range(80 if mix != "issue16" else 53):
                y, fs, _ch = fa.record(mix, 10_000 + 1_000_003 * fa.MIXES.index(mix) + 97 * k)
                r = slow_line_test(y, fs, ALPHA, calibrate=True)
                ps.append(None if r is None else [r["p_value"], r["statistic"], r["threshold"], r["accepted"]])
            rows[mix] = ps
    (out / "r13slowline_fa.json").write_text(json.dumps(rows))
    (out / "r13slowline_fa.md").write_text("\n".join(fa_md(rows, os.getloadavg())) + "\n")


def fa_md(rows: dict, load) -> list[str]:
    """The false-alarm records' table: per mixture, accepted (at α) and p-values ≤ 0.01, ≤ 0.05, with CP 95 %."""
    lines = [
        "# The slow-line test on refine_false_alarms.py's 613 null records",
        "",
        f"α = {ALPHA:g} (level {LEVEL} × 0.008); load average at the end {[round(v, 1) for v in load]} (2 cores).",
        "",
        "| mixture | records | accepted | p ≤ 0.01 | p ≤ 0.05 |",
        "|---|---|---|---|---|",
    ]
    tot = [0, 0, 0, 0]
    for mix, ps in rows.items():
        got = [p for p in ps if p is not None]
        c = [sum(1 for p in got if p[3]), sum(1 for p in got if p[0] <= 0.01), sum(1 for p in got if p[0] <= 0.05)]
        tot = [tot[0] + len(ps), tot[1] + c[0], tot[2] + c[1], tot[3] + c[2]]
        lines.append(f"| {mix} | {len(ps)} | {c[0]} | {c[1]} | {c[2]} |")
    cells = []
    for k in tot[1:]:
        lo, hi = clopper_pearson(k, tot[0])
        cells.append(f"**{k}** ({100 * lo:.2f}–{100 * hi:.2f} %)")
    lines.append(f"| all | {tot[0]} | " + " | ".join(cells) + " |")
    return lines


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--records", type=int, default=40, help="null records per kind")
    ap.add_argument("--seeds", type=int, default=30, help="seeds per power case and amplitude")
    ap.add_argument("--refine", type=int, default=2, help="seeds per power case through refine")
    ap.add_argument("--out", default=str(Path(__file__).parent / "results"))
    ap.add_argument("--fa", action="store_true", help="only the test on refine_false_alarms.py's 613 records")
    args = ap.parse_args(argv)
    if args.fa:
        false_alarm_records(Path(args.out))
        return
    res: dict = {"machine": machine_info(), "load_start": [round(v, 1) for v in os.getloadavg()], "alpha": ALPHA}
    with one_thread():
        res["nulls"] = {name: _null(name, args.records) for name in NULLS}
        print("nulls done", flush=True)
        res["power"] = {name: [_power(name, args.seeds, a) for a in POWER[name][4]] for name in POWER}
        print("power done", flush=True)
    res["refine"] = {name: _refine(name, args.refine) for name in POWER}
    res["load_end"] = [round(v, 1) for v in os.getloadavg()]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "r13slowline.json").write_text(json.dumps(res, indent=1, default=float))
    (out / "r13slowline.md").write_text("\n".join(_md(res)) + "\n")
    print("\n".join(_md(res)))


if __name__ == "__main__":
    main()
