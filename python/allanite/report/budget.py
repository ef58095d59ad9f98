"""What a report will hold, known before it is built: its memory against the library's budget.

The report's size grows with its DAVAR windows: the surface (axes × τ × windows), the noise fit of every
window and the coefficient series it keeps — and with its record: the axes the analysis copies (one at a
time for a long or memory-mapped record, :mod:`allanite.report.axes`) and the noise identification's
working arrays. :func:`report_memory` estimates the peak from the request alone
(record length, axes, window, hop, τ); :func:`check_report_memory` refuses a request over the budget
(``max_memory``, else ``ALLANITE_MAX_MEMORY``, else 2 GiB — the same budget :func:`allanite.davar` keeps)
before any heavy work, naming the size and a hop that fits, as :func:`allanite.davar` does.

Per-window series longer than :data:`SIDE_FILE_WINDOWS` windows are not written into ``summary.json`` but
into side files next to it (:mod:`allanite.report.sidefiles`).
"""

from __future__ import annotations

import math

from .._validate import resolve_max_memory
from ..errors import MemoryBudgetError

__all__ = ["SIDE_FILE_WINDOWS", "FIXED_BYTES", "report_memory", "check_report_memory"]

#: Per-window series with more windows than this go to a side file instead of ``summary.json``.
SIDE_FILE_WINDOWS = 2000

#: What the report holds whatever the windows: the static analysis, the figures (their data are thinned to
#: at most a few thousand points), the page, the interpreter's own arrays — measured ≲ 150 MB.
FIXED_BYTES = 192 * 2**20


def report_memory(
    n_windows: int, n_axes: int, n_tau: int, n_tau_fit: int, n_terms: int, fit: bool, record: int = 0
) -> dict:
    """The report's peak memory in bytes, by part, for ``n_windows`` windows of ``n_tau`` τ (``n_tau_fit``
    of them fitted) on ``n_axes`` axes:

    - ``record``: what the analysis of the record itself holds (the caller's
      :func:`allanite.report.axes.record_bytes`: its axes copied, all at once or one at a time, and the
      noise identification's working arrays) — a memory-mapped record's own pages are not counted, as the
      report never maps them in (it reads the file);
    - ``surface``: the DAVAR of every axis (kept);
    - ``fits``: the fit of one axis's windows at a time — its estimates, their floored copy and the core's
      record of θ, covariance and χ² per window (transient) — and the coefficient series of every axis:
      value, interval and IEEE value per term, χ² (kept);
    - ``fixed``: :data:`FIXED_BYTES`.
    """
    w = int(n_windows)
    k = int(n_terms) if fit else 0
    surface = 8 * w * n_axes * n_tau
    fits = 0
    if fit:
        working = 8 * w * (2 * n_tau_fit + k * k + 3 * k + 3)
        kept = 8 * w * n_axes * (4 * k + 2)
        fits = working + kept
    total = surface + fits + FIXED_BYTES + int(record)
    return {"record": int(record), "surface": surface, "fits": fits, "fixed": FIXED_BYTES, "total": total}


def check_report_memory(
    n: int,
    n_axes: int,
    window: int,
    hop: int,
    n_tau: int,
    n_tau_fit: int,
    n_terms: int,
    fit: bool,
    max_memory=None,
    record: int = 0,
) -> dict:
    """:func:`report_memory` of the request, or a :class:`~allanite.errors.MemoryBudgetError` when it is over
    the budget — naming the size, the budget and the smallest hop that fits."""
    budget = resolve_max_memory(max_memory)
    n_windows = (n - window) // hop + 1
    cost = report_memory(n_windows, n_axes, n_tau, n_tau_fit, n_terms, fit, record)
    if cost["total"] <= budget:
        return cost
    fixed = FIXED_BYTES + int(record)
    per_window = (report_memory(2, n_axes, n_tau, n_tau_fit, n_terms, fit, record)["total"] - fixed) / 2
    size = (
        f"the report would hold about {cost['total'] / 2**30:.2f} GiB ({n_windows} DAVAR windows × {n_tau} τ × "
        f"{n_axes} axes: surface {cost['surface'] / 2**30:.2f} GiB, per-window fits {cost['fits'] / 2**30:.2f} GiB; "
        f"the record's analysis {cost['record'] / 2**30:.2f} GiB), over the memory budget of {budget / 2**30:.2f} GiB"
    )
    max_windows = math.floor((budget - fixed) / per_window) if budget > fixed else 0
    if max_windows < 2:
        raise MemoryBudgetError(
            f"{size}; even two windows do not fit: use a shorter window (fewer τ) or a shorter record, or raise "
            "max_memory / ALLANITE_MAX_MEMORY"
        )
    # windows = ⌊(n − window)/hop⌋ + 1 ≤ max_windows ⟺ hop > (n − window)/max_windows: the smallest such hop
    suggest = max(hop + 1, (n - window) // max_windows + 1)
    raise MemoryBudgetError(f"{size}; use hop={suggest} or more, or raise max_memory / ALLANITE_MAX_MEMORY")
