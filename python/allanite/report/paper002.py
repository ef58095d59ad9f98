"""The report's paper-002 sections: a tapered DAVAR (``--taper hann``) and the wavelet split with the
window-function combination (``--split db5``).

``compute`` runs them per axis and returns a JSON-able dict (it goes into summary.json as
``"paper002"``); ``page_context`` shapes it into the page's tables; ``text_lines`` into the terminal
summary.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._validate import as_rate_columns
from ..analysis import davar
from ..combination import combine
from ..errors import AllaniteError
from ..model import fit as fit_model
from .fmt import g

__all__ = ["compute", "page_context", "text_lines"]

#: Terms fitted per window in these sections.
TERMS = ("Q", "N", "B", "K", "R")


def _spread(v: np.ndarray) -> dict:
    med = float(np.median(v))
    q1, q3 = np.percentile(v, [25, 75])
    return {"median": med, "iqr_rel": float((q3 - q1) / med) if med > 0 else None}


def _values(series) -> dict:
    """Coefficients per window in IEEE-952 units when the unit is known, else in base form."""
    return series.ieee if series.ieee is not None else series.values


def _fit_values(res, unit) -> dict:
    try:
        return _values(fit_model(res, unit=unit, tau_range="auto"))
    except AllaniteError:
        return _values(fit_model(res, unit=unit, tau_range="auto", thin=False))


def compute(x, fs, *, input, window, hop, taus, unit, axis_names, taper=None, split=None, notes=None) -> dict | None:
    """The sections asked for (``taper``: a taper name other than "rect"; ``split``: a wavelet name),
    per axis; failures become notes and an ``error`` entry, never an exception."""
    if not taper and not split:
        return None
    cols, fs, _ = as_rate_columns(x, fs, input)
    out: dict[str, Any] = {
        "taper": taper,
        "split": split,
        "window": int(window),
        "hop": int(hop),
        "units": "IEEE-952 units" if unit else "base form (unit unknown)",
        "axes": [],
    }
    for k, y in enumerate(cols):
        ax: dict[str, Any] = {"name": axis_names[k]}
        if taper:
            try:
                rect = davar(y, fs, window=window, hop=hop, taus=taus)
                tap = davar(y, fs, window=window, hop=hop, taus=rect.tau, taper=taper)
                vr, vt = _fit_values(rect, unit), _fit_values(tap, unit)
                ax["taper"] = {t: {"rect": _spread(vr[t]), taper: _spread(vt[t])} for t in vr}
            except AllaniteError as exc:
                ax["taper_error"] = str(exc)
                if notes is not None:
                    notes.append(f"{axis_names[k]}: the {taper} DAVAR section failed: {exc}")
        if split:
            try:
                c = combine(y, fs, window=window, hop=hop, split={"wavelet": split}, taus=taus, unit=unit)
                ax["combination"] = {
                    "bands": {b: {"levels": list(v["levels"]), "hz": list(v["hz"])} for b, v in c.split.bands.items()},
                    "cross_max_rel": float(np.max(np.abs(c.cross))),
                    "coefficients": {t: _spread(v) for t, v in _values(c.coefficients).items()},
                }
            except AllaniteError as exc:
                ax["combination_error"] = str(exc)
                if notes is not None:
                    notes.append(f"{axis_names[k]}: the wavelet-split section failed: {exc}")
        out["axes"].append(ax)
    return out


def _table(header, rows, left=1) -> dict:
    return {"header": list(header), "rows": [list(r) for r in rows], "left": left}


def _cell(s: dict) -> str:
    iqr = s["iqr_rel"]
    return f"{g(s['median'], 3)} ({'—' if iqr is None else f'{iqr:.2f}'})"


def page_context(p: dict | None) -> dict | None:
    """Tables for the page: coefficient medians (relative IQR) rect vs taper, and the combination."""
    if p is None:
        return None
    tables = []
    if p["taper"]:
        rows = []
        for ax in p["axes"]:
            if "taper" in ax:
                for t, d in ax["taper"].items():
                    rows.append([ax["name"], t, _cell(d["rect"]), _cell(d[p["taper"]])])
            else:
                rows.append([ax["name"], "failed", ax.get("taper_error", ""), ""])
        tables.append(
            _table(["axis", "term", "rect: median (IQR/median)", f"{p['taper']}: median (IQR/median)"], rows, 2)
        )
    if p["split"]:
        rows = []
        for ax in p["axes"]:
            c = ax.get("combination")
            if c is None:
                rows.append([ax["name"], "failed", ax.get("combination_error", ""), "", ""])
                continue
            bands = "; ".join(
                f"{b}: {'+'.join(v['levels']) or '—'} {g(v['hz'][0], 3)}–{g(v['hz'][1], 3)} Hz"
                for b, v in c["bands"].items()
            )
            coefs = "; ".join(f"{t} {_cell(s)}" for t, s in c["coefficients"].items())
            rows.append([ax["name"], bands, f"{c['cross_max_rel']:.3f}", coefs, ""])
        tables.append(
            _table(
                [
                    "axis",
                    "bands (trend dropped)",
                    "max |band cross term| / total",
                    "coefficients: median (IQR/median)",
                    "",
                ],
                rows,
                2,
            )
        )
    return {
        "taper": p["taper"],
        "split": p["split"],
        "window": p["window"],
        "hop": p["hop"],
        "units": p["units"],
        "tables": tables,
    }


def text_lines(p: dict | None) -> list[str]:
    """Lines for the terminal summary."""
    if p is None:
        return []
    lines = ["", f"Paper 002 sections (window {p['window']}, hop {p['hop']}; coefficients in {p['units']})"]
    for ax in p["axes"]:
        if "taper" in ax:
            parts = [f"{t} {_cell(d['rect'])} → {_cell(d[p['taper']])}" for t, d in ax["taper"].items()]
            lines.append(f"  {ax['name']} rect → {p['taper']}: " + "; ".join(parts))
        if "combination" in ax:
            c = ax["combination"]
            parts = [f"{t} {_cell(s)}" for t, s in c["coefficients"].items()]
            lines.append(
                f"  {ax['name']} {p['split']} split + combination (cross ≤ {c['cross_max_rel']:.3f}): "
                + "; ".join(parts)
            )
    return lines
