"""The :class:`Report`: everything the report shows, its summary, text, figures and the files it writes
(built by :func:`allanite.report.build_report`)."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from .._display import render
from .._progress import StepBar
from ..results import AllanResult, DynamicAllanResult
from ..units import ACCEL_LABELS, adev_unit_label
from . import _worker
from ._notebook import report_summary
from .figures import figure_specs
from .fmt import count
from .page import html_page, page_context
from .rendering import render_pngs
from .sidefiles import write_side_files
from .summary import summarize, text_summary

if TYPE_CHECKING:
    from ..model import Refinement

__all__ = ["Report", "steps"]


def steps(progress, total: int, desc: str):
    """(step object, made here?): the caller's (the CLI's bar), or a :class:`StepBar` for ``progress``
    None/True/False — None shows one only in a notebook or a terminal (see :mod:`allanite._progress`)."""
    if progress is None or isinstance(progress, bool):
        return StepBar(progress, total, desc), True
    return progress, False


@dataclass
class Report:
    """Everything the report shows. Build it with :func:`build_report` or :func:`from_log`. In a notebook it
    shows as its main numbers, the units they are in, what the refinement left unexplained and where
    :meth:`write` put the files (``_repr_html_``).

    Attributes
    ----------
    static : AllanResult
        Overlapping Allan variance of the whole record, with confidence intervals, (axes, τ).
    dynamic : DynamicAllanResult
        DAVAR, (axes, τ, t).
    fits : list of NoiseFit or None
        Whole-record noise-model fit per axis (None with ``fit=False`` or when it failed: ``fit_error``).
    series : list of CoefficientSeries or None
        The coefficients fitted in every DAVAR window, per axis (``series_error`` when it failed).
    unit : str or None
        Unit of the samples (canonical name, e.g. ``"deg/s"``); None when unknown or an accelerometer's.
    accel_unit : str or None
        The accelerometer's unit of the samples (e.g. ``"m/s^2"``, ``"g"``) where they are an accelerometer's
        (``build_report(unit="m/s^2")``), else None.
    axis_names : list of str
    source : dict
        Where the record came from (JSON-able): path, format, columns, gaps, …
    notes : list of str
        Things the reader must know (unit unknown, gaps, warnings while reading).
    written_to : Path or None
        The folder the last :meth:`write` wrote into (None before).
    """

    static: AllanResult
    dynamic: DynamicAllanResult
    fits: list | None
    series: list | None
    fs: float
    unit: str | None
    input: str
    axis_names: list
    source: dict
    settings: dict
    notes: list = field(default_factory=list)
    fit_requested: bool = True
    fit_error: str | None = None
    series_error: str | None = None
    created: str = ""
    #: per axis :class:`~allanite.Refinement` (``refine=True``), else None
    refinements: list[Refinement | None] | None = None
    #: per axis :class:`~allanite.TimeFrames` and :func:`allanite.forecast.compare` table (``frames=`` or
    #: ``forecast=`` given), else None; ``forecast_error`` when they could not be computed
    frames: list | None = None
    forecasts: list | None = None
    forecast_settings: dict | None = None
    forecast_error: str | None = None
    #: the paper-002 sections (``taper=`` / ``split=``; :mod:`allanite.report.paper002`), else None
    paper002: dict | None = None
    accel_unit: str | None = None
    written_to: Path | None = field(default=None, init=False)
    _summary: dict | None = field(default=None, repr=False)

    # ---------------------------------------------------------------------------- properties
    @property
    def n_axes(self) -> int:
        """Number of axes the report analyses."""
        return len(self.axis_names)

    @property
    def adev_unit(self) -> str | None:
        """Label of the Allan deviation's unit (e.g. ``"°/s"``), None when the unit is unknown."""
        if self.unit is None:
            return None if self.accel_unit is None else ACCEL_LABELS[self.accel_unit]
        return adev_unit_label(self.unit)

    def __repr__(self) -> str:
        fit = "not fitted" if self.fits is None else f"{len(self.fits)} noise fits"
        unit = self.unit or self.accel_unit or "unknown"
        return (
            f"Report({self.source.get('name', 'record')!r}: {self.static.n_samples} samples × "
            f"{count(self.n_axes, 'axis', 'axes')} at {self.fs:g} Hz, unit {unit}; "
            f"{self.static.tau.size} τ, "
            f"{self.dynamic.t.size} DAVAR windows; {fit})"
        )

    # ---------------------------------------------------------------------------- summary
    def summary(self) -> dict:
        """Every number of the report, JSON-able (what ``summary.json`` holds)."""
        if self._summary is None:
            self._summary = summarize(self)
        return self._summary

    def _repr_html_(self) -> str:
        """The notebook display (:mod:`allanite.report._notebook`, in :mod:`allanite._display`'s template)."""
        return render(report_summary(self))

    def text(self) -> str:
        """The terminal summary: ADEV table with intervals, fitted coefficients, DAVAR summary."""
        return text_summary(self.summary())

    # ---------------------------------------------------------------------------- figures
    def figure_specs(self) -> list:
        """(file name, title, caption, draw) for every figure; ``draw(fig)`` fills a matplotlib Figure."""
        return figure_specs(self)

    def render_figures(self, progress=None, dpi: int = 100) -> dict:
        """File name → PNG bytes of every figure: by the figure process started before the report was computed
        where one waits (:mod:`allanite.report._worker`, the command line's), else drawn here — on two
        processes where two cores are available (:mod:`allanite.report.rendering`)."""
        specs = self.figure_specs()
        progress, own = steps(progress, len(specs), "figures")
        images = _worker.take(self, dpi)
        if images is not None and list(images) == [spec[0] for spec in specs]:
            for name in images:
                progress.step(f"figure {name}")
        else:
            images = render_pngs(specs, dpi, progress.step)
        if own:
            progress.close()
        return images

    def html(self, images: dict) -> str:
        """The self-contained HTML page, with ``images`` (file name → PNG bytes) embedded as data URIs."""
        return html_page(self, images)

    def write(self, out, progress=None, dpi: int = 100) -> list:
        """Write ``report.html``, ``summary.json`` and the PNG figures into folder ``out`` (created if
        needed), and the side files of a report of more than ``SIDE_FILE_WINDOWS`` windows
        (:mod:`allanite.report.sidefiles`). Returns the paths written, report.html and summary.json first,
        the side files last."""
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        specs = self.figure_specs()
        progress, own = steps(progress, len(specs) + 1, "report files")
        # while a figure process draws (handed the report now), the JSON and the page's template are made here
        _worker.hand_over(self, dpi)
        summary = self.summary()
        entry = (summary.get("side_files") or {}).get("series") or {}
        side = [name for name in (entry.get("npz"), entry.get("parquet")) if name]
        summary["files"] = {
            "html": "report.html",
            "summary": "summary.json",
            "figures": [spec[0] for spec in specs],
            "side_files": list(side),
        }
        text = json.dumps(summary, indent=1, ensure_ascii=False, allow_nan=False)
        page = page_context(self)
        images = self.render_figures(progress, dpi=dpi)
        progress.step("writing report.html, summary.json")
        pngs = []
        for name, data in images.items():
            p = out / name
            p.write_bytes(data)
            pngs.append(p)
        written = write_side_files(self, out) if side else []
        (out / "summary.json").write_text(text, encoding="utf-8")
        (out / "report.html").write_text(html_page(self, images, page), encoding="utf-8")
        self.written_to = out
        if own:
            progress.close()
        return [out / "report.html", out / "summary.json"] + pngs + written
