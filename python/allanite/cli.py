"""The ``allanite`` command line. It only wires the library together: load, estimate, print, plot."""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from .errors import AllaniteError

DESCRIPTION = """\
allanite: static and dynamic Allan variance for gyroscopes, IMUs and clocks.

Commands:
  report   Allan deviation table, dynamic Allan variance summary and plots for a log
           (runs on the bundled simulated gyro record when no log is given).

Run 'allanite COMMAND --help' for a command's options."""

REPORT_EPILOG = """\
examples:
  allanite report                              # the bundled 3-axis simulated gyro, 1 h at 100 Hz
  allanite report gyro.npy --fs 200 --window 60000 --hop 2000 --out results/
  allanite report gyro.csv --fs 100 --unit deg/s

Outputs in --out: adev.png, davar.png (one panel per axis) and summary.json.
Exit status: 0 on success, 2 for a usage or input error (one line on stderr)."""


def _load(path: str, fs: float | None):
    p = Path(path)
    if not p.exists():
        raise AllaniteError(f"{path}: no such file")
    if fs is None:
        raise AllaniteError(f"{path}: --fs is required for a log file (samples per second)")
    try:
        if p.suffix == ".npy":
            x = np.load(p, mmap_mode="r")
        else:
            x = np.loadtxt(p, delimiter="," if p.suffix == ".csv" else None, comments="#", ndmin=1)
    except (ValueError, OSError) as exc:
        raise AllaniteError(f"{path}: cannot read numeric samples ({exc})") from None
    return x, fs, {"what": str(p)}


def _report(args) -> int:
    from . import avar, davar, default_record

    t0 = time.perf_counter()
    if args.log is None:
        x, fs, info = default_record()
        unit = info["unit"]
    else:
        x, fs, info = _load(args.log, args.fs)
        unit = args.unit
    x = np.asarray(x)
    n = x.shape[0]
    window = args.window or max(2, n // 12)
    hop = args.hop or max(1, window // 25)
    static = avar(x, fs, taus="octave")
    dyn = davar(x, fs, window=window, hop=hop, taus="exp")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    adev = np.atleast_2d(static.adev)
    n_axes = adev.shape[0]
    print(f"record: {info['what']} — {n} samples × {n_axes} axes at {fs:g} Hz ({n / fs / 3600:.3g} h), unit {unit}")
    print(f"\nOverlapping Allan deviation ({unit}):")
    print("  " + f"{'tau (s)':>10}  {'n':>8}  " + "  ".join(f"{'axis ' + str(k):>11}" for k in range(n_axes)))
    for i, tau in enumerate(static.tau):
        print("  " + f"{tau:10.4g}  {static.n[i]:8d}  " + "  ".join(f"{adev[k, i]:11.4e}" for k in range(n_axes)))

    dadev = dyn.adev if dyn.avar.ndim == 3 else dyn.adev[None]
    print(f"\nDynamic Allan deviation: window {window} samples ({window / fs:g} s), hop {hop} "
          f"({hop / fs:g} s), {dyn.t.size} windows × {dyn.tau.size} τ ({dyn.tau[0]:g}–{dyn.tau[-1]:g} s)")
    summary_axes = []
    for k in range(n_axes):
        row = dadev[k, 0]
        med = float(np.median(row))
        j_max, j_min = int(np.argmax(row)), int(np.argmin(row))
        print(f"  axis {k}: ADEV at τ = {dyn.tau[0]:g} s over time: median {med:.4e}, "
              f"max {row[j_max]:.4e} at t = {dyn.t[j_max]:.0f} s, min {row[j_min]:.4e} at t = {dyn.t[j_min]:.0f} s, "
              f"max/min = {row[j_max] / row[j_min]:.2f}")
        summary_axes.append({
            "axis": k,
            "adev_shortest_tau_median": med,
            "adev_shortest_tau_max": float(row[j_max]), "t_of_max_s": float(dyn.t[j_max]),
            "adev_shortest_tau_min": float(row[j_min]), "t_of_min_s": float(dyn.t[j_min]),
        })

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    static.plot(ax=ax, unit=unit)
    ax.set_title("Overlapping Allan deviation")
    fig.tight_layout()
    fig.savefig(out / "adev.png", dpi=110)
    plt.close(fig)
    fig, axs = plt.subplots(n_axes, 1, figsize=(7.5, 2.8 * n_axes), squeeze=False)
    for k in range(n_axes):
        dyn.plot(ax=axs[k, 0], axis=k, unit=unit)
        axs[k, 0].set_title(f"Dynamic Allan deviation, axis {k}")
    fig.tight_layout()
    fig.savefig(out / "davar.png", dpi=110)
    plt.close(fig)

    summary = {
        "record": {k: v for k, v in info.items() if isinstance(v, (str, int, float, list, tuple))},
        "unit": unit, "fs_hz": fs, "samples": n, "axes": n_axes,
        "static": {"estimator": static.estimator, "tau_s": static.tau.tolist(), "n": static.n.tolist(),
                   "adev": adev.tolist(), "adev_unit": unit},
        "dynamic": {"window_samples": window, "hop_samples": hop, "windows": int(dyn.t.size),
                    "tau_s": dyn.tau.tolist(), "axes": summary_axes},
    }
    (out / "summary.json").write_text(json.dumps(summary, indent=1))
    print(f"\nwrote {out / 'adev.png'}, {out / 'davar.png'}, {out / 'summary.json'} "
          f"in {time.perf_counter() - t0:.1f} s")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="allanite", description=DESCRIPTION,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    from . import __version__

    parser.add_argument("--version", action="version", version=f"allanite {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    rep = sub.add_parser("report", help="Allan deviation table, DAVAR summary and plots",
                         description="Allan deviation table, dynamic Allan variance summary and plots.",
                         epilog=REPORT_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    rep.add_argument("log", nargs="?", metavar="LOG",
                     help=".npy (samples or samples × axes) or numeric text/CSV; default: the bundled record")
    rep.add_argument("--fs", type=float, metavar="HZ", help="sampling rate in Hz (required with LOG)")
    rep.add_argument("--unit", default="rate unit", help="unit of the samples, for labels (e.g. deg/s)")
    rep.add_argument("--window", type=int, metavar="N", help="DAVAR window in samples (default: 1/12 of the record)")
    rep.add_argument("--hop", type=int, metavar="N", help="DAVAR hop in samples (default: window/25)")
    rep.add_argument("--out", default="allanite-report", metavar="DIR", help="output folder (default: %(default)s)")
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 2
    try:
        return _report(args)
    except AllaniteError as exc:
        print(f"allanite: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
