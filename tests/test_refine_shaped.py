"""Noise-shaped (sigma-delta) quantisation: the exact Allan variance of white noise differenced k times against a
plain reference and a simulation, the spectrum's guard that keeps it from low-passes and plain quantisation, its
parameters rendered, and refine naming it on a sigma-delta record with the default call."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import signal

import allanite
from allanite.errors import ParameterError
from allanite.model import fitting
from allanite.model._shaped import SHAPED_ORDERS, shaped_autocorrelation, shaped_avar, shaped_q_factor
from allanite.model.effects import EFFECTS, format_params
from allanite.model.refinement._shaped import SHAPED_SHARE, spectrum_rises, spectrum_shaped_share
from allanite.model.terms import design_matrix

FS = 1000.0


def _reference_avar(order: int, m: int) -> float:
    """Allan variance of Δ^k w (w white, unit variance) at m samples, from the filter itself: the Allan difference
    (m samples of −1/m then m of +1/m) convolved with the binomial difference, its squared taps summed, over 2."""
    allan = np.concatenate([-np.ones(m), np.ones(m)]) / m
    diff = np.array([(-1.0) ** j * math.comb(order, j) for j in range(order + 1)])
    return float(np.sum(np.convolve(allan, diff) ** 2) / 2.0)


def _sigma_delta(n: int, fs: float, order: int, sigma: float, n_white: float, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    y = allanite.simulate(n, fs, N=n_white, K=1e-5, seed=rng)
    return y + np.diff(sigma * rng.standard_normal(n + order), order)


def test_exact_avar_equals_the_filters_own_sum():
    m = np.arange(1, 13)
    for k in (1, 2, 3, 4):
        # per unit q² with y = (q/τ0)·Δ^k w: the reference's variance times f_s²
        ref = np.array([_reference_avar(k, int(mi)) for mi in m]) * FS**2
        assert shaped_avar(m / FS, k, FS) == pytest.approx(ref, rel=1e-12)
    # k = 1 is the Q term's column; from m = k on the shaped curve is C(2k − 2, k − 1) times it
    q_col = design_matrix(m / FS, m, FS, ("Q",))[:, 0]
    assert shaped_avar(m / FS, 1, FS) == pytest.approx(q_col, rel=1e-12)
    assert shaped_avar(m[1:] / FS, 2, FS) == pytest.approx(2.0 * q_col[1:], rel=1e-12)
    assert shaped_avar(m[2:] / FS, 3, FS) == pytest.approx(6.0 * q_col[2:], rel=1e-12)
    assert shaped_avar(1 / FS, 2, FS)[0] / q_col[0] == pytest.approx(10 / 3)  # 5/3 of its own line at τ0
    assert [shaped_q_factor(k) for k in (1, 2, 3)] == [1.0, 2.0, 6.0]
    assert shaped_autocorrelation(2).tolist() == [6.0, -4.0, 1.0]
    assert SHAPED_ORDERS == (2, 3)


def test_exact_avar_within_the_simulations_edf_sd():
    n = 400_000
    m = np.array([1, 2, 3, 4, 8, 16, 64])
    for k, seed in ((2, 5), (3, 6)):
        w = np.random.default_rng(seed).standard_normal(n + k)
        y = np.diff(w, k) * FS  # (q/τ0)·Δ^k w with q = 1
        est = allanite.avar(y, FS, taus=m / FS).avar
        exact = shaped_avar(m / FS, k, FS)
        edf = fitting.edf_per_tau(np.full(m.size, 2), m, n + 1, "oavar")
        z = (est / exact - 1.0) / np.sqrt(2.0 / edf)
        assert np.all(np.abs(z) < 4.0), (k, z)
        assert abs(est[0] / exact[0] - 1.0) < 0.01  # τ0's estimate is precise: 5/3 (k = 2) is not within it


def test_order_must_be_whole():
    for bad in (0, 2.5, -1):
        with pytest.raises(ParameterError, match=r"order must be a whole number ≥ 1, got"):
            shaped_avar(0.01, bad, FS)


def test_spectrum_guard_takes_shaping_and_nothing_the_five_terms_or_a_low_pass_make():
    n = 50_000
    sd2 = _sigma_delta(n, FS, 2, 0.05, 5e-3, 1)
    sd3 = _sigma_delta(n, FS, 3, 0.02, 5e-3, 2)
    assert spectrum_shaped_share(sd2, FS)["share"] > 0.4 and spectrum_rises(sd3, FS)
    rng = np.random.default_rng(3)
    white_q = allanite.simulate(n, FS, Q=2e-5, N=2e-3, B=5e-4, seed=rng)  # white angle noise dominating τ0
    lsb = 0.5 * 2e-3 * math.sqrt(FS)
    rounded = np.round(np.convolve(allanite.simulate(n + 3, FS, N=2e-3, seed=rng), np.ones(4) / 4, "valid") / lsb)
    b, a = signal.butter(4, 200.0, fs=FS)
    butter = signal.lfilter(b, a, allanite.simulate(n, FS, N=2e-3, seed=rng))
    for y in (white_q, rounded * lsb, butter):
        assert spectrum_shaped_share(y, FS)["share"] < SHAPED_SHARE
    # a modulator followed by its decimation filter (sinc³ CIC, 8×): the filter removed the shaping — no rise
    x = np.diff(0.05 * rng.standard_normal(8 * n + 2), 2) + allanite.simulate(8 * n, 8 * FS, N=2e-3, seed=rng)
    h = np.convolve(np.convolve(np.ones(8), np.ones(8)), np.ones(8)) / 512
    assert not spectrum_rises(signal.oaconvolve(x, h, mode="valid")[::8], FS)
    assert spectrum_shaped_share(None, FS)["share"] != spectrum_shaped_share(None, FS)["share"]  # NaN


def test_registry_entry_and_its_words():
    e = EFFECTS["shaped_quantisation"]
    assert e.kind == "curve" and e.replaces == "Q" and e.param_names == ("q", "order")
    text = format_params("shaped_quantisation", {"q": 5.0e-5, "order": 2}, {"q": (4.9e-5, 5.1e-5)}, "deg/s")
    assert text == "q = 5e-05 [4.9e-05, 5.1e-05] deg/s·s; order = 2"


def test_default_refine_names_a_second_order_sigma_delta():
    # 100 Hz × 2·10⁴ (cheap): white rate noise and shaped noise of about the same power at f_s/2 (the blind12
    # row's mix, at another rate and length)
    fs = 100.0
    y = _sigma_delta(20_000, fs, 2, 0.05, 5e-3, 2)
    r = allanite.refine(y, fs, unit="deg/s", progress=False)
    assert r.found == ["shaped_quantisation"] and r.unexplained == []
    st = r.steps[0]
    assert st.params["order"] == 2 and isinstance(st.params["order"], int)
    q, (lo, hi) = st.params["q"], st.intervals["q"]
    assert q == pytest.approx(0.05 / fs, rel=0.05) and lo < q < hi
    assert st.evidence["psd_shaped"]["share"] > SHAPED_SHARE
    # the model's Q is the line the shaped noise shows from m = 2 on: √2·q; N is the white rate noise
    coeffs = r.fit.coefficients
    assert coeffs["Q"].value == pytest.approx(math.sqrt(2.0) * q, rel=1e-6)
    assert coeffs["N"].value == pytest.approx(5e-3, rel=0.05)
    assert coeffs["shaped_quantisation"].unit == coeffs["Q"].unit
    assert "shaped_quantisation" in r.report() and "order = 2" in r.report()
    assert "shaped_quantisation" in r._repr_html_()


@pytest.mark.slow  # the default test above covers the kind's naming at order 2 on a short record
def test_default_refine_names_a_third_order_sigma_delta_at_1khz():
    y = _sigma_delta(100_000, FS, 3, 0.02, 5e-3, 2)
    r = allanite.refine(y, FS, unit="deg/s", progress=False)
    assert r.found == ["shaped_quantisation"] and r.unexplained == []
    st = r.steps[0]
    assert st.params["order"] == 3 and st.params["q"] == pytest.approx(0.02 / FS, rel=0.05)
    assert st.intervals["q"][0] < 0.02 / FS < st.intervals["q"][1]
    assert r.fit.coefficients["Q"].value == pytest.approx(math.sqrt(6.0) * st.params["q"], rel=1e-6)


def test_shaped_goes_before_a_bandwidth_only_within_the_tie():
    from types import SimpleNamespace

    from allanite.model.refinement._choose import _shaped_before_filter

    def prop(effect, chi2):
        return SimpleNamespace(effect=effect, sol=SimpleNamespace(chi2=chi2))

    bw, sq, line = prop("bandwidth", 154.7), prop("shaped_quantisation", 155.6), prop("sinusoid", 100.0)
    assert _shaped_before_filter([line, bw, sq], 17.0) == [line, sq, bw]  # a near-tie: the kind with a number fewer
    assert _shaped_before_filter([line, bw, sq], 0.5) == [line, bw, sq]  # the bandwidth fits better beyond the tie
    far = prop("shaped_quantisation", 200.0)
    assert _shaped_before_filter([bw, far], 17.0) == [bw, far]
    assert _shaped_before_filter([sq, bw], 17.0) == [sq, bw] and _shaped_before_filter([bw], 17.0) == [bw]


@pytest.mark.slow  # test_spectrum_guard_... covers the guard; here the curve test on a record the guard lets through
def test_a_rounded_three_tap_average_stays_a_bandwidth():
    # its spectrum rises from its zero at f_s/3 to f_s/2: the guard passes, the one-sided curve test does not
    rng = np.random.default_rng(41)
    n = 200_000
    y = np.convolve(allanite.simulate(n + 2, FS, N=2e-3, K=1e-5, seed=rng), np.ones(3) / 3, "valid")
    lsb = 0.5 * 2e-3 * math.sqrt(FS / 3)
    y = np.round(y / lsb) * lsb
    assert spectrum_rises(y, FS)
    r = allanite.refine(y, FS, unit="deg/s", progress=False)
    assert r.found == ["bandwidth"] and r.steps[0].params["taps"] == pytest.approx(3.0, abs=0.1)
    assert all(c["statistic"] < c["threshold"] for c in r.considered["shaped_quantisation"])
