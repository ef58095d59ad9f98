"""The batched per-window fit (the Rust core's ``fit_windows``) gives today's per-window fit.

``allanite.fit(dynamic_result)`` fits all windows at once in the core; the reference is the per-window
path, ``fit_core`` on each window in turn. They must agree within 10 × GLS_TOL on the model values and on
every coefficient both resolve, and leave exactly the same coefficients at zero — on simulated and measured
windows, for the GLS fit (overlapping estimates) and the independent-weights fit (classic, DHVAR).
"""

from __future__ import annotations

import numpy as np
import pytest

import allanite
from allanite.model import _batched, _dynamicfit, _tauselect, fitting
from allanite.model.terms import design_matrix

TOL = 10 * fitting.GLS_TOL


def _both(result, terms=fitting.TERMS, thin=True, tau_range=(0.0, np.inf)):
    """(batched, reference) θ, variance of θ, χ² of every window of a one-axis dynamic result."""
    idx = _tauselect.select_taus(result.tau, np.median(result.avar, axis=1), thin, len(terms), "x", tau_range)
    y = np.maximum(np.ascontiguousarray(result.avar[idx].T), 1e-300)
    got = _dynamicfit.window_fits(result, idx, y, terms, 0.683, 50, False)
    th, cov, chi2 = _dynamicfit.window_fits_reference(result, idx, y, terms, 0.683, 50)
    return idx, got, (th, np.diagonal(cov, axis1=1, axis2=2), chi2)


def _check_agreement(result, **kw):
    terms = kw.get("terms", fitting.TERMS)
    idx, (th, var, chi2), (th0, var0, chi20) = _both(result, **kw)
    assert th.shape == th0.shape and th.shape[0] >= 20
    # zeros exactly: the same terms unresolved in every window
    np.testing.assert_array_equal(th > 0, th0 > 0)
    a = design_matrix(result.tau[idx], result.tau[idx] * result.fs, result.fs, terms)
    model, model0 = th @ a.T, th0 @ a.T
    assert np.max(np.abs(model - model0) / model0) <= TOL
    on = th0 > 0
    assert np.max(np.abs(np.sqrt(th[on]) - np.sqrt(th0[on])) / np.sqrt(th0[on])) <= TOL
    # χ² and the coefficient variances behind the intervals follow
    assert np.max(np.abs(chi2 - chi20) / chi20) <= TOL
    ok = np.isfinite(var0) & (var0 > 0)
    assert np.max(np.abs(var[ok] - var0[ok]) / var0[ok]) <= TOL
    return th0


@pytest.fixture(scope="module")
def simulated():
    return allanite.simulate(60_000, 100.0, Q=1e-4, N=0.01, B=1e-3, K=1e-4, seed=11)


def test_gls_windows_agree_on_a_simulated_record(simulated):
    res = allanite.davar(simulated, 100.0, window=401, hop=200)
    th0 = _check_agreement(res)
    # the windows differ in what they resolve (the zero pattern is tested, not trivially all-positive)
    assert 0 < np.count_nonzero(th0 == 0) < th0.size


def test_gls_windows_agree_for_three_terms_and_every_tau(simulated):
    res = allanite.davar(simulated, 100.0, window=2000, hop=1000)
    _check_agreement(res, terms=("N", "B", "K"), thin=False, tau_range=(0.05, 0.6))


def test_classic_windows_agree_through_the_independent_weights_fit(simulated):
    res = allanite.davar(simulated, 100.0, window=3000, hop=1000, estimator="avar")
    _check_agreement(res)


def test_dhvar_windows_agree_through_the_independent_weights_fit(simulated):
    res = allanite.davar(simulated[:30_000], 100.0, window=2000, hop=1000, estimator="theoh", taus="octave")
    _check_agreement(res, terms=("N", "B", "K"), thin=False)


def test_measured_windows_agree(shared_data):
    path = shared_data / "adis16405" / "adis16405_run1_100Hz.csv.gz"
    if not path.is_file():
        pytest.skip(f"{path} not found")
    log = allanite.read_log(path, fs=100.0, columns=["gyro_x"], unit="deg/s")
    x = log.data[:, 0]
    # the report's default geometry (record/12, hop window/25), with and without its 0.1 s cut
    w = x.size // 12
    res = allanite.davar(x, 100.0, window=w, hop=w // 25)
    _check_agreement(res, tau_range=(0.1, np.inf))
    # paper 002's short windows
    _check_agreement(allanite.davar(x[:40_000], 100.0, window=401, hop=1000))


def test_the_series_is_built_from_the_batched_fit(simulated):
    res = allanite.davar(simulated, 100.0, window=401, hop=500)
    s = allanite.fit(res, unit="deg/s")
    idx, _, (th0, var0, chi20) = _both(res)
    zq = fitting.z_quantile(0.683)
    for k, t in enumerate(fitting.TERMS):
        np.testing.assert_allclose(s.values[t], np.sqrt(th0[:, k]), rtol=TOL, atol=0)
        dof = np.maximum(1, idx.size - np.count_nonzero(th0 > 0, axis=1))
        inflate = np.maximum(1.0, np.sqrt(chi20 / dof))
        ref = np.array([fitting.interval(a, b, zq, c) for a, b, c in zip(th0[:, k], var0[:, k], inflate)])
        np.testing.assert_allclose(s.ci_low[t], ref[:, 0], rtol=1e-5, atol=1e-12 * ref[:, 1].max())
        np.testing.assert_allclose(s.ci_high[t], ref[:, 1], rtol=1e-5)


def test_windows_the_core_hands_back_are_refitted_by_the_reference(simulated, monkeypatch):
    res = allanite.davar(simulated, 100.0, window=401, hop=2000)
    want = allanite.fit(res)
    real = _batched.fit_windows

    def hand_back_some(*args, **kw):
        theta, cov, chi2, it, status = real(*args, **kw)
        status[::3] = 1  # as if the core had met an indefinite covariance there
        theta[::3] = cov[::3] = chi2[::3] = np.nan
        return theta, cov, chi2, it, status

    monkeypatch.setattr(_batched, "fit_windows", hand_back_some)
    got = allanite.fit(res)
    for t in fitting.TERMS:
        np.testing.assert_allclose(got.values[t], want.values[t], rtol=TOL, atol=0)


def test_a_flat_window_is_zero_and_not_fitted(simulated):
    x = simulated[:20_000].copy()
    x[:3000] = 0.25  # a sensor not yet streaming
    s = allanite.fit(allanite.davar(x, 100.0, window=1000, hop=1000))
    for t in s.terms:
        assert s.values[t][0] == s.ci_low[t][0] == s.ci_high[t][0] == 0.0
    assert s.chi2_dof[0] == 0.0 and np.all(s.values["N"][3:] > 0)


def test_a_bad_progress_value_is_refused_before_the_fit(simulated):
    res = allanite.davar(simulated, 100.0, window=401, hop=2000)
    with pytest.raises(allanite.ParameterError, match="progress must be True, False or None"):
        allanite.fit(res, progress="yes")
