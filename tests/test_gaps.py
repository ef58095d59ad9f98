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


@pytest.mark.parametrize("est", ["totvar", "mtotvar", "ttotvar", "htotvar"])
def test_total_family_skip_equals_the_twin(est, rng):
    # the total family keeps a term when every original sample it reads is present (TOTVAR's reflected
    # samples mapped back; MTOTVAR/HTOTVAR's 3m-point subsequences whole) — twins: tests/twins_deviations.py
    y = holed(rng, n=160, holes=((3, 2), (70, 1), (101, 6), (159, 1)))
    ms = [1, 2, 3, 5, 8, 13, 21, 34, 52] + ([64, 80] if est == "totvar" else [])
    r = allanite.avar(y, FS, taus=[m / FS for m in ms], estimator=est, gaps="skip")
    core = "mtotvar" if est == "ttotvar" else est
    want = [tw.gap_total(y, m, core) for m in ms]
    wv = np.array([w[0] for w in want]) * ((r.tau**2 / 3.0) if est == "ttotvar" else 1.0)
    np.testing.assert_array_equal(r.n, [w[1] for w in want])
    ok = r.n > 0
    assert ok[:6].all() and np.all(r.n < allanite.avar(np.nan_to_num(y), FS, taus=r.tau, estimator=est).n)
    np.testing.assert_allclose(r.avar[ok], wv[ok], rtol=1e-10)
    assert np.all(np.isnan(r.avar[~ok]))
    # no complete stretch as long as a term: n = 0 and NaN (TOTVAR's reflection reuses the record's own
    # ends, so it does not bridge the hole either)
    z = np.ones(120) + rng.standard_normal(120)
    z[20:100] = np.nan
    r = allanite.avar(z, 1.0, taus=[1.0, 7.0, 30.0], estimator=est, gaps="skip")
    want = [tw.gap_total(z, m, core) for m in (1, 7, 30)]
    np.testing.assert_array_equal(r.n, [w[1] for w in want])
    assert r.n[0] > 0 and r.n[2] == 0 and np.isnan(r.avar[2]) and not np.isnan(r.avar[0])


@pytest.mark.parametrize("est", ["mtie", "tierms"])
def test_mtie_and_tie_skip_keep_the_windows_whose_rate_samples_are_present(est, rng):
    # a phase window [k, k+m] is exact when y[k, k+m) is present, whatever offset a gap before it left
    y = holed(rng, n=400) + 0.2
    ms = [1, 2, 3, 7, 20, 64, 150]
    r = allanite.avar(y, FS, estimator=est, taus=[m / FS for m in ms], gaps="skip")
    for i, m in enumerate(ms):
        vals = []
        for k in range(y.size - m + 1):
            seg = y[k : k + m]
            if np.isnan(seg).any():
                continue
            x = np.concatenate(([0.0], np.cumsum(seg))) / FS
            vals.append(x.max() - x.min() if est == "mtie" else x[-1] ** 2)
        assert r.n[i] == len(vals)
        want = max(vals) if est == "mtie" else np.sqrt(np.mean(vals))
        assert r.adev[i] == pytest.approx(want, rel=1e-10)


@pytest.mark.parametrize(
    "est", ["oavar", "avar", "mvar", "tvar", "ohvar", "hvar", "totvar", "mtotvar", "htotvar", "mtie", "tierms"]
)
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
    for est in ("theo1", "theobr", "theoh"):
        with pytest.raises(
            ParameterError,
            match='gaps="skip" is supported by the estimators oavar, avar, mvar, tvar, ohvar, hvar, totvar, mtotvar, '
            "ttotvar, htotvar, mtie, tierms",
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


@pytest.mark.parametrize("est", ["totvar", "mtotvar", "htotvar"])
def test_total_family_edf_follows_the_complete_terms(est, rng):
    # n complete terms: the EDF of a gapless record that has n terms (TOTVAR N − 2, MTOTVAR N − 3m + 1,
    # HTOTVAR N − 3m phase points' worth); unchanged without gaps
    y = rng.standard_normal(400)
    taus = [m / FS for m in (1, 2, 4, 8, 16, 30)]
    plain = allanite.avar(y, FS, estimator=est, taus=taus)
    z = y.copy()
    z[150:230] = np.nan
    r = allanite.avar(z, FS, estimator=est, taus=taus, gaps="skip")
    ci = allanite.confidence_intervals(r, alpha=0)
    ci_plain = allanite.confidence_intervals(plain, alpha=0)
    via_terms = allanite.confidence_intervals(allanite.avar(y, FS, estimator=est, taus=taus, gaps="skip"), alpha=0)
    np.testing.assert_allclose(via_terms.edf, ci_plain.edf, rtol=1e-12)
    assert np.all(ci.edf < ci_plain.edf)
    for i in range(len(taus)):
        m = int(r.m[i])
        length = int(r.n[i]) + {"totvar": 2, "mtotvar": 3 * m - 1, "htotvar": 3 * m}[est] - 1
        short = allanite.avar(y[:length], FS, estimator=est, taus=[r.tau[i]])
        assert short.n[0] == r.n[i]
        assert ci.edf[i] == pytest.approx(allanite.confidence_intervals(short, alpha=0).edf[0], rel=1e-12)


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


# ---- davar(gaps="skip"): every window from its own complete terms ---------------------------------


@pytest.mark.parametrize("est", ["oavar", "ohvar"])
def test_davar_skip_is_the_gap_twin_of_every_window(est, rng):
    y = holed(rng, n=900, holes=((10, 2), (200, 1), (341, 30), (777, 1), (899, 1)))
    window, hop = 250, 37  # the hop divides neither the window nor the record
    d = allanite.davar(y, FS, window=window, hop=hop, taus=[m / FS for m in (1, 2, 5, 13, 40, 80)], estimator=est,
                       gaps="skip")  # fmt: skip
    assert d.avar.shape == d.n.shape == (6, (900 - window) // hop + 1)
    for j in range(d.n.shape[1]):
        w = y[j * hop : j * hop + window]
        for i, m in enumerate(d.m):
            v, n = tw.gap_var(w, int(m), est)
            assert d.n[i, j] == n
            if n:
                assert d.avar[i, j] == pytest.approx(v, rel=1e-10)
            else:
                assert np.isnan(d.avar[i, j])
    assert np.any(d.n == 0) and np.any(d.n < d.n.max())  # the 30-sample hole empties τ = 20 s there


def test_davar_skip_without_nan_is_plain_davar_and_survives_a_level_change(rng):
    y = rng.standard_normal((3000, 2)) + 7000.0
    a = allanite.davar(y, FS, window=700, hop=13, gaps="skip")
    b = allanite.davar(y, FS, window=700, hop=13)
    np.testing.assert_allclose(a.avar, b.avar, rtol=1e-12)
    np.testing.assert_array_equal(a.n, np.broadcast_to(b.n[:, None], a.n.shape))
    # white noise whose level changes by 10⁶, with gaps on both sides: every window as if alone
    z = rng.standard_normal(4000)
    z[2000:] *= 1e6
    z[[500, 1500, 2500, 3500]] = np.nan
    d = allanite.davar(z, FS, window=600, hop=100, taus=[0.25, 2.0, 20.0], gaps="skip")
    for j in range(d.n.shape[1]):
        for i, m in enumerate(d.m):
            v, n = tw.gap_var(z[j * 100 : j * 100 + 600], int(m), "oavar")
            assert d.n[i, j] == n and d.avar[i, j] == pytest.approx(v, rel=1e-9)


def test_davar_skip_edf_per_window_and_refusals(rng):
    y = rng.standard_normal(3000)
    y[1200:1260] = np.nan
    d = allanite.davar(y, FS, window=500, hop=50, taus=[0.25, 2.0, 10.0], gaps="skip")
    ci = allanite.confidence_intervals(d, alpha=0)
    assert ci.edf.shape == d.avar.shape == ci.ci_low.shape
    full = allanite.confidence_intervals(allanite.davar(y[:500], FS, window=500, taus=d.tau), alpha=0).edf
    for i, m in enumerate(d.m):
        for j in range(d.n.shape[1]):
            n = int(d.n[i, j])
            if n == 500 - 2 * int(m) + 1:  # a window without gaps: the plain window's EDF
                assert ci.edf[i, j] == pytest.approx(full[i], rel=1e-12)
            else:  # a gapless record with as many terms
                short = allanite.avar(y[: n + 2 * int(m) - 1], FS, taus=[d.tau[i]])
                assert short.n[0] == n
                assert ci.edf[i, j] == pytest.approx(allanite.confidence_intervals(short, alpha=0).edf[0], rel=1e-12)
    for kw in ({"estimator": "avar"}, {"estimator": "theoh"}, {"taper": "hann"}, {"method": "naive"}):
        with pytest.raises(ParameterError, match="gaps"):
            allanite.davar(y, FS, window=500, hop=50, gaps="skip", **kw)
    with pytest.raises(InputError, match="nan"):
        allanite.davar(y, FS, window=500, hop=50)
