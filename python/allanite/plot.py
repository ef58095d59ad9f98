"""Matplotlib figures for the results (imported lazily: the estimators do not need matplotlib)."""

from __future__ import annotations

import numpy as np

__all__ = ["plot_adev", "plot_davar"]


def _axes(ax):
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(6.4, 4.4))
    return ax


def plot_adev(result, ax=None, unit: str | None = None, labels=None, **kwargs):
    """Log-log ADEV against τ, one line per axis."""
    ax = _axes(ax)
    adev = np.atleast_2d(result.adev)
    names = labels or ([f"axis {k}" for k in range(adev.shape[0])] if adev.shape[0] > 1 else [None])
    for row, name in zip(adev, names):
        ax.loglog(result.tau, row, marker=".", label=name, **kwargs)
    ax.set_xlabel("τ (s)")
    ax.set_ylabel(f"Allan deviation ({unit})" if unit else "Allan deviation")
    ax.grid(True, which="both", alpha=0.3)
    if adev.shape[0] > 1:
        ax.legend()
    return ax


def plot_davar(result, ax=None, axis: int = 0, unit: str | None = None, cmap: str = "viridis", **kwargs):
    """Heat map of the dynamic ADEV: time on x, τ on a log y axis, log colour."""
    from matplotlib.colors import LogNorm

    ax = _axes(ax)
    adev = result.adev if result.avar.ndim == 2 else result.adev[axis]
    positive = adev[adev > 0]
    norm = LogNorm(vmin=positive.min(), vmax=positive.max()) if positive.size else None
    mesh = ax.pcolormesh(result.t, result.tau, adev, shading="nearest", norm=norm, cmap=cmap, **kwargs)
    ax.set_yscale("log")
    ax.set_xlabel("window centre t (s)")
    ax.set_ylabel("τ (s)")
    ax.figure.colorbar(mesh, ax=ax, label=f"Allan deviation ({unit})" if unit else "Allan deviation")
    return ax
