"""The report's optional sections, each computed after the noise model: the model refinement of every axis
(:func:`allanite.refine`), the time frames and the coefficient forecast (paper 004), and paper 002's sections
(tapered DAVAR, wavelet split). Each is None when not asked for; a failure is a note, not a failed report. Used
by :func:`allanite.report.build.build_report`."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..errors import AllaniteError, ParameterError
from ..model.effects import EFFECTS
from .axes import axis_column
from .forecasting import run_forecast
from .paper002 import compute as paper002_sections

if TYPE_CHECKING:
    from ..model import Refinement

__all__ = ["forecast_section", "paper002_section", "refine_axes", "refine_candidates", "refinement_section"]


def refinement_section(x, fs, input, unit_name, static, axis_names, asked, notes, settings, progress):
    """Every axis's refinement (None where it failed), or None when not asked for; ``asked``: the candidate
    effects, the other channels and the declared filter (None: none). The effects tried and the channels' names go
    into ``settings``."""
    candidates, channels = asked[:2]
    refinements: list[Refinement | None] | None = None
    if candidates is not None:
        progress.step("model refinement")
        refinements = refine_axes(x, fs, input, unit_name, static, axis_names, asked, notes)
        settings["refine_candidates"] = list(candidates)
        if channels:
            settings["channels"] = list(channels)
            notes.append(
                f"Channel{'s' if len(channels) > 1 else ''} {', '.join(channels)} passed to every axis's model "
                f"refinement, for its regression on {'them' if len(channels) > 1 else 'it'}; a coefficient is per "
                "unit of the channel's samples, as logged (its name's unit, where it gives one, e.g. [degC]): "
                "allanite converts no channel's unit."
            )
    return refinements


def forecast_section(x, fs, plan, unit_name, input, confidence, notes, progress) -> tuple:
    """(frame fits, forecasts, the plan, error or None) of the time-frame section, all None without a plan;
    a forecast that cannot be computed is a note, not a failed report."""
    frame_fits = forecasts = forecast_error = None
    if plan is None:
        return None, None, None, None
    progress.step("time frames and coefficient forecast")
    try:
        frame_fits, forecasts = run_forecast(x, fs, plan, unit=unit_name, input=input, confidence=confidence)
    except AllaniteError as exc:
        forecast_error = str(exc)
        notes.append(f"The coefficient forecast could not be computed: {exc}")
    return frame_fits, forecasts, plan, forecast_error


def paper002_section(x, fs, input, dynamic, unit_name, axis_names, taper, split, notes, progress) -> dict | None:
    """Paper 002's sections (tapered DAVAR, wavelet split) on the DAVAR's windows and τ, or None unasked."""
    if not (taper or split):
        return None
    progress.step("paper 002 sections")
    return paper002_sections(
        x, fs, input=input, window=dynamic.window, hop=dynamic.hop, taus=dynamic.tau, unit=unit_name,
        axis_names=axis_names, taper=taper, split=split, notes=notes,
    )  # fmt: skip


def refine_candidates(refine) -> tuple | None:
    """The candidate effects of ``refine=`` (True: all of them; False/None: no refinement), checked."""
    if refine is None or refine is False:
        return None
    if refine is True:
        return tuple(EFFECTS)
    names = (refine,) if isinstance(refine, str) else tuple(refine)
    bad = [n for n in names if n not in EFFECTS]
    if bad:
        raise ParameterError(f"refine: unknown candidate effect {bad[0]!r}; allowed: {', '.join(EFFECTS)}")
    return names


def _axis_notes(ref, name: str) -> list[str]:
    """The notes the page needs from one axis's refinement: which samples the searches saw filled, a counter's
    exact quantisation term (its Q is the counter's: said where it is read), and the filter the user declared."""
    from ..model.refinement._gapfill import filled_words
    from ..model.refinement.words import declared_sentence

    out = []
    if ref.filled:
        out.append(f"Model refinement of {name}: {filled_words(ref.filled)}.")
    if ref.counter is not None:
        out.append(f"Model refinement of {name}: {ref.counter.describe(ref.fit.unit)}.")
    if getattr(ref, "declared_filter", None) is not None:
        out.append(f"Model refinement of {name}: {declared_sentence(ref.declared_filter, 'bandwidth' in ref.found)}")
    return out


def refine_axes(x, fs, input, unit_name, static, axis_names, asked, notes) -> list:
    """:func:`allanite.refine` on every axis (None for an axis it fails on, with a note why); ``asked``: the
    candidate effects and the other channels (None: none)."""
    from ..model import refine as refine_axis  # the refinement package (scipy.signal) only when asked
    from ..model._null_records import sharing

    candidates, channels = asked[:2]
    declared = asked[2] if len(asked) > 2 else None

    refinements: list = []
    # the same τ range the whole-record fit used (none unless given): start at 0.1 s when the
    # shortest τ are below it, as real gyros' anti-alias filters colour them
    t0 = 0.1 if static.tau[0] < 0.1 else None
    # the checks' null records are every axis's: their flicker kept from one axis's call to the next
    with sharing():
        for k in range(x.shape[1]):
            try:
                refinements.append(
                    refine_axis(
                        axis_column(x, k),
                        fs,
                        input=input,
                        unit=unit_name,
                        tau_range=None if t0 is None else (t0, None),
                        candidates=candidates,
                        channels=channels,
                        filter=declared,
                        gaps="skip" if np.any(np.asarray(static.missing) > 0) else "error",
                    )
                )
                notes.extend(_axis_notes(refinements[-1], axis_names[k]))
            except AllaniteError as exc:
                refinements.append(None)
                notes.append(f"Model refinement of {axis_names[k]} failed: {exc}")
    return refinements
