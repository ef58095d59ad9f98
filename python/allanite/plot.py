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


_TERM_STYLE = {"Q": "C1", "N": "C2", "B": "C3", "K": "C4", "R": "C5"}


def plot_fit(fit, ax=None, unit: str | None = None, tau=None):
    """ADEV estimates (fit points), the fitted model and each term as its own line."""
    ax = _axes(ax)
    lo = fit.tau[0] if tau is None else np.min(tau)
    hi = fit.tau[-1] if tau is None else np.max(tau)
    grid = np.geomspace(lo, hi, 200)
    err = np.sqrt(fit.avar) * np.sqrt(2.0 / fit.edf) / 2.0  # 1σ of adev ≈ adev/√(2ν)
    ax.errorbar(fit.tau, np.sqrt(fit.avar), yerr=err, fmt="o", color="k", ms=4, label="estimate (±1σ)")
    ax.loglog(grid, np.sqrt(fit.curve(grid)), color="C0", lw=2, label="fitted model")
    for name in fit.terms:
        comp = fit.component(name, grid)
        if np.any(comp > 0):
            c = fit.coefficients[name]
            label = f"{name} = {c.ieee:.3g} {c.ieee_unit}" if c.ieee is not None else f"{name} = {c.value:.3g}"
            ax.loglog(grid, np.sqrt(comp), ls="--", color=_TERM_STYLE[name], label=label)
    ax.set_xlabel("τ (s)")
    ax.set_ylabel(f"Allan deviation ({unit or fit.unit})" if (unit or fit.unit) else "Allan deviation")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize="small")
    return ax


def plot_coefficient_series(series, axes=None, ieee: bool = True):
    """One panel per coefficient against window centre time, with the interval band."""
    import matplotlib.pyplot as plt

    names = [t for t in series.terms if np.any(series.values[t] > 0)] or list(series.terms)
    if axes is None:
        _, axes = plt.subplots(len(names), 1, figsize=(7.0, 1.9 * len(names)), sharex=True, squeeze=False)
        axes = axes[:, 0]
    for ax, name in zip(np.atleast_1d(axes), names):
        scale = 1.0
        label = name
        if ieee and series.ieee is not None:
            base = series.values[name]
            with np.errstate(divide="ignore", invalid="ignore"):
                ratio = np.where(base > 0, series.ieee[name] / base, np.nan)
            scale = float(np.nanmedian(ratio)) if np.any(np.isfinite(ratio)) else 1.0
            label = f"{name} ({series.ieee_units[name]})"
        ax.plot(series.t, series.values[name] * scale, color=_TERM_STYLE.get(name, "C0"))
        ax.fill_between(series.t, series.ci_low[name] * scale, series.ci_high[name] * scale,
                        color=_TERM_STYLE.get(name, "C0"), alpha=0.25, lw=0)
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    np.atleast_1d(axes)[-1].set_xlabel("window centre t (s)")
    return axes
