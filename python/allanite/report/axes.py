"""The report's analyses of the record one axis at a time: a long or memory-mapped record is never copied
whole.

:func:`allanite.avar`, its confidence intervals and :func:`allanite.davar` take every axis at once and make
a contiguous float64 copy of each (a (samples, axes) array stores its axes interleaved). For a record of
10⁸ samples × 3 axes that is 2.4 GB besides the record — and a memory-mapped ``.npy`` read through its
map leaves every page it touched resident as well. :func:`analyse_by_axis` instead reads one axis into
memory (from the file for a mapped ``.npy``: :func:`allanite._mapped.column`, no page of the map is
touched), computes that axis's static variance, its intervals and its DAVAR, drops it and goes on to the
next; :func:`stack` joins the per-axis results into the all-axes result the report uses — the same
numbers, as every estimator treats its axes independently.

:func:`record_bytes` is what the analysis of the record holds either way (the report's memory budget,
:mod:`allanite.report.budget`, counts it); :func:`wants_by_axis` says when the report takes this path.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from .._mapped import column, columns, file_layout
from .._validate import resolve_max_memory
from ..analysis import avar, davar
from ..estimators.noise_id import LONG_SAMPLES

__all__ = ["record_bytes", "wants_by_axis", "axes_per_read", "analyse_by_axis", "stack", "axis_column"]

#: Samples × axes beyond which the core streams its sums: below, a static or DAVAR call builds a double-word
#: phase (16 bytes a sample) of every axis it is given (rust/core; allanite.dask's docstring); beyond, the static
#: call still held ≈ 8 bytes a sample (measured: +775 MB for one axis of 10⁸ samples).
CORE_STREAMS = 1 << 26


#: Steps of the report's bar this analysis takes (static variance, intervals, DAVAR on the all-axes path).
STEPS = 3

#: Per-axis results: fields with one row per axis; the others are shared by the axes.
_PER_AXIS = ("avar", "edf", "ci_low", "ci_high", "alpha")


def record_bytes(n: int, n_axes: int, by_axis: bool) -> int:
    """Bytes the analysis of a record of ``n`` samples × ``n_axes`` holds at its peak: the axes it copies
    (all of them, or one at a time), and the larger of the core's working arrays and the noise
    identification's working arrays (:func:`~allanite.estimators.confidence.identify_alpha`: the samples
    less their mean and the phase; on a record over ``LONG_SAMPLES`` the phase alone, where R(n) needs it)."""
    n, k = int(n), 1 if by_axis else int(n_axes)
    core = (16 if n * k <= CORE_STREAMS else 8) * n * k
    noise_id = 8 * n * (1 if n > LONG_SAMPLES else 2)
    return 8 * n * k + max(core, noise_id)


def wants_by_axis(x) -> bool:
    """True for a memory-mapped ``.npy`` (read from its file, axis by axis)."""
    return file_layout(x) is not None


def axes_per_read(n: int, n_axes: int, total: int, max_memory) -> int:
    """Axes read from the record in one pass: as many as the memory budget holds beside the report's
    ``total`` (its cost with one axis in memory) — each further axis held costs its 8 bytes a sample."""
    spare = resolve_max_memory(max_memory) - int(total)
    return int(max(1, min(n_axes, 1 + spare // max(1, 8 * int(n)))))


def axis_column(x, k: int) -> np.ndarray:
    """Axis ``k`` of the (samples, axes) record ``x`` as a contiguous float64 array (from the file for a
    mapped ``.npy``)."""
    return column(x, k)


def stack(results: list):
    """One all-axes result from per-axis results of one axis each (1-D ``avar``)."""
    first = results[0]
    kw = {}
    for f in dataclasses.fields(first):
        values = [getattr(r, f.name) for r in results]
        if f.name in _PER_AXIS and values[0] is not None:
            kw[f.name] = np.stack(values)
        elif f.name == "kf" and values[0] is not None:
            kw[f.name] = np.asarray(values, dtype=np.float64)
        elif f.name == "n" and any(not np.array_equal(v, values[0]) for v in values[1:]):
            kw[f.name] = np.stack(values)
    return dataclasses.replace(first, **kw)


def analyse_by_axis(x, fs, *, input, taus, static_est, static_extra, confidence, window, hop, grid, dynamic_est,
                    max_memory, progress, group=1):  # fmt: skip
    """(static result with intervals, DAVAR) of every axis of ``x``, one axis analysed at a time; the axes
    read ``group`` at a time in one pass over the record (:func:`axes_per_read`; each axis dropped once
    analysed). ``progress``: told of three steps (``step(text)``, ``add(n)``), one per axis for the first
    three."""
    statics, dynamics = [], []
    n_axes = x.shape[1]
    held: list[np.ndarray] = []  # the axes read in this pass and not analysed yet
    for k in range(n_axes):
        if k < STEPS:
            which = f"axis {k + 1}" if k < STEPS - 1 or n_axes == STEPS else f"axes {k + 1}–{n_axes}"
            progress.step(f"{which} of {n_axes}: static Allan deviation, intervals, dynamic Allan variance")
        if not held:  # one pass over the record for the next `group` axes
            held = columns(x, list(range(k, min(n_axes, k + max(1, group)))))
        y = held.pop(0)
        s = avar(y, fs, input=input, taus=taus, estimator=static_est, **static_extra)
        statics.append(s.with_confidence(y, confidence=confidence))
        dynamics.append(
            davar(y, fs, window=window, hop=hop, taus=grid, input=input, estimator=dynamic_est, max_memory=max_memory)
        )
        del y
    if n_axes < STEPS:
        progress.add(STEPS - n_axes)
    return stack(statics), stack(dynamics)
