"""Rich display of results in Jupyter: one ``_repr_html_`` shared by every result, from one template.

How a result gets its HTML
--------------------------
A result class inherits :class:`RichDisplay` and defines one method, ``_summary(self)``, that
returns a :class:`Summary` — plain data, no HTML:

.. code-block:: python

    @dataclass(frozen=True, repr=False, eq=False)
    class MyResult(RichDisplay):
        ...
        def _summary(self) -> Summary:
            return Summary(
                title="My result",
                what="what was computed, in words",
                facts=[("record", "3.6e6 samples at 100 Hz"), ("τ", "0.01–3600 s")],
                tables=[Table(header=("τ (s)", "ADEV (°/h)"), rows=[(1.0, 3.2)], caption="…")],
                notes=["fitted from τ ≥ 0.16 s"],
                figure=self._draw_small,  # optional: draws on one matplotlib Axes, ≤ MAX_POINTS points
            )

:class:`RichDisplay` renders it with ``_display.html.j2`` (Jinja2, autoescaped: every string of the
summary is text, never markup). Numbers in the rows are formatted to 4 significant digits by
:func:`fmt`; strings pass through. Tables longer than :data:`MAX_ROWS` are thinned evenly (first
and last row kept) and say so. The figure is drawn only when matplotlib is importable, on a small
``matplotlib.figure.Figure`` (no pyplot, no global state, no GUI backend), saved as SVG with text as
text; a result's ``figure`` callable must keep to :data:`MAX_POINTS` points per line (use
:func:`thin`). A figure that fails to draw is left out (the table is what matters), never an error
in the notebook. The plain ``repr`` of results is unchanged.
"""

from __future__ import annotations

import io
import math
import numbers
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from functools import lru_cache
from importlib import resources
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    import jinja2

__all__ = ["MAX_POINTS", "MAX_ROWS", "RichDisplay", "Summary", "Table", "fmt", "fmt_ci", "fmt_range", "thin"]

#: Most rows a table shows (thinned evenly beyond, first and last kept).
MAX_ROWS = 24
#: Most points a line of the inline figure may hold (see :func:`thin`).
MAX_POINTS = 300
#: Inline figure size, inches, and its resolution (SVG: only the layout depends on it).
FIGSIZE = (3.6, 2.4)


@dataclass
class Table:
    """A compact table: column headers (units in the header, e.g. ``"τ (s)"``) and rows of values."""

    header: Sequence[str]
    rows: Sequence[Sequence[Any]]
    caption: str = ""


@dataclass
class Summary:
    """What a result shows at a glance; see the module docstring."""

    title: str
    what: str = ""
    facts: Sequence[tuple[str, Any]] = ()
    tables: Sequence[Table] = ()
    notes: Sequence[str] = ()
    figure: Callable[[Any], Any] | None = None
    extra: dict = field(default_factory=dict)


def fmt(v: Any, digits: int = 4) -> str:
    """A table cell or a parameter's value: numbers (Python's, NumPy's scalars and 0-d arrays, any real) to
    ``digits`` significant digits, ∞ and NaN spelled, None as "—", strings as they are, a list, tuple or array
    as its entries so formatted, ``", "``-separated; anything else as ``str``."""
    if v is None:
        return "—"
    if isinstance(v, str):
        return v
    if isinstance(v, np.ndarray) and v.ndim == 0:
        v = v.item()
    if isinstance(v, (bool, np.bool_)):
        return str(bool(v))
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (list, tuple, np.ndarray)):
        return ", ".join(fmt(x, digits) for x in v)
    if isinstance(v, (numbers.Real, np.floating)):
        f = float(v)
        if math.isnan(f):
            return "NaN"
        if math.isinf(f):
            return "∞" if f > 0 else "−∞"
        return f"{f:.{digits}g}"
    return str(v)


def fmt_ci(v: Any, lo: Any, hi: Any, digits: int = 4) -> str:
    """``value [low, high]``."""
    return f"{fmt(v, digits)} [{fmt(lo, digits)}, {fmt(hi, digits)}]"


def fmt_range(a: Any, unit: str = "") -> str:
    """First–last of an array with a unit (``"0.01–3600 s"``)."""
    a = np.asarray(a)
    if a.size == 0:
        return "none"
    u = f" {unit}" if unit else ""
    return f"{fmt(a.flat[0])}–{fmt(a.flat[-1])}{u}" if a.size > 1 else f"{fmt(a.flat[0])}{u}"


def thin(n: int, cap: int = MAX_POINTS) -> np.ndarray:
    """Indices of at most ``cap`` of ``n`` items, evenly spread, first and last included."""
    if n <= cap:
        return np.arange(n)
    return np.unique(np.round(np.linspace(0, n - 1, cap)).astype(np.int64))


@lru_cache(maxsize=1)
def _template() -> jinja2.Template:
    import jinja2  # where a result is shown as HTML: not on ``import allanite`` (~0.1 s)

    text = resources.files(__package__).joinpath("_display.html.j2").read_text(encoding="utf-8")
    env = jinja2.Environment(autoescape=True, undefined=jinja2.StrictUndefined)
    return env.from_string(text)


def _svg(draw: Callable[[Any], Any]) -> str | None:
    """The figure ``draw`` makes on one small Axes, as SVG text; None without matplotlib or on failure."""
    try:
        import matplotlib
        from matplotlib.figure import Figure
    except ImportError:
        return None
    try:
        with matplotlib.rc_context({"svg.fonttype": "none", "font.size": 7, "svg.hashsalt": "allanite"}):
            fig = Figure(figsize=FIGSIZE)
            ax = fig.add_subplot()
            draw(ax)
            fig.tight_layout(pad=0.3)
            buf = io.StringIO()
            fig.savefig(buf, format="svg")
    except Exception:  # a figure is a nicety: the summary must show even if drawing fails
        return None
    text = buf.getvalue()
    start = text.find("<svg")  # drop the XML prolog and DOCTYPE: the SVG sits inside HTML
    return text[start:] if start >= 0 else None


def _rows(table: Table) -> tuple[list[list[str]], str]:
    rows = list(table.rows)
    keep = thin(len(rows), MAX_ROWS)
    note = f"{keep.size} of {len(rows)} rows shown" if keep.size < len(rows) else ""
    return [[fmt(c) for c in rows[i]] for i in keep], note


def render(summary: Summary, figure: bool = True) -> str:
    """The HTML of a summary (``figure=False``: without the inline figure)."""
    tables = []
    for t in summary.tables:
        rows, note = _rows(t)
        tables.append({"header": [str(h) for h in t.header], "rows": rows, "caption": t.caption, "note": note})
    svg = _svg(summary.figure) if (figure and summary.figure is not None) else None
    return _template().render(
        title=summary.title,
        what=summary.what,
        facts=[(str(k), fmt(v)) for k, v in summary.facts],
        tables=tables,
        notes=[str(n) for n in summary.notes],
        svg=svg,
    )


class RichDisplay:
    """Mixin: ``_repr_html_`` for Jupyter from the class's ``_summary()`` (see the module docstring)."""

    def _summary(self) -> Summary:  # pragma: no cover - every result defines its own
        raise NotImplementedError

    def _repr_html_(self) -> str:
        return render(self._summary())
