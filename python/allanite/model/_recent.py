"""The last few results of a computation on a long array, found again by the array's content.

:func:`allanite.refine` asks for some computations on the same samples more than once, from places that do not
share them: a line family's phasors fitted on one half of a record and evaluated on the other, family after
family; a record's local noise scale and quantisation step for the outlier test and again for the replacement;
the held-out parts' Allan curves of samples a removal left as they were. Comparing an array with the few
remembered ones costs one pass over it, the computations many. Arrays longer than the memory's limit are never
kept (copies of a 10⁸-sample record would cost gigabytes), and nothing is remembered outside
:func:`remembering` (a refine call): on leaving it every memory is emptied.

:class:`Suffixes` remembers the last few results computed per τ (covariance blocks, EDF columns) for a fit that
cuts its shortest τ one at a time. Both are used from threads (Dask workers, a user's threads, the report's):
each memory's look-ups and inserts hold its lock, the computations run outside it.
"""

from __future__ import annotations

import contextlib
import threading
import weakref

import numpy as np

__all__ = ["Recent", "Suffixes", "remembering"]

#: One entry per :func:`remembering` open (refine calls in threads each open one); every memory made.
_OPEN: list = []
_ALL: weakref.WeakSet = weakref.WeakSet()
_LOCK = threading.Lock()  # guards _OPEN and _ALL


@contextlib.contextmanager
def remembering():
    """Within it, every :class:`Recent` remembers; when the last one open is left, they all forget."""
    with _LOCK:
        _OPEN.append(True)
    try:
        yield
    finally:
        with _LOCK:
            _OPEN.pop()
            memos = [] if _OPEN else list(_ALL)
        for memo in memos:
            with memo._lock:
                memo._items.clear()


class Recent:
    """The last ``keep`` values computed from arrays of at most ``max_size`` elements, by (the array's content,
    a key of hashable scalars); the newest last."""

    def __init__(self, keep: int, max_size: int):
        self.keep, self.max_size = keep, max_size
        self._items: list = []
        self._lock = threading.Lock()
        with _LOCK:
            _ALL.add(self)

    def get(self, arr: np.ndarray, key: tuple = ()):
        """The value remembered for an array equal to ``arr`` (same shape, dtype and elements) and ``key``, or
        None (always outside :func:`remembering`)."""
        if not _OPEN:
            return None
        with self._lock:
            items = list(self._items)
        for k, a, value in items:
            if k == key and a.shape == arr.shape and a.dtype == arr.dtype and np.array_equal(a, arr):
                return value
        return None

    def put(self, arr: np.ndarray, key: tuple, value):
        """Remember ``value`` for (a copy of) ``arr`` and ``key`` if ``arr`` is short enough (and within
        :func:`remembering`); returns ``value``."""
        if _OPEN and arr.size <= self.max_size:
            item = (key, np.array(arr, copy=True), value)
            with self._lock:
                # checked again under the lock the last leaving refine clears under: a copy made as it left is
                # dropped, not kept until some later call returns
                if _OPEN:
                    self._items.append(item)
                    del self._items[: max(0, len(self._items) - self.keep)]  # the oldest out
        return value


class Suffixes:
    """The last ``keep`` values computed per τ for (``m``, ``rest``): ``m`` the averaging factors (a tuple of
    ints, the value's axes along them), ``rest`` the other inputs (hashable). A request whose ``m`` ends a
    remembered one finds it, with how many leading τ to cut: each τ's entries depend on its own τ only."""

    def __init__(self, keep: int):
        self.keep = keep
        self._items: dict = {}
        self._lock = threading.Lock()

    def find(self, m: tuple, rest: tuple, strict: bool = False):
        """(value, k) of the newest remembered ``m`` that ends with ``m`` (k leading τ more; k > 0 if
        ``strict``) under the same ``rest``, or None."""
        with self._lock:
            items = list(self._items.items())
        for (full, others), value in reversed(items):
            k = len(full) - len(m)
            if k >= int(strict) and others == rest and full[k:] == m:
                return value, k
        return None

    def put(self, m: tuple, rest: tuple, value):
        """Remember ``value`` for (``m``, ``rest``) as the newest (the oldest beyond ``keep`` out); returns it."""
        with self._lock:
            self._items.pop((m, rest), None)
            self._items[(m, rest)] = value
            while len(self._items) > self.keep:
                self._items.pop(next(iter(self._items)))
        return value
