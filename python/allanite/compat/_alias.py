"""The one opt-in alias that makes ``import allantools`` give :mod:`allanite.compat`.

The only place in allanite that writes ``sys.modules`` (tests/test_layering.py allows it here, in
this one function, and nowhere else).
"""

from __future__ import annotations

import importlib

from ..errors import AllaniteError

#: allantools' submodules, each served by the compat module of the same name
SUBMODULES = ("allantools", "ci", "dataset", "noise", "noise_kasdin", "plot", "realtime", "mask")


def install_as_allantools():
    """Make ``import allantools`` and ``from allantools.X import Y`` resolve to :mod:`allanite.compat`
    for the rest of this Python process (X: allantools, ci, dataset, noise, noise_kasdin, plot,
    realtime, mask). Call it once, before the script's first ``import allantools``; calling it again is
    harmless. Returns the compat package. Nothing is changed on disk or in other processes, and
    ``import allanite`` never does this by itself.

    Raises
    ------
    AllaniteError
        If the real allantools (or one of its submodules) is already imported in this process.

    Examples
    --------
    >>> import subprocess, sys
    >>> code = ("from allanite.compat import install_as_allantools; install_as_allantools(); "
    ...         "import allantools; from allantools.ci import edf_greenhall; print(allantools.__name__)")
    >>> subprocess.run([sys.executable, "-c", code], capture_output=True, text=True).stdout.strip()
    'allanite.compat'
    """
    import sys

    package = importlib.import_module(__package__ or "allanite.compat")
    names = {"allantools": package} | {f"allantools.{s}": getattr(package, s) for s in SUBMODULES}
    clash = [n for n, mod in names.items() if sys.modules.get(n, mod) is not mod]
    if clash:
        where = getattr(sys.modules[clash[0]], "__file__", None) or "?"
        raise AllaniteError(
            f"{clash[0]} is already imported (from {where}): call install_as_allantools() before the "
            "first `import allantools`"
        )
    sys.modules.update(names)
    return package
