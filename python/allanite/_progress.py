"""Progress of long library calls (report building, refine, DHVAR): ``tqdm.auto`` bars, on stderr.

Every long call takes ``progress``:

- ``None`` (default): a bar only when someone can see it — inside a Jupyter kernel (a widget when
  ipywidgets is installed, text otherwise) or when stderr is a terminal. A script whose stderr goes to a
  file or a pipe, a test run or a service gets nothing.
- ``True``: always a bar; ``False``: never.

A bar appears only after :data:`DELAY` seconds, so quick calls print nothing either way.

The CLI keeps its own bar on stderr (``--quiet`` turns it off) and passes its step object to
``build_report``, which then uses it instead of making one.
"""

from __future__ import annotations

import builtins
import sys
import warnings
from typing import Any

from .errors import ParameterError

__all__ = ["DELAY", "StepBar", "attached", "show_progress"]

#: Seconds before a bar appears: quick calls stay silent even when a bar is allowed.
DELAY = 1.0


def attached() -> bool:
    """True inside a Jupyter kernel or when stderr is a terminal."""
    # IPython puts get_ipython into builtins; its Jupyter kernel's shell is a ZMQInteractiveShell. Read
    # from builtins so that nothing is imported (IPython is slow to import and usually absent).
    shell = getattr(builtins, "get_ipython", None)
    if shell is not None:
        try:
            if type(shell()).__name__ == "ZMQInteractiveShell":
                return True
        except Exception:  # an odd shell: fall back to the terminal test
            pass
    try:
        return bool(sys.stderr.isatty())
    except (AttributeError, ValueError):  # stderr replaced or closed
        return False


def show_progress(progress: Any) -> bool:
    """Whether to show a bar for ``progress`` (None, True or False; see the module docstring)."""
    if progress is None:
        return attached()
    if isinstance(progress, bool):
        return progress
    raise ParameterError(
        f"progress must be True, False or None (shown when a notebook or terminal is attached), got {progress!r}"
    )


def _tqdm() -> Any:
    with warnings.catch_warnings():
        # tqdm.auto warns once when a notebook has no ipywidgets, then draws text: text is fine
        warnings.simplefilter("ignore")
        from tqdm.auto import tqdm
    return tqdm


class StepBar:
    """A bar over named steps: ``step(name)`` before each, ``add(n)`` to skip n, ``close()`` at the end.

    Parameters
    ----------
    progress : bool or None
        See the module docstring.
    total : int
        Steps expected (``expect`` may change it).
    desc : str
        What the bar is for; shown before the step name.
    unit : str
        What a step is (shown with the rate).
    """

    def __init__(self, progress: Any, total: int, desc: str = "", unit: str = "step") -> None:
        self.desc = desc
        self.started = False
        self.bar = _tqdm()(
            total=total,
            desc=desc,
            file=sys.stderr,
            delay=DELAY,  # a call that ends sooner shows nothing
            mininterval=0.5,
            disable=not show_progress(progress),
            leave=False,
            unit=unit,
            dynamic_ncols=True,
        )

    def step(self, name: str) -> None:
        if self.started:
            self.bar.update(1)
        self.started = True
        # no refresh here: a refresh would draw the bar before its delay
        self.bar.set_description_str(f"{self.desc}: {name}" if self.desc else name, refresh=False)

    def add(self, n: int) -> None:
        self.bar.update(n)

    def expect(self, remaining: int) -> None:
        """``remaining`` more steps after the current one."""
        self.bar.total = self.bar.n + 1 + remaining

    def close(self) -> None:
        if self.started and self.bar.total is not None:
            self.bar.update(max(0, self.bar.total - self.bar.n))
        self.bar.close()

    def __enter__(self) -> StepBar:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
