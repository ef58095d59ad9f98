"""The report's figures drawn on two processes: the same PNG bytes, in the same order, as drawn one after
another; a figure failing in the child is drawn again (and fails) in the parent."""

import os

import numpy as np
import pytest

from allanite.report.rendering import figure_processes, render_pngs

pytestmark = pytest.mark.skipif(not hasattr(os, "fork"), reason="figures are drawn on two processes only with fork")


def _spec(k, fail=False):
    def draw(fig):
        if fail:
            raise ValueError(f"figure {k} cannot be drawn")
        ax = fig.add_subplot()
        x = np.logspace(-2, 3, 40)
        ax.loglog(x, (k + 1) / np.sqrt(x), marker=".")
        ax.set_title(f"figure {k}")
        ax.grid(True, which="both")

    return (f"f{k}.png", f"figure {k}", "caption", (2.4, 1.8), draw)


def test_two_processes_give_the_serial_bytes_in_order():
    specs = [_spec(k) for k in range(5)]
    steps_1, steps_2 = [], []
    serial = render_pngs(specs, 60, steps_1.append, processes=1)
    split = render_pngs(specs, 60, steps_2.append, processes=2)
    assert list(split) == [f"f{k}.png" for k in range(5)] == list(serial)
    assert all(split[k] == serial[k] for k in serial)
    assert all(v.startswith(b"\x89PNG") for v in split.values())
    assert len(set(split.values())) == 5  # five different figures, not one repeated
    assert sorted(steps_2) == sorted(steps_1) == sorted(f"figure f{k}.png" for k in range(5))


def test_a_figure_failing_in_the_child_fails_in_the_parent():
    specs = [_spec(0), _spec(1, fail=True), _spec(2), _spec(3)]  # whichever process takes it, it fails here
    with pytest.raises(ValueError, match="figure 1 cannot be drawn"):
        render_pngs(specs, 60, lambda text: None, processes=2)


def test_figures_are_drawn_with_fewer_collections_and_the_thresholds_come_back():
    import gc

    from allanite.report import rendering

    old = gc.get_threshold()
    seen = []

    def draw(fig):
        seen.append(gc.get_threshold())
        fig.add_subplot().plot([0, 1])

    try:
        gc.set_threshold(700, 10, 10)
        got = render_pngs([("g.png", "g", "c", (1.0, 1.0), draw)], 40, lambda text: None, processes=1)
        assert seen == [(rendering.GC_THRESHOLD, 10, 10)]  # the older generations keep their ratios
        assert gc.get_threshold() == (700, 10, 10)
        assert got["g.png"].startswith(b"\x89PNG")
        gc.set_threshold(50_000, 10, 10)  # a higher threshold set by the user is kept
        with pytest.raises(ValueError, match="boom"), rendering.fewer_collections():
            assert gc.get_threshold() == (50_000, 10, 10)
            raise ValueError("boom")
        assert gc.get_threshold() == (50_000, 10, 10)
    finally:
        gc.set_threshold(*old)


def test_figure_processes_is_one_or_two():
    assert figure_processes() in (1, 2)


def test_a_report_drawn_in_a_worker_thread_forks_nothing():
    import threading

    seen = []
    t = threading.Thread(target=lambda: seen.append(figure_processes()))
    t.start()
    t.join()
    assert seen == [1]


def test_idle_cores_reads_the_run_queue_less_this_process(monkeypatch):
    import io

    from allanite.report import rendering

    queue = iter(["0.9 0.5 0.4 3/200 1\n", "0.9 0.5 0.4 1/200 1\n", "0.9 0.5 0.4 3/200 1\n"] * 3)
    monkeypatch.setattr(rendering, "open", lambda *a, **k: io.StringIO(next(queue)), raising=False)
    monkeypatch.setattr(rendering, "RUN_QUEUE_PAUSE", 0.0)
    monkeypatch.setattr(rendering, "RUN_QUEUE_SAMPLES", 3)
    # median of 3, 1, 3 runnable tasks = 3, one of them this process: 2 others on 4 cores leave 2 idle
    assert rendering.idle_cores(4) == 2


def test_idle_cores_without_the_run_queue_uses_the_load_average(monkeypatch):
    from allanite.report import rendering

    def unreadable(*args, **kwargs):
        raise OSError("no /proc")

    monkeypatch.setattr(rendering, "open", unreadable, raising=False)
    monkeypatch.setattr(rendering.os, "getloadavg", lambda: (1.5, 1.0, 1.0))
    assert rendering.idle_cores(2) == 0.5


def test_the_figures_are_queued_largest_first():
    from allanite.report.rendering import draw_order

    def sized(k, w, h):
        return (f"f{k}.png", "", "", (w, h), None)

    # one large figure (area 8), one middling (4) and three small ones (2 each, kept in the specs' order)
    specs = [sized(0, 2, 1), sized(1, 4, 2), sized(2, 2, 1), sized(3, 2, 2), sized(4, 2, 1)]
    assert draw_order(specs) == [1, 3, 0, 2, 4]


def _marking(k, folder, size=(2.4, 1.8)):
    """A figure whose drawing leaves a file named after it and the drawing process's id."""

    def draw(fig):
        (folder / f"f{k}.{os.getpid()}").touch()
        fig.add_subplot().plot([0, k + 1])

    return (f"f{k}.png", f"figure {k}", "caption", size, draw)


def test_each_queued_figure_is_drawn_once_by_one_of_the_two_processes(tmp_path):
    specs = [_marking(k, tmp_path, (2.0 + 0.1 * (k % 3), 1.5)) for k in range(8)]
    split = render_pngs(specs, 40, lambda text: None, processes=2)
    marks = sorted(p.name for p in tmp_path.iterdir())
    assert [m.split(".")[0] for m in marks] == [f"f{k}" for k in range(8)]  # each figure drawn exactly once
    drawers = {m.split(".")[1] for m in marks}
    assert len(drawers) <= 2 and (len(drawers) == 1 or str(os.getpid()) in drawers)  # this process and its child
    for p in tmp_path.iterdir():
        p.unlink()
    serial = render_pngs(specs, 40, lambda text: None, processes=1)
    assert list(split) == list(serial) and all(split[k] == serial[k] for k in serial)


def test_figures_a_dead_child_took_are_drawn_by_the_parent(tmp_path):
    """A child that dies after taking a figure from the queue (killed, out of memory) hands nothing back: the
    parent draws the figure it took, and the other figures as before."""
    import time

    parent, died = os.getpid(), tmp_path / "child died"

    def dying(k):
        def draw(fig):
            if os.getpid() != parent:
                died.touch()
                os._exit(3)  # the child dies on the first figure it takes
            deadline = time.monotonic() + 30
            while not died.exists() and time.monotonic() < deadline:  # leave the child a figure to take
                time.sleep(0.005)
            fig.add_subplot().plot([0, k + 1])

        return (f"f{k}.png", f"figure {k}", "caption", (2.4, 1.8), draw)

    specs = [dying(k) for k in range(5)]
    steps = []
    split = render_pngs(specs, 40, steps.append, processes=2)
    assert died.exists()
    serial = render_pngs(specs, 40, lambda text: None, processes=1)
    assert list(split) == list(serial) and all(split[k] == serial[k] for k in serial)
    assert sorted(steps) == sorted(f"figure f{k}.png" for k in range(5))


def test_lean_figure_draws_the_minor_ticks_where_matplotlib_puts_them():
    import io

    import numpy as np
    from matplotlib.figure import Figure
    from matplotlib.ticker import NullLocator

    from allanite.report._lean import lean_figure

    fig = Figure(figsize=(12, 4))
    wide, narrow = fig.subplots(1, 2)
    wide.loglog([1e-2, 1e3], [1e-3, 1.0])  # five decades on x, three on y
    wide.grid(True, which="both", alpha=0.3)
    wide.set_title("wide")
    narrow.semilogy([0, 1], [2.0, 5.0])  # less than a decade: matplotlib labels its minor ticks, left as it is
    lo, hi = wide.get_xlim()
    expected = wide.xaxis.get_minorticklocs()
    expected = expected[(expected >= lo) & (expected <= hi)]
    lean_figure(fig)
    assert isinstance(wide.xaxis.get_minor_locator(), NullLocator)
    assert not isinstance(narrow.yaxis.get_minor_locator(), NullLocator)
    marks = [a for a in wide.lines if a.get_marker() == 3]  # TICKDOWN: the x axis' marks, outward
    assert len(marks) == 1 and np.allclose(marks[0].get_xdata(), expected)
    grids = list(wide.collections)
    assert len(grids) == 2  # minor grid lines of x and y
    assert sorted(len(g.get_segments()) for g in grids)[-1] == expected.size
    assert wide.xaxis.get_major_formatter()(1e-2) == "10⁻²"  # plain text, no mathtext
    assert wide.title.get_position()[1] == 1.0
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    assert buf.getvalue().startswith(b"\x89PNG")


@pytest.fixture
def small_report():
    import allanite
    from allanite.report import build_report

    y = allanite.simulate(6_000, 100.0, N=0.01, K=1e-3, seed=3)[:, None]
    return build_report(y, 100.0, unit="deg/s", window=1_500, hop=500, progress=False)


def test_the_early_worker_draws_the_same_bytes(small_report, monkeypatch):
    from allanite.report import _worker, result

    serial = render_pngs(small_report.figure_specs(), 60, lambda text: None, processes=1)
    assert _worker.start(when_idle=False)

    def here(*args, **kwargs):
        raise AssertionError("drawn in this process although a worker waited")

    monkeypatch.setattr(result, "render_pngs", here)
    steps = []

    class Bar:
        def step(self, text):
            steps.append(text)

    images = small_report.render_figures(Bar(), dpi=60)
    assert list(images) == list(serial) and all(images[k] == serial[k] for k in serial)
    assert steps == [f"figure {k}" for k in serial]
    assert not _worker._WORKER  # used once


def test_a_dead_worker_leaves_the_figures_to_this_process(small_report):
    import signal

    from allanite.report import _worker

    serial = render_pngs(small_report.figure_specs(), 60, lambda text: None, processes=1)
    assert _worker.start(when_idle=False)
    os.kill(_worker._WORKER[0][0], signal.SIGKILL)
    images = small_report.render_figures(False, dpi=60)
    assert list(images) == list(serial) and all(images[k] == serial[k] for k in serial)


def test_an_unused_worker_is_ended():
    from allanite.report import _worker

    assert _worker.start(when_idle=False)
    pid = _worker._WORKER[0][0]
    _worker.close()
    assert not _worker._WORKER
    with pytest.raises(ChildProcessError):
        os.waitpid(pid, os.WNOHANG)  # reaped


def test_the_worker_draws_the_davar_figures_from_the_offered_analysis(monkeypatch):
    import allanite
    from allanite.report import _worker, build_report

    y = allanite.simulate(6_000, 100.0, N=0.01, K=1e-3, seed=4)[:, None]
    offered = []
    real_offer = _worker.offer
    monkeypatch.setattr(
        _worker, "offer", lambda partial, complete=False: offered.append(partial) or real_offer(partial, complete)
    )
    assert _worker.start(when_idle=False)
    rep = build_report(y, 100.0, unit="deg/s", window=1_500, hop=500, progress=False)
    assert len(offered) == 1 and offered[0].fits is None and offered[0].dynamic is rep.dynamic
    images = rep.render_figures(False)  # the offered figures were drawn at the default 100 dpi
    serial = render_pngs(rep.figure_specs(), 100, lambda text: None, processes=1)
    assert list(images) == list(serial) and all(images[k] == serial[k] for k in serial)
    assert not _worker.waiting()


def test_a_report_computing_more_after_its_fits_offers_them_too(monkeypatch):
    """With paper 002's sections (or ``refine``, frames) computed after the fits, the worker is offered the
    report with its fits before them and draws every figure it has meanwhile: the same bytes."""
    import allanite
    from allanite.report import _worker, build_report

    y = allanite.simulate(6_000, 100.0, N=0.01, K=1e-3, seed=4)[:, None]
    offered = []
    real_offer = _worker.offer

    def offer(partial, complete=False):
        offered.append((partial, complete))
        real_offer(partial, complete=complete)

    monkeypatch.setattr(_worker, "offer", offer)
    assert _worker.start(when_idle=False)
    rep = build_report(y, 100.0, unit="deg/s", window=1_500, hop=500, taper="hann", progress=False)
    assert [(p.fits is None, c) for p, c in offered] == [(True, False), (False, True)]
    assert offered[1][0].fits is rep.fits and offered[1][0].series is rep.series
    images = rep.render_figures(False)
    serial = render_pngs(rep.figure_specs(), 100, lambda text: None, processes=1)
    assert list(images) == list(serial) and all(images[k] == serial[k] for k in serial)
    assert not _worker.waiting()


def test_two_figures_are_split_where_matplotlib_is_set_up(monkeypatch):
    """The figure process has drawn before it is handed the report: a --refine report's three refinement
    figures left then are split; a process that has not drawn yet keeps fewer than four."""
    from allanite.report import rendering

    monkeypatch.setitem(rendering._STATE, "drawn", False)
    assert rendering.min_figures_to_split() == rendering.MIN_FIGURES_TO_SPLIT == 4
    specs = [_spec(k) for k in range(2)]
    serial = render_pngs(specs, 60, lambda text: None, processes=1)  # sets up the Agg canvas here
    assert rendering.min_figures_to_split() == 2
    forked = []
    real_fork = rendering._fork_child
    monkeypatch.setattr(rendering, "_fork_child", lambda *a: forked.append(a[1]) or real_fork(*a))
    split = render_pngs(specs, 60, lambda text: None, processes=2)
    assert len(forked) == 1  # a child took figures from the queue
    assert list(split) == list(serial) and all(split[k] == serial[k] for k in serial)


def test_write_hands_the_report_over_before_making_the_json_and_page(small_report, tmp_path, monkeypatch):
    """With a figure process waiting, ``Report.write`` hands it the report first and makes the summary, the
    JSON text and the page's context while it draws; the files are those of a write without it."""
    import json

    from allanite.report import _worker, result

    order = []
    real_hand_over, real_context = _worker.hand_over, result.page_context
    monkeypatch.setattr(_worker, "hand_over", lambda rep, dpi: order.append("hand over") or real_hand_over(rep, dpi))
    monkeypatch.setattr(result, "page_context", lambda rep: order.append("page") or real_context(rep))
    here = small_report.write(tmp_path / "here", progress=False, dpi=60)
    small_report._summary = None
    assert _worker.start(when_idle=False)
    there = small_report.write(tmp_path / "worker", progress=False, dpi=60)
    # (the last: take's, which finds the report handed over already and only collects)
    assert order == ["hand over", "page", "hand over", "page", "hand over"]
    assert not _worker._WORKER  # used and reaped
    assert [p.name for p in here] == [p.name for p in there]
    for a, b in zip(here, there):
        if a.suffix == ".png":
            assert a.read_bytes() == b.read_bytes()
    one, two = (
        json.loads((d / "summary.json").read_text(encoding="utf-8")) for d in (tmp_path / "here", tmp_path / "worker")
    )
    one.pop("created", None), two.pop("created", None)
    assert one["files"] == two["files"] and one["files"]["figures"] == [p.name for p in here if p.suffix == ".png"]
    page = (tmp_path / "worker" / "report.html").read_text(encoding="utf-8")
    assert page.count("data:image/png;base64,") == len(one["files"]["figures"])


_DRAW_IN_A_FRESH_PROCESS = r"""
import hashlib, io, sys
from allanite.report import _worker
if sys.argv[1] == "skip":
    _worker._skip_setter_docs()
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from allanite.report.rendering import png
def draw(fig):
    ax = fig.add_subplot()
    (line,) = ax.loglog([1e-2, 1e3], [1.0, 1e-3], label="a")
    line.set(lw=2.5, c="C3", ls="--")  # set's keyword aliases, normalised by Artist.set
    assert line.get_linewidth() == 2.5 and line.get_linestyle() == "--"
    ax.set_title("τ"); ax.legend()
data = png(("f.png", "", "", (3.0, 2.0), draw), 60)
print(hashlib.sha256(data).hexdigest(), bool(Line2D.set.__doc__))
"""


def test_the_figure_process_skips_the_setter_docstrings_and_draws_the_same_bytes():
    """``_worker._skip_setter_docs`` (the figure process's, before matplotlib is imported): the Artist classes'
    ``set`` keeps working, with its aliases; only its docstring is left out; the PNG is the same bytes."""
    import subprocess
    import sys

    def run(mode):
        p = subprocess.run([sys.executable, "-c", _DRAW_IN_A_FRESH_PROCESS, mode], capture_output=True, text=True)
        assert p.returncode == 0, p.stderr
        digest, documented = p.stdout.split()
        return digest, documented

    plain, skip = run("plain"), run("skip")
    assert plain[1] == "True" and skip[1] == "False"  # the docstring was skipped where asked, and only there
    assert skip[0] == plain[0]


def test_skipping_the_setter_docstrings_leaves_an_imported_matplotlib_alone():
    import matplotlib.figure  # noqa: F401 - imported before, as in a process that has drawn already
    from matplotlib.lines import Line2D

    from allanite.report import _worker

    _worker._skip_setter_docs()

    class Later(Line2D):  # a class defined afterwards still gets its docstring: nothing was patched
        pass

    assert Later.set.__doc__ and "linewidth" in Later.set.__doc__


def test_a_task_about_to_wait_counts_as_an_idle_core(monkeypatch):
    """The figure process, handed the report, counts the command's process (runnable while it writes the JSON,
    then waiting for the PNGs) as leaving its core: two processes draw even where the run queue shows none idle."""
    from allanite.report import _worker, rendering

    monkeypatch.setattr(rendering, "idle_cores", lambda cores: 0.0)
    monkeypatch.setattr(rendering.os, "sched_getaffinity", lambda pid: {0, 1}, raising=False)
    assert rendering.figure_processes() == 1
    assert rendering.figure_processes(leaving=1) == 2
    monkeypatch.setattr(rendering, "idle_cores", lambda cores: -1.0)  # one more task than cores: still busy
    assert rendering.figure_processes(leaving=1) == 1
    assert _worker._runnable(os.getpid())  # this process, running this line
    assert not _worker._runnable(-5)  # no such process: unknown counts as not runnable
