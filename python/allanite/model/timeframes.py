"""Time-frame DAVAR (paper 004): the record cut into consecutive rectangular frames, the five-term noise
model fitted in each, and the per-frame coefficient series forecast.

``frames(x, fs, frame=F)`` is ``davar(x, fs, window=F·fs, hop=F·fs)`` followed by :func:`allanite.fit`:
one Allan variance per non-overlapping frame, one fit with intervals per frame. The coefficient series
of the frames are what paper 004 forecasts with GM(1,1) (:mod:`allanite.forecast`);
:meth:`TimeFrames.forecast` runs that comparison — every method, honest and paper-rule C/P — on the terms
the frame fits resolve. Definitions: ``docs/FORMULAS.md §11``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._validate import check_positive
from ..analysis import davar
from ..errors import ParameterError
from ..forecast import compare
from ..results import DynamicAllanResult
from ..units import report_unit
from .fitting import CoefficientSeries, fit, z_quantile
from .terms import TERMS

__all__ = ["frames", "frame_for_count", "TimeFrames", "MIN_FRAME_SAMPLES"]

#: A frame shorter than this holds too few octaves of τ for a five-term fit.
MIN_FRAME_SAMPLES = 64


@dataclass(frozen=True, repr=False, eq=False)
class TimeFrames:
    """The noise coefficients of consecutive rectangular frames of one axis (paper 004 §2, Fig. 3).

    Attributes
    ----------
    t : ndarray
        Frame centres, s from the first sample.
    frame_s : float
        Frame length, s (``frame_samples / fs``).
    frame_samples : int
        Frame length in samples (``round(frame·fs)``).
    dropped_samples : int
        Samples after the last whole frame, left out.
    series : CoefficientSeries
        The per-frame fit: ``values``, ``ci_low``, ``ci_high`` (base form), ``ieee`` (IEEE-952 units when
        the unit is known), ``chi2_dof``.
    dynamic : DynamicAllanResult
        The Allan variance of every frame (all axes).
    axis : int
        Which axis of ``dynamic`` this is (0 for 1-D input).
    forecastable : dict
        Term → True when its fit is positive in every frame. A term a frame's fit leaves at zero (often Q
        or R) is not resolved there; it is not forecastable and ``not_forecastable`` says why.
    """

    t: np.ndarray
    frame_s: float
    frame_samples: int
    dropped_samples: int
    series: CoefficientSeries
    dynamic: DynamicAllanResult
    axis: int = 0
    forecastable: dict = field(default_factory=dict)
    not_forecastable: dict = field(default_factory=dict)

    @property
    def terms(self) -> tuple:
        """The terms fitted in every frame."""
        return self.series.terms

    @property
    def unit(self) -> str | None:
        """Unit of the samples (None when unknown)."""
        return self.series.unit

    @property
    def n_frames(self) -> int:
        """Number of frames."""
        return int(self.t.size)

    def values(self, ieee: bool = True) -> dict:
        """Term → per-frame value: IEEE-952 units when known and ``ieee``, else base form."""
        s = self.series
        if ieee and s.ieee is not None:
            return dict(s.ieee)
        return dict(s.values)

    def intervals(self, ieee: bool = True) -> tuple[dict, dict]:
        """(low, high) term → per-frame interval bounds, in the units of :meth:`values`."""
        s = self.series
        if ieee and s.ieee is not None:
            # the IEEE value is a fixed multiple of the base value: scale the bounds by the same factor
            lo, hi = {}, {}
            for t in s.terms:
                f = float(report_unit(t, 1.0, s.unit).value)  # an accelerometer's: its report units
                lo[t], hi[t] = s.ci_low[t] * f, s.ci_high[t] * f
            return lo, hi
        return dict(s.ci_low), dict(s.ci_high)

    def units(self, ieee: bool = True) -> dict:
        """Term → unit label of :meth:`values` (None when unknown)."""
        s = self.series
        if ieee and s.ieee_units is not None:
            return dict(s.ieee_units)
        return {t: None for t in s.terms}

    def standard_errors(self, ieee: bool = True) -> dict:
        """Term → per-frame standard error of the fitted value: half the interval width over its z."""
        lo, hi = self.intervals(ieee)
        z = z_quantile(self.series.confidence)
        return {t: (hi[t] - lo[t]) / (2.0 * z) for t in self.terms}

    def forecast(
        self, build: int = 60, check: int = 30, *, methods=None, sd: str = "population", ieee: bool = True
    ) -> dict:
        """Paper 004's experiment on these frames: build on the first ``build``, check on the next ``check``.

        Every method of :func:`allanite.forecast.compare` (GM(1,1), improved GM(1,1), persistence, build
        mean, linear trend, Holt) on every forecastable term; the others are in ``skipped`` with the
        reason. The fit's per-frame standard errors are passed as ``noise``, so each cell has
        ``rmse_over_se``: the forecast error against the frame-to-frame estimation noise.

        Raises
        ------
        ParameterError
            When ``build + check`` exceeds the number of frames (naming both), or the split is too small.
        """
        for nm, v in (("build", build), ("check", check)):
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
                raise ParameterError(f"{nm} = {v!r} must be an integer number of frames")
        if build + check > self.n_frames:
            raise ParameterError(
                f"build + check = {build} + {check} = {build + check} frames, but the record gives {self.n_frames} "
                f"frames of {self.frame_s:g} s: use shorter frames or a smaller split"
            )
        vals = self.values(ieee)
        out = compare(vals, build, check, methods=methods, sd=sd, noise=self.standard_errors(ieee))
        out["units"] = self.units(ieee)
        out["frame_s"] = self.frame_s
        return out

    def __repr__(self) -> str:
        parts = ", ".join(
            f"{t} median {np.median(self.series.values[t]):.3g}" + ("" if self.forecastable[t] else " (not resolved)")
            for t in self.terms
        )
        return f"TimeFrames({self.n_frames} frames of {self.frame_s:g} s: {parts})"

    def plot(self, axes=None, ieee: bool = True, terms=None):
        """Paper 004 Fig. 3 style: each coefficient against the frame number, with its interval band.

        Parameters
        ----------
        axes : sequence of matplotlib Axes, optional
            One per term drawn; new ones in a new figure when omitted.
        ieee : bool
            IEEE-952 units when the unit is known.
        terms : sequence of str, optional
            Terms to draw (default: all).

        Returns
        -------
        list of Axes
        """
        terms = list(terms or self.terms)
        if axes is None:
            import matplotlib.pyplot as plt  # matplotlib only when a figure is drawn

            _, axs = plt.subplots(len(terms), 1, sharex=True, squeeze=False, figsize=(7.0, 1.2 + 1.6 * len(terms)))
            axes = list(axs[:, 0])
        vals, (lo, hi), units = self.values(ieee), self.intervals(ieee), self.units(ieee)
        k = np.arange(1, self.n_frames + 1)
        for ax, t in zip(axes, terms):
            ax.fill_between(k, lo[t], hi[t], color="C0", alpha=0.25, lw=0, label=f"{self.series.confidence:.1%}")
            ax.plot(k, vals[t], "o-", color="C0", ms=2.5, lw=0.8, label=t)
            ax.set_ylabel(f"{t}" + (f" ({units[t]})" if units[t] else ""))
            if not self.forecastable[t]:
                ax.text(0.99, 0.9, "not resolved in every frame", transform=ax.transAxes, ha="right", va="top")
        axes[-1].set_xlabel(f"frame ({self.frame_s:g} s each)")
        return list(axes)

    def plot_forecast(self, table: dict, axes=None, ieee: bool = True, methods=("GM(1,1)", "improved GM(1,1)")):
        """Paper 004 Fig. 3–4 style: each forecastable term's frames, the improved model's smoothed series
        (Fig. 4), and each method's in-sample fit and forecast; a line marks the build/check split.

        ``table`` is the result of :meth:`forecast` (with the same ``ieee``).
        """
        terms = list(table["terms"])
        if not terms:
            raise ParameterError("no forecastable term in the table: nothing to draw")
        if axes is None:
            import matplotlib.pyplot as plt  # matplotlib only when a figure is drawn

            _, axs = plt.subplots(len(terms), 1, sharex=True, squeeze=False, figsize=(7.0, 1.2 + 1.8 * len(terms)))
            axes = list(axs[:, 0])
        vals, units = self.values(ieee), self.units(ieee)
        b, c = table["build"], table["check"]
        k = np.arange(1, b + c + 1)
        for ax, t in zip(axes, terms):
            ax.plot(k, vals[t][: b + c], "o", color="0.35", ms=2.5, label="per frame")
            imp = table["cells"].get("improved GM(1,1)", {}).get(t, {})
            if "processed" in imp:
                ax.plot(k[:b], imp["processed"], "-", color="C2", lw=1.0, label="wavelet-smoothed (build)")
            for j, m in enumerate(methods):
                cell = table["cells"].get(m, {}).get(t)
                if not cell or "error" in cell:
                    continue
                col = f"C{(3 + j) % 10}"
                ax.plot(k[:b], cell["fitted"], "--", color=col, lw=0.9)
                ax.plot(k[b:], cell["forecast"], "-", color=col, lw=1.6, label=f"{m}: C = {cell['C']:.2f}")
            ax.axvline(b + 0.5, color="k", lw=0.6, ls=":")
            ax.set_ylabel(f"{t}" + (f" ({units[t]})" if units.get(t) else ""))
            ax.legend(fontsize="x-small", loc="best", ncol=2)
        axes[-1].set_xlabel(f"frame ({self.frame_s:g} s each); build 1–{b}, check {b + 1}–{b + c}")
        return list(axes)


def frames(
    x,
    fs,
    frame: float = 20.0,
    *,
    unit=None,
    input: str = "rate",
    terms=TERMS,
    confidence: float = 0.683,
    taus="exp",
    tau_range=None,
    thin: bool = True,
    workers=None,
    progress=None,
):
    """Time-frame DAVAR: the noise model fitted in consecutive rectangular frames (paper 004).

    Parameters
    ----------
    x : array_like, shape (samples,) or (samples, axes)
        Samples, as for :func:`allanite.avar`.
    fs : float
        Sampling rate, Hz.
    frame : float
        Frame length, s (default 20, paper 004's); ``round(frame·fs)`` samples, at least
        ``MIN_FRAME_SAMPLES``. Samples after the last whole frame are left out (``dropped_samples``).
    unit : str, optional
        Unit of the rate samples (e.g. "deg/s"): the coefficients get IEEE-952 values (an accelerometer's,
        e.g. "m/s^2" or "g": its report units, as :func:`allanite.fit`).
    input : {"rate", "increment", "angle"}
    terms, confidence, thin, tau_range
        As for :func:`allanite.fit` (``tau_range="auto"`` chooses the cut on the frames' median curve).
    taus : str or array_like
        τ grid of each frame, as for :func:`allanite.davar` (default paper 000's exponential grid up to
        frame/9).
    workers : int, optional
        Threads of the DAVAR.
    progress : bool, optional
        A ``tqdm.auto`` bar over the frames' fits when there are very many, as for :func:`allanite.fit`.

    Returns
    -------
    TimeFrames or list of TimeFrames
        One per axis (a list for 2-D input, as :func:`allanite.fit`).

    Examples
    --------
    >>> import allanite
    >>> y = allanite.simulate(200_000, 100.0, N=0.01, B=1e-3, seed=4)
    >>> f = allanite.frames(y, 100.0, frame=20.0, terms=("N", "B"), unit="deg/s")
    >>> f.n_frames, f.t[:2]
    (100, array([10., 30.]))
    >>> round(float(np.median(f.series.values["N"])), 4)
    0.01
    """
    fs_v = check_positive(fs, "fs")
    fr = check_positive(frame, "frame")
    n_frame = int(round(fr * fs_v))
    if n_frame < MIN_FRAME_SAMPLES:
        raise ParameterError(
            f"frame = {frame!r} s is {n_frame} samples at {fs_v:g} Hz; at least {MIN_FRAME_SAMPLES} are needed "
            "for a noise-model fit"
        )
    arr = np.asarray(x)
    n = arr.shape[0] if arr.ndim >= 1 else 0
    if n_frame > n:
        raise ParameterError(
            f"frame = {frame!r} s ({n_frame} samples) is longer than the record ({n} samples, {n / fs_v:g} s)"
        )
    dyn = davar(x, fs_v, window=n_frame, hop=n_frame, taus=taus, input=input, workers=workers)
    fitted = fit(dyn, terms=terms, unit=unit, confidence=confidence, thin=thin, tau_range=tau_range, progress=progress)
    series = fitted if isinstance(fitted, list) else [fitted]
    n_frames = int(dyn.t.size)
    dropped = int(dyn.n_samples - n_frames * n_frame)
    out = []
    for k, s in enumerate(series):
        ok, why = {}, {}
        for t in s.terms:
            zero = int(np.count_nonzero(s.values[t] <= 0))
            ok[t] = zero == 0
            if zero:
                why[t] = f"the fit leaves {t} at 0 in {zero} of {n_frames} frames (not resolved there)"
        out.append(
            TimeFrames(
                t=np.asarray(s.t, dtype=np.float64),
                frame_s=n_frame / fs_v,
                frame_samples=n_frame,
                dropped_samples=dropped,
                series=s,
                dynamic=dyn,
                axis=k,
                forecastable=ok,
                not_forecastable=why,
            )
        )
    return out if isinstance(fitted, list) else out[0]


def frame_for_count(n_samples: int, fs: float, count: int) -> float:
    """The frame length (s) that cuts ``n_samples`` at ``fs`` into ``count`` whole frames (paper 004: 90)."""
    if count < 1 or n_samples < count:
        raise ParameterError(f"count = {count!r} frames do not fit a record of {n_samples} samples")
    return math.floor(n_samples / count) / float(fs)
