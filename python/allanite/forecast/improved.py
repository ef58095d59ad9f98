"""Paper 004's improved GM(1,1): wavelet detection and smoothing, residual correction, metabolic re-fit."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import InputError, ParameterError
from ._forecaster import Forecaster
from ._series import as_series, check_horizon, check_sd
from .grades import Accuracy, accuracy
from .grey import GM11

__all__ = ["Detection", "ImprovedGM11"]


@dataclass(frozen=True)
class Detection:
    """What the wavelet detector found (0-based indices into the series).

    Attributes
    ----------
    bad : ndarray of int
        Bad values (isolated spikes), replaced by interpolation between their nearest good neighbours.
    breaks : ndarray of int
        Level breaks: a break at j lies between values j and j + 1; everything up to j was moved by
        ``steps[i]`` so the series continues at its newest level.
    steps : ndarray of float
        The step height removed at each break.
    sigma : float
        Robust noise scale of the Haar details (MAD/0.6745).
    threshold : float
        The detail magnitude above which a difference counts as a jump (``detect_threshold·sigma``).
    """

    bad: np.ndarray
    breaks: np.ndarray
    steps: np.ndarray
    sigma: float
    threshold: float


def _detect(x: np.ndarray, k_sigma: float) -> tuple[np.ndarray, Detection]:
    """Haar stationary-wavelet detection of spikes and steps; returns the repaired series and the findings.

    d[j] = (x[j] − x[j+1])/√2 is the level-1 SWT Haar detail. A jump is |d[j]| > k_sigma·σ with
    σ = median|d|/0.6745. A spike at j is two adjacent jumps of opposite sign (x[j] sticks out from both
    neighbours); a jump at either end of the series is taken as a bad end value (one value cannot
    establish a new level); any other unpaired jump is a break.
    """
    import pywt  # PyWavelets only where a wavelet is used (~0.08 s off ``import allanite``)

    n = x.size
    xp = x if n % 2 == 0 else np.append(x, x[-1])
    ((_, d),) = pywt.swt(xp, "haar", level=1, trim_approx=False, norm=False)
    d = d[: n - 1]  # the last SWT detail wraps around to x[0]; drop it
    sigma = float(np.median(np.abs(d)) / 0.6745)
    thr = k_sigma * sigma
    jump = np.abs(d) > thr if sigma > 0 else np.abs(d) > 0
    used = np.zeros(n - 1, dtype=bool)
    bad: list[int] = []
    for j in range(1, n - 1):  # spike at value j <=> jumps at d[j-1] and d[j] of opposite sign
        if jump[j - 1] and jump[j] and not used[j - 1] and np.sign(d[j - 1]) != np.sign(d[j]):
            bad.append(j)
            used[j - 1] = used[j] = True
    breaks: list[int] = []
    for jj in np.flatnonzero(jump & ~used):
        j = int(jj)
        if j == 0:
            bad.append(0)
        elif j == n - 2:
            bad.append(n - 1)
        else:
            breaks.append(j)
    bad_arr = np.array(sorted(set(bad)), dtype=int)
    y = x.copy()
    if bad_arr.size:
        good = np.setdiff1d(np.arange(n), bad_arr)
        # linear interpolation in the index between the nearest good neighbours; at the ends np.interp
        # holds the nearest good value
        y[bad_arr] = np.interp(bad_arr, good, x[good])
    steps: list[float] = []
    for j in sorted(breaks, reverse=True):  # newest break first, so older ones see the aligned series
        after = y[j + 1 : j + 4]
        before = y[max(0, j - 2) : j + 1]
        step = float(np.median(after) - np.median(before))
        y[: j + 1] += step
        steps.append(step)
    brk = np.array(sorted(breaks, reverse=True), dtype=int)
    return y, Detection(bad_arr, brk, np.array(steps), sigma, thr)


def _smooth(x: np.ndarray, wavelet: str, level: int | None, mode: str) -> tuple[np.ndarray, int]:
    """Wavelet shrinkage: soft universal threshold σ√(2 ln n) on every detail level, σ from the finest one."""
    import pywt  # PyWavelets only where a wavelet is used (~0.08 s off ``import allanite``)

    n = x.size
    w = pywt.Wavelet(wavelet)
    lmax = pywt.dwt_max_level(n, w.dec_len)
    lev = lmax if level is None else min(int(level), lmax)
    if lev < 1:
        return x.copy(), 0
    coeffs = pywt.wavedec(x, w, mode=mode, level=lev)
    sigma = float(np.median(np.abs(coeffs[-1])) / 0.6745)
    thr = sigma * math.sqrt(2.0 * math.log(n))
    coeffs = [coeffs[0]] + [pywt.threshold(c, thr, mode="soft") for c in coeffs[1:]]
    return pywt.waverec(coeffs, w, mode=mode)[:n], lev


class _ResidualCorrected:
    """A GM(1,1) with the residual GM(1,1) correction of paper 004 eqs. 16–18 (1-AGO domain)."""

    def __init__(self, base: GM11, residual_from: int | str, on: str, min_len: int = 6, max_a: float = 0.3) -> None:
        self.base = base
        y = base._y  # shifted series the base model fitted
        n = y.size
        k = np.arange(n)
        if on == "ago":
            q = np.cumsum(y) - base._x1hat(k)  # eq. 16: residual of the 1-AGO series
        else:
            q = y - base._x0hat(k)
        self.q = q
        self.on = on
        self.applied = False
        self.reason = ""
        # The last 1-AGO residual is Σx⁰ − x̂¹(n), which the least squares leaves close to 0, so its sign is
        # often noise: a same-sign run may end at the last or the second-to-last index.
        if residual_from == "auto":
            i: int | None = None
            end: int | None = None
            for stop in (n, n - 1):
                s = np.sign(q[stop - 1])
                j = stop - 1
                while s != 0 and j > 0 and np.sign(q[j - 1]) == s:
                    j -= 1
                if s != 0 and stop - j >= min_len and (i is None or end is None or stop - j > end - i):
                    i, end = j, stop
            if i is None:
                self.reason = (
                    f"no same-sign run of {min_len} or more residuals ending at the last or second-to-last value"
                )
                self.i = None
                return
        else:
            if (
                isinstance(residual_from, bool)
                or not isinstance(residual_from, (int, np.integer))
                or not (1 <= residual_from <= n - min_len)
            ):
                raise ParameterError(
                    f"residual_from = {residual_from!r} must be 'auto' or an index in 1..{n - min_len} "
                    f"({min_len} residuals needed, residual_min_len)"
                )
            i = int(residual_from)
            end = None
            for stop in (n, n - 1):
                tail = q[i:stop]
                if tail.size >= min_len and (np.all(tail > 0) or np.all(tail < 0)):
                    end = stop
                    break
            if end is None:
                raise ParameterError(
                    f"residual_from = {i}: the residuals from there change sign (or are 0); the residual GM(1,1) "
                    "needs a same-sign run to the last or second-to-last value — use 'auto' or a later index"
                )
        assert i is not None and end is not None
        self.i, self.end = i, end
        self.sign = float(np.sign(q[end - 1]))
        self.model = GM11(self.sign * q[i:end], shift="auto", allow_nonpositive=False)
        if abs(self.model.a) > max_a:
            # e^{−a'k} over a 30-step horizon: |a'| = 0.2 already multiplies the correction by 400
            self.reason = (
                f"residual model |a'| = {abs(self.model.a):.3g} exceeds residual_max_a = {max_a:g} "
                f"(run {i}..{end - 1}); its extrapolation would explode"
            )
            return
        self.applied = True

    @classmethod
    def switched_off(cls, base: GM11) -> _ResidualCorrected:
        """The base model unchanged (``residual=False``)."""
        rc = cls.__new__(cls)
        rc.base, rc.applied, rc.reason, rc.on, rc.i = base, False, "switched off", "ago", None
        return rc

    def _correction_series(self, k: np.ndarray) -> np.ndarray:
        """sign·q̂ at 0-based indices k (0 before the start index i)."""
        out = np.zeros(k.size)
        if not self.applied:
            return out
        m = k >= self.i
        kk = k[m] - self.i
        out[m] = self.sign * (self.model._x0hat(kk) - self.model.shift_applied)
        return out

    def x0hat(self, k: np.ndarray) -> np.ndarray:
        """Corrected restored values of the shifted series at 0-based indices k."""
        k = np.asarray(k, dtype=int)
        base = self.base._x0hat(k)
        if not self.applied:
            return base
        if self.on == "series":
            return base + self._correction_series(k)
        # x̂¹_c = x̂¹ + sign·q̂ for k ≥ i; restore by differencing, as GM11 does
        corr = self._correction_series(k) - self._correction_series(k - 1)
        return base + corr


def _check_options(
    detect_threshold: float, residual_on: str, wavelet: str, wavelet_mode: str, smooth_level: int | None
) -> None:
    """The detection, smoothing and residual-domain options of :class:`ImprovedGM11`, or a ParameterError."""
    import pywt  # PyWavelets only where a wavelet is used (~0.08 s off ``import allanite``)

    if not (np.isfinite(detect_threshold) and detect_threshold > 0):
        raise ParameterError(f"detect_threshold = {detect_threshold!r} must be a positive number")
    if residual_on not in ("ago", "series"):
        raise ParameterError(f"residual_on = {residual_on!r} is not allowed; use 'ago' or 'series'")
    if wavelet not in pywt.wavelist(kind="discrete"):
        raise ParameterError(f"wavelet = {wavelet!r} is not a PyWavelets discrete wavelet")
    if wavelet_mode not in pywt.Modes.modes:
        raise ParameterError(f"wavelet_mode = {wavelet_mode!r} is not one of {pywt.Modes.modes}")
    if smooth_level is not None and (isinstance(smooth_level, bool) or int(smooth_level) < 1):
        raise ParameterError(f"smooth_level = {smooth_level!r} must be a positive integer or None")


def _check_residual_guards(residual_min_len: int, residual_max_a: float) -> None:
    """The residual model's guards of :class:`ImprovedGM11` (see its step 4), or a ParameterError."""
    if (
        isinstance(residual_min_len, bool)
        or not isinstance(residual_min_len, (int, np.integer))
        or residual_min_len < 4
    ):
        raise ParameterError(f"residual_min_len = {residual_min_len!r} must be an integer >= 4")
    if not (np.isfinite(residual_max_a) and residual_max_a > 0):
        raise ParameterError(f"residual_max_a = {residual_max_a!r} must be a positive number")


class ImprovedGM11(Forecaster):
    """Paper 004's improved GM(1,1), every step switchable so its effect can be measured.

    Steps, in order:

    1. ``detect`` — Haar stationary-wavelet detection of bad values (spikes) and level breaks (see
       :class:`Detection`). Rule: a bad value is replaced by linear interpolation between its nearest good
       neighbours; at a break the older part is moved by the step height (median of up to 3 values after
       minus median of up to 3 before), so the series continues at its newest level.
    2. ``smooth`` — wavelet shrinkage of the (repaired) series: ``wavelet`` (default ``sym4``) decomposition
       to ``smooth_level`` (default the deepest PyWavelets allows), soft universal threshold σ√(2 ln n),
       σ = MAD/0.6745 of the finest details.
    3. GM(1,1) on the processed series (the level-ratio shift as in :class:`GM11`).
    4. ``residual`` — residual GM(1,1) correction from index i (eqs. 16–18): q(k) = x¹(k) − x̂¹(k) for
       k ≥ i on the 1-AGO series (``residual_on="ago"``, eq. 16), modelled by a GM(1,1) of sign·q;
       x̂¹ gets sign·q̂ added for k ≥ i and is restored by differencing, as GM11 restores. (Eq. 18 as
       printed adds the residual model's value to x̂⁰ directly; that matches ``residual_on="series"``,
       where q = x⁰ − x̂⁰.) ``residual_from="auto"`` takes the longest run of same-sign residuals that ends at
       the last or the second-to-last value (the last 1-AGO residual, Σx⁰ − x̂¹(n), is held near 0 by the
       least squares, so its sign is often noise; a run ending before it leaves it out of the residual
       model); with no such run of ``residual_min_len`` (default 6; GM(1,1)'s minimum is 4) or more, or
       when the residual model's |a'| exceeds ``residual_max_a`` (default 0.3, the usual bound of
       GM(1,1) for more than short-term forecasts: beyond it e^{−a'k} explodes over the horizon — on a
       4-point run an a' = −0.21 turned a 30-step K forecast into −49 for data near 0.5), the
       correction is skipped and said so in ``notes``.
    5. ``metabolic`` — forecasts by the metabolic (rolling) re-fit: predict one step, append the prediction,
       drop the oldest value, re-fit steps 3–4, repeat (paper 004 §3.2 step 3: the new value is the
       model's own (n+1)-th value). Without it, ``predict(h)`` extrapolates the one model.

    Parameters
    ----------
    series : array_like
        At least 4 positive finite values (8 for ``smooth``).
    detect, smooth, metabolic, residual : bool
        Switch each step.
    detect_threshold : float
        Jump threshold in robust SDs of the Haar details (default 4).
    wavelet, smooth_level, wavelet_mode : str, int or None, str
        Smoothing wavelet, depth and PyWavelets signal-extension mode.
    residual_from : "auto" or int
        First 0-based index of the residual model.
    residual_on : {"ago", "series"}
        Residual of the 1-AGO series (eq. 16) or of the series itself.
    residual_min_len, residual_max_a : int, float
        Guards of the residual model (see step 4).
    shift, sd, include_first
        As in :class:`GM11`.

    Attributes
    ----------
    series : ndarray
        The raw input.
    processed : ndarray
        The series after detection and smoothing (what the model fitted).
    detection : Detection or None
    model : GM11
        The GM(1,1) of the processed series (before the residual correction).
    fitted : ndarray
        In-sample values (with the residual correction when applied).
    accuracy, C, P, c_grade, grade
        In-sample, against the **raw** series; ``accuracy_processed`` against ``processed``.
    notes : list of str
    """

    name = "improved GM(1,1)"

    def __init__(
        self,
        series: Any,
        *,
        detect: bool = True,
        smooth: bool = True,
        metabolic: bool = True,
        residual: bool = True,
        detect_threshold: float = 4.0,
        wavelet: str = "sym4",
        smooth_level: int | None = None,
        wavelet_mode: str = "symmetric",
        residual_from: int | str = "auto",
        residual_on: str = "ago",
        residual_min_len: int = 6,
        residual_max_a: float = 0.3,
        shift: str | float | None = "auto",
        sd: str = "population",
        include_first: bool = True,
    ) -> None:
        check_sd(sd)
        x = as_series(series)
        nonpos = np.flatnonzero(x <= 0)
        if nonpos.size:
            i = int(nonpos[0])
            raise InputError(
                f"series[{i}] = {float(x[i])!r} is not positive ({nonpos.size} value(s) <= 0); GM(1,1) needs positive "
                "values. A noise coefficient at 0 usually means the fit did not resolve that term: do not "
                "forecast it (or use GM11(..., allow_nonpositive=True) for genuinely signed data)."
            )
        _check_options(detect_threshold, residual_on, wavelet, wavelet_mode, smooth_level)
        self.series = x
        self.sd, self.include_first = sd, bool(include_first)
        self.steps = {
            "detect": bool(detect),
            "smooth": bool(smooth),
            "metabolic": bool(metabolic),
            "residual": bool(residual),
        }
        self.notes: list[str] = []
        _check_residual_guards(residual_min_len, residual_max_a)
        self._opts = {
            "residual": bool(residual),
            "residual_from": residual_from,
            "residual_on": residual_on,
            "residual_min_len": int(residual_min_len),
            "residual_max_a": float(residual_max_a),
            "shift": shift,
        }
        self.detection: Detection | None = None
        self.processed = self._preprocess(
            x, detect_threshold if detect else None, smooth, wavelet, smooth_level, wavelet_mode
        )
        self.model, self._rc = self._fit(self.processed)
        self.notes.extend(self.model.notes)
        if residual and not self._rc.applied:
            self.notes.append(f"residual correction skipped: {self._rc.reason}")
        self.fitted = self._rc.x0hat(np.arange(x.size)) - self.model.shift_applied

    def _preprocess(
        self, x: np.ndarray, detect_threshold: float | None, smooth: bool, wavelet: str, level: int | None, mode: str
    ) -> np.ndarray:
        """Steps 1 and 2: repair spikes and breaks (unless ``detect_threshold`` is None), then smooth; the
        processed series, with what was done in ``notes`` and the findings in ``detection``."""
        y = x
        if detect_threshold is not None:
            y, self.detection = _detect(y, float(detect_threshold))
            if self.detection.bad.size:
                self.notes.append(f"bad values replaced at {self.detection.bad.tolist()}")
            if self.detection.breaks.size:
                self.notes.append(
                    f"breaks after {self.detection.breaks.tolist()} "
                    f"(steps {np.round(self.detection.steps, 6).tolist()}); "
                    "older values aligned to the newest level"
                )
        if smooth:
            y, lev = _smooth(y, wavelet, level, mode)
            if lev == 0:
                self.notes.append(f"series too short for {wavelet} smoothing; not smoothed")
        return y

    def _fit(self, y: np.ndarray) -> tuple[GM11, _ResidualCorrected]:
        m = GM11(y, shift=self._opts["shift"], sd=self.sd, include_first=self.include_first, allow_nonpositive=True)
        if self._opts["residual"]:
            o: dict[str, Any] = self._opts
            rc = _ResidualCorrected(m, o["residual_from"], o["residual_on"], o["residual_min_len"], o["residual_max_a"])
        else:
            rc = _ResidualCorrected.switched_off(m)
        return m, rc

    @property
    def accuracy_processed(self) -> Accuracy:
        """In-sample accuracy against the processed (repaired, smoothed) series."""
        return accuracy(self.processed, self.fitted, sd=self.sd, include_first=self.include_first)

    def predict(self, h: int) -> np.ndarray:
        """The next ``h`` values (metabolic re-fit when switched on)."""
        h = check_horizon(h)
        n = self.series.size
        with np.errstate(over="ignore", invalid="ignore"):
            if not self.steps["metabolic"]:
                out = self._rc.x0hat(np.arange(n, n + h)) - self.model.shift_applied
            else:
                window = self.processed.copy()
                m, rc = self.model, self._rc
                out = np.empty(h)
                for j in range(h):
                    out[j] = float(rc.x0hat(np.array([n]))[0]) - m.shift_applied
                    if not np.isfinite(out[j]):
                        out[j + 1 :] = np.nan
                        break
                    window = np.append(window[1:], out[j])
                    if j + 1 < h:
                        m, rc = self._fit(window)
        if not np.all(np.isfinite(out)):
            j = int(np.flatnonzero(~np.isfinite(out))[0])
            raise ParameterError(f"h = {h}: the forecast overflows at step {j + 1}; use a shorter horizon")
        return out
