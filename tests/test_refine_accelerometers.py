"""refine on quantised accelerometer-like records (issue 29): after the merge of line families and impulsive noise,
the default call on every ADIS16405 accelerometer took an "outliers" step of one sample in 10⁶ (the differences'
tail is really heavier than Gaussian there, but one sample moves nothing on the Allan curve) and lost the 0.56 Hz
site line (its family, whose phase wanders across the record, was turned down in time and its lines were offered
to no candidate). Simulated records at other rates and LSBs, and the real run 1 acc_x when the shared data are
there."""

from __future__ import annotations

import numpy as np
import pytest

import allanite
from allanite.model import outliers
from allanite.model.refinement import levels


def _accelerometer(n, fs, lsb_sigma, seed, offset=0.0):
    """White + flicker + a site line (0.3 σ of the white noise at 0.56 Hz), quantised to ``lsb_sigma`` σ."""
    n_white = 1e-3
    sigma = n_white * np.sqrt(fs)
    y = allanite.simulate(n, fs, N=n_white, B=2e-4, sinusoid=[(0.3 * sigma, 0.56, 0.4)], seed=seed)
    lsb = lsb_sigma * sigma
    return lsb * np.round(y / lsb + offset)


@pytest.mark.parametrize("fs", [50.0, 200.0, 400.0])
@pytest.mark.parametrize("lsb_sigma", [0.3, 0.6, 1.0])
def test_the_outlier_test_passes_quantised_gaussian_records(fs, lsb_sigma):
    # the lattice-aware robust scale: exceedances at 4–7 σ match the Gaussian count on every LSB and offset
    a = levels.alpha("outliers", levels.LEVEL)
    for seed, offset in ((1, 0.0), (2, 0.25), (3, 0.5)):
        y = _accelerometer(400_000, fs, lsb_sigma, seed, offset)
        r = outliers.outlier_test(y, fs, a)
        assert r["step"] > 0, "the lattice must be seen"
        assert not r["accepted"], (fs, lsb_sigma, seed, r["cuts"])
        four = r["cuts"][0]
        assert 0.6 < (four["count"] + 1) / (four["expected"] + 1) < 1.6, four


def test_refine_on_a_quantised_accelerometer_takes_the_line_and_no_outliers():
    # and three impulsive samples of 9 σ, as an ADIS16405 accelerometer's tail holds a few: beyond the Gaussian
    # count (the test finds them; before, refine removed them as a step), they move τ₀'s estimate by a fraction
    # of its standard error
    fs, n = 200.0, 300_000
    y = _accelerometer(n, fs, 0.7, seed=5)
    sigma = 1e-3 * np.sqrt(fs)
    y[[40_001, 150_003, 260_005]] += 9 * sigma * np.array([1.0, -1.0, 1.0])
    r = allanite.refine(y, fs, progress=False)
    assert "outliers" not in r.found
    why = [e.get("rejected", "") for e in r.considered["outliers"]]
    assert any("moves the Allan curve by" in w for w in why), why
    assert not any(u["domain"] == "outliers" for u in r.unexplained)
    assert r.found[0] == "sinusoid" and abs(r.steps[0].params["f0"] / 0.56 - 1) < 1e-3


def test_one_glitch_that_moves_the_curve_is_removed_and_the_rule_is_kept():
    # no least count of samples: one glitch of 300 σ in 2·10⁵ samples doubles the Allan variance at τ₀ — a real
    # log's dropout or bit flip — and is removed; what decides is how far the curve moves (≥ 2 standard errors)
    fs = 50.0
    y = allanite.simulate(200_000, fs, N=2e-3, B=3e-4, seed=8)
    sigma = 2e-3 * np.sqrt(fs)
    y[123_457] += 300 * sigma
    r = allanite.refine(y, fs, progress=False)
    assert r.found[0] == "outliers"
    st = r.steps[0]
    assert st.evidence["flagged"] == 1 and st.evidence["flagged_s"] == [pytest.approx(123_457 / fs)]
    assert st.evidence["curve_change"]["z"] >= st.evidence["curve_change"]["material_z"] == 2.0


@pytest.fixture(scope="module")
def adis_run1_acc_x(shared_data):
    path = shared_data / "adis16405" / "adis16405_run1_100Hz.csv.gz"
    if not path.is_file():
        pytest.skip(f"{path} not found")
    y = np.asarray(allanite.read_log(path, fs=100.0, columns=["acc_x"]).data, dtype=np.float64).ravel()
    return allanite.refine(y, 100.0, progress=False)


@pytest.mark.slow  # ADIS accelerometers: test_refine_line_amplitude.py
def test_adis_run1_acc_x_default_call(adis_run1_acc_x):
    r = adis_run1_acc_x
    # the one sample beyond 7 σ is considered and turned down: it moves τ₀'s estimate by 0.04 standard error
    assert "outliers" not in r.found
    why = [e.get("rejected", "") for e in r.considered["outliers"]]
    assert any("moves the Allan curve by" in w for w in why), why
    assert not any(u["domain"] == "outliers" for u in r.unexplained)
    # the site line first, as before the merge (sinusoid 0.564 Hz, 717 → 237)
    assert r.found[0] == "sinusoid" and abs(r.steps[0].params["f0"] / 0.564 - 1) < 1e-3
    # final χ²/dof on the record's curve: 391.6 with the one-sample removal and without the line, 4.00 now
    assert r.start.chi2_dof > 700 and r.fit.chi2_dof < 8.0
