"""The last few results of a computation on a long array, found again by the array's content.

:func:`allanite.refine` asks for some computations on the same samples more than once, from places that do not
share them: a line family's phasors fitted on one half of a record and evaluated on the other, family after
family; a record's local noise scale and quantisation step for the outlier test and again for the replacement;
the held-out parts' Allan curves of samples a removal left as they were. Comparing an array with the few
remembered ones costs one pass over it, the computations many. Arrays longer than the memory's limit are never
kept (copies of a 10⁸-sample record would cost gigabytes), and nothing is remembered outside
:func:`remembering` (a refine call): on leaving it every memory is emptied.
"""

from __future__ import annotations

import contextlib
import weakref

import numpy as np

__all__ = ["Recent", "remembering"]

#: One entry per :func:`remembering` open (refine calls in threads each open one); every memory made.
_OPEN: list = []
_ALL: weakref.WeakSet = weakref.WeakSet()


@contextlib.contextmanager
def remembering():
    """Within it, every :class:`Recent` remembers; when the last one open is left, they all forget."""
    _OPEN.append(True)
    try:
        yield
    finally:
        _OPEN.pop()
        if not _OPEN:
            for memo in list(_ALL):
                memo._items.clear()


class Recent:
    """The last ``keep`` values computed from arrays of at most ``max_size`` elements, by (the array's content,
    a key of hashable scalars); the newest last."""

    def __init__(self, keep: int, max_size: int):
        self.keep, self.max_size = keep, max_size
        self._items: list = []
        _ALL.add(self)

    def get(self, arr: np.ndarray, key: tuple = ()):
        """The value remembered for an array equal to ``arr`` (same shape, dtype and elements) and ``key``, or
        None (always outside :func:`remembering`)."""
        if not _OPEN:
            return None
        for k, a, value in list(self._items):  # a copy: another thread may be adding
            if k == key and a.shape == arr.shape and a.dtype == arr.dtype and np.array_equal(a, arr):
                return value
        return None

    def put(self, arr: np.ndarray, key: tuple, value):
        """Remember ``value`` for (a copy of) ``arr`` and ``key`` if ``arr`` is short enough (and within
        :func:`remembering`); returns ``value``."""
        if _OPEN and arr.size <= self.max_size:
            self._items.append((key, np.array(arr, copy=True), value))
            while len(self._items) > self.keep:  # the oldest out (another thread may be at it too)
                try:
                    self._items.pop(0)
                except IndexError:
                    break
        return value
