"""A short burst of louder noise is a change of level, not outliers (allanite.model._robust_scale.burst_scales, r12burst).

``benches/refine_blind9.py``'s truck (white noise 3× for 6000 of 5·10⁵ samples) straddled two blocks of the
outliers test's local scale, each block's median the quiet noise's: the burst's own Gaussian tail read as spikes
and 296 samples were removed before its two change points. Judged at a fine block's scale where a fine block is
louder than its block, the burst is Gaussian; sparse spikes, in it or beside it, are still flagged.
"""

from __future__ import annotations

import numpy as np

from allanite.model import _robust_scale, outliers

ALPHA = 0.0025  # the outliers test's share of refine's level
SIGMA = 0.01


def _burst(seed, n=100_000, start=5 * _robust_scale.LOCAL_BLOCK - 1500, length=3000, ratio=3.0, walk=0.0):
    """White noise (plus a random walk of step ``walk``) whose white part is ``ratio``× louder for ``length``
    samples from ``start`` — across the boundary of two blocks of the local scale."""
    rng = np.random.default_rng(seed)
    y = SIGMA * rng.standard_normal(n)
    y[start : start + length] *= ratio
    return y + walk * np.cumsum(rng.standard_normal(n))


def test_a_short_burst_is_no_outliers():
    for seed in range(3):  # main (local_scales alone): accepted on each, 246–336 samples flagged
        r = outliers.outlier_test(_burst(seed), 50.0, ALPHA)
        assert not r["accepted"]
        c4 = r["cuts"][0]
        assert c4["count"] < 2.0 * c4["expected"] + 5  # the Gaussian count at 4 σ (main: 182–232 against 6.3)
    # a record that is not white at the shortest lag (the rule off both neighbours): the same
    r = outliers.outlier_test(_burst(7, walk=0.02), 50.0, ALPHA)
    assert not r["accepted"]


def test_spikes_beside_and_inside_a_burst_are_still_flagged():
    y = _burst(11)
    rng = np.random.default_rng(12)
    quiet = rng.choice(np.arange(60_000, 99_000), 15, replace=False)
    loud = rng.choice(
        np.arange(5 * _robust_scale.LOCAL_BLOCK - 1400, 5 * _robust_scale.LOCAL_BLOCK + 1400), 5, replace=False
    )
    sign = np.where(rng.random(20) < 0.5, -1.0, 1.0)
    y[quiet] += 8.0 * SIGMA * sign[:15]  # 8 σ of the quiet noise
    y[loud] += 3.0 * 8.0 * SIGMA * sign[15:]  # 8 σ of the burst's
    r = outliers.outlier_test(y, 50.0, ALPHA)
    assert r["accepted"]
    flagged = set(np.flatnonzero(r["flags"]).tolist())
    assert set(quiet.tolist()) <= flagged and set(loud.tolist()) <= flagged
    assert len(flagged) - 20 <= 3  # few Gaussian samples beside them (main: the burst's tail too)


def test_burst_scales_are_the_local_scales_without_a_burst_and_the_bursts_own_in_it():
    rng = np.random.default_rng(3)
    x = rng.standard_normal(12 * _robust_scale.LOCAL_BLOCK)
    blocks, local = _robust_scale.local_scales(x, 0.0)
    fine_blocks, fine = _robust_scale.burst_scales(x, 0.0)
    assert fine_blocks == blocks and np.array_equal(fine, local)  # noise of one level: the very same
    x[40_000:43_000] *= 3.0  # inside block 4 (32 768 … 40 959) and 5
    blocks, local = _robust_scale.local_scales(x, 0.0)
    fine_blocks, fine = _robust_scale.burst_scales(x, 0.0)
    mid = np.array([(b.start + b.stop) // 2 for b in fine_blocks])
    inside = (mid > 40_000) & (mid < 43_000)
    assert inside.any() and np.all(np.abs(fine[inside] / 3.0 - 1.0) < 0.15)  # the burst's own σ
    kept = {b.start: s for b, s in zip(blocks, local)}
    whole = [k for k, b in enumerate(fine_blocks) if b in blocks]
    assert len(whole) == len(blocks) - 2  # only the two blocks the burst is in are cut into fine blocks
    assert all(fine[k] == kept[fine_blocks[k].start] for k in whole)  # every other block: its local scale
    # a block with dense spikes keeps its scale unless they are most of a fine block's samples: 5 % here
    y = rng.standard_normal(4 * _robust_scale.LOCAL_BLOCK)
    y[10_000:10_512:20] += 50.0
    b2, s2 = _robust_scale.local_scales(y, 0.0)
    assert _robust_scale.burst_scales(y, 0.0)[0] == b2


def test_burst_scales_on_a_lattice():
    rng = np.random.default_rng(4)
    step = 1.0
    x = np.round(2.0 * rng.standard_normal(6 * _robust_scale.LOCAL_BLOCK) + rng.random()) * step
    blocks, local = _robust_scale.local_scales(x, step)
    assert _robust_scale.burst_scales(x, step)[0] == blocks  # one level: no fine block loud
    x[20_000:23_000] = np.round(6.0 * rng.standard_normal(3000))
    fine_blocks, fine = _robust_scale.burst_scales(x, step)
    mid = np.array([(b.start + b.stop) // 2 for b in fine_blocks])
    inside = (mid > 20_000) & (mid < 23_000)
    assert inside.any() and np.all(np.abs(fine[inside] / 6.0 - 1.0) < 0.15)


def test_no_fine_block_is_loud_on_a_low_pass_or_a_wandering_lattice():
    """Shares of a low-passed record's differences (they move together) and of a quantised random walk (its
    offsets not uniform over 512 samples) scatter beyond the binomial's: the threshold follows their own spread.
    Against the binomial standard error alone, the fine blocks in the comments were split (seeds 21–23)."""
    from scipy import signal

    rng = np.random.default_rng(21)
    b, a = signal.butter(2, 0.02)
    d = np.diff(signal.lfilter(b, a, rng.standard_normal(200_000)))
    assert _robust_scale.burst_scales(d, 0.0)[0] == _robust_scale.local_scales(d, 0.0)[0]  # binomial: 120–165
    walk = np.cumsum(0.02 * rng.standard_normal(200_000)) + 0.3 * rng.standard_normal(200_000)
    q = np.diff(np.round(walk))
    assert _robust_scale.burst_scales(q, 1.0)[0] == _robust_scale.local_scales(q, 1.0)[0]  # 210–300 fine blocks
    d[100_000:103_000] *= 3.0  # and a burst on the low-pass is still found
    assert len(_robust_scale.burst_scales(d, 0.0)[0]) > len(_robust_scale.local_scales(d, 0.0)[0])
