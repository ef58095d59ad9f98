"""refine's compiled shortcuts agree with the Python they replace, to rounding (issue 29, refine's cost).

- The reweighted NNLS of a curve on many designs in the Rust core (``allanite._core.irls_curves``) against the
  Python loop (``_irls.irls_python``, itself checked bit for bit against the plain one-design IRLS in
  ``tests/test_refine_cost.py``): grids of every curve effect, with and without lines held at their power;
  its errors are SciPy's (a non-finite problem, an NNLS that does not settle).
- The χ² marginals of :class:`allanite.model.tracing.ScoreTest`'s draws from a table per ν
  (:mod:`allanite.model._chi2_draws`) against the quantile computed value by value.

The refine-level bound (the 36 ADIS16405 records and the simulated sensors, field by field against main) is in
``benches/results/refine_cost.md``.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.special import gammaincinv, ndtr

import allanite
from allanite.model import _chi2_draws
from allanite.model.refinement import _irls, curvefit
from allanite.model.refinement.candidates import bandwidth_grids

START = ("Q", "N", "B", "K", "R")
needs_core = pytest.mark.skipif(_irls.COMPILED is None, reason="the compiled core has no irls_curves")


@pytest.fixture(scope="module")
def curve():
    y = allanite.simulate(300_000, 200.0, N=3e-3, B=2e-4, K=1e-5, gauss_markov=[(3e-3, 1.5)], seed=11)
    res = allanite.avar(y, 200.0, taus=allanite.tau_grid(y.size, 200.0, "exp", points=220, m_max=y.size // 9))
    keep = res.avar > 0
    return curvefit.Curve(res.tau[keep], res.m[keep].astype(float), res.avar[keep], 200.0, y.size + 1, "oavar")


def _grids(curve):
    kind, bw = next(iter(bandwidth_grids(curve).items()))
    return [
        ("gauss_markov", np.geomspace(0.05, 500.0, 25)),
        ("resonance:16", np.geomspace(2.0, 90.0, 25)),
        ("sinusoid", np.geomspace(0.02, 90.0, 25)),
        (f"bandwidth:{kind}", bw),
    ]


def _both(curve, models, max_iter):
    a, nu_cols = curvefit._stacked(curve, START, models)
    held = curvefit._held(START, models[0]) or None
    nu0, floor = nu_cols[0][:, 1], 1e-12 * np.max(curve.avar)
    got = _irls.COMPILED and _irls.irls(a, nu_cols, curve.avar, nu0, max_iter, floor, held)
    want = _irls.irls_python(a, nu_cols, curve.avar, nu0, max_iter, floor, held)
    chi2 = [
        [_irls.chi2_at(curve.avar, a[g], th[g], nu[g], floor) for g in range(len(models))] for th, nu in (got, want)
    ]
    return got, want, chi2


@needs_core
@pytest.mark.parametrize("max_iter", [6, 40])
@pytest.mark.parametrize("held", [False, True])
def test_compiled_irls_agrees_with_the_python_loop(curve, max_iter, held):
    line = float(np.median(curve.avar)) * 0.2
    before = [(curvefit.held_key("sinusoid", line, 0.01 * line**2), 3.0)] if held else [("gauss_markov", 2.0)]
    n_designs = 0
    for key, grid in _grids(curve):
        models = [before + [(key, float(p))] for p in grid]
        (th_c, nu_c), (th_p, nu_p), (chi2_c, chi2_p) = _both(curve, models, max_iter)
        # the same coefficients at zero, the others and ν to rounding (a pass more or less where a
        # coefficient's change sits at RTOL would move them by ≲ RTOL: not met on these grids)
        np.testing.assert_array_equal(th_c > 0, th_p > 0)
        np.testing.assert_allclose(th_c, th_p, rtol=1e-9, atol=0)
        np.testing.assert_allclose(nu_c, nu_p, rtol=1e-9, atol=0)
        np.testing.assert_allclose(chi2_c, chi2_p, rtol=1e-9, atol=0)
        if held:
            assert np.all(th_c[:, len(START)] == line)
        n_designs += len(models)
    assert n_designs >= 90


@needs_core
def test_one_design_alone_gives_its_batch_numbers(curve):
    models = [[("gauss_markov", float(p))] for p in np.geomspace(0.1, 100.0, 9)]
    a, nu_cols = curvefit._stacked(curve, START, models)
    nu0, floor = nu_cols[0][:, 1], 1e-12 * np.max(curve.avar)
    theta, nu = _irls.irls(a, nu_cols, curve.avar, nu0, 40, floor)
    for g in (0, 4, 8):
        th1, nu1 = _irls.irls(a[g : g + 1], nu_cols[g : g + 1], curve.avar, nu0, 40, floor)
        np.testing.assert_array_equal(th1[0], theta[g])
        np.testing.assert_array_equal(nu1[0], nu[g])


@needs_core
def test_compiled_irls_keeps_scipys_errors(curve):
    models = [[("gauss_markov", 1.0)], [("gauss_markov", 2.0)]]
    a, nu_cols = curvefit._stacked(curve, START, models)
    nu0, floor = nu_cols[0][:, 1], 1e-12 * np.max(curve.avar)
    bad = a.copy()
    bad[1, 3, 2] = np.nan
    with pytest.raises(ValueError, match="array must not contain infs or NaNs"):
        _irls.irls(bad, nu_cols, curve.avar, nu0, 40, floor)
    nu_bad = nu0.copy()
    nu_bad[5] = np.inf  # an infinite weight
    with pytest.raises(ValueError, match="array must not contain infs or NaNs"):
        _irls.irls(a, nu_cols, curve.avar, nu_bad, 40, floor)
    with pytest.raises(allanite.AllaniteError, match="nu_cols must be shaped as design"):
        _irls.COMPILED(
            a,
            np.ascontiguousarray(nu_cols[:, :-1]),
            curve.avar,
            np.ascontiguousarray(nu0),
            np.full(a.shape[2], np.nan),
            40,
            floor,
            _irls.RTOL,
        )


@pytest.mark.parametrize("nu_lo, nu_hi", [(0.05, 1.0), (1.0, 60.0), (60.0, 1e9)])
def test_chi2_draws_from_the_table_agree_with_the_quantile(nu_lo, nu_hi):
    rng = np.random.default_rng(2)
    z = rng.standard_normal((40, 1000))
    z[0, :2] = (-4.9, 4.9)  # the tails a draw of 40 000 reaches
    nu = np.geomspace(nu_lo, nu_hi, 40)
    want = 2.0 * gammaincinv(0.5 * nu[:, None], ndtr(z)) / nu[:, None]
    got = _chi2_draws.scaled_quantiles(z, nu)
    np.testing.assert_allclose(got, want, rtol=1e-6, atol=0)
    # too few draws per row for a table: the values one by one, bit for bit
    np.testing.assert_array_equal(_chi2_draws.scaled_quantiles(z[:, :100], nu), want[:, :100])
