"""The static Allan variance of a dask array on the exact angle (see :mod:`allanite.dask.arrays`)."""

from __future__ import annotations

import math

import numpy as np

from .._validate import check_input, resolve_workers
from ..errors import InputError
from ..estimators.allan import angle_term_sums, n_terms
from ..estimators.grid import resolve_taus
from ..results import AllanResult
from ._common import as_dask, check_inputs, dask, rate, target_chunk

__all__ = ["MAX_STATIC_CHUNK", "QUANTUM_BITS", "avar"]


#: Bits of a quantum below the largest sample: |y/q| ≤ 2^26, so the whole quanta of a task's run of
#: chunks (≤ 6 chunks of ≤ :data:`MAX_STATIC_CHUNK` samples) sum exactly in float64 (< 2^52), a chunk's
#: total exactly in int64, and a second difference at m < 2^25 is an exact float64.
QUANTUM_BITS = 26

#: Longest chunk of the static variance (6 · 2^23 · 2^26 < 2^52: see :data:`QUANTUM_BITS`).
MAX_STATIC_CHUNK = 1 << 23


def _peak_block(block, fs: float, input: str):
    y = rate(block, fs, input)
    finite = np.isfinite(y)
    if not finite.all():
        i, a = np.unravel_index(int(np.argmin(finite)), y.shape)
        return np.array([[math.inf, float(i), float(a)]])
    return np.array([[float(np.max(np.abs(y))) if y.size else 0.0, -1.0, -1.0]])


def _split(y: np.ndarray, q_exp: int) -> tuple[np.ndarray, np.ndarray]:
    """y/q = whole quanta + remainder, both exact (q a power of two)."""
    u = np.ldexp(y, -q_exp)
    whole = np.rint(u)
    return whole.astype(np.int64), u - whole


def _totals_block(block, fs: float, input: str, q_exp: int):
    """The chunk's exact sum of whole quanta (int64, per axis) and its sum of remainders."""
    whole, rest = _split(rate(block, fs, input), q_exp)
    return whole.sum(axis=0), rest.sum(axis=0)


def _chunk_of(bounds: np.ndarray, i: int) -> int:
    """The chunk holding sample i (the last chunk for i = n, the final angle point)."""
    return min(int(np.searchsorted(bounds, i, side="right")) - 1, bounds.size - 2)


def _needed(bounds: np.ndarray, lo: int, hi: int) -> list[int]:
    """Chunks whose samples give the angle points X[lo:hi] (X[j] = Σ_{t<j} y[t]): from the chunk that
    holds sample lo to the one holding sample hi − 2."""
    k0 = _chunk_of(bounds, lo)
    return list(range(k0, max(k0, _chunk_of(bounds, hi - 2)) + 1))


def _sum_block(blocks, ks, bounds, offsets, *, fs, input, q_exp, plan, classic, threads):
    """Σ over this task's terms of (x[i+2m] − 2x[i+m] + x[i])², in quanta², per (plan item, axis).

    ``blocks[j]`` is chunk ``ks[j]``; ``offsets[j]`` the exact angle at its first sample (int64 quanta,
    float remainder). ``plan``: (τ index, m, i0, i1) — the terms i0 ≤ i < i1 of that m. The Rust kernel
    (``angle_term_sums``) builds the angle of every run of consecutive chunks once — an exact int64
    running sum of whole quanta plus a float running sum of the remainders (|r| ≤ 1/2 quantum) — and
    sums every item's terms in one pass."""
    return angle_term_sums(
        [rate(b, fs, input) for b in blocks],
        [int(bounds[k]) for k in ks],
        [o[0] for o in offsets],
        [o[1] for o in offsets],
        q_exp,
        [(m, i0, i1) for _j, m, i0, i1 in plan],
        classic,
        threads,
    )


def avar(
    x,
    fs,
    *,
    taus="octave",
    estimator: str = "oavar",
    input: str = "rate",
    chunk: int | None = None,
    client=None,
) -> AllanResult:
    """Static (overlapping or classic) Allan variance of a dask array, on the exact angle.

    Parameters
    ----------
    x : dask.array.Array or array_like, shape (samples,) or (samples, axes)
    fs, taus, input
        As for :func:`allanite.avar` (``input`` "rate" or "increment").
    estimator : {"oavar", "avar"}
    chunk : int, optional
        Samples per chunk (default: the caller's first chunk, at least :data:`DEFAULT_CHUNK`/4).
    client : distributed.Client, optional
        Where to compute (default: dask's current scheduler).

    Returns
    -------
    AllanResult
        Equal to :func:`allanite.avar` within a few units of rounding (≤ 1e-12 relative; not bitwise:
        the single-machine kernel sums the same terms in another order).

    Notes
    -----
    Three passes over the record: the largest |sample| (the quantum), the exact sum of every chunk
    (the angle offsets), then per task the terms of the τ whose three slices fall into it — for
    m < chunk one task per chunk reads that chunk and the next two; for larger m each (chunk, m)
    reads at most six chunks. No task holds more than six chunks.
    """
    input = check_input(input)  # another tool's word for it (allanite._validate.INPUT_WORDS) as allanite's
    fs = check_inputs(estimator, input, fs)
    arr = as_dask(x)
    n = int(arr.shape[0])
    if n < 2:
        raise InputError(f"record has {n} samples; at least 2 are needed for any Allan variance")
    n_axes = int(arr.shape[1]) if arr.ndim == 2 else 1
    ms = resolve_taus(taus, n, fs)
    target = target_chunk(arr, chunk)
    target = max(1, min(target, MAX_STATIC_CHUNK))
    arr = arr.rechunk({0: target, 1: -1} if arr.ndim == 2 else {0: target})
    bounds = np.concatenate([[0], np.cumsum(arr.chunks[0])]).astype(np.int64)
    blocks = arr.to_delayed().ravel().tolist()
    compute = client.compute if client is not None else None

    def run(tasks):
        if compute is None:
            return dask.compute(*tasks)
        return [f.result() for f in compute(tasks)]

    # pass 1: the largest sample → the quantum (and the first non-finite sample, if any)
    peak = _peak(np.concatenate(run([dask.delayed(_peak_block)(b, fs, input) for b in blocks])), bounds, n_axes)
    if peak == 0.0:
        values = np.zeros((n_axes, ms.size))
        return _static_result(values, ms, estimator, fs, n, input, arr.ndim == 2)
    q_exp = math.frexp(peak)[1] - QUANTUM_BITS  # 2^(E−26) with 2^E > peak

    # pass 2: exact chunk totals → exact angle offsets (Python ints for the whole quanta)
    offsets = _offsets(run([dask.delayed(_totals_block)(b, fs, input, q_exp) for b in blocks]), n_axes)

    # pass 3: partial sums of squared second differences
    threads = resolve_workers(None)
    classic = estimator == "avar"
    where = _plans(ms, bounds, int(arr.chunks[0][0]), n)
    options = dict(fs=fs, input=input, q_exp=q_exp, classic=classic, threads=threads)
    partial = run([_sum_task(plan, blocks, bounds, offsets, options) for plan in where])
    values = _avar_values(where, partial, ms, n_axes, n_terms(estimator, n, ms), q_exp)
    if not np.all(np.isfinite(values)):
        raise InputError(f"the Allan variance of samples of magnitude up to {peak:.3g} exceeds float64's range")
    return _static_result(values, ms, estimator, fs, n, input, arr.ndim == 2)


def _sum_task(plan, blocks, bounds, offsets, options: dict):
    """The delayed :func:`_sum_block` of one plan: the chunks its terms' three slices fall into."""
    ks = sorted({kk for _j, m, a, b in plan for s in (0, m, 2 * m) for kk in _needed(bounds, a + s, b + s)})
    return dask.delayed(_sum_block)(
        [blocks[kk] for kk in ks], ks, bounds, [offsets[kk] for kk in ks], plan=plan, **options
    )


def _avar_values(where, partial, ms, n_axes: int, counts, q_exp: int) -> np.ndarray:
    """The Allan variance per (axis, τ) from every task's partial sums (in quanta²), each τ's summed exactly."""
    sums: list[list[list[float]]] = [[[] for _ in range(ms.size)] for _ in range(n_axes)]
    for plan, part in zip(where, partial):
        for p, (j, *_rest) in enumerate(plan):
            for a in range(n_axes):
                sums[a][j].append(float(part[p, a]))
    values = np.empty((n_axes, ms.size))
    for a in range(n_axes):
        for j, m in enumerate(ms):
            s = math.fsum(sums[a][j])
            # Σ (q·d)² / (2 m² n): scaled back by q² = 2^(2·q_exp) last, so no intermediate overflows
            values[a, j] = math.ldexp(s / (2.0 * float(m) * float(m) * float(counts[j])), 2 * q_exp)
    return values


def _peak(peaks: np.ndarray, bounds: np.ndarray, n_axes: int) -> float:
    """The largest |sample| of the record from the blocks' (peak, row, axis) rows; an InputError naming the
    first non-finite sample."""
    bad = np.flatnonzero(~np.isfinite(peaks[:, 0]))
    if bad.size:
        k = int(bad[0])
        i, a = int(bounds[k] + peaks[k, 1]), int(peaks[k, 2])
        raise InputError(
            f"samples contain a non-finite value at sample {i}"
            + (f" of axis {a}" if n_axes > 1 else "")
            + "; only finite numbers are allowed"
        )
    return float(peaks[:, 0].max())


def _offsets(totals, n_axes: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """The exact angle at every chunk's first sample from the chunks' totals: whole quanta summed as Python
    integers (int64 per axis), remainders summed exactly (:func:`math.fsum`)."""
    off_w = [np.zeros(n_axes, dtype=np.int64)]
    off_r = [np.zeros(n_axes)]
    acc_w = [0] * n_axes
    rests: list[list[float]] = [[] for _ in range(n_axes)]
    for k in range(len(totals) - 1):
        for a in range(n_axes):
            acc_w[a] += int(totals[k][0][a])
            rests[a].append(float(totals[k][1][a]))
        off_w.append(np.array(acc_w, dtype=np.int64))
        off_r.append(np.array([math.fsum(r) for r in rests]))
    return list(zip(off_w, off_r))


def _plans(ms: np.ndarray, bounds: np.ndarray, c: int, n: int) -> list[list[tuple[int, int, int, int]]]:
    """Pass 3's tasks, in order: per chunk, one plan of every m below the chunk length ``c`` (the chunk and
    the next two at most) and one plan per larger m (three slices, ≤ six chunks); a plan is (τ index, m,
    i0, i1), the terms i0 ≤ i < i1 of that m."""
    small = [(j, int(m)) for j, m in enumerate(ms) if m < c]
    large = [(j, int(m)) for j, m in enumerate(ms) if m >= c]
    out: list[list[tuple[int, int, int, int]]] = []
    for k in range(bounds.size - 1):
        i0, i1 = int(bounds[k]), int(bounds[k + 1])
        groups = []
        if small:  # every small m at once: the chunk and the next two at most
            plan = [(j, m, i0, min(i1, n + 1 - 2 * m)) for j, m in small]
            groups.append([p for p in plan if p[3] > p[2]])
        for j, m in large:  # one task per (chunk, large m): three slices, ≤ six chunks
            groups.append([(j, m, i0, min(i1, n + 1 - 2 * m))] if n + 1 - 2 * m > i0 else [])
        out.extend(plan for plan in groups if plan)
    return out


def _static_result(values, ms, estimator, fs, n, input, is_multi) -> AllanResult:
    return AllanResult(
        tau=ms / fs,
        avar=values if is_multi else values[0],
        n=n_terms(estimator, n, ms),
        m=ms,
        estimator=estimator,
        fs=fs,
        n_samples=n,
        input=input,
        source=None,
        kf=None,
    )
