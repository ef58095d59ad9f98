"""The resonance's two shapes (``allanite.model.effects.resonance_avar``): the Lorentzian pair and the band-pass
digital resonator, each against the exact Allan variance of the process it describes, and refine's choice
between them on a short simulated record of each (``refinement._bumps._shape_test``)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

import allanite
from allanite.errors import ParameterError
from allanite.model.effects import resonance_avar
from allanite.model.refinement._bumps import bandpass_chain_kept, bandpass_named
from allanite.model.refinement.curvefit import res_kind

FS = 400.0


def _lag_sum(r: np.ndarray, m: int) -> float:
    """σ²(m) = Σ_l A_m(l)·R(l)/2m² of a unit-variance process with autocorrelation ``r`` at lags 0, 1, …"""
    lag = np.arange(-(r.size - 1), r.size)
    rr = r[np.abs(lag)]
    tri = lambda x: np.maximum(0, m - np.abs(x))  # noqa: E731
    return float(np.sum((2 * tri(lag) - tri(lag - m) - tri(lag + m)) * rr) / (2 * m * m))


def _bandpass_r(f_r: float, q: float, fs: float, n: int = 6000) -> np.ndarray:
    """Autocorrelation (per unit variance) of white noise through ``iirpeak(f_r, q)``, from its impulse response."""
    b, a = signal.iirpeak(f_r, q, fs=fs)
    h = signal.lfilter(b, a, np.r_[1.0, np.zeros(n - 1)])
    r = np.correlate(h, h, mode="full")[n - 1 :]
    return r / r[0]


@pytest.mark.parametrize("f_r,q", [(60.0, 8.0), (15.0, 2.0), (150.0, 16.0), (190.0, 4.0)])
def test_both_shapes_are_the_exact_allan_variance_of_their_process(f_r, q):
    lag = np.arange(6000)
    lor = np.exp(-np.pi * f_r * lag / (q * FS)) * np.cos(2 * np.pi * f_r * lag / FS)
    bp = _bandpass_r(f_r, q, FS)
    for m in (1, 2, 3, 7, 40, 300):
        assert resonance_avar(m / FS, f_r, q, FS)[0] == pytest.approx(_lag_sum(lor, m), rel=1e-9, abs=1e-15)
        assert resonance_avar(m / FS, f_r, q, FS, "bandpass")[0] == pytest.approx(_lag_sum(bp, m), rel=1e-7, abs=1e-15)


def test_the_shapes_tails_white_like_and_falling_as_tau_squared():
    # the Lorentzian pair's PSD is not zero at DC (a 1/τ tail, like N's); the band-pass one's is (1/τ²): 10× the
    # τ gives 1/10 and 1/100 of the Allan variance, well past 1/f_r (0.0997 and 0.0100 at τ 20 → 200 s)
    tau = np.array([20.0, 200.0])
    lor = resonance_avar(tau, 60.0, 8.0, FS)
    bp = resonance_avar(tau, 60.0, 8.0, FS, "bandpass")
    assert lor[1] / lor[0] == pytest.approx(0.1, rel=5e-3)
    assert bp[1] / bp[0] == pytest.approx(0.01, rel=1e-6)


def test_bandpass_matches_a_simulated_resonator():
    b, a = signal.iirpeak(60.0, 8.0, fs=FS)
    y = signal.lfilter(b, a, np.random.default_rng(3).standard_normal(400_000))[2000:]
    tau = np.array([1, 2, 3, 5, 10]) / FS
    got = allanite.avar(y, FS, taus=tau).avar / y.var()
    np.testing.assert_allclose(got, resonance_avar(tau, 60.0, 8.0, FS, "bandpass"), rtol=0.02)


def test_an_unknown_shape_is_refused_by_name():
    with pytest.raises(ParameterError, match="'gaussian'.*lorentzian"):
        resonance_avar(0.01, 60.0, 8.0, FS, "gaussian")


def test_keys_name_the_shape_and_the_whole_chain_decides():
    assert res_kind("resonance:8") == (8.0, "lorentzian") and res_kind("resonance:bp:16") == (16.0, "bandpass")
    assert bandpass_named([("bandwidth:single_pole", 20.0), ("resonance:bp:4", 12.0)])
    assert not bandpass_named([("resonance:4", 12.0), ("gauss_markov", 3.0)])
    chi2 = lambda c: type("Sol", (), {"chi2": c})  # noqa: E731
    # the band-pass chain only where its final χ² is more than one effective point (tie) below the Lorentzian's
    assert bandpass_chain_kept(chi2(90.0), chi2(100.0), 5.0)
    assert not bandpass_chain_kept(chi2(96.0), chi2(100.0), 5.0)
    assert not bandpass_chain_kept(chi2(120.0), chi2(100.0), 5.0)


def _lorentzian(n: int, f_r: float, q: float, sigma: float, seed: int) -> np.ndarray:
    rho = np.exp(-np.pi * f_r / (q * FS) + 2j * np.pi * f_r / FS)
    rng = np.random.default_rng(seed)
    e = (rng.normal(size=n) + 1j * rng.normal(size=n)) * np.sqrt(1 - abs(rho) ** 2)
    return sigma * signal.lfilter([1], [1, -rho], e).real


def _bandpass(n: int, f_r: float, q: float, sigma: float, seed: int) -> np.ndarray:
    b, a = signal.iirpeak(f_r, q, fs=FS)
    x = signal.lfilter(b, a, np.random.default_rng(seed).standard_normal(n + 2000))[2000:]
    return sigma * x / x.std()


# the Lorentzian record under slow: test_refine_domains.test_finds_a_simulated_resonance (a default test) asserts
# the Lorentzian shape kept on its own simulated Lorentzian record
@pytest.mark.parametrize("shape", ["bandpass", pytest.param("lorentzian", marks=pytest.mark.slow)])
def test_refine_chooses_the_shape_of_a_simulated_resonance(shape):
    # 500 s at 400 Hz: white rate noise (0.04 °/s a sample) and random walk beside a 60 Hz, Q 8 hump of the same
    # rms in each shape. One resonance, in the shape simulated, f0 and σ near the truth, and N not traded into
    # its column (the band-pass one's PSD is zero at DC; the Lorentzian's white level is only its hump's tail)
    n, sigma = 200_000, 0.04
    make = _bandpass if shape == "bandpass" else _lorentzian
    y = allanite.simulate(n, FS, N=2e-3, K=2e-5, seed=11) + make(n, 60.0, 8.0, sigma, 111)
    r = allanite.refine(y, FS)
    assert r.found == ["resonance"], r.found
    st = r.steps[0]
    assert st.params["shape"] == shape and st.params["q"] == 8.0, (st.params, st.evidence["shape_test"])
    assert abs(st.params["f0"] / 60.0 - 1) < 0.01 and abs(st.params["sigma"] / sigma - 1) < 0.05
    assert st.evidence["shape_test"]["tested"] is True
    if shape == "bandpass":  # the chain with the Lorentzian shape alone was run too, and ended worse
        ch = st.evidence["shape_chains"]
        assert ch["with_bandpass"]["chi2_dof"] < ch["lorentzian_only"]["chi2_dof"], ch
    assert abs(r.fit.coefficients["N"].value / 2e-3 - 1) < 0.03
