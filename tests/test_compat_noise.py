"""allanite.compat's noise generators (``noise``, ``noise_kasdin.Noise``): written from Kasdin & Walter
1992 and NIST SP 1065, checked by their spectra, levels and Allan statistics — against the theory and
against allantools' generators (same levels and spectra, not the same draws)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from allanite import compat
from allanite.errors import ParameterError

N, R = 4096, 60


def _psd(gen, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Hann-windowed one-sided periodogram of ``gen()`` averaged over R draws (fs = 1 unless gen says)."""
    np.random.seed(seed)
    acc = 0.0
    for _ in range(R):
        x = gen()
        w = np.hanning(x.size)
        acc = acc + 2.0 * np.abs(np.fft.rfft((x - x.mean()) * w)) ** 2 / np.sum(w**2)
    return np.fft.rfftfreq(x.size), acc / R


def _band(f, s, lo, hi):
    sel = (f >= lo) & (f < hi)
    return f[sel], s[sel]


@pytest.mark.parametrize(
    "gen, beta, level",
    [
        (lambda: compat.noise.white(N, b0=3.0), 0, 3.0),
        (lambda: compat.noise.brown(N, b_minus2=2e-3), -2, 2e-3),
        (lambda: compat.noise.violet(N, b2=5.0), 2, 5.0),
        (lambda: compat.noise.pink(N), -1, 4.0 / math.pi),
    ],
    ids=["white", "brown", "violet", "pink"],
)
def test_levels_are_the_documented_power_laws(gen, beta, level):
    f, s = _psd(gen)
    # mid band: above the window's leakage of red noise, below the discrete-time roll-off near fs/2
    fb, sb = _band(f, s, 0.02, 0.08)
    ratio = np.mean(sb / (level * fb**beta))
    assert ratio == pytest.approx(1.0, abs=0.08), ratio
    assert isinstance(gen(), np.ndarray) and gen().shape == (N,)


@pytest.mark.parametrize("name, kw", [("white", {"b0": 2.0}), ("brown", {}), ("violet", {}), ("pink", {})])
def test_spectra_match_allantools_generators(name, kw):
    allantools = pytest.importorskip("allantools")
    f, ours = _psd(lambda: getattr(compat.noise, name)(N, **kw), seed=1)
    _, theirs = _psd(lambda: getattr(allantools.noise, name)(N, **kw), seed=2)
    # pink: allantools' Voss–McCartney spectrum is 1/f only above ≈ fs/256
    fb = (f >= 1 / 64) & (f < 0.25)
    ratio = np.mean(ours[fb]) / np.mean(theirs[fb])
    assert ratio == pytest.approx(1.0, abs=0.1 if name == "pink" else 0.05), ratio


def test_sampling_rate_scales_as_allantools_does():
    np.random.seed(3)
    x = compat.noise.white(200_000, b0=2.0, fs=10.0)
    assert x.var() == pytest.approx(10.0, rel=0.01)  # b0·fs/2
    np.random.seed(3)
    b = compat.noise.brown(1000, b_minus2=1.0, fs=4.0)
    np.random.seed(3)
    w = compat.noise.white(1000, b0=4 * math.pi**2, fs=4.0)
    np.testing.assert_allclose(b, np.cumsum(w) / 4.0, rtol=1e-15)
    assert compat.noise.violet(10).shape == (10,) and compat.noise.pink(1).shape == (1,)
    with pytest.raises(ParameterError, match="fs must be a positive finite number, got 0"):
        compat.noise.white(10, fs=0)
    with pytest.raises(ParameterError, match="num_points must be an integer ≥ 0"):
        compat.noise.brown(-1)


def test_psd_helpers():
    np.random.seed(4)
    x = compat.noise.white(8192, b0=2.0, fs=5.0)
    f, p = compat.noise.numpy_psd(x, 5.0)
    assert f[-1] == 2.5 and np.mean(p[1:-1]) == pytest.approx(2.0, rel=0.05)
    f, p = compat.noise.scipy_psd(x, 5.0)
    assert np.mean(p[1:-1]) == pytest.approx(2.0, rel=0.05)


# --------------------------------------------------------------------------------------------
# Noise (Kasdin & Walter)


@pytest.mark.parametrize("b", [0, -1, -2, -3, -4])
def test_generated_phase_has_the_psd_of_kasdin_walter_eq39(b):
    """S_x(f) = 2Q_d·τ0/|2 sin(πfτ0)|^(−b) (the filter's exact response; ≈ g_b·f^b at low f), checked on
    the series differenced until its spectrum is no steeper than f^-1 (so the window cannot leak)."""
    n = compat.Noise(nr=N, qd=3e-18, b=b)
    d = max(0, -b - 1)

    def gen():
        n.generateNoise()
        return np.diff(n.time_series, d)

    f, s = _psd(gen, seed=5)
    fb, sb = _band(f, s, 0.02, 0.2)
    want = 2 * 3e-18 * np.abs(2 * np.sin(np.pi * fb)) ** (b + 2 * d)
    assert np.mean(sb / want) == pytest.approx(1.0, abs=0.08)
    assert n.phase_psd_from_qd(1.0) == pytest.approx(2 * 3e-18 * (2 * np.pi) ** b)


@pytest.mark.parametrize("b", [0, -1, -2, -3, -4])
@pytest.mark.parametrize("tau", [4.0, 16.0])
def test_predicted_adev_mdev_match_the_sample_average(b, tau):
    n = compat.Noise(nr=2**14, qd=1e-20, b=b)
    np.random.seed(6)
    avar, mvar = [], []
    for _ in range(40):
        n.generateNoise()
        avar.append(compat.oadev(n.time_series, taus=[tau])[1][0] ** 2)
        mvar.append(compat.mdev(n.time_series, taus=[tau])[1][0] ** 2)
    # asymptotic (τ ≫ τ0) forms; the m = 4 MVAR of white and flicker PM is still 10–20 % off them
    tol_m = 0.25 if (b in (0, -1) and tau == 4.0) else 0.12
    assert np.mean(avar) == pytest.approx(n.adev(1.0, tau) ** 2, rel=0.12)
    assert np.mean(mvar) == pytest.approx(n.mdev(1.0, tau) ** 2, rel=tol_m)


def _integral(fn, x_max: float) -> float:
    edges = np.arange(0.0, x_max + np.pi, np.pi)
    edges[0] = 1e-12
    return sum(quad(fn, a, min(b, x_max), limit=200)[0] for a, b in zip(edges[:-1], edges[1:]) if a < x_max)


def _pvar_response(x: float) -> float:
    """|G|² of PVAR's weighting (τ/2 − s on [0, τ] minus the same a τ later), for x = πfτ, τ = 1."""
    w = 2 * x
    e = np.exp(1j * w)
    inner = 0.5 * (e - 1) / (1j * w) - (e / (1j * w) - (e - 1) / (1j * w) ** 2)
    return abs((1 - e) * inner) ** 2


@pytest.mark.parametrize("b", [0, -1, -2, -3, -4])
def test_prediction_constants_are_the_transfer_function_integrals(b):
    """AVAR = ∫S_y·2sin⁴(πfτ)/(πfτ)² df (to f_h), MVAR = ∫S_y·2sin⁶/(πfτ)⁴ df (τ ≫ τ0),
    PVAR = 72/τ⁶·∫S_x|G|² df — with S_y = h_a f^a, at τ = 1 s, f_h = 1/(2τ0) and τ0 = 1 ms."""
    a, tau0 = b + 2, 1e-3
    n = compat.Noise(qd=1.0, b=b)
    h = n.frequency_psd_from_qd(tau0)
    sy = lambda x: h * (x / np.pi) ** a  # noqa: E731 — S_y at f = x/(πτ), τ = 1
    x_h = np.pi * 0.5 / tau0
    avar = _integral(lambda x: sy(x) * 2 * np.sin(x) ** 4 / x**2 / np.pi, x_h)
    mvar = _integral(lambda x: sy(x) * 2 * np.sin(x) ** 6 / x**4 / np.pi, 400.0)
    pvar = 72 * _integral(lambda x: sy(x) / (2 * x) ** 2 * _pvar_response(x) / np.pi, 400.0)
    assert n.adev(tau0, 1.0) ** 2 == pytest.approx(avar, rel=2e-3)
    assert n.mdev(tau0, 1.0) ** 2 == pytest.approx(mvar, rel=3e-3)
    assert n.pdev_from_qd(tau0) ** 2 == pytest.approx(pvar, rel=3e-3)


def test_predictions_equal_allantools_but_two_documented_constants():
    allantools = pytest.importorskip("allantools")
    for b in (0, -1, -2, -3, -4):
        ours, theirs = compat.Noise(qd=2e-20, b=b), allantools.Noise(qd=2e-20, b=b)
        for tau0, tau in ((1.0, 7.0), (0.01, 3.0)):
            assert ours.adev(tau0, tau) == pytest.approx(theirs.adev(tau0, tau), rel=1e-13)
            assert ours.frequency_psd_from_qd(tau0) == pytest.approx(theirs.frequency_psd_from_qd(tau0), rel=1e-13)
            m_ratio = ours.mdev(tau0, tau) / theirs.mdev(tau0, tau)
            p_ratio = ours.pdev_from_qd(tau0) / theirs.pdev_from_qd(tau0)
            # MVAR of FFM: (27/8)ln3 − 4ln2, not (27/20)ln2; PVAR of FPM: 3(ln16 − 1)/(2π²), not (3ln16 − 1)/(2π²)
            m_want = math.sqrt((27 / 8 * math.log(3) - 4 * math.log(2)) / (27 / 20 * math.log(2))) if b == -3 else 1.0
            p_want = math.sqrt(3 * (math.log(16) - 1) / (3 * math.log(16) - 1)) if b == -1 else 1.0
            assert m_ratio == pytest.approx(m_want, rel=1e-13) and p_ratio == pytest.approx(p_want, rel=1e-13)
            assert ours.c_avar() == theirs.c_avar() and ours.c_mvar() == theirs.c_mvar()


def test_noise_object_interface():
    n = compat.Noise()
    assert (n.nr, n.qd, n.b) == (2, 1, 0) and n.time_series.size == 0
    for nr in (1, 5, 2**10):
        n.set_input(nr=nr, qd=1e-12, b=-2)
        n.generateNoise()
        assert n.time_series.shape == (nr,)
    n.set_input(nr=8, qd=-1.0)
    with pytest.raises(ParameterError, match="qd must be a variance ≥ 0, got -1.0"):
        n.generateNoise()
    n.set_input(b=-5)
    with pytest.raises(ParameterError, match="b must be 0, -1, -2, -3 or -4"):
        n.adev(1.0, 1.0)
