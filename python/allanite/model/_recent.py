"""The last few results of a computation on a long array, found again by the array's content.

:func:`allanite.refine` asks for some computations on the same samples more than once, from places that do not
share them: a line family's phasors fitted on one half of a record and evaluated on the other, family after
family; a record's local noise scale and quantisation step for the outlier test and again for the replacement;
the held-out parts' Allan curves of samples a removal left as they were. Comparing an array with the few
remembered ones costs one pass over it, the computations many. Arrays longer than the memory's limit are never
kept (copies of a 10⁸-sample record would cost gigabytes), and nothing is remembered outside
:func:`remembering` (a refine call): on leaving it every memory is emptied. The memories keep one read-only copy
of each content between them (:func:`_shared_copy`): the outlier test's local scales and flags, a family's phasors
for each frequency, the held-out curves and the line refits are asked for on the same samples, and each memory's
own copy was 213 MB of copies for 122 MB of distinct samples in one refine of a 10⁶-sample ADIS channel.

:class:`Small` remembers the last results of a small computation repeated many times on equal small inputs (a
noise fit of a few hundred numbers asked for again by every nested fit's cold start), by the inputs' bytes.
:class:`Suffixes` remembers the last few results computed per τ (covariance blocks, EDF columns) for a fit that
cuts its shortest τ one at a time. Both are used from threads (Dask workers, a user's threads, the report's):
each memory's look-ups and inserts hold its lock, the computations run outside it.
"""

from __future__ import annotations

import contextlib
import threading
import weakref

import numpy as np

__all__ = ["Recent", "Suffixes", "Small", "holding", "remembering"]

#: One entry per :func:`remembering` open (refine calls in threads each open one); every memory made.
_OPEN: list = []
_ALL: weakref.WeakSet = weakref.WeakSet()
_LOCK = threading.Lock()  # guards _OPEN and _ALL
#: The copies the memories keep, by (shape, dtype, a few samples' bytes): weak references, so a copy lives as long
#: as some memory keeps it and no longer.
_COPIES: dict = {}
_COPIES_LOCK = threading.Lock()


def _fingerprint(arr: np.ndarray) -> tuple:
    """(shape, dtype, the bytes of at most 16 evenly spaced elements): arrays equal to the bit have equal
    fingerprints (equal ones differing in a zero's sign may not, and are then kept apart, as before)."""
    picks = arr.flat[np.linspace(0, arr.size - 1, min(arr.size, 16), dtype=np.intp)]  # no copy of the rest
    return arr.shape, arr.dtype.str, np.ascontiguousarray(picks).tobytes()


def _shared_copy(arr: np.ndarray) -> np.ndarray:
    """A read-only copy of ``arr``: the one some memory already keeps of equal content (shape, dtype, elements),
    else a new one, registered for the next memory asking."""
    fp = _fingerprint(arr)
    with _COPIES_LOCK:
        refs = [r for r in _COPIES.get(fp, []) if r() is not None]
    for ref in refs:
        kept = ref()
        if kept is not None and np.array_equal(kept, arr):
            return kept
    kept = np.array(arr, copy=True)
    kept.setflags(write=False)
    with _COPIES_LOCK:
        live = [r for r in _COPIES.get(fp, []) if r() is not None]
        _COPIES[fp] = live + [weakref.ref(kept)]
        for key in [k for k, v in _COPIES.items() if not any(r() is not None for r in v)]:
            del _COPIES[key]  # the fingerprints of copies no memory keeps any more
    return kept


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
                if not getattr(memo, "_held", 0):  # a memory :func:`holding` keeps for the next call
                    memo._items.clear()


@contextlib.contextmanager
def holding(memo):
    """Within it, ``memo`` (a :class:`Small`) keeps what it remembered from one call (a :func:`remembering`) to the
    next — a report's refinements of a log's axes, each a call, share what depends on none of them — and forgets
    it when the last holding is left. It remembers still only within calls (:func:`remembering`)."""
    with memo._lock:
        memo._held += 1
    try:
        yield
    finally:
        with memo._lock:
            memo._held -= 1
            if not memo._held:
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
        None (always outside :func:`remembering`). Equal arrays whose sampled elements (:func:`_fingerprint`)
        differ in a zero's sign are kept apart, as :func:`_shared_copy` keeps them: the value is then computed
        again, on ``arr`` itself."""
        if not _OPEN:
            return None
        with self._lock:
            items = list(self._items)
        fp = None
        for k, a, value, fp_a in items:
            if k == key and a.shape == arr.shape and a.dtype == arr.dtype:
                # a few samples first (an unequal array of the same size — the record before and after a removal,
                # another part — differs there almost always), the whole array only where they agree
                fp = _fingerprint(arr) if fp is None else fp
                if fp_a == fp and np.array_equal(a, arr):
                    return value
        return None

    def put(self, arr: np.ndarray, key: tuple, value):
        """Remember ``value`` for (a copy of) ``arr`` and ``key`` if ``arr`` is short enough (and within
        :func:`remembering`); returns ``value``. The copy is shared with every memory keeping the same content
        (:func:`_shared_copy`)."""
        if _OPEN and arr.size <= self.max_size:
            item = (key, _shared_copy(arr), value, _fingerprint(arr))
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


class Small:
    """The last ``keep`` values computed from a few small arrays (and hashable scalars), found again by the arrays'
    bytes, shapes and dtypes: a dictionary look-up, for computations of microseconds to milliseconds repeated
    thousands of times in a refine on equal inputs. Remembers only within :func:`remembering`, as :class:`Recent`
    does; the values are handed out as they were put (the caller keeps them read-only)."""

    def __init__(self, keep: int):
        self.keep = keep
        self._items: dict = {}
        self._held = 0  # open :func:`holding` scopes
        self._lock = threading.Lock()
        with _LOCK:
            _ALL.add(self)

    @staticmethod
    def key(*parts) -> tuple:
        """A key of ``parts``: each array as (shape, dtype, bytes), anything else as itself (hashable)."""
        return tuple(
            (p.shape, p.dtype.str, np.ascontiguousarray(p).tobytes()) if isinstance(p, np.ndarray) else p for p in parts
        )

    def get(self, key: tuple):
        """The value remembered for ``key``, or None (always outside :func:`remembering`)."""
        if not _OPEN:
            return None
        with self._lock:
            return self._items.get(key)

    def put(self, key: tuple, value):
        """Remember ``value`` for ``key`` (within :func:`remembering`; the oldest beyond ``keep`` out); returns it."""
        if _OPEN:
            with self._lock:
                if _OPEN:
                    self._items.pop(key, None)
                    self._items[key] = value
                    while len(self._items) > self.keep:
                        self._items.pop(next(iter(self._items)))
        return value
