#!/usr/bin/env python3
"""The whole pipeline at engine speed (issue 30): each row of the issue's table, before and after, as ratios
measured in one run.

Rows
1. ``allanite report <ADIS run 1> --fs 100 --columns gyro_x,gyro_y,gyro_z --unit deg/s`` in a fresh process
   (wall time, peak RSS), against the same run's baselines: reading the log alone (``read_log``), the engine
   calls inside the report (``avar`` + ``davar`` as the report makes them), and — with ``--baseline DIR``, a
   ``python/`` folder of an earlier checkout (e.g. main) holding its compiled core — the same command on it.
   Inside the report: its figures drawn one after another against two processes (the same PNG bytes).
2. ``fit(davar(...))`` of the ADIS run (3 axes × its windows), batched against the per-window reference
   (``fit_core`` on each window, what the fit did before).
3. ``allanite.combine(y, 100, window=401, hop=10)`` of 10⁶ simulated samples (10⁵ windows), against the
   per-window fits of the same windows (timed on a slice of them, per window) — and with ``--baseline``,
   the baseline's ``combine`` on a fifth of the record (per window).
4. ``fit(davar)`` of 10⁵ windows (window 401, hop 10), batched against the per-window fit (per window).
5. The hop-1 request ``--columns gyro_x --window 500000 --hop 1``: refused or answered, its wall time and
   peak RSS (the issue's "before": 593 s, 4.4 GB peak, 376 MB summary.json — not rerun here).
6. ``import allanite``: wall time of a fresh interpreter's import (median of 5), after and baseline, and
   the top of ``python -X importtime``.

7. ``allanite report <ADIS run 1> ... --refine``: its wall and CPU time against the refine calls alone (the
   report's own cost beyond them), and against the report without ``--refine`` — five rounds of the three
   (one with ``--quick``), medians, and each round's cost beyond both.
8. Scale (issue 30 item 4): ``allanite report`` of a 10⁸-sample × 3-axis float64 ``.npy`` (2.4 GB, written to
   ``--scratch`` and deleted after; memory-mapped by the reader) in a fresh process — wall, CPU, peak RSS
   (ru_maxrss of the process and its children, file pages included) against the target of the file's size
   + 1 GiB. ``--scale-samples`` for another length.

Not measured here (issue 30 item 5): DAVAR's hop-1 case against its write floor — ``benches/bench_davar_floor.py``.

``--rows report,scale`` reruns only those rows (names: import, report, refine, fit_adis, combine, hop1, scale)
and keeps the other rows of the ``pipeline.json`` already in ``--out``; the page says which rows were measured
when, at which load.

Usage::

    python benches/bench_pipeline.py --baseline /path/to/main/python   # -> benches/results/pipeline.{md,json}
    python benches/bench_pipeline.py --quick --out /tmp/p              # a few minutes: fewer windows, 1 repeat
    python benches/bench_pipeline.py --rows report,refine,scale --scratch /tmp   # these rows only

Timing lives here, never in a pass/fail test. The machine's load is noted at the start and the end.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import _common

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
ADIS = "adis16405/adis16405_run1_100Hz.csv.gz"
REPORT_ARGS = ["--fs", "100", "--columns", "gyro_x,gyro_y,gyro_z", "--unit", "deg/s", "--quiet"]
HOP1_ARGS = ["--fs", "100", "--columns", "gyro_x", "--unit", "deg/s", "--window", "500000", "--hop", "1", "--quiet"]
CONFIGS = {
    "full": {
        "repeats": 3,
        "n_combine": 1_000_000,
        "n_baseline_combine": 50_000,
        "ref_windows": 400,
        "import_repeats": 5,
        "refine_repeats": 5,
    },
    "quick": {
        "repeats": 1,
        "n_combine": 200_000,
        "n_baseline_combine": 20_000,
        "ref_windows": 100,
        "import_repeats": 3,
        "refine_repeats": 1,
    },
}


def cpu_timed(fn, repeats: int, warmup: bool = False):
    """(best wall s, CPU s of this process in that run, last result) of ``repeats`` runs of ``fn``."""
    if warmup:
        fn()
    best = (float("inf"), float("nan"))
    out = None
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        best = min(best, (time.perf_counter() - t0, time.process_time() - c0))
    return best[0], best[1], out


def _env(python_dir: Path | None) -> dict:
    env = dict(os.environ)
    if python_dir is not None:
        env["PYTHONPATH"] = str(python_dir)
    return env


def run_timed(cmd: list, env: dict, timeout: float) -> dict:
    """Wall time, exit status and peak RSS (the child's own ru_maxrss from wait4, file pages included;
    a child's children count where larger) of one command."""
    with tempfile.TemporaryFile() as fo, tempfile.TemporaryFile() as fe:
        t0 = time.perf_counter()
        p = subprocess.Popen(cmd, env=env, stdout=fo, stderr=fe)
        status = "timeout"
        while True:
            pid, code, ru = os.wait4(p.pid, os.WNOHANG)
            if pid:
                status = os.waitstatus_to_exitcode(code)
                break
            if time.perf_counter() - t0 > timeout:
                p.kill()
                _, _, ru = os.wait4(p.pid, 0)
                break
            time.sleep(0.01)
        wall = time.perf_counter() - t0
        p.returncode = -1 if status == "timeout" else status  # reaped here, not by Popen
        fo.seek(0)
        fe.seek(0)
        out, err = fo.read(), fe.read()
    return {
        "wall_s": wall,
        "status": status,
        "cpu_s": ru.ru_utime + ru.ru_stime,  # its own and its reaped children's (the figure process)
        "peak_rss_mb": ru.ru_maxrss / 1024,
        "stderr_tail": err.decode(errors="replace").strip().splitlines()[-2:],
        "stdout_tail": out.decode(errors="replace").strip().splitlines()[-1:],
    }


def _report_cmd(path: Path, out: Path, extra: list) -> list:
    return [sys.executable, "-m", "allanite", "report", str(path), *extra, "--out", str(out)]


#: The baseline's figures drawn one after another, CPU time of the best of ``repeats`` (run in a subprocess with
#: the baseline's ``python/``; a checkout before report/rendering.py draws them serially in ``render_figures``).
_FIGURES_BEFORE = """
import json, sys, time
import allanite
from allanite.report.build import from_log
log = allanite.read_log(sys.argv[1], fs=100, columns=["gyro_x", "gyro_y", "gyro_z"], unit="deg/s")
rep = from_log(log, progress=False)
try:
    from allanite.report.rendering import render_pngs
    def draw():
        return render_pngs(rep.figure_specs(), 100, lambda s: None, processes=1)
except ImportError:
    def draw():
        return rep.render_figures(progress=False)
draw()
best = min(
    (lambda c0: (draw(), time.process_time() - c0)[1])(time.process_time()) for _ in range(int(sys.argv[2]))
)
print(json.dumps({"figures_serial_cpu_s": best, "figures": len(rep.figure_specs())}))
"""


def figures_before(data: Path, baseline: Path, repeats: int) -> dict | None:
    """CPU seconds of the baseline's figures drawn one after another and how many they are (None when that run
    fails)."""
    p = subprocess.run(
        [sys.executable, "-c", _FIGURES_BEFORE, str(data), str(repeats)],
        env=_env(baseline),
        capture_output=True,
        text=True,
        timeout=900,
    )
    if p.returncode != 0:
        return None
    return json.loads(p.stdout.strip().splitlines()[-1])


def row_report(data: Path, cfg: dict, baseline: Path | None, tmp: Path) -> dict:
    row: dict = {"command": "allanite report <run1> " + " ".join(REPORT_ARGS)}
    for label, pdir in (("after", REPO / "python"), ("before", baseline)):
        if label == "before" and pdir is None:
            continue
        runs = [
            run_timed(_report_cmd(data, tmp / f"rep_{label}_{i}", REPORT_ARGS), _env(pdir), 900)
            for i in range(cfg["repeats"])
        ]
        best = min(runs, key=lambda r: r["wall_s"])
        row[label] = {"best_s": best["wall_s"], "cpu_s": best["cpu_s"], "runs_s": [r["wall_s"] for r in runs]}
        row[label]["status"] = runs[-1]["status"]
        row[label]["peak_rss_mb"] = max(r["peak_rss_mb"] for r in runs)
    # the same run's baselines, in-process: reading, the engine calls, the figures serial vs two processes
    import allanite
    from allanite.report.build import from_log
    from allanite.report.rendering import render_pngs

    best_read, _, log = _common.timed(
        lambda: allanite.read_log(data, fs=100, columns=["gyro_x", "gyro_y", "gyro_z"], unit="deg/s"), cfg["repeats"]
    )
    rep = from_log(log)
    dy = rep.dynamic
    best_engine, _, _ = _common.timed(
        lambda: (
            allanite.avar(log.data, 100.0, taus=rep.static.tau),
            allanite.davar(log.data, 100.0, window=dy.window, hop=dy.hop, taus=dy.tau),
        ),
        cfg["repeats"],
    )
    best_build, _, _ = _common.timed(lambda: from_log(log), cfg["repeats"])
    specs = rep.figure_specs()
    render_pngs(specs[:1], 100, lambda s: None, processes=1)  # matplotlib's set-up outside the timing
    best_serial, cpu_serial, serial = cpu_timed(
        lambda: render_pngs(specs, 100, lambda s: None, processes=1), cfg["repeats"]
    )
    best_two, _, two = _common.timed(lambda: render_pngs(specs, 100, lambda s: None, processes=2), cfg["repeats"])
    if baseline is not None:
        before = figures_before(data, baseline, cfg["repeats"])
        if before is not None:
            row["figures_before_serial_cpu_s"] = before["figures_serial_cpu_s"]
            row["figures_before"] = before["figures"]
    row.update(
        read_s=best_read,
        engine_s=best_engine,
        build_s=best_build,
        figures=len(specs),
        figures_serial_s=best_serial,
        figures_serial_cpu_s=cpu_serial,
        figures_two_processes_s=best_two,
        figures_identical=all(serial[k] == two[k] for k in serial),
    )
    return row


#: The refine calls the report makes, timed in a fresh process of their own (imports and first-call set-up
#: included, as in the report's process): [wall s, CPU s] of the calls alone.
_REFINE_CALLS = """
import json, sys, time
import numpy as np, allanite
log = allanite.read_log(sys.argv[1], fs=100, columns=["gyro_x", "gyro_y", "gyro_z"], unit="deg/s")
t0 = 0.1 if allanite.avar(log.data, 100.0).tau[0] < 0.1 else None  # as the report calls it (report/build.py)
w, c = time.perf_counter(), time.process_time()
for k in range(log.data.shape[1]):
    x = np.ascontiguousarray(log.data[:, k])
    allanite.refine(x, 100.0, unit="deg/s", tau_range=None if t0 is None else (t0, None))
print(json.dumps([time.perf_counter() - w, time.process_time() - c]))
"""


def _refine_calls(data: Path) -> tuple[float, float]:
    p = subprocess.run(
        [sys.executable, "-c", _REFINE_CALLS, str(data)],
        env=_env(REPO / "python"),
        capture_output=True,
        text=True,
        timeout=1800,
        check=True,
    )
    wall, cpu = json.loads(p.stdout.strip().splitlines()[-1])
    return wall, cpu


def row_refine(data: Path, cfg: dict, tmp: Path) -> dict:
    """The report with ``--refine`` against the refine calls it makes (:data:`_REFINE_CALLS`, a fresh process)
    and the plain report: ``cfg["refine_repeats"]`` rounds of the three, medians of each and of each round's
    differences."""
    import statistics

    runs = []
    for i in range(cfg["refine_repeats"]):
        plain = run_timed(_report_cmd(data, tmp / f"rep_plain_{i}", REPORT_ARGS), _env(REPO / "python"), 900)
        with_refine = run_timed(
            _report_cmd(data, tmp / f"rep_refine_{i}", REPORT_ARGS + ["--refine"]), _env(REPO / "python"), 1800
        )
        wall, cpu = _refine_calls(data)
        runs.append({"plain": plain, "refine": with_refine, "calls_wall_s": wall, "calls_cpu_s": cpu})
    med = statistics.median
    keys = ("wall_s", "cpu_s", "peak_rss_mb")
    return {
        "repeats": len(runs),
        "plain": {k: med(r["plain"][k] for r in runs) for k in keys} | {"status": runs[-1]["plain"]["status"]},
        "refine": {k: med(r["refine"][k] for r in runs) for k in keys} | {"status": runs[-1]["refine"]["status"]},
        "refine_calls_wall_s": med(r["calls_wall_s"] for r in runs),
        "refine_calls_cpu_s": med(r["calls_cpu_s"] for r in runs),
        "beyond_refine_wall_s": med(r["refine"]["wall_s"] - r["calls_wall_s"] for r in runs),
        "beyond_refine_cpu_s": med(r["refine"]["cpu_s"] - r["calls_cpu_s"] for r in runs),
        # each round's report with --refine less its refine calls and its plain report
        "beyond_both_cpu_runs_s": [r["refine"]["cpu_s"] - r["calls_cpu_s"] - r["plain"]["cpu_s"] for r in runs],
        "beyond_both_wall_runs_s": [r["refine"]["wall_s"] - r["calls_wall_s"] - r["plain"]["wall_s"] for r in runs],
    }


def _write_scale_record(path: Path, n: int) -> None:
    """A (n, 3) float64 .npy: white rate noise, a small rate random walk and a bias per axis, in 2^22-row slabs."""
    mm = np.lib.format.open_memmap(path, mode="w+", dtype=np.float64, shape=(n, 3))
    rng = np.random.default_rng(0)
    walk = np.zeros(3)
    step = 1 << 22
    for a in range(0, n, step):
        b = min(n, a + step)
        rw = np.cumsum(rng.normal(size=(b - a, 3)) * 1e-6, axis=0) + walk
        walk = rw[-1]
        mm[a:b] = 0.01 * rng.normal(size=(b - a, 3)) + rw + np.array([0.1, -0.2, 0.05])
    mm.flush()
    del mm


#: One read of a mapped .npy's whole file: axis 0's column read through the file (allanite._mapped).
_READ_ONCE = (
    "import sys, numpy as np; from allanite._mapped import column; column(np.load(sys.argv[1], mmap_mode='r'), 0)"
)


def _scale_report_cmd(path: Path, out: Path) -> list:
    return [sys.executable, "-m", "allanite", "report", str(path), "--fs", "100", "--unit", "deg/s", "--out", str(out)]


def row_scale(n: int, scratch: Path, tmp: Path, baseline: Path | None = None) -> dict:
    """``allanite report`` of an (n, 3) float64 .npy in a fresh process: wall, CPU, peak RSS against the target;
    with ``baseline``, the baseline checkout's report of the same file in the same run."""
    path = scratch / f"allanite_scale_{os.getpid()}.npy"
    before = None
    try:
        _write_scale_record(path, n)
        size = path.stat().st_size
        out = tmp / "scale"
        r = run_timed(_scale_report_cmd(path, out), _env(REPO / "python"), 3600)
        if baseline is not None:
            b = run_timed(_scale_report_cmd(path, tmp / "scale_before"), _env(baseline), 3600)
            before = {k: b[k] for k in ("wall_s", "cpu_s", "peak_rss_mb", "status")}
        # the same run's reference: one read of the whole file (one axis's column through the file, as the
        # report reads each axis), in a fresh process
        read_once = run_timed([sys.executable, "-c", _READ_ONCE, str(path)], _env(REPO / "python"), 900)
    finally:
        path.unlink(missing_ok=True)
    summ = out / "summary.json"
    record = json.loads(summ.read_text())["record"] if summ.exists() else {}
    return {
        "samples": n,
        "axes": 3,
        "file_gb": size / 1e9,
        "status": r["status"],
        "wall_s": r["wall_s"],
        "cpu_s": r["cpu_s"],
        "peak_rss_mb": r["peak_rss_mb"],
        "target_rss_mb": (size + 2**30) / 2**20,
        "read_once_wall_s": read_once["wall_s"],
        "read_once_cpu_s": read_once["cpu_s"],
        "by_axis": record.get("analysed_axis_by_axis"),
        "memory_estimate_mb": (record.get("memory_estimate_bytes") or 0) / 2**20,
        "log_tail": r["stderr_tail"],
        "before": before,
    }


def _per_window_reference(result, rows_avar, k_windows: int):
    """Seconds per window of the per-window fit (``fit_core`` on each), on ``k_windows`` windows spread over
    one axis (``rows_avar``, τ × windows) of ``result``, at the τ the fit selects."""
    from allanite.model import _dynamicfit, _tauselect, fitting

    idx = _tauselect.select_taus(
        result.tau, fitting.row_medians(rows_avar), True, len(fitting.TERMS), "x", (0.0, np.inf)
    )
    cols = _common.sample_starts(rows_avar.shape[1], min(k_windows, rows_avar.shape[1]))
    y = np.ascontiguousarray(rows_avar[idx][:, cols].T)
    t0, c0 = time.perf_counter(), time.process_time()
    _dynamicfit.window_fits_reference(result, idx, y, fitting.TERMS, 0.683, 50)
    return (time.perf_counter() - t0) / y.shape[0], (time.process_time() - c0) / y.shape[0]


def row_fit_adis(data: Path, cfg: dict) -> dict:
    import allanite

    log = allanite.read_log(data, fs=100, columns=["gyro_x", "gyro_y", "gyro_z"], unit="deg/s")
    from allanite.report.build import from_log

    dy = from_log(log, fit=False).dynamic
    best, cpu, _ = cpu_timed(lambda: allanite.fit(dy, unit="deg/s"), cfg["repeats"], warmup=True)
    n_win = dy.t.size * dy.avar.shape[0]
    refs = [_per_window_reference(dy, dy.avar[k], dy.t.size) for k in range(dy.avar.shape[0])]
    per_ref, per_ref_cpu = float(np.mean([r[0] for r in refs])), float(np.mean([r[1] for r in refs]))
    return {
        "call": f"fit(davar(ADIS run 1)) — {dy.avar.shape[0]} axes × {dy.t.size} windows",
        "batched_s": best,
        "batched_us_per_window": best / n_win * 1e6,
        "batched_cpu_us_per_window": cpu / n_win * 1e6,
        "per_window_ref_us": per_ref * 1e6,
        "per_window_ref_cpu_us": per_ref_cpu * 1e6,
        "per_window_ref_total_s": per_ref * n_win,
        "ratio": per_ref * n_win / best,
        "cpu_ratio": per_ref_cpu * n_win / cpu,
    }


def row_combine_and_fit(cfg: dict, baseline: Path | None) -> tuple[dict, dict]:
    import allanite

    n = cfg["n_combine"]
    y = allanite.simulate(n, 100.0, Q=1e-4, N=0.01, B=1e-3, K=1e-4, seed=30)
    best_c, cpu_c, comb = cpu_timed(lambda: allanite.combine(y, 100.0, window=401, hop=10), 1)
    res = allanite.davar(y, 100.0, window=401, hop=10)
    best_d, _, _ = _common.timed(lambda: allanite.davar(y, 100.0, window=401, hop=10), cfg["repeats"])
    best_f, cpu_f, _ = cpu_timed(lambda: allanite.fit(res), cfg["repeats"], warmup=True)
    per_ref, per_ref_cpu = _per_window_reference(res, res.avar, cfg["ref_windows"])
    w = res.t.size
    comb_row = {
        "call": f"combine(y, 100, window=401, hop=10), {n:,} samples, {w:,} windows",
        "after_s": best_c,
        "after_cpu_s": cpu_c,
        "per_window_fits_estimate_s": per_ref * w,
        "ratio_vs_per_window_fits": per_ref * w / best_c,
    }
    if baseline is not None:
        n_b = cfg["n_baseline_combine"]
        code = (
            f"import time, allanite; y = allanite.simulate({n_b}, 100.0, Q=1e-4, N=0.01, B=1e-3, K=1e-4, seed=30); "
            "t = time.perf_counter(); c = allanite.combine(y, 100.0, window=401, hop=10); "
            "print(time.perf_counter() - t)"
        )
        r = run_timed([sys.executable, "-c", code], _env(baseline), 1800)
        try:
            t_b = float(r["stdout_tail"][0].split()[0])
            w_b = (n_b - 401) // 10 + 1
            comb_row.update(
                baseline_samples=n_b,
                baseline_s=t_b,
                baseline_us_per_window=t_b / w_b * 1e6,
                after_us_per_window=best_c / w * 1e6,
                ratio_vs_baseline_per_window=(t_b / w_b) / (best_c / w),
            )
        except (IndexError, ValueError):
            comb_row["baseline_error"] = r["stderr_tail"]
    fit_row = {
        "call": f"fit(davar(y, window=401, hop=10)), {w:,} windows",
        "davar_s": best_d,
        "batched_s": best_f,
        "batched_us_per_window": best_f / w * 1e6,
        "batched_cpu_us_per_window": cpu_f / w * 1e6,
        "per_window_ref_us": per_ref * 1e6,
        "per_window_ref_cpu_us": per_ref_cpu * 1e6,
        "per_window_ref_total_s": per_ref * w,
        "ratio": per_ref * w / best_f,
        "cpu_ratio": per_ref_cpu * w / cpu_f,
    }
    del comb
    return comb_row, fit_row


def row_hop1(data: Path, tmp: Path) -> dict:
    r = run_timed(_report_cmd(data, tmp / "hop1", HOP1_ARGS), _env(REPO / "python"), 900)
    side = sorted(p.name for p in (tmp / "hop1").glob("*")) if (tmp / "hop1").is_dir() else []
    summ = tmp / "hop1" / "summary.json"
    return {
        "command": "allanite report <run1> " + " ".join(HOP1_ARGS),
        "status": r["status"],
        "answer": "refused" if r["status"] not in (0, "timeout") else ("answered" if r["status"] == 0 else "timeout"),
        "wall_s": r["wall_s"],
        "peak_rss_mb": r["peak_rss_mb"],
        "summary_json_mb": summ.stat().st_size / 2**20 if summ.exists() else None,
        "files": side,
        "message": r["stderr_tail"],
        "before_from_issue": {"wall_s": 593, "peak_gb": 4.4, "summary_json_mb": 376},
    }


def row_import(cfg: dict, baseline: Path | None) -> dict:
    code = "import time; t = time.perf_counter(); import allanite; print(time.perf_counter() - t)"
    out = {}
    for label, pdir in (("after", REPO / "python"), ("before", baseline)):
        if pdir is None:
            continue
        ts = []
        for _ in range(cfg["import_repeats"]):
            p = subprocess.run([sys.executable, "-c", code], env=_env(pdir), capture_output=True, text=True)
            ts.append(float(p.stdout.strip()))
        p = subprocess.run(
            [sys.executable, "-X", "importtime", "-c", "import allanite"],
            env=_env(pdir),
            capture_output=True,
            text=True,
        )
        rows = [ln.split("|") for ln in p.stderr.splitlines() if ln.startswith("import time:") and "|" in ln]
        cum = sorted(((int(r[1]), r[2].strip()) for r in rows if r[1].strip().isdigit()), reverse=True)
        heavy = [
            n
            for n in ("scipy.stats", "scipy.signal", "scipy.optimize", "scipy.special", "matplotlib")
            if any(name == n for _, name in cum)
        ]
        out[label] = {
            "median_s": float(np.median(ts)),
            "runs_s": ts,
            "heavy_modules_imported": heavy,
            "top_cumulative_us": cum[:6],
        }
    if "before" in out:
        out["ratio"] = out["before"]["median_s"] / out["after"]["median_s"]
    return out


def parallel_capacity() -> dict:
    """Wall time of two forked processes spinning against one: how many cores the run really had."""
    import math

    def spin():
        x = 0.0
        for i in range(4_000_000):
            x += math.sqrt(i)
        return x

    t0 = time.perf_counter()
    spin()
    one = time.perf_counter() - t0
    t0 = time.perf_counter()
    pid = os.fork()
    if pid == 0:
        spin()
        os._exit(0)
    spin()
    os.waitpid(pid, 0)
    two = time.perf_counter() - t0
    return {"one_s": one, "two_s": two, "two_over_one": two / one}


def load_note() -> dict:
    return {"loadavg": Path("/proc/loadavg").read_text().split()[:3], "cpu_busy": _common.cpu_busy_fraction()}


def _beyond_both(rf: dict) -> str:
    """The refine row's cost beyond the refine calls and the plain report: the median of each round's (and the
    rounds) where the row has rounds, else the difference of its single run."""
    import statistics

    if "beyond_both_cpu_runs_s" not in rf:  # a row recorded before the rounds
        wall = rf["beyond_refine_wall_s"] - rf["plain"]["wall_s"]
        return f"{wall:.2f} s (CPU {rf['beyond_refine_cpu_s'] - rf['plain']['cpu_s']:.2f} s)"
    cpu, wall = rf["beyond_both_cpu_runs_s"], rf["beyond_both_wall_runs_s"]
    runs = ", ".join(f"{c:.2f}" for c in cpu)
    return (
        f"median of {len(cpu)} rounds {statistics.median(wall):.2f} s (CPU {statistics.median(cpu):.2f} s; "
        f"each round's CPU: {runs} s)"
    )


def write_md(res: dict, path: Path) -> None:
    r, L = res["rows"], []
    L.append("# Pipeline benchmark (issue 30): the report and the per-window fits at engine speed\n")
    L.append(
        f"`python benches/bench_pipeline.py{' --quick' if res['quick'] else ''}` — {res['date']}, "
        f"{res['machine'].get('cpu_model', '')}, {res['machine'].get('cpu_count', '')} CPUs shared with other workers; "
        f"branch commit {res['commit']}. Cores this run could use: two spinning processes took "
        f"{res['parallel_capacity']['two_over_one']:.2f}× one's time (1.0 = two idle cores, 2.0 = one). "
    )
    L.append(
        f"Load at start: {res['load_start']}; at end: {res['load_end']}. Baseline: {res['baseline'] or 'none given'}.\n"
    )
    L.append("| row | before | after | ratio | same run's reference |")
    L.append("|---|---|---|---|---|")
    L += _md_report_rows(r["report"])
    L += [_md_fit_adis(r["fit_adis"]), _md_combine(r["combine"]), _md_fit_many(r["fit_many"]), _md_hop1(r["hop1"])]
    if r.get("refine"):
        L.append(_md_refine(r["refine"]))
    if r.get("scale"):
        L.append(_md_scale(r["scale"]))
    L.append(_md_import(r["import"]))
    L += _md_notes(res)
    path.write_text("\n".join(L) + "\n", encoding="utf-8")


def _md_report_rows(rep: dict) -> list[str]:
    """The ADIS report's rows: its wall and CPU time, its figures in one and two processes, against a baseline."""
    L = []
    b = rep.get("before", {}).get("best_s")
    bc = rep.get("before", {}).get("cpu_s")
    a, ac = rep["after"]["best_s"], rep["after"]["cpu_s"]
    L.append(
        f"| ADIS report (3 axes, fresh process) | {f'{b:.2f} s (CPU {bc:.2f} s)' if b else '— (no baseline run)'} | "
        f"{a:.2f} s (CPU {ac:.2f} s) | {f'{b / a:.2f}× (CPU {bc / ac:.2f}×)' if b else '—'} | "
        f"read {rep['read_s']:.2f} s, engine (avar+davar) {rep['engine_s']:.3f} s, build {rep['build_s']:.2f} s |"
    )
    fcpu = rep.get("figures_serial_cpu_s")
    L.append(
        f"| its {rep['figures']} figures | serial {rep['figures_serial_s']:.2f} s"
        + (f" (CPU {fcpu:.2f} s)" if fcpu is not None else "")
        + " | two processes "
        f"{rep['figures_two_processes_s']:.2f} s | {rep['figures_serial_s'] / rep['figures_two_processes_s']:.2f}× | "
        f"PNG bytes identical: {rep['figures_identical']} |"
    )
    fb = rep.get("figures_before_serial_cpu_s")
    if fb and fcpu:
        nb = rep.get("figures_before")
        L.append(
            f"| its figures drawn one after another (CPU) | baseline {fb:.2f} s"
            + (f" ({nb} figures)" if nb else "")
            + f" | {fcpu:.2f} s ({rep['figures']} figures: per-axis figures merged, fewer artists) | {fb / fcpu:.2f}× "
            "| the same report, this run |"
        )
    return L


def _md_fit_adis(f: dict) -> str:
    return (
        f"| {f['call']} | per-window {f['per_window_ref_total_s']:.2f} s ({f['per_window_ref_us']:.0f} µs/window) | "
        f"{f['batched_s']:.3f} s ({f['batched_us_per_window']:.1f} µs/window; CPU {f['batched_cpu_us_per_window']:.1f} µs) | {f['ratio']:.0f}× | |"
    )


def _md_combine(c: dict) -> str:
    bl = (
        (
            f"baseline {c['baseline_s']:.1f} s on {c['baseline_samples']:,} samples = {c['baseline_us_per_window']:.0f} µs/window; "
            f"{c['ratio_vs_baseline_per_window']:.0f}× per window"
        )
        if "baseline_s" in c
        else "no baseline run"
    )
    return (
        f"| {c['call']} | per-window fits alone ≈ {c['per_window_fits_estimate_s']:.1f} s | {c['after_s']:.2f} s "
        f"(CPU {c['after_cpu_s']:.2f} s) | "
        f"{c['ratio_vs_per_window_fits']:.0f}× | {bl} |"
    )


def _md_fit_many(g: dict) -> str:
    return (
        f"| {g['call']} | per-window ≈ {g['per_window_ref_total_s']:.1f} s ({g['per_window_ref_us']:.0f} µs/window) | "
        f"{g['batched_s']:.2f} s ({g['batched_us_per_window']:.1f} µs/window; CPU {g['batched_cpu_us_per_window']:.1f} µs) | "
        f"{g['ratio']:.0f}× (CPU {g['cpu_ratio']:.0f}×) | per-window CPU {g['per_window_ref_cpu_us']:.0f} µs; davar {g['davar_s']:.2f} s |"
    )


def _md_hop1(h: dict) -> str:
    return (
        f"| hop-1 `--window 500000 --hop 1` | 593 s, 4.4 GB, 376 MB JSON (issue; not rerun) | {h['answer']} in "
        f"{h['wall_s']:.1f} s, peak RSS {h['peak_rss_mb']:.0f} MB"
        + (f", summary.json {h['summary_json_mb']:.2f} MB" if h["summary_json_mb"] is not None else "")
        + f" | {593 / h['wall_s']:.0f}× | files: {', '.join(h['files'])} |"
    )


def _md_refine(rf: dict) -> str:
    return (
        f"| ADIS report `--refine` (fresh process) | without: {rf['plain']['wall_s']:.2f} s (CPU "
        f"{rf['plain']['cpu_s']:.2f} s) | {rf['refine']['wall_s']:.2f} s (CPU {rf['refine']['cpu_s']:.2f} s) | "
        f"beyond the refine calls: {rf['beyond_refine_wall_s']:.2f} s (CPU {rf['beyond_refine_cpu_s']:.2f} s); "
        f"beyond them and the plain report: {_beyond_both(rf)} | "
        f"the refine calls alone {rf['refine_calls_wall_s']:.2f} s (CPU {rf['refine_calls_cpu_s']:.2f} s) |"
    )


def _md_scale(sc: dict) -> str:
    return (
        f"| scale: `allanite report` of a {sc['samples']:.0e} × {sc['axes']} float64 .npy ({sc['file_gb']:.1f} GB, "
        f"memory-mapped) | "
        + (
            f"same run, the baseline: {sb['wall_s']:.0f} s (CPU {sb['cpu_s']:.0f} s), peak RSS "
            f"{sb['peak_rss_mb']:.0f} MB — CPU {sb['cpu_s'] / max(sc['cpu_s'], 1e-9):.2f}× the report's | "
            if (sb := sc.get("before"))
            else "before the chunked-phase core (27f2226, load 19): 779 s (CPU 152 s), peak RSS 2578 MB; "
            "before the by-axis report: every axis copied at once (10⁷ × 3: peak RSS 997 MB) | "
        )
        + f"{'done' if sc['status'] == 0 else sc['status']} in {sc['wall_s']:.0f} s (CPU {sc['cpu_s']:.0f} s), "
        f"peak RSS {sc['peak_rss_mb']:.0f} MB | target ≤ 60 s, RSS ≤ {sc['target_rss_mb']:.0f} MB; "
        + (
            f"same run, one read of the file: {sc['read_once_wall_s']:.1f} s (CPU {sc['read_once_cpu_s']:.1f} s) — "
            f"the report {sc['cpu_s'] / max(sc['read_once_cpu_s'], 1e-9):.0f}× its CPU | "
            if "read_once_cpu_s" in sc
            else "| "
        )
        + f"axis by axis: {sc['by_axis']}; the report's estimate {sc['memory_estimate_mb']:.0f} MB |"
    )


def _md_import(im: dict) -> str:
    ib = im.get("before", {}).get("median_s")
    heavy_b = ", ".join(im.get("before", {}).get("heavy_modules_imported", []))
    heavy_a = ", ".join(im["after"]["heavy_modules_imported"]) or "no scipy/matplotlib"
    ratio = im.get("ratio")
    return (
        f"| `import allanite` (median) | {f'{ib:.2f} s ({heavy_b})' if ib else '— (no baseline run)'} | "
        f"{im['after']['median_s']:.2f} s ({heavy_a}) | {f'{ratio:.2f}×' if ratio else '—'} | |"
    )


def _md_notes(res: dict) -> list[str]:
    """Below the table: how the times were taken, the rows measured in other runs, what is measured elsewhere."""
    L = [""]
    L.append(
        "Wall times are the best of the repeats on a machine shared with other workers (its load above); CPU "
        "times (this process's, and a report's figure process's) are less sensitive to that load. "
    )
    L.append(
        "Per-window reference: `fit_core` on each window in turn (today's reference path, what `fit(dynamic)` "
        "did before the batched core), timed on windows spread over the record, per window × the number of windows."
    )
    L.append("")
    stamps = res.get("row_runs", {})
    if stamps:
        L.append("")
        L.append("Rows measured in other runs than the header's (`--rows`), with that run's load:")
        L.append("")
        for name, st in stamps.items():
            L.append(
                f"- {name}: {st['date']}, commit {st['commit']}, load {st['load']['loadavg']} "
                f"(busy {st['load']['cpu_busy']:.2f})" + (" — `--quick`: one repeat" if st.get("quick") else "")
            )
    L.append("")
    L.append(
        "Not measured here (issue 30 item 5): DAVAR's hop-1 case against its write floor — "
        "benches/bench_davar_floor.py, results in davar_floor.md (case 1's old target in engine.md is retired)."
    )
    return L


ROWS = ("import", "report", "refine", "fit_adis", "combine", "hop1", "scale")


def _commit() -> str:
    return subprocess.run(
        ["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"], capture_output=True, text=True
    ).stdout.strip()


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer windows and one repeat: a few minutes")
    ap.add_argument("--baseline", type=Path, default=None, help="python/ folder of the checkout to compare with")
    ap.add_argument("--out", type=Path, default=HERE / "results", help="folder for pipeline.md and pipeline.json")
    ap.add_argument("--rows", default=None, help=f"comma-separated rows to rerun ({', '.join(ROWS)}); default all")
    ap.add_argument(
        "--scratch", type=Path, default=None, help="folder for the scale row's record (default: a temp dir)"
    )
    ap.add_argument("--scale-samples", type=int, default=100_000_000, help="samples of the scale row's record")
    args = ap.parse_args()
    rows = ROWS if args.rows is None else tuple(r.strip() for r in args.rows.split(","))
    unknown = sorted(set(rows) - set(ROWS))
    if unknown:
        ap.error(f"unknown rows {unknown}; rows are {', '.join(ROWS)}")
    cfg = CONFIGS["quick" if args.quick else "full"]
    data = _common.shared_data_dir() / ADIS
    if not data.exists():
        print(f"the ADIS16405 log {data} is absent (set ALLANITE_SHARED_DATA): nothing to measure", file=sys.stderr)
        return 2
    res = {
        "quick": args.quick,
        "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
        "machine": _common.machine_info(),
        "baseline": str(args.baseline) if args.baseline else None,
        "load_start": load_note(),
        "commit": _commit(),
        "parallel_capacity": parallel_capacity(),
        "rows": {},
    }
    previous = args.out / "pipeline.json"
    if args.rows is not None and not previous.exists():
        ap.error(f"--rows keeps the other rows of {previous}, which does not exist: run every row first")
    if args.rows is not None and previous.exists():  # keep the rows not rerun, and when they were measured
        old = json.loads(previous.read_text(encoding="utf-8"))
        stamp = {k: old[k] for k in ("date", "commit")} | {"load": old["load_start"]}
        res["rows"] = old["rows"]
        res["row_runs"] = old.get("row_runs", {})
        for name in old["rows"]:
            res["row_runs"].setdefault(name, stamp)
        for k in ("date", "commit", "load_start", "parallel_capacity", "quick", "baseline", "machine"):
            res[k] = old.get(k, res[k])
        res["load_end"] = old.get("load_end")
    with tempfile.TemporaryDirectory() as tmp:
        t = Path(tmp)
        for name in rows:
            _common.log(name)
            if name == "import":
                res["rows"]["import"] = row_import(cfg, args.baseline)
            elif name == "report":
                res["rows"]["report"] = row_report(data, cfg, args.baseline, t)
            elif name == "refine":
                res["rows"]["refine"] = row_refine(data, cfg, t)
            elif name == "fit_adis":
                res["rows"]["fit_adis"] = row_fit_adis(data, cfg)
            elif name == "combine":
                res["rows"]["combine"], res["rows"]["fit_many"] = row_combine_and_fit(cfg, args.baseline)
            elif name == "hop1":
                res["rows"]["hop1"] = row_hop1(data, t)
            elif name == "scale":
                res["rows"]["scale"] = row_scale(args.scale_samples, args.scratch or t, t, args.baseline)
            if args.rows is not None:
                now = {
                    "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
                    "commit": _commit(),
                    "load": load_note(),
                    "quick": args.quick,
                }
                for key in ("combine", "fit_many") if name == "combine" else (name,):
                    res.setdefault("row_runs", {})[key] = now
    if args.rows is None:
        res["load_end"] = load_note()
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "pipeline.json").write_text(json.dumps(res, indent=1, default=str), encoding="utf-8")
    write_md(res, args.out / "pipeline.md")
    print((args.out / "pipeline.md").read_text())
    return 0


if __name__ == "__main__":
    sys.exit(main())
