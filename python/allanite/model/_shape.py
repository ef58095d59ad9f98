"""Does the rate depend on a channel's *value* beyond the terms kept for it? — ``unexplained``'s check of a
coupling's shape (:mod:`allanite.model.refinement._channel_shape`, the ``"channel_shape"`` check; docs/channels.md,
"A coupling no term models").

Real sensors' bias follows a temperature in ways no term of a channel regression models: a mode switch, a
thermostat, a compensation table with steps, hysteresis. A straight line in the channel takes most of such a
staircase (92 % of a two-step staircase at 20 and 30 °C over a 10–40 °C cycle) and leaves a residual that is
uncorrelated with the channel *linearly* — the linear checks cannot see it — yet a function of its value.

The test (:func:`shape_test`): the record and the channel (read as the regressors read it: its form read back,
band-limited to its signal bands) as block means of at most :data:`MAX_POINTS` points; candidates, each a column
of Whittle's design (:mod:`allanite.model._whittle`) — a step of the rate where the channel crosses each of its
:data:`BINS` − 1 inner quantiles (the indicator of the channel above it), and its square where the quadratic is
not kept. The null: the kept terms (the channel, and its square or d/dt where kept), their noise fitted. At that
noise the candidates' scores, made orthogonal to the null's columns, are N(0, h) under the null; the best
candidate and the one that adds most beside it are chosen (greedy), and the statistic is their likelihood ratio
2Δℓ, the noise refitted beside them. Its reference is the same greedy choice on :data:`DRAWS` seeded draws of the
scores, over √(χ²_ν/ν) (ν the smaller Satterthwaite count of the two directions,
:func:`allanite.model._whittle.noise_dof`: the noise level's own error, as an F reference takes it), the 1 − α
quantile; widened by the record's edge factor over the two directions where the statistic passes
(:func:`allanite.model._edge.edge_factor`: a channel that moves once puts its steps at the record's edge). What
the kept terms explain lies in the null's columns and is not a departure.

Why a search over cuts and not a fixed basis: the residual's information on a staircase lies in its edges (when
the channel crosses a threshold), so a step one degree off the true one keeps a fraction of it (blind8's
staircase: 2Δℓ 33.8 with steps at 20 and 30 °C, 9.1 at 19 and 31); a piecewise-constant fit on 8 fixed bins read
32.0 against 35.1, the greedy pair over 63 cuts 37.6 against 34.7. It adds no removal.
"""

from __future__ import annotations

import math
from itertools import islice

import numpy as np
from scipy.stats import f as f_dist

from . import _whittle as wh
from ._edge import EdgeSource, edge_factor
from ._regressors import read_channel, regressor_design, regressor_iter

__all__ = ["shape_test", "BINS", "DRAWS", "MAX_POINTS"]

#: Bins of the channel's value (quantiles): steps are looked for at its BINS − 1 inner quantiles.
BINS = 64
#: Null draws of the greedy statistic (its threshold: the 1 − α quantile), at least; more where α is so small
#: that fewer than :data:`TAIL` draws would lie beyond it (up to :data:`MAX_DRAWS`).
DRAWS = 100_000
TAIL = 20
MAX_DRAWS = 2_000_000
#: Draws per chunk.
CHUNK = 10_000
#: The record and channel are tested as block means of at most this many points (a step's edge in time needs
#: no finer a grid; the Gram matrix of many cuts is then cheap).
MAX_POINTS = 1 << 15


def _columns(xs: np.ndarray, mean: float, quad_mean: float, fs: float, cuts: np.ndarray):
    """The kept terms' three regressors, then one step column per cut (the indicator of the channel above it, less
    its mean): one at a time, for the transforms to let each go."""
    yield from regressor_iter(xs, mean, quad_mean, fs, None)
    for c in cuts:
        col = (xs > c).astype(np.float64)
        yield col - col.mean()


def _greedy(z: np.ndarray, h: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The greedy choice of up to two steps for each row of scores ``z`` (draws × cuts; covariance ``h`` under the
    null): the cut of the largest z_j²/h_jj, then the cut that adds most beside it. Returns (statistic, first,
    second) per row — the statistic the two steps' 2Δℓ at the noise held fixed."""
    d = np.maximum(np.diag(h), 1e-300)
    r1 = z**2 / d
    j = np.argmax(r1, axis=1)
    rows = np.arange(z.shape[0])
    hj = h[j]  # (draws, cuts): the chosen cut's covariances
    zc = z - z[rows, j][:, None] * hj / d[j][:, None]
    hc = d[None, :] - hj**2 / d[j][:, None]
    inc = np.where(hc > 1e-9 * d[None, :], zc**2 / np.maximum(hc, 1e-300), 0.0)
    inc[rows, j] = 0.0
    k = np.argmax(inc, axis=1)
    return r1[rows, j] + inc[rows, k], j, k


def _scores(bands: wh.Bands, design: wh.Design, n_null: int, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The steps' scores made orthogonal to the null's ``n_null`` columns at the noise ``s``, scaled to covariance
    ``h`` under the null (Whittle: cov U = H/2), and ``h`` itself."""
    big_h, u = design.gram(bands, 1.0 / s)
    a = np.linalg.solve(big_h[:n_null, :n_null], big_h[:n_null, n_null:])
    h = big_h[n_null:, n_null:] - big_h[n_null:, :n_null] @ a
    z = math.sqrt(2.0) * (u[n_null:] - a.T @ u[:n_null])
    return z, h


def _draws(rng: np.random.Generator, h: np.ndarray, nu: float, n_draws: int):
    """``n_draws`` null score vectors, N(0, h) over √(χ²_ν/ν), in chunks of :data:`CHUNK` (memory)."""
    w, v = np.linalg.eigh(h)
    root = v * np.sqrt(np.maximum(w, 0.0))
    for start in range(0, n_draws, CHUNK):
        size = min(CHUNK, n_draws - start)
        z = rng.standard_normal((size, h.shape[0])) @ root.T
        if math.isfinite(nu):
            z /= np.sqrt(rng.chisquare(nu, size) / nu)[:, None]
        yield z


def _null_draws(h: np.ndarray, nu: float, alpha: float, seed: int = 0) -> np.ndarray:
    """The greedy statistic under the null, sorted (its 1 − α quantile the threshold): scores N(0, h) over a
    χ²_ν/ν noise level (the multivariate t, as an F reference takes the noise level's own error), seeded:
    :data:`DRAWS`, or enough for :data:`TAIL` of them beyond ``alpha`` (at most :data:`MAX_DRAWS`)."""
    rng = np.random.default_rng(seed)
    n_draws = int(min(MAX_DRAWS, max(DRAWS, math.ceil(TAIL / max(alpha, 1e-300)))))
    return np.sort(np.concatenate([_greedy(z, h)[0] for z in _draws(rng, h, nu, n_draws)]))


def _direction(bands: wh.Bands, design: wh.Design, n_null: int, s: np.ndarray, j: int) -> np.ndarray:
    """Cut ``j``'s direction made orthogonal (GLS metric at the noise ``s``) to the null's ``n_null`` columns: a
    row over ``design``'s regressors."""
    info = design.gram(bands, 1.0 / s)[0]
    v = np.zeros(len(design))
    v[n_null + j] = 1.0
    v[:n_null] = -np.linalg.solve(info[:n_null, :n_null], info[:n_null, n_null + j])
    return v


def _decimated(y: np.ndarray, xs: np.ndarray, fs: float) -> tuple[np.ndarray, np.ndarray, float]:
    """``y`` and ``xs`` as block means of at most :data:`MAX_POINTS` points (unchanged when shorter), and their
    rate."""
    f = -(-y.size // MAX_POINTS)
    if f == 1:
        return y, xs, fs
    n = y.size // f * f
    yb, xb = y[:n].reshape(-1, f).mean(axis=1), xs[:n].reshape(-1, f).mean(axis=1)
    m = wh.usable_length(yb.size)
    return yb[:m], xb[:m], fs / f


def shape_test(y, x, fs: float, alpha: float, kept=(), bins: int = BINS, exact: bool = False) -> dict:
    """Steps of the rate at ``bins`` − 1 quantiles of the channel ``x``'s value, beside the kept terms (``kept``:
    names among ``"quadratic"``, ``"rate_coefficient"``; the channel itself always), against them alone (module
    docstring). ``y`` the final residual samples, ``fs`` Hz, ``alpha`` the test's level. The null's draws are
    spent only where the statistic passes a fixed pair's 2·F(2, ν) (below it the test cannot pass; the threshold
    reported is then that bound, ``threshold_is_bound``, and ``p_value`` 1), or with ``exact``.

    Returns ``{"statistic", "threshold", "alpha", "nu", "edge", "fired", "cuts", "named"}`` — ``cuts`` the
    channel's values tried, ``named`` [(cut, step)] the two chosen steps (channel unit, rate unit; empty unless
    fired)."""
    n_use = wh.usable_length(y.size)
    y, x = np.asarray(y, dtype=np.float64)[:n_use], np.asarray(x, dtype=np.float64)[:n_use]
    xs = read_channel(x, fs)[3]  # the channel as the regressions read it
    y, xs, fs = _decimated(y, xs, fs)
    mean = float(xs.mean())
    quad_mean = float(np.mean((xs - mean) ** 2))
    cuts = np.unique(np.quantile(xs, np.arange(1, bins) / bins))
    cuts = cuts[(cuts > xs.min()) & (cuts < xs.max())]
    out: dict = {"statistic": 0.0, "threshold": math.inf, "alpha": float(alpha), "nu": math.inf, "edge": 1.0}
    out |= {"p_value": 1.0, "fired": False, "cuts": [float(c) for c in cuts], "named": [], "threshold_is_bound": False}
    if cuts.size < 2:
        return out
    bands = wh.spectra(y, _columns(xs, mean, quad_mean, fs, cuts), fs)
    bands.source = EdgeSource(lambda i: next(islice(_columns(xs, mean, quad_mean, fs, cuts), i, None)))
    small_design = regressor_design(kept, bands.m.size)
    n_null = len(small_design)
    # the candidates: the channel's square where it is not kept (smooth curvature), then a step at each cut
    src = ([] if "quadratic" in kept else [1]) + [3 + i for i in range(cuts.size)]
    design = small_design
    for i in src:
        design = design.plus(i, np.ones(bands.m.size))
    small = wh.joint_fit(bands, small_design)
    z, h = _scores(bands, design, n_null, small["s"])
    _, js, ks = _greedy(z[None, :], h)
    j, k = int(js[0]), int(ks[0])
    sel = small_design.plus(src[j], np.ones(bands.m.size)).plus(src[k], np.ones(bands.m.size))
    big = wh.nested_fit(bands, sel, small)  # the chosen steps' likelihood ratio, the noise refitted beside them
    stat = float(2.0 * (big["loglik"] - small["loglik"]))
    rows = [_direction(bands, design, n_null, small["s"], c) for c in (j, k)]
    nu = min(wh.noise_dof(bands, small, wh.band_info(bands, design, v)) for v in rows)
    # the best pair of many is never below a fixed pair's 2·F(2, ν): below that bound the draws are not spent
    bound = float(2.0 * f_dist.isf(alpha, 2, nu))
    null = _null_draws(h, nu, alpha) if (stat > bound or exact) else None
    threshold = float(np.quantile(null, 1.0 - alpha)) if null is not None else bound
    if stat > threshold:  # the edge factor (≥ 1) can only turn a pass into a fail: computed only then
        out["edge"] = float(edge_factor(bands, small, design, np.array(rows))["factor"])
        threshold *= out["edge"]
    out |= {"statistic": stat, "threshold": threshold, "nu": float(nu), "fired": bool(stat > threshold)}
    out["threshold_is_bound"] = null is None
    if null is not None:
        out["p_value"] = float((null.size - np.searchsorted(null, stat / out["edge"]) + 1) / (null.size + 1))
    if out["fired"]:
        c = big["c"][n_null:]
        # a step: (the cut, its size); the square: ("curvature", its coefficient per channel unit²)
        out["named"] = [(float(cuts[i - 3]) if i >= 3 else "curvature", float(v)) for i, v in zip((src[j], src[k]), c)]
    return out
