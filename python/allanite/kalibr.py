"""IMU noise files for Kalibr and the ROS calibration tools (``imu.yaml``) from fitted Allan models.

Kalibr's IMU noise model (its wiki page "IMU Noise Model") takes continuous-time densities: the white
noise n(t) with E[n(t₁)n(t₂)] = σ²δ(t₁ − t₂) and the bias b(t) driven by white noise of strength σ_b.
In the Allan variance of such a sensor σ²(τ) = σ²/τ + σ_b²·τ/3, which is the IEEE-952 model with
N = σ and K = σ_b (docs/FORMULAS.md §4), so

=============================  ======================  ====================================
Kalibr field                   unit                    from the fit
=============================  ======================  ====================================
``gyroscope_noise_density``    rad/s/√Hz               N (angle random walk, rad/√s)
``gyroscope_random_walk``      rad/s²/√Hz              K (rate random walk, rad/s^1.5)
``accelerometer_noise_density`` m/s²/√Hz               N (velocity random walk, m/s/√s)
``accelerometer_random_walk``  m/s³/√Hz                K (acceleration random walk, m/s^2.5)
=============================  ======================  ====================================

(1/√Hz = √s: the densities are the coefficients themselves, only converted to SI — no factor of
√fs or √2, which is where hand conversions usually go wrong.) Kalibr makes them discrete itself:
σ_d = σ·√fs for the white noise, σ_b,d = σ_b/√fs for the random walk, with fs = ``update_rate``.
"""

from __future__ import annotations

import datetime as _dt
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ._core import __version__
from .errors import ParameterError
from .units import ACCEL_UNITS, accel_factor, accel_unit_name, rate_unit

__all__ = ["to_kalibr", "kalibr_values", "AGGREGATES"]

#: ``aggregate=`` of :func:`to_kalibr`: the largest axis (allan_variance_ros) or the axes' mean (imu_utils).
AGGREGATES = ("worst", "mean")

_FIELDS = {
    ("gyroscope", "N"): ("gyroscope_noise_density", "rad/s/sqrt(Hz)"),
    ("gyroscope", "K"): ("gyroscope_random_walk", "rad/s^2/sqrt(Hz)"),
    ("accelerometer", "N"): ("accelerometer_noise_density", "m/s^2/sqrt(Hz)"),
    ("accelerometer", "K"): ("accelerometer_random_walk", "m/s^3/sqrt(Hz)"),
}
_B_UNIT = {"gyroscope": "rad/s", "accelerometer": "m/s^2"}


def _fits(fits, what: str) -> list:
    out = [fits] if hasattr(fits, "coefficients") else list(fits) if isinstance(fits, Sequence) else None
    if not out or not all(hasattr(f, "coefficients") for f in out):
        raise ParameterError(
            f"{what} must be a NoiseFit or a list of them (one per axis, from allanite.fit), got {fits!r}"
        )
    return out


def _factor(sensor: str, fit, unit) -> tuple[float, str]:
    """Factor from the fit's base units to SI, and the unit's name."""
    if sensor == "gyroscope":
        u = unit if unit is not None else fit.unit
        if u is None:
            raise ParameterError(
                "the gyro fits carry no unit: fit with allanite.fit(..., unit='deg/s') (or the samples' unit), "
                "or pass gyro_unit="
            )
        r = rate_unit(u)
        return r.factor * math.pi / 180.0, r.name
    own = accel_unit_name(fit.unit)  # fit(..., unit="g") carries the accelerometer's unit
    if fit.unit is not None and own is None:
        raise ParameterError(
            f"the accelerometer fits carry the unit {fit.unit!r}, not an accelerometer's (allowed: "
            f"{', '.join(ACCEL_UNITS)}): were the gyro's fits passed as accel=?"
        )
    if unit is not None and own is not None and accel_factor(unit) != accel_factor(own):
        raise ParameterError(
            f"accel_unit={unit!r}, but the accelerometer fits were made with unit={own!r}: give one, or the same"
        )
    u = unit if unit is not None else own or "m/s^2"
    return accel_factor(u), u


def kalibr_values(fits, sensor: str, *, unit=None, aggregate: str = "worst") -> dict:
    """Per-axis and aggregated Kalibr values of one sensor (``"gyroscope"`` or ``"accelerometer"``).

    Returns a dict: term ("N", "K", "B") → {"axes": [per-axis dicts with value, ci, used, flagged (SI)],
    "value": the aggregate, "flagged": bool}. A coefficient whose interval reaches 0 is not identifiable
    from the record: its upper bound is used and flagged (for B, only reported).
    """
    if aggregate not in AGGREGATES:
        raise ParameterError(f"aggregate must be one of {AGGREGATES}, got {aggregate!r}")
    fits = _fits(fits, sensor)
    out: dict = {"unit": None}
    for term in ("N", "K", "B"):
        axes: list[dict[str, Any]] = []
        for a, f in enumerate(fits):
            c = f.coefficients.get(term)
            if c is None:
                if term == "B":
                    continue
                raise ParameterError(
                    f"{sensor} axis {a}: the fit has no {term} term (terms {tuple(f.coefficients)}); Kalibr needs "
                    "N (noise density) and K (random walk): fit with terms including 'N' and 'K'"
                )
            factor, uname = _factor(sensor, f, unit)
            out["unit"] = uname
            lo, hi = (float(c.ci[0]) * factor, float(c.ci[1]) * factor)
            value = float(c.value) * factor
            flagged = not lo > 0.0
            axes.append(
                {
                    "value": value,
                    "ci": (lo, hi),
                    "used": hi if flagged else value,
                    "flagged": flagged,
                    "tau_range": (float(min(f.tau)), float(max(f.tau))),
                    "confidence": float(f.confidence),
                }
            )
        if not axes:
            continue
        used: list[float] = [float(x["used"]) for x in axes]
        if aggregate == "worst":
            k = max(range(len(used)), key=used.__getitem__)
            agg, flag = used[k], axes[k]["flagged"]
        else:
            agg, flag = sum(used) / len(used), any(x["flagged"] for x in axes)
        out[term] = {"axes": axes, "value": agg, "flagged": flag}
    return out


def to_kalibr(
    path,
    *,
    gyro,
    accel=None,
    update_rate: float,
    rostopic: str = "/imu0",
    aggregate: str = "worst",
    gyro_unit=None,
    accel_unit: str | None = None,
) -> Path:
    """Write a Kalibr / ROS ``imu.yaml`` from per-axis noise fits.

    Parameters
    ----------
    path : str or Path
        The file to write.
    gyro : NoiseFit or list of NoiseFit
        Per-axis fits of the gyro (:func:`allanite.fit`; terms including "N" and "K").
    accel : NoiseFit or list of NoiseFit, optional
        Per-axis fits of the accelerometer; without them the accelerometer fields (which Kalibr
        requires) are left out and the file says so.
    update_rate : float
        IMU message rate, Hz (Kalibr's ``update_rate``).
    rostopic : str
        IMU topic (default ``"/imu0"``).
    aggregate : {"worst", "mean"}
        One value per field from the axes: the largest (default, as allan_variance_ros does) or their
        mean (as imu_utils does). Every axis's value is written in the comment block.
    gyro_unit : str, optional
        Unit of the gyro samples when the fits carry none (``fit(..., unit=...)`` sets it).
    accel_unit : str, optional
        Unit of the accelerometer samples: ``"m/s^2"``, ``"g"`` (9.80665 m/s²), ``"mg"``, … Default: the
        unit the fits carry (``fit(..., unit="g")``), else ``"m/s^2"``; one that differs from the fits' is a
        ``ParameterError``.

    Returns
    -------
    Path
        The file written. Fields: ``gyroscope_noise_density`` [rad/s/√Hz] = N,
        ``gyroscope_random_walk`` [rad/s²/√Hz] = K, ``accelerometer_noise_density`` [m/s²/√Hz],
        ``accelerometer_random_walk`` [m/s³/√Hz], ``update_rate``, ``rostopic``; a comment block gives
        B (bias instability, not a Kalibr field), each coefficient's interval, the τ range fitted and
        the allanite version. A coefficient whose interval reaches 0 (not identifiable from the record —
        typically K of a short record) is written as its upper bound and flagged in the file.
    """
    if not (isinstance(update_rate, (int, float)) and math.isfinite(update_rate) and update_rate > 0):
        raise ParameterError(f"update_rate must be a positive rate in Hz, got {update_rate!r}")
    if not isinstance(rostopic, str) or not rostopic:
        raise ParameterError(f"rostopic must be a non-empty string such as '/imu0', got {rostopic!r}")
    sensors = {"gyroscope": kalibr_values(gyro, "gyroscope", unit=gyro_unit, aggregate=aggregate)}
    if accel is not None:
        sensors["accelerometer"] = kalibr_values(accel, "accelerometer", unit=accel_unit, aggregate=aggregate)
    when = _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")
    how = "largest axis (as allan_variance_ros)" if aggregate == "worst" else "mean of the axes (as imu_utils)"
    head = [
        f"# IMU noise parameters for Kalibr, written by allanite {__version__} on {when}",
        "# continuous-time densities: noise density = N (white noise), random walk = K (bias random walk),",
        "# from the fitted Allan variance sigma^2(tau) = N^2/tau + B^2*(2 ln2/pi) + K^2*tau/3 + ...;",
        f"# aggregate over axes: {how}.",
    ]
    warnings: list[str] = []
    fields: dict[str, float] = {}
    flagged: set[str] = set()
    for sensor, vals in sensors.items():
        _sensor_lines(sensor, vals, head, warnings, fields, flagged)
    if accel is None:
        warnings.append(
            "# NOTE: no accelerometer fits were given: Kalibr also needs accelerometer_noise_density and "
            "accelerometer_random_walk"
        )
    body = [
        f"{k}: {v:.6e}" + ("  # upper bound: not identifiable (see WARNING)" if k in flagged else "")
        for k, v in sorted(fields.items())
    ]
    body += [f"rostopic: {rostopic}", f"update_rate: {float(update_rate):g}"]
    p = Path(path)
    p.write_text("\n".join(head + warnings + body) + "\n", encoding="utf-8")
    return p


def _sensor_lines(
    sensor: str, vals: dict, head: list[str], warnings: list[str], fields: dict[str, float], flagged: set[str]
) -> None:
    """One sensor's part of the file: its comment lines (each term's value, interval and τ range per axis) onto
    ``head``, a warning per axis whose N or K is not identifiable onto ``warnings``, its Kalibr fields' values
    into ``fields`` and the names of those that are upper bounds into ``flagged``."""
    ax0 = vals["N"]["axes"][0]
    head.append(
        f"# {sensor} (samples in {vals['unit']}), {len(vals['N']['axes'])} axes, "
        f"{ax0['confidence']:.1%} intervals, per axis its value, interval and the tau range fitted:"
    )
    for term in ("N", "K", "B"):
        if term not in vals:
            continue
        name, unit = _FIELDS[(sensor, term)] if term != "B" else ("bias instability B (not a Kalibr field)", "")
        unit = unit or _B_UNIT[sensor]
        head.append(f"#   {name} [{unit}]:")
        for a, x in enumerate(vals[term]["axes"]):
            flag = "  NOT IDENTIFIABLE: upper bound used" if x["flagged"] and term != "B" else ""
            head.append(
                f"#     axis {a}: {x['value']:.6e}  interval [{x['ci'][0]:.6e}, {x['ci'][1]:.6e}]"
                f"  tau {x['tau_range'][0]:.4g}..{x['tau_range'][1]:.4g} s{flag}"
            )
            if x["flagged"] and term != "B":
                warnings.append(
                    f"# WARNING: {sensor} axis {a}: {term} is not identifiable from this record (its interval "
                    f"reaches 0); its upper bound {x['ci'][1]:.6e} {unit} is used"
                    + (" and is the aggregate" if vals[term]["flagged"] else "")
                )
        if term != "B":
            fields[name] = vals[term]["value"]
            if vals[term]["flagged"]:
                flagged.add(name)
