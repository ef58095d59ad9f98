"""A static curve's fit in the Rust core (``_corefit.fit_curve``) gives ``fit_core``'s fit.

``allanite.fit`` on a static result (and the report's whole-record fits, ``tau_range="auto"``) runs the core's
per-window kernel on the one curve. The reference is ``fit_core``, the Python iteration. They must agree within
10 × GLS_TOL on the model values, every resolved coefficient, χ² and the coefficient variances, leave exactly
the same coefficients at zero, and give the same EDF and normalised residuals per τ — for the GLS fit
(overlapping estimates) and the independent-weights fit (classic, Theo-family), with a term at zero, a ramp,
and every τ.
"""

from __future__ import annotations

import numpy as np
import pytest

import allanite
from allanite.model import _batched, _corefit, _fitcore, _tauselect, fitting
from allanite.model.terms import TERM_ALPHA

TOL = 10 * fitting.GLS_TOL

#: Simulated curves of different shapes (coefficients in the base units of simulate).
CURVES = {
    "adis-like": dict(Q=3.5e-4, N=2e-3, B=1e-3, K=6e-5),
    "clock-like": dict(Q=1e-3, N=1e-4, B=1e-5, K=1e-7),
    "flicker-dominated": dict(N=1e-4, B=1e-2),
    "a term at zero": dict(N=1e-2, K=1e-4),
}


def _args(result, row, terms=fitting.TERMS, thin=True, cut=0.0):
    idx = _tauselect.select_taus(result.tau, np.asarray(row, dtype=np.float64), thin, len(terms), "x", (cut, np.inf))
    est = _tauselect.estimator_key(result, idx)
    m = result.m[idx].astype(np.float64)
    return (result.tau[idx], m, np.asarray(row)[idx], result.fs, result.n_samples + 1, est, tuple(terms), 0.683, 50)


def _check(args):
    """Both paths on one curve; returns the reference's θ."""
    th0, cov0, model0, nu0, z0, it0, a0, chi20 = _fitcore.fit_core(*args)
    th, cov, model, nu, z, it, a, chi2 = _corefit.fit_curve(*args)
    np.testing.assert_array_equal(th > 0, th0 > 0)  # zeros exactly
    np.testing.assert_array_equal(a, a0)
    assert it == it0
    assert np.max(np.abs(model - model0) / model0) <= TOL
    on = th0 > 0
    assert np.max(np.abs(np.sqrt(th[on]) - np.sqrt(th0[on])) / np.sqrt(th0[on])) <= TOL
    assert abs(chi2 - chi20) / chi20 <= TOL
    v, v0 = np.diag(cov), np.diag(cov0)
    ok = np.isfinite(v0) & (v0 > 0)  # (at 1e-290 the variances underflow to 0 on both paths)
    assert np.all(np.abs(v[ok] - v0[ok]) <= TOL * v0[ok])
    np.testing.assert_array_equal(np.isfinite(cov), np.isfinite(cov0))
    np.testing.assert_allclose(nu, nu0, rtol=TOL)
    np.testing.assert_allclose(z, z0, rtol=0, atol=TOL * max(1.0, float(np.max(np.abs(z0)))))
    return th0


@pytest.fixture(scope="module")
def records():
    return {name: allanite.simulate(200_000, 100.0, seed=5, **kw) for name, kw in CURVES.items()}


@pytest.mark.parametrize("name", list(CURVES))
def test_gls_fit_agrees(records, name):
    r = allanite.avar(records[name], 100.0)
    th = _check(_args(r, r.avar))
    if name == "a term at zero":
        assert 0 < np.count_nonzero(th == 0) < th.size  # the zero pattern is tested, not trivially all-positive


@pytest.mark.parametrize("name", list(CURVES))
def test_independent_weights_fit_agrees(records, name):
    r = allanite.avar(records[name], 100.0, estimator="avar")
    _check(_args(r, r.avar))


def test_a_ramp_every_tau_and_a_theo_family_result_agree(records):
    r = allanite.avar(records["adis-like"], 100.0)
    _check(_args(r, r.avar, terms=("N", "B", "K", "R")))
    _check(_args(r, r.avar, terms=("N", "K"), thin=False))
    t = allanite.avar(records["flicker-dominated"][:50_000], 100.0, estimator="theobr")
    _check(_args(t, t.avar, terms=("N", "B", "K")))


def test_extreme_units_agree(records):
    """Estimates of 1e-290 and 1e290 (samples in extreme units): the power-of-two scaling on both paths."""
    r = allanite.avar(records["adis-like"], 100.0)
    for f in (1e-145, 1e145):
        s = allanite.avar(records["adis-like"] * f, 100.0)
        assert s.avar.max() > 1e280 or s.avar.max() < 1e-280
        th = _check(_args(s, s.avar))
        np.testing.assert_allclose(th / (f * f), _fitcore.fit_core(*_args(r, r.avar))[0], rtol=1e-9)


def test_a_fit_the_core_hands_back_is_the_reference(records, monkeypatch):
    r = allanite.avar(records["adis-like"], 100.0)
    args = _args(r, r.avar)
    real = _batched.fit_windows

    def hand_back(*a, **kw):
        theta, cov, chi2, it, status = real(*a, **kw)
        status[:] = 1  # as if the core had met an indefinite covariance
        theta[:] = np.nan
        return theta, cov, chi2, it, status

    monkeypatch.setattr(_batched, "fit_windows", hand_back)
    got, want = _corefit.fit_curve(*args), _fitcore.fit_core(*args)
    for g, w in zip(got, want):
        np.testing.assert_array_equal(g, w)


def test_the_edf_of_a_cut_is_sliced_from_the_uncut_curve(records):
    r = allanite.avar(records["clock-like"], 100.0)
    idx = _tauselect.select_taus(r.tau, r.avar, True, 5, "x")
    m = r.m[idx].astype(np.float64)
    _corefit._nu_terms(m, r.n_samples + 1, "oavar", fitting.TERMS, None)
    sliced = _corefit._nu_terms(m[3:], r.n_samples + 1, "oavar", fitting.TERMS, None)
    n = r.n_samples + 1
    fresh = np.column_stack(
        [_fitcore.edf_per_tau(np.full(m.size - 3, TERM_ALPHA[t]), m[3:], n, "oavar") for t in fitting.TERMS]
    )
    np.testing.assert_array_equal(sliced, fresh)


def test_public_static_fit_runs_in_the_core(records, monkeypatch):
    """allanite.fit on a static result (and tau_range='auto', the report's) goes through the core: with the
    reference swapped out, every fit still comes back."""
    r = allanite.avar(records["adis-like"], 100.0)

    def no_reference(*a, **kw):
        raise AssertionError("fit_core called")

    want = allanite.fit(r, tau_range="auto")
    monkeypatch.setattr(_corefit, "fit_core", no_reference)
    got = allanite.fit(r, tau_range="auto")
    for t in fitting.TERMS:
        assert got.coefficients[t].value == want.coefficients[t].value


def test_measured_curves_agree(shared_data):
    path = shared_data / "adis16405" / "adis16405_run1_100Hz.csv.gz"
    if not path.is_file():
        pytest.skip(f"{path} not found")
    log = allanite.read_log(path, fs=100.0, columns=["gyro_x", "gyro_y", "gyro_z", "acc_x"])
    st = allanite.avar(log.data, 100.0)
    for row in st.avar:
        for cut in (0.0, 0.02, 0.04, 0.08, 0.16):  # the report's tau_range='auto' cuts
            _check(_args(st, row, cut=cut))
