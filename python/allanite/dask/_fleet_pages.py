"""The fleet's outputs of :func:`allanite.dask.fleet.batch`: ``fleet.csv`` (and ``fleet.parquet`` when pyarrow is
installed), one row per sensor axis in :data:`COLUMNS`' order, and ``fleet.html``, the fleet's distributions of
N, B, K with the flagged and failed rows — each written to a temporary name and renamed into place."""

from __future__ import annotations

import base64
import csv
import io
import os
import uuid
from pathlib import Path

import numpy as np

#: |robust z| above which a sensor is flagged as outside the fleet's spread.
Z_FLAG = 3.5

#: The coefficients summarised per sensor axis.
TERMS = ("N", "B", "K")

#: The fleet table's columns, in order.
COLUMNS = (
    ["file", "axis", "sensor", "status", "error"]
    + [f"{t}{s}" for t in TERMS for s in ("", "_low", "_high", "_unit")]
    + ["effects", "still_missing"]
    + [f"z_{t}" for t in TERMS]
    + ["flag", "out"]
)


def atomic_write(path: Path, data: bytes) -> None:
    tmp = path.with_name(f".{path.name}.tmp-{uuid.uuid4().hex[:8]}")
    tmp.write_bytes(data)
    os.replace(tmp, path)


def write_table(rows: list, out: Path) -> dict:
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=COLUMNS, extrasaction="ignore", lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow({k: ("" if r.get(k) is None else r.get(k)) for k in COLUMNS})
    paths = {"csv": out / "fleet.csv"}
    atomic_write(paths["csv"], buf.getvalue().encode("utf-8"))
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        return paths
    table = pa.table({k: [r.get(k) for r in rows] for k in COLUMNS})
    sink = io.BytesIO()
    pq.write_table(table, sink)
    paths["parquet"] = out / "fleet.parquet"
    atomic_write(paths["parquet"], sink.getvalue())
    return paths


def _histograms(ok: list) -> str:
    """The base64 PNG of N, B, K's distributions over the rows ``ok``: one row of three histograms per unit the
    rows are in (a gyro's °/√h and an accelerometer's m/s/√h never share an axis), the flagged rows in red."""
    from matplotlib.figure import Figure

    units = sorted({r.get("N_unit") or "" for r in ok}) or [""]
    fig = Figure(figsize=(10, 3.2 * len(units)), dpi=100)
    for j, unit in enumerate(units):
        same = [r for r in ok if (r.get("N_unit") or "") == unit]
        for i, t in enumerate(TERMS):
            ax = fig.add_subplot(len(units), 3, 3 * j + i + 1)
            v = np.array([r[t] for r in same if r.get(t) is not None and r[t] > 0])
            flagged = np.array([r[t] for r in same if r.get(t) is not None and r[t] > 0 and t in r["flag"].split(",")])
            if v.size:
                bins = list(np.logspace(np.log10(v.min()) - 0.05, np.log10(v.max()) + 0.05, 20))
                ax.hist(v, bins=bins, color="0.6", label="fleet")
                if flagged.size:
                    ax.hist(flagged, bins=bins, color="C3", label="flagged")
                ax.set_xscale("log")
            t_unit = next((r[f"{t}_unit"] for r in same if r.get(f"{t}_unit")), "")
            ax.set_title(f"{t} ({t_unit})" if t_unit else t)
            ax.set_ylabel("sensor axes" if i == 0 else "")
    fig.tight_layout()
    png = io.BytesIO()
    fig.savefig(png, format="png")
    return base64.b64encode(png.getvalue()).decode("ascii")


def write_html(rows: list, files: list, out: Path) -> Path:
    """``out/fleet.html``: the distributions of N, B, K (a row per unit), the flagged, the failed and all rows."""
    from html import escape

    ok = [r for r in rows if r["status"] != "error"]
    img = _histograms(ok)
    flagged_rows = [r for r in rows if r.get("flag")]
    failed = [f for f in files if f["status"] == "error"]

    def table(rs, cols):
        head = "".join(f"<th>{escape(c)}</th>" for c in cols)
        body = "".join(
            "<tr>" + "".join(f"<td>{escape('' if r.get(c) is None else str(r.get(c)))}</td>" for c in cols) + "</tr>"
            for r in rs
        )
        return f"<table><tr>{head}</tr>{body}</table>"

    page = (
        "<!doctype html><meta charset='utf-8'><title>allanite fleet</title>"
        "<style>body{font-family:sans-serif;margin:2em}td,th{padding:2px 8px;border-bottom:1px solid #ddd}</style>"
        f"<h1>Fleet: {len(files)} files, {len(ok)} sensor axes</h1>"
        f"<p>{len(failed)} failed; {len(flagged_rows)} axes flagged (|robust z| of log10 N, B or K > {Z_FLAG}).</p>"
        f"<img alt='distributions of N, B, K' src='data:image/png;base64,{img}'>"
        "<h2>Flagged</h2>" + table(flagged_rows, ["file", "axis", "N", "B", "K", "z_N", "z_B", "z_K", "flag"]) + ""
        "<h2>Failed</h2>" + table(failed, ["path", "error"]) + "<h2>All</h2>" + table(rows, COLUMNS[:-1])
    )
    path = out / "fleet.html"
    atomic_write(path, page.encode("utf-8"))
    return path
