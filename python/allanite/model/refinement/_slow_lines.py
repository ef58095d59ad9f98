"""Lines slow enough to move the drift test's block means, and their least-squares component in time
(:meth:`._in_time.TimeRemovals.drift_beside_slow_lines`: the drift test once more with them taken out)."""

from __future__ import annotations

import numpy as np

from .. import periodic
from ..tracing import DRIFT_BLOCKS

__all__ = ["slow_lines", "lines_component"]


def slow_lines(search: dict | None, length_s: float, declined: list) -> list[float]:
    """The frequencies (Hz) of the search's lone lines — and of the families a removal turned down — whose period
    spans more than two of the drift test's :data:`~allanite.model.tracing.DRIFT_BLOCKS` block means of a record
    ``length_s`` long (faster ones average out within a block)."""
    if search is None:
        return []
    f_max = DRIFT_BLOCKS / (2.0 * length_s)
    return [d["f0"] for d in periodic.sinusoid_lines(search, families=declined) if d["f0"] < f_max]


def lines_component(y: np.ndarray, fs: float, freqs: list[float]) -> np.ndarray:
    """The sinusoids at ``freqs`` (Hz) fitted to ``y`` by least squares together, with a constant and a ramp
    beside them (a warm-up's or a random walk's slope must not leak into a slow line's phase), as samples."""
    t = np.arange(y.size) / fs
    t_mid = t - t.mean()
    cols = [np.ones_like(t), t_mid / max(float(np.ptp(t_mid)), 1e-300)]
    for f in freqs:
        cols += [np.sin(2 * np.pi * f * t), np.cos(2 * np.pi * f * t)]
    x = np.column_stack(cols)
    coef, *_ = np.linalg.lstsq(x, np.asarray(y, dtype=np.float64), rcond=None)
    return x[:, 2:] @ coef[2:]
