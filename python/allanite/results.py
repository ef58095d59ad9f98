"""Result objects of the estimators: small dataclasses with arrays, a readable repr and ``.plot()``.

Axis layout: for 1-D input ``avar`` is ``(tau,)`` (static) or ``(tau, t)`` (dynamic). For 2-D input
of shape (samples, axes) an axes dimension comes **first**: ``(axes, tau)`` and ``(axes, tau, t)``,
so ``result.avar[k]`` is axis k's result, equal to analysing that column alone. In the dynamic
result the last axis is time, as in ``scipy.signal.spectrogram``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["AllanResult", "DynamicAllanResult"]


def _fmt_range(a: np.ndarray, unit: str) -> str:
    if a.size == 0:
        return "none"
    return f"{a[0]:.4g}–{a[-1]:.4g} {unit}" if a.size > 1 else f"{a[0]:.4g} {unit}"


@dataclass(frozen=True, repr=False, eq=False)
class AllanResult:
    """Static Allan variance of a record.

    Attributes
    ----------
    tau : ndarray, (T,)
        Averaging times actually used, s (exactly ``m / fs``).
    avar : ndarray, (T,) or (axes, T)
        Allan variance, in the input's rate unit squared (e.g. (°/s)²).
    n : ndarray, (T,)
        Number of squared differences averaged at each τ (Stable32's "#" column: N − 2m for the
        overlapping estimator, K − 1 for the classic one).
    m : ndarray, (T,)
        Averaging factors, τ = m / fs.
    estimator : str
        ``"oavar"`` (overlapping) or ``"avar"`` (classic, non-overlapping).
    fs : float
        Sampling rate, Hz.
    n_samples : int
        Rate samples per axis in the record.
    input : str
        What the samples were (``"rate"``, ``"increment"``, ``"angle"``); results are in rate units.
    """

    tau: np.ndarray
    avar: np.ndarray
    n: np.ndarray
    m: np.ndarray
    estimator: str
    fs: float
    n_samples: int
    input: str = "rate"

    @property
    def adev(self) -> np.ndarray:
        """Allan deviation, √avar, in the input's rate unit."""
        return np.sqrt(self.avar)

    @property
    def n_axes(self) -> int | None:
        """Number of axes, or None for 1-D input."""
        return self.avar.shape[0] if self.avar.ndim == 2 else None

    def __repr__(self) -> str:
        axes = f", {self.n_axes} axes" if self.n_axes else ""
        return (
            f"AllanResult({self.estimator}, {self.tau.size} τ in {_fmt_range(self.tau, 's')}, "
            f"{self.n_samples} samples at {self.fs:g} Hz{axes}; "
            f"adev {_fmt_range(np.atleast_2d(self.adev)[0], '')})"
        )

    def plot(self, ax=None, **kwargs):
        """Log-log ADEV against τ (one line per axis). Returns the matplotlib Axes."""
        from .plot import plot_adev

        return plot_adev(self, ax=ax, **kwargs)


@dataclass(frozen=True, repr=False, eq=False)
class DynamicAllanResult:
    """Dynamic Allan variance: the Allan variance of every sliding window.

    Attributes
    ----------
    tau : ndarray, (T,)
        Averaging times actually used, s.
    t : ndarray, (J,)
        Window centres, s from the start of the record: ``(j·hop + window/2) / fs``.
    avar : ndarray, (T, J) or (axes, T, J)
        Column j is the static Allan variance of the ``window`` samples starting at sample
        ``j·hop`` (rate unit squared).
    n : ndarray, (T,)
        Squared differences averaged per window at each τ.
    m : ndarray, (T,)
        Averaging factors.
    window, hop : int
        Window length and spacing, in rate samples (for ``input="angle"``, in angle intervals: a
        window of W spans W + 1 angle points).
    method : str
        ``"fast"`` (sliding sums) or ``"naive"`` (every window recomputed).
    estimator : str
        ``"oavar"`` or ``"avar"``.
    fs : float
    n_samples : int
    input : str
    """

    tau: np.ndarray
    t: np.ndarray
    avar: np.ndarray
    n: np.ndarray
    m: np.ndarray
    window: int
    hop: int
    method: str
    estimator: str
    fs: float
    n_samples: int
    input: str = "rate"

    @property
    def adev(self) -> np.ndarray:
        """Allan deviation, √avar (computed on access, so the result holds one big array)."""
        return np.sqrt(self.avar)

    @property
    def n_axes(self) -> int | None:
        return self.avar.shape[0] if self.avar.ndim == 3 else None

    def __repr__(self) -> str:
        axes = f", {self.n_axes} axes" if self.n_axes else ""
        return (
            f"DynamicAllanResult({self.estimator}/{self.method}, {self.tau.size} τ in "
            f"{_fmt_range(self.tau, 's')} × {self.t.size} windows centred {_fmt_range(self.t, 's')}; "
            f"window {self.window}, hop {self.hop} samples at {self.fs:g} Hz{axes})"
        )

    def plot(self, ax=None, axis: int = 0, **kwargs):
        """Heat map of ADEV over (t, τ), log colour. Returns the matplotlib Axes."""
        from .plot import plot_davar

        return plot_davar(self, ax=ax, axis=axis, **kwargs)
