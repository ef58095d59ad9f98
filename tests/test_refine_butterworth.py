"""The bandwidth's 2nd-order Butterworth kind (``"butterworth2"``): its Allan variance exact for
``scipy.signal.butter(2, f_c, fs=f_s)`` filtered white noise — against the Allan kernel convolved with the
filter's impulse response, and against the estimator on simulated samples — and refine naming it on a record at
a rate other than the blind suite's."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

import allanite
from allanite.errors import ParameterError
from allanite.model.effects import filter_autocorrelation, filter_cutoff, filtered_white_avar, two_pole_terms
from allanite.model.refinement._rolloff import SPECTRUM_FACTOR, needs_spectrum, spectrum_agrees

#: (f_s, f_c): the blind suite's, another rate, near Nyquist, and a slow filter (a long impulse response)
CASES = [(400.0, 100.0), (1000.0, 200.0), (100.0, 45.0), (100.0, 49.0), (100.0, 1.5)]


def _impulse(fc, fs):
    """The filter's impulse response, to where it has fallen below 1e-18 of its peak."""
    b, a = signal.butter(2, fc, fs=fs)
    d = np.zeros(200_000)
    d[0] = 1.0
    h = signal.lfilter(b, a, d)
    return h[: np.flatnonzero(np.abs(h) > 1e-18 * np.abs(h).max())[-1] + 1]


@pytest.mark.parametrize("fs, fc", CASES)
def test_avar_is_the_allan_kernel_through_the_filter(fs, fc):
    # plain reference: σ²(m) = Σ_n ((g_m * h)[n])² / (2m²) for unit white input, g_m = m ones then m minus ones
    h = _impulse(fc, fs)
    m = np.array([1, 2, 3, 5, 8, 13, 40, 200, 1000])
    plain = np.array([np.sum(np.convolve(np.r_[np.ones(k), -np.ones(k)], h) ** 2) / (2.0 * k * k) for k in m])
    exact = filtered_white_avar(m / fs, "butterworth2", fc, fs) / fs  # per unit N²: σ_w² = N²·f_s
    np.testing.assert_allclose(exact, plain, rtol=1e-9)


@pytest.mark.parametrize("fs, fc", CASES)
def test_autocorrelation_and_cutoff(fs, fc):
    h = _impulse(fc, fs)
    r_plain = np.correlate(h, h, mode="full")[h.size - 1 :] if h.size < 5000 else None
    r = filter_autocorrelation("butterworth2", fc, fs)
    assert r[0] + 2.0 * r[1:].sum() == pytest.approx(1.0, abs=1e-9)  # unit DC gain
    if r_plain is not None:
        n = min(r.size, r_plain.size)
        np.testing.assert_allclose(r[:n], r_plain[:n], atol=1e-14)
    # prewarped: −3 dB at f_c exactly, which is what the step reports
    assert filter_cutoff("butterworth2", fc, fs) == fc
    b, a = signal.butter(2, fc, fs=fs)
    _w, resp = signal.freqz(b, a, worN=[fc], fs=fs)
    assert abs(resp[0]) ** 2 == pytest.approx(0.5, rel=1e-9)


@pytest.mark.parametrize("fs, fc", [(400.0, 100.0), (1000.0, 200.0), (100.0, 45.0)])
def test_avar_matches_filtered_white_noise(fs, fc):
    n_white = 2e-3
    w = np.random.default_rng(int(fc)).normal(size=1_000_000) * n_white * np.sqrt(fs)
    y = signal.lfilter(*signal.butter(2, fc, fs=fs), w)
    tau = np.array([1, 2, 3, 4, 8, 32]) / fs  # relative SD ≤ 0.6 % at 10⁶ samples
    sim = allanite.avar(y, fs, taus=tau).avar
    exact = n_white**2 * filtered_white_avar(tau, "butterworth2", fc, fs)
    np.testing.assert_allclose(sim, exact, rtol=0.03)
    # and it is not a single pole at the same cutoff: they differ at the shortest τ by far more than the
    # estimate’s ≈ 0.2 % (6.5 % at 45 Hz of 100, 14 % at 100 of 400)
    pole = n_white**2 * filtered_white_avar(tau[:1], "single_pole", fc, fs)
    assert abs(pole[0] / sim[0] - 1) > 0.05


def test_cutoff_at_or_beyond_nyquist():
    fs = 100.0
    with pytest.raises(ParameterError, match=r"two-pole cutoff 50\.0 Hz: must lie in \(0, fs/2 = 50\.0\)"):
        two_pole_terms(50.0, fs)
    with pytest.raises(ParameterError, match="two-pole cutoff -1.0 Hz"):
        two_pole_terms(-1.0, fs)
    # the filter's limit there (poles meet the double zero at −1): no filter, white noise N²/τ
    tau = np.array([0.01, 0.02, 0.1])
    np.testing.assert_allclose(filtered_white_avar(tau, "butterworth2", 60.0, fs), 1.0 / tau)
    np.testing.assert_allclose(filtered_white_avar(tau, "butterworth2", 0.4999 * fs, fs), 1.0 / tau, rtol=1e-3)
    assert filter_autocorrelation("butterworth2", 50.0, fs).tolist() == [1.0]


def test_a_butterworth_is_named_only_where_the_spectrum_shows_it():
    fs = 100.0
    rng = np.random.default_rng(3)
    w = rng.normal(size=400_000)
    through = signal.lfilter(*signal.butter(2, 23.0, fs=fs), w)
    # a boxcar of 1.2 samples (an ADIS16405 gyro's): lag-1 correlation 1/6, nothing beyond
    box = w[1:] + (3.0 - np.sqrt(8.0)) * w[:-1]  # a/(1 + a²) = 1/6
    assert needs_spectrum("butterworth2") and not needs_spectrum("boxcar") and SPECTRUM_FACTOR == 2.0
    assert spectrum_agrees(through, fs, "butterworth2", 23.0)
    assert not spectrum_agrees(box, fs, "butterworth2", 23.0)  # its 40–48 Hz band holds half the 2–10 Hz power
    assert spectrum_agrees(box, fs, "boxcar", 1.2)
    assert not spectrum_agrees(None, fs, "butterworth2", 23.0)  # a curve alone shows no spectrum


def test_refine_names_a_butterworth_at_1khz():
    # 1 kHz, a 2nd-order Butterworth at 200 Hz on the white noise and a Gauss–Markov rate (both filtered, as a
    # sensor's anti-alias stage filters everything), flicker beside: a two-pole bandwidth, no resonance
    fs, n = 1000.0, 600_000
    rng = np.random.default_rng(7)
    y = allanite.simulate(n, fs, N=1e-3, K=1e-6, seed=rng) + allanite.simulate(
        n, fs, gauss_markov=[(3e-3, 2.0)], seed=rng
    )
    y = signal.lfilter(*signal.butter(2, 200.0, fs=fs), y)
    r = allanite.refine(y, fs, unit="deg/s", progress=False)
    assert "resonance" not in r.found, r.found
    bw = next(st for st in r.steps if st.effect == "bandwidth")
    assert bw.final_params["filter"] == "butterworth2"
    assert bw.final_params["cutoff"] == pytest.approx(200.0, rel=0.05)
    lo, hi = bw.final_intervals["cutoff"]
    assert lo <= bw.final_params["cutoff"] <= hi <= fs / 2
    gm = next(st for st in r.steps if st.effect == "gauss_markov")
    assert gm.final_params["sigma"] == pytest.approx(3e-3, rel=0.2)
    assert gm.final_params["tc"] == pytest.approx(2.0, rel=0.2)
    assert r.unexplained == []
