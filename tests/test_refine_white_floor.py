"""White noise after the sensor's filter: the bandwidth effect's N column beside the filtered one (its ``floor``).

A digital part quantises its output after its decimation filter: a step Δ adds white *rate* noise of Δ²/12 per
sample — Allan variance Δ²·τ0/(12τ), N's τ⁻¹ slope, not Q's τ⁻² — so floor = Δ·√(τ0/12). Before the floor was
modelled, blind suite 3's quantised 4th-order filter at 400 Hz of 2 kHz was read with a 704 Hz resonance (Q 2)
that is not there, and a 3rd order plus white angle noise stood in for the 4th plus the floor (the two within
0.08 % on the Allan curve; the spectrum above f_s/4 tells them apart: :func:`white_psd_misfit`). Beside a
Butterworth always (:func:`has_floor`); beside a single pole or a moving average only where the spectrum shows a
floor and the Allan curve's fit agrees with it (:func:`floor_choice`) — before, a quantised single pole read its
cutoff 7–10 % high and a quantised 4-tap average took a resonance for the floor."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
from scipy import signal

import allanite
from allanite.estimators.grid import tau_grid
from allanite.model.effects import filter_cutoff
from allanite.model.refinement._rolloff import PSD_MISFIT_FACTOR, _floor_agrees, psd_white, white_psd_misfit
from allanite.model.refinement.candidates import bandwidth_grids
from allanite.model.refinement.curvefit import FLOOR_TAG, Curve, has_floor, search

N = 4e-3  # °/√s of white rate noise before the filter


def _record(seed: int, fs: float, filt, step: float, n: int = 400_000) -> np.ndarray:
    """White rate noise N plus a little rate random walk, through ``filt`` ("pole" at f_s/10, "ma4" a 4-tap moving
    average, an int: the
    Butterworth of that order at f_s/5, None: no filter), rounded to ``step`` white-noise σ (N·√f_s)."""
    rng = np.random.default_rng(seed)
    y = allanite.simulate(n, fs, N=N, K=2e-5, seed=rng)
    if filt == "ma4":
        y = signal.lfilter(np.full(4, 0.25), [1.0], y)
    elif filt == "pole":
        a = math.exp(-2.0 * math.pi * 0.1)
        y = signal.lfilter([1.0 - a], [1.0, -a], y)
    elif filt:
        y = signal.sosfilt(signal.butter(int(filt), 0.2 * fs, fs=fs, output="sos"), y)
    if step:
        lsb = step * N * math.sqrt(fs)
        y = np.round(y / lsb) * lsb
    return y


def _floor(step: float) -> float:
    """The quantisation's white rate noise as N: Δ·√(τ0/12) with Δ = step·N·√f_s."""
    return step * N / math.sqrt(12.0)


@pytest.mark.slow  # floor: single pole, 4-tap
def test_a_quantised_4th_order_butterworth_keeps_its_order_and_finds_the_floor():
    fs = 2000.0
    r = allanite.refine(_record(1, fs, 4, 1.0), fs)
    assert [s.effect for s in r.steps] == ["bandwidth"]  # no resonance standing in for the floor
    p = r.steps[0].final_params
    assert p["filter"] == "butterworth4" and p["cutoff"] == pytest.approx(400.0, rel=0.01)
    assert p["floor"] == pytest.approx(_floor(1.0), rel=0.10)
    lo, hi = r.steps[0].final_intervals["floor"]
    assert lo < p["floor"] < hi
    assert r.fit.coefficients["N"].value == pytest.approx(N, rel=0.03)  # the white noise before the filter
    # the spectrum above f_s/4 splits the white part after the filter: all floor, no white angle noise
    white = r.steps[0].evidence["psd_white"]
    assert white["floor"] == pytest.approx(_floor(1.0), rel=0.03) and white["q"] < 1e-3 * _floor(1.0)
    assert white["misfit"] < 0.03
    assert r.fit.chi2_dof < 1.5 and not r.unexplained


@pytest.mark.slow  # floor: single pole, 4-tap
def test_a_quantised_2nd_order_butterworth_at_200hz_finds_the_floor():
    fs = 200.0
    r = allanite.refine(_record(7, fs, 2, 1.0, n=300_000), fs)
    assert [s.effect for s in r.steps] == ["bandwidth"]
    p = r.steps[0].final_params
    assert p["filter"] == "butterworth2" and p["cutoff"] == pytest.approx(40.0, rel=0.02)
    assert p["floor"] == pytest.approx(_floor(1.0), rel=0.10)


@pytest.mark.slow  # no floor unquantised: test_no_floor_without_quantisation...
def test_an_unquantised_single_pole_has_no_floor_column():
    # beside a single pole (or a boxcar) a floor trades with the cutoff (the span) and white angle noise on the
    # Allan curve: N stays replaced unless the spectrum shows a floor (curvefit.has_floor, _rolloff.floor_choice)
    assert not has_floor("bandwidth:single_pole") and not has_floor("bandwidth:boxcar")
    assert has_floor("bandwidth:single_pole" + FLOOR_TAG) and has_floor("bandwidth:boxcar" + FLOOR_TAG)
    assert has_floor("bandwidth:butterworth2") and not has_floor("resonance:2")
    fs = 500.0
    r = allanite.refine(_record(1, fs, "pole", 0.0), fs)
    st = r.steps[0]
    assert st.params["filter"] == "single_pole" and "floor" not in st.params
    assert st.params["cutoff"] == pytest.approx(50.0, rel=0.03)


def test_no_floor_without_quantisation_and_no_bandwidth_without_a_filter():
    fs = 2000.0
    clean = allanite.refine(_record(1, fs, 4, 0.0), fs)
    p = clean.steps[0].final_params
    assert p["filter"] == "butterworth4" and p["cutoff"] == pytest.approx(400.0, rel=0.01)
    assert p["floor"] < 0.1 * _floor(1.0) and clean.steps[0].evidence["psd_white"]["floor"] < 0.1 * _floor(1.0)
    # quantised white noise without a filter is white noise: nothing to add
    plain = allanite.refine(_record(1, fs, None, 1.0), fs)
    assert plain.steps == [] and not plain.unexplained


def test_the_spectrum_tells_the_order_plus_floor_from_an_order_less_plus_white_angle_noise():
    fs = 2000.0
    y = _record(1, fs, 4, 1.0)
    res = allanite.avar(y, fs, taus=tau_grid(y.size, fs, "exp", points=300, m_max=y.size // 9))
    curve = Curve(res.tau, res.m.astype(np.float64), res.avar, fs, res.n_samples + 1, res.estimator)
    grid = bandwidth_grids(curve)["butterworth2"]
    start = ("Q", "N", "B", "K", "R")
    fits = {k: search(curve, start, [], f"bandwidth:butterworth{k}", grid)[:2] for k in (3, 4)}
    # on the curve the two are within a few effective points …
    tie = curve.tau.size / curve.n_eff
    assert abs(fits[4][1].chi2 - fits[3][1].chi2) < tie
    q3, floor4 = fits[3][1].theta[0], fits[4][1].theta[1]
    assert q3 > 0 and floor4 == pytest.approx(_floor(1.0) ** 2, rel=0.2)  # the 3rd order took white angle noise
    # … the spectrum above f_s/4 is flat, as a floor is, not rising as white angle noise does
    mis = {k: white_psd_misfit(y, fs, f"butterworth{k}", p, sol) for k, (p, sol) in fits.items()}
    assert mis[4] < 0.03 and mis[4] < PSD_MISFIT_FACTOR * mis[3]


def test_a_quantised_single_pole_reads_its_cutoff_with_the_floor_beside_it():
    # a step of one σ after a single pole at f_s/10: without the floor the pole's cutoff stood in for it, +6.9 %
    # (benches/refine_white_floor.py's row, this record)
    fs = 2000.0
    r = allanite.refine(_record(2053, fs, "pole", 1.0), fs)
    assert [s.effect for s in r.steps] == ["bandwidth"]
    p = r.steps[0].final_params
    assert p["filter"] == "single_pole" and p["cutoff"] == pytest.approx(200.0, rel=0.03)
    assert p["floor"] == pytest.approx(_floor(1.0), rel=0.20)
    assert r.steps[0].evidence["psd_white"]["floor"] == pytest.approx(_floor(1.0), rel=0.20)
    assert r.fit.coefficients["N"].value == pytest.approx(N, rel=0.03)


@pytest.mark.slow  # floor: the quantised single pole; no resonance: the clean records
def test_a_quantised_4_tap_average_names_no_resonance():
    # a step of ½ σ after a 4-tap moving average at 1 kHz: without the floor a resonance stood in for it
    fs = 1000.0
    r = allanite.refine(_record(2058, fs, "ma4", 0.5), fs)
    assert [s.effect for s in r.steps] == ["bandwidth"]
    p = r.steps[0].final_params
    assert p["filter"] in ("boxcar", "moving_average") and p["cutoff"] == pytest.approx(
        filter_cutoff("moving_average", 4, fs), rel=0.03
    )
    assert p["floor"] == pytest.approx(_floor(0.5), rel=0.20)


def test_a_floor_beside_a_single_pole_is_kept_only_where_the_spectrum_agrees_and_it_is_no_filter_by_itself():
    fs = 2000.0
    y = _record(2053, fs, "pole", 1.0)
    spec = psd_white(y, fs, "single_pole", 200.0, N**2)["floor"]
    assert spec == pytest.approx(_floor(1.0), rel=0.10)

    def found(floor: float, n: float) -> tuple:  # (key, p, a stand-in solution: Q, N (the floor), B, K, R, filter)
        return (
            "bandwidth:single_pole" + FLOOR_TAG,
            200.0,
            SimpleNamespace(theta=np.array([0, floor**2, 0, 0, 0, n**2])),
            False,
        )

    assert _floor_agrees(y, fs, 1, found(spec, N))
    assert _floor_agrees(y, fs, 1, found(1.4 * spec, N)) and not _floor_agrees(y, fs, 1, found(1.6 * spec, N))
    assert not _floor_agrees(y, fs, 1, found(0.0, N))  # white angle noise took it on the curve: no floor
    # a "filter" carrying almost none of the white noise, the floor all of it (the spectrum then agrees): refused
    lone = psd_white(y, fs, "single_pole", 200.0, (0.01 * N) ** 2)["floor"]
    assert not _floor_agrees(y, fs, 1, found(lone, 0.01 * N))
