"""refine runs OpenBLAS on one thread and gives the count back (:mod:`allanite._blas`)."""

from __future__ import annotations

import threading

import pytest

import allanite
from allanite import _blas
from allanite.model.refinement import loop

pytestmark = pytest.mark.blas_threads  # the library's own thread count, not the suite's one thread (conftest)


def _counts_or_skip() -> list[int]:
    import scipy.linalg  # noqa: F401  (loads SciPy's OpenBLAS)

    counts = _blas.thread_counts()
    if not counts:
        pytest.skip("no OpenBLAS ≥ 0.3.27 found among the loaded libraries (or no /proc/self/maps)")
    return counts


def test_one_thread_sets_and_restores_nested():
    before = _counts_or_skip()
    with _blas.one_thread() as n:
        assert n == len(before)
        assert _blas.thread_counts() == [1] * n
        with _blas.one_thread():
            assert _blas.thread_counts() == [1] * n
        assert _blas.thread_counts() == [1] * n  # the inner block leaving does not restore
    assert _blas.thread_counts() == before


def test_one_thread_restores_after_an_error_and_across_threads():
    before = _counts_or_skip()
    with pytest.raises(RuntimeError, match="boom"):
        with _blas.one_thread():
            raise RuntimeError("boom")
    assert _blas.thread_counts() == before
    inside, go_on = threading.Event(), threading.Event()

    def hold():
        with _blas.one_thread():
            inside.set()
            go_on.wait(10)

    t = threading.Thread(target=hold)
    t.start()
    inside.wait(10)
    with _blas.one_thread():  # the other thread's block is still open: this one must not restore when it leaves
        pass
    assert _blas.thread_counts() == [1] * len(before)
    go_on.set()
    t.join(10)
    assert _blas.thread_counts() == before


def test_refine_runs_blas_on_one_thread(monkeypatch):
    before = _counts_or_skip()
    seen = []
    original = loop._Run.add_curve_effects

    def spy(self, candidates):
        seen.append(_blas.thread_counts())
        return original(self, candidates)

    monkeypatch.setattr(loop._Run, "add_curve_effects", spy)
    y = allanite.simulate(40_000, 10.0, N=1e-3, K=1e-5, seed=3)
    allanite.refine(y, 10.0, progress=False)
    assert seen == [[1] * len(before)]
    assert _blas.thread_counts() == before
