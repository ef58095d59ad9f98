"""A rate quantised at the output after a smoothing filter (allanite.model._quantiser): the floor after the filter is
its error's exact Allan variance, and the default ``refine`` takes it (benches/refine_bartlett_null.py)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from scipy import signal

import allanite
from allanite.model._quantiser import detect_output_quantiser, error_autocorrelation


def _bartlett_output(n: int, quantum: float, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """(quantised output, its error) of unit white noise through a Bartlett of 7 taps, quantised at ``quantum``
    times the output's SD, with a bias of a random share of the step."""
    rng = np.random.default_rng(seed)
    box = np.full(4, 0.25)
    h = np.convolve(box, box)
    x = signal.lfilter(h, [1.0], rng.standard_normal(n + 16))[16:] + rng.uniform(0.0, 1.0)
    step = quantum * float(np.sqrt(h @ h))
    y = np.round(x / step) * step
    return y, y - x


def _avar(e: np.ndarray, m: int) -> float:
    s = np.cumsum(np.concatenate(([0.0], e)))
    means = (s[m:] - s[:-m]) / m
    return float(0.5 * np.mean((means[m:] - means[:-m]) ** 2))


def test_error_autocorrelation_is_the_sawtooths():
    # R_e(0) = Δ²/12; far apart (D ≫ Δ²) nothing; at D = Δ²/100 the first term e^{−4π²/100}/(2π²) dominates
    r = error_autocorrelation(np.array([0.0, 0.01, 5.0]))
    assert r[0] == pytest.approx(1 / 12, rel=1e-3)
    assert r[1] == pytest.approx(
        sum(np.exp(-4 * np.pi**2 * k * k * 0.01) / (2 * np.pi**2 * k * k) for k in range(1, 50))
    )
    assert r[2] < 1e-12


def test_the_floor_of_a_coarse_quantum_is_its_errors_allan_variance():
    # quantum 1.2× the output's SD (the ADIS-like Bartlett of refine_declared_null): the error's lag-1 correlation is
    # ≈ 0.05, read off the samples alone; the floor's factor over white matches the error's own Allan variance
    y, e = _bartlett_output(400_000, 1.2, 1)
    q = detect_output_quantiser(y, 100.0)
    assert q is not None
    rho1 = float(np.mean(e[1:] * e[:-1]) / np.mean(e * e))
    assert q.rho[1] == pytest.approx(rho1, abs=0.01)
    assert 0.03 < q.rho[1] < 0.08
    white = float(np.var(e))
    for m in (1, 2, 4):
        measured = _avar(e, m) / (white / m)
        assert float(q.factor(m)[0]) == pytest.approx(measured, abs=0.02)
    # the white floor is off by that much at m = 1 and 2: what the old white floor column missed
    assert abs(float(q.factor(1)[0]) - 1.0) > 0.03


def test_a_fine_quantum_is_left_white():
    y, _e = _bartlett_output(100_000, 0.2, 2)
    assert detect_output_quantiser(y, 100.0) is None
    assert detect_output_quantiser(np.random.default_rng(3).standard_normal(5000), 100.0) is None  # no lattice


@pytest.mark.slow  # covered by default: test_the_floor_of_a_coarse_quantum_is_its_errors_allan_variance
def test_refine_takes_the_bartlett_and_its_floor():
    # benches/refine_declared_null.py's record 7 (a clean quantised Bartlett): before, a sinc⁵ of 2.4 samples and
    # "the Allan curve departs from the model"; now the Bartlett of 7 taps, its floor, nothing unexplained
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benches"))
    import refine_declared_null as d

    _name, y, fs, _spec = d.record(7)
    r = allanite.refine(y, fs, progress=False)
    assert r.found == ["bandwidth"] and r.unexplained == []
    params = r.steps[0].params
    assert params["filter"] == "bartlett" and params["taps"] == 7
    assert params["floor"] > 0
