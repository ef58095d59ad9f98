"""Forecasting a series of noise coefficients: grey GM(1,1), its improved form, and baselines.

Paper 004 (Li, Wang, Shen, Acta Optica Sinica 2020) fits the Allan noise terms frame by frame
(time-frame DAVAR) and forecasts each coefficient series with a grey GM(1,1) model: the first 60
frames build the model, the last 30 check it. This module gives

- :class:`GM11` — the traditional GM(1,1) (paper 004 eqs. 1–15);
- :class:`ImprovedGM11` — the paper's improvements, each one switchable: wavelet detection of breaks
  and bad values, wavelet smoothing, the metabolic (rolling) re-fit, the residual GM(1,1) correction
  (eqs. 16–18);
- baselines with the same interface: :class:`Persistence`, :class:`BuildMean`, :class:`LinearTrend`,
  :class:`Holt`;
- :func:`accuracy` (the posterior-variance ratio C, the small-error probability P and their grades) and
  :func:`score`, which judges a method on a build/check split against the **raw** held-out values,
  and also by paper 004's own rule, labelled.

Every model takes the series first and its options keyword-only, and exposes ``series``, ``fitted``
(the in-sample values x̂⁰), ``predict(h)``, ``accuracy`` and its fields ``C``, ``P``, ``c_grade``,
``grade``. Indices in this module are 0-based: ``series[0]`` is the paper's x⁰(1). The formulas and
conventions: ``docs/FORMULAS.md §11``.

Conventions (the literature is not uniform; each is a parameter):

``sd``
    ``"population"`` (divide by n, paper 004 eqs. 13–14) or ``"sample"`` (divide by n − 1).
    When S1 and S2 run over the same number of values, C does not depend on it; P can (its
    threshold is 0.6745·S1).
``include_first``
    Whether k = 1 (``series[0]``) counts in C and P. GM(1,1) reproduces x⁰(1) exactly, so counting
    it adds a zero residual. The textbook oracles (Liu & Lin's 2.874, 3.278, … example and the
    road-noise example) count it; paper 004 §3.2 step 3 leaves it out.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
import pywt

from ._display import RichDisplay, Summary, Table, thin
from .errors import AllaniteError, InputError, ParameterError

__all__ = [
    "GM11",
    "Accuracy",
    "BuildMean",
    "Detection",
    "Holt",
    "ImprovedGM11",
    "LevelRatio",
    "LinearTrend",
    "Persistence",
    "Score",
    "accuracy",
    "c_grade",
    "compare",
    "default_methods",
    "joint_grade",
    "level_ratio_test",
    "score",
    "split",
]

#: Paper 004 Table 2 as printed: grade 1 C < 0.35, grade 2 C < 0.5, grade 3 C < 0.65, grade 4 otherwise.
C_GRADE_BOUNDS = (0.35, 0.5, 0.65)

#: The common joint C/P labels, best first: (label, P must exceed, C must stay below).
JOINT_GRADES = (("good", 0.95, 0.35), ("qualified", 0.80, 0.50), ("barely", 0.70, 0.65))

_SD_CHOICES = ("population", "sample")


# --------------------------------------------------------------------------------------------------
# validation


def _as_series(series: Any, *, name: str = "series", min_len: int = 4) -> np.ndarray:
    try:
        x = np.asarray(series, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must be a 1-D sequence of numbers ({exc})") from None
    if x.ndim != 1:
        raise InputError(f"{name} must be 1-D, got shape {x.shape}")
    if x.size < min_len:
        raise InputError(f"{name} has {x.size} values; at least {min_len} are needed")
    bad = np.flatnonzero(~np.isfinite(x))
    if bad.size:
        i = int(bad[0])
        raise InputError(
            f"{name}[{i}] = {x[i]} is not finite ({bad.size} non-finite value(s)); remove or fill them first"
        )
    return x


def _check_sd(sd: str) -> int:
    if sd not in _SD_CHOICES:
        raise ParameterError(f"sd = {sd!r} is not allowed; use 'population' (divide by n) or 'sample' (n - 1)")
    return 0 if sd == "population" else 1


def _check_horizon(h: Any) -> int:
    if isinstance(h, bool) or not isinstance(h, (int, np.integer)) or h < 0:
        raise ParameterError(f"h = {h!r} must be a non-negative integer (the number of steps ahead)")
    return int(h)


def _phi(t: np.ndarray | float) -> np.ndarray:
    """expm1(t)/t, equal to 1 at t = 0 and accurate near it (Taylor series below |t| < 1e-5)."""
    t = np.asarray(t, dtype=np.float64)
    out = np.empty_like(t)
    small = np.abs(t) < 1e-5
    ts = t[small]
    out[small] = 1.0 + ts / 2.0 + ts * ts / 6.0
    tl = t[~small]
    out[~small] = np.expm1(tl) / tl
    return out


# --------------------------------------------------------------------------------------------------
# accuracy


def c_grade(C: float) -> int:
    """Paper 004 Table 2 grade of a posterior-variance ratio: 1 (C < 0.35), 2 (< 0.5), 3 (< 0.65), else 4."""
    if not np.isfinite(C):
        return 4
    for g, bound in enumerate(C_GRADE_BOUNDS, start=1):
        if C < bound:
            return g
    return 4


def joint_grade(C: float, P: float) -> str:
    """The common joint label: "good" (P > 0.95, C < 0.35), "qualified" (P > 0.80, C < 0.50),
    "barely" (P > 0.70, C < 0.65), else "fail"."""
    for label, p_min, c_max in JOINT_GRADES:
        if P > p_min and C < c_max:
            return label
    return "fail"


@dataclass(frozen=True)
class Accuracy:
    """Posterior-variance check of predictions against actual values (paper 004 eqs. 10–15).

    Attributes
    ----------
    C : float
        S2/S1, the residual SD over the data SD. For constant data (S1 at round-off level) C = 0 and
        P = 1 when S2 is at round-off level too, else C = inf and P = 0.
    P : float
        Small-error probability: share of residuals with |e − ē| < 0.6745·S1.
    c_grade : int
        Paper 004 Table 2 grade of C (1 best … 4).
    grade : str
        Joint C/P label ("good", "qualified", "barely", "fail").
    S1, S2 : float
        SD of the actual values and of the residuals.
    n : int
        Number of values counted.
    sd : str
        "population" or "sample".
    include_first : bool
        Whether the first value counted.
    """

    C: float
    P: float
    c_grade: int
    grade: str
    S1: float
    S2: float
    n: int
    sd: str
    include_first: bool


def accuracy(actual: Any, predicted: Any, *, sd: str = "population", include_first: bool = True) -> Accuracy:
    """C, P and grades of ``predicted`` against ``actual``.

    Parameters
    ----------
    actual, predicted : array_like
        Same length, at least 2 values (3 if ``include_first`` is False).
    sd : {"population", "sample"}
        Divide the sums of squares by n or by n − 1.
    include_first : bool
        Count the first pair. Set False for paper 004's rule (x⁰(1) left out).

    Returns
    -------
    Accuracy
    """
    ddof = _check_sd(sd)
    x = _as_series(actual, name="actual", min_len=2)
    p = _as_series(predicted, name="predicted", min_len=2)
    if x.shape != p.shape:
        raise InputError(f"actual has {x.size} values but predicted has {p.size}")
    if not include_first:
        x, p = x[1:], p[1:]
    if x.size < 2 + ddof:
        raise InputError(f"{x.size} value(s) left to score; at least {2 + ddof} needed for sd={sd!r}")
    e = x - p
    S1 = float(np.std(x, ddof=ddof))
    S2 = float(np.std(e, ddof=ddof))
    # Constant data (S1 at round-off level): C is 0/0. Call a residual spread at round-off level a
    # perfect fit (C = 0, P = 1) and anything more an infinitely bad one (C = inf, P = 0).
    tol = 64 * np.finfo(np.float64).eps * max(float(np.max(np.abs(x))), float(np.max(np.abs(p))), 1e-300)
    if S1 > tol:
        C = S2 / S1
        P = float(np.mean(np.abs(e - e.mean()) < 0.6745 * S1))
    elif S2 <= tol:
        C, P = 0.0, 1.0
    else:
        C, P = math.inf, 0.0
    return Accuracy(C, P, c_grade(C), joint_grade(C, P), S1, S2, int(x.size), sd, bool(include_first))


def _accuracy_rows(acc: Accuracy, label: str) -> list:
    return [
        [f"C = S2/S1 ({label})", acc.C, f"grade {acc.c_grade}"],
        [f"P ({label})", acc.P, acc.grade],
        [f"S1, S2 ({label})", f"{acc.S1:.4g}, {acc.S2:.4g}", f"{acc.n} values, {acc.sd} SD"],
    ]


class _Forecaster(RichDisplay):
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
            tables=[Table(("in-sample check", "value", "grade"), _accuracy_rows(self.accuracy, "in-sample"))],
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


# --------------------------------------------------------------------------------------------------
# GM(1,1)


@dataclass(frozen=True)
class LevelRatio:
    """The GM(1,1) level-ratio test σ(k) = x(k−1)/x(k) ∈ (e^{−2/(n+1)}, e^{2/(n+1)}), k = 2 … n."""

    ratios: np.ndarray
    low: float
    high: float
    passed: bool
    failing: np.ndarray = field(repr=False)


def level_ratio_test(series: Any) -> LevelRatio:
    """Level-ratio test of a series (0-based: ``ratios[j] = series[j] / series[j + 1]``).

    A non-positive value fails the test (its ratios are reported as they come, possibly negative or inf).
    """
    x = _as_series(series, min_len=2)
    n = x.size
    low, high = math.exp(-2.0 / (n + 1)), math.exp(2.0 / (n + 1))
    with np.errstate(divide="ignore", invalid="ignore"):
        r = x[:-1] / x[1:]
    bad = ~((r > low) & (r < high)) | (x[:-1] <= 0) | (x[1:] <= 0)
    return LevelRatio(r, low, high, not bool(bad.any()), np.flatnonzero(bad))


def _shift_for_level_ratio(x: np.ndarray, margin: float = 0.9) -> float:
    """Smallest constant c with every (x(k−1)+c)/(x(k)+c) inside e^{±margin·2/(n+1)} and min(x)+c > 0.

    The bounds are shrunk by ``margin`` in the exponent so that the shifted series passes the test
    strictly (the original bounds are open).
    """
    n = x.size
    theta = margin * 2.0 / (n + 1)
    lo, hi = math.exp(-theta), math.exp(theta)
    prev, nxt = x[:-1], x[1:]
    # (prev + c) > lo (nxt + c)  <=>  c > (lo·nxt − prev)/(1 − lo);  (prev + c) < hi (nxt + c)  <=>
    # c > (prev − hi·nxt)/(hi − 1).  Both only once prev + c and nxt + c are positive.
    need = max(
        float(np.max((lo * nxt - prev) / (1.0 - lo))),
        float(np.max((prev - hi * nxt) / (hi - 1.0))),
    )
    positive = -float(np.min(x)) + 1e-12 * max(1.0, float(np.max(np.abs(x))))
    return max(0.0, need, positive)


class GM11(_Forecaster):
    """Grey GM(1,1) model of a short positive series (paper 004 eqs. 1–15).

    Least squares for (a, b) on x⁰(k) + a·z¹(k) = b, k = 2 … n, with the 1-AGO series
    x¹(k) = Σ_{i≤k} x⁰(i) and background values z¹(k) = ½(x¹(k) + x¹(k−1)). Time response
    x̂¹(k+1) = (x⁰(1) − b/a)·e^{−ak} + b/a, restored by differencing:
    x̂⁰(k+1) = (1 − e^a)(x⁰(1) − b/a)·e^{−ak}, evaluated as e^{−ak}·(b·φ(a) − expm1(a)·x⁰(1)) with
    φ(a) = expm1(a)/a (a Taylor series near 0), so a → 0 (a series with no trend) stays exact.

    Parameters
    ----------
    series : array_like
        At least 4 finite values, positive unless ``allow_nonpositive``.
    shift : "auto", float or None
        The constant-shift (translation) transform. ``"auto"``: when the level-ratio test fails, add the
        smallest constant c that puts every ratio inside the test's bounds (shrunk by 10 % in the
        exponent, so it passes strictly); the model is fitted on x + c and every output has c removed.
        A number: add exactly that constant. ``None``: never shift (the test is still reported).
    sd : {"population", "sample"}
        SD convention of C and P (see the module docstring).
    include_first : bool
        Whether k = 1 counts in the in-sample C and P.
    allow_nonpositive : bool
        GM(1,1) needs positive values; a noise coefficient at or below 0 usually means the fit did not
        resolve the term, which should not be forecast. Set True to accept it (``shift="auto"`` then
        shifts the series to positive values).

    Attributes
    ----------
    series : ndarray
        The input values.
    a, b : float
        Development coefficient and grey input (of the shifted series when ``shift_applied`` ≠ 0).
    shift_applied : float
        The constant c added before fitting (0 when none).
    level_ratio : LevelRatio
        The test on the input series; ``level_ratio_shifted`` on the series actually fitted.
    fitted : ndarray
        In-sample x̂⁰ (``fitted[0] == series[0]``).
    notes : list of str
        What was done to the series, in words.

    Examples
    --------
    >>> m = GM11([2.874, 3.278, 3.337, 3.390, 3.679])
    >>> print(f"a = {m.a:.6f}, b = {m.b:.6f}, C = {m.C:.4f}, P = {m.P}, {m.grade}")
    a = -0.037204, b = 3.065363, C = 0.2125, P = 1.0, good
    >>> print(m.predict(2).round(4))
    [3.7507 3.8928]
    """

    name = "GM(1,1)"

    def __init__(
        self,
        series: Any,
        *,
        shift: str | float | None = "auto",
        sd: str = "population",
        include_first: bool = True,
        allow_nonpositive: bool = False,
    ) -> None:
        _check_sd(sd)
        x = _as_series(series)
        self.series = x
        self.sd = sd
        self.include_first = bool(include_first)
        self.notes: list[str] = []
        nonpos = np.flatnonzero(x <= 0)
        if nonpos.size and not allow_nonpositive:
            i = int(nonpos[0])
            raise InputError(
                f"series[{i}] = {float(x[i])!r} is not positive ({nonpos.size} value(s) <= 0); GM(1,1) needs positive "
                "values. A noise coefficient at 0 usually means the fit did not resolve that term: do not "
                "forecast it. If the values are genuinely signed, pass allow_nonpositive=True (shift='auto' "
                "then adds a constant) or shift=<number>."
            )
        self.level_ratio = level_ratio_test(x)
        if shift is None:
            c = 0.0
            if nonpos.size:
                raise ParameterError(
                    f"shift=None but series[{int(nonpos[0])}] = {float(x[nonpos[0]])!r} is not positive; "
                    "use shift='auto' or a number"
                )
            if not self.level_ratio.passed:
                self.notes.append(
                    f"level-ratio test failed at {self.level_ratio.failing.size} of {x.size - 1} ratios "
                    f"(bounds {self.level_ratio.low:.4f}..{self.level_ratio.high:.4f}); not shifted (shift=None)"
                )
        elif isinstance(shift, str):
            if shift != "auto":
                raise ParameterError(f"shift = {shift!r} is not allowed; use 'auto', a number or None")
            c = 0.0 if self.level_ratio.passed else _shift_for_level_ratio(x)
            if c:
                self.notes.append(
                    f"level-ratio test failed at {self.level_ratio.failing.size} of {x.size - 1} ratios "
                    f"(bounds {self.level_ratio.low:.4f}..{self.level_ratio.high:.4f}); fitted on series + {c:.6g}"
                )
        else:
            try:
                c = float(shift)
            except (TypeError, ValueError):
                raise ParameterError(f"shift = {shift!r} is not allowed; use 'auto', a number or None") from None
            if not np.isfinite(c) or np.min(x) + c <= 0:
                raise ParameterError(
                    f"shift = {shift!r} leaves min(series) + shift = {float(np.min(x) + c)!r} <= 0; GM(1,1) needs "
                    "positive values"
                )
            if c:
                self.notes.append(f"fitted on series + {c:.6g} (shift given)")
        self.shift_applied = c
        y = x + c
        self._y = y
        self.level_ratio_shifted = level_ratio_test(y) if c else self.level_ratio
        x1 = np.cumsum(y)
        z = 0.5 * (x1[1:] + x1[:-1])
        B = np.column_stack([-z, np.ones_like(z)])
        # lstsq (QR/SVD), not the normal equations (BᵀB)⁻¹BᵀY of eq. 6: same solution, better conditioned.
        sol, *_ = np.linalg.lstsq(B, y[1:], rcond=None)
        self.a = float(sol[0])
        self.b = float(sol[1])
        if not (np.isfinite(self.a) and np.isfinite(self.b)):  # pragma: no cover - guarded by validation
            raise InputError("GM(1,1) least squares gave non-finite a, b for this series")
        self.fitted = self._x0hat(np.arange(x.size)) - c
        if not np.all(np.isfinite(self.fitted)):
            raise InputError(
                f"GM(1,1) fitted values overflow for this series (n = {x.size}, a = {self.a:.6g}): "
                "e^(−a·k) exceeds the float range; use a shorter series"
            )

    # k below is 0-based: value index k is the paper's x(k+1)
    def _x0hat(self, k: np.ndarray) -> np.ndarray:
        """Restored model values of the shifted series at 0-based indices k (k = 0 gives x⁰(1))."""
        k = np.asarray(k, dtype=np.float64)
        a, b, x0 = self.a, self.b, self._y[0]
        em = math.expm1(a)
        # (1 − e^a)(x0 − b/a)·e^{−ak} = e^{−ak}·(b·φ(a) − expm1(a)·x0): no division by a.
        with np.errstate(over="ignore"):  # an overflow is reported by the callers, by name
            vals = np.exp(-a * k) * (b * float(_phi(a)) - em * x0)
        return np.where(k == 0, x0, vals)

    def _x1hat(self, k: np.ndarray) -> np.ndarray:
        """1-AGO time response of the shifted series at 0-based indices k: x⁰(1)e^{−ak} + b·k·φ(−ak)."""
        k = np.asarray(k, dtype=np.float64)
        a, b, x0 = self.a, self.b, self._y[0]
        with np.errstate(over="ignore", invalid="ignore"):
            return x0 * np.exp(-a * k) + b * k * _phi(-a * k)

    def predict(self, h: int) -> np.ndarray:
        """The next ``h`` values x̂⁰(n+1) … x̂⁰(n+h), shift removed."""
        h = _check_horizon(h)
        n = self.series.size
        out = self._x0hat(np.arange(n, n + h)) - self.shift_applied
        if not np.all(np.isfinite(out)):
            j = int(np.flatnonzero(~np.isfinite(out))[0])
            raise ParameterError(
                f"h = {h}: the forecast overflows at step {j + 1} (e^(−a·k) with a = {self.a:.6g}); "
                "use a shorter horizon"
            )
        return out

    def __repr__(self) -> str:
        return f"GM11(n={self.series.size}, a={self.a:.6g}, b={self.b:.6g}, shift={self.shift_applied:.6g})"


# --------------------------------------------------------------------------------------------------
# baselines


class Persistence(_Forecaster):
    """Forecast = the last value. In-sample ``fitted[k] = series[k − 1]`` (``fitted[0] = series[0]``)."""

    name = "persistence"

    def __init__(self, series: Any, *, sd: str = "population", include_first: bool = True) -> None:
        _check_sd(sd)
        self.series = _as_series(series, min_len=2)
        self.sd, self.include_first = sd, bool(include_first)
        self.fitted = np.concatenate([self.series[:1], self.series[:-1]])

    def predict(self, h: int) -> np.ndarray:
        """``h`` copies of the last value."""
        return np.full(_check_horizon(h), self.series[-1])


class BuildMean(_Forecaster):
    """Forecast = the mean of the series it was built on (``fitted`` is that mean everywhere)."""

    name = "build mean"

    def __init__(self, series: Any, *, sd: str = "population", include_first: bool = True) -> None:
        _check_sd(sd)
        self.series = _as_series(series, min_len=2)
        self.sd, self.include_first = sd, bool(include_first)
        self.mean = float(np.mean(self.series))
        self.fitted = np.full(self.series.size, self.mean)

    def predict(self, h: int) -> np.ndarray:
        """``h`` copies of the mean."""
        return np.full(_check_horizon(h), self.mean)


class LinearTrend(_Forecaster):
    """Ordinary least-squares straight line through (k, series[k]), extrapolated.

    Attributes
    ----------
    slope, intercept : float
        ``fitted[k] = intercept + slope·k`` (0-based k).
    """

    name = "linear trend"

    def __init__(self, series: Any, *, sd: str = "population", include_first: bool = True) -> None:
        _check_sd(sd)
        self.series = _as_series(series, min_len=2)
        self.sd, self.include_first = sd, bool(include_first)
        k = np.arange(self.series.size, dtype=np.float64)
        # centre k so the fit is well conditioned for long series
        kc = k - k.mean()
        self.slope = float(np.dot(kc, self.series - self.series.mean()) / np.dot(kc, kc))
        self.intercept = float(self.series.mean() - self.slope * k.mean())
        self.fitted = self.intercept + self.slope * k

    def predict(self, h: int) -> np.ndarray:
        """The line at k = n … n + h − 1."""
        n = self.series.size
        return self.intercept + self.slope * np.arange(n, n + _check_horizon(h), dtype=np.float64)


class Holt(_Forecaster):
    """Holt's linear (additive-trend) exponential smoothing.

    Level ℓ and trend b: ℓ_k = α·x_k + (1 − α)(ℓ_{k−1} + b_{k−1}),
    b_k = β(ℓ_k − ℓ_{k−1}) + (1 − β)b_{k−1},
    started at ℓ_0 = x_0, b_0 = x_1 − x_0. α and β (in [0, 1]) minimise the sum of squared one-step
    in-sample errors unless given. ``fitted[k]`` is the one-step forecast ℓ_{k−1} + b_{k−1}
    (``fitted[0] = series[0]``); ``predict(h)`` is ℓ_n + j·b_n, j = 1 … h.

    Parameters
    ----------
    series : array_like
        At least 3 finite values.
    alpha, beta : float, optional
        Fix the smoothing constants (each in [0, 1]) instead of fitting them.
    """

    name = "Holt"

    def __init__(
        self,
        series: Any,
        *,
        alpha: float | None = None,
        beta: float | None = None,
        sd: str = "population",
        include_first: bool = True,
    ) -> None:
        _check_sd(sd)
        x = _as_series(series, min_len=3)
        self.series = x
        self.sd, self.include_first = sd, bool(include_first)
        for nm, v in (("alpha", alpha), ("beta", beta)):
            if v is not None and not (0.0 <= float(v) <= 1.0):
                raise ParameterError(f"{nm} = {v!r} must lie in [0, 1]")

        def sse(p: np.ndarray) -> float:
            f, _, _ = self._run(x, p[0], p[1])
            return float(np.sum((x[1:] - f[1:]) ** 2))

        if alpha is None or beta is None:
            free = [i for i, v in enumerate((alpha, beta)) if v is None]
            fixed = np.array([0.5 if alpha is None else float(alpha), 0.1 if beta is None else float(beta)])

            def obj(q: np.ndarray) -> float:
                p = fixed.copy()
                p[free] = q
                return sse(p)

            # a coarse grid first (the SSE surface has flat valleys), then a bounded polish
            grid = np.linspace(0.05, 0.95, 10)
            starts = [np.array(g) for g in np.array(np.meshgrid(*([grid] * len(free)))).reshape(len(free), -1).T]
            best = min(starts, key=obj)
            from scipy import optimize  # at its first use: keeps scipy.optimize out of import allanite

            res = optimize.minimize(obj, best, method="L-BFGS-B", bounds=[(0.0, 1.0)] * len(free))
            q = res.x if res.fun <= obj(best) else best
            fixed[free] = q
            alpha, beta = float(fixed[0]), float(fixed[1])
        self.alpha, self.beta = float(alpha), float(beta)
        self.fitted, self.level, self.trend = self._run(x, self.alpha, self.beta)

    @staticmethod
    def _run(x: np.ndarray, alpha: float, beta: float) -> tuple[np.ndarray, float, float]:
        level, trend = x[0], x[1] - x[0]
        f = np.empty_like(x)
        f[0] = x[0]
        for k in range(1, x.size):
            f[k] = level + trend
            new_level = alpha * x[k] + (1.0 - alpha) * (level + trend)
            trend = beta * (new_level - level) + (1.0 - beta) * trend
            level = new_level
        return f, float(level), float(trend)

    def predict(self, h: int) -> np.ndarray:
        """ℓ_n + j·b_n for j = 1 … h."""
        return self.level + self.trend * np.arange(1, _check_horizon(h) + 1, dtype=np.float64)


# --------------------------------------------------------------------------------------------------
# improved GM(1,1)


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


class ImprovedGM11(_Forecaster):
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
        _check_sd(sd)
        x = _as_series(series)
        nonpos = np.flatnonzero(x <= 0)
        if nonpos.size:
            i = int(nonpos[0])
            raise InputError(
                f"series[{i}] = {float(x[i])!r} is not positive ({nonpos.size} value(s) <= 0); GM(1,1) needs positive "
                "values. A noise coefficient at 0 usually means the fit did not resolve that term: do not "
                "forecast it (or use GM11(..., allow_nonpositive=True) for genuinely signed data)."
            )
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
        self.series = x
        self.sd, self.include_first = sd, bool(include_first)
        self.steps = {
            "detect": bool(detect),
            "smooth": bool(smooth),
            "metabolic": bool(metabolic),
            "residual": bool(residual),
        }
        self.notes: list[str] = []
        if (
            isinstance(residual_min_len, bool)
            or not isinstance(residual_min_len, (int, np.integer))
            or residual_min_len < 4
        ):
            raise ParameterError(f"residual_min_len = {residual_min_len!r} must be an integer >= 4")
        if not (np.isfinite(residual_max_a) and residual_max_a > 0):
            raise ParameterError(f"residual_max_a = {residual_max_a!r} must be a positive number")
        self._opts = {
            "residual": bool(residual),
            "residual_from": residual_from,
            "residual_on": residual_on,
            "residual_min_len": int(residual_min_len),
            "residual_max_a": float(residual_max_a),
            "shift": shift,
        }
        y = x
        self.detection: Detection | None = None
        if detect:
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
            y, lev = _smooth(y, wavelet, smooth_level, wavelet_mode)
            if lev == 0:
                self.notes.append(f"series too short for {wavelet} smoothing; not smoothed")
        self.processed = y
        self.model, self._rc = self._fit(y)
        self.notes.extend(self.model.notes)
        if residual and not self._rc.applied:
            self.notes.append(f"residual correction skipped: {self._rc.reason}")
        self.fitted = self._rc.x0hat(np.arange(x.size)) - self.model.shift_applied

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
        h = _check_horizon(h)
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


# --------------------------------------------------------------------------------------------------
# scoring on a build/check split


@dataclass(frozen=True)
class Score(RichDisplay):
    """A method judged on a build/check split.

    Attributes
    ----------
    name : str
    forecast : ndarray
        The method's forecast of the check part (built on the build part only).
    honest : Accuracy
        C, P of ``forecast`` against the **raw** check values (all of them).
    paper_rule : Accuracy
        Paper 004's rule: a-posteriori values over build and check together — the in-sample ``fitted``
        against the series the model was fitted to (``processed`` for the improved model, else the raw
        build), then ``forecast`` against the raw check — with x⁰(1) left out.
    rmse : float
        Root-mean-square forecast error against the raw check values.
    bias : float
        Mean of (check − forecast). C and P ignore a constant offset (S2 is the SD of e about its mean,
        so any constant forecast has C = 1 exactly); ``bias`` and ``rmse`` show it.
    model : object
        The fitted model.
    """

    name: str
    forecast: np.ndarray
    honest: Accuracy
    paper_rule: Accuracy
    rmse: float
    bias: float
    model: Any = field(repr=False)

    @property
    def differs(self) -> bool:
        """Whether the paper's rule gives another C (to 3 decimals) than the honest one."""
        return round(self.paper_rule.C, 3) != round(self.honest.C, 3)

    def _summary(self) -> Summary:
        notes = ["the paper's rule gives another C than the honest check"] if self.differs else []
        return Summary(
            title=f"Score · {self.name}",
            what="a forecast judged on a build/check split",
            facts=[
                ("forecast", f"{np.asarray(self.forecast).size} values of the check part"),
                ("RMSE", f"{self.rmse:.4g}"),
                ("bias (check − forecast)", f"{self.bias:.4g}"),
            ],
            tables=[
                Table(
                    ("check", "value", "grade"),
                    _accuracy_rows(self.honest, "honest") + _accuracy_rows(self.paper_rule, "paper's rule"),
                )
            ],
            notes=notes,
        )


def split(series: Any, build: int, check: int) -> tuple[np.ndarray, np.ndarray]:
    """The first ``build`` values and the ``check`` values after them; errors name what does not fit."""
    x = _as_series(series, min_len=2)
    for nm, v in (("build", build), ("check", check)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
            raise ParameterError(f"{nm} = {v!r} must be an integer count of values")
    if build < 4:
        raise ParameterError(f"build = {build} is too small; GM(1,1) needs at least 4 values to build on")
    if check < 2:
        raise ParameterError(f"check = {check} is too small; C and P need at least 2 held-out values")
    if build + check > x.size:
        raise ParameterError(
            f"build + check = {build} + {check} = {build + check} exceeds the series length ({x.size})"
        )
    return x[:build].copy(), x[build : build + check].copy()


def score(
    method: Callable[..., Any],
    build: Any,
    check: Any,
    *,
    sd: str = "population",
    name: str | None = None,
) -> Score:
    """Build ``method`` on ``build``, forecast ``len(check)`` values, and score them.

    Parameters
    ----------
    method : callable
        A model class or factory called as ``method(build)`` (e.g. ``GM11``, ``Holt``,
        ``functools.partial(ImprovedGM11, smooth=False)``); the result needs ``fitted`` and ``predict(h)``.
    build, check : array_like
        The build part and the raw held-out check part (use :func:`split`).
    sd : {"population", "sample"}
    name : str, optional
        Label; defaults to the model's ``name``.

    Returns
    -------
    Score

    Examples
    --------
    >>> x = [1.0, 1.1, 1.25, 1.3, 1.45, 1.5, 1.62, 1.7, 1.85, 1.9]
    >>> build, check = split(x, 7, 3)
    >>> s = score(GM11, build, check)
    >>> print(f"{s.name}: C = {s.honest.C:.3f} ({s.honest.grade}), rmse = {s.rmse:.3f}")
    GM(1,1): C = 0.466 (qualified), rmse = 0.080
    """
    _check_sd(sd)
    b = _as_series(build, name="build")
    c = _as_series(check, name="check", min_len=2)
    model = method(b)
    fc = np.asarray(model.predict(c.size), dtype=np.float64)
    if fc.shape != c.shape or not np.all(np.isfinite(fc)):
        raise InputError(f"{name or getattr(model, 'name', method)} gave a non-finite or mis-sized forecast")
    honest = accuracy(c, fc, sd=sd, include_first=True)
    basis = np.asarray(getattr(model, "processed", b), dtype=np.float64)
    paper = accuracy(np.concatenate([basis, c]), np.concatenate([model.fitted, fc]), sd=sd, include_first=False)
    e = c - fc
    return Score(
        str(name or getattr(model, "name", None) or method),
        fc,
        honest,
        paper,
        float(np.sqrt(np.mean(e * e))),
        float(np.mean(e)),
        model,
    )


# --------------------------------------------------------------------------------------------------
# every method on every coefficient series


def default_methods() -> dict[str, Callable[..., Any]]:
    """Name → model factory of the methods :func:`compare` judges, in table order: the traditional and the
    improved GM(1,1) (all steps on) and the four baselines."""
    return {
        "GM(1,1)": GM11,
        "improved GM(1,1)": ImprovedGM11,
        "persistence": Persistence,
        "build mean": BuildMean,
        "linear trend": LinearTrend,
        "Holt": Holt,
    }


def compare(
    series: Mapping[str, Any],
    build: int,
    check: int,
    *,
    methods: Mapping[str, Callable[..., Any]] | None = None,
    sd: str = "population",
    noise: Mapping[str, Any] | None = None,
) -> dict[str, Any]:
    """Judge every method on every series (e.g. one noise coefficient per time frame, paper 004 §4).

    Parameters
    ----------
    series : mapping
        Name (a noise term) → values, at least ``build + check`` of them (the first ``build + check`` are
        used). A series with a value ≤ 0 (a term the frame fits did not resolve) is not forecastable:
        it is listed in ``skipped`` with the reason and fed to no model.
    build, check : int
        The split: build on the first ``build`` values, forecast and check the next ``check`` (paper 004:
        60 / 30).
    methods : mapping, optional
        Name → factory called as ``factory(build_values)``; default :func:`default_methods`.
    sd : {"population", "sample"}
        SD convention of C and P.
    noise : mapping, optional
        Name → per-value standard error of the series itself (e.g. the frame fits' intervals). Adds
        ``se_check``, the RMS standard error over the check values, and ``rmse_over_se`` to every cell: a
        forecast cannot be expected to beat the estimation noise of the values it is checked against
        (≈ 1 means the forecast error is that noise).

    Returns
    -------
    dict
        ``{"build", "check", "sd", "terms", "methods", "cells": {method: {term: cell}}, "skipped": {term:
        reason}, "scatter": {term: robust SD of successive differences / √2}, "se_check": {term: …}}``. A
        cell holds the forecast (``forecast``), the in-sample ``fitted`` values, ``C``, ``P``, ``c_grade``,
        ``grade`` (honest: against the raw check values), ``C_paper``, ``P_paper``, ``c_grade_paper``,
        ``grade_paper`` (paper 004's rule, see :class:`Score`), ``rmse``, ``bias``, ``notes`` — or
        ``error`` when the method failed on that series.

    Raises
    ------
    ParameterError
        The split does not fit a series (``build`` < 4, ``check`` < 2, ``build + check`` > its length).
    InputError
        A series is not 1-D finite numbers, or is shorter than 4 values.

    Examples
    --------
    >>> x = 1.03 ** np.arange(12) + 0.02 * np.sin(2.0 * np.arange(12))  # exponential growth + a wiggle
    >>> t = compare({"N": x}, 8, 4)
    >>> for m in ("GM(1,1)", "persistence", "linear trend"):
    ...     c = t["cells"][m]["N"]
    ...     print(f"{m}: C = {c['C']:.2f} ({c['grade']}), rmse = {c['rmse']:.3f}")
    GM(1,1): C = 0.23 (good), rmse = 0.013
    persistence: C = 1.00 (fail), rmse = 0.090
    linear trend: C = 0.32 (good), rmse = 0.020
    """
    _check_sd(sd)
    methods = default_methods() if methods is None else dict(methods)
    if not methods:
        raise ParameterError("methods is empty; give at least one name → model factory")
    cells: dict[str, dict[str, Any]] = {m: {} for m in methods}
    out: dict[str, Any] = {
        "build": build,
        "check": check,
        "sd": sd,
        "terms": [],
        "methods": list(methods),
        "cells": cells,
        "skipped": {},
        "scatter": {},
        "se_check": {},
    }
    for term, values in series.items():
        x = _as_series(values, name=f"series[{term!r}]")
        b, c = split(x, build, check)
        used = x[: build + check]
        d = np.diff(used)
        # robust frame-to-frame scatter: successive differences of independent noise have SD √2·σ
        out["scatter"][term] = float(1.4826 * np.median(np.abs(d - np.median(d))) / math.sqrt(2.0))
        se = None
        if noise is not None and term in noise:
            se_all = np.asarray(noise[term], dtype=np.float64)
            if se_all.shape[0] < build + check:
                raise InputError(f"noise[{term!r}] has {se_all.shape[0]} values; {build + check} needed")
            se = float(np.sqrt(np.mean(se_all[build : build + check] ** 2)))
            out["se_check"][term] = se
        nonpos = np.flatnonzero(used <= 0)
        if nonpos.size:
            out["skipped"][term] = (
                f"{nonpos.size} of {used.size} values at or below 0 (first at index {int(nonpos[0])}): the term is "
                "not resolved there, so it is not forecastable (GM(1,1) needs positive values)"
            )
            continue
        out["terms"].append(term)
        for name, factory in methods.items():
            try:
                s = score(factory, b, c, sd=sd, name=name)
            except AllaniteError as exc:
                cells[name][term] = {"error": str(exc)}
                continue
            cell: dict[str, Any] = {
                "forecast": s.forecast,
                "fitted": np.asarray(s.model.fitted, dtype=np.float64),
                "C": s.honest.C,
                "P": s.honest.P,
                "c_grade": s.honest.c_grade,
                "grade": s.honest.grade,
                "C_paper": s.paper_rule.C,
                "P_paper": s.paper_rule.P,
                "c_grade_paper": s.paper_rule.c_grade,
                "grade_paper": s.paper_rule.grade,
                "rmse": s.rmse,
                "bias": s.bias,
                "notes": list(getattr(s.model, "notes", [])),
            }
            if isinstance(s.model, ImprovedGM11):
                cell["processed"] = s.model.processed
            if se is not None:
                cell["rmse_over_se"] = s.rmse / se if se > 0 else math.inf
            cells[name][term] = cell
    return out
