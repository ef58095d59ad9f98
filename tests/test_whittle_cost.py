"""The Whittle noise fit behind the channel regression's tests (:mod:`allanite.model._whittle`) at its cost: its NNLS
called without SciPy's wrapper (the same numbers and errors), and the coupling bootstrap's draws fitted in the Rust
core (``allanite._core.whittle_noise``: the same loop, the numbers to rounding). The memories of its fits and
Bartlett factors: ``test_refine_recent.py``."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import nnls as scipy_nnls

import allanite
from allanite import _core


def test_whittle_noise_fit_nnls_equals_scipy_and_keeps_its_errors():
    from allanite.model import _whittle as wh

    rng = np.random.default_rng(6)
    for _ in range(20):  # a noise fit's weighted problems: band powers on a few non-negative shapes
        a = np.abs(rng.standard_normal((80, 12))) * rng.uniform(0.1, 10.0, 80)[:, None]
        b = a @ np.abs(rng.standard_normal(12)) * rng.exponential(1.0, 80) - rng.uniform(0, 1, 80)
        np.testing.assert_array_equal(wh._lawson_hanson(a, b, 600), scipy_nnls(a, b, maxiter=600)[0])
    a[5, 3] = np.inf
    with pytest.raises(ValueError, match="infs or NaNs"):
        wh._lawson_hanson(a, b, 600)


@pytest.mark.skipif(getattr(_core, "whittle_noise", None) is None, reason="the compiled core lacks whittle_noise")
def test_compiled_whittle_noise_fit_equals_python_to_rounding(monkeypatch):
    """The coupling bootstrap's draws fit their noise in the Rust core (``Bands.compiled``): the same loop with the
    core's Lawson–Hanson NNLS — amounts and levels to rounding, the Bartlett factors to 1e-9, SciPy's errors."""
    from allanite.model import _coupling
    from allanite.model import _whittle as wh

    rng = np.random.default_rng(11)
    n = 8000
    temp = np.cumsum(rng.standard_normal(n)) * 0.02
    y = allanite.simulate(n, 10.0, N=1e-3, B=3e-4, K=2e-5, seed=rng)
    bands = wh.spectra(y, [temp - temp.mean()], 10.0)
    m, basis = bands.m[bands.par], bands.basis
    for k in range(6):  # the record's power and null draws of it, cold and warm
        b = bands if k == 0 else _coupling._null_bands(bands, bands.q / bands.m, rng)
        power = b.q[b.par] / m
        for start in (None, wh._fit_noise(power, m, basis, None)[0]):
            ref = wh._fit_noise(power, m, basis, start, False)
            got = wh._fit_noise(power, m, basis, start, True)
            np.testing.assert_allclose(got[1], ref[1], rtol=1e-9)
            np.testing.assert_allclose(got[0], ref[0], rtol=1e-7, atol=1e-9 * float(np.max(ref[0] * basis.max(0))))
    bad = bands.q[bands.par] / m
    bad[2] = np.nan
    with pytest.raises(ValueError, match="infs or NaNs"):
        wh._fit_noise(bad, m, basis, None, True)
    monkeypatch.setattr(_coupling, "BOOT_DRAWS", 40)
    null = wh.joint_fit(bands, wh.Design([], []))
    compiled = _coupling._bootstrap_scale(bands, null, 0)
    monkeypatch.setattr(wh, "COMPILED", None)
    np.testing.assert_allclose(compiled, _coupling._bootstrap_scale(bands, null, 0), rtol=1e-9)
