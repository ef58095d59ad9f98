"""A record with NaN-marked gaps made whole for :func:`allanite.refine` (``gaps="skip"``): the searches along time
(spectral lines, outliers, change points, drift, channels, warm-up) and the held-out split need every sample, so
each gap is filled — by the straight line between the medians of its neighbours — after checking that few enough
samples are missing for the fill not to matter. What was filled, and how far the fill moved the Allan curve from
the curve that skips the gaps, is said in ``Refinement.filled``.

Why a line between neighbourhood medians, not between the two neighbours: a straight segment between two single
samples carries their noise over the whole gap (its sum varies as L²σ²/2 against Lσ² for the samples it stands
for), which raises the Allan variance of white noise at τ beyond the gap's length; medians of L samples on each
side make it ~(π/4)·Lσ², a little below, and follow a drift or a slow wander through the gap. The samples filled
carry no noise of their own: the curve falls by about the share filled at τ shorter than a gap (≤ 5 %, the most
allowed), which ``curve_change_pct`` states.

The report (``build_report(..., gaps="skip")``) fills with the same line (:func:`filled_columns`) for the one thing
it needs whole samples for: identifying each τ's noise type behind the Allan deviation's intervals. Before, it
joined the two single neighbours, which carries their noise (a spike's too) across the gap as a ramp; with 1 %
dropped in 20 gaps that named another noise type than the record before the drop at 15 of 204 τ of 12 simulated
records (the medians at 2), at 138 of 204 with a spike beside each gap (at 5), and at 11 and 12 of 57 τ × axis
of ADIS16405 runs 1 and 2 (at none).
"""

from __future__ import annotations

import numpy as np

from ...errors import DataGapError

__all__ = [
    "MAX_MISSING",
    "MAX_GAP",
    "MIN_SIDE",
    "fill_gaps",
    "filled_columns",
    "gap_runs",
    "filled_record",
    "fill_channel",
    "filled_words",
]

#: At most this share of the samples may be missing (more: a DataGapError).
MAX_MISSING = 0.05
#: No gap may be longer than this share of the record (longer: a DataGapError — split the log at it instead).
MAX_GAP = 0.01
#: Each side's median takes at least this many samples (and as many as the gap is long).
MIN_SIDE = 8

#: How the gaps were filled, in words (``Refinement.filled["method"]``).
METHOD = (
    "each gap filled by the straight line between the medians of its neighbours (as many samples on each side as "
    f"the gap is long, at least {MIN_SIDE}), for the searches along time and the held-out split"
)


def gap_runs(missing: np.ndarray) -> np.ndarray:
    """(start, length) of every run of True in ``missing``, shape (runs, 2)."""
    d = np.diff(np.concatenate(([0], missing.astype(np.int8), [0])))
    starts, ends = np.flatnonzero(d == 1), np.flatnonzero(d == -1)
    return np.column_stack((starts, ends - starts))


def check_gaps(missing: np.ndarray, fs: float, what: str = "the samples") -> np.ndarray:
    """The gaps of ``missing`` (:func:`gap_runs`), or a DataGapError when too many samples are missing or one gap
    is too long to fill."""
    n = missing.size
    runs = gap_runs(missing)
    lost = int(runs[:, 1].sum()) if runs.size else 0
    if lost > MAX_MISSING * n:
        raise DataGapError(
            f"{what}: {lost} of {n} samples ({100 * lost / n:.3g} %) are missing (NaN); refine(gaps='skip') fills at "
            f"most {100 * MAX_MISSING:g} % — analyse the longest gap-free stretch instead (read_log(..., "
            f"gaps='longest'))"
        )
    if runs.size and runs[:, 1].max() > MAX_GAP * n:
        k = int(np.argmax(runs[:, 1]))
        start, length = int(runs[k, 0]), int(runs[k, 1])
        raise DataGapError(
            f"{what}: a gap of {length} samples ({length / fs:.6g} s) from sample {start} is longer than "
            f"{100 * MAX_GAP:g} % of the record ({MAX_GAP * n / fs:.6g} s), the longest refine(gaps='skip') fills — "
            f"split the log there (read_log(..., gaps='split')) or analyse its longest stretch (gaps='longest')"
        )
    return runs


def fill_gaps(y: np.ndarray, runs: np.ndarray) -> np.ndarray:
    """A copy of ``y`` whose NaN runs ``runs`` are filled by the line between their neighbourhoods' medians."""
    out = np.array(y, dtype=np.float64)
    n = out.size
    for start, length in runs:
        side = max(MIN_SIDE, int(length))
        left = out[max(0, start - side) : start]
        right = y[start + length : min(n, start + length + side)]
        left, right = left[np.isfinite(left)], right[np.isfinite(right)]
        lo = float(np.median(left)) if left.size else None
        hi = float(np.median(right)) if right.size else None
        lo = hi if lo is None else lo
        hi = lo if hi is None else hi
        if lo is None or hi is None:  # nothing finite near: not reached after check_gaps on a record of ≥ 2 samples
            lo = hi = float(np.nanmedian(y))
        # the two levels sit at the middle of their neighbourhoods; the line through them, read inside the gap
        xl, xr = -(left.size + 1) / 2.0, length - 1 + (right.size + 1) / 2.0
        pos = np.arange(length, dtype=np.float64)
        out[start : start + length] = lo + (hi - lo) * (pos - xl) / (xr - xl)
    return out


def filled_columns(x) -> np.ndarray:
    """A float64 copy of ``x`` (samples, or samples × axes) with each column's NaN runs filled by :func:`fill_gaps`,
    without :func:`check_gaps`' limits (the caller's samples are analysed with their gaps skipped; the fill serves
    the noise identification alone); a column with no finite sample stays NaN."""
    out = np.array(x, dtype=np.float64)
    cols = out.reshape(out.shape[0], -1)  # a view: filling a column fills ``out``
    for j in range(cols.shape[1]):
        missing = np.isnan(cols[:, j])
        if missing.any() and not missing.all():
            cols[:, j] = fill_gaps(cols[:, j], gap_runs(missing))
    return out


def filled_record(y: np.ndarray, fs: float) -> tuple[np.ndarray, dict | None]:
    """(``y`` with its NaN gaps filled, what was filled — None when nothing was missing)."""
    missing = np.isnan(y)
    if not missing.any():
        return y, None
    runs = check_gaps(missing, fs)
    lost = int(runs[:, 1].sum())
    info = {
        "samples": lost,
        "fraction": lost / y.size,
        "gaps": int(runs.shape[0]),
        "longest_s": float(runs[:, 1].max() / fs),
        "runs": [(int(a), int(b)) for a, b in runs],
        "method": METHOD,
    }
    return fill_gaps(y, runs), info


def fill_channel(name: str, c: np.ndarray, fs: float) -> np.ndarray:
    """A channel's NaN gaps (``read_log(..., gaps="nan")`` marks the channels too) filled as the samples'."""
    arr = np.asarray(c)
    if arr.dtype.kind != "f" or arr.ndim != 1 or not np.isnan(arr).any():
        return c
    return fill_gaps(arr, check_gaps(np.isnan(arr), fs, f"channel {name!r}"))


def filled_words(filled: dict) -> str:
    """``Refinement.filled`` in words (the report's "Gaps:" line)."""
    change = filled.get("curve_change_pct")
    moved = (
        ""
        if change is None or not np.isfinite(change)
        else f"; the fill moved the Allan curve by at most {change:.2g} % from the curve that skips the gaps (at the τ "
        "where that keeps ≥ 90 % of the terms)"
    )
    return (
        f"{filled['samples']} samples missing ({100 * filled['fraction']:.2g} %) in {filled['gaps']} gap(s), the "
        f"longest {filled['longest_s']:.6g} s: {filled['method']}{moved}"
    )
