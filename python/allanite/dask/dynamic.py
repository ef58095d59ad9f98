"""The dynamic Allan variance of a dask array, block by block, bit for bit (see :mod:`allanite.dask.arrays`)."""

from __future__ import annotations

import math

import numpy as np

from .. import _core, analysis, estimators
from .._validate import check_choice, check_input, resolve_workers
from ..errors import InputError, ParameterError
from ..estimators.allan import compensated_sums, n_terms, part_values
from ..results import DynamicAllanResult
from ._common import as_dask, check_inputs, dask, rate, target_chunk

__all__ = ["CENTRE_BATCH", "davar", "davar_chunks", "scale_exponent"]


def davar_chunks(
    n: int, window: int, hop: int, target: int, unit: int | None = None
) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """Input chunks along the samples and DAVAR windows per chunk, for ``map_overlap``.

    Every chunk but the last holds a multiple of ``unit`` samples (default ``hop``; a multiple of it —
    the core's ``part_grid``, where a cut gives the whole call's values bit for bit), so each block's
    first window starts on the global hop grid, and at least ``window − 1`` (so one neighbour supplies
    the whole overlap); the last chunk takes the remainder. Block k then computes the windows that
    *start* in it; the counts are exact — dask accepts wrong ``chunks=`` silently, so they are
    computed, not guessed.
    """
    unit = hop if unit is None else unit
    if unit % hop:
        raise ParameterError(f"unit ({unit} samples) must be a multiple of the hop ({hop})")
    size = max(target, window - 1, hop)
    size = -(-size // unit) * unit
    n_win = (n - window) // hop + 1
    k = max(1, n // size)
    chunks = [size] * (k - 1) + [n - size * (k - 1)]
    counts = []
    start = 0
    for c in chunks:
        first = -(-start // hop)  # first window index starting at or after `start`
        last = min((start + c - 1) // hop, n_win - 1)  # last window index starting inside the chunk
        counts.append(max(0, last - first + 1))
        start += c
    assert sum(counts) == n_win
    return tuple(chunks), tuple(counts)


#: Chunks whose compensated sums one ``dask.compute`` chains (the centring pass is sequential: the
#: record's mean is the core's Neumaier sum run over the chunks in order). Bounds what the pass holds.
CENTRE_BATCH = 4


def scale_exponent(peak: float) -> int:
    """The power of two the single-machine call scales a column by (``allanite.analysis``: samples whose
    largest magnitude lies outside (2^-SAFE_EXP, 2^SAFE_EXP) are scaled into it, exactly)."""
    if peak == 0.0 or 2.0**-analysis.SAFE_EXP < peak < 2.0**analysis.SAFE_EXP:
        return 0
    return math.frexp(peak)[1]


def _columns(block, fs: float, input: str, exps) -> list[np.ndarray]:
    """The core's columns of a block: rate, scaled by 2^-e per axis as the single-machine call scales them."""
    y = rate(block, fs, input)
    # C-contiguous and aligned (a block received from another worker may sit at an odd address)
    return [
        np.require(np.ldexp(y[:, a], -e) if e else y[:, a], requirements=("C_CONTIGUOUS", "ALIGNED"))
        for a, e in enumerate(exps)
    ]


def _centre_step(acc, block, start: int, fs: float, input: str, exps):
    """One chunk of the centring pass: the compensated sums continued over the chunk (in order), the
    largest |sample| per axis, and the first non-finite sample (record index, axis) if any."""
    state, peak, bad = acc
    if bad is not None:
        return acc
    y = rate(block, fs, input)
    finite = np.isfinite(y)
    if not finite.all():
        i, a = np.unravel_index(int(np.argmin(finite)), y.shape)
        return state, peak, (start + int(i), int(a), float(y[i, a]))
    state = compensated_sums(_columns(block, fs, input, exps), state)
    if y.shape[0]:
        peak = np.maximum(peak, np.max(np.abs(y), axis=0))
    return state, peak, None


def _centre(blocks, bounds, n_axes: int, fs: float, input: str, exps):
    """The compensated sums of the whole record, chunk after chunk, in batches of CENTRE_BATCH chunks."""
    acc = ([(0.0, 0.0)] * n_axes, np.zeros(n_axes), None)
    for k0 in range(0, len(blocks), CENTRE_BATCH):
        step = acc
        for k in range(k0, min(len(blocks), k0 + CENTRE_BATCH)):
            step = dask.delayed(_centre_step)(step, blocks[k], int(bounds[k]), fs, input, exps)
        (acc,) = dask.compute(step)
        if acc[2] is not None:
            break
    return acc


def _davar_block(
    block,
    *,
    fs,
    window,
    hop,
    ms,
    method,
    estimator,
    input,
    n_out,
    first,
    n_windows,
    mus,
    exps,
    power,
    threads,
    block_info=None,
):
    """One block: the windows that start in chunk k, from the chunk and its overlap, laid out
    (windows, axes·τ) so the windows run along the samples' dimension. The core computes them as parts
    of the whole record (its centring values ``mus``, the block's first window ``first[k]`` of
    ``n_windows``): the single-machine :func:`allanite.davar` (bit for bit where it streams)."""
    k = block_info[None]["chunk-location"][0] if block_info else 0
    count = n_out[k]
    n_axes = len(exps)
    n_tau = len(ms)
    if count == 0:
        return np.zeros((0, n_axes * n_tau), dtype=np.float64)
    # the block holds exactly the windows that start in chunk k (chunk lengths are multiples of hop)
    use = block[: (count - 1) * hop + window]
    vals = part_values(
        _columns(use, fs, input, exps),
        window,
        hop,
        ms,
        estimator,
        method,
        threads,
        mus=mus,
        first_window=first[k],
        n_windows=n_windows,
    )  # (axes, τ, windows)
    if vals.shape[2] != count:  # pragma: no cover - a wrong chunk plan would be a bug
        raise AssertionError(f"block {k}: {vals.shape[2]} windows, expected {count}")
    # scaled back as the single-machine call does (exact: powers of two)
    vals = np.stack([np.ldexp(v, power * e) if e else v for v, e in zip(vals, exps)])
    if not np.all(np.isfinite(vals)):
        raise InputError("the Allan variance of these samples exceeds float64's range: express them in a larger unit")
    return np.ascontiguousarray(vals.reshape(n_axes * n_tau, count).T)


def davar(
    x,
    fs,
    *,
    window: int,
    hop: int = 1,
    taus="exp",
    method: str = "fast",
    estimator: str = "oavar",
    input: str = "rate",
    chunk: int | None = None,
    compute: bool = True,
):
    """Dynamic Allan variance of a dask array: :func:`allanite.davar`, block by block.

    Parameters
    ----------
    x : dask.array.Array or array_like, shape (samples,) or (samples, axes)
        Rate or increment samples (e.g. ``da.from_zarr``, :func:`from_npy` for a .npy on disk, an HDF5
        dataset); any chunks and any real dtype (float32 is widened exactly, as on one machine) —
        they are rechunked along the samples (one chunk across the axes).
    fs, window, hop, taus, method, input
        As for :func:`allanite.davar`.
    estimator : {"oavar", "avar"}
    chunk : int, optional
        Samples per chunk before rounding up to at least ``window − 1`` and to a multiple of the
        core's part grid: the hop where the single-machine call streams its sums, whole phase segments
        (max(2^22, 16 · window) samples' worth of windows; 4 · window on records over 2^26 samples ×
        axes) where it takes its phase path — records of
        at most 2^26 samples × axes, and windows of at most 2^21 samples on any record (default: the
        caller's first chunk, at least :data:`DEFAULT_CHUNK`/4).
    compute : bool
        True (default): a :class:`~allanite.DynamicAllanResult`, as the single-machine one.
        False: the lazy (axes, τ, windows) dask array of the Allan variance (the centring pass runs now).

    Notes
    -----
    Equal to :func:`allanite.davar` bit for bit: the chunks are cut where the core's parts give the
    whole call's values (on the hop grid where it streams its sums — ``estimator="avar"``, and
    ``"oavar"`` with windows over 2^21 samples on records over 2^26 samples × axes — and at its phase
    segments elsewhere; see the module notes). Two passes over the record: the centring pass runs the
    core's compensated sum over the chunks in order (a chain of tasks, :data:`CENTRE_BATCH` chunks per
    ``dask.compute``; a second chain only when the samples need the power-of-two scaling of the
    single-machine call, |sample| ≥ 2^200 or < 2^-200), which gives the record's centring value and
    the first non-finite sample; then every block hands the core its part of the record with that
    centring value and its first window, and the core forms the same terms and sums in the same order
    as for the whole record. Memory per task: one chunk plus ``window − 1`` samples plus its output, and on the
    phase path one segment's phase (16 B per sample of max(2^22, 4 · window) on records over 2^26 samples; with
    windows over 2^21 samples on such records, at hops ≥ 64, one chunk's phase: 16 B per sample of ≤ 2 · max(2^22,
    window) + hop).
    """
    input = check_input(input)  # another tool's word for it (allanite._validate.INPUT_WORDS) as allanite's
    fs = check_inputs(estimator, input, fs)
    arr = as_dask(x)
    n = int(arr.shape[0])
    window, hop = _check_window(window, hop, n)
    check_choice(method, "method", analysis.METHODS)
    entry = estimators.get(estimator, "dynamic")
    assert entry.resolve_m is not None
    ms = entry.resolve_m(taus, window, fs)
    n_tau = int(ms.size)
    n_axes = int(arr.shape[1]) if arr.ndim == 2 else 1
    arr, chunks, counts, bounds = _cut(arr, chunk, n_axes, window, hop, estimator, method)
    n_win = (n - window) // hop + 1
    hop_core = min(hop, n)  # as the single-machine call: a hop beyond the record gives one window

    # pass 1: the record's centring value (the core's compensated mean), chunk after chunk in order
    mus, exps = _centring(arr, bounds, n_axes, fs, input)

    # pass 2: every block's windows, as parts of the record
    kwargs = dict(
        fs=fs,
        window=window,
        hop=hop_core,
        ms=[int(m) for m in ms],
        method=method,
        estimator=estimator,
        input=input,
        first=[int(b) // hop for b in bounds[:-1]],
        n_windows=n_win,
        mus=mus,
        exps=exps,
        power=entry.unit_power,
        threads=resolve_workers(None),
    )
    values = _windows(arr, len(chunks), counts, window, n_axes * n_tau, kwargs).T.reshape(n_axes, n_tau, n_win)
    if not compute:
        return values
    result = values.compute()
    return _result(result if arr.ndim == 2 else result[0], ms, n_win, n, window, hop, method, estimator, fs, input)


def _cut(arr, chunk, n_axes: int, window: int, hop: int, estimator: str, method: str):
    """``arr`` rechunked along the samples where the core's parts are the whole call's values bit for bit (its
    phase segments or the hop), near ``chunk`` samples; with the chunks, their windows' counts and bounds."""
    n = int(arr.shape[0])
    target = target_chunk(arr, chunk)
    grid = _core.part_grid(n, n_axes, window, min(hop, n), estimator, method)
    chunks, counts = davar_chunks(n, window, min(hop, n), int(target), grid)
    arr = arr.rechunk({0: chunks, 1: -1} if arr.ndim == 2 else {0: chunks})
    bounds = np.concatenate([[0], np.cumsum(chunks)]).astype(np.int64)
    return arr, chunks, counts, bounds


def _result(avar, ms, n_win: int, n: int, window: int, hop: int, method, estimator, fs, input) -> DynamicAllanResult:
    """The computed surface as the single-machine call's result (window centres in s, τ = m/fs)."""
    t = (np.arange(n_win) * float(hop) + window / 2) / fs
    return DynamicAllanResult(
        tau=ms / fs,
        t=t,
        avar=avar,
        n=n_terms(estimator, window, ms),
        m=ms,
        window=window,
        hop=hop,
        method=method,
        estimator=estimator,
        fs=fs,
        n_samples=n,
        input=input,
        source=None,
        kf=None,
    )


def _check_window(window, hop, n: int) -> tuple[int, int]:
    """(window, hop) as ints: a window of 2 to n samples, a hop of at least 1."""
    if not isinstance(window, (int, np.integer)) or window < 2:
        raise ParameterError(f"window must be an integer ≥ 2 samples, got {window!r}")
    if not isinstance(hop, (int, np.integer)) or hop < 1:
        raise ParameterError(f"hop must be an integer ≥ 1 sample, got {hop!r}")
    window, hop = int(window), int(hop)
    if window > n:
        raise ParameterError(f"window ({window} samples) is longer than the record ({n} samples)")
    return window, hop


def _centring(arr, bounds, n_axes: int, fs: float, input: str) -> tuple[list[float], list[int]]:
    """Pass 1: the record's centring values (the core's compensated mean per axis, of the columns scaled as the
    single-machine call scales them) and those scaling exponents; an InputError at the first non-finite sample."""
    n = int(arr.shape[0])
    blocks = arr.to_delayed().ravel().tolist()
    exps = [0] * n_axes
    state, peak, bad = _centre(blocks, bounds, n_axes, fs, input, exps)
    if bad is not None:
        i, a, v = bad
        where = f"sample {i}" + (f" of axis {a}" if arr.ndim == 2 else "")
        raise InputError(f"samples contain a non-finite value ({v}) at {where}; only finite numbers are allowed")
    exps = [scale_exponent(float(p)) for p in peak]
    if any(exps):  # the single-machine call centres the scaled columns: sum those
        state, _peak, _bad = _centre(blocks, bounds, n_axes, fs, input, exps)
    return [(s + c) / float(n) for s, c in state], exps


def _windows(arr, n_chunks: int, counts, window: int, width: int, kwargs: dict):
    """Pass 2: the lazy (windows, axes·τ) array, every block's windows from its chunk and the next
    ``window − 1`` samples (one chunk: no overlap needed)."""
    out_chunks = (counts, (width,))
    if n_chunks == 1:
        return arr.map_blocks(
            _davar_block,
            n_out=counts,
            chunks=out_chunks,
            dtype=np.float64,
            new_axis=None if arr.ndim == 2 else 1,
            **kwargs,
        )
    return arr.map_overlap(
        _davar_block,
        depth={0: (0, window - 1), 1: 0} if arr.ndim == 2 else {0: (0, window - 1)},
        boundary="none",
        trim=False,
        allow_rechunk=False,
        n_out=counts,
        chunks=out_chunks,
        dtype=np.float64,
        new_axis=None if arr.ndim == 2 else [1],
        **kwargs,
    )
