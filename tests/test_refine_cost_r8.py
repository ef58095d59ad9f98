"""refine's speed-ups of round r8cost give the numbers of the computations they stand for, bit for bit.

The line search's F thresholds (one quantile per distinct median dof, not per bin) against the per-bin quantiles.
No timings here: ``benches/bench_refine_cost.py``.
"""

from __future__ import annotations

import numpy as np
from scipy.stats import f as f_dist

import allanite
from allanite.model import lines


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
                want[ok] = f_dist.isf(a, ps["dof"], dof_med[ok])
                np.testing.assert_array_equal(lines._peaks(got, a)[2], want)
