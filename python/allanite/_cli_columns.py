"""Which columns of a log ``allanite report`` analyses without ``--columns``: the gyro's, chosen by the units
the column names give or by the names themselves (:func:`gyro_columns`). ``allanite report`` and ``allanite
batch`` (:func:`allanite.dask.fleet.run_one`) both choose so."""

from __future__ import annotations

import re
from dataclasses import replace

from ._cli_options import UsageError
from .units import accel_unit_name

#: Column names that say "gyro" and "accelerometer" (case-insensitive): gyro_x, omega_y, angular_velocity.z,
#: wx / gx; acc_x, accel_y, specific_force_z, ax.
_GYRO_NAME = re.compile(r"gyr|omega|angular|ang_?vel|^[wg]_?[xyz]$", re.IGNORECASE)
_ACCEL_NAME = re.compile(r"acc|specific_?force|^a_?[xyz]$", re.IGNORECASE)


def given_accel_unit(unit, log, hint: str = "") -> str | None:
    """The accelerometer's unit (canonical: ``m/s^2``, ``g``, ``mg``, …) that ``unit`` (--unit) names, for ``log``
    read without it (``read_log`` takes a gyro's or an angle unit only), else None (a gyro's, or none given); a
    UsageError where the log's column names give a gyro's unit (``hint``: what else the command offers).
    ``allanite report`` and ``allanite batch`` both read an accelerometer's log so, its report in that unit
    (``from_log(unit=…)``)."""
    name = accel_unit_name(unit)
    if name is not None and log.unit is not None:
        raise UsageError(
            f"--unit {unit} is an accelerometer's, and the names of columns "
            f"{', '.join(map(str, log.columns))} give a gyro's ({log.unit.name}): give the accelerometer's "
            f"columns with --columns{hint}"
        )
    return name


def is_accel_name(name: str) -> bool:
    """Whether a column's name says it is an accelerometer's (``acc_x``, ``accel_y``, ``ax``, ``specific_force_z``)."""
    return bool(_ACCEL_NAME.search(name))


def gyro_columns(log):
    """Without --columns: a log with accelerometer columns beside others is analysed on the columns its
    header names as gyro ones (with a note); when it names none, the user is asked (a usage error that
    lists the columns). A log without accelerometer-named columns is analysed whole, as before. ``allanite
    report`` and ``allanite batch`` (:func:`allanite.dask.fleet.run_one`) both choose so."""
    names = [str(c) for c in log.columns]
    by_unit = _gyro_by_unit(log)
    if by_unit is not None:
        return by_unit
    accel = [n for n in names if _ACCEL_NAME.search(n)]
    if not accel or len(accel) == len(names):
        return log, None
    gyro = [i for i, n in enumerate(names) if _GYRO_NAME.search(n) and not _ACCEL_NAME.search(n)]
    if not gyro:
        raise UsageError(
            f"{log.path.name} has accelerometer columns ({', '.join(accel)}) beside others, and its header names "
            f"none as a gyro: give the gyro's with --columns (the columns are: {', '.join(names)})"
        )
    chosen = [names[i] for i in gyro]
    left = [n for n in names if n not in chosen]
    note = (
        f"columns {', '.join(chosen)} analysed, chosen by their names (gyro); left out: {', '.join(left)} — "
        "give --columns to choose others (and --accel-columns with --kalibr for the accelerometer)"
    )
    return log.take(chosen if len(gyro) > 1 else chosen[0]), note


def _gyro_by_unit(log):
    """(the log on its gyro columns, the note) where the units the column names give set a gyro's rate columns
    beside an accelerometer's or others (EuRoC's ``w_RS_S_x [rad s^-1]`` … ``a_RS_S_x [m s^-2]``): the report
    gives the gyro's in IEEE-952 units; None where the names give no rate unit, or only rate units."""
    units = log.column_units or [None] * len(log.columns)
    rate = [str(c) for c, cu in zip(log.columns, units) if cu is not None and cu.kind == "rate"]
    if not rate or len(rate) == len(log.columns):
        return None
    left = [f"{c} ({cu.name if cu is not None else 'no unit'})" for c, cu in zip(log.columns, units) if c not in rate]
    gyro = log.take(rate if len(rate) > 1 else rate[0])
    said = gyro.unit.name if gyro.unit is not None else "several units"
    note = (
        f"columns {', '.join(rate)} analysed, chosen by the rate unit their names give ({said}); left out: "
        f"{', '.join(left)} — give --columns to analyse others (an accelerometer's in its own unit; "
        "--accel-columns with --kalibr writes its noise in SI)"
    )
    return gyro, note


#: Where ``allanite report`` writes an accelerometer's report of its own, inside --out.
ACCEL_FOLDER = "accelerometer"


def accel_columns(log):
    """The log on its accelerometer's columns where their names all give the same accelerometer unit beside a
    gyro's rate columns (EuRoC and TUM-VI: ``a_RS_S_x [m s^-2]`` beside ``w_RS_S_x [rad s^-1]``), analysed in a
    report of their own in that unit; else None — names without units (the ADIS16405's ``acc_x``), or
    accelerometer columns in several units, leave them out as before."""
    units = log.column_units or [None] * len(log.columns)
    rate = [c for c, cu in zip(log.columns, units) if cu is not None and cu.kind == "rate"]
    acc = [str(c) for c, cu in zip(log.columns, units) if cu is not None and cu.kind == "acceleration"]
    if not rate or not acc or len({cu.name for cu in units if cu is not None and cu.kind == "acceleration"}) > 1:
        return None
    # a --unit given is the gyro's (Log.take keeps a given unit): the accelerometer's is the one its names give
    return replace(log.take(acc if len(acc) > 1 else acc[0]), unit=None, unit_source=None)


def sensor_columns(log, accel_unit=None):
    """(the gyro's log, the accelerometer's log or None, the note or None) of a log read without --columns: the
    gyro's columns as :func:`gyro_columns` chooses them and the accelerometer's for a report of their own in
    ``ACCEL_FOLDER`` — where the names give a gyro's and an accelerometer's units (:func:`accel_columns`), or where
    a unit is given for each (``accel_unit``, --accel-unit, beside the gyro's --unit) and the names tell the
    accelerometer's columns from the gyro's (the ADIS16405's ``gyro_x`` … ``acc_x``: as before without it)."""
    accel = accel_columns(log)
    gyro, note = gyro_columns(log)
    if accel is None and accel_unit is not None and gyro.unit is not None and gyro is not log:
        named = [str(c) for c in log.columns if _ACCEL_NAME.search(str(c)) and c not in gyro.columns]
        if named:  # the gyro's given unit is no accelerometer's: --accel-unit is theirs (from_log(unit=…))
            accel = replace(log.take(named if len(named) > 1 else named[0]), unit=None, unit_source=None)
    if accel is None:
        return gyro, None, note
    taken = {str(c) for c in (*gyro.columns, *accel.columns)}
    left = [str(c) for c in log.columns if str(c) not in taken]
    said = accel_unit or accel.column_units[0].name
    note = (
        f"columns {', '.join(map(str, gyro.columns))} analysed in {gyro.unit.name if gyro.unit else 'their unit'}, "
        f"and the accelerometer's {', '.join(map(str, accel.columns))} in {said} in a report of their own "
        f"({ACCEL_FOLDER}/report.html), each chosen by "
        + ("the unit its name gives" if accel_unit is None else "its name and given unit")
        + (f"; left out: {', '.join(left)} — give --columns to analyse others" if left else "")
    )
    return gyro, accel, note
