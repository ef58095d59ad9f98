"""Is the noise level the same along the record? A calibrated homogeneity test of the Allan variance at τ₀.

A record whose white-noise level steps or drifts has, over the whole record, the Allan curve of a stationary
noise at the mean level: the fit of the curve cannot see it. Along the record it is plain. The Allan variance
at τ₀ is half the mean of the squared first differences dᵢ = yᵢ₊₁ − yᵢ; differencing takes the slow terms
(flicker, random walk, a drift) nearly out of it, so it measures the fast noise's level in any stretch.

The test: ``n_blocks`` blocks along the record, each cut into ``SUB`` sub-blocks; xₖ is the log of block k's
mean d², and its variance is estimated from the scatter of the log mean d² of its sub-blocks (batch means:
the squared differences' correlation — a filter's, a flicker term's — is in it, whatever its shape, as long
as it is shorter than a sub-block; a level change from one block to the next is not). The statistic is the
largest standardised sum of the xₖ − x̄ over a run of blocks i < k ≤ j, max over runs of
|Σᵢ<ₖ≤ⱼ (xₖ − x̄)| / √(v̂·L(K − L)/K), L = j − i, v̂ the pooled variance: the runs that start at the record's
start are the standardised CUSUM (one change of level), the others a stretch louder or quieter than the rest (a
truck passing for 120 s of a 10⁴ s record: one block of 32, which a single split's CUSUM dilutes over the whole
record). Its null distribution — which depends only on (K, SUB) — is simulated once, studentised the same way
(Gaussian sub-block values), and the threshold is its (1 − α) quantile. Where it rejects, the change is said as
the split of the largest CUSUM where that alone exceeds the threshold and the stretch's gain over it in the squared
statistic, z²_stretch − z²_split, does not exceed the threshold's square (one change is the simpler reading; the
second must pay for itself at the test's own threshold; the decision is the maximum's either way, so the
calibration does not move), else as the run of the maximum, a stretch; exp((x̄_in − x̄_out)/2) the ratio of the
Allan deviations at τ₀ inside and outside it (right over left for a split).
"""

from __future__ import annotations

import numpy as np

__all__ = ["SUB", "MIN_SUB_SAMPLES", "MAX_BLOCKS", "NULL_DRAWS", "level_test", "null_statistics"]

#: Sub-blocks per block (batch means for the variance of a block's log level).
SUB = 8
#: Fewest squared differences in a sub-block (a sub-block's log mean must be near Gaussian, and longer than
#: the differences' correlation).
MIN_SUB_SAMPLES = 64
#: Blocks along the record at most; at least 8 are needed for the test to run.
MAX_BLOCKS = 32
MIN_BLOCKS = 8
#: Draws of the null distribution of the statistic (simulated once per number of blocks).
NULL_DRAWS = 40_000

_NULL: dict[tuple[int, int], np.ndarray] = {}


def _run_max(x: np.ndarray, v: np.ndarray, splits_only: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For rows of block levels ``x`` (draws, K) with pooled variances ``v`` (draws,): the largest standardised
    sum over a run of blocks of each row (module docstring) and the run (i, j] where it is reached (blocks i+1 … j,
    counted from 1); ``splits_only``: over the runs from the record's start (the CUSUM of one split). One pass per
    run length L (slices of the cumulative sums, no gather)."""
    rows, k = x.shape
    s = np.zeros((rows, k + 1))
    s[:, 1:] = np.cumsum(x - x.mean(axis=1, keepdims=True), axis=1)
    sd = np.sqrt(np.maximum(v, 1e-300))
    best = np.full(rows, -1.0)
    best_i = np.zeros(rows, dtype=np.int64)
    best_len = np.ones(rows, dtype=np.int64)
    for length in range(1, k):
        z = np.abs(s[:, length:] - s[:, :-length])  # runs (i, i + length], i = 0 … k − length
        if splits_only:  # the runs from the record's start only: the CUSUM
            z = z[:, :1]
        at = np.argmax(z, axis=1)
        top = z[np.arange(rows), at] / (sd * np.sqrt(length * (k - length) / k))
        better = top > best
        best = np.where(better, top, best)
        best_i = np.where(better, at, best_i)
        best_len = np.where(better, length, best_len)
    return best, best_i, best_i + best_len


def _levels(sub: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Block levels (mean of each block's SUB sub-block values, rows × K) and the pooled variance of a block
    level (within-block scatter of the sub-block values / SUB), from sub-block values (rows, K, SUB)."""
    x = sub.mean(axis=2)
    within = np.sum((sub - x[:, :, None]) ** 2, axis=(1, 2)) / (sub.shape[1] * (sub.shape[2] - 1))
    return x, within / sub.shape[2]


def null_statistics(n_blocks: int, sub: int = SUB, draws: int = NULL_DRAWS) -> np.ndarray:
    """The statistic's null distribution for ``n_blocks`` blocks of ``sub`` sub-blocks (sorted; simulated once,
    fixed seed, independent Gaussian sub-block values)."""
    key = (n_blocks, sub)
    if key not in _NULL:
        rng = np.random.default_rng(1_000_003 + 31 * n_blocks + sub)
        out = []
        for _ in range(0, draws, 5000):
            x, v = _levels(rng.standard_normal((5000, n_blocks, sub)))
            out.append(_run_max(x, v)[0])
        _NULL[key] = np.sort(np.concatenate(out)[:draws])
    return _NULL[key]


def level_test(y: np.ndarray, fs: float, alpha: float, t0: float = 0.0) -> dict | None:
    """The homogeneity test of the Allan variance at τ₀ along the samples ``y`` (rate ``fs``; ``t0`` the time of
    the first sample, s), at false-alarm probability ``alpha``; None where the record is too short for
    :data:`MIN_BLOCKS` blocks (or a sub-block's differences are all zero: a constant stretch).

    Returns ``statistic``, ``threshold``, ``p_value`` (share of null draws at or above the statistic, +1 over
    draws + 1), ``rejected``, ``blocks`` and where the level differs most: ``stretch_s`` None where the run of the
    maximum reaches an end of the record — a split, at ``split_s``, with ``left_s`` / ``right_s`` (t ranges, s) and
    ``ratio`` the Allan deviation at τ₀ right over left —, else ``stretch_s`` (lo, hi) s, the stretch louder or
    quieter than the rest, and ``ratio`` inside over outside (``split_s`` its start, ``left_s`` / ``right_s``
    the record before and after it).

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(3)
    >>> y = np.concatenate([rng.standard_normal(50_000), 2 * rng.standard_normal(50_000)])
    >>> r = level_test(y, 10.0, 0.001)
    >>> r["rejected"], round(r["split_s"]), round(r["ratio"], 1), r["stretch_s"]
    (True, 4992, 2.0, None)
    >>> y[40_000:43_000] *= 3                                  # a louder stretch of 300 s
    >>> r = level_test(y[:50_000], 10.0, 0.001)
    >>> r["rejected"], [round(t) for t in r["stretch_s"]], round(r["ratio"], 1)
    (True, [3900, 4368], 2.0)
    """
    e = np.diff(np.asarray(y, dtype=np.float64)) ** 2
    k = min(MAX_BLOCKS, e.size // (SUB * MIN_SUB_SAMPLES))
    if k < MIN_BLOCKS:
        return None
    per = e.size // (k * SUB)
    means = e[: k * SUB * per].reshape(k, SUB, per).mean(axis=2)
    if not np.all(means > 0):
        return None
    x, v = _levels(np.log(means)[None])
    stat, i_run, j_run = _run_max(x, v)
    null = null_statistics(k)
    thr_at = int(np.ceil((null.size + 1) * (1.0 - alpha) - 1e-9))
    thr = float(null[min(thr_at, null.size) - 1])
    i, j = int(i_run[0]), int(j_run[0])
    if 0 < i and j < k:  # a stretch: a split where that alone rejects and the stretch's second change does not pay
        split_z, _i, at = _run_max(x, v, splits_only=True)
        if split_z[0] > thr and stat[0] ** 2 - split_z[0] ** 2 <= thr**2:
            i, j = 0, int(at[0])
    block_s, end = SUB * per / fs, t0 + (y.size - 1) / fs
    out = {
        "statistic": float(stat[0]),
        "threshold": thr,
        "p_value": float((1 + np.count_nonzero(null >= stat[0])) / (null.size + 1)),
        "rejected": bool(stat[0] > thr),
        "blocks": k,
    }
    if i == 0 or j == k:  # a split: the run reaches an end of the record
        cut = j if i == 0 else i
        ratio = float(np.exp((x[0, cut:].mean() - x[0, :cut].mean()) / 2.0))
        split = t0 + cut * block_s
        sides = {"left_s": (t0, split), "right_s": (split, end)}
        return out | {"split_s": split, "ratio": ratio, "stretch_s": None} | sides
    inside = np.zeros(k, dtype=bool)
    inside[i:j] = True
    ratio = float(np.exp((x[0, inside].mean() - x[0, ~inside].mean()) / 2.0))
    lo, hi = t0 + i * block_s, t0 + j * block_s
    return out | {"split_s": lo, "left_s": (t0, lo), "right_s": (hi, end), "ratio": ratio, "stretch_s": (lo, hi)}
