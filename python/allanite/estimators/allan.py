"""The overlapping and the classic Allan variance — registry entries over the Rust core.

``"oavar"``: NIST SP 1065 eq. 11, (1 / 2τ²(N − 2m)) Σ (x_{i+2m} − 2x_{i+m} + x_i)² over all N − 2m
second differences of the angle (phase) x. ``"avar"``: the classic estimator on non-overlapping
m-sample clusters. Both are computed by one drift-free sliding kernel (``rust/core/src/allan.rs``):
a whole record is the window that spans it.
"""

from __future__ import annotations

from functools import partial

import numpy as np

from .. import _core
from .._validate import resolve_workers
from ._registry import Computed, Estimator, register
from .confidence import edf_greenhall
from .grid import resolve_taus

__all__ = ["n_terms", "allan_values", "part_values", "compensated_sums", "angle_term_sums"]


def n_terms(estimator: str, window: int, ms: np.ndarray) -> np.ndarray:
    """Squared differences averaged per estimate: N − 2m + 1 rate-sample windows (overlapping), or
    ⌊W/m⌋ − 1 (classic)."""
    if estimator == "oavar":
        return (window + 1 - 2 * ms).astype(np.int64)
    return (window // ms - 1).astype(np.int64)


def allan_values(cols, window: int, hop: int, ms, estimator: str, method: str, threads: int) -> np.ndarray:
    """The core's Allan variance of every window: (axes, len(ms), windows). ``threads``: as resolved by
    :func:`allanite._validate.resolve_workers` (0 = rayon's default)."""
    return _core.davar(cols, window, hop, [int(m) for m in ms], estimator, method, threads)


def part_values(
    cols,
    window: int,
    hop: int,
    ms,
    estimator: str,
    method: str,
    threads: int,
    *,
    mus,
    first_window: int,
    n_windows: int,
) -> np.ndarray:
    """:func:`allan_values` of windows ``first_window ..`` of a record of ``n_windows`` windows, from a part
    of it: ``cols`` hold the record's samples from ``first_window·hop`` on, ``mus`` the record's centring
    values (:func:`compensated_sums` over its parts, in order, divided by its length). The whole-record
    values along the record's own path (``dynamic_avar_part_cancellable`` in rust/core/src/allan.rs):
    bit for bit when ``first_window · hop`` is a multiple of ``_core.part_grid`` (the hop where the record's
    call streams its sums, a phase segment where it takes the phase path), to a few ε otherwise.
    Internal: for :mod:`allanite.dask`."""
    return _core.davar_part(
        cols,
        window,
        hop,
        [int(m) for m in ms],
        estimator,
        method,
        threads,
        [float(m) for m in mus],
        int(first_window),
        int(n_windows),
    )


def compensated_sums(cols, state) -> list[tuple[float, float]]:
    """The core's compensated (Neumaier) sum of each column, continued from ``state`` — (sum,
    compensation) per axis, (0, 0) at the record's start. Fed a record's parts in order, the final
    (s + c)/n is the centring value the core gives the whole record, bit for bit. Internal: for
    :mod:`allanite.dask`."""
    return _core.compensated_sums(cols, [(float(s), float(c)) for s, c in state])


def angle_term_sums(blocks, starts, off_w, off_r, q_exp: int, plan, classic: bool, threads: int) -> np.ndarray:
    """Σ (X[i+2m] − 2X[i+m] + X[i])² in quanta² for every plan item (m, i0, i1) and axis: (items, axes).
    X is the exact angle of the rate ``blocks`` ((samples, axes) each, consecutive ones forming runs),
    in quanta 2^q_exp: int64 whole quanta from the exact offsets ``off_w`` plus float remainders from
    ``off_r`` (rust/core/src/angle.rs). Internal: the per-task kernel of :func:`allanite.dask.avar`."""
    return _core.angle_term_sums(
        [np.require(b, dtype=np.float64, requirements=("C_CONTIGUOUS", "ALIGNED")) for b in blocks],
        [int(s) for s in starts],
        [[int(v) for v in w] for w in off_w],
        [[float(v) for v in r] for r in off_r],
        int(q_exp),
        [(int(m), int(a), int(b)) for m, a, b in plan],
        bool(classic),
        int(threads),
    )


def _static(cols, fs, taus, workers, *, estimator: str) -> Computed:
    n = cols[0].size
    ms = resolve_taus(taus, n, fs)
    values = allan_values(cols, n, 1, ms, estimator, "fast", resolve_workers(workers))[:, :, 0]
    return Computed(tau=ms / fs, values=values, n=n_terms(estimator, n, ms), m=ms)


def _dynamic(cols, fs, window, hop, taus, method, workers, *, estimator: str) -> Computed:
    ms = resolve_taus(taus, window, fs)
    # with the rows' ranges: the caller's range check then needs no pass over a (hop-1: huge) surface
    values, ranges = _core.davar_ranged(
        cols, window, hop, [int(m) for m in ms], estimator, method, resolve_workers(workers)
    )
    return Computed(tau=ms / fs, values=values, n=n_terms(estimator, window, ms), m=ms, ranges=ranges)


def _edf(alpha, m, n_phase, *, overlapping: bool):
    return edf_greenhall(alpha, 2, m, n_phase, overlapping=overlapping)


for _name, _label, _overlapping in (
    ("oavar", "overlapping Allan variance", True),
    ("avar", "Allan variance (classic, non-overlapping)", False),
):
    register(
        Estimator(
            name=_name,
            label=_label,
            family="allan",
            static=partial(_static, estimator=_name),
            dynamic=partial(_dynamic, estimator=_name),
            edf=partial(_edf, overlapping=_overlapping),
            methods=("fast", "naive"),
            noise_id=_name,
            resolve_m=resolve_taus,
        )
    )
