"""The ``allanite`` command line. It only wires the library together: read the log
(:func:`allanite.read_log`), build the report (:mod:`allanite.report`), write it, print a summary.

Exit status: 0 success; 2 a usage or input error, reported as one line ``allanite: error: …`` on
stderr (never a traceback); 1 an internal error (a bug: the traceback is shown); 130 interrupted.
"""

from __future__ import annotations

import argparse
import gc
import os
import re
import shutil
import sys
import time
import warnings
from pathlib import Path
from typing import Any

from ._cli_columns import ACCEL_FOLDER, given_accel_unit, is_accel_name, sensor_columns
from ._cli_columns import gyro_columns as gyro_columns  # allanite.cli.gyro_columns, as before the move
from ._cli_options import (
    DESCRIPTION,
    EPILOG,
    REPORT_DESCRIPTION,
    REPORT_EPILOG,
    Parser,
    UsageError,
    add_analysis_options,
    add_input_options,
    add_output_options,
    formatter,
)
from ._core import __version__
from ._dist import special as load_quantile_kernels
from .analysis import avar
from .datasets import default_record
from .errors import AllaniteError, ParameterError
from .io import read_log
from .kalibr import to_kalibr
from .model import fit as fit_model
from .report import build_report, from_log
from .report._worker import close as close_figure_worker
from .report._worker import start as start_figure_worker
from .units import accel_unit_name

EXIT_OK, EXIT_INTERNAL, EXIT_USAGE, EXIT_INTERRUPTED = 0, 1, 2, 130

_KALIBR_NEEDS_UNIT = (
    "--kalibr needs the gyro's unit to write SI values: give --unit (e.g. --unit deg/s or --unit rad/s)"
)

#: Options that describe a LOG file; meaningless for the bundled record.
_LOG_OPTIONS = (
    "fs",
    "columns",
    "time_column",
    "time_unit",
    "unit",
    "input",
    "gaps",
    "accel_columns",
    "accel_unit",
    "channels",
)


def build_parser() -> argparse.ArgumentParser:
    """The ``allanite`` argument parser: the ``report`` and ``batch`` subcommands and their options."""
    parser = Parser(
        prog="allanite",
        usage="%(prog)s [-h] [--version] COMMAND [ARGS ...]",
        description=DESCRIPTION,
        epilog=EPILOG,
        formatter_class=formatter,
    )
    parser.add_argument(
        "--version", action="version", version=f"allanite {__version__}", help="show the version and exit"
    )
    # the commands are listed in DESCRIPTION (argparse's own listing adds a stray "COMMAND" line)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", help=argparse.SUPPRESS, parser_class=Parser)
    rep = sub.add_parser(
        "report",
        prog="allanite report",
        description=REPORT_DESCRIPTION,
        epilog=REPORT_EPILOG,
        formatter_class=formatter,
    )
    rep.add_argument(
        "log",
        nargs="?",
        metavar="LOG",
        help="the log: CSV/TSV/whitespace text (.gz too), .npy, .npz, Parquet, ROS 1 .bag or ROS 2 "
        "bag; default: the bundled record",
    )

    add_input_options(rep)
    add_analysis_options(rep)
    add_output_options(rep)
    return parser


# --------------------------------------------------------------------------------------------------
# progress


class _Progress:
    """A tqdm bar over the report's steps, on stderr; off with --quiet or when stderr is no terminal.
    When stdout is no terminal (a pipe, a log file) each step is also printed there as it starts, with
    the seconds since the start, so that a log shows where the run is."""

    def __init__(self, quiet: bool):
        self.lines = not quiet and not _isatty(sys.stdout)
        self.t0 = time.perf_counter()
        # tqdm (and the package metadata its import reads, ~0.1 s) only where a bar is drawn
        self.bar: Any = _NoBar() if quiet or not _isatty(sys.stderr) else _bar()
        self.started = False

    def step(self, name: str) -> None:
        if self.started:
            self.bar.update(1)
        self.started = True
        self.bar.set_description_str(name)
        if self.lines:
            print(f"[{time.perf_counter() - self.t0:7.1f} s] {name}", flush=True)

    def add(self, n: int) -> None:
        self.bar.update(n)

    def expect(self, remaining: int) -> None:
        """``remaining`` more steps after the current one."""
        self.bar.total = self.bar.n + 1 + remaining
        self.bar.refresh()

    def close(self) -> None:
        if self.started and self.bar.total is not None:
            self.bar.update(max(0, self.bar.total - self.bar.n))
        self.bar.close()


def _bar():
    """The tqdm bar on stderr (a terminal)."""
    from tqdm import tqdm

    return tqdm(
        total=8,
        file=sys.stderr,
        leave=False,
        unit="step",
        bar_format="{desc:<38.38}|{bar}| {n_fmt}/{total_fmt} [{elapsed}]",
        dynamic_ncols=True,
    )


class _NoBar:
    """What ``_Progress`` keeps of a bar that is not drawn (--quiet, stderr no terminal): the count; ``write``
    prints, as tqdm's does."""

    def __init__(self):
        self.n, self.total = 0, 8

    def update(self, n: int = 1) -> None:
        self.n += n

    def set_description_str(self, desc: str) -> None:
        pass

    def refresh(self) -> None:
        pass

    def close(self) -> None:
        pass

    def write(self, text: str, file=None) -> None:
        print(text, file=file if file is not None else sys.stdout, flush=True)


def _isatty(stream) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):  # no isatty, or a closed stream
        return False


# --------------------------------------------------------------------------------------------------
# the report command


def _spec_list(text: str, what: str):
    items = [c.strip() for c in text.split(",")]
    if not all(items):
        raise UsageError(f"{what} {text!r}: empty name in the comma-separated list")
    return [int(c) if c.isdigit() else c for c in items]


def _taus(text: str):
    if re.fullmatch(r"[A-Za-z]+", text.strip()):
        return text.strip()
    try:
        return [float(t) for t in text.split(",")]
    except ValueError:
        raise UsageError(
            f"argument --taus: {text!r} is neither a grid name (octave, decade, exp, all) nor comma-separated seconds"
        ) from None


def cli_words(message: str) -> str:
    """Library messages speak Python (gaps='longest'); say it as options, on one line."""
    message = re.sub(
        r"\b(gaps|input|time_unit)='([a-z]+)'", lambda m: f"--{m.group(1).replace('_', '-')} {m.group(2)}", message
    )
    message = (
        message.replace("drop fs=,", "drop --fs,")
        .replace("channels=None", "--channels none")
        .replace("time_unit=", "--time-unit")
    )
    message = re.sub(r"\bhop=(\d+)", r"--hop \1", message).replace(
        "max_memory / ALLANITE_MAX_MEMORY", "--max-memory / ALLANITE_MAX_MEMORY"
    )
    message = message.replace("(fs=… in Hz)", "(--fs HZ)").replace("(time_column=…)", "(--time-column C)")
    message = re.sub(r"\btime_column='([^']*)'", r"--time-column \1", message).replace("columns=[…]", "--columns")
    message = re.sub(r"\bfs=([0-9][0-9.e+-]*)", r"--fs \1", message)
    message = re.sub(r"\btime_column=(?=[\s,:;]|$)", "--time-column", message)
    return " ".join(message.split())


def _time_column(args):
    """--time-column as read_log takes it: a 0-based index or a name; None without it."""
    if args.time_column is None:
        return None
    tc = args.time_column.strip()
    return int(tc) if tc.isdigit() else tc


def _read(args, progress):
    """The log, the reading's notes and its channels (``Log.channels``: those --channels names, else the columns
    recognised as a temperature by their names; None without any)."""
    return _read_sensors(args, progress)[:3]


def _read_sensors(args, progress):
    """:func:`_read`'s log, notes and channels and, without --columns, the log on its accelerometer's columns where
    their names give its unit beside a gyro's (:func:`sensor_columns`), else None."""
    path = Path(args.log)
    if not path.exists():
        raise AllaniteError(f"{path}: no such file")
    progress.step(f"reading {path.name}")
    kwargs = {}
    if args.time_unit is not None:
        kwargs["time_unit"] = args.time_unit
    columns = None if args.columns is None else _spec_list(args.columns, "--columns")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        log = read_log(
            path,
            fs=args.fs,
            columns=columns,
            time_column=_time_column(args),
            unit=None if accel_unit_name(args.unit) else args.unit,  # an accelerometer's: from_log's (below)
            input=args.input or "rate",
            gaps=args.gaps or "error",
            channels=_channel_specs(args, columns),
            **kwargs,
        )
    notes = [" ".join(str(w.message).split()) for w in caught]
    accel = None
    if columns is None:
        log, accel, note = sensor_columns(log, args.accel_unit)
        notes += [note] if note else []
    return log, notes, log.channels or None, accel


def _accelerometers_unit(args, log, accel) -> str | None:
    """The accelerometer's unit the analysed columns are in where the log is an accelerometer's: --unit naming one
    (``m/s^2``, ``g``), or --accel-unit without a gyro's unit (given or from the names) where no accelerometer
    report of its own is split off and every analysed column is named as an accelerometer's (``ax``, ``acc_x``);
    else None (a gyro's, or an unknown unit)."""
    beside = " (or --accel-unit for the columns named as an accelerometer's beside the gyro's)"
    if (named := given_accel_unit(args.unit, log, beside)) is not None:
        return named
    if args.accel_unit is None or args.unit is not None or log.unit is not None or accel is not None:
        return None
    return args.accel_unit if all(is_accel_name(str(c)) for c in log.columns) else None


def _channel_specs(args, columns):
    """--channels as read_log's ``channels=``: "auto" without it (the columns named as a temperature), None for
    ``none``, else the column specs — refused with --refine-candidates that leave the regression out, and where a
    spec is also one of --columns. Named channels imply --refine (:func:`_refine_option`)."""
    if args.channels is None:
        return "auto"
    if args.channels.strip().lower() == "none":
        return None
    specs = _spec_list(args.channels, "--channels")
    tried = _refine_option(args)
    if isinstance(tried, tuple) and "regression" not in tried:
        raise UsageError(
            f"--channels {args.channels} is only used by the regression effect, which --refine-candidates "
            f"{args.refine_candidates} leaves out: add regression to it, or drop --channels"
        )
    both = [c for c in specs if c in (columns or [])]
    if both or len(set(specs)) < len(specs):
        twice = both[0] if both else next(c for c in specs if specs.count(c) > 1)
        where = "in both --columns and --channels" if both else "twice in --channels"
        raise ParameterError(
            f"column {twice!r} is given {where}: a column is either analysed as an axis (--columns) or "
            "a channel the axes are regressed on (--channels), once"
        )
    return specs


def _kalibr_ready(args, rep) -> None:
    """What --kalibr needs of the gyro's report (its unit, its fits) and of the options, checked before any file is
    written."""
    if rep.unit is None:
        raise UsageError(_KALIBR_NEEDS_UNIT)
    if rep.fits is None:
        raise AllaniteError(f"--kalibr needs the noise-model fit: {rep.fit_error or 'drop --no-fit'}")
    if args.accel_columns is not None and args.log is None:
        raise UsageError("--accel-columns describes a LOG file; the bundled record has no accelerometer")


def _kalibr(args, rep, progress, accel_rep=None) -> Path:
    """imu.yaml from the report's gyro fits and, with --accel-columns, the accelerometer's — else those of the
    accelerometer's report (``accel_rep``, written beside the gyro's) where there is one."""
    _kalibr_ready(args, rep)
    accel = None
    if args.accel_columns is None and accel_rep is not None:
        accel, named = accel_rep.fits, {accel_rep.accel_unit}
    elif args.accel_columns is not None:
        progress.step("accelerometer fit")
        kwargs = {} if args.time_unit is None else {"time_unit": args.time_unit}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the gyro read already reported the timing
            alog = read_log(
                Path(args.log),
                fs=args.fs,
                columns=_spec_list(args.accel_columns, "--accel-columns"),
                time_column=_time_column(args),
                gaps=args.gaps or "error",
                channels=None,  # the gyro read took the channels
                **kwargs,
            )
        accel = fit_model(avar(alog.data, alog.fs), tau_range="auto")
        named = {cu.name for cu in alog.column_units if cu is not None and cu.kind == "acceleration"}
    else:
        named = set()
    # --accel-unit, else the one unit the accelerometer columns' names give ("a [g]"), else m/s²
    header = named.pop() if len(named) == 1 else None
    return to_kalibr(
        Path(args.kalibr),
        gyro=rep.fits,
        accel=accel,
        update_rate=rep.fs,
        aggregate=args.kalibr_aggregate,
        accel_unit=args.accel_unit or header or "m/s^2",
    )


def _refine_option(args) -> bool | tuple:
    """``build_report``'s ``refine=``: False, True (--refine, or --channels C1,… alone), or the effects of
    --refine-candidates."""
    if args.refine_candidates is None:
        # --channels C1,… implies --refine: a channel has no other use than the refinement's regression on it
        # (so does --refine-filter: the declared filter is the refinement's bandwidth kind)
        return bool(args.refine or _named_channels(args) or args.refine_filter)
    names = [n.strip() for n in args.refine_candidates.split(",") if n.strip()]
    return () if names == ["none"] else tuple(names)


def _refine_filter(args) -> dict | None:
    """``build_report``'s ``refine_filter=`` from --refine-filter FILE (one row of FIR taps, or two rows: b, then a;
    numbers split by commas or white space, lines from '#' on ignored) and --refine-filter-rate; None without it."""
    if not args.refine_filter:
        if args.refine_filter_rate is not None:
            raise ParameterError("--refine-filter-rate: give the filter too (--refine-filter FILE)")
        return None
    path = Path(args.refine_filter)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ParameterError(f"--refine-filter {path}: cannot be read ({exc.strerror})") from None
    rows = []
    for line in text.splitlines():
        cells = [c for c in re.split(r"[,\s]+", line.split("#", 1)[0]) if c]
        if cells:
            try:
                rows.append([float(c) for c in cells])
            except ValueError:
                raise ParameterError(f"--refine-filter {path}: not a number in {line.strip()!r}") from None
    if len(rows) not in (1, 2):
        raise ParameterError(
            f"--refine-filter {path}: {len(rows)} rows of numbers; give one (FIR taps) or two (IIR b, then a)"
        )
    spec: dict = {"taps": rows[0]} if len(rows) == 1 else {"b": rows[0], "a": rows[1]}
    if args.refine_filter_rate is not None:
        spec["rate"] = args.refine_filter_rate
    return spec


def _named_channels(args) -> bool:
    """Whether --channels names channels (not ``none``, not left to the recognition of temperature names)."""
    return args.channels is not None and args.channels.strip().lower() != "none"


def _report(args) -> int:
    quiet = args.quiet
    _check_log_options(args)
    taus = _taus(args.taus)
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise AllaniteError(f"--out {out}: exists and is not a folder")
    out_existed = out.exists()
    t0 = time.perf_counter()
    # the intervals' χ² kernels (~15 ms) before the bar's monitor thread starts: they load without the whole
    # scipy.special package only while no other Python thread runs (allanite._dist.special)
    load_quantile_kernels()
    progress = _Progress(quiet)
    # matplotlib's import and font set-up in a process of its own while the log is read and analysed
    start_figure_worker()
    try:
        with warnings.catch_warnings():
            if quiet:
                warnings.simplefilter("ignore")
            common = dict(
                window=args.window,
                hop=args.hop,
                taus=taus,
                fit=not args.no_fit,
                progress=progress,
                estimator=args.estimator,
                refine=_refine_option(args),
                refine_filter=_refine_filter(args),
                frames=args.frames,
                forecast=args.forecast,
                taper=args.taper,
                split=args.split,
                max_memory=args.max_memory,
            )
            rep, accel = _analysed_report(args, progress, common)
            if args.kalibr:  # imu.yaml now, or with the accelerometer's report's fits once it is written
                _kalibr_ready(args, rep)
            kalibr_path = _kalibr(args, rep, progress) if args.kalibr and accel is None else None
            specs = rep.figure_specs()
            progress.expect(len(specs) + 1)
            if accel is not None:  # the page links it, summary.json names it
                rep.source["accelerometer_report"] = f"{ACCEL_FOLDER}/report.html"
            paths = rep.write(out, progress)
            accel_rep, accel_paths = _accel_report(accel, progress, dict(common, unit=args.accel_unit), out)
            if args.kalibr and accel_rep is not None:
                kalibr_path = _kalibr(args, rep, progress, accel_rep)
    except KeyboardInterrupt:
        if not out_existed and out.is_dir():  # a folder this run made holds a half-written report at most
            shutil.rmtree(out, ignore_errors=True)
        raise
    finally:
        close_figure_worker()
        progress.close()
    if not quiet:
        _print_written(rep, paths, out, kalibr_path, t0, (accel_rep, accel_paths))
    return EXIT_OK


def _accel_report(accel, progress, common: dict, out: Path) -> tuple:
    """(the report, its files) of the accelerometer's columns (``accel``, a Log; None: (None, [])), written in
    ``out/ACCEL_FOLDER`` with the options of the gyro's report — a figure process of its own where one helps."""
    if accel is None:
        return None, []
    start_figure_worker()
    if common.get("unit") is None:  # the accelerometer's unit from its columns' names
        common = {k: v for k, v in common.items() if k != "unit"}
    arep = from_log(accel, notes=[], **common)
    arep.source["gyro_report"] = "../report.html"  # its page links the gyro's, as the gyro's links it
    progress.expect(len(arep.figure_specs()) + 1)
    return arep, arep.write(out / ACCEL_FOLDER, progress)


def _check_log_options(args) -> None:
    """Options that describe a LOG file are refused without one (the bundled record is analysed then)."""
    if args.log is None:
        given = [f"--{o.replace('_', '-')}" for o in _LOG_OPTIONS if getattr(args, o) is not None]
        if given:
            raise UsageError(
                f"{', '.join(given)} describe{'s' if len(given) == 1 else ''} a LOG file; without LOG "
                f"the bundled record (100 Hz, 3 axes, deg/s) is analysed"
            )


def _analysed_report(args, progress, common: dict):
    """(the report, None) of the bundled record, or (the report of LOG read with its notes (warned of unless
    --quiet), the log on its accelerometer's columns or None: :func:`_read`)."""
    if args.log is None:
        progress.step("generating the bundled record")
        x, fs, info = default_record()
        source = {
            "name": "bundled record",
            **{k: (list(v) if isinstance(v, tuple) else v) for k, v in info.items()},
        }
        return build_report(x, fs, unit=info["unit"], axis_names=["x", "y", "z"], source=source, **common), None
    log, notes, _, accel = _read_sensors(args, progress)
    if args.kalibr and log.unit is None:
        raise UsageError(_KALIBR_NEEDS_UNIT)
    own = _accelerometers_unit(args, log, accel)
    if own is not None:  # the log is an accelerometer's: its report in that unit (build_report's accel_unit)
        common = dict(common, unit=own)
    # an IMU log's two reports, every column taken (EuRoC), are what was asked: said in the report's notes alone
    both = accel is not None and "left out:" not in notes[-1]
    if not args.quiet:
        for note in notes[:-1] if both else notes:
            progress.bar.write(f"allanite: warning: {note}", file=sys.stderr)
    return from_log(log, notes=notes, **common), accel  # with the log's channels (report._channels)


def _print_written(rep, paths, out: Path, kalibr_path, t0: float, accel=(None, [])) -> None:
    """The console's summary of the report and the files written (and of the accelerometer's report, ``accel``:
    (report, paths), where one was written), and the run's time since ``t0``."""
    print(rep.text())
    if accel[0] is not None:
        print(f"\n{accel[0].text()}")
    pngs = [p.name for p in paths[2:] if p.suffix == ".png"]
    print(f"\nwrote {paths[0]}\n      {paths[1]}\n      {len(pngs)} figures in {out}/: {', '.join(pngs)}")
    side = [p.name for p in paths[2:] if p.suffix != ".png"]
    if side:
        print(f"      per-window series in {out}/: {', '.join(side)} (named in summary.json)")
    if accel[0] is not None:
        apaths = accel[1]
        n_png = sum(p.suffix == ".png" for p in apaths[2:])
        print(f"      the accelerometer's report: {apaths[0]}\n      {apaths[1]}")
        print(f"      {n_png} figures in {apaths[0].parent}/")
    if kalibr_path is not None:
        print(f"      {kalibr_path} (Kalibr)")
    print(f"in {time.perf_counter() - t0:.1f} s")


def _error(message: str) -> int:
    print(f"allanite: error: {cli_words(message)}", file=sys.stderr)
    return EXIT_USAGE


def main(argv=None) -> int:
    """Run the command line; returns the exit status (``--help``/``--version`` exit through SystemExit(0)).

    Without ``argv`` — the process's own command line: the ``allanite`` script, ``python -m allanite`` — the
    process is about to exit when this returns, and the garbage collector's objects are frozen first
    (:func:`_exit_lightly`)."""
    if argv is None:
        try:
            return main(sys.argv[1:])
        finally:
            _exit_lightly()
    parser = build_parser()
    argv = list(argv)
    if argv[:1] == ["batch"]:  # fleets on Dask (issue 19): its own parser, dask imported only here
        from .dask.fleet import main as batch_main

        return batch_main(argv[1:])
    try:
        args = parser.parse_args(argv)
        if args.command is None:
            parser.print_help()
            return EXIT_USAGE
        return _report(args)
    except UsageError as exc:
        return _error(str(exc))
    except AllaniteError as exc:
        return _error(str(exc))
    except BrokenPipeError:  # stdout closed early (allanite report | head): not an error worth a message
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_INTERNAL
    except OSError as exc:  # cannot write the output folder, unreadable file, disk full, …
        where = f"{exc.filename}: " if getattr(exc, "filename", None) else ""
        return _error(f"{where}{exc.strerror or exc}")
    except KeyboardInterrupt:
        print("allanite: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED


def _exit_lightly() -> None:
    """Freeze every object the garbage collector tracks (:func:`gc.freeze`), so that the interpreter's exit
    does not walk them all again: after a report, some 10⁵ objects (the analysis, the report, the modules of
    NumPy, matplotlib, Jinja2) were walked by the collections of the exit — 0.5 s of CPU (at load 8; see
    docs/performance.md). The exit itself is the ordinary one: ``atexit`` handlers run, the standard
    streams are flushed and closed; the report's files are closed already (written with ``with`` blocks and
    ``Path.write_*``) and the figure process reaped (``_worker.close``). Only objects in reference cycles are
    then left to the operating system instead of being collected — nothing the command leaves open."""
    gc.freeze()


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
