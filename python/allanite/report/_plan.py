"""The report's plan before any heavy work: the DAVAR window and hop (given, or the report's defaults, and how
they were chosen) and the memory plan (the whole request's size against the budget, every axis at once or one
at a time). Used by :func:`allanite.report.build.build_report`."""

from __future__ import annotations

from .._validate import check_count
from ..errors import MemoryBudgetError, ParameterError
from ..model.terms import TERMS
from .axes import record_bytes, wants_by_axis
from .budget import check_report_memory
from .settings import (
    DHVAR_MAX_DEFAULT_WINDOW,
    DHVAR_MAX_WINDOWS,
    HOP_FRACTION,
    WINDOW_FRACTION,
    default_hop,
    default_window,
)

__all__ = ["memory_plan", "octaves", "window_and_hop"]


def window_and_hop(n, window, hop, estimator):
    """The DAVAR window and hop (given, or the report's defaults) and how they were chosen."""
    window_given, hop_given = window is not None, hop is not None
    window_rule = hop_rule = "given"
    if window is None:
        window = default_window(n)
        window_rule = f"record/{WINDOW_FRACTION}"
        if estimator == "theoh" and window > DHVAR_MAX_DEFAULT_WINDOW:
            window = DHVAR_MAX_DEFAULT_WINDOW
            window_rule = f"record/{WINDOW_FRACTION}, capped at {DHVAR_MAX_DEFAULT_WINDOW} samples for DHVAR"
    else:
        window = check_count(window, "window", 2)
    if window > n:
        raise ParameterError(f"window ({window} samples) is longer than the record ({n} samples)")
    if hop is None:
        hop = default_hop(window)
        hop_rule = f"window/{HOP_FRACTION}"
        if estimator == "theoh":
            # every DHVAR window gets its own fit: keep it to about DHVAR_MAX_WINDOWS of them — but never
            # hop past a window's end, which would leave samples out of every window
            fewer = min(window, -(-(n - window) // DHVAR_MAX_WINDOWS))
            if fewer > hop:
                hop = fewer
                hop_rule = f"raised from window/{HOP_FRACTION} to keep about {DHVAR_MAX_WINDOWS} windows" + (
                    " (at most the window, so that no sample is left out)" if hop == window else ""
                )
    else:
        hop = check_count(hop, "hop", 1)
        if hop > n:
            raise ParameterError(
                f"hop ({hop} samples) is longer than the record ({n} samples): give a hop of at most "
                f"the window ({window} samples) so that every sample is in a window"
            )
    settings = {
        "window": int(window),
        "hop": int(hop),
        "window_default": not window_given,
        "hop_default": not hop_given,
        "window_rule": window_rule,
        "hop_rule": hop_rule,
    }
    return window, hop, settings


def memory_plan(x, n, n_axes, window, hop, n_tau, n_fit, fit, max_memory) -> tuple[bool, dict]:
    """(analyse axis by axis?, the cost by part): a memory-mapped record always axis by axis; one in memory
    axis by axis where all its axes at once would exceed the budget and one at a time fits."""
    by_axis = wants_by_axis(x)
    try:
        cost = check_report_memory(
            n, n_axes, window, hop, n_tau, n_fit, len(TERMS), fit, max_memory,
            record=record_bytes(n, n_axes, by_axis),
        )  # fmt: skip
    except MemoryBudgetError:
        if by_axis or n_axes == 1:
            raise
        by_axis = True
        cost = check_report_memory(
            n, n_axes, window, hop, n_tau, n_fit, len(TERMS), fit, max_memory, record=record_bytes(n, n_axes, True)
        )
    return by_axis, cost


def octaves(ms) -> int:
    """How many of the averaging factors ``ms`` an octave-thinned fit keeps (each at least twice the last)."""
    kept, last = 0, 0.0
    for m in ms:
        if m >= 2.0 * last * (1 - 1e-12):
            kept, last = kept + 1, float(m)
    return kept
