"""Gap-aware estimation through the public API: ``avar(..., gaps="skip")`` (NaN-marked missing samples,
terms touching one skipped, true term counts in ``n``) against a plain NumPy twin that skips the same
terms (tests/twins_deviations.py), against allantools' ``gradev`` where the conventions agree (m = 1),
and ``read_log(..., gaps="nan")``."""

from __future__ import annotations

import numpy as np
import pytest

import allanite
import twins_deviations as tw
from allanite.errors import DataGapError, InputError, ParameterError

FS = 4.0


def holed(rng, n=600, holes=((10, 2), (200, 1), (341, 7), (599, 1))):
    y = rng.standard_normal(n) + 0.05 * np.cumsum(rng.standard_normal(n)) + 3.0
    for a, w in holes:
        y[a : a + w] = np.nan
    return y


@pytest.mark.parametrize("est", ["oavar", "avar", "mvar", "tvar", "ohvar", "hvar"])
def test_skip_equals_the_twin(est, rng):
    y = holed(rng)
    r = allanite.avar(
        y, FS, taus="all" if est in ("oavar", "avar") else [m / FS for m in range(1, 200)], estimator=est, gaps="skip"
    )
    core = "mvar" if est == "tvar" else est
    want = [tw.gap_var(y, int(m), core) for m in r.m]
    wv = np.array([w[0] for w in want]) * ((r.tau**2 / 3.0) if est == "tvar" else 1.0)
    np.testing.assert_array_equal(r.n, [w[1] for w in want])
    ok = r.n > 0
    np.testing.assert_allclose(r.avar[ok], wv[ok], rtol=1e-10)
    assert np.all(np.isnan(r.avar[~ok]))


@pytest.mark.parametrize("est", ["oavar", "avar", "mvar", "tvar", "ohvar", "hvar"])
def test_skip_without_nan_is_the_plain_estimate(est, rng):
    y = rng.standard_normal(500)
    a = allanite.avar(y, FS, estimator=est, gaps="skip")
    b = allanite.avar(y, FS, estimator=est)
    np.testing.assert_allclose(a.avar, b.avar, rtol=1e-12)
    np.testing.assert_array_equal(a.n, b.n)


def test_angle_input_marks_both_neighbouring_rate_samples(rng):
    x = np.cumsum(rng.standard_normal(401))
    x[[50, 51, 300]] = np.nan
    y = np.diff(x) * FS
    a = allanite.avar(x, FS, input="angle", gaps="skip", taus="all")
    b = allanite.avar(y, FS, gaps="skip", taus="all")  # NaN wherever either angle point is missing
    np.testing.assert_array_equal(a.n, b.n)
    np.testing.assert_allclose(a.avar, b.avar, rtol=1e-12, equal_nan=True)


def test_m1_equals_allantools_gradev(rng):
    allantools = pytest.importorskip("allantools")
    x = np.cumsum(rng.standard_normal(500))
    x[[10, 11, 57, 200, 201, 202, 499]] = np.nan
    t, dev, _, ns = allantools.gradev(x, rate=1.0, data_type="phase", taus=np.array([1.0, 4.0, 16.0]))
    r = allanite.avar(x, 1.0, input="angle", gaps="skip", taus=[1.0, 4.0, 16.0])
    assert r.n[0] == ns[0]
    assert r.adev[0] == pytest.approx(dev[0], rel=1e-12)
    assert np.all(r.n[1:] < ns[1:])  # for m > 1 gradev keeps terms across a gap (documented)


def test_counts_per_axis_and_empty_tau(rng):
    y = rng.standard_normal((300, 2))
    y[40:45, 1] = np.nan
    r = allanite.avar(y, FS, gaps="skip", taus=[0.25, 1.0])
    assert r.n.shape == (2, 2) and r.avar.shape == (2, 2)
    assert np.all(r.n[0] > r.n[1])
    z = np.ones(30)
    z[::4] = np.nan  # no 2-sample term is complete for m ≥ 2
    r = allanite.avar(z, 1.0, gaps="skip", taus=[1.0, 2.0, 5.0])
    assert r.n[0] > 0 and r.n[1] == 0 and r.n[2] == 0
    assert np.isnan(r.avar[1]) and np.isnan(r.avar[2])


def test_default_still_refuses_nan_and_other_estimators_refuse_gaps(rng):
    y = rng.standard_normal(100)
    y[17] = np.nan
    keep = y.copy()
    with pytest.raises(InputError, match="non-finite value \\(nan\\) at sample 17"):
        allanite.avar(y, FS)
    for est in ("totvar", "theo1", "mtotvar"):
        with pytest.raises(
            ParameterError, match='gaps="skip" is supported by the estimators oavar, avar, mvar, tvar, ohvar, hvar'
        ):
            allanite.avar(y, FS, estimator=est, gaps="skip")
    with pytest.raises(ParameterError, match="gaps"):
        allanite.avar(y, FS, gaps="drop")
    allanite.avar(y, FS, gaps="skip")
    np.testing.assert_array_equal(y, keep)  # the caller's array is not written


def test_read_log_fills_gaps_with_nan(tmp_path, rng):
    t = np.arange(100) / 10.0
    t = np.delete(t, [30, 31, 32, 70])
    v = rng.standard_normal(t.size)
    p = tmp_path / "g.csv"
    p.write_text("t,w\n" + "".join(f"{a:.3f},{float(b)!r}\n" for a, b in zip(t, v)), encoding="utf-8")
    with pytest.raises(DataGapError):
        allanite.read_log(p, time_column="t", columns="w")
    log = allanite.read_log(p, time_column="t", columns="w", gaps="nan")
    assert log.data.shape == (100,)
    np.testing.assert_array_equal(np.flatnonzero(np.isnan(log.data)), [30, 31, 32, 70])
    np.testing.assert_array_equal(log.data[~np.isnan(log.data)], v)
    np.testing.assert_allclose(log.time, np.arange(100) / 10.0, atol=1e-9)
    r = allanite.avar(log.data, log.fs, gaps="skip", taus=[0.1])
    assert r.n[0] == 99 - 4 - 2  # m = 1 terms are neighbouring pairs: 4 touch samples 30–32, 2 touch sample 70


@pytest.mark.parametrize("est", ["oavar", "mvar", "ohvar"])
def test_edf_follows_the_complete_terms(est, rng):
    y = rng.standard_normal(2000)
    plain = allanite.avar(y, FS, estimator=est)
    ci_plain = allanite.confidence_intervals(plain, alpha=0)
    # without gaps the term-count route is the record-length route
    want = allanite.edf_greenhall(
        np.zeros(plain.m.size), {"oavar": 2, "mvar": 2, "ohvar": 3}[est], plain.m, y.size + 1,
        overlapping=True, modified=est == "mvar",
    )  # fmt: skip
    np.testing.assert_allclose(ci_plain.edf, want, rtol=1e-12)
    # a record with a hole: the EDF of a gapless record with as many terms, NaN where none is complete
    z = y.copy()
    z[600:1400] = np.nan
    r = allanite.avar(z, FS, estimator=est, gaps="skip")
    ci = allanite.confidence_intervals(r, alpha=0)
    assert np.all(ci.edf[r.n > 0] < ci_plain.edf[r.n > 0])
    assert np.all(np.isnan(ci.edf[r.n == 0]))
    for i in np.flatnonzero(r.n > 0):
        short = allanite.avar(
            y[: int(r.n[i]) + ({"oavar": 2, "mvar": 3, "ohvar": 3}[est]) * int(r.m[i]) - 1 - (est == "mvar")],
            FS,
            estimator=est,
            taus=[r.tau[i]],
        )
        assert short.n[0] == r.n[i]
        assert ci.edf[i] == pytest.approx(allanite.confidence_intervals(short, alpha=0).edf[0], rel=1e-12)


@pytest.mark.parametrize("est, clusters", [("avar", 1), ("hvar", 2)])
def test_classic_edf_follows_the_complete_terms(est, clusters, rng):
    # a classic estimate with n complete terms has the EDF of a gapless record of (n + k)·m samples
    y = rng.standard_normal(2000)
    z = y.copy()
    z[700:1300] = np.nan
    r = allanite.avar(z, FS, estimator=est, gaps="skip")
    ci = allanite.confidence_intervals(r, alpha=0)
    plain = allanite.confidence_intervals(allanite.avar(y, FS, estimator=est), alpha=0)
    ok = r.n > 0
    assert np.all(ci.edf[ok] < plain.edf[ok]) and np.all(np.isnan(ci.edf[~ok]))
    for i in np.flatnonzero(ok)[:12]:
        m = int(r.m[i])
        short = allanite.avar(y[: (int(r.n[i]) + clusters) * m], FS, estimator=est, taus=[r.tau[i]])
        assert short.n[0] == r.n[i]
        np.testing.assert_allclose(ci.edf[i], allanite.confidence_intervals(short, alpha=0).edf[0], rtol=1e-12)
