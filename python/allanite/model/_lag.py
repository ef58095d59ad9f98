"""A channel's first-order lag: the regressor through the lag, the lag's test over a grid of time constants and
its profile likelihood — :mod:`allanite.model.channels`' ``lag_s`` term.

The rate follows the channel through L_T, a first-order lag of time constant T (impulse invariant, unit gain
at DC): the family c·ch + c_L·(L_T[ch] − ch)/T over T on a log grid (T → 0 is the d(ch)/dt direction) is tested
by its largest score statistic against the t-process upcrossing bound (Davies 1987; Worsley 1994:
P(F(1, ν) > u) + (V/π)·(1 + u/ν)^{−(ν−1)/2}, V the arc length of the whitened family over the grid); T itself
by the profile likelihood of the pure lag model c·L_T[ch], the noise fixed.

The profile over the grid multiplies the channel's band sums by the lag's response, the lag applied circularly;
the removal runs the channel through the lag in time, from equilibrium with its first sample. Over a record a
few lags long the two differ — the start's transient, the end wrapping onto the start — and the grid's T reads
short: 473 s (median of 8) for a true 600 s on 5000 s at 10 Hz, 545 s with the record started in steady state.
:func:`exact_lag` therefore refines T on the band sums of the channel lagged in time (590 and 602 s there); the
interval that is reported is then the profile's in time at the noise refitted beside the lagged channel
(:mod:`allanite.model._lag_time`).

A lag the test does not resolve may still be the best description of the coupling: a coefficient fitted at
lag 0 on a channel that reaches the rate through a 900 s lag leaves c·(L_T[ch] − ch) in the residual — the
channel's phase error, as large as the coupling itself at the channel's own period ≈ 2πT. :func:`unresolved_lag`
says when the profile prefers a lag to none at the intervals' level (the profile interval excludes the
shortest lag), for the removal only (the lag is then reported as not resolved, not as a kept term).
"""

from __future__ import annotations

import math

import numpy as np
from scipy import signal
from scipy.optimize import brentq, minimize_scalar
from scipy.stats import f as f_dist

from . import _whittle as wh

__all__ = [
    "lagged",
    "lag_response",
    "lag_grid",
    "lag_test",
    "upcrossing_p",
    "upcrossing_threshold",
    "lag_objective",
    "lag_profile",
    "unresolved_lag",
    "exact_lag",
    "LAG_PER_OCTAVE",
]

#: Lag grid: points per octave, from 2 samples to a quarter of the record.
LAG_PER_OCTAVE = 8


def lagged(x: np.ndarray, lag_s: float, fs: float) -> np.ndarray:
    """``x`` through a first-order lag of time constant ``lag_s`` (impulse invariant, a = 1 − e^{−1/(fs·T)}),
    starting in equilibrium with the first sample."""
    a = -math.expm1(-1.0 / (fs * lag_s))
    return signal.lfilter([a], [1.0, a - 1.0], x - x[0]) + x[0]


def lag_response(f: np.ndarray, lag_s: float, fs: float) -> np.ndarray:
    a = -math.expm1(-1.0 / (fs * lag_s))
    return a / (1.0 - (1.0 - a) * np.exp(-2j * np.pi * f / fs))


def lag_grid(n: int, fs: float) -> np.ndarray:
    lo, hi = 2.0 / fs, n / fs / 4.0
    k = max(2, int(round(LAG_PER_OCTAVE * math.log2(hi / lo))) + 1)
    return np.geomspace(lo, hi, k)


def lag_test(bands, design, fit, alpha, grid) -> dict:
    """The largest score statistic of (L_T[ch] − ch) added to ``design`` over the lag grid, against the
    upcrossing bound of its t process (module docstring)."""
    w = 1.0 / fit["s"]
    src = design.src[0]
    mult = np.array([lag_response(bands.f, t, bands.fs) - 1.0 for t in grid])  # (n_T, nb)
    gw = bands.G[:, src, src].real * w
    # the family's Gram matrix is needed only on its diagonal and first off-diagonal (the arc length)
    c_diag = 2.0 * np.sum(np.abs(mult) ** 2 * gw, axis=1)
    c_next = 2.0 * np.sum((np.conj(mult[:-1]) * mult[1:]).real * gw, axis=1)
    c_fd = np.column_stack(
        [2.0 * ((np.conj(mult) * (m * bands.G[:, src, k])).real @ w) for k, m in zip(design.src, design.mult)]
    )
    i_dd = 2.0 * wh.cross(bands, design, design, w)
    sol = np.linalg.solve(i_dd, c_fd.T)
    var = np.maximum(c_diag - np.sum(c_fd * sol.T, axis=1), 1e-300)
    cov_next = c_next - np.sum(c_fd[:-1] * sol.T[1:], axis=1)
    sc = 2.0 * ((np.conj(mult) * bands.g[:, src]).real @ w) - c_fd @ fit["c"]
    stat = sc**2 / var
    j = int(np.argmax(stat))
    cos = np.abs(cov_next) / np.sqrt(var[:-1] * var[1:])
    arc = float(np.sum(np.arccos(np.clip(cos, 0.0, 1.0))))
    v = np.append(-np.linalg.solve(i_dd, c_fd[j]), 1.0)
    full = design.plus(src, mult[j])
    dof = wh.noise_dof(bands, fit, wh.band_info(bands, full, v))

    thr = upcrossing_threshold(alpha, dof, arc)
    return {
        "statistic": float(stat[j]),
        "threshold": float(thr),
        "alpha": float(alpha),
        "dof": float(dof),
        "p_value": min(1.0, upcrossing_p(float(stat[j]), dof, arc)),
        "arc_length": arc,
        "at_lag_s": float(grid[j]),
    }


def upcrossing_p(u: float, dof: float, arc: float) -> float:
    """P(max over the lag grid > u): P(F(1, ν) > u) + (V/π)·(1 + u/ν)^{−(ν−1)/2} (module docstring)."""
    return float(f_dist.sf(u, 1, dof) + arc / math.pi * (1.0 + u / dof) ** (-(dof - 1.0) / 2.0))


def upcrossing_threshold(alpha: float, dof: float, arc: float) -> float:
    """The u where :func:`upcrossing_p` falls to ``alpha``; with few degrees of freedom the bound's tail is slow
    (ν = 2.6, V = 2.5: beyond 10⁴), and where it never gets there (ν ≤ 1) no statistic can pass: ∞."""
    if upcrossing_p(1e-6, dof, arc) <= alpha:
        return 0.0
    hi = 1e4
    while upcrossing_p(hi, dof, arc) > alpha and hi < 1e12:
        hi *= 100.0
    if upcrossing_p(hi, dof, arc) > alpha:
        return math.inf
    return float(brentq(lambda u: upcrossing_p(u, dof, arc) - alpha, 1e-6, hi))


def lag_objective(bands, design, s, lag_s) -> float:
    """Σ ĉᵀ·score with the noise fixed (the likelihood up to a constant) for the pure lag model: the channel
    column of ``design`` (its first) through the lag ``lag_s``."""
    d = wh.Design(design.src, [lag_response(bands.f, lag_s, bands.fs)] + design.mult[1:])
    info, sc = d.gram(bands, 1.0 / s)
    return float(sc @ np.linalg.solve(info, sc))


def lag_profile(bands, design, s, grid, z2) -> tuple[float, tuple]:
    """The pure lag model's T (profile likelihood, noise fixed) and its interval where 2Δℓ ≤ ``z2``."""
    prof = np.array([lag_objective(bands, design, s, t) for t in grid])
    j = int(np.argmax(prof))
    lo, hi = math.log(grid[max(0, j - 1)]), math.log(grid[min(grid.size - 1, j + 1)])
    res = minimize_scalar(lambda lt: -lag_objective(bands, design, s, math.exp(lt)), bounds=(lo, hi), method="bounded")
    best, top = math.exp(float(res.x)), -float(res.fun)

    def gap(lt):
        return 2.0 * (top - lag_objective(bands, design, s, math.exp(lt))) - z2

    ends = []
    for side in (range(j, -1, -1), range(j, grid.size)):
        inner, end = math.log(best), None
        for k in side:
            if gap(math.log(grid[k])) > 0:
                end = math.exp(brentq(gap, *sorted((inner, math.log(grid[k])))))
                break
            inner = math.log(grid[k])
        ends.append(end if end is not None else float(grid[side[-1]] if len(side) else best))
    return best, (min(ends[0], best), max(ends[1], best))


def unresolved_lag(bands, design, s, grid, z2) -> dict:
    """A lag its test did not keep, profiled for the removal: ``{"lag_s", "interval", "gain", "used"}`` — the
    pure lag model's T (:func:`lag_profile`, the noise ``s`` fixed), its interval where 2Δℓ ≤ ``z2``, ``gain``
    the 2Δℓ of that T over no lag (the channel column of ``design`` as it is), and ``used`` whether the gain
    exceeds ``z2`` (the interval excludes T → 0: the record prefers a lag to none at the intervals' level, far
    below the test's). The removal then takes the channel through that lag; the lag is not claimed."""
    best, interval = lag_profile(bands, design, s, grid, z2)
    info, sc = design.gram(bands, 1.0 / s)
    gain = 2.0 * (lag_objective(bands, design, s, best) - float(sc @ np.linalg.solve(info, sc)))
    return {"lag_s": best, "interval": interval, "gain": gain, "used": bool(gain > z2)}


def exact_lag(objective, best: float, interval: tuple, bounds: tuple) -> tuple[float, tuple]:
    """T refined on ``objective(T)`` — the pure lag model's likelihood (as :func:`lag_objective`) on the band sums
    of the channel lagged in time (module docstring) — from the grid's ``best``, searched over best/2 … 2·best
    within ``bounds`` (the grid's ends; log T, to 2 %), and the grid's ``interval`` moved by the same ratio (the
    circular response shifts the profile along log T; its width is kept). Each evaluation transforms the lagged
    channel once: ≈ 8 of them."""
    lo_b, hi_b = math.log(bounds[0]), math.log(bounds[1])
    centre = math.log(best)
    res = minimize_scalar(
        lambda lt: -objective(math.exp(lt)),
        bounds=(max(lo_b, centre - math.log(2.0)), min(hi_b, centre + math.log(2.0))),
        method="bounded",
        options={"xatol": 0.02},
    )
    new = math.exp(float(res.x))
    ratio = new / best
    lo, hi = interval
    return new, (max(min(lo * ratio, new), bounds[0]), min(max(hi * ratio, new), bounds[1]))
