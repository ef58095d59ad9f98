"""What every forecast model shares: in-sample accuracy accessors and the notebook display."""

from __future__ import annotations

import functools

import numpy as np

from .._display import RichDisplay, Summary, Table, thin
from .grades import Accuracy, accuracy


def accuracy_rows(acc: Accuracy, label: str) -> list:
    """Table rows (check, value, grade) of one :class:`Accuracy`, labelled."""
    return [
        [f"C = S2/S1 ({label})", acc.C, f"grade {acc.c_grade}"],
        [f"P ({label})", acc.P, acc.grade],
        [f"S1, S2 ({label})", f"{acc.S1:.4g}, {acc.S2:.4g}", f"{acc.n} values, {acc.sd} SD"],
    ]


class Forecaster(RichDisplay):
    """Shared read-only accessors of a fitted model's in-sample accuracy, and its notebook display."""

    series: np.ndarray
    fitted: np.ndarray
    sd: str
    include_first: bool
    name: str = "model"

    def predict(self, h: int) -> np.ndarray:  # pragma: no cover - overridden
        raise NotImplementedError

    @functools.cached_property
    def accuracy(self) -> Accuracy:
        """In-sample :class:`Accuracy` of ``fitted`` against ``series`` (computed once: a fitted model does not
        change)."""
        return accuracy(self.series, self.fitted, sd=self.sd, include_first=self.include_first)

    @property
    def C(self) -> float:
        return self.accuracy.C

    @property
    def P(self) -> float:
        return self.accuracy.P

    @property
    def c_grade(self) -> int:
        return self.accuracy.c_grade

    @property
    def grade(self) -> str:
        return self.accuracy.grade

    def _summary(self) -> Summary:
        params = [
            (k, v)
            for k in ("a", "b", "shift_applied", "alpha", "beta")
            if isinstance(v := getattr(self, k, None), (int, float, np.floating)) and not isinstance(v, bool)
        ]
        return Summary(
            title=f"{type(self).__name__} · {self.name}",
            what="forecast model of a coefficient series (paper 004)",
            facts=[("series", f"{self.series.size} values")] + [(k, f"{float(v):.6g}") for k, v in params],
            tables=[Table(("in-sample check", "value", "grade"), accuracy_rows(self.accuracy, "in-sample"))],
            notes=list(getattr(self, "notes", None) or []),
            figure=self._draw_small,
        )

    def _draw_small(self, ax) -> None:
        """The inline figure: the series and the in-sample fit (≤ MAX_POINTS points each)."""
        i = thin(self.series.size)
        ax.plot(i, self.series[i], "k.", ms=3, label="series")
        ax.plot(i, np.asarray(self.fitted)[i], "C3-", lw=1, label="fitted")
        ax.set_xlabel("index")
        ax.legend(fontsize="small", frameon=False)
