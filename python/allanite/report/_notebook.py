"""The report in a notebook: :class:`~allanite.report.Report`'s ``_repr_html_`` (:mod:`allanite._display`'s
template), read from :meth:`Report.summary` as the console text and the page are — the record, the units the
numbers are in (the input's, and IEEE-952's or an accelerometer's), the noise model per axis, what the
refinement added and what it left unexplained, the notes, and where :meth:`Report.write` put the files."""

from __future__ import annotations

import numpy as np

from .._display import Summary, Table, thin
from .fmt import count, duration, g
from .settings import NOTHING_ADDED
from .summary import coefficient_rows

__all__ = ["report_summary"]


def report_summary(rep) -> Summary:
    """The :class:`~allanite._display.Summary` of a report."""
    s = rep.summary()
    rec, fit = s["record"], s["fit"]
    tables = []
    if fit["axes"] is not None:
        tables.append(_fit_table(fit, rec))
    ref = s.get("refinement")
    if ref is not None:
        tables.append(_refinement_table(ref))
    notes = list(s["notes"]) + _missing_notes(ref)
    return Summary(
        title=f"allanite report — {rec['name']}",
        what=f"{rec['samples']} samples × {count(rec['axes'], 'axis', 'axes')} ({', '.join(rec['axis_names'])}) "
        f"at {rec['fs_hz']:g} Hz = {duration(rec['duration_s'])}",
        facts=_facts(rep, s),
        tables=tables,
        notes=notes,
        figure=lambda ax: _draw(rep, ax),
    )


def _facts(rep, s: dict) -> list:
    """The record's unit and input, the units of the model's table, the analysis and where the files went."""
    rec, fit, dy = s["record"], s["fit"], s["dynamic"]
    if rec["accel_unit"]:
        unit = f"{rec['accel_unit']} (an accelerometer's), {rec['input']} input"
    else:
        unit = f"{rec['unit'] or 'unknown (not given)'}, {rec['input']} input"
    facts = [("samples' unit", unit), ("Allan deviation in", rec["adev_unit"] or "the samples' own unit")]
    if fit["axes"] is not None:
        facts.append(("noise model in", _model_units(fit)))
    elif fit["requested"]:
        facts.append(("noise model", f"not fitted ({fit['error']})" if fit["error"] else "not fitted"))
    facts.append(
        (
            "dynamic Allan variance",
            f"{dy['windows']} windows of {dy['window_samples']} samples ({g(dy['window_s'])} s), "
            f"hop {dy['hop_samples']}",
        )
    )
    facts.append(("files", _files(rep)))
    return facts


def _model_units(fit: dict) -> str:
    """The units the noise model's table is in, as the console's heading says them."""
    if fit.get("sensor") == "accelerometer":
        return f"the accelerometer's units (m/s/√h, µg, m/s/h^1.5; samples in {fit['accel_unit']})"
    return "IEEE-952 units (°/√h, °/h, …)" if fit["unit_known"] else "base form (the unit is unknown)"


def _files(rep) -> str:
    """Where :meth:`Report.write` put report.html, summary.json and the figures, or how to write them."""
    out = getattr(rep, "written_to", None)
    if out is None:
        return "not written yet: rep.write(folder) writes report.html, summary.json and the figures"
    return f"{out / 'report.html'}, summary.json and the figures beside it"


def _fit_table(fit: dict, rec: dict) -> Table:
    """Term × axis: the coefficient with its interval (IEEE-952 or the accelerometer's units where known), χ²/dof
    and σmin at its τ."""
    rows = [[label, unit, *cells] for label, unit, cells in coefficient_rows(fit)]
    rows.append(["χ²/dof of the fit", "", *(g(ax["chi2_dof"], 3) for ax in fit["axes"])])
    rows.append(
        [
            "σmin (at τ)",
            rec["adev_unit"] or "",
            *(f"{g(ax['readoffs']['adev_min'], 3)} ({g(ax['readoffs']['tau_at_min_s'], 3)} s)" for ax in fit["axes"]),
        ]
    )
    names = [ax["name"] for ax in fit["axes"]]
    return Table(("term", "unit", *names), rows, f"noise model (IEEE 952), {fit['confidence']:.1%} intervals")


def _refinement_table(ref: dict) -> Table:
    """Axis: the effects refine added, its curve χ²/dof and RMS ADEV error start → final, held out."""
    rows = []
    for ax in ref["axes"]:
        if ax.get("error"):
            rows.append([ax["name"], "failed (see the notes)", "", "", ""])
            continue
        a, b = ax["start"], ax["final"]
        held = ax.get("start_heldout_rms_adev_pct"), ax.get("final_heldout_rms_adev_pct")
        rows.append(
            [
                ax["name"],
                ", ".join(st["effect"] for st in ax["steps"]) or NOTHING_ADDED,
                f"{g(a['chi2_dof'], 3)} → {g(b['chi2_dof'], 3)}",
                f"{g(a['rms_adev_pct'], 3)} → {g(b['rms_adev_pct'], 3)}",
                "—" if None in held else f"{g(held[0], 3)} → {g(held[1], 3)}",
            ]
        )
    header = ("axis", "effects added", "curve χ²/dof", "RMS ADEV error %", "held-out %")
    return Table(header, rows, "model refinement (allanite.refine; the curve χ²/dof is its GLS χ², not the table's)")


def _missing_notes(ref: dict | None) -> list:
    """What the refined model still misses and the channels it tried and did not keep, per axis (the console's and
    the page's sentences)."""
    if ref is None:
        return []
    said = [
        (ax["name"], ax.get("still_missing", []) + [d["text"] for d in ax.get("channels_not_kept", [])])
        for ax in ref["axes"]
    ]
    return [f"{name}: {' '.join(words)}" for name, words in said if words]


def _draw(rep, ax) -> None:
    """The inline figure: each axis's Allan deviation (≤ MAX_POINTS points) and its fitted model."""
    st = rep.static
    adev = np.atleast_2d(st.adev)
    i = thin(st.tau.size)
    for k in range(adev.shape[0]):
        ax.loglog(st.tau[i], adev[k][i], ".-", ms=2, lw=0.8, color=f"C{k % 10}", label=rep.axis_names[k])
        if rep.fits is not None:
            f = rep.fits[k]
            j = thin(f.tau.size)
            ax.loglog(f.tau[j], np.sqrt(f.model[j]), "-", lw=0.6, color="k", alpha=0.6)
    ax.set_xlabel("τ (s)")
    ax.set_ylabel(f"ADEV ({rep.adev_unit})" if rep.adev_unit else "ADEV")
    if adev.shape[0] <= 6:
        ax.legend(fontsize="small", frameon=False)
