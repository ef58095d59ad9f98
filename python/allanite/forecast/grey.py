"""The traditional grey GM(1,1) model (paper 004 eqs. 1–15) and its level-ratio test."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InputError, ParameterError
from ._forecaster import Forecaster
from ._series import as_series, check_horizon, check_sd

__all__ = ["GM11", "LevelRatio", "level_ratio_test"]


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
    x = as_series(series, min_len=2)
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


class GM11(Forecaster):
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
        check_sd(sd)
        x = as_series(series)
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
        c = self._shift(x, shift, nonpos)
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

    def _shift(self, x: np.ndarray, shift: str | float | None, nonpos: np.ndarray) -> float:
        """The constant added to ``x`` before the fit, as ``shift`` asks (None, 'auto' or a number), checked
        against the series; a note says why when one is added or the level-ratio test failed unshifted."""
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
        return c

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
        h = check_horizon(h)
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
