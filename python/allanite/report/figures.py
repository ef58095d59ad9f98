"""The report's figures: what each shows and how to draw it into a matplotlib Figure.

Each figure is a spec ``(file name, title, caption, size in inches, draw)``; ``draw(fig)`` fills a Figure. A
figure costs the drawing of its axes (matplotlib's ticks, texts, layout) more than that of its curves, so
curves that share their axes are drawn into one figure: the DAVAR heat maps of all axes in ``davar.png`` (one
panel per axis, on one time axis) and the noise coefficients over time of all axes in ``coefficients.png``
(one panel per coefficient, one colour per axis, each with its interval band and whole-record value).
"""

from __future__ import annotations

import numpy as np

from ..plot import plot_adev, plot_coefficient_series, plot_davar, plot_davar3d, plot_fit
from ..units import adev_unit_label
from .forecasting import forecast_specs
from .settings import NOTHING_ADDED

__all__ = ["figure_specs", "from_analysis_alone", "coefficient_panels"]

#: Figures drawn from the static and dynamic analysis alone — the same with or without the fits (file names
#: or their prefixes): a figure process can draw them while the noise model is being fitted.
ANALYSIS_FIGURES = ("davar.png", "davar3d_axis")


def from_analysis_alone(name: str) -> bool:
    """Whether figure ``name`` is drawn from the static and dynamic analysis alone (``ANALYSIS_FIGURES``)."""
    return name.startswith(ANALYSIS_FIGURES)


def figure_specs(rep) -> list:
    """(file name, title, caption, size, draw) for every figure of a report; ``draw(fig)`` fills a Figure."""
    words = _words(rep)
    specs = [_overview_spec(rep, words), _davar_spec(rep, words)]
    for k in range(rep.n_axes):
        specs.append(_adev_axis_spec(rep, words, k))
        specs.append(_davar3d_spec(rep, words, k))
    if rep.series is not None:
        specs.append(_coefficients_spec(rep))
    specs.extend(_refinement_specs(rep))
    specs.extend(forecast_specs(rep))
    return specs


def _words(rep) -> dict:
    """The names of what the figures show: TheoH or Allan deviation, the confidence level."""
    theoh = rep.static.source is not None
    return {
        # none yet in the partial report offered before the intervals (its figures do not show them)
        "conf": "" if rep.static.confidence is None else f"{rep.static.confidence:.1%}",
        "static": "TheoH deviation" if theoh else "Overlapping Allan deviation",
        "static_lower": "TheoH deviation" if theoh else "Allan deviation",
        "dynamic": "Dynamic TheoH deviation (DHVAR)" if theoh else "Dynamic Allan deviation",
        "dynamic_lower": "dynamic TheoH deviation (DHVAR)" if theoh else "dynamic Allan deviation",
    }


def _overview_spec(rep, words) -> tuple:
    """``adev.png``: the Allan deviation of every axis with its interval band and fitted model."""
    st, unit, names = rep.static, rep.unit or rep.adev_unit, rep.axis_names  # an accelerometer's: its label

    def overview(fig):
        ax = fig.add_subplot()
        plot_adev(st, ax=ax, unit=unit, labels=names)
        for k, f in enumerate(rep.fits or ()):
            plot_fit(
                f,
                ax=ax,
                unit=unit,
                tau=st.tau,
                points=False,
                terms=False,
                color=f"C{k % 10}",
                label=f"{names[k]} fit",
                lw=1.0,
                shade_unfitted=False,
            )
        ax.set_title(f"{words['static']}, {words['conf']} intervals" + (" and fits" if rep.fits else ""))
        fig.subplots_adjust(left=0.11, right=0.975, bottom=0.11, top=0.93)

    caption = f"Overlapping ADEV of every axis with its {words['conf']} interval band" + (
        " and fitted model (dotted over the τ its fit left out)." if rep.fits else "."
    )
    return ("adev.png", "Allan deviation, all axes", caption, (7.2, 4.8), overview)


def _davar_spec(rep, words) -> tuple:
    """``davar.png``: the DAVAR heat map of every axis, one panel per axis on one time axis."""
    dy, names = rep.dynamic, rep.axis_names
    window = f"window {dy.window / rep.fs:g} s"

    def davar_all(fig):
        axs = fig.subplots(rep.n_axes, 1, squeeze=False)
        for k in range(rep.n_axes):
            plot_davar(dy, ax=axs[k, 0], axis=k, unit=rep.unit or rep.adev_unit)
            axs[k, 0].set_title(f"{words['dynamic']}, {names[k]} ({window})")
        h = fig.get_figheight()
        fig.subplots_adjust(left=0.1, right=1.0, bottom=0.45 / h, top=1 - 0.35 / h, hspace=0.55)

    caption = (
        f"DAVAR heat maps, one panel per axis: the ADEV of every window ({window}) — window centre on x, "
        "τ on y, log colour."
    )
    return ("davar.png", f"{words['dynamic']}, all axes", caption, (7.5, 2.7 * rep.n_axes + 0.3), davar_all)


def _adev_axis_spec(rep, words, k: int) -> tuple:
    """``adev_axisK.png``: axis K's Allan deviation, its fitted model and each term."""
    st, unit, names = rep.static, rep.unit or rep.adev_unit, rep.axis_names  # an accelerometer's: its label

    def adev_k(fig):
        ax = fig.add_subplot()
        plot_adev(st, ax=ax, unit=unit, labels=names, axis=k)
        if rep.fits is not None:
            plot_fit(rep.fits[k], ax=ax, unit=unit, tau=st.tau, points=False, color="k")
        ax.set_title(f"{names[k]}: {words['static_lower']}" + (" and noise model" if rep.fits else ""))
        fig.subplots_adjust(left=0.11, right=0.975, bottom=0.11, top=0.93)

    caption = f"ADEV of {names[k]} with its {words['conf']} interval band" + (
        "; fitted model (black; dotted over the τ the fit left out, shaded) and each term (dashed, "
        "where it is within a decade of the model)."
        if rep.fits
        else "."
    )
    return (f"adev_axis{k}.png", f"{names[k]}: Allan deviation", caption, (7.2, 4.8), adev_k)


def _davar3d_spec(rep, words, k: int) -> tuple:
    """``davar3d_axisK.png``: axis K's DAVAR as a surface."""
    name = rep.axis_names[k]

    def davar3d_k(fig):
        ax = fig.add_subplot(projection="3d")
        plot_davar3d(rep.dynamic, ax=ax, axis=k, unit=rep.unit or rep.adev_unit)
        ax.set_title(f"{name}: {words['dynamic_lower']}")
        fig.subplots_adjust(left=0.0, right=0.95, bottom=0.05, top=0.95)

    caption = "The DAVAR heat map as a surface (t, log₁₀ τ, log₁₀ ADEV), drawn on a thinned grid."
    return (f"davar3d_axis{k}.png", f"{name}: DAVAR surface", caption, (7.5, 5.6), davar3d_k)


def coefficient_panels(series) -> list[str]:
    """The coefficients drawn for each axis' series: its non-zero terms (all terms where every one is zero);
    ``coefficients.png`` has one panel for each term some axis draws, in the terms' order."""
    drawn = [{t for t in s.terms if np.any(s.values[t] > 0)} or set(s.terms) for s in series]
    return [t for t in series[0].terms if any(t in d for d in drawn)]


def _coefficients_spec(rep) -> tuple:
    """``coefficients.png``: the noise coefficients per DAVAR window of every axis, one panel per term."""
    series, names, fits = rep.series, rep.axis_names, rep.fits
    panels = coefficient_panels(series)
    conf = f"{series[0].confidence:.1%}"

    def draw(fig):
        axs = fig.subplots(len(panels), 1, sharex=True, squeeze=False)[:, 0]
        _draw_coefficients(axs, panels, series, names, fits)
        h = fig.get_figheight()
        # the title, then the legend in a row of its own above the panels (not over the curves)
        fig.suptitle(f"Noise coefficients per DAVAR window, {conf} intervals", y=1 - 0.08 / h, va="top")
        fig.subplots_adjust(left=0.13, right=0.975, bottom=0.5 / h, top=1 - 0.6 / h, hspace=0.12)

    caption = (
        "Coefficients fitted in every DAVAR window (each axis' non-zero terms; one colour per axis), with "
        f"their {conf} interval bands; dotted: the whole-record value; open triangles: the upper bound of a "
        "window that did not resolve the term."
    )
    size = (7.5, 1.45 + 1.7 * len(panels))
    return ("coefficients.png", "Noise coefficients over time", caption, size, draw)


def _draw_coefficients(axs, panels, series, names, fits) -> None:
    """Every axis' coefficient series into the panels (:func:`allanite.plot.plot_coefficient_series` per
    axis, in its colour), each panel's vertical range the largest an axis asks for, one legend on top."""
    from matplotlib.lines import Line2D

    tops = np.zeros(len(panels))
    for k, s in enumerate(series):
        own = [t for t in coefficient_panels([s]) if t in panels]
        mine = [axs[panels.index(t)] for t in own]
        colour = f"C{k % 10}"
        plot_coefficient_series(
            s, axes=mine, reference=fits[k] if fits else None, color=colour, label=names[k], legend=False
        )
        for t, ax in zip(own, mine):
            tops[panels.index(t)] = max(tops[panels.index(t)], ax.get_ylim()[1])
    for ax, top in zip(axs, tops):
        if top > 0:
            ax.set_ylim(0.0, top)
        ax.set_xlabel("")
    axs[-1].set_xlabel("window centre t (s)")
    handles = [Line2D([], [], color=f"C{k % 10}", lw=1.2, label=names[k]) for k in range(len(series))]
    if fits:
        handles.append(Line2D([], [], color="0.3", ls=":", lw=1, label="whole record"))
    if any(not np.all(s.values[t] > 0) for s in series for t in coefficient_panels([s])):
        handles.append(Line2D([], [], ls="none", marker="v", mfc="none", mec="0.3", ms=4, label="not resolved"))
    axs[0].legend(
        handles=handles,
        fontsize="small",
        loc="lower center",
        bbox_to_anchor=(0.5, 1.0),
        ncol=len(handles),
        frameon=False,
    )


def _refinement_specs(rep) -> list:
    """One figure per refined axis: :meth:`allanite.Refinement.plot` (the starting and the refined model
    on the Allan curve, and the normalised residuals before and after)."""
    if rep.refinements is None:
        return []
    label = adev_unit_label(rep.unit) if rep.unit is not None else rep.adev_unit  # an accelerometer's, or None
    specs = []
    for k, r in enumerate(rep.refinements):
        if r is None:
            continue
        name = rep.axis_names[k]

        def draw(fig, r=r, name=name):
            r.plot(fig)
            if label:
                fig.axes[0].set_ylabel(f"Allan deviation ({label})")
            found = ", ".join(st.effect for st in r.steps) or NOTHING_ADDED
            fig.suptitle(f"{name}: model refinement — {found}", fontsize="medium")
            # fixed margins, room for the title above the panels: the report's figures do no tight layout
            # (report/rendering.py), which would measure every text of the figure before drawing it
            h = fig.get_figheight()
            fig.subplots_adjust(left=0.075, right=0.985, bottom=0.5 / h, top=1 - 0.45 / h, wspace=0.2)

        specs.append(
            (
                f"refinement_axis{k}.png",
                f"{name}: model refinement",
                "Left: the Allan deviation the refinement fitted (its τ range) with the starting five-term model "
                "(blue) and the refined model (red). Right: the normalised residuals z before and after; the "
                "band is |z| ≤ 2.",
                (10.0, 4.0),
                draw,
            )
        )
    return specs
