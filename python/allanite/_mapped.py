"""Reading a memory-mapped record through its file, so that its pages never enter the process.

A ``.npy`` read by :func:`allanite.read_log` is a read-only :class:`numpy.memmap`: nothing is read until a
sample is touched — but every page touched stays in the process's resident memory (its RSS) until the
map is closed. A (samples, axes) record is stored row by row, so one axis's column touches every page:
three passes over a 2.4 GB record leave 2.4 GB resident besides whatever the analysis allocates.

:func:`read_rows` and :func:`column` copy rows and columns of such a record into ordinary arrays by reading
the file (``readinto`` a buffer): the operating system's page cache serves the bytes, none of them is
mapped into this process. Any other array — in memory, or a memmap whose layout in its file cannot be
worked out (written to, or not a view of the map's start) — is read through NumPy as before.

Examples
--------
>>> import numpy as np, tempfile, os
>>> from allanite._mapped import column, file_layout
>>> path = os.path.join(tempfile.mkdtemp(), "x.npy")
>>> np.save(path, np.arange(12.0).reshape(4, 3))
>>> x = np.load(path, mmap_mode="r")
>>> file_layout(x) is not None
True
>>> column(x, 1, chunk=3)
array([ 1.,  4.,  7., 10.])
"""

from __future__ import annotations

import mmap
from collections.abc import Sequence

import numpy as np

__all__ = ["CHUNK_BYTES", "file_layout", "read_rows", "column", "columns"]

#: Bytes read from the file at a time (rows × row stride).
CHUNK_BYTES = 1 << 23


def file_layout(x) -> tuple[str, int] | None:
    """(file name, byte offset of ``x[0]`` in the file) of a read-only memory map of a ``.npy`` (or a row
    slice / column view of one) whose rows are evenly strided; None for any other array."""
    if not isinstance(x, np.ndarray) or x.ndim not in (1, 2) or x.size == 0:
        return None
    root = x
    while isinstance(root, np.ndarray) and isinstance(root.base, np.ndarray):
        root = root.base
    filename = getattr(root, "filename", None)
    offset = getattr(root, "offset", None)
    if not isinstance(root, np.memmap) or not isinstance(root.base, mmap.mmap) or filename is None:
        return None
    if getattr(root, "mode", None) != "r" or offset is None or not root.flags.c_contiguous:
        return None
    start = x.__array_interface__["data"][0] - root.__array_interface__["data"][0]
    if start < 0 or start >= root.nbytes or x.strides[0] <= 0 or (x.ndim == 2 and x.strides[1] <= 0):
        return None
    return str(filename), int(offset) + int(start)


def _file_rows(x, a: int, b: int, buf: np.ndarray | None = None) -> np.ndarray | None:
    """Rows ``a:b`` of the mapped ``x`` (``0 <= a < b <= len(x)``) read from its file into a fresh buffer (or
    into ``buf``, a 1-D array of ``x``'s dtype, where it is long enough: a reader of many chunks reuses one
    buffer instead of faulting in fresh pages for each), as a view of it with ``x``'s strides; None where ``x``
    is not a mapped ``.npy`` or the file is shorter."""
    lay = file_layout(x)
    if lay is None:
        return None
    name, off = lay
    stride = x.strides[0]
    # the bytes from row a's first element to row b − 1's last: whole row strides but the last row's
    last = (x.shape[1] - 1) * x.strides[1] + x.itemsize if x.ndim == 2 else x.itemsize
    nbytes = (b - a - 1) * stride + last
    size = -(-nbytes // x.itemsize)
    if buf is None or buf.size < size or buf.dtype != x.dtype:
        buf = np.empty(size, dtype=x.dtype)
    with open(name, "rb") as f:
        f.seek(off + a * stride)
        got = f.readinto(buf.view(np.uint8)[:nbytes].data)
    if got != nbytes:  # the file changed under the map: the caller reads it the ordinary way
        return None
    strides = x.strides if x.ndim == 2 else (stride,)
    return np.lib.stride_tricks.as_strided(buf, shape=(b - a,) + x.shape[1:], strides=strides, writeable=False)


def read_rows(x, a: int, b: int) -> np.ndarray:
    """Rows ``a:b`` of ``x`` as an in-memory array (the file read when ``x`` is a mapped ``.npy``)."""
    a, b = max(0, int(a)), min(int(x.shape[0]), int(b))
    rows = _file_rows(x, a, b) if b > a else None
    return np.array(x[a:b] if rows is None else rows)


def column(x, k: int | None = None, *, chunk: int | None = None, dtype=np.float64) -> np.ndarray:
    """Column ``k`` of a 2-D ``x`` (``k`` None: the 1-D ``x`` itself) as a contiguous array of ``dtype``,
    read ``chunk`` rows at a time (default: :data:`CHUNK_BYTES` of file) — for a mapped ``.npy`` from the
    file, never touching the map; for any other array a plain copy."""
    return columns(x, [k], chunk=chunk, dtype=dtype)[0]


def columns(x, ks: Sequence[int | None], *, chunk: int | None = None, dtype=np.float64) -> list[np.ndarray]:
    """:func:`column` of each of ``ks`` in one pass over the file: each chunk of rows is read once and every
    column asked for copied out of it — the same values as one :func:`column` call per axis, with one read
    of the file instead of one per axis."""
    n = int(x.shape[0])
    if file_layout(x) is None or n == 0:
        return [np.array(x if k is None else x[:, k], dtype=dtype, order="C") for k in ks]
    rows = chunk if chunk is not None else max(1, CHUNK_BYTES // max(1, x.strides[0]))
    outs = [np.empty(n, dtype=dtype) for _ in ks]
    buf = np.empty(-(-min(n, rows) * x.strides[0] // x.itemsize) + 1, dtype=x.dtype)
    for a in range(0, n, rows):
        b = min(n, a + rows)
        block = _file_rows(x, a, b, buf)
        if block is None:
            block = x[a:b]
        for out, k in zip(outs, ks):
            out[a:b] = block if k is None else block[:, k]
    return outs
