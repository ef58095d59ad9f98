"""A figure process started before the report is computed (the ``allanite report`` command's).

Importing matplotlib and setting up its fonts takes about half a second, and the report's figures cannot be
drawn before the report exists. :func:`start` forks a process right away that imports matplotlib and draws a
small figure (fonts, the Agg canvas, the 3-D axes) while this process reads the log and computes; handed the
report (pickled: arrays and the fits, a few hundred kB), it draws the figures — on two processes where a core
is idle then (:func:`allanite.report.rendering.render_pngs`) — and hands the PNGs back. This process then never
imports matplotlib. The PNGs are the same bytes as drawn here.

The worker is started only where the figures would be drawn on two processes
(:func:`~allanite.report.rendering.figure_processes`: ``fork``, two cores and one of them idle, the main
thread). It ends by itself when this process closes its pipe or exits (it reads end-of-file), and with the
process group it leads when :func:`close` or Ctrl-C ends it; a worker that fails leaves the figures to this
process, which draws them itself (an error in a figure is then raised here, with its traceback).
"""

from __future__ import annotations

import os
import pickle
import signal
import warnings

__all__ = ["start", "close", "take"]

_WORKER: list = []  # the one waiting worker: (pid, write end, read end)


def start(when_idle: bool = True) -> bool:
    """Fork the figure worker if none waits yet — with ``when_idle``, only where the figures would be drawn on
    two processes (:func:`~allanite.report.rendering.figure_processes`); whether one waits now."""
    from .rendering import figure_processes

    if _WORKER:
        return True
    if not hasattr(os, "fork") or (when_idle and figure_processes() < 2):
        return False
    to_child, from_parent = os.pipe()
    to_parent, from_child = os.pipe()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)  # 3.12+: fork with the core's idle threads
            pid = os.fork()
    except OSError:
        for fd in (to_child, from_parent, to_parent, from_child):
            os.close(fd)
        return False
    if pid == 0:  # pragma: no cover - the child (its work is checked through the PNGs it returns)
        status = 1
        try:
            os.close(from_parent)
            os.close(to_parent)
            status = _serve(to_child, from_child)
        finally:
            os._exit(status)
    try:
        os.setpgid(pid, pid)  # as the worker does itself: its group exists whichever of the two runs first
    except OSError:
        pass
    os.close(to_child)
    os.close(from_child)
    _WORKER.append((pid, from_parent, to_parent))
    return True


def take(rep, dpi: int) -> dict | None:
    """File name → PNG bytes of the report's figures drawn by the waiting worker, or None when no worker waits,
    the report cannot be pickled or the worker fails (the caller draws them)."""
    if not _WORKER:
        return None
    pid, w, r = _WORKER.pop()
    try:
        try:
            data = pickle.dumps((rep, dpi), protocol=pickle.HIGHEST_PROTOCOL)
        except Exception:  # something in the report that pickle cannot carry: drawn here
            return None
        with os.fdopen(w, "wb", closefd=False) as f:
            f.write(data)
        os.close(w)
        w = -1
        chunks = []
        while chunk := os.read(r, 1 << 20):
            chunks.append(chunk)
        _, status = os.waitpid(pid, 0)
        pid = -1
        if status != 0 or not chunks:
            return None
        return pickle.loads(b"".join(chunks))
    except (OSError, pickle.UnpicklingError, EOFError):
        return None
    finally:
        _end(pid, w, r)


def close() -> None:
    """End a worker that was started but not used (an error before the figures, Ctrl-C)."""
    while _WORKER:
        _end(*_WORKER.pop())


def _end(pid: int, w: int, r: int) -> None:
    for fd in (w, r):
        if fd >= 0:
            try:
                os.close(fd)
            except OSError:
                pass
    if pid < 0:
        return
    try:
        os.killpg(pid, signal.SIGKILL)  # the worker and the second drawing process it may have forked
    except OSError:
        try:
            os.kill(pid, signal.SIGKILL)
        except OSError:
            pass
    try:
        os.waitpid(pid, 0)
    except ChildProcessError:
        pass


def _serve(r: int, w: int) -> int:  # pragma: no cover - runs in the forked worker
    """The worker: set up matplotlib, wait for (report, dpi), draw, hand the PNGs back; 0 when done."""
    os.setpgid(0, 0)  # its own group: killed with the drawing process it forks; Ctrl-C reaches the parent only
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _warm_up()
    chunks = []
    while chunk := os.read(r, 1 << 20):
        chunks.append(chunk)
    os.close(r)
    if not chunks:  # the parent closed the pipe without a report: nothing to draw
        return 0
    from .rendering import render_pngs

    rep, dpi = pickle.loads(b"".join(chunks))
    images = render_pngs(rep.figure_specs(), dpi, lambda text: None)
    with os.fdopen(w, "wb") as f:
        f.write(pickle.dumps(images, protocol=pickle.HIGHEST_PROTOCOL))
    return 0


def _warm_up() -> None:  # pragma: no cover - runs in the forked worker
    """Import what drawing needs and draw one small figure (font loading, the canvas), not saved."""
    import io

    import mpl_toolkits.mplot3d  # noqa: F401 - the DAVAR surfaces' axes

    from .. import plot  # noqa: F401 - the drawing functions
    from .rendering import png

    def draw(fig):
        ax = fig.add_subplot()
        ax.loglog([1.0, 10.0], [1.0, 0.1], label="x")
        ax.set_title("τ")
        ax.legend()

    io.BytesIO(png(("warm-up", "", "", (2.0, 1.5), draw), 50))
