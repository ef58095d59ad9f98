"""refine's compiled shortcuts agree with the Python they replace, to rounding (issue 29, refine's cost).

- The reweighted NNLS of a curve on many designs in the Rust core (``allanite._core.irls_curves``) against the
  Python loop (``_irls.irls_python``, itself checked bit for bit against the plain one-design IRLS in
  ``tests/test_refine_cost.py``): grids of every curve effect, with and without lines held at their power;
  its errors are SciPy's (a non-finite problem, an NNLS that does not settle).
- The line families' two passes over the samples in the Rust core (``allanite._core.phase_bins``,
  ``add_waveform``, used by :mod:`allanite.model.linefit`) against NumPy's: the folding, the DTFT (one and
  two generators, in segments) and the waveform, bit for bit (a sideband waveform to 1e-13: NumPy's complex
  product may fuse a multiply-add); their bad input is refused by name.
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
from allanite import _core
from allanite.errors import AllaniteError
from allanite.model import _chi2_draws, linefit
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


needs_grid = pytest.mark.skipif(linefit._BINS is None, reason="the compiled core has no phase_bins")

_FAMILIES = [
    (np.array([0.0123]), np.arange(1, 40)[:, None]),  # harmonics: the real path
    (np.array([0.031, 0.0047]), np.array([[k, s] for k in (1, 2, 30) for s in (-2, -1, 0, 1, 2)])),  # sidebands
]


def _numpy_path(monkeypatch):
    monkeypatch.setattr(linefit, "_BINS", None)
    monkeypatch.setattr(linefit, "_WAVE", None)


@needs_grid
@pytest.mark.parametrize("n_seg", [1, 32])
def test_compiled_line_passes_equal_numpys(monkeypatch, n_seg):
    rng = np.random.default_rng(12)
    n = 70_001
    y = rng.standard_normal(n)
    idx = np.flatnonzero(rng.random(n) > 0.1)  # held-in samples: runs with gaps
    u = np.mod(np.arange(n) * 0.1234567, 1.0)
    u[:3] = [0.0, np.nextafter(1.0, 0.0), 0.5]  # the last phase bin wraps to the first
    seg = None if n_seg == 1 else np.minimum(np.arange(n) * n_seg // n, n_seg - 1)
    z = y + 1j * rng.standard_normal(n)
    got = [linefit._fold(z, u, 4096, seg, n_seg), linefit._fold(y, u, 2**14, seg, n_seg)]
    for gens, coefs in _FAMILIES:
        a, b = rng.standard_normal(coefs.shape[0]), rng.standard_normal(coefs.shape[0])
        got += [linefit.dtft(y[idx], idx, gens, coefs, n_seg), linefit.evaluate(idx, gens, coefs, a, b)]
    rng = np.random.default_rng(12)  # the same draws again, NumPy's passes
    rng.standard_normal(n), rng.random(n), rng.standard_normal(n)
    with monkeypatch.context() as mp:
        _numpy_path(mp)
        want = [linefit._fold(z, u, 4096, seg, n_seg), linefit._fold(y, u, 2**14, seg, n_seg)]
        for gens, coefs in _FAMILIES:
            a, b = rng.standard_normal(coefs.shape[0]), rng.standard_normal(coefs.shape[0])
            want += [linefit.dtft(y[idx], idx, gens, coefs, n_seg), linefit.evaluate(idx, gens, coefs, a, b)]
    for i, (g, w) in enumerate(zip(got, want, strict=True)):
        if i == 5 or (i == 4 and not _numpy_fuses()):
            # a sideband waveform: NumPy's complex product may fuse a multiply-add (x86 SIMD), the core's sum not; a
            # sideband DTFT: the core's lattice phasors are the fused products, NumPy's where its product fuses
            np.testing.assert_allclose(g, w, rtol=0, atol=1e-13 * np.max(np.abs(w)))
        else:  # the gridding, the DTFT and a real waveform: the same operations in the same order
            np.testing.assert_array_equal(g, w)
    assert np.std(got[-1]) > 1.0 and np.max(np.abs(got[2])) > 10.0  # real waveforms and sums, not zeros


def _numpy_fuses() -> bool:
    """Whether NumPy's complex product here is (fma(a.re, b.re, −a.im·b.im), fma(a.re, b.im, a.im·b.re)) — its x86-64
    SIMD loop's — as the core's lattice phasors form it: checked on a few products against exact rationals."""
    from fractions import Fraction as F

    rng = np.random.default_rng(3)
    a, b = np.exp(2j * np.pi * rng.random(64)), np.exp(2j * np.pi * rng.random(64))
    c = a * b
    re = [float(F(x.real) * F(y.real) - F(x.imag * y.imag)) for x, y in zip(a, b)]
    im = [float(F(x.real) * F(y.imag) + F(x.imag * y.real)) for x, y in zip(a, b)]
    return bool(np.array_equal(c.real, re) and np.array_equal(c.imag, im))


@pytest.mark.skipif(getattr(_core, "lattice_bins", None) is None, reason="the compiled core has no lattice passes")
def test_lattice_phasors_made_in_the_core_equal_the_phasor_arrays(monkeypatch):
    """The sidebands' phasors e^{i2π|s|ν2 n} made per sample in the core (``linefit._Lattice``) against the arrays of
    ``linefit._phasor`` and its powers through the same compiled passes: the DTFT (one piece and 32) and the waveform
    on indices with gaps from a block past zero, powers 1–3, a negative s without its positive: bit for bit where
    NumPy's complex product fuses as the core's (x86-64), else to 1e-13."""
    rng = np.random.default_rng(8)
    n = 40_000
    idx = np.flatnonzero(rng.random(n) > 0.15)[3000:]
    y = rng.standard_normal(idx.size)
    gens = np.array([0.0291, 0.00437])
    coefs = np.array([[k, s] for k in (1, 2, 7) for s in (-3, -2, -1, 0, 1, 3)] + [[5, -4]])
    a, b = rng.standard_normal(coefs.shape[0]), rng.standard_normal(coefs.shape[0])

    def passes():
        return [linefit.dtft(y, idx, gens, coefs, n_seg) for n_seg in (1, 32)] + [
            linefit.evaluate(idx, gens, coefs, a, b)
        ]

    got = passes()
    with monkeypatch.context() as mp:
        mp.setattr(linefit, "_LBINS", None)
        mp.setattr(linefit, "_LWAVE", None)
        want = passes()
    for g, w in zip(got, want, strict=True):
        assert np.max(np.abs(w)) > 10.0  # sums over the samples, not zeros
        if _numpy_fuses():
            np.testing.assert_array_equal(g, w)
        else:
            np.testing.assert_allclose(g, w, rtol=0, atol=1e-13 * np.max(np.abs(w)))
    with pytest.raises(AllaniteError, match=r"lattice_bins: y and idx must be as long as u \(2\)"):
        _core.lattice_bins(np.ones(3), np.array([0.1, 0.5]), 8, None, 1, np.array([3100, 3200]), *_tables(3))
    with pytest.raises(AllaniteError, match="every index's block among the blocks"):
        _core.add_lattice_waveform(np.zeros(1), np.array([0.5]), np.ones(4), np.array([9000]), *_tables(3))


def _tables(k0):
    """Two blocks of 1024 unit phasors (interleaved), from block k0, power 1, not conjugated."""
    blocks, offsets = np.ones(2, dtype=complex), np.ones(1024, dtype=complex)
    return blocks.view(np.float64), offsets.view(np.float64), k0, 1, False


@needs_grid
def test_compiled_line_passes_refuse_bad_input():
    u = np.array([0.1, 0.5])
    with pytest.raises(AllaniteError, match=r"phase_bins: every part must be as long as u \(2\), u in \[0, 1\)"):
        _core.phase_bins([np.ones(3)], u, 8, None, 1)
    with pytest.raises(AllaniteError, match=r"seg in \[0, 2\)"):
        _core.phase_bins([np.ones(2)], u, 8, np.array([0, 2]), 2)
    with pytest.raises(AllaniteError, match="u in"):
        _core.phase_bins([np.ones(2)], np.array([0.1, 1.0]), 8, None, 1)
    with pytest.raises(AllaniteError, match="with ph one part and 2·2 phasor values"):
        _core.phase_bins([np.ones(2), np.ones(2)], u, 8, None, 1, np.ones(4))
    with pytest.raises(AllaniteError, match=r"add_waveform: u must be 2 phases in \[0, 1\), wave 2\(m \+ 1\)"):
        _core.add_waveform(np.zeros(2), u, np.ones(3), None)
    with pytest.raises(AllaniteError, match="ph 2·2 values"):
        _core.add_waveform(np.zeros(2), u, np.ones(4), np.ones(2))
    with pytest.raises(AllaniteError, match="u must be a C-contiguous float64 array"):
        _core.phase_bins([np.ones(2)], np.linspace(0, 0.9, 4)[::2], 8, None, 1)
