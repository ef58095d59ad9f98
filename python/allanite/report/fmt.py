"""Numbers for the report: JSON-safe values and short text forms."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["json_number", "json_list", "g", "pct", "duration"]


def json_number(v):
    """A JSON number: Python float/int, ``None`` for NaN/inf/None (JSON has no infinity)."""
    if v is None:
        return None
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, (int, np.integer)):
        return int(v)
    v = float(v)
    return v if math.isfinite(v) else None


def json_list(a):
    """Nested lists of JSON numbers (exact doubles; non-finite → None)."""
    a = np.asarray(a)
    if a.dtype.kind in "iub":
        return a.tolist()
    a = a.astype(np.float64)
    if np.all(np.isfinite(a)):
        return a.tolist()
    return [json_list(r) for r in a] if a.ndim > 1 else [json_number(v) for v in a]


def g(v, d: int = 4) -> str:
    """A number with ``d`` significant digits; "—" for None, "∞" for infinity."""
    if v is None:
        return "—"
    if isinstance(v, float) and math.isinf(v):
        return "∞"
    return f"{v:.{d}g}"


def pct(v, b) -> str:
    """How far the bound ``b`` is from the value ``v``, in percent; "?" when either is missing or v is 0."""
    if v is None or b is None or v == 0:
        return "?"
    p = abs(b / v - 1.0) * 100.0
    return f"{p:.1f}" if p < 9.95 else f"{p:.0f}"


def duration(s: float) -> str:
    """A duration in seconds as h, min or s."""
    if s >= 3600:
        return f"{s / 3600:.3g} h"
    if s >= 60:
        return f"{s / 60:.3g} min"
    return f"{s:.4g} s"
