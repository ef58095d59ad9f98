"""Per-window series too long for ``summary.json``, written beside it.

A report of more than :data:`~allanite.report.budget.SIDE_FILE_WINDOWS` DAVAR windows keeps its per-window
numbers — window centres, and per axis each coefficient's value, interval and IEEE-952 value and interval,
χ²/dof — out of ``summary.json`` (a hop-1 report would make it hundreds of megabytes of JSON) and in
``series.npz`` (always; ``numpy.load``) and ``series.parquet`` (where pyarrow is installed), one column
per series. ``summary.json`` names them under ``"side_files"``, with the columns and what they hold; its
statistics (median, min, max and where) stay in the JSON.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np

from ..units import report_unit
from .budget import SIDE_FILE_WINDOWS

__all__ = ["NPZ", "PARQUET", "uses_side_files", "side_files_entry", "series_columns", "write_side_files"]

#: File name of the per-window series in NumPy's ``.npz`` format (always written; ``numpy.load``).
NPZ = "series.npz"
#: File name of the same series as a Parquet table (written where pyarrow is installed).
PARQUET = "series.parquet"


def uses_side_files(rep) -> bool:
    """Whether the report's per-window series go to side files (more than SIDE_FILE_WINDOWS windows)."""
    return int(rep.dynamic.t.size) > SIDE_FILE_WINDOWS


def _parquet_available() -> bool:
    return importlib.util.find_spec("pyarrow") is not None


def series_columns(rep) -> dict:
    """Column name → array over the windows: ``t_s``, then ``axis{k}_chi2_dof`` and
    ``axis{k}_{term}_{value|ci_low|ci_high}`` (base form) and, with a known unit,
    ``axis{k}_{term}_{ieee|ieee_ci_low|ieee_ci_high}``."""
    cols = {"t_s": np.asarray(rep.dynamic.t, dtype=np.float64)}
    for k, s in enumerate(rep.series or ()):
        cols[f"axis{k}_chi2_dof"] = np.asarray(s.chi2_dof, dtype=np.float64)
        for t in s.terms:
            v, lo, hi = (np.asarray(a, dtype=np.float64) for a in (s.values[t], s.ci_low[t], s.ci_high[t]))
            cols.update({f"axis{k}_{t}_value": v, f"axis{k}_{t}_ci_low": lo, f"axis{k}_{t}_ci_high": hi})
            if s.unit is not None:  # a gyro's IEEE-952 units, or an accelerometer's report units
                for name, a in (("ieee", v), ("ieee_ci_low", lo), ("ieee_ci_high", hi)):
                    cols[f"axis{k}_{t}_{name}"] = np.asarray(report_unit(t, a, s.unit).value, dtype=np.float64)
    return cols


def side_files_entry(rep) -> dict:
    """What ``summary.json`` says under ``"side_files"`` (the files are written by :func:`write_side_files`)."""
    s0 = rep.series[0] if rep.series else None
    return {
        "series": {
            "npz": NPZ,
            "parquet": PARQUET if _parquet_available() else None,
            "windows": int(rep.dynamic.t.size),
            "why": f"more than {SIDE_FILE_WINDOWS} DAVAR windows: the per-window series are kept out of summary.json",
            "columns": list(series_columns(rep)),
            "axes": {f"axis{k}": name for k, name in enumerate(rep.axis_names)},
            "terms": None if s0 is None else list(s0.terms),
            "units": "t_s in s; value/ci_* in the base form of each coefficient's unit (fit.series.axes[k]"
            ".coefficients[term].unit), ieee* in IEEE-952 units or an accelerometer's (….ieee_unit); ci_high may "
            "be inf (no upper bound)",
        }
    }


def write_side_files(rep, out: Path) -> list[Path]:
    """Write the side files into folder ``out``; returns their paths."""
    cols = series_columns(rep)
    paths = [out / NPZ]
    np.savez(paths[0], **cols)
    if _parquet_available():
        import pyarrow as pa
        import pyarrow.parquet as pq

        pq.write_table(pa.table(cols), out / PARQUET)
        paths.append(out / PARQUET)
    return paths
