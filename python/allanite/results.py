"""Result objects of the estimators: small dataclasses with arrays, a readable repr and ``.plot()``.

Axis layout: for 1-D input ``avar`` is ``(tau,)`` (static) or ``(tau, t)`` (dynamic). For 2-D input
of shape (samples, axes) an axes dimension comes **first**: ``(axes, tau)`` and ``(axes, tau, t)``,
so ``result.avar[k]`` is axis k's result, equal to analysing that column alone. In the dynamic
result the last axis is time, as in ``scipy.signal.spectrogram``.

Both results share :class:`_ResultBase`: the Allan deviation, the confidence intervals (computed by
:mod:`allanite.estimators.confidence`, below this module), ``to_xarray`` with units, and ``plot``.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np

from ._display import RichDisplay, Summary, Table, fmt_ci, fmt_range, thin
from .errors import MissingDependencyError, ParameterError
from .estimators import get as get_estimator
from .estimators.confidence import confidence_intervals
from .plot import plot_adev, plot_davar  # plot imports matplotlib only when a figure is drawn
from .units import adev_unit_label

__all__ = ["AllanResult", "DynamicAllanResult"]


def _fmt_range(a: np.ndarray, unit: str) -> str:
    if a.size == 0:
        return "none"
    u = f" {unit}" if unit else ""
    return f"{a[0]:.4g}–{a[-1]:.4g}{u}" if a.size > 1 else f"{a[0]:.4g}{u}"


def _xarray() -> Any:
    """The xarray module, or a MissingDependencyError naming the extra that installs it."""
    try:
        import xarray
    except ImportError:
        raise MissingDependencyError(
            "to_xarray() needs the optional package 'xarray': pip install 'allanite[xarray]'"
        ) from None
    return xarray


class _ResultBase(RichDisplay):
    """What every Allan-family result shares: deviation, intervals, labelled export, plotting, and the
    notebook display (``_repr_html_`` from :class:`allanite._display.RichDisplay`; each result gives its
    ``_summary``).

    Subclasses are frozen dataclasses with at least ``tau``, ``avar``, ``m``, ``n``, ``estimator``,
    ``fs``, ``n_samples``, ``input``, the interval fields (``edf``, ``ci_low``, ``ci_high``,
    ``alpha``, ``confidence``) and ``source``/``kf``; ``_time_dims`` names their dims after τ.
    """

    _time_dims: tuple[str, ...] = ()

    tau: np.ndarray
    avar: np.ndarray
    m: np.ndarray
    n: np.ndarray
    estimator: str
    fs: float
    n_samples: int
    input: str
    edf: np.ndarray | None
    ci_low: np.ndarray | None
    ci_high: np.ndarray | None
    alpha: np.ndarray | None
    confidence: float | None
    source: np.ndarray | None
    kf: np.ndarray | float | None

    @property
    def adev(self) -> np.ndarray:
        """Allan deviation, √avar, in the input's rate unit (computed on access)."""
        return np.sqrt(self.avar)

    @property
    def adev_ci(self) -> tuple[np.ndarray, np.ndarray] | None:
        """(low, high) bounds on the Allan deviation, or None before :meth:`with_confidence`."""
        if self.ci_low is None or self.ci_high is None:
            return None
        return np.sqrt(self.ci_low), np.sqrt(self.ci_high)

    @property
    def n_axes(self) -> int | None:
        """Number of axes, or None for 1-D input."""
        return self.avar.shape[0] if self.avar.ndim == 2 + len(self._time_dims) else None

    @property
    def estimator_label(self) -> str:
        """The estimator in words (from the estimator registry)."""
        return get_estimator(self.estimator).label

    def static_row(self, avar, *, n_samples: int | None = None) -> AllanResult:
        """A static :class:`AllanResult` holding the one row ``avar`` on this result's τ grid: its ``tau``,
        ``n``, ``m``, estimator, rate, input and ``source``, without intervals — one axis of a multi-axis
        result, or a row that sums up a dynamic one (its windows' medians; ``n_samples`` then the window).

        Examples
        --------
        >>> import numpy as np, allanite
        >>> r = allanite.avar(np.random.default_rng(1).normal(size=(2, 1_000)).T, fs=10.0, taus=[0.1, 1.0])
        >>> one = r.static_row(r.avar[1])
        >>> one.n_axes, one.avar.shape, one.n_samples, float(one.tau[1])
        (None, (2,), 1000, 1.0)
        """
        return AllanResult(
            tau=self.tau,
            avar=np.asarray(avar),
            n=self.n,
            m=self.m,
            estimator=self.estimator,
            fs=self.fs,
            n_samples=self.n_samples if n_samples is None else int(n_samples),
            input=self.input,
            source=self.source,
        )

    def with_confidence(
        self,
        x=None,
        *,
        confidence: float = 0.683,
        alpha=None,
        edf_method: str = "greenhall",
        chi2: str = "exact",
        b1_n: str = "terms",
        fallback: str = "prudent",
    ):
        """This result with χ² confidence intervals per τ (``edf``, ``ci_low``, ``ci_high``, ``alpha``).

        Pass the samples the result was computed from (``x``, same ``input`` kind) to identify the
        noise type per τ (a dynamic result: once, from the whole record), or give ``alpha``; see
        :func:`allanite.confidence_intervals`.

        Examples
        --------
        >>> import numpy as np, allanite
        >>> y = np.random.default_rng(3).normal(size=10_000)
        >>> r = allanite.avar(y, fs=1.0, taus=[1, 10, 100]).with_confidence(y)
        >>> r.alpha, np.round(r.edf)
        (array([0, 0, 0]), array([7826., 1368.,  148.]))
        """
        ci = confidence_intervals(
            self,
            x,
            confidence=confidence,
            alpha=alpha,
            edf_method=edf_method,
            chi2=chi2,
            b1_n=b1_n,
            fallback=fallback,
        )
        return dataclasses.replace(
            self,
            edf=ci.edf,
            ci_low=ci.ci_low,
            ci_high=ci.ci_high,  # type: ignore[type-var]
            alpha=ci.alpha,
            confidence=ci.confidence,
        )

    def _record_facts(self) -> list:
        """The summary lines every result shows: the record and the τ range."""
        axes = f", {self.n_axes} {'axis' if self.n_axes == 1 else 'axes'}" if self.n_axes else ""
        facts: list = [
            ("record", f"{self.n_samples} samples at {self.fs:g} Hz ({self.n_samples / self.fs:.6g} s){axes}"),
            ("input", f"{self.input} (results in the samples' rate unit)"),
            ("τ", f"{self.tau.size} values, {fmt_range(self.tau, 's')}"),
        ]
        if self.confidence is None:
            facts.append(("intervals", "none yet — .with_confidence(x) adds them"))
        else:
            facts.append(("intervals", f"{self.confidence:.1%} χ² intervals"))
        return facts

    def _xr_common(self, unit, axis_names):
        """Dims prefix, coords, unit label and attrs shared by both results' ``to_xarray``."""
        label = adev_unit_label(unit)  # "rate unit" when None; checks the unit otherwise
        coords: dict[str, Any] = {
            "tau": ("tau", self.tau, {"units": "s", "long_name": "averaging time τ"}),
            "m": ("tau", self.m, {"units": "1", "long_name": "averaging factor, τ = m/fs"}),
            "n": ("tau", self.n, {"units": "1", "long_name": "squared differences averaged"}),
        }
        axes: tuple[str, ...] = ()
        if self.n_axes is not None:
            names = list(range(self.n_axes)) if axis_names is None else [str(a) for a in axis_names]
            if len(names) != self.n_axes:
                raise ParameterError(f"axis_names has {len(names)} names for {self.n_axes} axes")
            coords["axis"] = ("axis", names, {"long_name": "sensor axis"})
            axes = ("axis",)
        attrs: dict[str, Any] = {
            "estimator": self.estimator,
            "fs_hz": self.fs,
            "n_samples": self.n_samples,
            "input": self.input,
            "unit": "unknown" if unit is None else str(unit),
            "allanite_result": type(self).__name__,
        }
        if self.confidence is not None:
            attrs["confidence"] = self.confidence
        if self.source is not None:
            coords["m"][2]["long_name"] = "averaging factor (τ = m/fs; Theo points τ = 0.75·m/fs)"
            coords["source"] = ("tau", np.asarray(self.source, dtype=str), {"long_name": "estimator of each τ"})
        return axes, coords, label, attrs

    def _xr_data(self, axes, label):
        """The data variables: variance, deviation and (when present) their intervals, EDF and α."""
        dims = axes + ("tau",) + self._time_dims
        var_units = f"({label})²"
        dyn = "dynamic " if self._time_dims else ""
        data = {
            "avar": (dims, self.avar, {"units": var_units, "long_name": f"{dyn}Allan variance ({self.estimator})"}),
            "adev": (dims, self.adev, {"units": label, "long_name": f"{dyn}Allan deviation"}),
        }
        if self.ci_low is not None and self.ci_high is not None and self.confidence is not None:
            level = f"{self.confidence:.1%}"
            data["ci_low"] = (dims, self.ci_low, {"units": var_units, "long_name": f"{level} lower bound, variance"})
            data["ci_high"] = (dims, self.ci_high, {"units": var_units, "long_name": f"{level} upper bound, variance"})
            if not self._time_dims:
                data["adev_low"] = (
                    dims,
                    np.sqrt(self.ci_low),
                    {"units": label, "long_name": f"{level} lower bound, ADEV"},
                )
                data["adev_high"] = (
                    dims,
                    np.sqrt(self.ci_high),
                    {"units": label, "long_name": f"{level} upper bound, ADEV"},
                )
            data["edf"] = (axes + ("tau",), self.edf, {"units": "1", "long_name": "equivalent degrees of freedom"})
            data["alpha"] = (axes + ("tau",), self.alpha, {"units": "1", "long_name": "noise type α (S_y ∝ f^α)"})
        return data


@dataclass(frozen=True, repr=False, eq=False)
class AllanResult(_ResultBase):
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
        ``"oavar"`` (overlapping) or ``"avar"`` (classic, non-overlapping); ``"theo1"``, ``"theobr"``
        or ``"theoh"`` (see :mod:`allanite.estimators.theo`: Theo1 values belong to τ = 0.75·m/fs).
    fs : float
        Sampling rate, Hz.
    n_samples : int
        Rate samples per axis in the record.
    input : str
        What the samples were (``"rate"``, ``"increment"``, ``"angle"``); results are in rate units.
    edf, ci_low, ci_high, alpha, confidence : optional
        Confidence intervals, None until :meth:`with_confidence`: equivalent degrees of freedom
        and noise type α per τ (shape of ``avar``), bounds on the true Allan variance, coverage.
    source : ndarray of str, (T,), optional
        Theo-family estimators: the estimator behind each τ (``"oavar"``, ``"avar"``, ``"theo1"``,
        ``"theobr"``); None for plain Allan results.
    kf : ndarray, optional
        TheoBR's bias ratio per axis (scalar for 1-D input), None when not used.
    missing : int or ndarray
        Rate samples marked missing (NaN) per axis, ``avar(..., gaps="skip")``: an int for 1-D input, (axes,)
        otherwise; 0 for a gapless record. :func:`allanite.fit` scales each τ's EDF by the share of terms kept.
    """

    tau: np.ndarray
    avar: np.ndarray
    n: np.ndarray
    m: np.ndarray
    estimator: str
    fs: float
    n_samples: int
    input: str = "rate"
    #: Filled by :meth:`with_confidence` (None until then): EDF, variance bounds and noise type per
    #: τ, and the coverage probability.
    edf: np.ndarray | None = None
    ci_low: np.ndarray | None = None
    ci_high: np.ndarray | None = None
    alpha: np.ndarray | None = None
    confidence: float | None = None
    #: Theo-family estimators only: which estimator each τ came from (``"oavar"``, ``"avar"``,
    #: ``"theo1"``, ``"theobr"``) and TheoBR's bias ratio kf (per axis; per axis and window for DHVAR).
    source: np.ndarray | None = None
    kf: np.ndarray | float | None = None
    #: Weighting of the terms inside the window (``"rect"``, ``"hann"``, ``"hann_signal"``; paper 002).
    taper: str = "rect"
    #: Rate samples marked missing per axis (``gaps="skip"``), 0 when none.
    missing: int | np.ndarray = 0

    def __repr__(self) -> str:
        axes = f", {self.n_axes} {'axis' if self.n_axes == 1 else 'axes'}" if self.n_axes else ""
        which = " (axis 0)" if self.n_axes else ""
        return (
            f"AllanResult({self.estimator}, {self.tau.size} τ in {_fmt_range(self.tau, 's')}, "
            f"{self.n_samples} samples at {self.fs:g} Hz{axes}; "
            f"adev{which} {_fmt_range(np.atleast_2d(self.adev)[0], '')}"
            f"{'' if self.confidence is None else f'; {self.confidence:.1%} intervals'})"
        )

    def _summary(self) -> Summary:
        adev = np.atleast_2d(self.adev)
        ci = self.adev_ci
        lo, hi = (np.atleast_2d(ci[0]), np.atleast_2d(ci[1])) if ci is not None else (None, None)
        shown = min(adev.shape[0], 3)
        header = ["τ (s)", "m"]
        header += [f"ADEV{'' if self.n_axes is None else f' axis {k}'}" for k in range(shown)]
        if self.edf is not None:
            header += ["ν (EDF)", "α"]
        if self.source is not None:
            header.append("estimator")
        rows = []
        for i in range(self.tau.size):
            row: list = [self.tau[i], int(self.m[i])]
            for k in range(shown):
                row.append(adev[k, i] if lo is None or hi is None else fmt_ci(adev[k, i], lo[k, i], hi[k, i]))
            if self.edf is not None and self.alpha is not None:
                row += [np.atleast_2d(self.edf)[0, i], int(np.atleast_2d(self.alpha)[0, i])]
            if self.source is not None:
                row.append(str(self.source[i]))
            rows.append(row)
        notes = []
        if self.n_axes is not None and self.n_axes > shown:
            notes.append(f"axes 0–{shown - 1} of {self.n_axes} shown")
        if self.edf is not None and self.n_axes is not None:
            notes.append("ν and α of axis 0")
        if self.kf is not None:
            kf = np.atleast_1d(np.asarray(self.kf, dtype=float))
            notes.append("TheoBR bias ratio kf = " + ", ".join(f"{v:.4g}" for v in kf[:shown]))
        imin = int(np.argmin(adev[0]))
        facts = self._record_facts()
        facts.append(("minimum ADEV", f"{adev[0, imin]:.4g} at τ = {self.tau[imin]:.4g} s"))
        level = "" if self.confidence is None else f" [{self.confidence:.1%} interval]"
        return Summary(
            title=f"AllanResult · {self.estimator_label}",
            what=f"static deviation of the whole record ({self.estimator})",
            facts=facts,
            tables=[Table(header=header, rows=rows, caption=f"deviation in the samples' rate unit{level}")],
            notes=notes,
            figure=self._draw_small,
        )

    def _draw_small(self, ax) -> None:
        """The inline figure: ADEV of axis 0 (band: its interval), at most MAX_POINTS points."""
        i = thin(self.tau.size)
        adev = np.atleast_2d(self.adev)[0][i]
        ci = self.adev_ci
        if ci is not None:
            ax.fill_between(self.tau[i], np.atleast_2d(ci[0])[0][i], np.atleast_2d(ci[1])[0][i], color="C0", alpha=0.25)
        ax.loglog(self.tau[i], adev, "C0.-", ms=3, lw=1)
        ax.set_xlabel("τ (s)")
        ax.set_ylabel("ADEV")

    def to_xarray(self, unit=None, axis_names=None):
        """The result as an ``xarray.Dataset`` with labelled dims ``(axis, tau)`` (``(tau,)`` for 1-D
        input) and units in the attrs. Needs the optional extra: ``pip install 'allanite[xarray]'``.

        Parameters
        ----------
        unit : str, optional
            Unit of the samples (e.g. ``"deg/s"``), for the ``units`` attrs (default "rate unit").
        axis_names : list of str, optional
            Labels of the ``axis`` coordinate (default 0, 1, …).

        Returns
        -------
        xarray.Dataset
            ``avar`` and ``adev``; with intervals also ``ci_low``, ``ci_high`` (variance),
            ``adev_low``, ``adev_high``, ``edf`` and ``alpha``; coords ``tau`` (s), ``m``, ``n``,
            ``axis``; attrs ``estimator``, ``fs_hz``, ``n_samples``, ``input``, ``unit``, ``confidence``.
        """
        xr = _xarray()
        axes, coords, label, attrs = self._xr_common(unit, axis_names)
        data = self._xr_data(axes, label)
        if self.kf is not None:
            data["kf"] = (axes, np.asarray(self.kf, dtype=float), {"units": "1", "long_name": "TheoBR bias ratio"})
        return xr.Dataset(data, coords=coords, attrs=attrs)

    def plot(self, ax=None, *, labels=None, unit=None, axis=None, band=True, **kwargs):
        """Log-log ADEV against τ, one line per axis, with the interval band when there is one.

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Draw here (default: a new figure).
        labels : str or sequence of str, optional
            Legend label of each axis' line, one per axis, e.g. ``labels=["gyro_x", "gyro_y", "gyro_z"]``
            (default "axis 0", "axis 1", …). Pass the names here rather than to ``ax.legend``, which
            would pair them with the interval bands as well as the lines.
        unit : str, optional
            Unit of the samples (e.g. ``"deg/s"``), for the y label.
        axis : int, optional
            Draw only this axis of a multi-axis result.
        band : bool
            Shade the confidence interval (when the result has one).
        **kwargs
            Passed to ``Axes.loglog`` for the curves.

        Returns
        -------
        matplotlib Axes
        """
        return plot_adev(self, ax=ax, unit=unit, labels=labels, axis=axis, band=band, **kwargs)


@dataclass(frozen=True, repr=False, eq=False)
class DynamicAllanResult(_ResultBase):
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
        ``"oavar"`` or ``"avar"``; ``"theoh"`` (DHVAR) or ``"theoh_a"`` (DHVAR-A).
    fs : float
    n_samples : int
    input : str
    edf, alpha : ndarray, (T,) or (axes, T), optional
        Per-τ EDF and noise type after :meth:`with_confidence` (one ν per τ: all windows have
        the same length).
    ci_low, ci_high : ndarray, shape of ``avar``, optional
        Bounds on the true Allan variance of every window.
    confidence : float, optional
    source : ndarray of str, (T,), optional
        DHVAR: the estimator behind each τ (``"oavar"`` or ``"avar"`` up to 10 % of the window,
        ``"theobr"`` beyond).
    kf : ndarray, (J,) or (axes, J), optional
        DHVAR: every window's own TheoBR bias ratio.
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
    #: Filled by :meth:`with_confidence`: ``edf``/``alpha`` per τ (every window has the same
    #: length, so ν depends on τ only), ``ci_low``/``ci_high`` of the shape of ``avar``.
    edf: np.ndarray | None = None
    ci_low: np.ndarray | None = None
    ci_high: np.ndarray | None = None
    alpha: np.ndarray | None = None
    confidence: float | None = None
    #: Theo-family estimators only: which estimator each τ came from (``"oavar"``, ``"avar"``,
    #: ``"theo1"``, ``"theobr"``) and TheoBR's bias ratio kf (per axis; per axis and window for DHVAR).
    source: np.ndarray | None = None
    kf: np.ndarray | float | None = None
    #: Weighting of the terms inside the window (``"rect"``, ``"hann"``, ``"hann_signal"``; paper 002).
    taper: str = "rect"

    _time_dims = ("t",)

    def __repr__(self) -> str:
        axes = f", {self.n_axes} {'axis' if self.n_axes == 1 else 'axes'}" if self.n_axes else ""
        return (
            f"DynamicAllanResult({self.estimator}/{self.method}, {self.tau.size} τ in "
            f"{_fmt_range(self.tau, 's')} × {self.t.size} windows centred {_fmt_range(self.t, 's')}; "
            f"window {self.window}, hop {self.hop} samples at {self.fs:g} Hz{axes})"
        )

    def _summary(self) -> Summary:
        adev = self.adev if self.n_axes is None else self.adev[0]
        med = np.median(adev, axis=1)
        header = ["τ (s)", "m", "ADEV median", "min over t", "max over t", "max/min"]
        rows = [
            [self.tau[i], int(self.m[i]), med[i], adev[i].min(), adev[i].max(), adev[i].max() / adev[i].min()]
            for i in range(self.tau.size)
        ]
        facts = self._record_facts()
        facts[2:2] = [
            ("windows", f"{self.t.size}, centred {fmt_range(self.t, 's')}"),
            (
                "window, hop",
                f"{self.window} and {self.hop} samples ({self.window / self.fs:.4g} s, {self.hop / self.fs:.4g} s)",
            ),
        ]
        which = "" if self.n_axes is None else ", axis 0"
        notes = []
        if self.tau.size and rows[0][5] > 2.0:  # at the shortest τ every window's estimate is tight
            notes.append(
                f"ADEV at τ = {self.tau[0]:.4g} s varies ×{rows[0][5]:.3g} across the windows: "
                "the noise level changes along the record"
            )
        return Summary(
            title=f"DynamicAllanResult · {self.estimator_label}",
            what=f"deviation of every sliding window ({self.estimator}, {self.method})",
            facts=facts,
            tables=[Table(header=header, rows=rows, caption=f"ADEV across the windows, samples' rate unit{which}")],
            notes=notes,
            figure=self._draw_small,
        )

    def _draw_small(self, ax) -> None:
        """The inline figure: log ADEV over (t, τ) of axis 0, at most 60 × 60 cells."""
        adev = self.adev if self.n_axes is None else self.adev[0]
        i, j = thin(self.tau.size, 60), thin(self.t.size, 60)
        with np.errstate(divide="ignore", invalid="ignore"):
            z = np.log10(adev[np.ix_(i, j)])
        mesh = ax.pcolormesh(self.t[j], self.tau[i], z, shading="nearest", cmap="viridis", rasterized=True)
        ax.set_yscale("log")
        ax.set_xlabel("t (s)")
        ax.set_ylabel("τ (s)")
        ax.figure.colorbar(mesh, ax=ax, label="log₁₀ ADEV")

    def to_xarray(self, unit=None, axis_names=None):
        """The result as an ``xarray.Dataset`` with labelled dims ``(axis, tau, t)`` (``(tau, t)`` for
        1-D input) and units in the attrs. Needs ``pip install 'allanite[xarray]'``.

        ``avar`` is the result's own array (no copy); ``adev`` is computed (one more array of the
        same size). With intervals: ``ci_low``, ``ci_high`` (variance, shape of ``avar``), ``edf`` and
        ``alpha`` per (axis, τ). Coords ``tau`` (s), ``t`` (window centres, s), ``m``, ``n``,
        ``axis``; attrs as :meth:`AllanResult.to_xarray` plus ``window``, ``hop``, ``method``.
        """
        xr = _xarray()
        axes, coords, label, attrs = self._xr_common(unit, axis_names)
        coords["t"] = ("t", self.t, {"units": "s", "long_name": "window centre from the start of the record"})
        attrs.update(window=self.window, hop=self.hop, method=self.method)
        data = self._xr_data(axes, label)
        if self.kf is not None:
            data["kf"] = (
                axes + ("t",),
                np.asarray(self.kf, dtype=float),
                {"units": "1", "long_name": "TheoBR bias ratio of each window"},
            )
        return xr.Dataset(data, coords=coords, attrs=attrs)

    def plot(self, ax=None, axis: int = 0, **kwargs):
        """Heat map of ADEV over (t, τ), log colour. Returns the matplotlib Axes."""
        return plot_davar(self, ax=ax, axis=axis, **kwargs)
