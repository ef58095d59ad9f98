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

import numpy as np

from .._validate import check_count
from ..errors import InputError
from ._common import DEFAULT_CHUNK, da, dask
from .dynamic import CENTRE_BATCH, davar, davar_chunks, scale_exponent
from .static import MAX_STATIC_CHUNK as MAX_STATIC_CHUNK
from .static import QUANTUM_BITS as QUANTUM_BITS
from .static import avar
from .wavelets import wavelet_chunks, wavelet_overlap, wavelet_split

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
