"""A fixed spectral line on the Allan curve adds to the estimates' covariance only its cross term with the noise
(issue 29: refine_blind6's 7.3 Hz row — white noise plus a strong line read GLS χ²/dof 5.9 after the exact
sinusoid was taken, and a stand-in term was added; ``benches/line_covariance.py``)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import allanite
from allanite.model.refinement.calibrated import noise_psd
from allanite.model.refinement.curvefit import held_coherent, held_key, held_theta


def test_white_noise_and_a_strong_line_end_at_the_line_alone():
    fs, n = 7.3, 60_000
    rng = np.random.default_rng(1)
    t = np.arange(n) / fs
    y = 4e-3 * math.sqrt(fs) * rng.standard_normal(n) + 0.042 * np.sin(2 * np.pi * 1.0 * t + 2.2)
    r = allanite.refine(y, fs, unit="deg/s", candidates=("sinusoid",), progress=False)
    assert r.found == ["sinusoid"]
    st = r.steps[0]
    assert st.params["f0"] == pytest.approx(1.0, rel=1e-3)
    assert st.params["amplitude"] == pytest.approx(0.042, rel=0.05)
    assert st.evidence["coherent_amplitude"] == pytest.approx(0.042, rel=0.05)
    # the line's Allan variance is exact; with the noise's covariance scaled by model/terms the estimates got a
    # noise 14× the white one's scatter and correlation where the line dominates: χ²/dof 6.1 and "the Allan
    # curve departs from the model" (1.63 with the line's cross term)
    assert st.after["chi2_dof"] < 2.5
    assert r.unexplained == []


def test_a_held_key_carries_the_coherent_share():
    key = held_key("sinusoid", 4e-4, 1e-10, 0.25)
    assert held_theta(key) == (4e-4, 1e-10)
    assert held_coherent(key) == 0.25
    # not measured (or not held): all of it is noise to the tests' covariance
    assert held_coherent(held_key("sinusoid", 4e-4, 1e-10)) == 0.0
    assert held_theta(held_key("sinusoid", 4e-4, 1e-10)) == (4e-4, 1e-10)
    assert held_coherent("gauss_markov") == 0.0
    assert held_coherent(held_key("sinusoid", 4e-4, 1e-10, 1.7)) == 1.0  # clipped to [0, 1]


def test_noise_psd_per_sample():
    fs = 100.0
    assert noise_psd(("N",), (4e-6,), 3.0, fs) == pytest.approx(4e-6 * fs)  # σ² of white noise
    # a sampled random walk of increments' variance K²/fs: K²/(fs·4 sin²(πf/fs))
    assert noise_psd(("K",), (1e-6,), 0.3, fs) == pytest.approx(1e-6 / (fs * 4 * math.sin(math.pi * 0.003) ** 2))
    assert noise_psd(("N", "R"), (4e-6, 1.0), 3.0, fs) == pytest.approx(4e-6 * fs)  # a ramp is no noise
