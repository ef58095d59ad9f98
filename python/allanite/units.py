"""Units of gyro samples and of the Allan-model coefficients reported from them (IEEE Std 952).

Samples are either a *rate* (°/s, rad/s, °/h, …) or an *angle* (°, rad, arcsec, … — per-sample
increments or cumulative angle). Every unit is stored with its factor to degrees (angles) or degrees
per second (rates), so any two units of the same kind convert through that base.

Allan-model coefficients come out of a fit in the samples' own unit and seconds ("base form"): with
samples in a rate unit u,

====  =========================  ==============  ========================
term  meaning                    base form       IEEE-952 report (default)
====  =========================  ==============  ========================
Q     angle quantization         u·s             °  (also arcsec, µrad)
N     angle random walk          u·√s            °/√h      (×60 for °/s)
B     bias instability           u               °/h       (×3600)
K     rate random walk           u/√s            °/h^1.5   (×216000)
R     rate ramp                  u/s             °/h²      (×1.296e7)
====  =========================  ==============  ========================

(docs/FORMULAS.md §4.2: N[°/√h] = 60·N[°/√s], B[°/h] = 3600·B[°/s], K[°/h^1.5] = 216000·K[°/s^1.5],
R[°/h²] = 1.296e7·R[°/s²], Q[arcsec] = 3600·Q[°].) When the samples are angles (``input=
"increment"`` or ``"angle"``), the Allan deviation is in that angle per second and the same table
applies to the rate unit angle/s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from .errors import ParameterError

__all__ = [
    "Unit",
    "Quantity",
    "parse_unit",
    "rate_unit",
    "convert",
    "to_deg_per_s",
    "ieee952",
    "adev_unit_label",
    "coefficient_unit",
    "RATE_UNITS",
    "ANGLE_UNITS",
    "IEEE952_TERMS",
    "STANDARD_GRAVITY",
    "ACCEL_UNITS",
    "accel_factor",
    "ACCEL_LABELS",
    "ACCEL_TERMS",
    "accel_report_unit",
    "accel_unit_name",
    "check_sensor_unit",
    "report_unit",
]


@dataclass(frozen=True)
class Unit:
    """A unit of gyro samples.

    Attributes
    ----------
    name : str
        Canonical spelling, e.g. ``"deg/s"``, ``"urad/s"``, ``"arcsec"``.
    kind : {"rate", "angle"}
    factor : float
        Size of one unit in degrees (angles) or degrees per second (rates).
    label : str
        Typographic form for plots and reports, e.g. ``"°/s"``, ``"µrad/s"``.
    """

    name: str
    kind: str
    factor: float
    label: str

    def __str__(self) -> str:
        return self.name


_RAD = 180.0 / math.pi

# canonical name: (kind, factor to deg or deg/s, label, aliases). Aliases are matched after
# normalisation (lower case, no spaces, µ/μ → u, "sec" → "s", "hr"/"hour" → "h", "degree(s)" → "deg").
_TABLE = {
    # rates
    "deg/s": ("rate", 1.0, "°/s", ("°/s", "dps", "deg/s")),
    "deg/h": ("rate", 1.0 / 3600.0, "°/h", ("°/h", "dph")),
    "mdeg/s": ("rate", 1e-3, "m°/s", ("mdps",)),
    "rad/s": ("rate", _RAD, "rad/s", ()),
    "mrad/s": ("rate", 1e-3 * _RAD, "mrad/s", ()),
    "urad/s": ("rate", 1e-6 * _RAD, "µrad/s", ()),
    "arcsec/s": ("rate", 1.0 / 3600.0, "arcsec/s", ('"/s', "asec/s")),
    "rev/s": ("rate", 360.0, "rev/s", ("rps",)),
    "rpm": ("rate", 6.0, "rpm", ("rev/min", "r/min")),
    # angles (increments or cumulative angle)
    "deg": ("angle", 1.0, "°", ("°",)),
    "mdeg": ("angle", 1e-3, "m°", ()),
    "rad": ("angle", _RAD, "rad", ()),
    "mrad": ("angle", 1e-3 * _RAD, "mrad", ()),
    "urad": ("angle", 1e-6 * _RAD, "µrad", ()),
    "arcmin": ("angle", 1.0 / 60.0, "arcmin", ("'",)),
    "arcsec": ("angle", 1.0 / 3600.0, "arcsec", ('"', "asec")),
    "rev": ("angle", 360.0, "rev", ()),
}

_UNITS = {name: Unit(name, kind, factor, label) for name, (kind, factor, label, _) in _TABLE.items()}

#: Canonical names of the accepted rate units.
RATE_UNITS = tuple(n for n, u in _UNITS.items() if u.kind == "rate")
#: Canonical names of the accepted angle units.
ANGLE_UNITS = tuple(n for n, u in _UNITS.items() if u.kind == "angle")

# angle unit → the rate unit "that angle per second"
_RATE_OF = {
    "deg": "deg/s",
    "mdeg": "mdeg/s",
    "rad": "rad/s",
    "mrad": "mrad/s",
    "urad": "urad/s",
    "arcsec": "arcsec/s",
    "rev": "rev/s",
}


def _normalise(s: str) -> str:
    s = s.strip().lower().replace(" ", "").replace("\u00b5", "u").replace("\u03bc", "u")
    s = s.replace("micro", "u").replace("milli", "m")
    s = s.replace("degrees", "deg").replace("degree", "deg").replace("radians", "rad").replace("radian", "rad")
    s = s.replace("arcseconds", "arcsec").replace("arcsecond", "arcsec")
    s = s.replace("arcminutes", "arcmin").replace("arcminute", "arcmin")
    s = s.replace("revolutions", "rev").replace("revolution", "rev")
    for long, short in (("/second", "/s"), ("/sec", "/s"), ("/hour", "/h"), ("/hr", "/h"), ("/minute", "/min")):
        if s.endswith(long):
            s = s[: -len(long)] + short
    return s


_ALIASES: dict = {}
for _name, (_kind, _f, _label, _aliases) in _TABLE.items():
    for _a in (_name, _label) + _aliases:
        _ALIASES[_normalise(_a)] = _name


#: Said after the allowed units: the units are a gyro's; an accelerometer's are their own (:data:`ACCEL_UNITS`,
#: taken by fit, refine and build_report); any other sensor's samples are analysed with no unit, the terms then
#: in the samples' own unit and seconds.
_OTHER_SENSORS = (
    " (a gyro's; an accelerometer's m/s^2, g, mg, … are taken by fit, refine and build_report as its own; for a "
    "magnetometer or another sensor give no unit: the terms are then in the samples' own unit and seconds)"
)


def _allowed(kind=None) -> str:
    rates = ", ".join(RATE_UNITS)
    angles = ", ".join(ANGLE_UNITS)
    if kind == "rate":
        return f"rate units: {rates}"
    if kind == "angle":
        return f"angle units: {angles}"
    return f"rate units: {rates}; angle units: {angles}"


def parse_unit(s, kind=None) -> Unit:
    """The :class:`Unit` a string names (a :class:`Unit` is returned as is).

    Parameters
    ----------
    s : str or Unit
        ``"deg/s"`` (also ``"°/s"``, ``"dps"``), ``"rad/s"``, ``"deg/h"`` (``"°/h"``, ``"dph"``),
        ``"mdeg/s"``, ``"mrad/s"``, ``"urad/s"`` (``"µrad/s"``), ``"arcsec/s"``, ``"rev/s"``,
        ``"rpm"``; angles ``"deg"``, ``"mdeg"``, ``"rad"``, ``"mrad"``, ``"urad"``, ``"arcmin"``,
        ``"arcsec"``, ``"rev"``. Case and spaces do not matter; ``"/sec"`` and ``"/hr"`` are accepted.
    kind : {"rate", "angle"}, optional
        Require this kind.

    Raises
    ------
    ParameterError
        Unknown unit, or a unit of the other kind; the message lists the allowed units.

    Examples
    --------
    >>> from allanite.units import parse_unit
    >>> parse_unit("°/h")
    Unit(name='deg/h', kind='rate', factor=0.0002777777777777778, label='°/h')
    >>> parse_unit("µrad").name
    'urad'
    """
    if kind is not None and kind not in ("rate", "angle"):
        raise ParameterError(f"unknown unit kind {kind!r}; allowed: 'rate', 'angle'")
    if isinstance(s, Unit):
        unit = s
    elif isinstance(s, str):
        name = _ALIASES.get(_normalise(s))
        if name is None:
            raise ParameterError(f"unknown unit {s!r}; allowed {_allowed(kind)}{_OTHER_SENSORS}")
        unit = _UNITS[name]
    else:
        raise ParameterError(f"a unit must be a string such as 'deg/s', got {s!r}; allowed {_allowed(kind)}")
    if kind is not None and unit.kind != kind:
        raise ParameterError(
            f"unit {s!r} is {'an' if unit.kind == 'angle' else 'a'} {unit.kind} unit, "
            f"but {'an' if kind == 'angle' else 'a'} {kind} unit is needed here; "
            f"allowed {_allowed(kind)}"
        )
    return unit


def rate_unit(unit) -> Unit:
    """The rate unit of an Allan deviation computed from samples in ``unit``: the unit itself for a
    rate, angle per second for an angle (increments or cumulative angle).

    >>> from allanite.units import rate_unit
    >>> rate_unit("arcsec").name, rate_unit("dph").name
    ('arcsec/s', 'deg/h')
    """
    u = parse_unit(unit)
    if u.kind == "rate":
        return u
    if u.name in _RATE_OF:
        return _UNITS[_RATE_OF[u.name]]
    return Unit(f"{u.name}/s", "rate", u.factor, f"{u.label}/s")


def convert(values, src, dst):
    """Convert values between two units of the same kind.

    >>> from allanite.units import convert
    >>> float(convert(1.0, "deg/s", "deg/h"))
    3600.0
    """
    a, b = parse_unit(src), parse_unit(dst)
    if a.kind != b.kind:
        raise ParameterError(
            f"cannot convert {a.kind} unit {src!r} to {b.kind} unit {dst!r}; both must be rates or both angles"
        )
    return np.asarray(values, dtype=np.float64) * (a.factor / b.factor)


def to_deg_per_s(values, unit):
    """Rate samples in ``unit`` converted to °/s (a float64 array).

    ``unit`` must be a rate unit: increments or angles need τ0 first (see ``input=`` of the estimators).

    >>> from allanite.units import to_deg_per_s
    >>> to_deg_per_s([3600.0, 7200.0], "deg/h")
    array([1., 2.])
    """
    u = parse_unit(unit, kind="rate")
    return np.asarray(values, dtype=np.float64) * u.factor


# term: (power of seconds in the base form, target unit → (label, factor from deg·s^p base), default)
_SQH = 60.0  # √3600 s/√h
_TERMS = {
    "Q": (
        1.0,
        {"deg": ("°", 1.0), "arcsec": ("arcsec", 3600.0), "urad": ("µrad", 1e6 / _RAD), "rad": ("rad", 1.0 / _RAD)},
        "deg",
    ),
    "N": (
        0.5,
        {
            "deg/sqrt(h)": ("°/√h", _SQH),
            "deg/sqrt(s)": ("°/√s", 1.0),
            "deg/h/sqrt(Hz)": ("°/h/√Hz", 3600.0),
            "rad/sqrt(s)": ("rad/√s", 1.0 / _RAD),
        },
        "deg/sqrt(h)",
    ),
    "B": (0.0, {"deg/h": ("°/h", 3600.0), "deg/s": ("°/s", 1.0), "rad/s": ("rad/s", 1.0 / _RAD)}, "deg/h"),
    "K": (
        -0.5,
        {
            "deg/h^1.5": ("°/h^1.5", 3600.0 * _SQH),
            "deg/s^1.5": ("°/s^1.5", 1.0),
            "rad/s^1.5": ("rad/s^1.5", 1.0 / _RAD),
        },
        "deg/h^1.5",
    ),
    "R": (
        -1.0,
        {"deg/h^2": ("°/h²", 3600.0**2), "deg/s^2": ("°/s²", 1.0), "rad/s^2": ("rad/s²", 1.0 / _RAD)},
        "deg/h^2",
    ),
}
_TERM_ALIASES = {
    "q": "Q",
    "quantization": "Q",
    "quantisation": "Q",
    "n": "N",
    "arw": "N",
    "angle_random_walk": "N",
    "b": "B",
    "bias_instability": "B",
    "bi": "B",
    "k": "K",
    "rrw": "K",
    "rate_random_walk": "K",
    "r": "R",
    "rate_ramp": "R",
    "ramp": "R",
}
#: The IEEE-952 terms and the report units each accepts (first: the default).
IEEE952_TERMS = {t: tuple([d] + [k for k in v[1] if k != d]) for t, v in _TERMS.items() for d in [v[2]]}


class Quantity(NamedTuple):
    """A value with its unit label, e.g. ``Quantity(value=0.15, unit='°/√h')``."""

    value: Any
    unit: str


def ieee952(term, value, unit, *, to=None) -> Quantity:
    """An Allan-model coefficient converted from the samples' unit to IEEE-952 report units.

    Parameters
    ----------
    term : {"Q", "N", "B", "K", "R"}
        Quantization, angle random walk, bias instability, rate random walk, rate ramp (also
        ``"arw"``, ``"bias_instability"``, ``"rrw"``, …).
    value : float or array_like
        The coefficient in base form for samples in ``unit``: Q in unit·s (an angle), N in unit·√s,
        B in unit, K in unit/√s, R in unit/s, with τ in seconds — what a fit of σ²(τ) returns.
    unit : str or Unit
        The samples' unit. An angle unit (increment input) stands for angle per second.
    to : str, optional
        Report unit; defaults: Q "deg" (also "arcsec", "urad", "rad"), N "deg/sqrt(h)" (also
        "deg/sqrt(s)", "deg/h/sqrt(Hz)", "rad/sqrt(s)"), B "deg/h" ("deg/s", "rad/s"), K "deg/h^1.5"
        ("deg/s^1.5", "rad/s^1.5"), R "deg/h^2" ("deg/s^2", "rad/s^2").

    Returns
    -------
    Quantity
        ``(value, unit label)``.

    Examples
    --------
    >>> from allanite.units import ieee952
    >>> ieee952("N", 0.0025, "deg/s")              # ARW from °/s samples: 0.0025 °/√s
    Quantity(value=0.15, unit='°/√h')
    >>> round(ieee952("B", 1e-5, "rad/s").value, 4)  # 1e-5 rad/s in °/h
    2.0626
    """
    t = _TERM_ALIASES.get(term.lower()) if isinstance(term, str) else None
    if t is None:
        raise ParameterError(
            f"unknown IEEE-952 term {term!r}; allowed: 'Q' (quantization), 'N' (angle random "
            f"walk), 'B' (bias instability), 'K' (rate random walk), 'R' (rate ramp)"
        )
    _, targets, default = _TERMS[t]
    target = default if to is None else to
    if target not in targets:
        raise ParameterError(f"unknown report unit {to!r} for term {t}; allowed: {', '.join(IEEE952_TERMS[t])}")
    label, factor = targets[target]
    u = rate_unit(unit)
    v = np.asarray(value, dtype=np.float64) * (u.factor * factor)
    return Quantity(float(v) if v.ndim == 0 else v, label)


def adev_unit_label(unit) -> str:
    """Axis label for an Allan deviation of samples in ``unit`` (the rate unit; angle → angle/s);
    ``"rate unit"`` when the unit is not known.

    >>> from allanite.units import adev_unit_label
    >>> adev_unit_label("dps"), adev_unit_label("urad")
    ('°/s', 'µrad/s')
    """
    if unit is None:
        return "rate unit"
    acc = accel_unit_name(unit)
    return ACCEL_LABELS[acc] if acc is not None else rate_unit(unit).label


def coefficient_unit(term: str, unit) -> str:
    """Label of a noise coefficient's base form for samples in ``unit``: for °/s, Q in °, N in °/√s,
    B in °/s, K in °/s^1.5, R in °/s² (what :func:`allanite.fit` returns before IEEE-952 conversion); for an
    accelerometer's m/s², Q in m/s, N in m/s^1.5, B in m/s², K in m/s^2.5, R in m/s³ (g: g·s, g·√s, g, …).

    >>> from allanite.units import coefficient_unit
    >>> coefficient_unit("N", "deg/s"), coefficient_unit("K", "rad/s"), coefficient_unit("N", "m/s^2")
    ('deg/√s', 'rad/s^1.5', 'm/s^1.5')
    """
    acc = accel_unit_name(unit)
    if acc is not None:
        return _accel_coefficient_unit(term, acc)
    u = str(rate_unit(unit))
    if u.endswith("/s"):
        angle = u[:-2]
        return {"Q": angle, "N": f"{angle}/√s", "B": u, "K": f"{angle}/s^1.5", "R": f"{angle}/s²"}[term]
    return {"Q": f"({u})·s", "N": f"({u})·√s", "B": u, "K": f"({u})/√s", "R": f"({u})/s"}[term]


# ----------------------------------------------------------------------------------------------
# accelerometer units (for IMU noise files: Kalibr wants SI)

#: Standard gravity, m/s² (CGPM 1901; the "g" of accelerometer datasheets such as the ADIS16405's).
STANDARD_GRAVITY = 9.80665

# canonical name: (factor to m/s², aliases after normalisation)
_ACCEL = {
    "m/s^2": (1.0, ("m/s2", "m/s²", "m/s/s", "mps2", "m/s**2")),
    "mm/s^2": (1e-3, ("mm/s2", "mm/s²")),
    "g": (STANDARD_GRAVITY, ("gee", "g0")),
    "mg": (1e-3 * STANDARD_GRAVITY, ("milli-g",)),
    "ug": (1e-6 * STANDARD_GRAVITY, ("micro-g",)),
}

#: Canonical names of the accepted accelerometer units.
ACCEL_UNITS = tuple(_ACCEL)
#: Typographic form of each accelerometer unit (plots and reports).
ACCEL_LABELS = {"m/s^2": "m/s²", "mm/s^2": "mm/s²", "g": "g", "mg": "mg", "ug": "µg"}


def accel_factor(unit: str) -> float:
    """Size of one accelerometer ``unit`` in m/s² (g = 9.80665 m/s²).

    >>> from allanite.units import accel_factor
    >>> accel_factor("g"), accel_factor("mg"), accel_factor("m/s^2")
    (9.80665, 0.00980665, 1.0)
    """
    if isinstance(unit, str):
        key = unit.strip().lower().replace(" ", "").replace("\u00b5", "u").replace("\u03bc", "u")
        for name, (factor, aliases) in _ACCEL.items():
            if key == name or key in aliases:
                return factor
    raise ParameterError(f"unknown accelerometer unit {unit!r}; allowed: {', '.join(ACCEL_UNITS)} (g = 9.80665 m/s²)")


# term: (name, target unit → (label, factor from the base form in m/s² and seconds), default). The
# accelerometer's names and report units (IEEE Std 1293 and datasheets): N a velocity random walk, B in µg,
# K an acceleration random walk; the factors are the gyro's (√h = 60 √s) and g = 9.80665 m/s².
_UG = 1e-6 * STANDARD_GRAVITY
_ACCEL_TERMS = {
    "Q": ("velocity quantization", {"m/s": ("m/s", 1.0), "mm/s": ("mm/s", 1e3)}, "m/s"),
    "N": (
        "velocity random walk",
        {
            "m/s/sqrt(h)": ("m/s/√h", _SQH),
            "m/s/sqrt(s)": ("m/s/√s", 1.0),
            "ug/sqrt(Hz)": ("µg/√Hz", 1.0 / _UG),
        },
        "m/s/sqrt(h)",
    ),
    "B": ("bias instability", {"ug": ("µg", 1.0 / _UG), "mg": ("mg", 1e-3 / _UG), "m/s^2": ("m/s²", 1.0)}, "ug"),
    "K": (
        "acceleration random walk",
        {"m/s/h^1.5": ("m/s/h^1.5", 3600.0 * _SQH), "m/s^2.5": ("m/s^2.5", 1.0)},
        "m/s/h^1.5",
    ),
    "R": ("acceleration ramp", {"m/s/h^2": ("m/s/h²", 3600.0**2), "m/s^3": ("m/s³", 1.0)}, "m/s/h^2"),
}
_ACCEL_ALIASES = {
    **{t.lower(): t for t in _ACCEL_TERMS},
    **{v[0].replace(" ", "_"): t for t, v in _ACCEL_TERMS.items()},
    "vrw": "N",
    "bi": "B",
}
#: The accelerometer's noise terms: name and the report units each accepts (first: the default).
ACCEL_TERMS = {t: (v[0], tuple([v[2]] + [k for k in v[1] if k != v[2]])) for t, v in _ACCEL_TERMS.items()}


def accel_report_unit(term, value, unit, *, to=None) -> Quantity:
    """An accelerometer's noise coefficient converted from its samples' ``unit`` to a report unit: the
    accelerometer's counterpart of :func:`ieee952`.

    Parameters
    ----------
    term : {"Q", "N", "B", "K", "R"}
        Velocity quantization, velocity random walk, bias instability, acceleration random walk, acceleration
        ramp (the gyro's letters; also ``"vrw"``, ``"bias_instability"``, ``"acceleration_random_walk"``, …).
    value : float or array_like
        The coefficient in base form for samples in ``unit``: Q in unit·s, N in unit·√s, B in unit, K in
        unit/√s, R in unit/s (τ in seconds) — what a fit of the accelerometer's σ²(τ) returns.
    unit : str
        The samples' accelerometer unit (one of :data:`ACCEL_UNITS`: ``"m/s^2"``, ``"g"``, ``"mg"``, …).
    to : str, optional
        Report unit; defaults: Q "m/s" (also "mm/s"), N "m/s/sqrt(h)" ("m/s/sqrt(s)", "ug/sqrt(Hz)"), B "ug"
        ("mg", "m/s^2"), K "m/s/h^1.5" ("m/s^2.5"), R "m/s/h^2" ("m/s^3").

    Examples
    --------
    >>> from allanite.units import accel_report_unit
    >>> accel_report_unit("N", 0.001, "m/s^2")          # VRW 0.001 m/s/√s
    Quantity(value=0.06, unit='m/s/√h')
    >>> round(accel_report_unit("B", 2e-5, "g").value, 6)  # 20 µg
    20.0
    """
    t = _ACCEL_ALIASES.get(term.lower()) if isinstance(term, str) else None
    if t is None:
        raise ParameterError(
            f"unknown accelerometer noise term {term!r}; allowed: 'Q' (velocity quantization), 'N' (velocity "
            "random walk), 'B' (bias instability), 'K' (acceleration random walk), 'R' (acceleration ramp)"
        )
    _, targets, default = _ACCEL_TERMS[t]
    target = default if to is None else to
    if target not in targets:
        raise ParameterError(f"unknown report unit {to!r} for term {t}; allowed: {', '.join(ACCEL_TERMS[t][1])}")
    label, factor = targets[target]
    v = np.asarray(value, dtype=np.float64) * (accel_factor(unit) * factor)
    return Quantity(float(v) if v.ndim == 0 else v, label)


def accel_unit_name(unit) -> str | None:
    """The canonical name (one of :data:`ACCEL_UNITS`) of an accelerometer's ``unit``, else None (a gyro's unit,
    an unknown one, or not a string) — never raises.

    >>> from allanite.units import accel_unit_name
    >>> accel_unit_name("m/s²"), accel_unit_name("G"), accel_unit_name("deg/s")
    ('m/s^2', 'g', None)
    """
    if not isinstance(unit, str):
        return None
    key = unit.strip().lower().replace(" ", "").replace("\u00b5", "u").replace("\u03bc", "u")
    for name, (_, aliases) in _ACCEL.items():
        if key == name or key in aliases:
            return name
    return None


def _accel_coefficient_unit(term: str, name: str) -> str:
    """Base-form label of term Q…R for an accelerometer's samples in ``name`` (canonical)."""
    if name.endswith("/s^2"):
        v = name[:-4]  # m or mm: the velocity's length
        return {"Q": f"{v}/s", "N": f"{v}/s^1.5", "B": f"{v}/s²", "K": f"{v}/s^2.5", "R": f"{v}/s³"}[term]
    u = ACCEL_LABELS[name]
    return {"Q": f"{u}·s", "N": f"{u}·√s", "B": u, "K": f"{u}/√s", "R": f"{u}/s"}[term]


def check_sensor_unit(unit) -> str | None:
    """Check a unit ``fit`` and ``refine`` take for rate samples: a gyro's (:func:`parse_unit`) or an
    accelerometer's (:data:`ACCEL_UNITS`). Returns the accelerometer's canonical name, or None for a gyro's.

    Raises
    ------
    ParameterError
        Neither: the message names the value and both sensors' allowed units.
    """
    acc = accel_unit_name(unit)
    if acc is not None:
        return acc
    try:
        rate_unit(unit)
    except ParameterError:
        raise ParameterError(
            f"unknown unit {unit!r}; allowed {_allowed()} (a gyro's), or {', '.join(ACCEL_UNITS)} (an "
            "accelerometer's; g = 9.80665 m/s²); for another sensor give no unit: the terms are then in the samples' "
            "own unit and seconds"
        ) from None
    return None


def report_unit(term, value, unit) -> Quantity:
    """A noise coefficient in its report unit: IEEE-952's (:func:`ieee952`) for a gyro's ``unit``, the
    accelerometer's (:func:`accel_report_unit`: velocity random walk in m/s/√h, bias instability in µg, …) for
    an accelerometer's — what :func:`allanite.fit` gives as ``Coefficient.ieee``.

    >>> from allanite.units import report_unit
    >>> report_unit("N", 0.0025, "deg/s"), report_unit("N", 0.001, "m/s^2")
    (Quantity(value=0.15, unit='°/√h'), Quantity(value=0.06, unit='m/s/√h'))
    """
    if accel_unit_name(unit) is not None:
        return accel_report_unit(term, value, unit)
    return ieee952(term, value, unit)
