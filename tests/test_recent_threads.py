"""The memories refine and fit keep (:mod:`allanite.model._recent`) used from threads — Dask workers, a user's
threads, the report's — give what a fresh computation gives: the per-τ suffix memory behind the covariance
blocks and EDF columns, the content memory, and two refine calls on different records run side by side."""

from __future__ import annotations

import sys
import threading

import numpy as np
import pytest

import allanite
from allanite.model import _covariance
from allanite.model._recent import Recent, Suffixes, remembering


def _in_threads(work, n_threads: int = 6) -> list:
    """Run ``work(i)`` in ``n_threads`` threads started together; their results, re-raising the first error."""
    start = threading.Barrier(n_threads)
    out: list = [None] * n_threads
    errors: list = []

    def run(i):
        start.wait()
        try:
            out[i] = work(i)
        except BaseException as exc:  # noqa: BLE001 - handed to the test's thread
            errors.append(exc)

    threads = [threading.Thread(target=run, args=(i,)) for i in range(n_threads)]
    interval = sys.getswitchinterval()
    sys.setswitchinterval(1e-6)  # threads switch as often as they can: a race shows
    try:
        for t in threads:
            t.start()
        for t in threads:
            t.join()
    finally:
        sys.setswitchinterval(interval)
    if errors:
        raise errors[0]
    return out


def test_suffixes_find_the_newest_longer_run():
    memo = Suffixes(2)
    memo.put((1, 2, 4), ("a",), "first")
    assert memo.find((2, 4), ("a",)) == ("first", 1)
    assert memo.find((1, 2, 4), ("a",)) == ("first", 0)
    assert memo.find((1, 2, 4), ("a",), strict=True) is None  # the same run is no strict suffix
    assert memo.find((2, 4), ("b",)) is None and memo.find((4, 8), ("a",)) is None
    memo.put((0, 2, 4), ("a",), "second")
    assert memo.find((2, 4), ("a",)) == ("second", 1)  # the newest first
    memo.put((8,), ("a",), "third")  # keep = 2: the oldest out
    assert memo.find((1, 2, 4), ("a",)) is None and memo.find((4,), ("a",)) == ("second", 2)


def test_suffixes_from_threads_equal_a_fresh_computation():
    memo = Suffixes(3)

    def work(i):
        rng = np.random.default_rng(i)
        for _ in range(3000):
            full = tuple(int(v) for v in np.cumsum(rng.integers(1, 4, size=6)))
            rest = (int(rng.integers(0, 3)),)
            cut = int(rng.integers(0, 3))
            hit = memo.find(full[cut:], rest)
            if hit is not None:
                value, k = hit
                assert value[k:] == tuple(m * 10 + rest[0] for m in full[cut:])
            memo.put(full, rest, tuple(m * 10 + rest[0] for m in full))
        return True

    assert all(_in_threads(work))


def test_covariance_blocks_from_threads_equal_sequential_ones():
    m = np.array([1, 2, 4, 8, 16, 32])
    cases = [(m[k:], n) for k in range(3) for n in range(2_000, 10_000, 1_000)]
    want = [_covariance._blocks(mm, n, 100.0, ("N", "K")) for mm, n in cases]

    def work(i):
        order = np.random.default_rng(i).permutation(len(cases))
        for _ in range(20):
            for j in order:
                s_blk, t_blk = _covariance.covariance_blocks(cases[j][0], cases[j][1], 100.0, ("N", "K"))
                np.testing.assert_array_equal(s_blk, want[j][0])
                np.testing.assert_array_equal(t_blk, want[j][1])
        return True

    assert all(_in_threads(work))


def test_recent_from_threads_finds_equal_arrays_only():
    memo = Recent(3, 1000)

    def work(i):
        rng = np.random.default_rng(i)
        for _ in range(2000):
            arr = np.arange(int(rng.integers(1, 6)), dtype=np.float64)
            key = (int(rng.integers(0, 3)),)
            got = memo.get(arr, key)
            assert got is None or got == (arr.size, key[0])
            memo.put(arr, key, (arr.size, key[0]))
        return True

    with remembering():
        assert all(_in_threads(work))
        assert len(memo._items) <= memo.keep
    assert memo._items == []  # emptied on leaving


@pytest.mark.slow  # two refines twice; the memories from threads: the tests above
def test_two_refines_in_threads_equal_sequential_calls():
    records = [
        (allanite.simulate(60_000, 50.0, N=2e-3, K=2e-5, gauss_markov=[(5e-3, 4.0)], seed=8), 50.0),
        (allanite.simulate(80_000, 100.0, N=1e-3, B=1e-4, seed=3), 100.0),
    ]
    alone = [allanite.refine(y, fs, progress=False) for y, fs in records]
    together = _in_threads(lambda i: allanite.refine(*records[i], progress=False), n_threads=2)
    for a, b in zip(alone, together):
        assert a.found == b.found
        assert [s.params for s in a.steps] == [s.params for s in b.steps]
        assert [(s.before, s.after) for s in a.steps] == [(s.before, s.after) for s in b.steps]
        assert a.fit.chi2 == b.fit.chi2 and a.unexplained == b.unexplained
    assert alone[0].found  # the first record's Gauss–Markov term is found


def test_a_put_as_the_last_refine_leaves_keeps_nothing(monkeypatch):
    """A put from a thread outside refine (a user's direct call) that passed the ``remembering`` check just as
    the last refine call left must not keep its copy after that call's clearing (up to ``keep`` records of
    4·10⁶ samples, 32 MB each, held until some later refine returns): the interleaving made deterministic by
    leaving inside the copy that ``put`` makes between its check and its insert."""
    from allanite.model import _recent

    memo = Recent(2, 100)
    ctx = remembering()
    ctx.__enter__()

    class LeavesWhileCopying:
        def __getattr__(self, name):  # the rest of NumPy as it is (the shared copy's fingerprint)
            return getattr(np, name)

        @staticmethod
        def array(a, copy):
            ctx.__exit__(None, None, None)  # the last refine leaves here, in another thread
            return np.array(a, copy=copy)

    monkeypatch.setattr(_recent, "np", LeavesWhileCopying())
    memo.put(np.arange(3.0), (), "value")
    monkeypatch.undo()
    assert memo._items == []
