"""The unit of a time column: given (``time_unit=``), named (``time_ns``), read from an epoch's magnitude, or
seconds — and the plausibility rule that keeps a time column in ms read as seconds from giving a silent wrong fs.

The rule, applied only when neither ``time_unit=`` nor the column's name gives the unit:

1. **Epoch magnitudes name their unit.** A first time stamp that reads as a date in 2001–2286 in exactly one
   unit — 10⁹–10¹⁰ s (≈ 1.7·10⁹ now), 10¹²–10¹³ ms, 10¹⁵–10¹⁶ µs, 10¹⁸–10¹⁹ ns — is read in that unit, when its
   median step then gives a rate over 1 Hz and up to 10 MHz (:data:`PLAUSIBLE_FS`; ``Log.time_unit_source`` says
   so).
2. Otherwise the times are seconds. **A span over** :data:`MAX_SPAN_S` **(10 years)** read so is implausible for
   any log: an :class:`~allanite.errors.InputError` naming the value, what it reads as in ms, µs and ns, and
   ``time_unit=``.
3. **Stamps over 10¹¹ s** (3000 years) that are no epoch and span less: a warning, as below. **A rate below 1 Hz
   over more than** :data:`SLOW_ROWS` **rows** (over 2.8 h of a slow logger — or a time column
   in ms, 0, 10, 20 … at 100 Hz, read as 0.1 Hz): a warning naming the step, the rate it gives, what it gives in
   ms and µs, and ``time_unit=`` (``time_unit="s"`` keeps seconds without it).
"""

from __future__ import annotations

import warnings

import numpy as np

from ..errors import InputError
from ._columns import Record, time_unit_of
from .log import TIME_UNITS

#: Rates (Hz) an epoch reading must give to be taken: over 1 Hz, at most 10 MHz. A slower reading is more likely
#: the next smaller unit counted from another origin — ns from boot, 10¹² (16 min) at 200 Hz, read as epoch ms would
#: give 0.2 Hz — and is left to rules 2–3 (epoch seconds at 1 Hz read as seconds all the same).
PLAUSIBLE_FS = (1.0, 1e7)
#: A time column read as seconds may span at most this long (10 years, s).
MAX_SPAN_S = 10 * 365.25 * 86400.0
#: More rows than this at under 1 Hz (read as seconds) make the warning of rule 3.
SLOW_ROWS = 10_000
#: The first time stamp in seconds of an epoch date in 2001–2286.
_EPOCH_S = (1e9, 1e10)


def _median_step(t: np.ndarray) -> float:
    """The median step of the first 10⁴ + 1 times (enough to tell a unit; the reader's fs comes later)."""
    head = np.diff(t[: SLOW_ROWS + 1])
    return float(np.median(head)) if head.size else 0.0


def _epoch_unit(t0: float, step: float) -> str | None:
    """The unit in which ``t0`` reads as an epoch date in 2001–2286 and ``step`` as a plausible rate, or None."""
    for unit, factor in TIME_UNITS.items():
        if _EPOCH_S[0] <= abs(t0) * factor < _EPOCH_S[1]:
            fs = 1.0 / (step * factor) if step > 0 else 0.0
            return unit if PLAUSIBLE_FS[0] < fs <= PLAUSIBLE_FS[1] else None
    return None


def _readings(step: float) -> str:
    """What a step reads as in ms, µs and ns: "in ms 100 Hz, in us 1e+05 Hz, in ns 1e+08 Hz"."""
    return ", ".join(f"in {u}: {1.0 / (step * TIME_UNITS[u]):.6g} Hz" for u in ("ms", "us", "ns"))


def _likely(step: float) -> str:
    """The first of ms, us, ns in which ``step`` gives 1 Hz to 100 kHz (ms where none does): the unit suggested."""
    return next((u for u in ("ms", "us", "ns") if 1.0 <= 1.0 / (step * TIME_UNITS[u]) <= 1e5), "ms")


def time_unit(path, rec: Record, given: str | None) -> tuple[str, str]:
    """(unit, where it came from) of the record's time column — ``given``, its name, an epoch's magnitude or
    seconds by default (the module's rule, whose warnings and errors name the column, the value and
    ``time_unit=``). The times are scaled to seconds in place where the record owns them."""
    if given is not None:
        unit, source = given, "time_unit="
    elif (named := time_unit_of(rec.time_name)) is not None:
        unit, source = named, "its name"
    else:
        unit, source = _by_magnitude(path, rec)
    factor = TIME_UNITS[unit]
    t = rec.time
    assert t is not None
    if factor != 1.0:
        if rec.time_owned and t.dtype == np.float64:
            t *= factor
        else:
            rec.time = t * factor
    return unit, source


def _by_magnitude(path, rec: Record) -> tuple[str, str]:
    """(unit, source) of a time column whose unit nothing gives: rules 1–3 of the module."""
    t = rec.time
    assert t is not None
    if t.size < 2:
        return "s", "default"
    t0, step = float(t[0]), _median_step(t)
    epoch = _epoch_unit(t0, step)
    if epoch is not None:
        return epoch, "epoch magnitude"
    span = float(t[-1]) - t0
    name = rec.time_name
    if span > MAX_SPAN_S:
        raise InputError(
            f"{path}: time column {name!r} spans {span:.6g} (from {t0:.6g}) — {span / MAX_SPAN_S * 10:.3g} years "
            f"read as seconds, which no log spans; its median step {step:.6g} reads {_readings(step)}: give its unit, "
            f"time_unit='{_likely(step)}' (or 'ms', 'us', 'ns', 's')"
        )
    if max(abs(t0), abs(float(t[-1]))) > 1e11:  # a short span of huge stamps: ms, µs or ns from another origin
        warnings.warn(
            f"{path}: time column {name!r} reads {float(t[-1]):.6g} s (over 3000 years) as seconds; its median step "
            f"{step:.6g} reads {_readings(step)} — give its unit, time_unit='{_likely(step)}' (--time-unit "
            f"{_likely(step)})",
            stacklevel=4,
        )
    elif step > 1.0 and t.size > SLOW_ROWS:
        whole = bool(np.all(np.diff(t[: SLOW_ROWS + 1]) % 1.0 == 0.0))
        warnings.warn(
            f"{path}: time column {name!r} names no unit and is read as seconds: its median step "
            f"{step:.6g}{' (integer steps)' if whole else ''} gives fs = {1.0 / step:.6g} Hz over {t.size} rows "
            f"({span / 3600:.3g} h); {_readings(step)} — give its unit if it is not seconds, time_unit="
            f"'{_likely(step)}' (--time-unit {_likely(step)}; time_unit='s' keeps seconds without this warning)",
            stacklevel=4,
        )
    return "s", "default"
