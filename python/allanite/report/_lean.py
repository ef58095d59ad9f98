"""The report's figures drawn with fewer matplotlib artists: the same picture, a fraction of the drawing.

Most of a report figure's time is matplotlib's Python per tick, not the pixels: a log axis spanning six decades
has ~50 minor ticks, each a ``Tick`` with two marks, a grid line and two labels (created, laid out and drawn one
by one), and its decade labels are mathtext (``$\\mathdefault{10^{-2}}$``, parsed and drawn glyph by glyph).
:func:`lean_figure`, applied to a finished figure before it is saved, draws

- the minor ticks of a log axis spanning more than ``MIN_DECADES`` decades (matplotlib labels none of them
  there) as one marker line per side and one grid-line collection — at the same places, in the same length,
  width, colour, direction and grid style;
- its decade labels as plain text with Unicode superscripts (10⁻², 2×10³);
- the title of a 2-D axes at its place above the axes (y = 1) without matplotlib's search for tick labels it
  could overlap (the report's axes have none on top).

Axes of other projections (3-D), axes with ticks drawn both ways (``direction="inout"``) and log axes of a
decade or less (whose minor ticks matplotlib labels) are left as they are.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, cast

import numpy as np

__all__ = ["lean_figure", "decade_label"]

#: A log axis is redrawn leanly when its view spans more than this many decades (matplotlib's LogFormatter
#: labels minor ticks up to one decade; above it only the decades).
MIN_DECADES = 1.05

_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")
#: (marker, axes coordinate) of tick marks on each side, pointing out of / into the axes
_MARKS = {
    ("bottom", "out"): (3, 0.0),  # matplotlib.markers.TICKDOWN
    ("bottom", "in"): (2, 0.0),  # TICKUP
    ("top", "out"): (2, 1.0),
    ("top", "in"): (3, 1.0),
    ("left", "out"): (0, 0.0),  # TICKLEFT
    ("left", "in"): (1, 0.0),  # TICKRIGHT
    ("right", "out"): (1, 1.0),
    ("right", "in"): (0, 1.0),
}


def decade_label(value: float, _pos=None) -> str:
    """A log axis' tick label as plain text: ``10⁻²`` for a decade, ``2×10³`` between decades, ``0`` for 0.

    Examples
    --------
    >>> decade_label(0.01), decade_label(2000.0), decade_label(1.0)
    ('10⁻²', '2×10³', '10⁰')
    """
    if value == 0 or not math.isfinite(value):
        return "0" if value == 0 else ""
    sign = "−" if value < 0 else ""
    exponent = math.floor(math.log10(abs(value)) + 1e-9)
    mantissa = abs(value) / 10.0**exponent
    power = "10" + str(exponent).translate(_SUPERSCRIPT)
    if abs(mantissa - round(mantissa)) < 1e-6 and round(mantissa) == 1:
        return sign + power
    return f"{sign}{mantissa:.3g}×{power}"


def lean_figure(fig) -> None:
    """Redraw the minor ticks, decade labels and titles of ``fig``'s 2-D axes with fewer artists (see the
    module's text). Call it on a finished figure, before saving: the axes' limits are taken as they are."""
    for ax in fig.axes:
        if ax.name != "rectilinear":
            continue
        for axis in (ax.xaxis, ax.yaxis):
            if axis.get_scale() == "log":
                _lean_log_axis(ax, axis)
        title = ax.title.get_text()
        if title:
            # y given: matplotlib then keeps the title where it is instead of measuring every tick label
            ax.set_title(title, y=1.0)


def _lean_log_axis(ax, axis) -> None:
    from matplotlib import rcParams as _rc
    from matplotlib.collections import LineCollection
    from matplotlib.lines import Line2D
    from matplotlib.ticker import FuncFormatter, LogFormatterSciNotation, NullLocator

    rcParams = cast("Mapping[str, Any]", _rc)  # indexed by composed names ("xtick.minor.size")
    x = axis is ax.xaxis
    lo, hi = sorted(float(v) for v in (ax.get_xlim() if x else ax.get_ylim()))  # autoscaled where pending
    if not (lo > 0 and math.isfinite(hi) and math.log10(hi / lo) > MIN_DECADES):
        return
    params = axis.get_tick_params(which="minor")
    letter = "x" if x else "y"
    direction = params.get("direction", rcParams[f"{letter}tick.direction"])
    if direction not in ("in", "out"):
        return
    if type(axis.get_major_formatter()) is LogFormatterSciNotation:
        axis.set_major_formatter(FuncFormatter(decade_label))
    locs = np.asarray(axis.get_minorticklocs(), dtype=np.float64)
    locs = locs[(locs >= lo * (1 - 1e-10)) & (locs <= hi * (1 + 1e-10))]
    axis.set_minor_locator(NullLocator())
    if locs.size == 0:
        return
    trans = ax.get_xaxis_transform(which="grid") if x else ax.get_yaxis_transform(which="grid")
    if params.get("gridOn", False):
        ends = np.array([0.0, 1.0])
        segs = [np.column_stack([np.full(2, v), ends] if x else [ends, np.full(2, v)]) for v in locs]
        grid = LineCollection(
            segs,
            transform=trans,
            colors=params.get("grid_color", rcParams["grid.color"]),
            linewidths=params.get("grid_linewidth", rcParams["grid.linewidth"]),
            linestyles=params.get("grid_linestyle", rcParams["grid.linestyle"]),
            alpha=params.get("grid_alpha", rcParams["grid.alpha"]),
            zorder=axis.get_zorder(),
        )
        ax.add_artist(grid)
    for side in ("bottom", "top") if x else ("left", "right"):
        if not params.get(side, False):
            continue
        marker, at = _MARKS[(side, direction)]
        across = np.full(locs.size, at)
        marks = Line2D(
            locs if x else across,
            across if x else locs,
            transform=trans,
            linestyle="none",
            marker=cast(Any, marker),  # matplotlib.markers.TICK*
            markersize=params.get("length", rcParams[f"{letter}tick.minor.size"]),
            markeredgewidth=params.get("width", rcParams[f"{letter}tick.minor.width"]),
            color=params.get("color", rcParams[f"{letter}tick.color"]),
            zorder=axis.get_zorder(),
            clip_on=False,
        )
        ax.add_artist(marks)
        marks.set_clip_on(False)
