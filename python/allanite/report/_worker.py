"""A figure process started before the report is computed (the ``allanite report`` command's).

Importing matplotlib and setting up its fonts takes about half a second, and the report's figures cannot be
drawn before the report exists. :func:`start` forks a process right away that imports matplotlib and draws a
small figure (fonts, the Agg canvas, the 3-D axes) while this process reads the log and computes. Offered the
analysis as soon as it exists (:func:`offer`: the static and dynamic results, before the noise model is fitted),
it draws the figures that need nothing more (:func:`allanite.report.figures.from_analysis_alone`: the DAVAR heat
maps and surfaces) while this process fits; offered it again with the fits where more is computed after them
(``refine``, frames, paper 002's sections), it draws every figure but theirs meanwhile; handed the whole report
(pickled: arrays and the fits, a few hundred kB), it draws the rest — on two processes where a core is idle then,
this process's counted as free (it only writes the JSON before it waits; :func:`allanite.report.rendering.render_pngs`)
— and hands the PNGs back. This process then never imports
matplotlib. The PNGs are the same bytes as drawn here.

The worker is started only where the figures would be drawn on two processes
(:func:`~allanite.report.rendering.figure_processes`: ``fork``, two cores and one of them idle, the main
thread). It ends by itself when this process closes its pipe or exits (it reads end-of-file), and with the
process group it leads when :func:`close` or Ctrl-C ends it; a worker that fails leaves the figures to this
process, which draws them itself (an error in a figure is then raised here, with its traceback).
"""

from __future__ import annotations

import gc
import os
import pickle
import signal
import warnings

__all__ = ["start", "waiting", "offer", "hand_over", "take", "close"]

#: Capacity asked for the pipe to the worker (Linux allows up to 1 MiB unprivileged).
PIPE_BYTES = 1 << 20

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
    try:  # room in the pipe for the offered analysis (a few hundred kB) while the worker still sets up (Linux)
        import fcntl

        fcntl.fcntl(from_parent, fcntl.F_SETPIPE_SZ, PIPE_BYTES)
    except (ImportError, AttributeError, OSError):
        pass
    try:
        os.setpgid(pid, pid)  # as the worker does itself: its group exists whichever of the two runs first
    except OSError:
        pass
    os.close(to_child)
    os.close(from_child)
    _WORKER.append((pid, from_parent, to_parent))
    return True


#: Resolution of the figures drawn from the analysis before the report is complete (Report.write's default);
#: a report written at another resolution has them drawn again.
EARLY_DPI = 100


def waiting() -> bool:
    """Whether a worker waits for this process's report."""
    return bool(_WORKER)


def offer(partial, complete: bool = False) -> None:
    """Hand the waiting worker (if any) the report as far as it is computed, so that it draws the figures
    that need nothing more now: the static and dynamic results, no fits — the figures of the analysis alone
    (:func:`~allanite.report.figures.from_analysis_alone`); ``complete``: with the fits, every figure the
    partial report has is final (a report with ``refine``, frames or paper 002's sections offers it before
    computing them: their figures come with the whole report). Nothing when no worker waits or the report
    cannot be pickled."""
    if _WORKER:
        _send(("analysis", partial, EARLY_DPI, complete))


def hand_over(rep, dpi: int) -> bool:
    """Hand the waiting worker the whole report (it then draws what it has not drawn yet) and return at once,
    so that this process can prepare the files meanwhile; :func:`take` collects the PNGs. False when no worker
    waits or the report cannot be pickled (the worker is then ended; the caller draws the figures)."""
    if not _WORKER or _WORKER[0][1] < 0:
        return bool(_WORKER)  # none waits, or it has the report already
    if not _send(("report", rep, dpi)):
        return False
    pid, w, r = _WORKER[0]
    os.close(w)
    _WORKER[0] = (pid, -1, r)
    return True


def take(rep, dpi: int) -> dict | None:
    """File name → PNG bytes of the report's figures drawn by the waiting worker (handed the report here unless
    :func:`hand_over` did), or None when no worker waits, the report cannot be pickled or the worker fails (the
    caller draws them)."""
    if not _WORKER:
        return None
    try:
        if not hand_over(rep, dpi):
            return None
        pid, _, r = _WORKER[0]
        chunks = []
        while chunk := os.read(r, 1 << 20):
            chunks.append(chunk)
        _, status = os.waitpid(pid, 0)
        _WORKER[0] = (-1, -1, r)
        if status != 0 or not chunks:
            return None
        return pickle.loads(b"".join(chunks))
    except (OSError, pickle.UnpicklingError, EOFError):
        return None
    finally:
        close()


def _send(message) -> bool:
    """Write one message (its length, then its pickle) to the worker; False when it cannot be pickled or
    written (the worker is then ended)."""
    try:
        data = pickle.dumps(message, protocol=pickle.HIGHEST_PROTOCOL)
    except Exception:  # something in the report that pickle cannot carry: drawn here
        close()
        return False
    try:
        with os.fdopen(_WORKER[0][1], "wb", closefd=False) as f:
            f.write(len(data).to_bytes(8, "little") + data)
    except OSError:
        close()
        return False
    return True


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
    """The worker: set up matplotlib, draw the figures of the analysis when it is offered, the rest when the
    report comes, hand all the PNGs back; 0 when done."""
    import select

    _skip_setter_docs()
    from .figures import figure_specs, from_analysis_alone
    from .rendering import GC_THRESHOLD, figure_processes, png, render_pngs

    os.setpgid(0, 0)  # its own group: killed with the drawing process it forks; Ctrl-C reaches the parent only
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    # a process of its own that only draws: fewer collections for all its figures (rendering.fewer_collections)
    gc.set_threshold(max(gc.get_threshold()[0], GC_THRESHOLD), *gc.get_threshold()[1:])
    _warm_up()
    message = _receive(r)
    early: dict = {}  # file name -> (PNG, dpi) drawn from an offered partial report
    while message is not None and message[0] == "analysis":
        _, partial, dpi, complete = message
        for spec in figure_specs(partial):  # one at a time, until the next message comes
            if (complete or from_analysis_alone(spec[0])) and early.get(spec[0], (None, None))[1] != dpi:
                early[spec[0]] = (png(spec, dpi), dpi)
                if select.select([r], [], [], 0)[0]:
                    break
        message = _receive(r)
    if message is None:  # the parent closed the pipe without a report: nothing to draw
        return 0
    _, rep, dpi = message
    specs = figure_specs(rep)
    rest = [sp for sp in specs if early.get(sp[0], (None, None))[1] != dpi]
    # the command's process, where runnable now, waits for the PNGs once it has written the JSON: its core frees
    leaving = int(_runnable(os.getppid()))
    drawn = render_pngs(rest, dpi, lambda text: None, processes=figure_processes(leaving=leaving))
    images = {sp[0]: drawn[sp[0]] if sp[0] in drawn else early[sp[0]][0] for sp in specs}
    with os.fdopen(w, "wb") as f:
        f.write(pickle.dumps(images, protocol=pickle.HIGHEST_PROTOCOL))
    return 0


def _runnable(pid: int) -> bool:
    """Whether process ``pid`` is running or runnable now (``R`` in ``/proc/PID/stat``); False where unknown."""
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii", errors="replace") as f:
            return f.read().rsplit(")", 1)[1].split()[0] == "R"
    except (OSError, IndexError):
        return False


def _receive(r: int):
    """The next message from the parent, None at end-of-file."""
    head = _read_exactly(r, 8)
    if head is None:
        return None
    data = _read_exactly(r, int.from_bytes(head, "little"))
    return None if data is None else pickle.loads(data)


def _read_exactly(r: int, n: int) -> bytes | None:
    parts, got = [], 0
    while got < n:
        chunk = os.read(r, min(n - got, 1 << 20))
        if not chunk:
            return None
        parts.append(chunk)
        got += len(chunk)
    return b"".join(parts)


def _skip_setter_docs() -> None:  # pragma: no cover - runs in the forked worker
    """Let matplotlib's import skip writing the signature and docstring of each Artist class's ``set``.

    Every Artist subclass matplotlib defines lists its settable properties in its ``set`` method's docstring at
    import (``Artist.__init_subclass__``: an introspection of all its setters) — about a third of the CPU that
    importing what the figures need costs (``benches/bench_figure_worker.py``). This process only draws and
    shows no help text: ``set`` itself is unchanged (each class's ``set`` still calls ``Artist.set``, which
    normalises the keyword aliases as before), only its ``__doc__`` and ``__signature__`` are not filled in, and
    the PNGs are the same bytes. Nothing is done where matplotlib is imported already or no longer has the hook."""
    try:
        import matplotlib
        from matplotlib.artist import Artist
    except ImportError:
        return
    if any(hasattr(matplotlib, m) for m in ("lines", "text", "patches", "figure")):
        return  # its artists are defined already: imported before the fork
    if callable(getattr(Artist, "_update_set_signature_and_docstring", None)):
        Artist._update_set_signature_and_docstring = classmethod(lambda cls: None)  # type: ignore[attr-defined]


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
