"""The sinc^k (CIC) kinds of the bandwidth effect: the autocorrelation of a CIC decimator read at its output rate,
its Allan variance against a plain simulation, and refine naming a CIC's order and cutoff."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import optimize, signal

import allanite
from allanite.model._sinc import SINC_ORDERS, sinc_autocorrelation, sinc_cutoff, sinc_order
from allanite.model.effects import FILTERS, filter_autocorrelation, filter_cutoff, filtered_white_avar
from allanite.model.refinement._rolloff import CIC_SPAN, needs_samples, needs_spectrum, sinc_choice, sinc_grids
from allanite.model.refinement.candidates import CURVE_CANDIDATES, bandwidth_grids
from allanite.model.refinement.curvefit import Curve

FS = 200.0


def _cic(w: np.ndarray, order: int, dec: int) -> np.ndarray:
    """``w`` through ``order`` boxcars of ``dec`` taps, every ``dec``-th sample kept."""
    h = np.ones(dec) / dec
    for _ in range(order - 1):
        h = np.convolve(h, np.ones(dec) / dec)
    return signal.oaconvolve(w, h, mode="valid")[::dec]


def _cic_cutoff(order: int, dec: int, fs: float) -> float:
    """−3 dB frequency of the discrete CIC (``order`` boxcars of ``dec`` taps at fs·dec)."""

    def gain(f):
        x = math.pi * f / (fs * dec)
        return (math.sin(dec * x) / (dec * math.sin(x))) ** order - 1 / math.sqrt(2)

    return float(optimize.brentq(gain, 1e-6, fs / 2))


def test_kinds_and_orders():
    assert tuple(f"sinc{k}" for k in SINC_ORDERS) == ("sinc2", "sinc3", "sinc4", "sinc5")
    assert all(f"sinc{k}" in FILTERS for k in SINC_ORDERS)
    assert [sinc_order(k) for k in ("sinc2", "sinc5", "sinc1", "sinc6", "boxcar", "sincx")] == [2, 5, 0, 0, 0, 0]


def test_autocorrelation_is_the_b_spline_at_the_output_lags():
    # span one output sample: M_2k(l), zero from lag k on; M_4: 2/3, 1/6; M_6: 66, 26, 1 (/120)
    r2, r3 = sinc_autocorrelation(2, 1.0), sinc_autocorrelation(3, 1.0)
    assert r2.size == 2 and r2[1] / r2[0] == pytest.approx(0.25, abs=1e-12)
    assert r3.size == 3 and r3[1] / r3[0] == pytest.approx(26 / 66) and r3[2] / r3[0] == pytest.approx(1 / 66)
    for k in SINC_ORDERS:
        for span in (0.8, 1.0, 1.7):
            r = filter_autocorrelation(f"sinc{k}", span, FS)
            assert r[0] + 2 * r[1:].sum() == pytest.approx(1.0) and r.size == math.ceil(k * span)
        # the discrete CIC's autocorrelation (every 64th lag of the 2k-fold boxcar) tends to the spline
        h = np.ones(64) / 64
        for _ in range(k - 1):
            h = np.convolve(h, np.ones(64) / 64)
        disc = np.correlate(h, h, "full")[h.size - 1 :][::64][:k]
        spline = sinc_autocorrelation(k, 1.0)
        np.testing.assert_allclose(disc / disc[0], spline / spline[0], atol=3e-4)
    # spans shorter than 1/k are white: nothing to fold
    assert sinc_autocorrelation(4, 0.1).tolist() == [1.0]


def test_cutoff_is_the_continuous_filters():
    # order 1 is the boxcar's 0.4430·f_s/D; a sinc³ CIC 3200 → 200 Hz: 52.39 Hz, the discrete filter's 52.48 Hz
    assert sinc_cutoff(1, 2.0, FS) == pytest.approx(filter_cutoff("boxcar", 2.0, FS), rel=1e-4)
    assert filter_cutoff("sinc3", 1.0, FS) == pytest.approx(52.39, abs=0.01)
    assert filter_cutoff("sinc3", 1.0, FS) == pytest.approx(_cic_cutoff(3, 16, FS), rel=0.003)
    for k in SINC_ORDERS:  # |H|² = ½ there, and a longer span a lower cutoff
        x = math.pi * sinc_cutoff(k, 1.3, FS) * 1.3 / FS
        assert (math.sin(x) / x) ** (2 * k) == pytest.approx(0.5, rel=1e-9)
        assert sinc_cutoff(k, 2.0, FS) == pytest.approx(sinc_cutoff(k, 1.0, FS) / 2)


@pytest.mark.parametrize("order", SINC_ORDERS)
def test_allan_variance_matches_a_simulated_cic(order):
    # white noise at 16·f_s through the CIC, read at f_s: the Allan variance per N² of the spline's autocorrelation
    dec, n = 16, 300_000
    rng = np.random.default_rng(10 + order)
    y = _cic(rng.standard_normal(n * dec + order * dec) * math.sqrt(FS * dec), order, dec)[:n]
    tau = np.array([1, 2, 3, 4, 6, 10]) / FS  # scatter of the estimate ≲ 0.7 % up to m = 10
    sim = allanite.avar(y, FS, taus=tau).avar
    np.testing.assert_allclose(sim, filtered_white_avar(tau, f"sinc{order}", 1.0, FS), rtol=0.02)
    # the boxcar of the same cutoff does not (the check can fail): a sinc^k is not a triangle
    span = filter_cutoff("boxcar", 1.0, FS) / filter_cutoff(f"sinc{order}", 1.0, FS)
    box = filtered_white_avar(tau, "boxcar", span, FS)
    # (sinc³: 2.6 % off at m = 1 where the spline's form is 0.2 % off; the others 6–9 %)
    assert (
        abs(sim[0] / box[0] - 1.0)
        > 0.02
        > 0.01
        > abs(sim[0] / filtered_white_avar(tau[0], f"sinc{order}", 1.0, FS)[0] - 1)
    )


def test_sinc_grids_follow_the_boxcar_cutoffs():
    box = np.geomspace(1.02, 20.0, 32)
    for kind, grid in sinc_grids(box).items():
        k = sinc_order(kind)
        assert grid.size == 32 and grid[0] >= 1.02 / k
        assert filter_cutoff(kind, grid[-1], FS) == pytest.approx(filter_cutoff("boxcar", 20.0, FS), rel=1e-9)


class _Sol:
    def __init__(self, chi2):
        self.chi2 = chi2


def test_sinc_choice_rules():
    tie = 10.0

    def f(kind, p, chi2, edge=False):
        return (f"bandwidth:{kind}", p, _Sol(chi2), edge)

    box = f("boxcar", 1.66, 156.0)
    sincs = [f("sinc2", 1.24, 83.4), f("sinc3", 1.00, 83.5), f("sinc4", 0.87, 85.3), f("sinc5", 0.78, 87.9)]
    # beyond the boxcar: of the tied orders the one whose span is nearest one output sample
    assert [x[0] for x in sinc_choice([box] + sincs, tie)] == ["bandwidth:boxcar", "bandwidth:sinc3"]
    # an MA(1) roll-off (a boxcar of 1–2 samples): every order ties with it, none kept
    ma1 = [f("boxcar", 1.2, 50.0), f("sinc2", 0.95, 49.0), f("sinc3", 0.62, 49.5)]
    assert [x[0] for x in sinc_choice(ma1, tie)] == ["bandwidth:boxcar"]
    # a boxcar over two samples tied with a sinc of span one: the CIC reading; at a span of 1.3 not
    long = [f("boxcar", 2.1, 190.4), f("sinc3", 1.14, 190.3), f("sinc4", 0.99, 193.4)]
    assert sinc_choice(long, tie)[-1][0] == "bandwidth:sinc4"
    far = [f("boxcar", 2.1, 190.4), f("sinc3", 1.3, 190.3)]
    assert 1.3 > CIC_SPAN and [x[0] for x in sinc_choice(far, tie)] == ["bandwidth:boxcar"]
    # an order at the edge of its grid is not identified
    assert [x[0] for x in sinc_choice([box, f("sinc3", 1.0, 80.0, True)], tie)] == ["bandwidth:boxcar"]


def test_refine_names_a_cic_and_its_cutoff():
    # a sinc⁴ CIC 1600 → 200 Hz (main named a boxcar of 2.1 samples, its cutoff 8 % low)
    order, dec, n = 4, 8, 300_000
    rng = np.random.default_rng(7)
    y = _cic(rng.standard_normal(n * dec + order * dec) * 4e-3 * math.sqrt(FS * dec), order, dec)[:n]
    y = y + allanite.simulate(n, FS, K=2e-5, seed=rng)
    r = allanite.refine(y, FS)
    assert r.found == ["bandwidth"]
    st = r.steps[0]
    assert st.params["filter"] == "sinc4" and st.params["taps"] == pytest.approx(1.0, abs=0.05)
    assert st.params["cutoff"] == pytest.approx(_cic_cutoff(order, dec, FS), rel=0.03)
    assert r.curve_errors(r.fit)["chi2_dof"] < 1.6 and not r.unexplained


def test_sinc_kinds_only_with_samples():
    # a steep shape the Allan curve alone does not pin (as a Butterworth's): not proposed on a curve alone
    assert all(needs_samples(f"sinc{k}") and not needs_spectrum(f"sinc{k}") for k in SINC_ORDERS)
    assert not needs_samples("boxcar") and needs_samples("butterworth2")
    m = np.unique(np.geomspace(1, 20_000, 40).astype(int)).astype(float)
    curve = Curve(m / FS, m, FS / m, FS, 1_000_000, "oavar")
    grids = bandwidth_grids(curve)
    assert {f"sinc{k}" for k in SINC_ORDERS} <= set(grids)
    family = CURVE_CANDIDATES["bandwidth"].family
    with_samples, curve_only = family(curve, True), family(curve, False)
    steep = sum(grids[k].size for k in grids if needs_samples(k))
    assert len(with_samples) - len(curve_only) == steep > sum(grids[f"sinc{k}"].size for k in SINC_ORDERS)
