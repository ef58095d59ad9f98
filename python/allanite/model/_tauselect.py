"""Which τ of a result enter a noise-model fit: the requested range, octave spacing, positive finite estimates
enough for the terms; and the estimator argument of the fit at those τ.
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError


def _octave_thin(tau: np.ndarray) -> np.ndarray:
    """Indices of τ at least a factor 2 apart, starting from the shortest."""
    keep = [0]
    for i in range(1, tau.size):
        if tau[i] >= 2.0 * tau[keep[-1]] * (1 - 1e-12):
            keep.append(i)
    return np.asarray(keep)


def estimator_key(result, idx):
    """The estimator argument of fit_core: a name, or a tuple of per-τ sources for Theo-family results."""
    return result.estimator if result.source is None else tuple(np.asarray(result.source)[idx])


def check_tau_range(tau_range):
    """A (low, high) τ range in seconds (None for an open end) as floats, or a ParameterError."""
    if tau_range is None:
        return (0.0, np.inf)
    try:
        lo, hi = tau_range
    except (TypeError, ValueError):
        raise ParameterError(f"tau_range must be a (low, high) pair of seconds, got {tau_range!r}") from None
    lo = 0.0 if lo is None else float(lo)
    hi = np.inf if hi is None else float(hi)
    if not (lo >= 0 and hi > lo) or np.isnan(lo) or np.isnan(hi):
        raise ParameterError(f"tau_range must satisfy 0 ≤ low < high, got {tau_range!r}")
    return (lo, hi)


def select_taus(tau, avar, thin, n_terms, what, tau_range=(0.0, np.inf)):
    """Indices of the τ a fit uses: inside ``tau_range``, octave-spaced when ``thin``, with a positive estimate;
    a ParameterError naming ``what`` when the estimates are not finite or too few τ remain for ``n_terms``."""
    if not np.all(np.isfinite(avar)):
        i = int(np.flatnonzero(~np.isfinite(avar))[0])
        raise ParameterError(
            f"{what} has a non-finite Allan variance ({avar[i]}) at τ = {tau[i]:g} s (NaN-marked gaps: "
            f"avar(..., gaps='skip') then fit(..., gaps='skip') leaves out the τ without a complete term)"
        )
    inside = np.flatnonzero((tau >= tau_range[0]) & (tau <= tau_range[1]))
    if inside.size == 0:
        raise ParameterError(f"no τ of {what} lies in tau_range {tau_range} s (τ spans {tau[0]:g}–{tau[-1]:g} s)")
    if not np.any(avar[inside] > 0):
        raise ParameterError(
            f"{what} has an Allan variance of zero at every τ in range (a constant record?): there is no noise to fit"
        )
    idx = inside[_octave_thin(tau[inside])] if thin else inside
    idx = idx[avar[idx] > 0]
    if idx.size <= n_terms:
        raise ParameterError(
            f"{what} has {idx.size} usable τ{' (octave-spaced)' if thin else ''} for {n_terms} terms; "
            f"at least {n_terms + 1} are needed — use a wider τ grid or fewer terms"
            + (", or fit every τ (thin=False)" if thin else "")
        )
    return idx


def row_medians(a) -> np.ndarray:
    """The median of every row of a 2-D array, one row at a time: ``np.median(a, axis=1)`` partitions a copy
    of the whole array (a hop-1 DAVAR surface: gigabytes)."""
    return np.array([np.median(r) for r in a])
