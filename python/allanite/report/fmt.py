"""Numbers for the report: JSON-safe values and short text forms."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["json_number", "json_list", "json_value", "json_interval", "g", "param_text", "pct", "duration"]


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


def json_value(v):
    """A parameter as JSON: a string as it is, a list as an array of JSON values, a number as
    :func:`json_number` (an int stays an int)."""
    if isinstance(v, str):
        return v
    if isinstance(v, (list, tuple, np.ndarray)):
        return [json_value(x) for x in v]
    return json_number(v)


def json_interval(iv):
    """An interval as JSON: ``[low, high]``, or, for a list parameter, one ``[low, high]`` per entry."""
    if len(iv) and isinstance(iv[0], (list, tuple, np.ndarray)):
        return [json_interval(x) for x in iv]
    return [json_number(iv[0]), json_number(iv[1])]


def param_text(v, interval=None, d: int = 3) -> str:
    """A parameter as text with its interval if it has one: a string as it is, an int as an int, a number as
    ``value [low, high]``, a list as ``[a [lo, hi], b [lo, hi]]``."""
    if isinstance(v, (list, tuple, np.ndarray)):
        ivs = list(interval) if interval is not None else [None] * len(v)
        return "[" + ", ".join(param_text(x, iv, d) for x, iv in zip(v, ivs)) + "]"
    if isinstance(v, str):
        return v
    if isinstance(v, (bool, int, np.integer)):
        return str(int(v))
    if interval is None:
        return g(v, d)
    return f"{g(v, d)} [{g(interval[0], d)}, {g(interval[1], d)}]"


def g(v, d: int = 4) -> str:
    if v is None:
        return "—"
    if isinstance(v, float) and math.isinf(v):
        return "∞"
    return f"{v:.{d}g}"


def pct(v, b) -> str:
    if v is None or b is None or v == 0:
        return "?"
    p = abs(b / v - 1.0) * 100.0
    return f"{p:.1f}" if p < 9.95 else f"{p:.0f}"


def duration(s: float) -> str:
    if s >= 3600:
        return f"{s / 3600:.3g} h"
    if s >= 60:
        return f"{s / 60:.3g} min"
    return f"{s:.4g} s"
