"""The report's figures: what each shows and how to draw it into a matplotlib Figure."""

from __future__ import annotations

import numpy as np

from ..plot import plot_adev, plot_coefficient_series, plot_davar, plot_davar3d, plot_fit
from ..units import adev_unit_label
from .forecasting import forecast_specs
from .settings import NOTHING_ADDED

__all__ = ["figure_specs", "from_analysis_alone"]

#: Figures drawn from the static and dynamic analysis alone — the same with or without the fits (file names
#: or their prefixes): a figure process can draw them while the noise model is being fitted.
ANALYSIS_FIGURES = ("davar.png", "davar_axis", "davar3d_axis")


def from_analysis_alone(name: str) -> bool:
    """Whether figure ``name`` is drawn from the static and dynamic analysis alone (``ANALYSIS_FIGURES``)."""
    return name.startswith(ANALYSIS_FIGURES)


def figure_specs(rep) -> list:
    """(file name, title, caption, size, draw) for every figure of a report; ``draw(fig)`` fills a Figure."""
    st, dy, unit, names = rep.static, rep.dynamic, rep.unit, rep.axis_names
    specs = []
    conf = f"{st.confidence:.1%}"
    theoh = st.source is not None
    static_word = "TheoH deviation" if theoh else "Overlapping Allan deviation"
    dynamic_word = "Dynamic TheoH deviation (DHVAR)" if theoh else "Dynamic Allan deviation"
    static_lower = "TheoH deviation" if theoh else "Allan deviation"
    dynamic_lower = "dynamic TheoH deviation (DHVAR)" if theoh else "dynamic Allan deviation"

    def overview(fig):
        ax = fig.add_subplot()
        plot_adev(st, ax=ax, unit=unit, labels=names)
        if rep.fits is not None:
            for k, f in enumerate(rep.fits):
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
        ax.set_title(f"{static_word}, {conf} intervals" + (" and fits" if rep.fits else ""))
        fig.subplots_adjust(left=0.11, right=0.975, bottom=0.11, top=0.93)

    specs.append(
        (
            "adev.png",
            "Allan deviation, all axes",
            f"Overlapping ADEV of every axis with its {conf} "
            "interval band" + (" and fitted model (dotted over the τ its fit left out)." if rep.fits else "."),
            (7.2, 4.8),
            overview,
        )
    )

    def davar_all(fig):
        axs = fig.subplots(rep.n_axes, 1, squeeze=False)
        for k in range(rep.n_axes):
            plot_davar(dy, ax=axs[k, 0], axis=k, unit=unit)
            axs[k, 0].set_title(f"{dynamic_word}, {names[k]}")
        fig.subplots_adjust(
            left=0.1, right=1.0, bottom=0.45 / fig.get_figheight(), top=1 - 0.35 / fig.get_figheight(), hspace=0.55
        )

    specs.append(
        (
            "davar.png",
            "Dynamic Allan deviation, all axes",
            "DAVAR heat maps, one panel per axis.",
            (7.5, 2.7 * rep.n_axes + 0.3),
            davar_all,
        )
    )

    for k in range(rep.n_axes):

        def adev_k(fig, k=k):
            ax = fig.add_subplot()
            plot_adev(st, ax=ax, unit=unit, labels=names, axis=k)
            if rep.fits is not None:
                plot_fit(rep.fits[k], ax=ax, unit=unit, tau=st.tau, points=False, color="k")
            ax.set_title(f"{names[k]}: {static_lower}" + (" and noise model" if rep.fits else ""))
            fig.subplots_adjust(left=0.11, right=0.975, bottom=0.11, top=0.93)

        def davar_k(fig, k=k):
            ax = fig.add_subplot()
            plot_davar(dy, ax=ax, axis=k, unit=unit)
            ax.set_title(f"{names[k]}: {dynamic_lower} (window {dy.window / rep.fs:g} s)")
            fig.subplots_adjust(left=0.1, right=1.0, bottom=0.12, top=0.92)

        def davar3d_k(fig, k=k):
            ax = fig.add_subplot(projection="3d")
            plot_davar3d(dy, ax=ax, axis=k, unit=unit)
            ax.set_title(f"{names[k]}: {dynamic_lower}")
            fig.subplots_adjust(left=0.0, right=0.95, bottom=0.05, top=0.95)

        specs.append(
            (
                f"adev_axis{k}.png",
                f"{names[k]}: Allan deviation",
                f"ADEV of {names[k]} with its {conf} interval band"
                + (
                    "; fitted model (black; dotted over the τ the fit left out, shaded) and each term (dashed, "
                    "where it is within a decade of the model)."
                    if rep.fits
                    else "."
                ),
                (7.2, 4.8),
                adev_k,
            )
        )
        specs.append(
            (
                f"davar_axis{k}.png",
                f"{names[k]}: DAVAR heat map",
                "ADEV of every window: window centre on x, τ on y, log colour.",
                (7.5, 4.2),
                davar_k,
            )
        )
        specs.append(
            (
                f"davar3d_axis{k}.png",
                f"{names[k]}: DAVAR surface",
                "The same as a surface (t, log₁₀ τ, log₁₀ ADEV), drawn on a thinned grid.",
                (7.5, 5.6),
                davar3d_k,
            )
        )
        if rep.series is not None:
            s = rep.series[k]
            n_panels = len([t for t in s.terms if np.any(s.values[t] > 0)] or s.terms)

            def coef_k(fig, k=k, s=s, n_panels=n_panels):
                axs = fig.subplots(n_panels, 1, sharex=True, squeeze=False)[:, 0]
                plot_coefficient_series(s, axes=axs, reference=rep.fits[k] if rep.fits else None)
                axs[0].set_title(f"{names[k]}: noise coefficients per DAVAR window, {s.confidence:.1%} intervals")
                fig.subplots_adjust(
                    left=0.13,
                    right=0.975,
                    bottom=0.5 / fig.get_figheight(),
                    top=1 - 0.35 / fig.get_figheight(),
                    hspace=0.12,
                )

            specs.append(
                (
                    f"coefficients_axis{k}.png",
                    f"{names[k]}: coefficients over time",
                    "Coefficients fitted in every DAVAR window (non-zero terms), with interval bands; "
                    "dotted: the whole-record value.",
                    (7.5, 1.2 + 1.7 * n_panels),
                    coef_k,
                )
            )
    specs.extend(_refinement_specs(rep))
    specs.extend(forecast_specs(rep))
    return specs


def _refinement_specs(rep) -> list:
    """One figure per refined axis: :meth:`allanite.Refinement.plot` (the starting and the refined model
    on the Allan curve, and the normalised residuals before and after)."""
    if rep.refinements is None:
        return []
    label = adev_unit_label(rep.unit) if rep.unit is not None else None
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
