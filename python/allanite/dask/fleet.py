"""Fleets of logs on Dask: one ``allanite report`` per file, then a fleet summary.

``allanite batch 'logs/**/*.csv.gz' --fs 100 --out results/`` (and :func:`batch`) reads every file
that matches, builds its report (:func:`allanite.report.from_log`, what ``allanite report`` writes) as a
Dask task — a LocalCluster by default, any scheduler given by its address — and writes

* ``out/<path relative to the glob's root, extensions stripped>/`` — the file's report (and, for an IMU log's
  accelerometer columns beside the gyro's, their report in its ``accelerometer/``, as ``allanite report`` writes);
* ``out/fleet.csv`` (and ``fleet.parquet`` when pyarrow is installed) — one row per file and axis (``sensor``
  gyro or accelerometer): the fitted N, B, K with their intervals (IEEE-952 units; an accelerometer's —
  ``unit="g"``, or names such as ``ax [g]`` — in m/s/√h, µg, m/s/h^1.5; without a unit, the base form,
  ``N_unit`` "base form"), the effects ``refine`` found and what the refined model still misses
  (``still_missing``), robust z-scores of N, B, K against the fleet's rows in the same unit and a flag when one
  is beyond :data:`Z_FLAG`, or the file's error;
* ``out/fleet.html`` — the fleet's distributions, one row of histograms per unit (a gyro's, an accelerometer's).

Reliability: a file that fails (malformed, gaps, …) becomes a row with its error and does not stop the
others; a report is written into a temporary folder and renamed into place, so a worker killed
mid-write leaves nothing half-written (Dask retries the task); ``resume=True`` skips files whose report
is complete and newer than the file.
"""

from __future__ import annotations

import argparse
import glob
import json
import math
import os
import shutil
import sys
import time
import uuid
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._cli_options import UsageError
from .._validate import input_word
from ..errors import AllaniteError, ParameterError
from ..io import read_log
from ..io.reader import check_time_unit_used
from ..report import from_log
from ..units import ACCEL_UNITS, accel_unit_name
from ._fleet_pages import TERMS, Z_FLAG, write_html, write_table

__all__ = ["batch", "FleetResult", "main", "Z_FLAG", "TERMS"]

_EXTENSIONS = {".gz", ".bz2", ".xz", ".zst", ".csv", ".tsv", ".txt", ".dat", ".npy", ".npz", ".parquet", ".bag"}


@dataclass
class FleetResult:
    """What :func:`batch` did: ``rows`` (the fleet table, one dict per file and axis), ``files`` (one
    status dict per input: path, out, status ok/skipped/error, error) and the paths written."""

    rows: list
    files: list
    paths: dict = field(default_factory=dict)

    @property
    def failed(self) -> list:
        """The files whose report failed, each with its error (a failing file stops nothing)."""
        return [f for f in self.files if f["status"] == "error"]


def glob_root(pattern: str) -> Path:
    """The folder of the pattern before its first wildcard component: outputs are named relative to it."""
    parts = Path(pattern).parts
    fixed = []
    for p in parts[:-1]:
        if glob.has_magic(p):
            break
        fixed.append(p)
    return Path(*fixed) if fixed else Path(".")


def out_folder(path: Path, root: Path, out: Path) -> Path:
    """``out/<path relative to root, extensions stripped>`` (``a/b.csv.gz`` → ``out/a/b``)."""
    rel = path.relative_to(root)
    name = rel.name
    while Path(name).suffix.lower() in _EXTENSIONS:
        name = name[: -len(Path(name).suffix)]
    return out / rel.parent / name


def _complete(folder: Path, source: Path) -> bool:
    need = [folder / "summary.json", folder / "report.html"]
    return all(p.is_file() for p in need) and min(p.stat().st_mtime for p in need) >= source.stat().st_mtime


def run_one(path: str, folder: str, read_opts: dict, report_opts: dict, accel_unit=None) -> dict:
    """One file: read it, build its report — and, as ``allanite report`` does, a report of its own for the
    accelerometer's columns beside a gyro's (:func:`allanite._cli_columns.sensor_columns`: where their names give
    its unit, or ``accel_unit`` names it and their names tell them from the gyro's), in ``folder/accelerometer/`` —
    write them atomically; never raises for a bad file."""
    src, dst = Path(path), Path(folder)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            reports = _reports(read_log(src, **read_opts), "columns" not in read_opts, report_opts, accel_unit)
            _write_atomically(reports, dst)
        return {"path": path, "out": folder, "status": "ok", "error": None}
    except (AllaniteError, OSError, ValueError, UsageError) as exc:
        return {"path": path, "out": folder, "status": "error", "error": f"{type(exc).__name__}: {exc}"}


def _reports(log, choose: bool, report_opts: dict, accel_unit) -> dict:
    """The reports of one log by the folder they go in ("" the log's, ``ACCEL_FOLDER`` its accelerometer's): the
    columns chosen as ``allanite report`` chooses them without --columns (``choose``)."""
    from .._cli_columns import ACCEL_FOLDER, given_accel_unit, is_accel_name, sensor_columns

    notes, accel = [], None
    if choose:  # as allanite report: the gyro's columns, and the accelerometer's in a report of their own
        log, accel, note = sensor_columns(log, accel_unit)
        notes += [note] if note else []
    if report_opts.get("unit") is not None:  # an accelerometer's (batch): the log's names give no gyro's
        given_accel_unit(report_opts["unit"], log)
    elif (
        accel is None and accel_unit is not None and log.unit is None and all(map(is_accel_name, map(str, log.columns)))
    ):
        report_opts = dict(report_opts, unit=accel_unit)  # an accelerometer's log (ax, ay, az): in --accel-unit
    rep = from_log(log, notes=notes, **report_opts)
    if accel is None:
        return {"": rep}
    opts = {k: v for k, v in report_opts.items() if k != "unit"}  # its unit: accel_unit, else its names'
    arep = from_log(accel, notes=[], **(opts if accel_unit is None else dict(opts, unit=accel_unit)))
    rep.source["accelerometer_report"] = f"{ACCEL_FOLDER}/report.html"  # each page links the other
    arep.source["gyro_report"] = "../report.html"
    return {"": rep, ACCEL_FOLDER: arep}


def _write_atomically(reports: dict, dst: Path) -> None:
    """The reports (folder inside ``dst`` → report) written into a temporary folder renamed to ``dst``: a worker
    killed mid-write leaves no half-written report."""
    dst.parent.mkdir(parents=True, exist_ok=True)
    tmp = dst.parent / f".{dst.name}.tmp-{uuid.uuid4().hex[:8]}"
    try:
        for sub, rep in reports.items():
            rep.write(tmp / sub if sub else tmp)
        if dst.exists():
            old = dst.parent / f".{dst.name}.old-{uuid.uuid4().hex[:8]}"
            os.rename(dst, old)
            os.rename(tmp, dst)
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.rename(tmp, dst)
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)


def _rows(status: dict) -> list:
    """Fleet rows of one file, from its summary.json (the same for a fresh and a resumed report) and, where it
    names one, its accelerometer's report's (the rows' ``out`` that report's folder, ``sensor`` accelerometer)."""
    base = {"file": status["path"], "out": status["out"], "status": status["status"], "error": status["error"]}
    if status["status"] == "error":
        return [dict(base, axis=None)]
    summary = json.loads((Path(status["out"]) / "summary.json").read_text(encoding="utf-8"))
    rows = _axis_rows(summary, base)
    beside = (summary["record"].get("source") or {}).get("accelerometer_report")
    if beside:
        folder = Path(status["out"]) / Path(beside).parent
        accel = json.loads((folder / "summary.json").read_text(encoding="utf-8"))
        rows += _axis_rows(accel, dict(base, out=str(folder)))
    return rows


def _axis_rows(summary: dict, base: dict) -> list:
    """One fleet row per axis of a report's summary.json: N, B, K with their intervals and units, the effects
    refine kept and what it still misses."""
    fit = summary.get("fit") or {}
    ref = summary.get("refinement") or {}
    ref_axes = {a["axis"]: a for a in (ref.get("axes") or [])}
    sensor = "accelerometer" if summary["record"].get("accel_unit") else "gyro"
    rows = []
    for ax in fit.get("axes") or [{"axis": k, "name": str(k)} for k in range(int(summary["record"]["axes"]))]:
        row = dict(base, axis=ax.get("name"), sensor=sensor)
        coefs = ax.get("coefficients") or {}
        for t in TERMS:
            c = coefs.get(t) or {}
            # IEEE-952 units; without a unit (none given) the base form — before, an empty row
            ieee = c.get("ieee") is not None
            row[t] = c.get("ieee") if ieee else c.get("value")
            ci = c.get("ieee_ci") if ieee else c.get("ci")
            row[f"{t}_low"], row[f"{t}_high"] = (None, None) if ci is None else (ci[0], ci[1])
            row[f"{t}_unit"] = c.get("ieee_unit") if ieee else (c.get("unit") or "base form") if c else None
        ref_ax = ref_axes.get(ax.get("axis"), {})
        row["effects"] = ";".join(s["effect"] for s in ref_ax.get("steps") or []) if ref else None
        row["still_missing"] = _still_missing(ref_ax) if ref else None
        rows.append(row)
    return rows


def _still_missing(ref_ax: dict) -> str | None:
    """What the refined model of an axis still misses (summary.json's ``unexplained``, each entry's words,
    "; "-joined), "none" when it passes every calibrated check; None for an axis that was not refined."""
    if "unexplained" not in ref_ax:
        return None
    return "; ".join(u["text"] for u in ref_ax["unexplained"]) or "none"


def robust_z(values) -> np.ndarray:
    """0.6745·(v − median)/MAD (Iglewicz & Hoaglin); NaN where v is missing or MAD is 0."""
    v = np.array([np.nan if x is None else float(x) for x in values])
    ok = np.isfinite(v)
    z = np.full(v.shape, np.nan)
    if ok.sum() >= 3:
        med = np.median(v[ok])
        mad = np.median(np.abs(v[ok] - med))
        if mad > 0:
            z[ok] = 0.6745 * (v[ok] - med) / mad
    return z


def _flag(rows: list) -> None:
    ok = [r for r in rows if r["status"] != "error"]
    for t in TERMS:
        # against the rows in the same unit only: °/√h and a base form (no unit given) do not compare
        for unit in {r.get(f"{t}_unit") for r in ok}:
            same = [r for r in ok if r.get(f"{t}_unit") == unit]
            # log10: N, B, K spread over decades; a sensor 10× off is as far as one 10× better
            z = robust_z([None if (r.get(t) is None or r[t] <= 0) else math.log10(r[t]) for r in same])
            for r, zi in zip(same, z):
                r[f"z_{t}"] = None if not np.isfinite(zi) else round(float(zi), 3)
    for r in rows:
        out = [t for t in TERMS if r.get(f"z_{t}") is not None and abs(r[f"z_{t}"]) > Z_FLAG]
        r["flag"] = ",".join(out) if out else ""


def batch(
    pattern: str,
    *,
    out,
    fs=None,
    columns=None,
    time_column=None,
    unit=None,
    accel_unit=None,
    input: str = "rate",
    gaps: str = "error",
    channels="auto",
    time_unit=None,
    window=None,
    hop=None,
    taus="octave",
    estimator: str = "oavar",
    refine: bool = False,
    fit: bool = True,
    scheduler: str | None = None,
    dask_workers: int | None = None,
    client=None,
    resume: bool = False,
    quiet: bool = True,
    retries: int = 2,
) -> FleetResult:
    """Reports for every file matching ``pattern`` (``**`` recursive), as Dask tasks, and the fleet summary.

    Parameters
    ----------
    pattern : str
        Glob of the logs; outputs are named relative to the folder before its first wildcard.
    out : path
        Output folder.
    fs, columns, time_column, unit, input, gaps, channels, time_unit
        As for :func:`allanite.read_log` (the same for every file) — ``unit`` also an accelerometer's (``m/s^2``,
        ``g``, ``mg``, …: the reports an accelerometer's, as ``allanite report --unit g``; a file whose column names
        give a gyro's unit is then an error row): by default a column named as a temperature
        is no axis, and a channel of the refinement when ``refine`` (:func:`allanite.report.from_log`); channels
        named here imply the refinement (``allanite report --channels``).
    accel_unit : str, optional
        The accelerometer columns' unit (``m/s^2``, ``g``, ``mg``, …), as ``allanite report --accel-unit``: without
        ``columns``, a log's accelerometer columns beside a gyro's — where their names give its unit (EuRoC's
        ``a_RS_S_x [m s^-2]``), or where this names it and their names (``acc_x``) tell them from the gyro's —
        are reported in their own report, ``<file's folder>/accelerometer/``, and their fleet rows are in the
        accelerometer's units (``sensor`` accelerometer); a log whose columns are all named as an accelerometer's
        (``ax``) and give no unit is reported in it.
    window, hop, taus, estimator, refine, fit
        As for ``allanite report``.
    scheduler : str, optional
        Address of a running Dask scheduler (e.g. ``tcp://host:8786``); only ever the one given.
    dask_workers : int, optional
        Workers of the LocalCluster started when neither ``scheduler`` nor ``client`` is given
        (default 2).
    client : distributed.Client, optional
        Use this client.
    resume : bool
        Skip files whose report is complete and newer than the file.
    quiet : bool
        No progress bar.
    retries : int
        Dask retries of a task whose worker died.
    """
    import distributed  # noqa: F401  (missing: this fails at once, before any folder is made)

    check_time_unit_used(time_unit, fs, time_column, None)  # once, not an error row per file
    out = Path(out)
    paths, folders = _report_folders(pattern, out)
    out.mkdir(parents=True, exist_ok=True)
    # an accelerometer's unit (m/s^2, g, …) is the report's, as allanite report takes it: read_log takes a gyro's
    accel = accel_unit_name(unit)
    read_opts = {"fs": fs, "columns": columns, "time_column": time_column, "input": input, "time_unit": time_unit}
    read_opts["unit"] = None if accel else unit
    read_opts = {k: v for k, v in read_opts.items() if v is not None}
    read_opts.update(gaps=gaps, channels=channels)
    report_opts = {"window": window, "hop": hop, "taus": taus, "estimator": estimator, "refine": refine, "fit": fit}
    report_opts.update({"unit": accel} if accel else {})
    accel_unit = None if accel_unit is None else _accel_unit_named(accel_unit)
    statuses: dict[str, dict] = {}
    todo = []
    for f, p in folders.items():
        if resume and _complete(f, p):
            statuses[str(p)] = {"path": str(p), "out": str(f), "status": "skipped", "error": None}
        else:
            todo.append((str(p), str(f)))

    own = []
    if client is None:
        client, own = _start_client(scheduler, dask_workers)
    try:
        opts = (read_opts, report_opts, accel_unit)
        statuses.update(_run_reports(client, todo, opts, retries, quiet))
    finally:
        for o in own:
            o.close()
    # a worker killed mid-write leaves its temporary folder behind (its retry wrote a fresh one)
    for f in folders:
        for stale in [*f.parent.glob(f".{f.name}.tmp-*"), *f.parent.glob(f".{f.name}.old-*")]:
            shutil.rmtree(stale, ignore_errors=True)
    files = [statuses[str(p)] for p in paths]
    rows = []
    for st in files:
        try:
            rows.extend(_rows(st))
        except (OSError, ValueError, KeyError) as exc:  # a resumed report that cannot be read
            rows.extend(_rows(dict(st, status="error", error=f"summary.json unreadable: {exc}")))
    _flag(rows)
    written = write_table(rows, out)
    written["html"] = write_html(rows, files, out)
    return FleetResult(rows=rows, files=files, paths=written)


def _accel_unit_named(unit: str) -> str:
    """The canonical name of an accelerometer's unit (``m/s^2``, ``g``, …); a ParameterError naming the allowed."""
    name = accel_unit_name(unit)
    if name is None:
        raise ParameterError(f"accel_unit={unit!r} is no accelerometer's unit; allowed: {', '.join(ACCEL_UNITS)}")
    return name


def _report_folders(pattern: str, out: Path) -> tuple[list[Path], dict[Path, Path]]:
    """The files matching ``pattern`` in order, and each one's report folder under ``out`` (folder → file); a
    ParameterError when none matches or two would share a folder."""
    root = glob_root(pattern)
    paths = sorted(Path(p) for p in glob.glob(pattern, recursive=True) if Path(p).is_file())
    if not paths:
        raise ParameterError(f"no file matches {pattern!r}")
    folders: dict[Path, Path] = {}
    for p in paths:
        f = out_folder(p, root, out)
        if f in folders:
            raise ParameterError(f"{folders[f]} and {p} would share the report folder {f}: rename one")
        folders[f] = p
    return paths, folders


def _start_client(scheduler, dask_workers):
    """A client of the scheduler at ``scheduler``, else of a LocalCluster of ``dask_workers`` workers (default 2),
    and what to close afterwards (the client first)."""
    from distributed import Client, LocalCluster

    own = []
    if scheduler is not None:
        client = Client(scheduler, timeout="30s")
    else:
        cluster = LocalCluster(
            n_workers=dask_workers or 2, threads_per_worker=1, host="127.0.0.1", dashboard_address=None
        )
        own.append(cluster)
        client = Client(cluster)
    own.insert(0, client)
    return client, own


def _run_reports(client, todo, opts: tuple, retries, quiet) -> dict[str, dict]:
    """Each (file, folder) of ``todo`` reported as a Dask task: file path → its status (a task that died is an
    error row, not a stop)."""
    from distributed import as_completed
    from tqdm import tqdm

    statuses: dict[str, dict] = {}
    # disable=None: no bar when stderr is no terminal (a pipe, a log file)
    bar = tqdm(total=len(todo), disable=True if quiet else None, unit="file", file=sys.stderr, desc="allanite batch")
    futures = [
        client.submit(run_one, p, f, *opts, key=f"allanite-report-{uuid.uuid4().hex}", retries=retries) for p, f in todo
    ]
    for fut in as_completed(futures):
        try:
            st = fut.result()
        except Exception as exc:  # the task itself died (e.g. its worker, beyond the retries)
            i = futures.index(fut)
            st = {"path": todo[i][0], "out": todo[i][1], "status": "error", "error": f"{type(exc).__name__}: {exc}"}
        statuses[st["path"]] = st
        bar.update(1)
    bar.close()
    return statuses


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="allanite batch",
        description="One report per log matching PATTERN, as Dask tasks, and a fleet summary "
        "(out/fleet.csv, fleet.parquet, fleet.html).",
    )
    p.add_argument("pattern", metavar="PATTERN", help="glob of the logs, quoted ('logs/**/*.csv.gz')")
    p.add_argument(
        "--fs", type=float, metavar="HZ", help="sampling rate in Hz (or give --time-column; ROS bags use their stamps)"
    )
    p.add_argument(
        "--columns",
        metavar="C1,C2,...",
        help="the sample columns, as allanite report's (default: every column but time and channels — or, when "
        "the header also names accelerometer columns, the ones it names as gyro)",
    )
    p.add_argument("--time-column", metavar="C", help="column of sample times: derives --fs, finds gaps")
    p.add_argument(
        "--time-unit",
        choices=("s", "ms", "us", "ns"),
        help="unit of the time column, as allanite report's (default: the unit its name ends in, else s)",
    )
    p.add_argument(
        "--unit",
        metavar="U",
        help="unit of the samples, as allanite report's: a gyro's (deg/s, rad/s, ...) or an accelerometer's (m/s^2, "
        "g, mg, ...: the reports an accelerometer's, in m/s/√h, µg, m/s/h^1.5); without it the unit the column names "
        "give (ax [g]), else the coefficients are in base form",
    )
    p.add_argument(
        "--accel-unit",
        choices=ACCEL_UNITS,
        help="as allanite report's: unit of the accelerometer columns beside a gyro's (default: the one their names "
        "give, [g] or [m s^-2]); each file's accelerometer columns are then reported in OUT/<file>/accelerometer/ "
        "and their fleet rows are in m/s/√h, µg, m/s/h^1.5 (sensor accelerometer)",
    )
    p.add_argument(
        "--input",
        type=input_word,
        choices=("rate", "increment", "angle"),
        default="rate",
        help="what a sample is (default rate; phase is angle, freq rate)",
    )
    p.add_argument(
        "--gaps",
        choices=("error", "longest", "split"),
        default="error",
        help="as allanite report's: stop on gaps (default), analyse the longest gap-free stretch, "
        "or the same and list every stretch (split)",
    )
    p.add_argument(
        "--channels",
        metavar="C1,C2,...",
        help="as allanite report's: other columns every axis is regressed on (implies --refine); default: the "
        "columns named as a temperature (never an axis; a channel with --refine); 'none': no channel",
    )
    p.add_argument("--taus", default="octave", help="the τ grid, as allanite report's (default octave)")
    p.add_argument("--window", type=int, metavar="N", help="DAVAR window in samples (default: 1/12 of the record)")
    p.add_argument(
        "--hop", type=int, metavar="N", help="DAVAR hop between windows in samples (default: 1/25 of the window)"
    )
    p.add_argument(
        "--estimator", choices=("oavar", "theoh"), default="oavar", help="as allanite report's (default oavar)"
    )
    p.add_argument("--refine", action="store_true", help="add the model refinement to every report")
    p.add_argument("--no-fit", action="store_true", help="skip the noise-model fit")
    p.add_argument("--out", required=True, metavar="DIR", help="folder for the reports and the fleet summary")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--scheduler", metavar="ADDRESS", help="a running Dask scheduler, e.g. tcp://host:8786")
    where.add_argument("--dask-workers", type=int, metavar="N", help="LocalCluster workers (default 2)")
    p.add_argument("--resume", action="store_true", help="skip files whose report is complete and newer")
    p.add_argument("-q", "--quiet", action="store_true")
    return p


def _spec(text):
    if text is None:
        return None
    items = [c.strip() for c in text.split(",")]
    return [int(c) if c.isdigit() else c for c in items]


def _channels(text):
    """--channels as read_log's ``channels=``: "auto" without it, None for ``none``, else the column specs."""
    if text is None:
        return "auto"
    return None if text.strip().lower() == "none" else _spec(text)


def main(argv=None) -> int:
    """``allanite batch``: exit 0 when every file succeeded, 3 when some failed, 2 on a usage error."""
    args = build_parser().parse_args(argv)
    t0 = time.perf_counter()
    taus = args.taus if args.taus.isalpha() else [float(t) for t in args.taus.split(",")]
    tc = args.time_column
    try:
        res = batch(
            args.pattern,
            out=args.out,
            fs=args.fs,
            columns=_spec(args.columns),
            time_column=None if tc is None else (int(tc) if tc.isdigit() else tc),
            unit=args.unit,
            accel_unit=args.accel_unit,
            input=args.input,
            gaps=args.gaps,
            channels=_channels(args.channels),
            time_unit=args.time_unit,
            window=args.window,
            hop=args.hop,
            taus=taus,
            estimator=args.estimator,
            refine=args.refine,
            fit=not args.no_fit,
            scheduler=args.scheduler,
            dask_workers=args.dask_workers,
            resume=args.resume,
            quiet=args.quiet,
        )
    except AllaniteError as exc:
        from ..cli import cli_words  # in the command's words (--time-unit ms, not time_unit='ms')

        print(f"allanite: error: {cli_words(str(exc))}", file=sys.stderr)
        return 2
    if not args.quiet:
        n_ok = sum(f["status"] == "ok" for f in res.files)
        n_skip = sum(f["status"] == "skipped" for f in res.files)
        print(f"{len(res.files)} files: {n_ok} reported, {n_skip} skipped (resume), {len(res.failed)} failed")
        from ..cli import cli_words  # a file's error in the command's words (--gaps longest, not gaps='longest')

        for f in res.failed:
            print(f"  failed: {f['path']}: {cli_words(f['error'])}")
        flagged = [r for r in res.rows if r.get("flag")]
        for r in flagged:
            print(f"  flagged: {r['file']} axis {r['axis']}: {r['flag']}")
        print(f"wrote {', '.join(str(p) for p in res.paths.values())} in {time.perf_counter() - t0:.1f} s")
    return 3 if res.failed else 0
