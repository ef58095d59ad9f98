"""Is the noise level the same along the record? A calibrated homogeneity test of the Allan variance at τ₀.

A record whose white-noise level steps or drifts has, over the whole record, the Allan curve of a stationary
noise at the mean level: the fit of the curve cannot see it. Along the record it is plain. The Allan variance
at τ₀ is half the mean of the squared first differences dᵢ = yᵢ₊₁ − yᵢ; differencing takes the slow terms
(flicker, random walk, a drift) nearly out of it, so it measures the fast noise's level in any stretch.

The test: ``n_blocks`` blocks along the record, each cut into ``SUB`` sub-blocks; xₖ is the log of block k's
mean d², and its variance is estimated from the scatter of the log mean d² of its sub-blocks (batch means:
the squared differences' correlation — a filter's, a flicker term's — is in it, whatever its shape, as long
as it is shorter than a sub-block; a level change from one block to the next is not). The statistic is the
largest standardised CUSUM of the xₖ, max over splits j of |Σₖ≤ⱼ (xₖ − x̄)| / √(v̂·j(K − j)/K), v̂ the
pooled variance; its null distribution — which depends only on (K, SUB) — is simulated once, studentised the
same way (Gaussian sub-block values), and the threshold is its (1 − α) quantile. The split j of the maximum is
where the level changes most, and exp((x̄_right − x̄_left)/2) the ratio of the Allan deviations at τ₀ of the
two sides.
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


def _cusum_max(x: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For rows of block levels ``x`` (draws, K) with pooled variances ``v`` (draws,): the largest standardised
    CUSUM of each row and the split (number of blocks on the left) where it is reached."""
    k = x.shape[1]
    s = np.cumsum(x - x.mean(axis=1, keepdims=True), axis=1)[:, :-1]
    j = np.arange(1, k)
    z = np.abs(s) / np.sqrt(np.maximum(v, 1e-300)[:, None] * j * (k - j) / k)
    at = np.argmax(z, axis=1)
    return z[np.arange(x.shape[0]), at], at + 1


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
            out.append(_cusum_max(x, v)[0])
        _NULL[key] = np.sort(np.concatenate(out)[:draws])
    return _NULL[key]


def level_test(y: np.ndarray, fs: float, alpha: float, t0: float = 0.0) -> dict | None:
    """The homogeneity test of the Allan variance at τ₀ along the samples ``y`` (rate ``fs``; ``t0`` the time of
    the first sample, s), at false-alarm probability ``alpha``; None where the record is too short for
    :data:`MIN_BLOCKS` blocks (or a sub-block's differences are all zero: a constant stretch).

    Returns ``statistic``, ``threshold``, ``p_value`` (share of null draws at or above the statistic, +1 over
    draws + 1), ``rejected``, ``split_s`` (time of the split), ``left_s`` / ``right_s`` (t ranges, s) and
    ``ratio`` (Allan deviation at τ₀ right over left), ``blocks``.

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(3)
    >>> y = np.concatenate([rng.standard_normal(50_000), 2 * rng.standard_normal(50_000)])
    >>> r = level_test(y, 10.0, 0.001)
    >>> r["rejected"], round(r["split_s"]), round(r["ratio"], 1)
    (True, 4992, 2.0)
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
    stat, split = _cusum_max(x, v)
    null = null_statistics(k)
    thr_at = int(np.ceil((null.size + 1) * (1.0 - alpha) - 1e-9))
    thr = float(null[min(thr_at, null.size) - 1])
    j = int(split[0])
    block_s = SUB * per / fs
    return {
        "statistic": float(stat[0]),
        "threshold": thr,
        "p_value": float((1 + np.count_nonzero(null >= stat[0])) / (null.size + 1)),
        "rejected": bool(stat[0] > thr),
        "split_s": t0 + j * block_s,
        "left_s": (t0, t0 + j * block_s),
        "right_s": (t0 + j * block_s, t0 + (y.size - 1) / fs),
        "ratio": float(np.exp((x[0, j:].mean() - x[0, :j].mean()) / 2.0)),
        "blocks": k,
    }
