#!/usr/bin/env python3
"""The cost of one default ``allanite.refine`` (issue 29: ≤ 5 s per 10⁶ samples), before and after, as ratios.

Records: seven ADIS16405 channels (10⁶ samples at 100 Hz, from the shared data: the slowest of
``benches/results/refine.json`` — the accelerometers of runs 3 and 6 — and gyros), three simulated sensors of
``tests/sensors.py`` (10⁶ samples at 100 Hz with a temperature channel, line families at 100 Hz × 10⁶, a sawtooth
at 1 kHz × 10⁷) and a short 3-axis log with a temperature (1.2·10⁵ samples per axis at 100 Hz, every axis refined
as ``allanite report --refine`` does; the row is the three calls). Each record is refined with the default call in a fresh process
(imports paid by a small refine first, untimed), once with this checkout and once with the baseline — a
``python/`` folder of an earlier checkout (``--baseline``; by default a worktree of main at
:data:`BASELINE` made under the temporary folder, with this checkout's compiled core copied in) — the two
alternating record by record so that they share the machine's load; each call's CPU time (the process's own,
all its threads: what the load changes least) and wall time are recorded. Both results are compared: the
effects found, their parameters and intervals, each step's χ²/dof and errors before and after, and what is
still missing — field by field, and where numbers differ in their last digits (the compiled reweighting loop,
the χ² quantile table) with the largest relative difference of the parameters, of the χ²/dof and of the rest
(:mod:`compare_refine`).

Usage::

    python benches/bench_refine_cost.py                 # -> benches/results/refine_cost.md
    python benches/bench_refine_cost.py --quick         # ADIS run 1 gyro_z only, to a temporary folder
    python benches/bench_refine_cost.py --records 1:acc_x 1:gyro_z --rounds 3 --out /tmp/x
                                                        # chosen ADIS records, each round alternating which
                                                        # checkout runs first
    python benches/bench_refine_cost.py --records sensor:temperature "sensor:line families" --out /tmp/x
                                                        # simulated sensors, by a part of their name
    python benches/bench_refine_cost.py --records log --rounds 2 --out /tmp/x
                                                        # the short 3-axis log with a temperature
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
#: main before this round of refine's speed-ups (issue 29, refine's cost, round r18cost; earlier rounds' baselines:
#: 9165947, 313a76b, f836703, a0e3816, 3637a85, 904c152, 80c1a7b, f68a6c9, f24f72e, b12d419, 4ce759c).
BASELINE = "db0a328"
ADIS = [
    ("adis", 1, "gyro_z"),
    ("adis", 4, "gyro_x"),
    ("adis", 3, "gyro_z"),
    ("adis", 1, "acc_x"),
    ("adis", 3, "acc_x"),
    ("adis", 6, "acc_x"),
    ("adis", 6, "acc_y"),
]
SENSORS = [
    ("sensor", "temperature random walk, 100 Hz"),
    ("sensor", "consumer IMU line families"),
    ("sensor", "sawtooth 0.05 Hz, 1 kHz"),
]
#: A short multi-axis log with a channel (a notebook user's 20 minutes): every axis refined as ``allanite report
#: --refine`` refines them (one call per axis, the checks' null records shared between the calls where the checkout
#: can: ``model/_null_records.sharing``); the row is the sum over the axes.
LOGS = [("log", "3-axis gyro log with a temperature, 100 Hz × 1.2·10⁵ per axis")]
LOG_AXES = (("gyro_x", 2e-3, 3e-3), ("gyro_y", 0.0, 2.5e-3), ("gyro_z", -1e-3, 3.5e-3))


def _short_log():
    """(axes (n, 3), fs, {"temp": channel}) of :data:`LOGS`: white rate, flicker and a random walk per axis, two of
    the three following a room's temperature (a random walk through the housing's lag) by their coefficient."""
    import numpy as np

    import allanite

    sys.path.insert(0, str(REPO / "tests"))
    import sensors

    n, fs = 120_000, 100.0
    rng = np.random.default_rng(42)
    temp = sensors.temperature_profile(np.arange(n) / fs, "walk", rng)
    cols = []
    for _name, c, white in LOG_AXES:
        y = allanite.simulate(n, fs, N=white, K=2e-5, seed=rng) + 1.5e-3 * sensors.kasdin_walter(8 * n, 1.0, rng)[-n:]
        cols.append(y + c * (temp - temp.mean()))
    return np.column_stack(cols), fs, {"temp": temp + 0.01 * rng.standard_normal(n)}


def _record(spec):
    """(samples, fs, keyword arguments of the default call, name, samples) of a record spec."""
    import numpy as np

    import _common
    import allanite

    if spec[0] == "adis":
        _kind, run, ax = spec
        path = _common.shared_data_dir() / "adis16405" / f"adis16405_run{run}_100Hz.csv.gz"
        x = np.asarray(allanite.read_log(path, fs=100.0, columns=[ax]).data, dtype=np.float64).ravel()
        return x, 100.0, {}, f"ADIS16405 run {run} {ax}"
    sys.path.insert(0, str(REPO / "tests"))
    import sensors

    case = next(c for c in sensors.CASES if spec[1] in c.name)
    y, fs, channels = sensors.make(case)
    kw = {"unit": case.unit} | ({"channels": channels} if channels else {})
    return y, fs, kw, case.name


def _spec(text: str) -> tuple:
    """A record of ``--records``: ``RUN:AXIS`` (ADIS16405), ``sensor:NAME`` (a part of a sensor's name) or ``log`` (the
    short 3-axis log with a temperature, :data:`LOGS`)."""
    if text == "log":
        return LOGS[0]
    kind, rest = text.split(":", 1)
    return ("sensor", rest) if kind == "sensor" else ("adis", int(kind), rest)


def worker(spec, out: Path) -> None:
    """Refine one record with the default call (in the process's own allanite) and write its row."""
    import numpy as np

    import allanite
    from refine_measured import _jsonable, summarize

    if spec[0] == "log":
        x, fs, channels = _short_log()
        kw, name = {"unit": "deg/s", "channels": channels}, spec[1]
    else:
        x, fs, kw, name = _record(spec)
    allanite.refine(np.random.default_rng(0).standard_normal(20_000), 10.0, progress=False)  # imports, untimed
    load = os.getloadavg()[0]

    def summary(r, label):
        return _jsonable(summarize(label, r)) | {
            "fit_chi2": float(r.fit.chi2),
            "unexplained_all": _jsonable(r.unexplained),
        }

    t0, c0 = time.perf_counter(), time.process_time()
    if spec[0] == "log":
        with _sharing():
            rs = [allanite.refine(x[:, k], fs, progress=False, **kw) for k in range(x.shape[1])]
    else:
        r = allanite.refine(x, fs, progress=False, **kw)
    seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
    if spec[0] == "log":
        row = {"record": name, "axes": [summary(r, ax[0]) for r, ax in zip(rs, LOG_AXES)]}
    else:
        row = summary(r, name)
    info = {"row": row, "seconds": seconds, "cpu": cpu, "samples": int(x.size), "load": load}
    out.write_text(json.dumps(info, default=float))


def _sharing():
    """The report's scope over a log's axes (the null records' flicker kept between the calls), where the checkout
    being timed has it; else nothing (a checkout before it refines each axis afresh, as its report did)."""
    import contextlib

    try:
        from allanite.model._null_records import sharing
    except ImportError:
        return contextlib.nullcontext()
    return sharing()


def _baseline_python(ref: str) -> Path:
    """``python/`` of ``ref`` (exported once under the temporary folder), this checkout's compiled core copied in."""
    root = Path(tempfile.gettempdir()) / f"allanite-baseline-{ref}"
    if not (root / "python" / "allanite").exists():
        root.mkdir(parents=True, exist_ok=True)
        archive = subprocess.run(["git", "-C", str(REPO), "archive", ref, "python"], check=True, capture_output=True)
        subprocess.run(["tar", "-x", "-C", str(root)], input=archive.stdout, check=True)
    core = next((REPO / "python" / "allanite").glob("_core*.so"))
    if not any((root / "python" / "allanite").glob("_core*.so")):
        shutil.copy(core, root / "python" / "allanite" / core.name)
    return root / "python"


def _run(spec, python_dir: Path, tmp: Path) -> dict:
    out = tmp / f"{abs(hash((spec, str(python_dir))))}.json"
    env = os.environ | {"PYTHONPATH": str(python_dir)}
    subprocess.run([sys.executable, __file__, "--worker", json.dumps(spec), str(out)], check=True, env=env, cwd=HERE)
    return json.loads(out.read_text())


def _differences(a, b, path="") -> list[str]:
    if isinstance(a, dict) and isinstance(b, dict):
        return [d for k in sorted(set(a) | set(b), key=str) for d in _differences(a.get(k), b.get(k), f"{path}/{k}")]
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        return [d for i, (u, v) in enumerate(zip(a, b)) for d in _differences(u, v, f"{path}[{i}]")]
    return [] if a == b else [f"{path}: {a!r} → {b!r}"]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", type=Path)
    ap.add_argument("--baseline", type=Path, help="python/ folder of the baseline checkout (with its core)")
    ap.add_argument("--after", type=Path, default=REPO / "python", help="python/ folder to time (default: this one)")
    ap.add_argument(
        "--records",
        nargs="+",
        metavar="RUN:AXIS",
        help="ADIS16405 records, sensor:NAME or log (default: the lists above)",
    )
    ap.add_argument("--rounds", type=int, default=1, help="times each record is refined by each checkout")
    ap.add_argument("--worker", nargs=2, help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.worker:
        worker(tuple(json.loads(a.worker[0])), Path(a.worker[1]))
        return 0
    import _common
    import compare_refine

    out = a.out or (Path(tempfile.mkdtemp()) if a.quick else HERE / "results")
    base = a.baseline or _baseline_python(BASELINE)
    specs = ADIS[:1] if a.quick else ADIS + SENSORS + LOGS
    if a.records:
        specs = [_spec(r) for r in a.records]
    rows, load0 = [], os.getloadavg()
    busy0, own0, wall0 = _common.OtherLoad._busy(), _own_and_children(), time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        for rnd, spec in ((r, sp) for r in range(a.rounds) for sp in specs):
            if rnd % 2:  # odd rounds: this checkout first, so that neither always meets the load first
                after = _run(spec, a.after, Path(tmp))
                before = _run(spec, base, Path(tmp))
            else:
                before = _run(spec, base, Path(tmp))
                after = _run(spec, a.after, Path(tmp))
            diff = _differences(before["row"], after["row"])
            close = compare_refine.compare(before["row"], after["row"])
            rows.append(
                {
                    "record": after["row"]["record"] + (f" (round {rnd + 1})" if a.rounds > 1 else ""),
                    "before": before,
                    "after": after,
                    "differences": diff,
                    "close": close,
                }
            )
            print(
                f"{rows[-1]['record']}: CPU {before['cpu']:.1f} → {after['cpu']:.1f} s, wall "
                f"{before['seconds']:.1f} → {after['seconds']:.1f} s, {len(diff)} differences",
                flush=True,
            )
    others = None
    busy1, wall = _common.OtherLoad._busy(), time.perf_counter() - wall0
    if busy0 is not None and busy1 is not None:  # CPU time of processes other than this run's, of all CPUs' time
        others = max(0.0, (busy1 - busy0) - (_own_and_children() - own0)) / (wall * (os.cpu_count() or 1))
    _write(rows, out, base, load0, os.getloadavg(), others)
    (out / "refine_cost.json").write_text(json.dumps({"after": str(a.after), "rows": rows}, indent=1, default=float))
    print(f"wrote {out / 'refine_cost.md'}")
    return 0


def _own_and_children() -> float:
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


def _differing(r) -> str:
    """The differences of a row in words: fields not equal, the largest relative differences of numbers."""
    close = r["close"]
    words = [f"{len(r['differences'])} fields differ"]
    words += [f"{say} ≤ {close[k][0]:.1e}" for k, say in (("params", "params"), ("chi2", "χ²/dof")) if close[k][0]]
    words += [f"rest ≤ {close['other'][0]:.1e}"] if close["other"][0] else []
    if close["mismatch"]:
        words.append(f"not equal: {close['mismatch'][:3]}")
    return ", ".join(words)


def _write(rows, out: Path, base: Path, load0, load1, others) -> None:
    import _common

    m = _common.machine_info()
    lines = [
        "# The cost of one default `refine` (issue 29)",
        "",
        f"Written by `benches/bench_refine_cost.py`: {m['cpu_model']}, {m['cpus_usable']} CPUs, allanite at "
        f"{m['git_commit']} against the baseline `{base}`, {m['date_utc'][:16]} UTC. 1-minute load average "
        f"{load0[0]:.1f} at the start, {load1[0]:.1f} at the end (2 cores shared with other work"
        + (f"; other processes used {others:.0%} of the CPUs" if others is not None else "")
        + "). Each record refined with the default call in a fresh process, before and after alternating; "
        "CPU: the refine call's own process time (all its threads), wall: its elapsed time; the result compared field "
        "by field (effects, parameters, intervals, χ²/dof and errors of every step, what is still missing).",
        "",
        "| record | samples | CPU before (s) | CPU after (s) | CPU after per 10⁶ samples (s) | CPU ratio "
        "| wall before → after (s) | results |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        b, a = r["before"], r["after"]
        same = "identical" if not r["differences"] else _differing(r)
        lines.append(
            f"| {r['record']} | {a['samples']:,} | {b['cpu']:.1f} | {a['cpu']:.1f} | "
            f"{a['cpu'] / a['samples'] * 1e6:.1f} | {b['cpu'] / a['cpu']:.2f}× | "
            f"{b['seconds']:.1f} → {a['seconds']:.1f} | {same} |"
        )
    adis = [r for r in rows if r["record"].startswith("ADIS")]
    if adis:
        med = [statistics.median(r[w]["cpu"] / r[w]["samples"] * 1e6 for r in adis) for w in ("before", "after")]
        lines += ["", f"Median CPU per 10⁶ samples over the {len(adis)} ADIS rows: {med[0]:.1f} → {med[1]:.1f} s."]
    out.mkdir(parents=True, exist_ok=True)
    (out / "refine_cost.md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    sys.exit(main())
