"""The noise-model fit of a report as JSON (``summary.json``'s ``fit``): the record's fit per axis with its
coefficients (base form and IEEE-952 units), χ² and read-offs, and the coefficient series over the DAVAR
windows with their statistics: each term's median over all windows (an unresolved window counted as 0) and the
median, minimum and maximum of the windows that resolve it."""

from __future__ import annotations

import numpy as np

from ..model.terms import TERM_NAMES
from ..units import ACCEL_TERMS, accel_report_unit, accel_unit_name, coefficient_unit, ieee952, report_unit
from .fmt import json_list, json_number
from .settings import FIT_MODEL


def fit_dict(rep, inline: bool) -> dict:
    """``summary.json``'s ``fit``: the record's fit per axis, and the series per window (``inline``: the
    per-window lists in the JSON, else in the side files)."""
    st, dy = rep.static, rep.dynamic
    fit = {
        "requested": rep.fit_requested,
        "model": FIT_MODEL,
        "unit": rep.unit,
        # "ieee"/"ieee_ci" hold IEEE-952 units for a gyro, the accelerometer's report units for an accelerometer
        "unit_known": rep.unit is not None or rep.accel_unit is not None,
        "sensor": "accelerometer" if rep.accel_unit is not None else "gyro",
        "accel_unit": rep.accel_unit,
        "confidence": st.confidence if rep.fit_requested else None,
        "error": rep.fit_error,
        "axes": None,
        "series": None,
    }
    if rep.fits is not None:
        f0 = rep.fits[0]
        fit["terms"] = list(f0.terms)
        fit["confidence"] = f0.confidence
        fit["axes"] = [_fit_axis(rep, k, f) for k, f in enumerate(rep.fits)]
    if rep.fit_requested:
        ser = {"error": rep.series_error, "axes": None}
        if rep.series is not None:
            ser["terms"] = list(rep.series[0].terms)
            ser["confidence"] = rep.series[0].confidence
            ser["window_samples"] = int(dy.window)
            ser["hop_samples"] = int(dy.hop)
            ser["axes"] = [
                dict(axis=k, name=rep.axis_names[k], **_series_dict(s, rep.unit or rep.accel_unit, inline))
                for k, s in enumerate(rep.series)
            ]
        fit["series"] = ser
    return fit


def _fit_axis(rep, k: int, f) -> dict:
    """One axis's fit of the record: coefficients, χ², the τ fitted, notes and the datasheet read-offs."""
    return {
        "axis": k,
        "name": rep.axis_names[k],
        "coefficients": {
            t: _coef_dict(f.coefficients[t], rep.unit, t)
            if rep.accel_unit is None
            else _accel_coef_dict(f.coefficients[t], rep.accel_unit, t)
            for t in f.terms
        },
        "chi2": json_number(f.chi2),
        "dof": int(f.dof),
        "chi2_dof": json_number(f.chi2_dof),
        "p_value": json_number(f.p_value),
        "tau_s": json_list(f.tau),
        "iterations": int(f.iterations),
        "method": f.method,
        "notes": list(f.notes),
        "readoffs": _readoffs(f, rep.unit, rep.adev_unit, rep.accel_unit),
    }


def _coef_dict(c, unit, name) -> dict:
    d = {
        "name": TERM_NAMES[name],
        "value": json_number(c.value),
        "ci": [json_number(c.ci[0]), json_number(c.ci[1])],
        "unit": c.unit,
        "ieee": json_number(c.ieee),
        "ieee_ci": None if c.ieee_ci is None else [json_number(c.ieee_ci[0]), json_number(c.ieee_ci[1])],
        "ieee_unit": c.ieee_unit,
    }
    if name == "Q" and unit is not None:
        q = ieee952("Q", c.value, unit, to="urad")
        d["also"] = {
            "value": json_number(q.value),
            "ci": [
                json_number(ieee952("Q", c.ci[0], unit, to="urad").value),
                json_number(ieee952("Q", c.ci[1], unit, to="urad").value),
            ],
            "unit": q.unit,
        }
    return d


def _accel_coef_dict(c, unit: str, name: str) -> dict:
    """An accelerometer's coefficient: base form in its ``unit`` and seconds, and in the accelerometer's report
    units (:func:`allanite.units.accel_report_unit`) as ``ieee``/``ieee_ci``/``ieee_unit``."""
    q = accel_report_unit(name, c.value, unit)
    lo, hi = (accel_report_unit(name, v, unit).value for v in c.ci)
    base = {"Q": f"({unit})·s", "N": f"({unit})·√s", "B": unit, "K": f"({unit})/√s", "R": f"({unit})/s"}
    return {
        "name": ACCEL_TERMS[name][0],
        "value": json_number(c.value),
        "ci": [json_number(c.ci[0]), json_number(c.ci[1])],
        "unit": base[name],
        "ieee": json_number(q.value),
        "ieee_ci": [json_number(lo), json_number(hi)],
        "ieee_unit": q.unit,
    }


def _readoffs(f, unit, adev_unit, accel_unit=None) -> dict:
    r = f.readoffs
    out = {
        "adev_at_1s": json_number(r["adev_at_1s"]),
        "adev_at_1s_interpolated": r["adev_at_1s_interpolated"],
        "adev_min": json_number(r["adev_min"]),
        "tau_at_min_s": json_number(r["tau_at_min"]),
        "bias_instability_readoff": json_number(r["bias_instability_readoff"]),
        "readoff_tau_max_s": json_number(r.get("readoff_tau_max")),
        "adev_unit": adev_unit,
    }
    if unit is not None or accel_unit is not None:  # the read-offs in IEEE-952 units, or the accelerometer's

        def report(term, value):
            return ieee952(term, value, unit) if unit is not None else accel_report_unit(term, value, accel_unit)

        n_ro = report("N", r["adev_at_1s"]) if r["adev_at_1s"] is not None else None
        b_ro = report("B", r["bias_instability_readoff"])
        out["arw_readoff_ieee"] = None if n_ro is None else json_number(n_ro.value)
        out["arw_readoff_ieee_unit"] = report("N", 1.0).unit
        out["bias_instability_readoff_ieee"] = json_number(b_ro.value)
        out["bias_instability_readoff_ieee_unit"] = b_ro.unit
    return out


def _series_dict(s, unit, inline: bool = True) -> dict:
    """One axis's coefficient series (``unit``: a gyro's, an accelerometer's — its coefficients then in the
    accelerometer's report units and names — or None); ``inline`` False: statistics only (the per-window lists are
    in the side files, :mod:`allanite.report.sidefiles`)."""
    coeffs = {}
    accel = accel_unit_name(unit) is not None
    for t in s.terms:
        v, lo, hi = s.values[t], s.ci_low[t], s.ci_high[t]
        d = {
            "name": ACCEL_TERMS[t][0] if accel else TERM_NAMES[t],
            "unit": coefficient_unit(t, unit) if unit is not None else None,
            "value": json_list(v) if inline else None,
            "ci_low": json_list(lo) if inline else None,
            "ci_high": json_list(hi) if inline else None,
        }
        show, show_unit = v, d["unit"]
        if unit is not None:
            ie = report_unit(t, v, unit)
            show, show_unit = np.asarray(ie.value), ie.unit
            d.update(
                ieee_unit=ie.unit,
                ieee=json_list(show) if inline else None,
                ieee_ci_low=json_list(report_unit(t, lo, unit).value) if inline else None,
                ieee_ci_high=json_list(report_unit(t, hi, unit).value) if inline else None,
            )
        d["stats"] = _resolved_stats(np.asarray(show, dtype=np.float64), v, s.t, show_unit)
        coeffs[t] = d
    if not inline:
        return {"t_s": None, "chi2_dof": None, "per_window": "side_files", "coefficients": coeffs}
    return {"t_s": json_list(s.t), "chi2_dof": json_list(s.chi2_dof), "coefficients": coeffs}


def _resolved_stats(show: np.ndarray, value: np.ndarray, t: np.ndarray, unit) -> dict:
    """A coefficient over the windows. ``median``: over every window, one whose fit leaves the term at 0 (does not
    resolve it) counted as 0, its fit's value — so a term resolved in fewer than half the windows has median 0, not
    the median of its upward swings (the windows that resolve a term absent from the record are those whose noise
    happened to swing up). ``median_resolved``, ``min`` and ``max`` (and where): over the windows that resolve it
    (value > 0), None when none does; ``windows_nonzero`` of ``windows`` resolve it."""
    value = np.asarray(value)
    resolved = np.flatnonzero(value > 0)
    out = {"unit": unit, "windows_nonzero": int(resolved.size), "windows": int(np.size(value))}
    everywhere = np.where(value > 0, show, 0.0)
    out["median"] = json_number(np.median(everywhere)) if everywhere.size else None
    if resolved.size == 0:
        return out | {"median_resolved": None, "min": None, "t_of_min_s": None, "max": None, "t_of_max_s": None}
    shown = show[resolved]
    j_min, j_max = resolved[int(np.argmin(shown))], resolved[int(np.argmax(shown))]
    return out | {
        "median_resolved": json_number(np.median(shown)),
        "min": json_number(show[j_min]),
        "t_of_min_s": json_number(t[j_min]),
        "max": json_number(show[j_max]),
        "t_of_max_s": json_number(t[j_max]),
    }
