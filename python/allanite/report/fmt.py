"""Numbers for the report: JSON-safe values and short text forms."""

from __future__ import annotations

import math

import numpy as np

from ..model.effects import format_param

__all__ = [
    "json_number",
    "json_list",
    "json_value",
    "g",
    "num",
    "pct",
    "duration",
    "clock",
    "time_decimals",
    "step_params",
    "LONG_RECORD_S",
    "count",
    "CLOCK_TERMS",
]

#: Said beside a fit whose unit is unknown (a clock's fractional frequency among such logs): the IEEE-952 terms'
#: names are a gyro's, their τ laws those of the frequency-stability noise types (Riley, NIST SP 1065) — R²τ²/2
#: is a linear frequency drift's Allan variance exactly.
CLOCK_TERMS = (
    "for a clock's fractional frequency the same terms are Q ↔ white/flicker PM, N ↔ white FM, B ↔ flicker FM, "
    "K ↔ random-walk FM, R ↔ linear frequency drift"
)


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
    """A JSON value of an effect's parameter: a string as it is, an int as an int, a float as
    :func:`json_number`, a list or tuple element by element."""
    if isinstance(v, str) or v is None:
        return v
    if isinstance(v, (list, tuple, np.ndarray)):
        return [json_value(e) for e in v]
    return json_number(v)


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
    if 0 < p < 0.095:  # one significant digit: "0.0" read as an interval of no width (10⁷ samples: ±0.03 %)
        return f"{p:.1g}"
    return f"{p:.1f}" if p < 9.95 else f"{p:.0f}"


def duration(s: float) -> str:
    """A duration in seconds as h, min or s."""
    if s >= 3600:
        return f"{s / 3600:.3g} h"
    if s >= 60:
        return f"{s / 60:.3g} min"
    return f"{s:.4g} s"


def num(v, d: int = 3) -> str:
    """At most ``d`` significant digits (no trailing zeros), in positional notation between 10⁻³ and
    10⁵ (1200 s is "1200", not "1.2e+03"); scientific outside it."""
    if v is None:
        return "—"
    v = float(v)
    if not math.isfinite(v):
        return "∞" if v > 0 else ("−∞" if v < 0 else "nan")
    if v == 0 or not 1e-3 <= abs(v) < 1e5:
        return f"{v:.{d}g}"
    decimals = max(0, d - 1 - math.floor(math.log10(abs(v))))
    text = f"{v:.{decimals}f}"
    return text.rstrip("0").rstrip(".") if "." in text else text


def time_decimals(fs) -> int:
    """Decimals of seconds that resolve one sample at ``fs`` Hz (0 at ≤ 1 Hz, 2 at 100 Hz, at most 6)."""
    if fs is None or not fs > 0:
        return 3
    return int(min(6, max(0, math.ceil(math.log10(fs) - 1e-9))))


def clock(t, fs=None, long: bool = False, unit: bool = True) -> str:
    """A time along the record, to the sample: seconds (``"1200.00 s"`` at 100 Hz; ``unit=False``
    leaves out " s"), or ``h:mm:ss`` with the same fraction for a long record (``long``; e.g.
    ``"2:13:20.45"``)."""
    if t is None:
        return "—"
    d = time_decimals(fs)
    t = float(t)
    if not long:
        return f"{t:.{d}f}" + (" s" if unit else "")
    sign = "−" if t < 0 else ""
    t = round(abs(t), d)
    h, rest = divmod(t, 3600.0)
    m, sec = divmod(rest, 60.0)
    width = 2 + (d + 1 if d else 0)
    return f"{sign}{int(h)}:{int(m):02d}:{sec:0{width}.{d}f}"


#: A record longer than this (s) gives its times along the record as h:mm:ss.
LONG_RECORD_S = 3600.0


def step_params(st: dict, fs, duration_s, *, units: bool = False, intervals: bool = False, final: bool = False) -> str:
    """The parameters of a refinement step (one ``summary.json`` step) as ``"p = v [lo, hi] unit"``
    joined by "; " — at acceptance, or after the final joint refit (``final``). The time of a change point is a
    time along the record, to the sample (:func:`clock`); strings, ints and lists (one interval per entry) as
    :func:`allanite.model.effects.format_param` writes them."""
    long = duration_s is not None and duration_s > LONG_RECORD_S
    use_final = final and st.get("final_params")
    pkey, ikey = ("final_params", "final_intervals") if use_final else ("params", "intervals")
    parts = []
    for p, v in st[pkey].items():
        unit = (st.get("units", {}).get(p) or "") if units else ""
        iv = st.get(ikey, {}).get(p) if intervals else None
        if st.get("statistic") == "window_levels" and p == "t" and not isinstance(v, (str, list)):
            text = clock(v, fs, long, unit=units)
            if iv is not None:
                text += f" [{clock(iv[0], fs, long, unit=False)}, {clock(iv[1], fs, long, unit=False)}]"
            parts.append(f"{p} = {text}")
        else:
            parts.append(format_param(p, v, iv, unit, 3))
    return "; ".join(parts)


def count(n: int, one: str, many: str) -> str:
    """``"1 axis"``, ``"3 axes"``."""
    return f"{n} {one if n == 1 else many}"
