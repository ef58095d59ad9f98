"""A column's unit from its name: the small grammar :func:`~allanite.io.read_log` reads units in.

A name gives a unit in one of two ways (case-insensitive):

* in brackets or parentheses at its end — ``w_RS_S_x [rad s^-1]`` (EuRoC, TUM-VI, Kalibr), ``gyro_x (deg/s)``,
  ``a [m/s^2]``, ``acc_z [g]``, ``wx [°/s]``, ``gz [mdps]``, ``rate (µrad/s)``. Inside, a unit is one that
  :func:`allanite.units.parse_unit` takes (a gyro's rate or angle unit) or an accelerometer's
  (:data:`allanite.units.ACCEL_UNITS`: ``m/s^2``, ``mm/s^2``, ``g``, ``mg``, ``ug``); a power of a unit may be
  written with ``^-1``, ``-1``, ``⁻¹`` and the factors separated by spaces, ``.``, ``·`` or ``*``
  (``rad s^-1`` = ``rad/s``, ``m.s-2`` = ``m s⁻²`` = ``m/s^2``);
* after its last ``_``, one of the unambiguous suffixes :data:`SUFFIXES` (``gx_dps``, ``gyro_z_rads``,
  ``acc_x_mps2``).

Anything else — no bracket, a bracketed word that is no such unit (``[counts]``, ``[LSB]``, a temperature's
``[degC]``) — gives no unit. The kinds: ``"rate"`` and ``"angle"`` (a gyro's), ``"acceleration"``.
"""

from __future__ import annotations

import re
import warnings
from typing import NamedTuple

from ..errors import ParameterError
from ..units import ACCEL_UNITS, accel_factor, parse_unit

__all__ = ["ColumnUnit", "column_unit", "units_of", "SUFFIXES"]

#: Suffixes after a name's last ``_`` that name a unit: suffix → unit.
SUFFIXES = {
    "dps": "deg/s",
    "degps": "deg/s",
    "mdps": "mdeg/s",
    "dph": "deg/h",
    "rads": "rad/s",
    "radps": "rad/s",
    "mradps": "mrad/s",
    "mps2": "m/s^2",
    "mss": "m/s^2",
}

_BRACKETED = re.compile(r"[\[(]\s*([^\])]*?)\s*[\])]\s*$")
_SUPERSCRIPTS = str.maketrans({"⁻": "-", "¹": "1", "²": "2", "³": "3", "·": " ", "*": " ", "⋅": " "})
_POWER = re.compile(r"^([a-zµμ°]+)\^?(-?\d)$")


class ColumnUnit(NamedTuple):
    """A unit read from a column's name: its canonical name (``"rad/s"``, ``"m/s^2"``), its kind (``"rate"``,
    ``"angle"`` or ``"acceleration"``) and the text it was read from (``"[rad s^-1]"``)."""

    name: str
    kind: str
    text: str


def _as_quotient(text: str) -> str:
    """``rad s^-1`` → ``rad/s``, ``m.s-2`` → ``m/s^2``: factors with negative powers moved under a ``/``; a text
    without such factors is returned as it is."""
    s = text.translate(_SUPERSCRIPTS)
    s = re.sub(r"(?<=[a-z°])\.(?=[a-z])", " ", s, flags=re.IGNORECASE)
    parts = s.split()
    if len(parts) < 2:
        return text
    num: list[str] = []
    den: list[str] = []
    for p in parts:
        m = _POWER.match(p.lower())
        if m is None:
            num.append(p)
            continue
        base, power = m.group(1), int(m.group(2))
        (den if power < 0 else num).append(base if abs(power) == 1 else f"{base}^{abs(power)}")
    if not den or len(den) > 1:
        return text
    return f"{' '.join(num)}/{den[0]}"


def _known(text: str) -> tuple[str, str] | None:
    """(canonical name, kind) of a unit's text, or None when it names none."""
    for cand in dict.fromkeys((text, _as_quotient(text))):
        try:
            u = parse_unit(cand)
        except ParameterError:
            pass
        else:
            return u.name, u.kind
        key = cand.replace(" ", "")
        try:
            factor = accel_factor(key)
        except ParameterError:
            continue
        return next(n for n in ACCEL_UNITS if accel_factor(n) == factor), "acceleration"
    return None


#: ``rostopic echo -p``'s columns of a sensor_msgs/Imu, whose units REP 103 fixes (rad/s, m/s²).
_ROS_FIELD = re.compile(r"field\.(angular_velocity|linear_acceleration)\.[xyz]")


def column_unit(name) -> ColumnUnit | None:
    """The unit a column's name gives (the module's grammar), or None.

    >>> [column_unit(c).name for c in ("w_RS_S_x [rad s^-1]", "a_RS_S_z [m s^-2]", "gx (deg/s)", "gz_dps", "a [g]")]
    ['rad/s', 'm/s^2', 'deg/s', 'deg/s', 'g']
    >>> column_unit("field.angular_velocity.x").name, column_unit("field.linear_acceleration.z").name  # rostopic -p
    ('rad/s', 'm/s^2')
    >>> column_unit("gx") is None, column_unit("T [degC]") is None
    (True, True)
    """
    if not isinstance(name, str):
        return None
    ros = _ROS_FIELD.fullmatch(name.strip())
    if ros is not None:  # rostopic echo -p of a sensor_msgs/Imu: its units by REP 103
        hit = _known("rad/s" if ros.group(1) == "angular_velocity" else "m/s^2")
        assert hit is not None
        return ColumnUnit(hit[0], hit[1], "sensor_msgs/Imu, REP 103")
    m = _BRACKETED.search(name)
    if m is not None and m.group(1):
        hit = _known(m.group(1))
        if hit is not None:
            return ColumnUnit(hit[0], hit[1], name[m.start() :].strip())
        return None
    stem, sep, suffix = name.strip().rpartition("_")
    if sep and stem and suffix.lower() in SUFFIXES:
        unit = SUFFIXES[suffix.lower()]
        hit = _known(unit)
        assert hit is not None
        return ColumnUnit(hit[0], hit[1], "_" + suffix)
    return None


def units_of(path, names, given, input, ros=False) -> tuple:
    """(``Log.unit``, ``Log.unit_source``, ``Log.column_units``) of sample columns ``names``: the unit ``given``
    (``unit=``; a warning when the header names another for a column — ``unit=`` wins), else a ROS bag's rad/s
    (REP 103), else the unit every column's name gives when they all give the same one of the kind ``input`` needs
    (a rate; an angle for increments or angles), else None (no unit, or columns of several: ``Log.groups``)."""
    cols = [column_unit(c) for c in names]
    if given is not None:
        other = [(c, cu) for c, cu in zip(names, cols) if cu is not None and cu.name != given.name]
        if not other:
            return given, "given as unit=", cols
        shown = ", ".join(f"{c!r} ({cu.name})" for c, cu in other[:4]) + (", …" if len(other) > 4 else "")
        warnings.warn(
            f"{path}: unit={given.name!r} was given, but the header names another unit for column(s) {shown}: the "
            f"samples are read in {given.name} (unit= wins; leave it out to take the header's)",
            stacklevel=3,
        )
        said = ", ".join(dict.fromkeys(cu.name for _, cu in other))
        return given, f"given as unit=, overriding the header's {said}", cols
    if ros and input == "rate":
        return parse_unit("rad/s"), "ROS convention (REP 103)", cols
    need = "rate" if input == "rate" else "angle"
    found = {cu.name for cu in cols if cu is not None}
    first = cols[0] if cols else None
    if first is not None and len(found) == 1 and all(cu is not None and cu.kind == need for cu in cols):
        return parse_unit(first.name), f"from the column names: {first.text}", cols
    return None, None, cols
