"""The report's figures as PNG bytes, drawn on two processes where the machine gives this one two cores.

Drawing and rasterising a figure is matplotlib's Python (ticks, text layout) under one interpreter lock; the
report's 9 figures of a three-axis log are most of its wall time. Where ``os.fork`` exists, at least two cores
are available, one of them idle now (the run queue) and the report is drawn from the main thread, a forked child
(``fork``: the figures' drawing closures need no pickling, the child holds the report already) and this process
take the figures from one queue, largest first (:func:`draw_order`), each the next one left when it is done with
its last — so the two finish within about one figure of each other whatever each figure costs — and the child
hands its PNGs back through a pipe. The PNGs are the same bytes as drawn one after another. A child that fails or
is killed leaves the figures it took to the parent, which then draws them itself (so an error in a figure is
raised here, with its traceback); Ctrl-C ends the child with the parent.
"""

from __future__ import annotations

import gc
import io
import os
import pickle
import signal
import sys
import threading
import time
import warnings
from collections.abc import Iterable
from contextlib import contextmanager
from functools import cache

from ._lean import lean_figure

__all__ = [
    "render_pngs",
    "figure_processes",
    "idle_cores",
    "draw_order",
    "min_figures_to_split",
    "fewer_collections",
]

#: Fewer figures than this are drawn in this process where it has not drawn a figure yet (forking costs ~10 ms
#: and a child forked before matplotlib's font set-up pays it again); where it has (the figure process of
#: :mod:`allanite.report._worker`, set up before it is handed the report: a ``--refine`` report's three
#: refinement figures are what is left then), two figures are split (:func:`min_figures_to_split`).
MIN_FIGURES_TO_SPLIT = 4


#: Whether this process has drawn a figure (:func:`png`): matplotlib and its fonts are set up, and a child
#: forked now inherits them.
_STATE = {"drawn": False}


def min_figures_to_split() -> int:
    """Fewest figures drawn on two processes: 2 where this process has drawn a figure already (a forked child
    inherits matplotlib's set-up), else ``MIN_FIGURES_TO_SPLIT``."""
    return 2 if _STATE["drawn"] else MIN_FIGURES_TO_SPLIT


#: zlib level of the PNGs (measured on the ADIS16405 report's 14 figures: level 6, PIL's default, 6.3 s of CPU
#: and 1316 kB; level 1, 4.1 s and 1439 kB).
PNG_COMPRESSION = 1


#: Allocations between two collections of the garbage collector's youngest generation while figures are drawn
#: (CPython's default: 700). A figure allocates some 10⁵ objects (ticks, lines, texts, transforms), so the
#: default collects ~140 times over the ADIS16405 report's 9 figures: 0.14–0.23 s of their 2.0–2.7 s of CPU,
#: 0.02–0.03 s at 5000 (measured with ``gc.callbacks``; benches/results/pipeline.md). The older generations keep
#: their ratios, so a figure's reference cycles are still collected a few figures later.
GC_THRESHOLD = 5000


@contextmanager
def fewer_collections():
    """Raise the youngest generation's collection threshold to ``GC_THRESHOLD`` (where it is lower) while
    figures are drawn; the previous thresholds are restored on leaving."""
    old = gc.get_threshold()
    gc.set_threshold(max(old[0], GC_THRESHOLD), *old[1:])
    try:
        yield
    finally:
        gc.set_threshold(*old)


def figure_processes(leaving: int = 0) -> int:
    """Processes that draw the figures: 2 where ``fork`` exists, two cores are available, one of them is idle
    now (:func:`idle_cores`) and this is the main thread, else 1 (a report built in a worker thread — Dask's
    ``allanite batch`` — gets its parallelism from its workers, and a fork beside running threads could copy
    a lock one of them holds). ``leaving``: runnable tasks counted now that are about to wait — the figure
    process of :mod:`allanite.report._worker` counts the command's process, which hands it the report and then
    only writes the JSON before it waits for the PNGs."""
    if not hasattr(os, "fork") or sys.platform != "linux" or threading.current_thread() is not threading.main_thread():
        return 1
    try:
        cores = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        cores = os.cpu_count() or 1
    # a second process pays off only on an idle core: on a machine busy with other work it adds the child's
    # share (~15 % more CPU in all) and gains no core (measured: benches/results/pipeline.md)
    return 2 if cores >= 2 and idle_cores(cores) + leaving >= 1 else 1


#: Samples of the run queue :func:`idle_cores` takes, and the pause between them (s).
RUN_QUEUE_SAMPLES = 7
RUN_QUEUE_PAUSE = 0.002


def idle_cores(cores: int) -> float:
    """Cores no other task uses now: ``cores`` less the runnable tasks besides this one (the median of a few
    samples of ``/proc/loadavg``'s run queue, over ~15 ms); where that cannot be read, ``cores`` less the last
    minute's load average. The load average alone misjudges a report that has just computed on every core
    itself (``--refine``): its own past work would keep the figures on one process."""
    counts = []
    try:
        for i in range(RUN_QUEUE_SAMPLES):
            if i:
                time.sleep(RUN_QUEUE_PAUSE)
            with open("/proc/loadavg", encoding="ascii") as f:
                counts.append(int(f.read().split()[3].split("/")[0]))
    except (OSError, ValueError, IndexError):
        return cores - os.getloadavg()[0]
    counts.sort()
    return cores - (counts[len(counts) // 2] - 1)  # the run queue holds this process's thread too


@cache
def _report_figure():
    """The Figure class of the report: a ``tight_layout`` call of a drawing function does nothing.

    The report lays out its figures with fixed margins (``subplots_adjust``, in the drawing functions); a
    tight layout measures every text of the figure once more before it is drawn — most of the time of
    :meth:`allanite.Refinement.plot`'s figure, whose margins the report sets itself."""
    from matplotlib.figure import Figure  # matplotlib only when figures are drawn

    class ReportFigure(Figure):
        def tight_layout(self, *, pad=1.08, h_pad=None, w_pad=None, rect=None):
            """Nothing: the report's figures have fixed margins."""

    return ReportFigure


def png(spec, dpi: int) -> bytes:
    """One figure of :func:`allanite.report.figures.figure_specs` drawn and encoded as PNG (with the fewer
    artists of :func:`allanite.report._lean.lean_figure`)."""
    _name, _title, _caption, size, draw = spec
    fig = _report_figure()(figsize=size, dpi=dpi)
    with warnings.catch_warnings():  # a constant axis (ADEV 0 at every τ, said in the notes) draws no curve
        warnings.filterwarnings("ignore", message="Data has no positive values", category=UserWarning)
        draw(fig)
        lean_figure(fig)
    buf = io.BytesIO()
    # zlib level 1: a third of the drawing's CPU time less than the default 6, for PNGs ~10 % larger
    fig.savefig(buf, format="png", dpi=dpi, pil_kwargs={"compress_level": PNG_COMPRESSION})
    _STATE["drawn"] = True
    return buf.getvalue()


def render_pngs(specs: list, dpi: int, step, processes: int | None = None) -> dict:
    """File name → PNG bytes of every spec, in the specs' order; ``step(text)`` is called once per figure.
    ``processes``: 1 draws them here one after another; None chooses (:func:`figure_processes`)."""
    processes = figure_processes() if processes is None else processes
    pngs: list[bytes | None] = [None] * len(specs)
    split = processes > 1 and min_figures_to_split() <= len(specs) <= MAX_QUEUED
    with fewer_collections():  # the child forked here inherits the thresholds
        queue = _Queue(draw_order(specs)) if split else None
        child = _fork_child(specs, queue, dpi) if queue is not None else None
        mine: Iterable[int] = queue if queue is not None and child is not None else range(len(specs))
        try:
            for i in mine:
                step(f"figure {specs[i][0]}")
                pngs[i] = png(specs[i], dpi)
            got = _collect(child) if child is not None else None
        finally:
            if child is not None:
                _end(child)
            if queue is not None:
                queue.close()
        for i, spec in enumerate(specs):  # the child's figures, or those a failed child took: drawn here
            if pngs[i] is None:
                step(f"figure {spec[0]}")
                pngs[i] = got[i] if got is not None and i in got else png(spec, dpi)
    return {spec[0]: data for spec, data in zip(specs, pngs)}


def draw_order(specs: list) -> list:
    """Indices of the specs, the largest figure first — a figure's area (inches²) standing for its cost (panels,
    ticks, pixels: the ADIS report's five-panel coefficient figure costs about two and a half single-panel
    ones); equal figures in the specs' order. Taken from one queue by two processes, the costly figures are
    drawn first and the small ones fill the end, so neither waits long for the other."""
    return sorted(range(len(specs)), key=lambda i: -specs[i][3][0] * specs[i][3][1])


#: Most figures drawn from one queue (4 bytes each in a pipe, written whole before the child is forked: within
#: Linux's smallest pipe buffer, 4 kB); a report with more is drawn in one process.
MAX_QUEUED = 1024


class _Queue:
    """Figure indices in a pipe, 4 bytes each, the write end closed: either process takes the next one with one
    read (a pipe read of whole records is atomic under the pipe's lock) until the pipe is empty (end-of-file)."""

    def __init__(self, order: list):
        self.r, w = os.pipe()
        try:
            data = b"".join(int(i).to_bytes(4, "little") for i in order)
            while data:
                data = data[os.write(w, data) :]
        finally:
            os.close(w)

    def __iter__(self):
        while len(head := os.read(self.r, 4)) == 4:
            yield int.from_bytes(head, "little")

    def close(self) -> None:
        if self.r >= 0:
            os.close(self.r)
            self.r = -1


def _fork_child(specs: list, queue: _Queue, dpi: int):
    """(pid, read end) of a child drawing the figures it takes from ``queue``; None where fork fails."""
    r, w = os.pipe()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)  # 3.12+: fork with the core's idle threads
            pid = os.fork()
    except OSError:
        os.close(r)
        os.close(w)
        return None
    if pid == 0:  # the child: draw, hand back, exit without running the parent's exit handlers
        status = 1
        try:
            os.close(r)
            signal.signal(signal.SIGINT, signal.SIG_DFL)
            drawn = {i: png(specs[i], dpi) for i in queue}
            with os.fdopen(w, "wb") as f:
                f.write(pickle.dumps(drawn, protocol=pickle.HIGHEST_PROTOCOL))
            status = 0
        finally:
            os._exit(status)
    os.close(w)
    return pid, r


def _collect(child) -> dict | None:
    """The child's PNGs by figure index, or None where it failed (its figures are then drawn by the caller)."""
    pid, r = child
    chunks = []
    while chunk := os.read(r, 1 << 20):
        chunks.append(chunk)
    _, status = os.waitpid(pid, 0)
    if status != 0 or not chunks:
        return None
    try:
        return pickle.loads(b"".join(chunks))
    except Exception:  # a truncated hand-over: draw them here
        return None


def _end(child) -> None:
    """Close the pipe and reap the child; kill it first if it is still drawing (the parent was interrupted
    or failed)."""
    pid, r = child
    os.close(r)
    try:
        done, _ = os.waitpid(pid, os.WNOHANG)
        if done == 0:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
    except ChildProcessError:  # already reaped by _collect
        pass
