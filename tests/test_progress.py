"""Progress of long calls (issue 21): tqdm.auto bars that respect ``progress=`` and stay silent when
nobody can see them; grouping DHVAR's windows for the bar changes no number."""

from __future__ import annotations

import builtins

import numpy as np
import pytest

import allanite
from allanite import _progress
from allanite.errors import ParameterError
from allanite.report import build_report


def test_silent_without_a_terminal_or_notebook(capsys):
    assert not _progress.attached()  # pytest captures stderr: no terminal, no kernel
    y = allanite.simulate(50_000, 100.0, N=2e-3, seed=1)
    allanite.refine(y, 100.0)
    allanite.davar(y, 100.0, window=5_000, hop=2_500, estimator="theoh")
    build_report(y, 100.0, unit="deg/s")
    assert capsys.readouterr().err == ""


def test_progress_true_draws_a_bar_on_stderr_and_false_none(capsys, monkeypatch):
    monkeypatch.setattr(_progress, "DELAY", 0.0)  # these calls are quicker than the bar's delay
    y = allanite.simulate(50_000, 100.0, N=2e-3, seed=1)
    allanite.refine(y, 100.0, progress=True)
    err = capsys.readouterr().err
    assert "refine" in err and "step" in err
    allanite.refine(y, 100.0, progress=False)
    assert capsys.readouterr().err == ""
    build_report(y, 100.0, unit="deg/s", progress=True)
    assert "report" in capsys.readouterr().err


def test_a_notebook_kernel_counts_as_attached(monkeypatch):
    class ZMQInteractiveShell:  # the class name is what the check reads
        pass

    monkeypatch.setattr(builtins, "get_ipython", lambda: ZMQInteractiveShell(), raising=False)
    assert _progress.attached() and _progress.show_progress(None)
    assert not _progress.show_progress(False)


def test_progress_must_be_a_bool_or_none():
    with pytest.raises(ParameterError, match="progress must be True, False or None"):
        _progress.show_progress("yes")
    y = allanite.simulate(20_000, 100.0, N=2e-3, seed=1)
    with pytest.raises(ParameterError, match="progress"):
        allanite.refine(y, 100.0, progress="yes")


@pytest.mark.parametrize("estimator", ["theoh", pytest.param("theoh_a", marks=pytest.mark.slow)])
def test_dhvar_in_groups_equals_one_call(estimator, capsys, monkeypatch):
    monkeypatch.setattr(_progress, "DELAY", 0.0)
    rng = np.random.default_rng(5)
    x = np.column_stack([rng.normal(size=30_000), np.cumsum(rng.normal(size=30_000)) * 1e-3])
    one = allanite.davar(x, 10.0, window=3_000, hop=700, estimator=estimator, progress=False)
    grouped = allanite.davar(x, 10.0, window=3_000, hop=700, estimator=estimator, progress=True)
    assert "DHVAR" in capsys.readouterr().err
    assert grouped.avar.shape == one.avar.shape and grouped.t.size > 20  # more windows than groups
    np.testing.assert_allclose(grouped.avar, one.avar, rtol=1e-12, atol=0)
    np.testing.assert_allclose(grouped.kf, one.kf, rtol=1e-12, atol=0)
    np.testing.assert_array_equal(grouped.source, one.source)


def test_quick_calls_stay_silent_even_when_allowed(capsys):
    y = allanite.simulate(20_000, 100.0, N=2e-3, seed=1)
    allanite.davar(y, 100.0, window=2_000, hop=500, progress=True)  # milliseconds: far under DELAY
    assert capsys.readouterr().err == ""
