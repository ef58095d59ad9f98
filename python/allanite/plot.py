"""Matplotlib figures for the results (imported lazily: the estimators do not need matplotlib).

Every function draws into ``ax`` (or ``axes``) when given and returns it; without one it makes a
new pyplot figure, for notebooks. The report (:mod:`allanite.report`) passes axes of plain
``matplotlib.figure.Figure`` objects, so it never touches pyplot's global state or backend.

``unit`` is the unit of the samples (``"deg/s"``, ``"rad"``…; labels show the Allan deviation's
rate unit, e.g. ``°/s``) or any label string, shown as given when it is not a known unit.
"""

from __future__ import annotations

import warnings

import numpy as np

from .errors import AllaniteError
from .units import adev_unit_label, coefficient_unit, report_unit

__all__ = ["plot_adev", "plot_davar", "plot_davar3d", "plot_fit", "plot_coefficient_series"]


def _axes(ax, projection=None):
    if ax is None:
        import matplotlib.pyplot as plt

        if projection is None:
            _, ax = plt.subplots(figsize=(6.4, 4.4))
        else:
            fig = plt.figure(figsize=(7.0, 5.2))
            ax = fig.add_subplot(projection=projection)
    return ax


def _unit_label(unit) -> str | None:
    """Label of the Allan deviation's unit: '°/s' for 'deg/s', 'µrad/s' for increments in 'urad'; an
    unknown string is shown as given."""
    if unit is None:
        return None
    try:
        return adev_unit_label(unit)
    except AllaniteError:
        return str(unit)


def _adev_label(unit) -> str:
    label = _unit_label(unit)
    return f"Allan deviation ({label})" if label else "Allan deviation"


def _rows(result, axis):
    """(index, row) pairs of a static result's axes to draw."""
    adev = np.atleast_2d(result.adev)
    if axis is None:
        return list(range(adev.shape[0]))
    if result.n_axes is None:
        return [0]
    return [int(axis)]


def plot_adev(
    result,
    ax=None,
    unit: str | None = None,
    labels=None,
    axis: int | None = None,
    band: bool = True,
    **kwargs,
):
    """Log-log ADEV against τ, one line per axis, with the confidence band when the result has
    intervals (:meth:`~allanite.AllanResult.with_confidence`).

    Parameters
    ----------
    result : AllanResult
    ax : matplotlib Axes, optional
    unit : str, optional
        Unit of the samples, for the y label.
    labels : str or sequence of str, optional
        Legend label of each axis' line, one per axis of the result (default "axis 0", "axis 1", …;
        "Allan deviation" for 1-D input). With ``axis`` the label of that axis is used. Pass the names
        here rather than to ``ax.legend``: the band of an interval is drawn too, and a list given to
        ``legend`` afterwards would pair the names with the wrong artists.
    axis : int, optional
        Draw only this axis of a multi-axis result.
    band : bool
        Shade the confidence interval of each curve (when present).
    **kwargs
        Passed to ``Axes.loglog`` for the curves.

    Returns
    -------
    matplotlib Axes
    """
    ax = _axes(ax)
    adev = np.atleast_2d(result.adev)
    ci = getattr(result, "adev_ci", None)
    lo: np.ndarray | None = None
    hi: np.ndarray | None = None
    if band and ci is not None:
        lo, hi = np.atleast_2d(ci[0]), np.atleast_2d(ci[1])
    rows = _rows(result, axis)
    names = _line_labels(labels, adev.shape[0])
    for k in rows:
        (line,) = ax.loglog(result.tau, adev[k], marker=".", label=names[k], **kwargs)
        if lo is not None and hi is not None:
            band_label = None
            if len(rows) == 1:
                band_label = f"{result.confidence:.1%} interval"
            ax.fill_between(result.tau, lo[k], hi[k], color=line.get_color(), alpha=0.22, lw=0, label=band_label)
    ax.set_xlabel("τ (s)")
    ax.set_ylabel(_adev_label(unit))
    ax.grid(True, which="both", alpha=0.3)
    if len(rows) > 1 or lo is not None or labels is not None:
        ax.legend(fontsize="small")
    return ax


#: Windows drawn at most across a figure: more are merged into this many columns (a figure is ~750 pixels
#: wide; a hop-1 DAVAR has hundreds of thousands of windows).
MAX_COLUMNS = 2000


def _bins(n: int, max_bins: int) -> np.ndarray:
    """Starts of at most ``max_bins`` consecutive, near-equal bins over 0 … n − 1."""
    return np.unique(np.linspace(0, n, min(n, max_bins) + 1).astype(np.int64)[:-1])


def _line_labels(labels, n_axes: int) -> list[str]:
    """One legend label per axis: the given ones (checked against the number of axes) or the defaults."""
    if labels is None:
        return [f"axis {k}" for k in range(n_axes)] if n_axes > 1 else ["Allan deviation"]
    names = [labels] if isinstance(labels, str) else [str(v) for v in labels]
    if len(names) != n_axes:
        axes = "1 axis" if n_axes == 1 else f"{n_axes} axes"
        raise AllaniteError(f"labels has {len(names)} name(s) for a result of {axes}: give one label per axis")
    return names


def plot_davar(result, ax=None, axis: int = 0, unit: str | None = None, cmap: str = "viridis", **kwargs):
    """Heat map of the dynamic ADEV: time on x, τ on a log y axis, log colour.

    More than ``MAX_COLUMNS`` windows are drawn as ``MAX_COLUMNS`` columns, each the ADEV of its consecutive
    windows' mean Allan variance (at the figure's width a column is less than a pixel either way).
    """
    from matplotlib.colors import LogNorm

    ax = _axes(ax)
    avar = result.avar if result.avar.ndim == 2 else result.avar[axis]
    t = result.t
    if t.size > MAX_COLUMNS:
        starts = _bins(t.size, MAX_COLUMNS)
        width = np.diff(np.append(starts, t.size))
        binned = np.empty((avar.shape[0], starts.size))
        for i, row in enumerate(avar):  # row by row: no temporary the size of the surface
            ok = np.isfinite(row)
            if ok.all():
                binned[i] = np.add.reduceat(row, starts) / width
            else:  # windows with gaps (NaN) left out of their bin's mean
                count = np.add.reduceat(ok, starts)
                with np.errstate(invalid="ignore", divide="ignore"):
                    binned[i] = np.add.reduceat(np.where(ok, row, 0.0), starts) / np.where(count > 0, count, np.nan)
        avar, t = binned, np.add.reduceat(t, starts) / width
    adev = np.sqrt(avar)
    # colour range over the resolved values: a flat window's rounding residue (~1e-19 of the largest ADEV,
    # where the definition gives 0) would stretch the scale over 19 decades
    positive = adev[adev > 1e-12 * np.nanmax(adev)] if np.any(adev > 0) else adev[adev > 0]
    norm = LogNorm(vmin=positive.min(), vmax=positive.max()) if positive.size else None
    mesh = ax.pcolormesh(t, result.tau, adev, shading="nearest", norm=norm, cmap=cmap, **kwargs)
    ax.set_yscale("log")
    ax.set_xlabel("window centre t (s)")
    ax.set_ylabel("τ (s)")
    ax.figure.colorbar(mesh, ax=ax, label=_adev_label(unit))
    return ax


def _thin_index(n: int, max_points: int) -> np.ndarray:
    """At most ``max_points`` indices spread evenly over 0 … n − 1, both ends included."""
    if n <= max_points:
        return np.arange(n)
    return np.unique(np.round(np.linspace(0, n - 1, max_points)).astype(np.int64))


def plot_davar3d(
    result,
    ax=None,
    axis: int = 0,
    unit: str | None = None,
    cmap: str = "viridis",
    max_points: int = 80,
    elev: float = 30.0,
    azim: float = -38.0,
):
    """The dynamic ADEV as a 3-D surface, as in the DAVAR papers' figures: window centre t,
    log₁₀ τ and log₁₀ ADEV.

    Only the drawing is thinned: at most ``max_points`` windows and τ (evenly spaced, ends kept) are
    drawn, so a result with thousands of windows still renders in a fraction of a second.
    """
    import mpl_toolkits.mplot3d  # noqa: F401  (registers the 3-D projection)

    ax = _axes(ax, projection="3d")
    avar = result.avar if result.avar.ndim == 2 else result.avar[axis]
    ti = _thin_index(result.t.size, max_points)
    qi = _thin_index(result.tau.size, max_points)
    sub = np.sqrt(avar[np.ix_(qi, ti)])
    positive = sub[sub > 0]
    floor = positive.min() if positive.size else 1.0
    z = np.log10(np.maximum(sub, floor))
    tt, ll = np.meshgrid(result.t[ti], np.log10(result.tau[qi]))
    ax.plot_surface(tt, ll, z, cmap=cmap, rcount=len(qi), ccount=len(ti), linewidth=0, antialiased=False)
    ax.set_xlabel("window centre t (s)")
    ax.set_ylabel("log₁₀ τ (s)")
    label = _unit_label(unit)
    ax.set_zlabel(f"log₁₀ ADEV ({label})" if label else "log₁₀ ADEV")
    ax.view_init(elev=elev, azim=azim)
    return ax


_TERM_STYLE = {"Q": "C1", "N": "C2", "B": "C3", "K": "C4", "R": "C5"}


def plot_fit(
    fit,
    ax=None,
    unit: str | None = None,
    tau=None,
    points: bool = True,
    terms: bool = True,
    color: str = "C0",
    label: str = "fitted model",
    lw: float = 2.0,
    term_decades: float | None = 1.0,
    shade_unfitted: bool = True,
):
    """The fitted model and each term as its own dashed line, over the fit's estimates.

    Parameters
    ----------
    fit : NoiseFit
    tau : array_like, optional
        Draw the model over min(tau)…max(tau) (default: the τ used in the fit). Where this reaches
        past the τ the fit used (``tau_range="auto"`` leaves out the shortest τ when the model cannot
        describe them), the model is drawn dotted there, as an extrapolation, not as a fit.
    points : bool
        Draw the estimates used in the fit with ±1σ bars (off when overlaying on :func:`plot_adev`).
    terms : bool
        Draw each non-zero term as a dashed line, labelled with its value.
    term_decades : float or None
        Draw each term only where its deviation is within this many decades below the model's
        (default 1: where it matters to the curve); None draws every term over the whole fitted τ
        range. Terms are not drawn over the τ the fit left out.
    shade_unfitted : bool
        Shade the τ outside the fitted range (when ``tau`` reaches past it) and label it "τ not fitted".

    Returns
    -------
    matplotlib Axes
    """
    ax = _axes(ax)
    lo = fit.tau[0] if tau is None else min(np.min(tau), fit.tau[0])
    hi = fit.tau[-1] if tau is None else max(np.max(tau), fit.tau[-1])
    grid = np.geomspace(lo, hi, 200)
    inside = (grid >= fit.tau[0] * (1 - 1e-9)) & (grid <= fit.tau[-1] * (1 + 1e-9))
    if points:
        err = np.sqrt(fit.avar) * np.sqrt(2.0 / fit.edf) / 2.0  # 1σ of adev ≈ adev/√(2ν)
        ax.errorbar(fit.tau, np.sqrt(fit.avar), yerr=err, fmt="o", color="k", ms=4, label="estimate (±1σ)")
    model = np.sqrt(fit.curve(grid))
    ax.loglog(grid, np.where(inside, model, np.nan), color=color, lw=lw, label=label)
    if not inside.all():
        ax.loglog(grid, _outside(model, inside), color=color, lw=max(lw / 2, 0.8), ls=":", label=None)
        if shade_unfitted:
            _shade_unfitted(ax, lo, hi, fit.tau[0], fit.tau[-1])
    if terms:
        for name in fit.terms:
            comp = np.sqrt(fit.component(name, grid))
            keep = inside if term_decades is None else inside & (comp >= model * 10.0**-term_decades)
            shown = np.where(keep, comp, np.nan)
            if np.any(comp > 0) and np.any(np.isfinite(shown) & (shown > 0)):
                c = fit.coefficients[name]
                text = f"{name} = {c.ieee:.3g} {c.ieee_unit}" if c.ieee is not None else f"{name} = {c.value:.3g}"
                ax.loglog(grid, shown, ls="--", color=_TERM_STYLE[name], label=text)
    ax.set_xlabel("τ (s)")
    ax.set_ylabel(_adev_label(unit or fit.unit))
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize="small")
    return ax


def _envelope(t: np.ndarray, low: np.ndarray, high: np.ndarray, max_bins: int = MAX_COLUMNS):
    """(t, y) drawing ``low`` … ``high`` over ``t`` with at most 2·``max_bins`` points: below that many
    windows every window as it is (t, low) — twice over for a band, (t, low, t, high) pairs interleaved —,
    above it each bin's smallest ``low`` and largest ``high`` at the bin's centre (the min–max envelope:
    at the figure's width the same picture; NaN, a gap, where a bin has none)."""
    if t.size <= max_bins:
        if low is high:
            return t, low
        return np.repeat(t, 2), np.column_stack([low, high]).ravel()
    starts = _bins(t.size, max_bins)
    centre = np.add.reduceat(t, starts) / np.diff(np.append(starts, t.size))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN bins stay NaN
        lo = np.fmin.reduceat(low, starts)
        hi = np.fmax.reduceat(high, starts)
    return np.repeat(centre, 2), np.column_stack([lo, hi]).ravel()


def _outside(values: np.ndarray, inside: np.ndarray) -> np.ndarray:
    """``values`` outside the fitted range (NaN inside), joined to the fitted part at its ends."""
    out = np.where(inside, np.nan, values)
    idx = np.flatnonzero(inside)
    if idx.size:
        out[idx[0]] = values[idx[0]]
        out[idx[-1]] = values[idx[-1]]
    return out


def _shade_unfitted(ax, lo: float, hi: float, fit_lo: float, fit_hi: float) -> None:
    label: str | None = "τ not fitted"
    for a, b in ((lo, fit_lo), (fit_hi, hi)):
        if b > a * (1 + 1e-9):
            ax.axvspan(a, b, color="0.5", alpha=0.12, lw=0, label=label)
            label = None


def plot_coefficient_series(
    series, axes=None, ieee: bool = True, reference=None, *, color=None, label=None, legend: bool = True
):
    """One panel per coefficient against window centre time, with the interval band.

    Parameters
    ----------
    series : CoefficientSeries
    axes : sequence of Axes, optional
        One per drawn coefficient (the non-zero ones, or all when every one is zero).
    ieee : bool
        IEEE-952 units (°/√h, °/h, …) when the series' unit is known, else the base form.
    reference : NoiseFit, optional
        Whole-record fit: its value of each coefficient is drawn as a dotted line (in ``color`` where given).
    color : matplotlib colour, optional
        Colour of every panel's curve, band and markers (default: one colour per coefficient) — several
        series (axes of one sensor) drawn into the same panels.
    label : str, optional
        Legend label of the curves (default: none).
    legend : bool
        Whether each panel gets its legend (whole-record line, unresolved windows).
    """
    names = [t for t in series.terms if np.any(series.values[t] > 0)] or list(series.terms)
    curve_label = label  # ``label`` below: each panel's axis label
    if axes is None:
        import matplotlib.pyplot as plt

        _, axes = plt.subplots(len(names), 1, figsize=(7.0, 1.9 * len(names)), sharex=True, squeeze=False)
        axes = axes[:, 0]
    axes = np.atleast_1d(axes)
    for ax, name in zip(axes, names):
        scale = 1.0
        label = name
        if series.unit is not None:
            if ieee:
                q = report_unit(name, 1.0, series.unit)
                scale, label = q.value, f"{name} ({q.unit})"
            else:
                label = f"{name} ({coefficient_unit(name, series.unit)})"
        colour = color if color is not None else _TERM_STYLE.get(name, "C0")
        values = np.asarray(series.values[name], dtype=np.float64)
        # A window whose fit put the term at zero (non-negative least squares) has not resolved it: the
        # value is "at most the upper bound", not 0. Draw those windows as gaps in the line, with an
        # open marker at the upper bound, so that the curve does not jump between 0 and its level.
        resolved = values > 0
        shown = np.where(resolved, values, np.nan)
        t, line = _envelope(series.t, shown, shown)
        ax.plot(
            t, line * scale, color=colour, lw=1.2, marker="." if resolved.sum() < 60 else None, ms=3, label=curve_label
        )
        low = np.where(resolved, series.ci_low[name], np.nan)
        high = np.where(resolved, np.minimum(series.ci_high[name], 1e300), np.nan)
        t, band = _envelope(series.t, low, high)
        ax.fill_between(t[::2], band[::2] * scale, band[1::2] * scale, color=colour, alpha=0.25, lw=0)
        if not resolved.all():
            up = np.where(~resolved & np.isfinite(series.ci_high[name]), series.ci_high[name], np.nan)
            t, up = _envelope(series.t, up, up)
            ax.plot(
                t,
                up * scale,
                ls="none",
                marker="v",
                mfc="none",
                mec=colour,
                ms=4,
                label="not resolved (upper bound)",
            )
        whole = reference is not None and name in reference.coefficients
        if whole:
            ref_colour = "k" if color is None else color
            ax.axhline(reference.coefficients[name].value * scale, color=ref_colour, ls=":", lw=1, label="whole record")
        if legend and (whole or not resolved.all()):  # one legend per panel (a second call would replace the first)
            ax.legend(fontsize="x-small", loc="upper right" if whole else "upper left")
        top = _coefficient_top(series, name, reference)
        if top > 0:
            ax.set_ylim(0.0, top * scale * 1.05)
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel("window centre t (s)")
    return axes


def _coefficient_top(series, name: str, reference) -> float:
    """Top of coefficient ``name``'s panel (its base unit): the highest finite interval bound, at most 3× the
    highest value (a few windows with huge intervals must not flatten the curve), and at least the highest value
    and the whole-record value."""
    finite_hi = series.ci_high[name][np.isfinite(series.ci_high[name])]
    vmax = float(np.max(series.values[name]))
    top = float(finite_hi.max()) if finite_hi.size else vmax
    if vmax > 0:
        top = min(top, 3.0 * vmax)
    top = max(top, vmax)
    if reference is not None and name in reference.coefficients:
        top = max(top, reference.coefficients[name].value)
    return top
