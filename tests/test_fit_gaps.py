"""fit on a record with NaN-marked gaps (``avar(..., gaps="skip")`` then ``fit(..., gaps="skip")``): the EDF
scaled by each τ's share of terms kept, the peer check against the same record's gapless fit (Stable32 skips
gaps in frequency data the same way; allantools has no gap support), and the errors that name ``gaps``."""

from __future__ import annotations

import numpy as np
import pytest

import allanite
from allanite.errors import ParameterError
from allanite.model._gapfit import gapless_terms

FS = 100.0


def dropped(y, seed, n_gaps=20, frac=0.01):
    """``y`` with ``frac`` of its samples marked missing in ``n_gaps`` equal gaps at seeded places."""
    z = y.copy()
    width = max(1, int(frac * y.size / n_gaps))
    for s in np.random.default_rng(seed).choice(y.size - width, n_gaps, replace=False):
        z[s : s + width] = np.nan
    return z


@pytest.fixture(scope="module")
def pair():
    y = allanite.simulate(50_000, FS, N=0.01, K=1e-3, seed=5)
    z = dropped(y, 6)
    full = allanite.fit(allanite.avar(y, FS), terms=("N", "K"), unit="deg/s")
    gap = allanite.fit(allanite.avar(z, FS, gaps="skip"), terms=("N", "K"), unit="deg/s", gaps="skip")
    return y, z, full, gap


def test_gapped_fit_agrees_with_the_full_record_within_intervals(pair):
    # peer check: the same record with its gaps' samples present; each fit's value inside the other's interval
    _y, z, full, gap = pair
    for t in ("N", "K"):
        a, b = full.coefficients[t], gap.coefficients[t]
        assert a.ci[0] <= b.value <= a.ci[1], (t, a, b)
        assert b.ci[0] <= a.value <= b.ci[1], (t, a, b)
    # the gapped intervals are wider (fewer terms), not narrower
    assert np.diff(gap.coefficients["K"].ci)[0] > np.diff(full.coefficients["K"].ci)[0]
    lost = int(np.isnan(z).sum())
    assert lost == 500 and gap.notes[0].startswith(f"{lost} of 50000 samples missing (1 %)")
    assert "τ from" in gap.notes[0] and "left out (gaps='skip')" in gap.notes[0]


def test_tau_with_too_few_terms_kept_are_left_out(pair):
    from allanite.model._gapfit import MIN_SHARE

    _y, z, _full, _gap = pair
    r = allanite.avar(z, FS, gaps="skip")
    share = r.n / gapless_terms("oavar", r.m, r.n_samples)
    few = (r.n > 0) & (share < MIN_SHARE)
    assert MIN_SHARE == 0.1 and few.any()  # this record has τ with a few runs of terms left
    f = allanite.fit(r, terms=("N", "K"), gaps="skip", thin=False)
    assert set(f.tau) == set(r.tau[share >= MIN_SHARE])
    assert f"{int(few.sum())} τ from {r.tau[few][0]:g} s with under 10 % of the terms left out" in f.notes[0]


def test_edf_is_the_full_records_times_the_share_of_terms_kept(pair):
    # one term: ν = 2·model²/var does not depend on its coefficient, so the ratio is the share exactly
    y, z, _full, _gap = pair
    r = allanite.avar(z, FS, gaps="skip")
    share = dict(zip(r.tau, r.n / gapless_terms("oavar", r.m, r.n_samples)))
    full = allanite.fit(allanite.avar(y, FS), terms=("N",), thin=False)
    gap = allanite.fit(r, terms=("N",), gaps="skip", thin=False)
    common = np.intersect1d(full.tau, gap.tau)
    assert common.size >= 10 and gap.method == full.method == "gls"
    for t in common:
        i, j = np.flatnonzero(full.tau == t)[0], np.flatnonzero(gap.tau == t)[0]
        assert gap.edf[j] / full.edf[i] == pytest.approx(share[t], rel=1e-6), t
    assert min(share.values()) < 0.5 < max(share.values())


def test_a_tau_without_complete_terms_is_an_error_naming_gaps_skip(pair):
    _y, z, _full, _gap = pair
    r = allanite.avar(z, FS, gaps="skip")
    assert np.isnan(r.avar[-1]) and r.n[-1] == 0 and r.missing == 500
    with pytest.raises(ParameterError, match="pass gaps='skip'"):
        allanite.fit(r, terms=("N", "K"))
    with pytest.raises(ParameterError, match="unknown gaps 'nan'"):
        allanite.fit(r, gaps="nan")


def test_gapless_result_is_fitted_as_before_with_gaps_skip(pair):
    y, _z, full, _gap = pair
    r = allanite.avar(y, FS)
    again = allanite.fit(r, terms=("N", "K"), unit="deg/s", gaps="skip")
    assert r.missing == 0 and again.notes == full.notes
    np.testing.assert_array_equal(again.theta, full.theta)
    # gaps="skip" on a record with no NaN: the same numbers and no gap note
    s = allanite.avar(y, FS, gaps="skip")
    assert s.missing == 0
    np.testing.assert_allclose(allanite.fit(s, terms=("N", "K"), unit="deg/s").theta, full.theta, rtol=1e-9)


def test_scale_for_gaps_scales_edf_by_the_share_and_covariance_by_its_root():
    from allanite.model._fitcore import scale_for_gaps

    nu = np.array([[10.0, 20.0], [30.0, 40.0]])
    s_blk, t_blk = np.ones((1, 1, 2, 2)), np.full((1, 2, 2), 2.0)
    nu2, (s2, t2) = scale_for_gaps(np.array([0.5, 0.25]), nu, (s_blk, t_blk))
    np.testing.assert_allclose(nu2, [[5.0, 10.0], [7.5, 10.0]])
    want = 1.0 / np.sqrt(np.outer([0.5, 0.25], [0.5, 0.25]))
    np.testing.assert_allclose(s2[0, 0], want)
    np.testing.assert_allclose(t2[0], 2.0 * want)
    assert scale_for_gaps(None, nu, (s_blk, t_blk))[0] is nu


def test_gapless_terms_match_the_estimators_counts():
    y = np.random.default_rng(2).standard_normal(1_001)
    for est in ("oavar", "avar"):
        r = allanite.avar(y, 1.0, estimator=est, taus="all")
        np.testing.assert_array_equal(gapless_terms(est, r.m, r.n_samples), r.n)
    with pytest.raises(ParameterError, match="'oavar' or 'avar'"):
        gapless_terms("mvar", np.array([1]), 10)


def test_multi_axis_fits_each_axis_with_its_own_gaps(pair):
    y, z, full, gap = pair
    r = allanite.avar(np.c_[z, y], FS, gaps="skip")
    assert list(r.missing) == [500, 0]
    fz, fy = allanite.fit(r, terms=("N", "K"), unit="deg/s", gaps="skip")
    np.testing.assert_allclose(fz.theta, gap.theta, rtol=1e-9)
    assert fy.notes == () and fy.tau.size > fz.tau.size
