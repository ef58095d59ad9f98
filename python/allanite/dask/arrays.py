"""Static and dynamic Allan variance and the wavelet split of a ``dask.array`` — records larger than memory.

The functions give the numbers of the single-machine calls (:func:`allanite.avar`,
:func:`allanite.davar`, :func:`allanite.wavelet_split`) without ever holding the record in one place:

* :func:`davar` rechunks the samples to chunks whose length is a multiple of the hop, appends the
  next ``window − 1`` samples to every chunk (``map_overlap`` with ``depth={0: (0, window − 1)}``,
  ``boundary="none"``, ``trim=False``) and hands every block to the Rust core as a *part of the record*
  (``dynamic_avar_part_cancellable``) with the record's centring value and the block's first window;
  the core follows the record's own path, and the chunks are cut where the core's parts give the
  whole call's values: **bit for bit**, at every size. Where the single-machine call streams its sums
  (the classic estimator; the overlapping one with windows over 2^21 samples on records over 2^26
  samples × axes) any cut on the hop grid does: the part forms the same terms, block sums and window
  sums in the same order. Elsewhere the single machine builds a double-word phase per *segment* of
  max(2^22, 16 · window) samples' worth of windows — max(2^22, 4 · window) on records over 2^26
  samples × axes — (a running sum from the segment's first sample), and the chunks are whole segments
  (``_core.part_grid``): each block rebuilds exactly its segments' phases. The
  centring value is the core's compensated (Neumaier) sum, which is sequential: a first pass runs it
  over the chunks in order (a chain of small tasks, :data:`CENTRE_BATCH` chunks per compute),
  continuing each chunk from the state the previous one left.
* :func:`avar` cannot do that: the overlap would be 2m samples, a whole record at the longest τ. It works
  on the angle instead. Every rate sample y is split exactly into a whole number of quanta
  q = 2^(E − 26) (2^E > max|y|) and a remainder |r| ≤ q/2: the cumulative sum of the quanta is an
  exact int64 sum, chunk offsets included (Python integers on the client), and only the tiny
  remainders are summed in floating point. Each τ's terms x[i+2m] − 2x[i+m] + x[i] come from three
  shifted slices of that angle, formed and squared and summed per task by a Rust kernel (one pass per
  τ, ``rust/core/src/angle.rs``; ≤ 5e-15 from the NumPy twin ``allanite._reference.angle_term_sums``);
  the client adds the tasks' partial sums with :func:`math.fsum` (exact). The single-machine kernel sums
  block sums of the rate in another order, so the two agree to rounding, not bitwise: ≤ 1e-12 relative (measured: a few
  1e-16, see tests/test_dask.py).
* :func:`wavelet_split` chunks on multiples of 2^level with :func:`wavelet_overlap` samples of each
  neighbour (320 for db5 at level 5) and keeps every block's own chunk: bit for bit the single-machine
  split (trend "a5" or "none"; the periodic trend is a fit over the whole record).
"""

from __future__ import annotations

import math

import numpy as np

from .. import _core, analysis, estimators
from .. import wavelet as wavelet_mod
from .._validate import check_choice, check_count, resolve_workers
from ..errors import InputError, MissingDependencyError, ParameterError
from ..estimators.allan import angle_term_sums, compensated_sums, n_terms, part_values
from ..estimators.grid import resolve_taus
from ..results import AllanResult, DynamicAllanResult

try:
    import dask
    import dask.array as da
except ImportError as exc:  # pragma: no cover - exercised only without the extra
    raise MissingDependencyError("allanite.dask needs dask and distributed: pip install 'allanite[dask]'") from exc

__all__ = [
    "from_npy",
    "davar",
    "avar",
    "wavelet_split",
    "davar_chunks",
    "wavelet_chunks",
    "wavelet_overlap",
    "scale_exponent",
    "DEFAULT_CHUNK",
    "CENTRE_BATCH",
]

#: Samples per chunk when the caller's chunks are rechunked (2^22 float64 = 32 MiB per axis).
DEFAULT_CHUNK = 1 << 22

#: Bits of a quantum below the largest sample: |y/q| ≤ 2^26, so the whole quanta of a task's run of
#: chunks (≤ 6 chunks of ≤ :data:`MAX_STATIC_CHUNK` samples) sum exactly in float64 (< 2^52), a chunk's
#: total exactly in int64, and a second difference at m < 2^25 is an exact float64.
QUANTUM_BITS = 26

#: Longest chunk of the static variance (6 · 2^23 · 2^26 < 2^52: see :data:`QUANTUM_BITS`).
MAX_STATIC_CHUNK = 1 << 23

_ESTIMATORS = ("oavar", "avar")
_INPUTS = ("rate", "increment")


def _read_npy_rows(path: str, a: int, b: int) -> np.ndarray:
    return np.array(np.load(path, mmap_mode="r")[a:b])


def from_npy(path, *, chunk: int = DEFAULT_CHUNK) -> da.Array:
    """A .npy file on disk as a dask array whose tasks read their own rows (memory-mapped).

    ``da.from_array(np.load(path, mmap_mode="r"))`` looks equivalent but is not on a cluster: the
    memory map is pickled into the task graph, and a NumPy memmap pickles as its whole contents — an
    8 GB record sent to the scheduler. Here every task opens the file and copies only its rows, so
    the client and the scheduler hold nothing but the file's name. The path must be readable by the
    workers (a shared or local disk).

    Parameters
    ----------
    path : str or os.PathLike
        A .npy file of shape (samples,) or (samples, axes), any real dtype.
    chunk : int
        Rows per chunk (default :data:`DEFAULT_CHUNK`).

    Returns
    -------
    dask.array.Array
    """
    path = str(path)
    chunk = check_count(chunk, "chunk", 1)
    try:
        head = np.load(path, mmap_mode="r")
    except (OSError, ValueError) as exc:
        raise InputError(f"{path!r} is not a readable .npy file: {exc}") from None
    if head.ndim not in (1, 2):
        raise InputError(f"{path!r} holds a {head.ndim}-D array of shape {head.shape}: (samples,) or (samples, axes)")
    n, tail, dtype = head.shape[0], head.shape[1:], head.dtype
    del head
    parts = [
        da.from_delayed(
            dask.delayed(_read_npy_rows, pure=True)(path, a, min(n, a + chunk)), (min(n, a + chunk) - a, *tail), dtype
        )
        for a in range(0, n, chunk)
    ]
    if not parts:
        return da.zeros((0, *tail), dtype=dtype)
    return da.concatenate(parts)


def _pywt():
    try:
        import pywt
    except ImportError:  # pragma: no cover - PyWavelets is a dependency
        raise MissingDependencyError("the wavelet split needs PyWavelets: pip install PyWavelets") from None
    return pywt


def _as_dask(x) -> da.Array:
    arr = x if isinstance(x, da.Array) else da.asarray(x)
    if arr.ndim not in (1, 2):
        raise InputError(f"samples must be 1-D (samples,) or 2-D (samples, axes), got {arr.ndim}-D shape {arr.shape}")
    if arr.dtype.kind not in "iuf":
        raise InputError(f"samples must be real numbers (integer or float dtype), got dtype {arr.dtype}")
    if any(math.isnan(s) for s in arr.shape):
        raise InputError("samples have an unknown length (NaN chunks): call .compute_chunk_sizes() first")
    if arr.ndim == 2 and arr.shape[1] == 0:
        raise InputError(f"samples have shape {arr.shape}: at least one axis is needed")
    return arr


def _check(estimator: str, input: str, fs) -> float:
    if estimator not in _ESTIMATORS:
        raise ParameterError(f"estimator {estimator!r}: allanite.dask computes {', '.join(map(repr, _ESTIMATORS))}")
    if input not in _INPUTS:
        raise ParameterError(f"input {input!r}: allanite.dask takes {', '.join(map(repr, _INPUTS))}")
    try:
        fs = float(fs)
    except (TypeError, ValueError):
        raise ParameterError(f"fs must be a positive finite number of Hz, got {fs!r}") from None
    if not (math.isfinite(fs) and fs > 0):
        raise ParameterError(f"fs must be a positive finite number of Hz, got {fs!r}")
    return fs


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
    y = _rate(block, fs, input)
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
    y = _rate(block, fs, input)
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
    phase path one segment's phase (16 B per sample of max(2^22, 4 · window) on records over 2^26 samples).
    """
    fs = _check(estimator, input, fs)
    arr = _as_dask(x)
    n = int(arr.shape[0])
    if not isinstance(window, (int, np.integer)) or window < 2:
        raise ParameterError(f"window must be an integer ≥ 2 samples, got {window!r}")
    if not isinstance(hop, (int, np.integer)) or hop < 1:
        raise ParameterError(f"hop must be an integer ≥ 1 sample, got {hop!r}")
    window, hop = int(window), int(hop)
    if window > n:
        raise ParameterError(f"window ({window} samples) is longer than the record ({n} samples)")
    check_choice(method, "method", analysis.METHODS)
    entry = estimators.get(estimator, "dynamic")
    assert entry.resolve_m is not None
    ms = entry.resolve_m(taus, window, fs)
    n_tau = int(ms.size)
    n_axes = int(arr.shape[1]) if arr.ndim == 2 else 1
    target = chunk if chunk is not None else max(int(arr.chunks[0][0]), DEFAULT_CHUNK // 4)
    # cut where the core's parts are the whole call's values bit for bit (its phase segments or the hop)
    grid = _core.part_grid(n, n_axes, window, min(hop, n), estimator, method)
    chunks, counts = davar_chunks(n, window, min(hop, n), int(target), grid)
    arr = arr.rechunk({0: chunks, 1: -1} if arr.ndim == 2 else {0: chunks})
    bounds = np.concatenate([[0], np.cumsum(chunks)]).astype(np.int64)
    n_win = (n - window) // hop + 1
    hop_core = min(hop, n)  # as the single-machine call: a hop beyond the record gives one window

    # pass 1: the record's centring value (the core's compensated mean), chunk after chunk in order
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
    mus = [(s + c) / float(n) for s, c in state]

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
    out_chunks = (counts, (n_axes * n_tau,))
    if len(chunks) == 1:
        out = arr.map_blocks(
            _davar_block,
            n_out=counts,
            chunks=out_chunks,
            dtype=np.float64,
            new_axis=None if arr.ndim == 2 else 1,
            **kwargs,
        )
    else:
        out = arr.map_overlap(
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
    values = out.T.reshape(n_axes, n_tau, n_win)
    if not compute:
        return values
    result = values.compute()
    t = (np.arange(n_win) * float(hop) + window / 2) / fs
    return DynamicAllanResult(
        tau=ms / fs,
        t=t,
        avar=result if arr.ndim == 2 else result[0],
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


# ------------------------------------------------------------------------------------------------
# the wavelet split


def wavelet_overlap(dec_len: int, level: int) -> int:
    """Samples of overlap on each side of a chunk for a ``level``-deep DWT with filters of ``dec_len``
    taps: an output sample depends on the samples within (F − 1)(2^L − 1) of it (L filters of F taps,
    spaced 1, 2, …, 2^(L−1) samples apart), shifted by the decimation's alignment (< 2^L) — rounded up
    to a multiple of 2^L, plus 2^L. db5 at level 5: 9·31 = 279 → 288 + 32 = 320."""
    step = 1 << level
    return -(-(dec_len - 1) * (step - 1) // step) * step + step


def wavelet_chunks(n: int, level: int, overlap: int, target: int) -> tuple[int, ...]:
    """Chunks along the samples for the wavelet split: every chunk but the last a multiple of 2^level
    samples (so every block starts on the record's decimation grid at every level) and at least the
    overlap (one neighbour supplies it); the last takes the remainder and is at least as long."""
    step = 1 << level
    size = -(-max(target, overlap, step) // step) * step
    k = max(1, n // size)
    return tuple([size] * (k - 1) + [n - size * (k - 1)])


def _split_block(block, *, fs, wavelet, level, bands, trend, overlap, n_chunks, starts, block_info=None):
    """One block: :func:`allanite.wavelet_split` of the chunk and its overlap, the chunk's samples kept:
    (samples, 3·axes) as [trend | low | high]."""
    k = block_info[None]["chunk-location"][0] if block_info else 0
    y = np.asarray(block, dtype=np.float64)
    front = 0 if k == 0 else overlap
    finite = np.isfinite(y)
    if not finite.all():
        i, a = np.unravel_index(int(np.argmin(finite)), y.shape)
        raise InputError(
            f"samples contain a non-finite value ({y[i, a]}) at sample {starts[k] - front + int(i)}"
            + (f" of axis {a}" if y.shape[1] > 1 else "")
            + "; only finite numbers are allowed"
        )
    back = 0 if k == n_chunks - 1 else overlap
    s = wavelet_mod.wavelet_split(y, fs, wavelet=wavelet, level=level, bands=bands, trend=trend)
    keep = slice(front, y.shape[0] - back)
    return np.concatenate([s.trend[keep], s.low[keep], s.high[keep]], axis=1)


def wavelet_split(
    x,
    fs,
    *,
    wavelet: str = "db5",
    level: int = 5,
    bands=None,
    trend: str = "a5",
    chunk: int | None = None,
    compute: bool = True,
) -> wavelet_mod.Split:
    """Wavelet split (paper 002) of a dask array: :func:`allanite.wavelet_split`, block by block, bit for bit.

    Parameters
    ----------
    x : dask.array.Array or array_like, shape (samples,) or (samples, axes)
        Rate samples; any chunks and real dtype.
    fs, wavelet, level, bands
        As for :func:`allanite.wavelet_split`.
    trend : {"a5", "none"}
        As for :func:`allanite.wavelet_split`. ``"periodic"`` fits one periodic trend to the whole record
        (a periodogram and a least-squares fit over all samples) and is not offered here.
    chunk : int, optional
        Samples per chunk before rounding up to a multiple of 2^level and to at least the overlap
        (default: the caller's first chunk, at least :data:`DEFAULT_CHUNK`/4).
    compute : bool
        True (default): a :class:`~allanite.wavelet.Split` of NumPy arrays, as on one machine. False: its
        ``trend``, ``low``, ``high`` are lazy dask arrays (computing them together runs the blocks once).

    Notes
    -----
    Chunks start on multiples of 2^level (the decimation grid of every level is the record's) and every
    block carries :func:`wavelet_overlap` samples of each neighbour (320 for db5 at level 5); the first
    and last blocks hold the record's own edges, so its symmetric extension is the single machine's.
    PyWavelets then forms every kept coefficient and sample from the same samples by the same sums:
    equal to :func:`allanite.wavelet_split` bit for bit (tests/test_dask.py: db5 L5, sym8 L6, haar L7).
    Memory per task: one chunk plus twice the overlap, times a few for the coefficients and parts.
    """
    if trend == "periodic":
        raise ParameterError(
            "trend='periodic' fits one periodic trend to the whole record (a periodogram and a least-squares "
            "fit over all samples), which allanite.dask does not split into chunks: use trend='a5' or 'none', "
            "or remove the periodic trend first"
        )
    arr = _as_dask(x)
    n = int(arr.shape[0])
    n_axes = int(arr.shape[1]) if arr.ndim == 2 else 1
    pywt = _pywt()
    if not isinstance(wavelet, str) or wavelet not in pywt.wavelist(kind="discrete"):
        raise ParameterError(
            f"unknown wavelet {wavelet!r}; allowed: a discrete PyWavelets wavelet such as 'db1' … 'db38', "
            f"'sym2' … 'sym20', 'coif1' … 'coif17' (pywt.wavelist(kind='discrete'))"
        )
    level = check_count(level, "level", 1)
    dec_len = int(pywt.Wavelet(wavelet).dec_len)
    deepest = pywt.dwt_max_level(n, dec_len)
    if level > deepest:
        raise ParameterError(
            f"level = {level} is too deep for {n} samples with {wavelet!r} (filter length {dec_len}): "
            f"the deepest useful level is {deepest}"
        )
    # the single-machine checks of fs, trend and bands, and the bands' description, on a short zero record
    shape = ((dec_len - 1) << level, n_axes)
    meta = wavelet_mod.wavelet_split(np.zeros(shape), fs, wavelet=wavelet, level=level, bands=bands, trend=trend)
    overlap = wavelet_overlap(dec_len, level)
    target = chunk if chunk is not None else max(int(arr.chunks[0][0]), DEFAULT_CHUNK // 4)
    chunks = wavelet_chunks(n, level, overlap, int(target))
    arr2 = (arr if arr.ndim == 2 else arr[:, None]).rechunk({0: chunks, 1: -1})
    starts = [int(v) for v in np.concatenate([[0], np.cumsum(chunks)[:-1]])]
    kwargs = dict(
        fs=meta.fs,
        wavelet=wavelet,
        level=level,
        bands=bands,
        trend=trend,
        overlap=overlap,
        n_chunks=len(chunks),
        starts=starts,
    )
    out_chunks = (chunks, (3 * n_axes,))
    if len(chunks) == 1:
        out = arr2.map_blocks(_split_block, chunks=out_chunks, dtype=np.float64, **kwargs)
    else:
        out = arr2.map_overlap(
            _split_block,
            depth={0: overlap, 1: 0},
            boundary="none",
            trim=False,
            allow_rechunk=False,
            chunks=out_chunks,
            dtype=np.float64,
            **kwargs,
        )
    parts = [out[:, p * n_axes : (p + 1) * n_axes] for p in range(3)]
    if arr.ndim == 1:
        parts = [p[:, 0] for p in parts]
    if compute:
        parts = list(dask.compute(*parts))
    return wavelet_mod.Split(
        trend=parts[0],
        low=parts[1],
        high=parts[2],
        bands=meta.bands,
        wavelet=wavelet,
        level=level,
        fs=meta.fs,
        trend_kind=trend,
        trend_freq=None,
    )


# ------------------------------------------------------------------------------------------------
# static: the exact angle


def _rate(block, fs: float, input: str) -> np.ndarray:
    b = np.asarray(block, dtype=np.float64)
    if b.ndim == 1:
        b = b[:, None]
    # the single-machine conversion, element by element (allanite._validate.as_rate_columns)
    return b * fs if input == "increment" else b


def _peak_block(block, fs: float, input: str):
    y = _rate(block, fs, input)
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
    whole, rest = _split(_rate(block, fs, input), q_exp)
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
        [_rate(b, fs, input) for b in blocks],
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
    fs = _check(estimator, input, fs)
    arr = _as_dask(x)
    n = int(arr.shape[0])
    if n < 2:
        raise InputError(f"record has {n} samples; at least 2 are needed for any Allan variance")
    n_axes = int(arr.shape[1]) if arr.ndim == 2 else 1
    ms = resolve_taus(taus, n, fs)
    target = int(chunk if chunk is not None else max(int(arr.chunks[0][0]), DEFAULT_CHUNK // 4))
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
    peaks = np.concatenate(run([dask.delayed(_peak_block)(b, fs, input) for b in blocks]))
    bad = np.flatnonzero(~np.isfinite(peaks[:, 0]))
    if bad.size:
        k = int(bad[0])
        i, a = int(bounds[k] + peaks[k, 1]), int(peaks[k, 2])
        raise InputError(
            f"samples contain a non-finite value at sample {i}"
            + (f" of axis {a}" if n_axes > 1 else "")
            + "; only finite numbers are allowed"
        )
    peak = float(peaks[:, 0].max())
    if peak == 0.0:
        values = np.zeros((n_axes, ms.size))
        return _static_result(values, ms, estimator, fs, n, input, arr.ndim == 2)
    q_exp = math.frexp(peak)[1] - QUANTUM_BITS  # 2^(E−26) with 2^E > peak

    # pass 2: exact chunk totals → exact angle offsets (Python ints for the whole quanta)
    totals = run([dask.delayed(_totals_block)(b, fs, input, q_exp) for b in blocks])
    off_w = [np.zeros(n_axes, dtype=np.int64)]
    off_r = [np.zeros(n_axes)]
    acc_w = [0] * n_axes
    rests: list[list[float]] = [[] for _ in range(n_axes)]
    for k in range(len(blocks) - 1):
        for a in range(n_axes):
            acc_w[a] += int(totals[k][0][a])
            rests[a].append(float(totals[k][1][a]))
        off_w.append(np.array(acc_w, dtype=np.int64))
        off_r.append(np.array([math.fsum(r) for r in rests]))
    offsets = list(zip(off_w, off_r))

    # pass 3: partial sums of squared second differences
    threads = resolve_workers(None)
    c = int(arr.chunks[0][0])
    n_chunks = len(blocks)
    tasks, where = [], []
    small = [(j, int(m)) for j, m in enumerate(ms) if m < c]
    large = [(j, int(m)) for j, m in enumerate(ms) if m >= c]
    classic = estimator == "avar"
    for k in range(n_chunks):
        i0, i1 = int(bounds[k]), int(bounds[k + 1])
        groups = []
        if small:  # every small m at once: the chunk and the next two at most
            plan = [(j, m, i0, min(i1, n + 1 - 2 * m)) for j, m in small]
            groups.append([p for p in plan if p[3] > p[2]])
        for j, m in large:  # one task per (chunk, large m): three slices, ≤ six chunks
            groups.append([(j, m, i0, min(i1, n + 1 - 2 * m))] if n + 1 - 2 * m > i0 else [])
        for plan in groups:
            if not plan:
                continue
            ks = sorted({kk for _j, m, a, b in plan for s in (0, m, 2 * m) for kk in _needed(bounds, a + s, b + s)})
            tasks.append(
                dask.delayed(_sum_block)(
                    [blocks[kk] for kk in ks],
                    ks,
                    bounds,
                    [offsets[kk] for kk in ks],
                    fs=fs,
                    input=input,
                    q_exp=q_exp,
                    plan=plan,
                    classic=classic,
                    threads=threads,
                )
            )
            where.append(plan)
    partial = run(tasks)
    sums: list[list[list[float]]] = [[[] for _ in range(ms.size)] for _ in range(n_axes)]
    for plan, part in zip(where, partial):
        for p, (j, *_rest) in enumerate(plan):
            for a in range(n_axes):
                sums[a][j].append(float(part[p, a]))
    counts = n_terms(estimator, n, ms)
    values = np.empty((n_axes, ms.size))
    for a in range(n_axes):
        for j, m in enumerate(ms):
            s = math.fsum(sums[a][j])
            # Σ (q·d)² / (2 m² n): scaled back by q² = 2^(2·q_exp) last, so no intermediate overflows
            values[a, j] = math.ldexp(s / (2.0 * float(m) * float(m) * float(counts[j])), 2 * q_exp)
    if not np.all(np.isfinite(values)):
        raise InputError(f"the Allan variance of samples of magnitude up to {peak:.3g} exceeds float64's range")
    return _static_result(values, ms, estimator, fs, n, input, arr.ndim == 2)


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
