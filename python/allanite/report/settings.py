"""The report's settings: its model line, default window and hop, and the estimators it offers."""

from __future__ import annotations

__all__ = [
    "FIT_MODEL",
    "WINDOW_FRACTION",
    "HOP_FRACTION",
    "DHVAR_MAX_DEFAULT_WINDOW",
    "DHVAR_MAX_WINDOWS",
    "REPORT_ESTIMATORS",
    "NOTHING_ADDED",
    "default_window",
    "default_hop",
]

#: The model the report fits (docs/FORMULAS.md §4.1; the K column is exact for a sampled random walk).
FIT_MODEL = "σ²(τ) = 3Q²/τ² + N²/τ + (2 ln2/π)·B² + K²·τ0·(2m²+1)/(6m) + R²·τ²/2"
#: The default DAVAR window is 1/WINDOW_FRACTION of the record.
WINDOW_FRACTION = 12
#: The default hop is 1/HOP_FRACTION of the window.
HOP_FRACTION = 25
#: DHVAR's cost grows with the window squared (Theo1 at every m of the bias ratio): its default
#: window is capped here (paper 001 uses 401 samples).
DHVAR_MAX_DEFAULT_WINDOW = 2001
#: ... and its default hop keeps the number of windows (each fitted) to about this.
DHVAR_MAX_WINDOWS = 400
#: What the page and the console say for an axis to which refine added no effect.
NOTHING_ADDED = "nothing added"
#: estimator → (static estimator, dynamic estimator, dynamic τ grid, section titles)
REPORT_ESTIMATORS = {
    "oavar": ("oavar", "oavar", "exp", "Overlapping Allan deviation", "Dynamic Allan variance"),
    "theoh": (
        "theoh",
        "theoh",
        "octave",
        "TheoH deviation (overlapping Allan ≤ 10 % of the record, TheoBR beyond)",
        "Dynamic TheoH (DHVAR)",
    ),
}


def default_window(n_samples: int) -> int:
    """The report's default DAVAR window: 1/12 of the record (at least 2 samples)."""
    return max(2, int(n_samples) // WINDOW_FRACTION)


def default_hop(window: int) -> int:
    """The report's default hop: 1/25 of the window (at least 1 sample) — 25 windows overlap at any time."""
    return max(1, int(window) // HOP_FRACTION)
