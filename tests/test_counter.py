"""A delta-angle counter's quantisation (:mod:`allanite.model._counter`): the closed form against simulated
counters, the records read as a counter's and those that are not, and refine on a counter's record.

A counter outputs the differences of its angle quantised at step q; its angle error is correlated from sample to
sample where the angle's noise per sample σ_θ is not large beside q, and 3Q²/τ² (a white angle error) is then
wrong at the shortest τ (blind7's counter took two resonances for it). Every record here is seeded and small.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import allanite
from allanite.model._counter import (
    MIN_EFFECT,
    active_counter,
    angle_error_autocorrelation,
    counter_avar,
    counter_factor,
    counter_quantisation,
    detect_counter,
)

FS = 100.0
N = 1e-2  # white rate noise (°/√s): σ_θ = N/√f_s per sample


def _counter(n: int, step_ratio: float, bias_counts: float, seed: int, drift: float = 0.0):
    """A counter's rate samples and its step q (°): white rate noise N, a mean rate of ``bias_counts`` steps per
    sample, q = ``step_ratio``·σ_θ, and optionally a bias drifting linearly by ``drift`` steps per sample along
    the record (a warming sensor)."""
    rng = np.random.default_rng(seed)
    st = N / math.sqrt(FS)
    q = step_ratio * st
    t = np.arange(n) / FS
    rate = N * math.sqrt(FS) * rng.standard_normal(n) + (bias_counts + drift * t / t[-1]) * q * FS
    counts = np.floor((np.cumsum(rate) / FS + rng.uniform(0.0, q)) / q)
    return np.diff(counts, prepend=counts[0] - round(bias_counts)) * (q * FS), q


def test_autocorrelation_limits():
    """R_e(0) = q²/12; far apart (σ_θ ≫ q or many samples) the error is white; with no noise it is the
    sawtooth's Bernoulli polynomial ½·B₂({b·m}) (b·m = 0.25: (1/16 − 1/4 + 1/6)/2)."""
    assert angle_error_autocorrelation([0], 0.3, 0.2)[0] == pytest.approx(1 / 12)
    assert abs(angle_error_autocorrelation([1], 2.0, 0.0)[0]) < 1e-30
    assert abs(angle_error_autocorrelation([50], 0.3, 0.1)[0]) < 1e-12
    assert angle_error_autocorrelation([1], 1e-9, 0.25)[0] == pytest.approx((1 / 16 - 1 / 4 + 1 / 6) / 2, abs=2e-5)
    assert counter_factor([1, 2], 3.0, 0.4) == pytest.approx([1.0, 1.0], abs=1e-12)


@pytest.mark.parametrize(
    ("step_ratio", "bias", "plain_off"),
    [(3.0, 0.0, 0.04), (3.0, 0.37, 0.03), (8.0, 0.1, 0.2), (0.3, 0.0, None)],
)
def test_closed_form_matches_simulation(step_ratio, bias, plain_off):
    """The counter's Allan variance, N²/τ + (3R_e(0) − 4R_e(m) + R_e(2m))/τ², within 1.2 % of a seeded 10⁶-sample
    counter's at m = 1 … 16 (its estimates' own scatter ≈ 0.3 %) — with a mean rate, and at steps 0.3× to 8× the
    angle noise per sample; where the step is coarse the plain 3Q²/τ² is off by more than ``plain_off`` at τ₀."""
    y, q = _counter(1_000_000, step_ratio, bias, seed=11)
    m = np.array([1, 2, 3, 4, 8, 16])
    tau = m / FS
    est = allanite.avar(y, FS, taus=tau).avar
    exact = N**2 / tau + counter_avar(tau, FS, q, 1.0 / step_ratio, bias % 1.0)
    assert np.max(np.abs(est / exact - 1.0)) < 0.012
    plain = N**2 / tau + q**2 / (4.0 * tau**2)
    if plain_off is not None:
        assert abs(est[0] / plain[0] - 1.0) > plain_off
    else:
        assert np.max(np.abs(est / plain - 1.0)) < 0.012


@pytest.mark.parametrize(("bias", "drift"), [(0.02, 0.0), (0.4, 0.0), (0.1, 0.8)])
def test_detects_a_counter(bias, drift):
    """A counter's record is read as one — its step, its ratio σ_θ/q within 2 %, its phase — also where the
    bias drifts by 0.8 steps per sample along the record (the mean rate a mix of phases, block by block)."""
    y, q = _counter(200_000, 3.0, bias, seed=5, drift=drift)
    c = detect_counter(y, FS)
    assert c is not None
    assert c.step == pytest.approx(q, rel=1e-9)
    assert c.ratio == pytest.approx(1 / 3, rel=0.02)
    assert c.contrast[0] == pytest.approx(c.contrast[1], rel=0.1)
    mean = np.angle(np.dot(c.weights, np.exp(2j * np.pi * np.asarray(c.phases)))) / (2 * np.pi)
    spread = 1.0 - abs(np.dot(c.weights, np.exp(2j * np.pi * np.asarray(c.phases))))
    if drift == 0.0:  # one phase, blurred by the block means' noise (σ_θ/q/√1024 ≈ 0.01)
        assert mean == pytest.approx(bias, abs=0.005) and spread < 0.01
    else:  # 0.1 … 0.9 steps per sample: spread round the circle
        assert spread > 0.5


def _rate_quantised(n: int, lsb_sigma: float, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    x = rng.standard_normal(n) + 0.3
    return np.round(x / lsb_sigma) * lsb_sigma


@pytest.mark.parametrize(
    "make",
    [
        lambda: np.random.default_rng(1).standard_normal(200_000),  # continuous
        lambda: _rate_quantised(200_000, 2.5, 2),  # a rate quantised coarsely at the output: white error
        lambda: _rate_quantised(200_000, 1.0, 3),
        lambda: np.sign(np.round(np.random.default_rng(4).standard_normal(200_000))),  # a dead band
        lambda: _counter(200_000, 1.0, 0.1, seed=6)[0],  # a fine counter: 3Q²/τ² is exact
        lambda: _counter(500, 3.0, 0.1, seed=7)[0],  # too short
    ],
)
def test_not_a_counter(make):
    """Records that are not a counter's (or whose counter the plain Q term already gives to
    :data:`MIN_EFFECT`) are left as they are."""
    assert detect_counter(make(), FS) is None


def test_counter_context_is_scoped():
    y, _q = _counter(200_000, 3.0, 0.1, seed=5)
    c = detect_counter(y, FS)
    assert active_counter() is None
    with counter_quantisation(c):
        assert active_counter() is c
    assert active_counter() is None
    assert np.max(np.abs(1.0 - c.factor(np.arange(1, 9)))) >= MIN_EFFECT


def test_refine_reads_a_counter_as_clean():
    """A counter's record (step 3× its angle noise per sample, 2·10⁵ samples) is clean: nothing added, nothing
    unexplained, Q = q/√12 within 1 %, and the report says the Q term is the counter's. With the plain 3Q²/τ²
    this record took a resonance at 1.3 CPU s (measured; not run here)."""
    y, q = _counter(200_000, 3.0, 0.13, seed=3)
    r = allanite.refine(y, FS, unit="deg/s", progress=False)
    assert r.found == [] and r.unexplained == []
    assert r.counter is not None and r.counter.step == pytest.approx(q, rel=1e-9)
    assert r.fit.coefficients["Q"].value == pytest.approx(q / math.sqrt(12.0), rel=0.01)
    assert "delta-angle counter" in r.report()
    assert any("delta-angle counter" in n for n in r.notes())


def test_detects_a_counter_given_as_its_angle():
    """A counter's angle given in floating point (``input="angle"``) differenced back to a rate: its differences
    carry rounding of ~10⁻¹⁵ beside the steps, and the lattice is still the counter's."""
    y, q = _counter(200_000, 3.0, 0.13, seed=5)
    rate = np.diff(np.cumsum(y) / FS, prepend=0.0) * FS
    assert np.count_nonzero((np.abs(np.diff(rate)) > 0) & (np.abs(np.diff(rate)) < 1e-9)) > 0
    c = detect_counter(rate, FS)
    assert c is not None and c.step == pytest.approx(q, rel=1e-9)
    assert c.ratio == pytest.approx(1 / 3, rel=0.02)


def test_remembered_mixed_cosines_equal_fresh_ones():
    """The root search's cosines (``_counter._mixed_cosines``) are computed once per phase mix and lag and sliced
    for the shorter sums of larger ratios: R_e(m) then equals a fresh computation's to rounding, at every ratio of a
    grid from the longest sum (ratio 0) up; the memory keeps at most 8 entries."""
    from allanite.model import _counter

    rng = np.random.default_rng(5)
    phase = (rng.random(40), np.full(40, 1 / 40))
    ratios = [0.0, 0.01, 0.1, 0.3, 1.0]
    _counter._COSINES.clear()
    kept = [_counter.angle_error_autocorrelation(np.arange(4.0), r, phase) for r in ratios]
    assert 0 < len(_counter._COSINES) <= 8
    for r, got in zip(ratios, kept):
        _counter._COSINES.clear()
        fresh = _counter.angle_error_autocorrelation(np.arange(4.0), r, phase)
        np.testing.assert_allclose(got, fresh, rtol=1e-12, atol=1e-15)
    for lag in range(1, 20):  # more lags than it keeps
        _counter.angle_error_autocorrelation(np.array([float(lag)]), 0.05, phase)
    assert len(_counter._COSINES) == 8
