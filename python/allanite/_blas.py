"""OpenBLAS on one thread for the length of a call.

:func:`allanite.refine` multiplies small matrices (the curve test's 63 × 1000 bootstrap draws, triangular
solves with 1000 right-hand sides) and long thin ones (a line's 9 × 62 500 block basis times the samples)
thousands of times. OpenBLAS splits each over its threads, whose wake-up and spin-wait cost more than the
product itself at these sizes, and far more when the cores are busy: on 2 cores at load 7, 544 products of
9 × 62 500 by a vector and 200 of 63 × 63 by 63 × 1000 (with as many triangular solves) took 20.6 s wall, 9.4 s
CPU on OpenBLAS's two threads against 0.43 s wall, 0.19 s CPU on one, the same numbers to the bit. (A sum that
OpenBLAS splits between its threads, a long dot product, moves in its last bits: refine's results are now a
one-thread OpenBLAS's on any machine.) :func:`one_thread` sets every OpenBLAS the process has loaded (NumPy's and
SciPy's wheels each bring one) to one thread (``openblas_set_num_threads_local``, OpenBLAS ≥ 0.3.27, which
returns the count it replaces) and puts the count back when the last call inside one leaves it. The count is the
library's, not the thread's: other threads of the process doing BLAS at the same time run on one thread too, and
a count set meanwhile is overwritten on leaving. Where there is no such OpenBLAS, or the platform does not list
its loaded libraries (``/proc/self/maps``, Linux), it does nothing.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import threading
from collections.abc import Callable, Iterator

__all__ = ["one_thread", "thread_counts"]

#: OpenBLAS's setter (≥ 0.3.27) that returns the thread count it replaces.
_SETTER = "openblas_set_num_threads_local"

_setters: dict[str, Callable[[int], int] | None] = {}  # library path → its setter, or None where it has none
_lock = threading.Lock()
_held: list = []  # while inside: [depth, [(setter, count to put back)]]


def _loaded_openblas() -> list[str]:
    """Paths of the OpenBLAS libraries the process has mapped (Linux; empty elsewhere)."""
    try:
        with open("/proc/self/maps", encoding="utf-8", errors="replace") as f:
            paths = {line.split(maxsplit=5)[-1].strip() for line in f if "openblas" in line.lower()}
    except OSError:
        return []
    return sorted(p for p in paths if os.path.basename(p).lower().startswith("lib") and ".so" in p)


def _setter(path: str) -> Callable[[int], int] | None:
    if path not in _setters:
        try:
            fn = getattr(ctypes.CDLL(path), _SETTER)
            fn.argtypes, fn.restype = [ctypes.c_int], ctypes.c_int
        except (OSError, AttributeError):
            fn = None
        _setters[path] = fn
    return _setters[path]


@contextlib.contextmanager
def one_thread() -> Iterator[int]:
    """OpenBLAS on one thread inside the ``with`` block (nested and concurrent blocks share one setting,
    restored by the last to leave); yields how many OpenBLAS libraries are held at one thread (0: nothing to
    do). SciPy's linear algebra is imported first, so that its OpenBLAS is loaded and set too."""
    import scipy.linalg  # noqa: F401  (loads SciPy's OpenBLAS)

    with _lock:
        if not _held:
            setters = [fn for fn in map(_setter, _loaded_openblas()) if fn is not None]
            _held[:] = [0, [(fn, fn(1)) for fn in setters]]
        _held[0] += 1
        n = len(_held[1])
    try:
        yield n
    finally:
        with _lock:
            _held[0] -= 1
            if _held[0] == 0:
                for fn, count in _held[1]:
                    fn(count)
                _held.clear()


def thread_counts() -> list[int]:
    """The thread count of every OpenBLAS the process has loaded that :func:`one_thread` can set (read by
    setting it and putting it back)."""
    out = []
    with _lock:
        for fn in filter(None, map(_setter, _loaded_openblas())):
            n = fn(1)
            fn(n)
            out.append(int(n))
    return out
