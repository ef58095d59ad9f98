"""The wavelet split (paper 002) of a dask array, block by block, bit for bit."""

from __future__ import annotations

import numpy as np

from .. import wavelet as wavelet_mod
from .._validate import check_count
from ..errors import InputError, MissingDependencyError, ParameterError
from ._common import as_dask, dask, target_chunk

__all__ = ["wavelet_chunks", "wavelet_overlap", "wavelet_split"]


def _pywt():
    try:
        import pywt
    except ImportError:  # pragma: no cover - PyWavelets is a dependency
        raise MissingDependencyError("the wavelet split needs PyWavelets: pip install PyWavelets") from None
    return pywt


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


def _check_wavelet(wavelet, level, n: int) -> tuple[int, int]:
    """(level, filter length) of a discrete PyWavelets wavelet at a level ``n`` samples allow."""
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
    return level, dec_len


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
    arr = as_dask(x)
    n = int(arr.shape[0])
    n_axes = int(arr.shape[1]) if arr.ndim == 2 else 1
    level, dec_len = _check_wavelet(wavelet, level, n)
    # the single-machine checks of fs, trend and bands, and the bands' description, on a short zero record
    shape = ((dec_len - 1) << level, n_axes)
    meta = wavelet_mod.wavelet_split(np.zeros(shape), fs, wavelet=wavelet, level=level, bands=bands, trend=trend)
    overlap = wavelet_overlap(dec_len, level)
    target = target_chunk(arr, chunk)
    chunks = wavelet_chunks(n, level, overlap, int(target))
    arr2 = (arr if arr.ndim == 2 else arr[:, None]).rechunk({0: chunks, 1: -1})
    kwargs = dict(fs=meta.fs, wavelet=wavelet, level=level, bands=bands, trend=trend)
    out = _split_blocks(arr2, chunks, overlap, n_axes, kwargs)
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


def _split_blocks(arr2, chunks, overlap: int, n_axes: int, kwargs: dict):
    """The lazy (samples, 3 · axes) array of trend, low and high: :func:`_split_block` on every chunk of
    ``arr2`` (samples, axes) with ``overlap`` samples of each neighbour (none for a single chunk)."""
    starts = [int(v) for v in np.concatenate([[0], np.cumsum(chunks)[:-1]])]
    kwargs = dict(kwargs, overlap=overlap, n_chunks=len(chunks), starts=starts)
    out_chunks = (chunks, (3 * n_axes,))
    if len(chunks) == 1:
        return arr2.map_blocks(_split_block, chunks=out_chunks, dtype=np.float64, **kwargs)
    return arr2.map_overlap(
        _split_block,
        depth={0: overlap, 1: 0},
        boundary="none",
        trim=False,
        allow_rechunk=False,
        chunks=out_chunks,
        dtype=np.float64,
        **kwargs,
    )
