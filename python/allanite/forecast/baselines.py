"""Baseline forecasts with the models' interface: persistence, build mean, linear trend, Holt."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import ParameterError
from ._forecaster import Forecaster
from ._series import as_series, check_horizon, check_sd

__all__ = ["BuildMean", "Holt", "LinearTrend", "Persistence"]


class Persistence(Forecaster):
    """Forecast = the last value. In-sample ``fitted[k] = series[k − 1]`` (``fitted[0] = series[0]``)."""

    name = "persistence"

    def __init__(self, series: Any, *, sd: str = "population", include_first: bool = True) -> None:
        check_sd(sd)
        self.series = as_series(series, min_len=2)
        self.sd, self.include_first = sd, bool(include_first)
        self.fitted = np.concatenate([self.series[:1], self.series[:-1]])

    def predict(self, h: int) -> np.ndarray:
        """``h`` copies of the last value."""
        return np.full(check_horizon(h), self.series[-1])


class BuildMean(Forecaster):
    """Forecast = the mean of the series it was built on (``fitted`` is that mean everywhere)."""

    name = "build mean"

    def __init__(self, series: Any, *, sd: str = "population", include_first: bool = True) -> None:
        check_sd(sd)
        self.series = as_series(series, min_len=2)
        self.sd, self.include_first = sd, bool(include_first)
        self.mean = float(np.mean(self.series))
        self.fitted = np.full(self.series.size, self.mean)

    def predict(self, h: int) -> np.ndarray:
        """``h`` copies of the mean."""
        return np.full(check_horizon(h), self.mean)


class LinearTrend(Forecaster):
    """Ordinary least-squares straight line through (k, series[k]), extrapolated.

    Attributes
    ----------
    slope, intercept : float
        ``fitted[k] = intercept + slope·k`` (0-based k).
    """

    name = "linear trend"

    def __init__(self, series: Any, *, sd: str = "population", include_first: bool = True) -> None:
        check_sd(sd)
        self.series = as_series(series, min_len=2)
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
        return self.intercept + self.slope * np.arange(n, n + check_horizon(h), dtype=np.float64)


class Holt(Forecaster):
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
        check_sd(sd)
        x = as_series(series, min_len=3)
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
        return self.level + self.trend * np.arange(1, check_horizon(h) + 1, dtype=np.float64)
