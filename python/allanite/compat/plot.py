"""``allantools.plot``: the Plot class — a log-log figure of a Dataset's statistic."""

from __future__ import annotations

from ..errors import MissingDependencyError

__all__ = ["Plot"]


class Plot:
    """A matplotlib figure for :class:`~allanite.compat.Dataset` results, as ``allantools.Plot``.

    ``fig`` and ``ax`` are the figure and axes (log-log); ``no_display=True`` selects matplotlib's
    non-interactive Agg backend (tests, servers).
    """

    def __init__(self, no_display=False):
        try:
            import matplotlib

            if no_display:
                matplotlib.use("Agg")
            import matplotlib.pyplot as plt
        except ImportError:  # pragma: no cover - matplotlib is a dependency of allanite
            raise MissingDependencyError("Plot needs matplotlib: pip install matplotlib") from None
        self.plt = plt
        self.fig, self.ax = plt.subplots()
        self.ax.set_xscale("log")
        self.ax.set_yscale("log")

    def plot(self, atDataset, errorbars=False, grid=False, **kwargs):
        """Draws the dataset's statistic against τ (with ``stat_err`` error bars if ``errorbars``);
        extra keywords go to matplotlib's ``plot``/``errorbar``."""
        out = atDataset.out
        if errorbars:
            self.ax.errorbar(out["taus"], out["stat"], yerr=out["stat_err"], **kwargs)
        else:
            self.ax.plot(out["taus"], out["stat"], **kwargs)
        self.ax.set_xlabel("Tau")
        self.ax.set_ylabel(out["stat_id"])
        if grid:
            self.ax.grid(True, which="minor", ls="-", color="0.65")
            self.ax.grid(True, which="major", ls="-", color="0.25")
        else:
            self.ax.grid(False)

    def show(self):
        """matplotlib's ``show()``."""
        self.plt.show()

    def save(self, f):
        """Saves the figure to ``f``."""
        self.fig.savefig(f)
