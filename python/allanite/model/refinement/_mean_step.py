"""The ``"mean"`` check of :mod:`.missing`: does the mean of the final samples step once along the record?

A bias step (the mean jumps by d at one time, the noise level unchanged) leaves the first differences alone —
the level check does not see it — and on the Allan curve it looks like rate random walk (its Allan variance
rises ≈ d²·τ/(3·T) over the middle τ), so the final fit absorbs it into K, and a null drawn from that model
covers it (blind2's bias step: K 2.6·10⁻⁵ against the true 2·10⁻⁶).

- The statistic: the record cut into :data:`MEAN_BLOCKS` block means b₁ … b_n; for each split k the two-segment
  mean change √(k(n − k))/n·|m₁ − m₂| (rate unit; the likelihood ratio of one step for independent block means,
  a weighted CUSUM), its maximum over k. The split is then located within ±1 block on :data:`FINE` times finer
  block means, the step d = the difference of the samples' means after and before it.
- Its null from the model **refitted without the located step**: d is subtracted from the samples after the
  split, the Allan curve of that record (exact, at the curve's τ) is fitted with the final model's terms and
  effects (:func:`.curvefit.solve`, refine's fit) — refitting without a step that is not there lowers K, which
  would lower the threshold on clean records — then profiled over what that curve allows: each slow term
  (flicker, random walk) at its upper end with the other terms refitted there (:func:`._noisefit.upper_models`,
  χ² within ≈ 2σ of its minimum). The threshold: the largest over those models of the statistic's (1 − α)
  quantile over records of the five-term model simulated at the block rate (seeded; :func:`mean_step_threshold`).
  Each model is one the curve allows; raising flicker and random walk to their upper ends *at once* (the drift
  check's :func:`.curvefit.upper_theta`) is a corner it does not — on blind6's clock (a 10⁻¹³ frequency step at
  0.4 T) that corner put K at 12× and B at 1.9× the refit's and its threshold at 1.14× the profile's, which
  missed the step (0.95× the corner's threshold, 1.08× the profile's; 2.0× the threshold under the true noise).
- Said only where the step matters: its exact Allan variance (the step alone, at the curve's τ) must move the
  refitted model's Allan deviation by more than the final model's held-out RMS ADEV error at some τ (the level
  and line checks' rule); the entry's τ range is where it does.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ...analysis import avar
from ..tracing import block_means, simulated_block_mean_chunks
from ._noisefit import upper_models
from .curvefit import Curve, chi2_dof_between, solve, theta_terms
from .words import heldout_clause

__all__ = [
    "MEAN_BLOCKS",
    "FINE",
    "MAX_BOOT",
    "split_statistic",
    "locate_step",
    "null_statistics",
    "mean_step_threshold",
    "profile_threshold",
    "step_avar",
    "located",
    "mean_step_check",
]

#: Block means the one-step statistic is taken on (≈ 2 % of the record each).
MEAN_BLOCKS = 48
#: Finer blocks per block for locating the split once the statistic is taken.
FINE = 32
#: Simulated records per unit of 1/α for the null's quantile (at least :data:`MIN_BOOT`): a Monte Carlo test's
#: rank rule holds α for any number of draws, more only sharpen its power; 5/α at the default level (32 000
#: records) keeps the block-rate record under 2²¹ samples.
BOOT_PER_ALPHA = 5
MIN_BOOT = 2000
#: Most simulated records (2²¹ block-rate samples in all, drawn 2¹⁸ at a time): refine accepts any level in
#: (0, 1), and 5/α records at level 10⁻⁴ (α 3.1·10⁻⁷) would be 7.7·10⁸ samples, gigabytes. From level ≈ 0.037 down
#: (α < 5/MAX_BOOT) fewer than 5/α are drawn; below α = 1/(MAX_BOOT + 1) (level ≈ 0.0073) the threshold is the
#: largest null statistic, whose false-alarm probability is 1/(MAX_BOOT + 1) ≈ 2.3·10⁻⁵ rather than α (as the
#: drift check's 1000 draws).
MAX_BOOT = 2**21 // MEAN_BLOCKS


def split_statistic(b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """max_k √(k(n − k))/n·|m₁(k) − m₂(k)| over the splits k = 1 … n − 1 of block means ``b`` (n, records), and
    the k where it is reached; for many records (columns) at once."""
    b = np.asarray(b, dtype=np.float64)
    if b.ndim == 1:
        b = b[:, None]
    n = b.shape[0]
    k = np.arange(1, n, dtype=np.float64)[:, None]
    c = np.cumsum(b, axis=0)[:-1]
    tot = np.sum(b, axis=0)[None, :]
    gain = np.sqrt(k * (n - k)) / n * np.abs(c / k - (tot - c) / (n - k))
    j = np.argmax(gain, axis=0)
    return gain[j, np.arange(b.shape[1])], j + 1


def locate_step(y: np.ndarray) -> dict:
    """The one-step statistic of ``y``'s block means, the split located to 1/:data:`FINE` of a block around the
    best block split (the same two-segment criterion on the fine block means), and the step ``d`` (the mean
    of the samples after the split less the mean before). ``index``: the first sample after the split. Memory
    O(blocks): the block means and the step are reductions of views of ``y`` (no record-length temporary, which
    would be 0.8 GB at 10⁸ samples)."""
    b, per = block_means(y, MEAN_BLOCKS)
    stat, k = split_statistic(b)
    fine, per_f = block_means(y, MEAN_BLOCKS * FINE)
    nf = fine.size
    c = np.cumsum(fine)
    lo, hi = max(1, (int(k[0]) - 1) * FINE), min(nf - 1, (int(k[0]) + 1) * FINE)
    kk = np.arange(lo, hi + 1, dtype=np.float64)
    cc = c[lo - 1 : hi]
    gain = np.sqrt(kk * (nf - kk)) * np.abs(cc / kk - (c[-1] - cc) / (nf - kk))
    index = int(kk[int(np.argmax(gain))]) * per_f
    d = float(np.mean(y[index:]) - np.mean(y[:index]))
    return {"statistic": float(stat[0]), "index": index, "d": d, "block": per}


def null_statistics(n: int, fs: float, terms, theta, n_boot: int, seed: int = 7919) -> np.ndarray:
    """:func:`split_statistic` (sorted) on the :data:`MEAN_BLOCKS` block means of ``n_boot`` records of ``n``
    samples of the five-term model ``theta`` (squared coefficients of ``terms``): simulated at the block rate
    (white, flicker and random walk of rate keep their coefficients; quantisation averages out), as consecutive
    pieces of long records, a chunk of records at a time (:func:`allanite.model.tracing.simulated_block_mean_chunks`:
    the statistic per chunk, not the 2²¹ block means and their sums at once)."""
    chunks = simulated_block_mean_chunks(MEAN_BLOCKS, n // MEAN_BLOCKS, fs, terms, theta, n_boot, seed)
    return np.sort(np.concatenate([split_statistic(b)[0] for b in chunks]))


def mean_step_threshold(n: int, fs: float, terms, theta, alpha: float, seed: int = 7919) -> float:
    """(1 − α) quantile of :func:`null_statistics`, max(:data:`MIN_BOOT`, :data:`BOOT_PER_ALPHA`/α) records, at
    most :data:`MAX_BOOT` (then the rank rule's index is capped at the largest statistic)."""
    n_boot = min(MAX_BOOT, max(MIN_BOOT, math.ceil(BOOT_PER_ALPHA / alpha)))
    stats = null_statistics(n, fs, terms, theta, n_boot, seed)
    return float(stats[min(math.ceil((n_boot + 1) * (1.0 - alpha)), n_boot) - 1])


def profile_threshold(
    n: int, fs: float, terms, thetas, alpha: float, seed: int = 7919, stop_at: float = math.inf
) -> float:
    """The largest :func:`mean_step_threshold` over the null models ``thetas`` (:func:`located`'s profile), the
    last model first (the random walk's end, most often the largest); once one reaches ``stop_at`` (the
    statistic: the test then holds whatever the others give) that one's."""
    out = -math.inf
    for theta in reversed(thetas):
        out = max(out, mean_step_threshold(n, fs, terms, theta, alpha, seed))
        if out >= stop_at:
            break
    return out


def refit_without(ctx: Any, index: int, d: float) -> tuple[Curve, Any]:
    """The final model's terms and effects refitted (:func:`.curvefit.solve`) on the exact Allan curve of the
    final samples less a step of ``d`` from sample ``index`` on, at the curve's τ (one copy of the record:
    8 bytes a sample, not a step array beside the difference)."""
    cur = ctx.curve
    less = np.array(ctx.y, dtype=np.float64)
    less[index:] -= d
    av = avar(less, ctx.fs, taus=cur.tau).avar
    del less
    curve = Curve(cur.tau, cur.m, np.asarray(av, dtype=np.float64), cur.fs, cur.n_points, cur.estimator)
    return curve, solve(curve, ctx.start, ctx.effects)


def step_avar(n: int, index: int, d: float, m: np.ndarray) -> np.ndarray:
    """The overlapping Allan variance, at averaging factors ``m``, of ``n`` samples that step by ``d`` at sample
    ``index`` (0 before, d from there on), exactly: the difference of two adjacent m-sample means straddling
    the step is d·u/m, u the triangle min(u, 2m − u) of the step's offset into the pair, so the sum over the
    n − 2m + 1 pairs is d²/m²·Σu² over the offsets the record holds (closed form)."""
    m = np.asarray(m, dtype=np.float64)

    def sq(x):  # Σ_{u=1}^{x} u²
        return x * (x + 1.0) * (2.0 * x + 1.0) / 6.0

    lo, hi = index - (n - 2.0 * m), float(index)
    a1, b1 = np.maximum(1.0, lo), np.minimum(m, hi)
    rise = np.where(b1 >= a1, sq(b1) - sq(a1 - 1.0), 0.0)
    a2, b2 = np.maximum(m + 1.0, lo), np.minimum(2.0 * m - 1.0, hi)
    fall = np.where(b2 >= a2, sq(2.0 * m - a2) - sq(2.0 * m - b2 - 1.0), 0.0)
    return d * d * (rise + fall) / (m * m * 2.0 * np.maximum(n - 2.0 * m + 1.0, 1.0))


def _pct(x: float) -> str:
    return f"{x:.0f}" if x >= 100 else f"{x:.2g}"


def located(ctx: Any) -> tuple[dict, Any, np.ndarray]:
    """The step of the final samples (:func:`locate_step`), the final model refitted without it
    (:func:`refit_without`) and its null's models (``"thetas"``: each slow term at the upper end the curve
    allows, the others refitted there, :func:`._noisefit.upper_models`), and how far (%) the step's own Allan
    variance moves the refitted model's Allan deviation at each τ of the curve."""
    y = ctx.y
    loc = locate_step(y)
    curve, sol = refit_without(ctx, loc["index"], loc["d"])
    loc["curve"] = curve  # the null's curve (the samples less the step)
    loc["thetas"] = upper_models(curve, sol, ctx.start, ctx.effects, theta_terms(sol, ctx.start, ctx.effects))
    s_av = step_avar(y.size, loc["index"], loc["d"], ctx.curve.m)
    return loc, sol, 100.0 * (np.sqrt(1.0 + s_av / np.maximum(sol.model, 1e-300)) - 1.0)


def mean_step_check(ctx: Any, a: float) -> list[dict]:
    """One entry when the final samples' mean steps once (the module docstring's test at ``a``) and the step
    moves the Allan deviation beyond the held-out error: ``"t"`` the side after the step (s), ``"step"`` d and
    ``"t_step"`` the split (s), ``"departure_pct"`` its largest move of the Allan deviation; else nothing."""
    if ctx.y is None or ctx.y.size < MEAN_BLOCKS * FINE * 2:
        return []
    y, fs, tau = ctx.y, ctx.fs, ctx.curve.tau
    loc, _sol, dep = located(ctx)
    big = np.flatnonzero(dep > float(ctx.heldout_pct or 0.0))
    if big.size == 0:  # checked before the null, which costs more
        return []
    thr = profile_threshold(y.size, fs, ctx.start, loc["thetas"], a, stop_at=loc["statistic"])
    if not loc["statistic"] > thr:
        return []
    lo, hi = float(tau[big[0]]), float(tau[big[-1]])
    t_step, i_top = loc["index"] / fs, int(np.argmax(dep))
    unit = f" {ctx.unit}" if ctx.unit else ""
    what = (
        f"the mean steps by {loc['d']:.2g}{unit} at t ≈ {t_step:.6g} s (it raises the Allan deviation by "
        f"{_pct(float(dep[i_top]))} % at τ {float(tau[i_top]):.4g} s" + heldout_clause(ctx.heldout_pct) + ")"
    )
    return [
        {"domain": "mean", "tau": (lo, hi), "t": (t_step, y.size / fs), "band_hz": (0.5 / hi, 0.5 / lo)}
        | {"chi2_dof": chi2_dof_between(tau, ctx.sol.z, lo, hi), "what": what, "step": loc["d"], "t_step": t_step}
        | {"departure_pct": float(dep[i_top]), "heldout_pct": ctx.heldout_pct}
        | {"statistic": loc["statistic"], "threshold": thr, "alpha": a}
    ]
