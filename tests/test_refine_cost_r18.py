"""refine's speed-ups of round r18cost give the numbers of the computations they stand for, bit for bit.

The χ² copula's Hermite table read in place (:func:`allanite.model._chi2_draws.scaled_quantiles`) against the
whole-array form it replaced; the line-constancy basis made part by part against the complex form; a line family's
refit evaluated once for equal indices against fresh ones. No timings here: ``benches/bench_refine_cost.py``.
"""

from __future__ import annotations

import numpy as np
import pytest

from allanite.model import _chi2_draws, linefit, periodic
from allanite.model._recent import remembering
from allanite.model.refinement import _line_constancy


def _hermite_whole_array(z, nu):
    """:func:`scaled_quantiles`'s interpolation as written before r18cost (``np.take_along_axis``, whole arrays)."""
    from scipy.special import gammaincinv, gammaln, ndtr, xlogy

    nodes = _chi2_draws.NODES
    half = 0.5 * nu[:, None]
    lo, hi = float(z.min()), float(z.max())
    zn = np.linspace(lo, hi, nodes)
    h = (hi - lo) / (nodes - 1)
    x = 2.0 * gammaincinv(half, ndtr(zn)[None, :])
    log_f = xlogy(half - 1.0, x) - 0.5 * x - half * np.log(2.0) - gammaln(half)
    g = np.log(x / nu[:, None])
    slope = np.exp(-0.5 * zn[None, :] ** 2 - 0.5 * np.log(2.0 * np.pi) - log_f - np.log(x)) * h
    t = (z - lo) / h
    j = np.minimum(t.astype(np.int64), nodes - 2)
    s = t - j
    s2, s3 = s * s, s * s * s
    g0, g1 = np.take_along_axis(g, j, 1), np.take_along_axis(g, j + 1, 1)
    d0, d1 = np.take_along_axis(slope, j, 1), np.take_along_axis(slope, j + 1, 1)
    return np.exp((2 * s3 - 3 * s2 + 1) * g0 + (s3 - 2 * s2 + s) * d0 + (3 * s2 - 2 * s3) * g1 + (s3 - s2) * d1)


@pytest.mark.parametrize("rows,draws,seed", [(63, 1000, 1), (7, 600, 2)])
def test_quantile_table_read_in_place_equals_the_whole_array_form(rows, draws, seed):
    rng = np.random.default_rng(seed)
    z = rng.standard_normal((rows, draws))
    nu = np.exp(rng.uniform(np.log(0.05), np.log(1e6), rows))
    got = _chi2_draws.scaled_quantiles(z, nu)
    assert np.array_equal(got, _hermite_whole_array(z, nu))
    assert got[0, 0] > 0 and np.all(np.isfinite(got))


def test_line_constancy_basis_equals_the_complex_form():
    fs, size, f0 = 100.0, 5000, 7.3
    k = np.arange(2, 6)
    freqs = np.concatenate([[f0], f0 - k * fs / size, f0 + k * fs / size])
    t = np.arange(size) / fs
    g, r, cov = _line_constancy._basis(t, freqs)
    # the form before r18cost: complex temporaries, divided by the real determinant
    rr = _line_constancy._taper(size)
    w = 2.0 * np.pi * freqs[:, None] * t[None, :]
    c, s = np.cos(w) * rr, np.sin(w) * rr
    rn = rr / np.linalg.norm(rr)
    c -= np.outer(c @ rn, rn)
    s -= np.outer(s @ rn, rn)
    cc, ss, cs = np.sum(c * c, 1), np.sum(s * s, 1), np.sum(c * s, 1)
    det = (cc * ss - cs**2)[:, None]
    g_ref = ((ss[:, None] * c - cs[:, None] * s) - 1j * (cc[:, None] * s - cs[:, None] * c)) / det
    gr = g_ref * rr
    assert np.array_equal(g, g_ref) and np.array_equal(r, rr) and np.array_equal(cov, gr @ gr.conj().T)
    with remembering():  # the same blocks and frequencies asked twice in a call: one basis, read-only
        first = _line_constancy._basis_of(size, fs, freqs)
        assert _line_constancy._basis_of(size, fs, freqs.copy()) is first and not first[0].flags.writeable
    assert np.array_equal(first[2], cov)


def test_a_refit_evaluated_twice_at_equal_indices_equals_fresh_ones():
    fs, n = 50.0, 40_000
    idx = np.arange(n)
    rng = np.random.default_rng(3)
    y = 0.3 * np.cos(2 * np.pi * 1.7 * idx / fs + 0.4) + 0.1 * np.cos(2 * np.pi * 3.4 * idx / fs) + rng.normal(size=n)
    gens, coefs = np.array([1.7]), np.array([[1], [2]])
    a, b = linefit.solve(y, idx, gens / fs, coefs)
    fam = periodic.LineFamily(fs, gens, np.zeros((1, 1)), coefs, a, b, np.ones(2), np.ones(2, bool), n)
    held_in, held_out = idx[: n // 2], idx[n // 2 :]
    with remembering():
        g = fam.refit(y[held_in], held_in)
        first = g(held_out)
        first[:] = 0.0  # a fresh array each time: the one remembered is not the caller's
        again = fam.refit(y[held_in], held_in)(held_out.copy())
    a_in, b_in = linefit.solve(y[held_in], held_in, gens / fs, coefs)
    assert np.array_equal(again, linefit.evaluate(held_out, gens / fs, coefs, a_in, b_in))
    assert abs(float(np.max(np.abs(again))) - 0.4) < 0.05  # the two lines' peak, refitted on the first half
