"""The sharp rippled bandwidth kinds (``elliptic4``/``elliptic6``, undecimated and decimated by 4: an elliptic of
fixed order and stop band, its signed passband ripple in the kind's name; :mod:`allanite.model._sharp`): their
Allan variance exact for sampled data (against the declared filter's independent impulse-response sum and against
simulation), their reported cutoff, their bad values — and the default call naming one on an elliptic-filtered
record without a stand-in."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

import allanite
from allanite.errors import ParameterError
from allanite.model._declared import declared_filter
from allanite.model._sharp import SHARP_DESIGNS, sharp_kind, sharp_of, sharp_zpk
from allanite.model.effects import filter_autocorrelation, filter_cutoff, filtered_white_avar
from allanite.model.refinement._rolloff import needs_spectrum
from allanite.model.refinement._sharp import near_grid

#: (kind, f_s, passband edge f_c): both designs, both signs of the ripple, undecimated and decimated, slow and
#: near the output's Nyquist
CASES = [
    ("elliptic4:1.0", 200.0, 30.0),
    ("elliptic6:-0.5", 1000.0, 150.0),
    ("elliptic6_dec4:0.8", 250.0, 90.0),
    ("elliptic4_dec4:-0.3", 100.0, 40.0),
    ("elliptic6:2.0", 100.0, 1.5),
]
#: the closed sums' worst relative error at the slow filter (f_c = f_s/67; its impulse response through
#: second-order sections agrees with the declared (b, a) path to 1e-9): at m = 1, where σ² is 0.3 % of its peak,
#: the poles crowd near z = 1 and their partial fractions cancel — 2.8e-4, as a 6th-order Butterworth's 2e-4 there
RTOL = {1.5: 5e-4}


def _declared(kind: str, fs: float, fc: float):
    """The same filter declared by its (b, a) at the rate it runs at: an independent computation (its impulse
    response's autocorrelation by FFT, every D-th lag kept)."""
    order, ripple, stop, dec = sharp_of(kind)
    b, a = signal.ellip(order, ripple, stop, fc, fs=fs * dec)
    return declared_filter({"b": b, "a": a, "rate": fs * dec}, fs), (b, a, dec)


def test_kind_names_and_bad_values():
    assert sharp_kind("elliptic6", -0.5) == "elliptic6:-0.5"
    assert sharp_kind("elliptic4_dec4", 1.23456) == "elliptic4_dec4:1.23"
    assert sharp_of("elliptic6:-0.5") == (5, 0.5, 60.0, 1)
    assert sharp_of("elliptic4_dec4:2.0") == (4, 2.0, 40.0, 4)
    assert sharp_of("butterworth4") is None and sharp_of("elliptic6:x") is None
    assert set(SHARP_DESIGNS) == {"elliptic4", "elliptic6", "elliptic4_dec4", "elliptic6_dec4"}
    assert needs_spectrum("elliptic6:1.0") and not needs_spectrum("boxcar")
    with pytest.raises(ParameterError, match=r"sharp filter design 'cheby9': must be one of"):
        sharp_kind("cheby9", 1.0)
    with pytest.raises(ParameterError, match=r"sharp filter ripple 0\.01 dB: its size must lie in \[0\.05, 3\.0\]"):
        sharp_kind("elliptic6", 0.01)
    with pytest.raises(ParameterError, match=r"sharp filter cutoff 50\.0 Hz: must lie in \(0, fs/2 = 50\.0\)"):
        sharp_zpk("elliptic6:1.0", 50.0, 100.0)
    # at f_c ≥ f_s/2 its limit, as a Butterworth's: no filter, white noise N²/τ
    tau = np.array([0.01, 0.02, 0.1])
    np.testing.assert_allclose(filtered_white_avar(tau, "elliptic6:1.0", 50.0, 100.0), 1.0 / tau)
    assert filter_autocorrelation("elliptic6:1.0", 60.0, 100.0).tolist() == [1.0]


@pytest.mark.parametrize("kind, fs, fc", CASES)
def test_avar_is_the_declared_filters(kind, fs, fc):
    decl, _ = _declared(kind, fs, fc)
    tau = np.array([1, 2, 3, 5, 10, 30, 100, 1000, 100_000]) / fs
    exact = filtered_white_avar(tau, kind, fc, fs)  # closed sums over the (folded) poles
    np.testing.assert_allclose(exact, filtered_white_avar(tau, decl.kind, 0.0, fs), rtol=RTOL.get(fc, 1e-8))
    r = filter_autocorrelation(kind, fc, fs)
    assert r[0] + 2.0 * r[1:].sum() == pytest.approx(1.0, abs=1e-9)  # unit DC gain: the curve tends to N²/τ
    # the reported cutoff is the −3 dB point of the filter at the rate it runs at, the declared filter's own (both
    # interpolated on a grid over 0–f_s/2, 2¹⁴ and 2¹⁵ points: 2e-3 of the slow filter's 1.5 Hz is one step)
    assert filter_cutoff(kind, fc, fs) == pytest.approx(decl.cutoff, rel=2e-3 if fc in RTOL else 1e-5)


@pytest.mark.parametrize("kind, fs, fc", CASES[:4])
def test_avar_matches_filtered_white_noise(kind, fs, fc):
    _decl, (b, a, dec) = _declared(kind, fs, fc)
    n_white, n = 2e-3, 400_000
    rng = np.random.default_rng(len(kind) + int(fc))
    w = rng.normal(size=n * dec + 4000) * n_white * np.sqrt(fs * dec)
    y = signal.lfilter(b, a, w)[4000::dec]
    tau = np.array([1, 2, 3, 4, 8]) / fs  # relative SD ≤ 0.9 % at 4·10⁵ samples
    sim = allanite.avar(y, fs, taus=tau).avar
    dc2 = (b.sum() / a.sum()) ** 2  # the kind has unit gain at DC; an even order's design −|r| dB there
    exact = dc2 * n_white**2 * filtered_white_avar(tau, kind, fc, fs)
    np.testing.assert_allclose(sim, exact, rtol=0.04)
    # and it tells the ripple's sign apart: the same design with the other sign is further off at some τ
    other = kind.split(":")[0] + ":" + repr(-float(kind.split(":")[1]))
    alt = dc2 * n_white**2 * filtered_white_avar(tau, other, fc, fs)
    assert np.max(np.abs(sim / alt - 1)) > 3 * np.max(np.abs(sim / exact - 1))


def test_near_grid():
    grid = np.geomspace(1.0, 100.0, 24)
    near = near_grid(grid, 20.0)
    assert near.min() >= 12.0 and near.max() <= 26.0 and near.size >= 3
    assert near_grid(grid, 1000.0).tolist() == grid[-3:].tolist()  # three nearest where none lie near


def test_refine_names_an_elliptic_without_stand_ins():
    # 200 Hz, an elliptic IIR of order 4 (1 dB ripple, 40 dB stop band) at 30 Hz on white noise and a rate random
    # walk, 10⁵ samples: the sharp kind named (its design, ripple within 0.2 dB, −3 dB cutoff within 2 %), no
    # resonance or Gauss–Markov term standing in for the ripple, nothing unexplained (before the sharp kinds: a
    # Butterworth, a resonance or two and "the Allan curve departs from the model", benches/refine_declared_null.py)
    fs, n = 200.0, 100_000
    rng = np.random.default_rng(3)
    y = allanite.simulate(n, fs, N=1e-3, K=1e-6, seed=rng)
    b, a = signal.ellip(4, 1.0, 40.0, 30.0, fs=fs)
    y = signal.lfilter(b, a, y)
    r = allanite.refine(y, fs, unit="deg/s", progress=False)
    assert r.found == ["bandwidth"], r.found
    bw = next(st for st in r.steps if st.effect == "bandwidth")
    assert bw.final_params["filter"] == "elliptic4"
    assert bw.final_params["ripple"] == pytest.approx(1.0, abs=0.2)
    cut = declared_filter((b, a), fs).cutoff
    assert bw.final_params["cutoff"] == pytest.approx(cut, rel=0.02)
    lo, hi = bw.final_intervals["cutoff"]
    assert lo <= bw.final_params["cutoff"] <= hi <= fs / 2
    r_lo, r_hi = bw.final_intervals["ripple"]  # its own profile, the edge searched again at each ripple
    assert 0.05 <= r_lo <= bw.final_params["ripple"] <= r_hi <= 3.0 and r_lo <= 1.0 <= r_hi
    assert r.unexplained == []
