"""A static result of a record with NaN-marked gaps (``avar(..., gaps="skip")``) made ready for :func:`fit`: the τ
with no complete term dropped (``fit(gaps="skip")``) or refused, and each kept τ's share of the terms a gapless
record of the same length would have — the fit scales that τ's EDF (and its covariance) by it.

Why the share: the estimate at τ averages the terms the gaps left, so its variance is the full record's times
n_full / n_kept when the terms left are long runs (gaps much shorter than the stretches between them, the case of
dropped samples in a log). Runs shorter than the terms' correlation length (~2m) make the true variance a little
larger; the share is then an optimistic EDF, the more so the closer the gaps are — so τ that kept under
:data:`MIN_SHARE` of the terms are left out of the fit (measured below).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..errors import ParameterError

__all__ = ["GAPS", "gapless_terms", "gap_row", "missing_of"]

#: τ whose curve kept less than this share of a gapless record's terms are left out of the fit: there the kept
#: terms are a few runs, and the share's EDF is optimistic — on 60 records of N + K (5·10⁴ samples, 1 % dropped in 20
#: gaps) the mean z² was 1.5 at a share of 0.17 and 2.8 at 0.06, and χ²/dof 1.35 against 1.02 without gaps. Leaving
#: out τ below 0.1 gave χ²/dof 1.11, the full fit's K inside the gapped interval 46/60 (41/60 with every τ) and the
#: truth inside it 41/60 (68.3 % intervals; the gapless fit 38/60); below 0.25, 1.13, 53/60 and 42/60, but on the
#: ADIS16405 run 1 (1 % dropped) it held the gapless fit's value for 12 of 15 coefficients against 13 at 0.1.
MIN_SHARE = 0.1

#: ``gaps=`` of :func:`allanite.fit`: a τ without a complete term is an error (default), or is left out.
GAPS = ("error", "skip")


def gapless_terms(estimator: str, m: np.ndarray, n_samples: int) -> np.ndarray:
    """Terms a gapless record of ``n_samples`` rate samples has at averaging factors ``m``: N − 2m + 1 for the
    overlapping estimator, ⌊N/m⌋ − 1 for the classic one (the two that both skip gaps and estimate Allan)."""
    m = np.asarray(m, dtype=np.int64)
    if estimator == "oavar":
        return np.maximum(n_samples - 2 * m + 1, 0)
    if estimator == "avar":
        return np.maximum(n_samples // m - 1, 0)
    raise ParameterError(f"a record with gaps is fitted from estimator 'oavar' or 'avar', got {estimator!r}")


def missing_of(result, axis: int | None) -> int:
    """Rate samples missing on ``axis`` (None: a one-axis result)."""
    miss = np.asarray(getattr(result, "missing", 0))
    return int(miss if miss.ndim == 0 else miss[0 if axis is None else axis])


def gap_row(result, avar_row, axis, gaps):
    """(result holding this row's usable τ, its estimates, the share of terms kept per τ or None, notes) for one
    row of a static result. A gapless result comes back as it is (share None, no notes). With gaps: a τ with no
    complete term (n = 0, NaN) is a ParameterError naming ``gaps="skip"``, or with it left out; a τ with under
    :data:`MIN_SHARE` of the terms is left out either way."""
    lost = missing_of(result, axis)
    n = np.asarray(result.n)
    n_row = n if n.ndim == 1 else n[0 if axis is None else axis]
    if lost == 0:
        return result, avar_row, None, ()
    full = gapless_terms(result.estimator, result.m, result.n_samples)
    empty = (n_row == 0) | ~np.isfinite(avar_row)
    if empty.any() and gaps != "skip":
        bad = result.tau[empty]
        raise ParameterError(
            f"the result has no complete term at {bad.size} τ from {bad[0]:g} s (the record's {lost} missing "
            f"samples leave no gapless stretch of 2τ there): pass gaps='skip' to fit the other τ, or compute "
            f"the Allan variance on a shorter τ grid"
        )
    share_all = n_row / np.maximum(full, 1)
    few = ~empty & (share_all < MIN_SHARE)
    ok = ~empty & ~few
    share = share_all[ok]
    sub = dataclasses.replace(result, tau=result.tau[ok], m=result.m[ok], n=n_row[ok], avar=avar_row[ok])
    pct = 100.0 * lost / result.n_samples
    note = (
        f"{lost} of {result.n_samples} samples missing ({pct:.2g} %): the Allan curve skips every term that "
        f"touches one; each τ's EDF scaled by its share of terms kept ({share.min():.3g}–{share.max():.3g})"
        if share.size
        else f"{lost} of {result.n_samples} samples missing ({pct:.2g} %)"
    )
    if few.any():
        note += (
            f"; {int(few.sum())} τ from {result.tau[few][0]:g} s with under {100 * MIN_SHARE:g} % of the terms left "
            f"out (their EDF would be optimistic)"
        )
    if empty.any():
        note += f"; {int(empty.sum())} τ from {result.tau[empty][0]:g} s without a complete term left out (gaps='skip')"
    return sub, avar_row[ok], share, (note,)
