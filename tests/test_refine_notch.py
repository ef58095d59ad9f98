"""A digital notch after the roll-off (the bandwidth kind ``"<kind>+notch:<f_n>:<Q>"``,
``scipy.signal.iirnotch``): its Allan variance exact — against the Allan kernel convolved with the cascade's
impulse response (``scipy.signal.lfilter``), for a Butterworth (one rational filter, closed sums) and for kinds whose
autocorrelation is convolved with the notch's (prefix sums) — and refine naming a notch behind a Butterworth at
rates other than blind7's, and none behind one without."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

import allanite
from allanite.errors import ParameterError
from allanite.model.effects import (
    NOTCH_Q,
    filter_autocorrelation,
    filter_cutoff,
    filtered_white_avar,
    notch_kind,
    notch_zpk,
    split_notch,
)
from allanite.model.refinement._notch import notch_grid, notch_threshold
from allanite.model.refinement.levels import CONDITIONAL_SHARES, alpha


def _plain(b, a, m):
    """σ²(m) per unit N² of white noise through b/a: Σ_n ((g_m * h)[n])² / (2m²) with unit DC gain, g_m m ones
    then m minus ones, h the impulse response to where it has fallen below 1e-17 of its peak."""
    d = np.zeros(40_000)
    d[0] = 1.0
    h = signal.lfilter(b, a, d)
    h = h[: np.flatnonzero(np.abs(h) > 1e-17 * np.abs(h).max())[-1] + 1] / h.sum()
    return np.array([np.sum(np.convolve(np.r_[np.ones(k), -np.ones(k)], h) ** 2) / (2.0 * k * k) for k in m])


M = np.array([1, 2, 3, 5, 8, 13, 40, 200, 1000])


@pytest.mark.parametrize(
    "base, p, fs, f_n, q",
    [
        ("butterworth2", 60.0, 400.0, 30.0, 3.0),  # blind7's
        ("butterworth4", 400.0, 2000.0, 100.0, 8.0),
        ("butterworth3", 100.0, 400.0, 100.0 * 0.7, 1.0),  # an odd order: a real pole
        ("butterworth2", 50.0, 100.0, 10.0, 2.0),  # the low-pass at f_s/2: the notch alone
    ],
)
def test_a_butterworth_and_a_notch_is_the_allan_kernel_through_the_cascade(base, p, fs, f_n, q):
    bn, an = signal.iirnotch(f_n, q, fs=fs)
    if p < fs / 2.0:
        bb, ab = signal.butter(int(base[-1]), p, fs=fs)
        bn, an = np.convolve(bb, bn), np.convolve(ab, an)
    kind = notch_kind(base, f_n, q)
    exact = filtered_white_avar(M / fs, kind, p, fs) / fs  # per unit N²: σ_w² = N²·f_s
    np.testing.assert_allclose(exact, _plain(bn, an, M), rtol=1e-8)
    r = filter_autocorrelation(kind, p, fs)
    assert r[0] + 2.0 * r[1:].sum() == pytest.approx(1.0, abs=1e-9)  # unit DC gain: the curve tends to N²/τ
    assert filter_cutoff(kind, p, fs) == filter_cutoff(base, p, fs)  # the low-pass's, not the notch's


@pytest.mark.parametrize(
    "base, p, b, a", [("single_pole", 50.0, None, None), ("moving_average", 3.0, np.full(3, 1 / 3), [1.0])]
)
def test_other_kinds_and_a_notch_by_convolved_autocorrelations(base, p, b, a):
    fs, f_n, q = 400.0, 20.0, 4.0
    if b is None:  # impulse-invariant single pole
        pole = np.exp(-2 * np.pi * p / fs)
        b, a = [1.0 - pole], [1.0, -pole]
    bn, an = signal.iirnotch(f_n, q, fs=fs)
    exact = filtered_white_avar(M / fs, notch_kind(base, f_n, q), p, fs) / fs
    np.testing.assert_allclose(exact, _plain(np.convolve(b, bn), np.convolve(a, an), M), rtol=1e-8)


def test_the_notch_against_simulated_samples():
    # white noise through the cascade: the estimator within its ≈ 1 % SD (2·10⁵ samples) of the closed form, and
    # the notch's mark (−9 % at τ = 1/60 s) told from the low-pass alone
    fs, n = 400.0, 200_000
    w = np.random.default_rng(5).normal(size=n) * 2e-3 * np.sqrt(fs)
    y = signal.lfilter(*signal.iirnotch(30.0, 3.0, fs=fs), signal.lfilter(*signal.butter(2, 60.0, fs=fs), w))
    tau = np.array([1, 2, 4, 7, 12]) / fs
    sim = allanite.avar(y, fs, taus=tau).avar
    exact = 4e-6 * filtered_white_avar(tau, notch_kind("butterworth2", 30.0, 3.0), 60.0, fs)
    alone = 4e-6 * filtered_white_avar(tau, "butterworth2", 60.0, fs)
    np.testing.assert_allclose(sim, exact, rtol=0.03)
    assert alone[-2] / exact[-2] > 1.08


def test_kind_names_and_bad_notches():
    kind = notch_kind("single_pole+boxcar:1.5", 30.0, 3.0)
    assert split_notch(kind) == ("single_pole+boxcar:1.5", 30.0, 3.0)
    assert split_notch("butterworth2") == ("butterworth2", None, None)
    with pytest.raises(ParameterError, match=r"notch at 250\.0 Hz, Q 3\.0: f_n must lie in \(0, fs/2 = 200\.0\)"):
        notch_zpk(250.0, 3.0, 400.0)
    with pytest.raises(ValueError, match=r"Q above 0"):
        notch_zpk(30.0, 0.0, 400.0)


def test_the_grid_and_the_test_spend_the_notch_share():
    # f_n in the low-pass's passband (≤ 0.8 f_c), ≥ 4 Welch bins from 0, every Q's width ≥ 4 bins; the threshold is
    # χ²₃'s at the conditional share over the pairs
    pairs = notch_grid(60.0, 400.0, 100.0, 1_000_000)
    fs_bin = 400.0 / 4096
    assert {q for _f, q in pairs} == set(NOTCH_Q)
    assert all(4 * fs_bin <= f <= 48.0 and f / q >= 4 * fs_bin for f, q in pairs)
    assert notch_grid(0.5, 400.0, 100.0, 1_000_000) == []  # no passband wide enough
    assert CONDITIONAL_SHARES["bandwidth:notch"] == 0.02
    assert alpha("bandwidth:notch", 0.05) == pytest.approx(1e-3)
    assert notch_threshold(0.05, 1) == pytest.approx(16.266, abs=1e-3)  # χ²₃ at 0.1 %
    assert notch_threshold(0.05, 100) > notch_threshold(0.05, 1)


def _filtered(fs, n, fc, notch, seed):
    y = allanite.simulate(n, fs, N=2e-3, K=5e-6, seed=seed)
    y = signal.lfilter(*signal.butter(2, fc, fs=fs), y)
    return signal.lfilter(*signal.iirnotch(*notch, fs=fs), y) if notch else y


def test_refine_names_a_notch_behind_a_butterworth():
    # 200 Hz × 2·10⁵, a 2nd-order Butterworth at 40 Hz and a 12 Hz notch of Q 2: the low-pass and the notch named,
    # the notch within 1 %, nothing unexplained
    fs = 200.0
    r = allanite.refine(_filtered(fs, 200_000, 40.0, (12.0, 2.0), 3), fs, unit="deg/s", progress=False)
    bw = next(st for st in r.steps if st.effect == "bandwidth")
    assert bw.params["filter"] == "butterworth2+notch"
    assert bw.params["notch_f"] == pytest.approx(12.0, rel=0.01)
    assert bw.params["notch_q"] == pytest.approx(2.0, rel=0.2)
    assert bw.params["cutoff"] == pytest.approx(40.0, rel=0.1)
    assert "resonance" not in r.found and r.unexplained == []


def test_no_notch_behind_a_butterworth_without_one():
    fs = 200.0
    r = allanite.refine(_filtered(fs, 200_000, 40.0, None, 4), fs, unit="deg/s", progress=False)
    bw = next(st for st in r.steps if st.effect == "bandwidth")
    assert bw.params["filter"] == "butterworth2"
    assert "notch_f" not in bw.params
