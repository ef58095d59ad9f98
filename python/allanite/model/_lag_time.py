"""The lag a channel regression uses (:mod:`allanite.model.channels`: kept, or profiled for the removal), worked in
time: T refined on the band sums of the channel lagged in time (:func:`allanite.model._lag.exact_lag`), the fit at
that T with its coefficients' covariance marginalised over the lag, and the lag's interval from the profile in time
at the noise refitted beside the lagged channel (docs/channels.md, "The lag's and the coefficient's intervals") —
for both intervals that noise restricted, the power the coefficients and the lag's direction took from their bands
given back, and the coefficients' covariance the sandwich with the score's exact variance
(:func:`interval_cov_beside_lag`, :mod:`allanite.model._gls_cov`; docs/channels.md, "Intervals that cover").

Why the coefficients' covariance with the lag free: the lag is estimated from the same record, and the coefficient
is not independent of it. At a cycling channel's one frequency ω the record fixes the coupling's amplitude c·|H|
and its phase arg H = −atan(ωT): the phase gives T, and c = amplitude / |H(T)| carries T's error — the variance at
a fixed lag is (1 + (ωT)²)× too small. On blind5's 600 s lag on a 1667 s cycle (ωT = 2.3) the coefficient's 68 %
interval at the fixed lag held the truth on 12 of 40 records (``benches/results/channel_lag_bias.md``).

Why the lag's interval again: the grid's profile (:func:`allanite.model._lag.lag_profile`) is taken at the noise of
the fit at lag 0, which the coupling's phase error (sin φ of it: 0.9 at 66°) has raised in the cycle's bands — the
bands the lag is read from — and over a record a few lags long its ends reach the grid's. On the same 40 records
its 68 % half-width was ±54 % in T for a scatter of 13 % (every record covered), the upper end at the grid's
last point on most; at the noise refitted beside the lagged channel the profile's 2Δℓ = 1 lies ≈ ±12 % away.
"""

from __future__ import annotations

import math
from itertools import chain, islice

import numpy as np
from scipy.optimize import brentq

from . import _whittle as wh
from ._edge import EdgeSource
from ._gls_cov import interval_cov
from ._lag import exact_lag, lag_grid, lagged
from ._regressors import regressor_design, regressor_iter, regressors

__all__ = ["lag_in_time", "lag_bands", "lag_slope", "interval_cov_beside_lag", "profile_interval"]


def lag_in_time(y, xs, means, fs: float, keys, s, t_lag: dict, z2: float) -> tuple[float, dict]:
    """The lag the removal takes (kept, or profiled: ``t_lag["profiled"]``) refined in time at the noise ``s`` of
    the fit without it, then the fit at that lag (noise refitted), its coefficients' covariance with the lag free
    (:func:`interval_cov_beside_lag`) and the lag's interval where the profile in time at that covariance's
    restricted noise is within ``z2`` of its top (:func:`profile_interval`), written back into ``t_lag`` (the grid's
    T and interval under ``"grid_lag_s"`` and ``"grid_interval"``). Returns (T, the fit)."""
    rec = t_lag if t_lag.get("kept") else t_lag["profiled"]
    grid = lag_grid(y.size, fs)
    bounds = (float(grid[0]), float(grid[-1]))
    best, _ = exact_lag(_objective(y, xs, means, fs, keys, s), float(rec["lag_s"]), rec["interval"], bounds)

    def cols():
        return chain(regressor_iter(xs, means[0], means[1], fs, best), [lag_slope(xs - means[0], best, fs)])

    def column(i: int) -> np.ndarray:  # one regressor again, for the score's exact variance (the lag's: 2 filters)
        return lag_slope(xs - means[0], best, fs) if i == 3 else next(islice(cols(), i, None))

    exact = wh.spectra(y, cols(), fs)
    exact.source = EdgeSource(column)
    fit = wh.joint_fit(exact, regressor_design(keys, exact.m.size))
    full, noise = interval_cov_beside_lag(exact, keys, fit)
    c = float(fit["c"][0])
    se = math.sqrt(max(float(full[-1, -1]), 0.0)) / abs(c) if c != 0.0 else math.inf
    interval = profile_interval(_objective(y, xs, means, fs, keys, noise["s"]), best, se, z2, bounds)
    rec |= {"grid_lag_s": float(rec["lag_s"]), "grid_interval": tuple(rec["interval"])}
    rec |= {"lag_s": best, "interval": interval, "se_log": se}
    return best, fit | {"cov": full[:-1, :-1]}


def lag_bands(y, xs, means, fs: float, keys, lag_s: float, state: bool = False) -> wh.Bands:
    """The band sums of ``y`` beside the channel lagged in time by ``lag_s`` (:func:`allanite.model._lag.lagged`,
    from equilibrium with its first sample), the quadratic beside it where among ``keys`` — the pure lag model's
    columns as the removal takes them —, and with ``state`` the lag's own decay e^{−t/T} after them: the lag's
    output at the record's first sample is not the channel's there unless the lag started with the record (a log
    begun while the temperature moves), and what it differs by decays so."""
    n_cols = 2 if "quadratic" in keys else 1  # a lag is never beside the d(ch)/dt term
    cols = regressors(xs, means[0], means[1], fs, lag_s)[:n_cols]
    if state:
        cols.append(np.exp(-np.arange(xs.size) / (fs * lag_s)))
    return wh.spectra(y, cols, fs)


def _objective(y, xs, means, fs: float, keys, s):
    """Δℓ of the pure lag model (the channel through T, the quadratic beside it where kept) at the noise ``s``, on
    the band sums of the channel lagged in time (:func:`lag_bands`) — a function of T."""

    def objective(lag_s: float) -> float:
        b = lag_bands(y, xs, means, fs, keys, lag_s)
        info, sc = regressor_design(keys, b.m.size).gram(b, 1.0 / s)
        return float(sc @ np.linalg.solve(info, sc))

    return objective


def lag_slope(xm: np.ndarray, lag_s: float, fs: float, h: float = 0.01) -> np.ndarray:
    """d L_T[xm] / d log T at ``lag_s`` (central difference over ±``h`` in log T): the direction in which the
    lagged channel moves when its lag does."""
    return (lagged(xm, lag_s * math.exp(h), fs) - lagged(xm, lag_s * math.exp(-h), fs)) / (2.0 * h)


def interval_cov_beside_lag(exact, keys, fit: dict) -> tuple[np.ndarray, dict]:
    """The covariance of the kept coefficients and the lag's direction (:func:`lag_slope`, the band sums' column
    after the three regressors; its coefficient is c·δlog T) — the sandwich at the restricted noise
    (:func:`allanite.model._gls_cov.interval_cov`, the lag's direction one more coefficient, its leverage given
    back to the noise too) — and that noise: the coefficients' block is their covariance with the lag free (module
    docstring), the last diagonal element c²·var(log T). Where the lag's direction is not separable from the
    coefficients' (a singular information): the coefficients' covariance at the lag held fixed, the lag's variance
    infinite."""
    nb = exact.m.size
    try:
        return interval_cov(exact, regressor_design(keys, nb).plus(3, np.ones(nb)), fit)
    except np.linalg.LinAlgError:
        cov, noise = interval_cov(exact, regressor_design(keys, nb), fit)
        k = cov.shape[0]
        full = np.zeros((k + 1, k + 1))
        full[:k, :k] = cov
        full[k, k] = math.inf
        return full, noise


def profile_interval(objective, best: float, se: float, z2: float, bounds: tuple, xtol: float = 0.02) -> tuple:
    """Where 2·(``objective(best)`` − ``objective(T)``) = ``z2`` on each side of ``best`` in log T (to ``xtol``):
    stepped out from the Fisher guess √z2·``se`` (doubling) until the profile falls that far, each end at most the
    grid's ``bounds``. ≈ 5 evaluations a side."""
    centre = math.log(best)
    top = objective(best)

    def gap(lt: float) -> float:
        return 2.0 * (top - objective(math.exp(lt))) - z2

    step = math.sqrt(z2) * se if math.isfinite(se) and se > 0.0 else 0.1
    ends = []
    for sign, edge in ((-1.0, math.log(bounds[0])), (1.0, math.log(bounds[1]))):
        inner, k, end = centre, 1.0, None
        while end is None:
            probe = centre + sign * min(k * step, abs(edge - centre))
            if gap(probe) > 0.0:
                end = brentq(gap, *sorted((inner, probe)), xtol=xtol)
            elif probe == edge or k > 64:
                end = probe
            inner, k = probe, 2.0 * k
        ends.append(math.exp(end))
    return (min(ends[0], best), max(ends[1], best))
