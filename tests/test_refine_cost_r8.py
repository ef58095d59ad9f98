"""refine's speed-ups of round r8cost give the numbers of the computations they stand for, bit for bit.

The line search's F thresholds (one quantile per distinct median dof, not per bin) against the per-bin quantiles;
the outlier flags off both neighbours with the record summed once for every cut and the flagged stretches found
from their indices, against the per-cut sums and the passes over the record; a filtered white noise's Allan
variance with its lag weights 2m − 3l where m reaches every lag, against the three triangles everywhere; the
line search's row medians (of every neighbour, and of those left unmasked) and the steps check's medians of its
increments by one sort, against ``np.median`` and ``np.nanmedian``.
No timings here: ``benches/bench_refine_cost.py``.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import f as f_dist

import allanite
from allanite.model import _medians, effects, lines, outliers


def test_line_thresholds_equal_the_per_bin_quantiles():
    y = allanite.simulate(200_000, 100.0, N=1e-3, B=1e-4, sinusoid=[(2e-3, 3.3), (1e-3, 0.71)], seed=1)
    passes = lines.line_spectrum(y, 100.0)
    for ps in passes:
        mask = np.zeros(ps["p"].size, dtype=bool)
        mask[40:60] = mask[900:905] = True  # other lines' lobes: the medians' dof then vary bin by bin
        for noise, dof_med in ((ps["noise"], ps["dof_med"]), lines._noise(ps, mask)):
            got = dict(ps, noise=noise, dof_med=dof_med)
            ok = np.isfinite(noise)
            assert 1 < np.unique(dof_med[ok]).size < ok.sum()
            for a in (1e-3, 1e-9):
                want = np.full(ps["p"].size, np.inf)
                want[ok] = f_dist.isf(a, ps["dof_bin"][ok], dof_med[ok])  # the Welch dof per bin (r9blind7)
                np.testing.assert_array_equal(lines._peaks(got, a)[2], want)


def _stretch_check_by_passes(y, flags, cut_d):  # outliers._stretch_check before round r8cost
    edge = np.diff(np.concatenate([[0], flags.astype(np.int8), [0]]))
    starts, stops = np.flatnonzero(edge == 1), np.flatnonzero(edge == -1)
    long = stops - starts > 1
    out = flags.copy()
    for a, b in zip(starts[long], stops[long]):
        if a == 0 or b >= y.size:
            continue
        lo, hi = sorted((y[a - 1], y[b]))
        out[a:b] = (y[a:b] > hi + cut_d[a - 1]) | (y[a:b] < lo - cut_d[a - 1])
    return out


def test_flags_off_both_neighbours_equal_the_passes_over_the_record():
    rng = np.random.default_rng(8)
    y = np.cumsum(rng.standard_normal(40_000)) * 0.05 + rng.standard_normal(40_000)
    spikes = rng.integers(1, y.size - 5, 120)
    for k, at in enumerate(spikes):  # lone spikes, bursts of 2–4 of one sign, spikes at the ends
        y[at : at + 1 + k % 4] += (8 + k % 5) * (1 if k % 2 else -1)
    y[0] += 9
    y[-2:] -= 9
    d = np.diff(y)
    cut_d = np.full(d.size, 4.0)
    for flags in (rng.random(y.size) < 0.3, np.zeros(y.size, dtype=bool), np.ones(y.size, dtype=bool)):
        np.testing.assert_array_equal(
            outliers._stretch_check(y, flags, cut_d), _stretch_check_by_passes(y, flags, cut_d)
        )
    step, blocks = outliers.lattice_step(d), outliers._blocks(d.size)
    sig = np.array([outliers.robust_sigma(d[b], step) for b in blocks])
    for c in outliers.FLAG_CUTS:
        plain = outliers._flags(d, blocks, sig, step, c, None)
        summed = outliers._flags(d, blocks, sig, step, c, None, outliers._summed(d))
        np.testing.assert_array_equal(summed[0], plain[0])
        assert summed[1:] == plain[1:]
    assert outliers._flags(d, blocks, sig, step, 4.0, None)[0].sum() >= 100


def _filtered_white_avar_triangles(tau, kind, p, fs):  # effects.filtered_white_avar's FIR form before r8cost
    m = np.maximum(1.0, np.round(np.atleast_1d(tau) * fs))
    r = effects.filter_autocorrelation(kind, p, fs)
    lag = np.arange(r.size, dtype=np.float64)

    def tri(x):
        return np.maximum(0.0, m[:, None] - np.abs(x))

    a = 2.0 * tri(lag[None, :]) - tri(lag[None, :] - m[:, None]) - tri(lag[None, :] + m[:, None])
    w = np.full(r.size, 2.0)
    w[0] = 1.0
    return a @ (w * r) / (2.0 * m * m) * fs


@pytest.mark.parametrize("fs", [100.0, 2000.0])
def test_filtered_white_columns_equal_the_triangle_sums(fs):
    tau = np.geomspace(0.5 / fs, 2e4 / fs, 241)
    kinds = [("single_pole", 0.016 * fs), ("boxcar", 1.33), ("boxcar", 40.3), ("sinc3", 0.69), ("bartlett", 7.0)]
    kinds += [("moving_average", 3.0), ("single_pole+boxcar:1.5", 0.016 * fs)]
    for kind, p in kinds:
        for t in (tau, tau[:3], tau[-2:]):
            want = _filtered_white_avar_triangles(t, kind, p, fs)
            np.testing.assert_array_equal(effects.filtered_white_avar(t, kind, p, fs), want)


def test_row_nanmedian_equals_numpys():
    rng = np.random.default_rng(4)
    for shape in [(3000, 16), (500, 7), (200, 64), (1, 2)]:
        v = rng.lognormal(size=shape)
        v[rng.random(shape) < 0.4] = np.nan
        v[:, 0] = 1.5  # a number in every row
        v[0, 1:] = np.nan  # one number alone
        if shape[1] > 3:
            v[-1] = np.where(np.isnan(v[-1]), np.nan, 2.0)  # ties
        np.testing.assert_array_equal(_medians.nanmedian_rows(v), np.nanmedian(v, axis=1))


def test_median_by_sort_equals_numpys():
    rng = np.random.default_rng(6)
    for shape in [(254, 64), (253, 40), (1, 9), (40, 16), (7, 1)]:
        a = rng.standard_normal(shape)
        a[: min(3, shape[0]), 0] = 0.25  # ties
        for axis in (0, 1):
            np.testing.assert_array_equal(_medians.median_by_sort(a, axis), np.median(a, axis=axis))
        a[min(3, shape[0] - 1), 0] = np.nan  # NaN where np.median gives NaN
        with np.errstate(invalid="ignore"):
            for axis in (0, 1):
                np.testing.assert_array_equal(_medians.median_by_sort(a, axis), np.median(a, axis=axis))
