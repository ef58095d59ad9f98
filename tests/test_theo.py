"""Theo1 / TheoBR / TheoH and DHVAR through the public API, against the plain double-sum twins in
``allanite._reference`` (themselves checked against NBS14, Howe 2006 and Stable32 in
tests/test_theo_reference.py), against Stable32's own tables and against allantools."""

from __future__ import annotations

import numpy as np
import pytest

import allanite
import allanite.model.fitting as fit_mod
from allanite import _reference as ref
from allanite.errors import ParameterError
from allanite.estimators import theo as theo_mod
from allanite.estimators.confidence import edf_theo1


def rel(a, b):
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    return float(np.max(np.abs(a - b) / np.abs(b)))


def rate_noises(n, seed):
    rng = np.random.default_rng(seed)
    w = rng.normal(size=n)
    return {
        "white": w,
        "random_walk": np.cumsum(w) * 1e-2 + 5.0,
        "flicker_like": allanite.simulate(n, 1.0, B=1.0, seed=seed),
        "white_angle": np.diff(rng.normal(size=n + 1)),
    }


# ----------------------------------------------------------------------------------------------
# Theo1 against the direct double sum


@pytest.mark.parametrize("kind", ["white", "random_walk", "flicker_like", "white_angle"])
def test_theo1_all_m_matches_double_sum(kind):
    y = rate_noises(257, 3)[kind]
    r = allanite.avar(y, 2.0, estimator="theo1", taus="all")
    assert list(r.m) == list(range(10, 257, 2))
    x = ref.angle_from_rate(y, 2.0, dtype=np.longdouble)
    want = ref.theo1_reference(x, 0.5, r.m, dtype=np.longdouble)
    assert rel(r.avar, want) < 1e-11
    np.testing.assert_allclose(r.tau, 0.75 * r.m / 2.0, rtol=0, atol=0)
    assert list(r.n) == [ref.theo1_terms(258, m) for m in r.m]
    assert list(r.source) == ["theo1"] * r.m.size and r.kf is None


def test_theo1_keeps_digits_on_large_drifting_records():
    # A rate random walk on a large offset plus a slow rate ramp, 3000 samples: the phase is large and
    # curved; the fast path must still equal the extended-precision double sum.
    rng = np.random.default_rng(11)
    n = 3000
    y = 1e4 + np.cumsum(rng.normal(size=n)) + 1e-2 * np.arange(n)
    r = allanite.avar(y, 1.0, estimator="theo1", taus=0.75 * np.array([10, 12, 100, 1000, 2000, 3000]))
    x = ref.angle_from_rate(y, 1.0, dtype=np.longdouble)
    assert rel(r.avar, ref.theo1_reference(x, 1.0, r.m, dtype=np.longdouble)) < 1e-9


def test_theo1_float32_and_input_kinds_agree():
    y = rate_noises(400, 5)["white"]
    base = allanite.avar(y, 10.0, estimator="theo1", taus="octave")
    r32 = allanite.avar(y.astype(np.float32), 10.0, estimator="theo1", taus="octave")
    x32 = ref.angle_from_rate(y.astype(np.float32).astype(np.longdouble), 10.0, dtype=np.longdouble)
    assert rel(r32.avar, ref.theo1_reference(x32, 0.1, r32.m, dtype=np.longdouble)) < 1e-11
    inc = allanite.avar(y / 10.0, 10.0, input="increment", estimator="theo1", taus="octave")
    ang = allanite.avar(
        np.concatenate(([0.0], np.cumsum(y / 10.0))), 10.0, input="angle", estimator="theo1", taus="octave"
    )
    assert rel(inc.avar, base.avar) < 1e-10 and rel(ang.avar, base.avar) < 1e-10


def test_theo1_is_invariant_to_rate_offset_and_scales_as_c_squared():
    y = rate_noises(300, 7)["random_walk"]
    a = allanite.avar(y, 1.0, estimator="theo1", taus="octave")
    b = allanite.avar(3.0 * y - 42.0, 1.0, estimator="theo1", taus="octave")
    assert rel(b.avar, 9.0 * a.avar) < 1e-10


def test_constant_record_gives_zeros_and_unit_kf():
    r = allanite.avar(np.full(500, 2.5), 1.0, estimator="theoh", taus="octave")
    assert np.all(r.avar == 0) and r.kf == 1.0


def test_multi_axis_matches_single_axis():
    y = np.column_stack([rate_noises(600, s)["white"] for s in (1, 2)])
    r = allanite.avar(y, 1.0, estimator="theoh", taus="octave")
    assert r.avar.shape == (2, r.tau.size) and r.kf.shape == (2,)
    for k in range(2):
        one = allanite.avar(y[:, k], 1.0, estimator="theoh", taus="octave")
        np.testing.assert_array_equal(one.avar, r.avar[k])
        assert one.kf == r.kf[k]


# ----------------------------------------------------------------------------------------------
# TheoBR and TheoH


@pytest.mark.parametrize("rule", ["textbook", "stable32"])
def test_theobr_and_theoh_match_twins(rule):
    y = rate_noises(900, 13)["flicker_like"]
    x = ref.angle_from_rate(y, 1.0, dtype=np.longdouble)
    br = allanite.avar(y, 1.0, estimator="theobr", taus="decade", kf_rule=rule)
    assert rel(br.kf, ref.theobr_kf(x, 1.0, rule=rule, dtype=np.longdouble)) < 1e-11
    assert rel(br.avar, ref.theobr_reference(x, 1.0, br.m, rule=rule, dtype=np.longdouble)) < 1e-11
    h = allanite.avar(y, 1.0, estimator="theoh", taus="all", kf_rule=rule)
    tw = ref.theoh_reference(x, 1.0, rule=rule, dtype=np.longdouble)
    assert list(h.m) == list(tw.m) and list(h.source) == list(tw.source)
    np.testing.assert_allclose(h.tau, tw.tau, rtol=1e-15)
    assert rel(h.avar, tw.var) < 1e-11


def test_theoh_switch_and_reach():
    n = 1000
    h = allanite.avar(rate_noises(n, 2)["white"], 4.0, estimator="theoh", taus="octave")
    allan = h.source == "oavar"
    assert np.all(h.tau[allan] <= 0.1 * n / 4.0) and np.all(h.tau[~allan] > 0.1 * n / 4.0)
    assert np.all(np.diff(h.tau) > 0)
    # the first TheoBR point follows the switch with no gap, the last reaches 75 % of the record
    k = int(0.1 * n)
    first = min(m for m in range(10, n + 1, 2) if 0.75 * m > k)
    assert h.m[~allan][0] == first
    assert h.tau[-1] == pytest.approx(0.75 * n / 4.0)


def test_nbs14_theoh_kf_and_raw_theo1():
    y = ref.nbs14_1000()
    r = allanite.avar(y, 1.0, estimator="theo1", taus=[7.5, 75.0, 750.0])
    # to the printed digits (half a unit of the last one)
    assert np.all(np.abs(np.sqrt(r.avar) - [0.107573989, 0.0317893126, 0.0050523996]) <= [5e-10, 5e-11, 5e-11])
    assert allanite.avar(y, 1.0, estimator="theobr", taus=[7.5]).kf == pytest.approx(1.0856664, abs=5e-8)


# ----------------------------------------------------------------------------------------------
# Stable32


def _rows(path):
    out = []
    for line in path.read_text(encoding="latin-1").splitlines():
        parts = line.split()
        if parts and parts[0].isdigit():
            out.append(parts)
    return out


def _half_units(ours, printed):
    """|ours − printed| in units of half the last printed digit (5 significant digits)."""
    printed = np.asarray(printed, dtype=np.float64)
    ulp = 10.0 ** (np.floor(np.log10(printed)) - 4)
    return np.abs(np.asarray(ours) - printed) / (0.5 * ulp)


@pytest.mark.parametrize("grid", ["decade", "many"])
def test_stable32_theoh_on_sr87(shared_data, grid):
    base = shared_data / "stable32" / "sr87" / "phase"
    x = np.loadtxt(base / "phase_data.txt")
    rows = [r for r in _rows(base / grid / "theoh.txt") if len(r) >= 8]
    r = allanite.avar(x, 0.4, input="angle", estimator="theoh", taus="all", kf_rule="stable32")
    assert r.kf == pytest.approx(1.3491114, abs=5e-8)
    ours = {(int(m), s): v for m, s, v in zip(r.m, r.source, r.avar)}
    theo = [(int(q[0]), float(q[5])) for q in rows if float(q[5]) > 0]
    sigma = [(int(q[0]), float(q[4])) for q in rows if float(q[4]) > 0]
    assert theo and sigma
    oav = allanite.avar(x, 0.4, input="angle", taus=np.array([m for m, _ in sigma]) / 0.4)
    assert np.max(_half_units(np.sqrt(oav.avar), [v for _, v in sigma])) <= 1.0
    assert np.max(_half_units([np.sqrt(ours[(m, "theobr")]) for m, _ in theo], [v for _, v in theo])) <= 1.0
    # the textbook kf range gives a constant 2.43 % lower variance — the documented difference
    tb = allanite.avar(x, 0.4, input="angle", estimator="theobr", taus="decade")
    assert r.kf / tb.kf == pytest.approx(1.024319, abs=2e-6)


@pytest.mark.parametrize("grid", ["decade", "many"])
def test_stable32_theo1_br_on_sr87(shared_data, grid):
    base = shared_data / "stable32" / "sr87" / "phase"
    x = np.loadtxt(base / "phase_data.txt")
    rows = [q for q in _rows(base / grid / "theo1.txt") if len(q) >= 7]
    ms = np.array([int(q[0]) for q in rows])
    # Stable32's Sr87 Thêo1 tables (header "Alpha = -1") are bias-removed with its own kf range
    r = allanite.avar(x, 0.4, input="angle", estimator="theobr", taus=0.75 * ms / 0.4, kf_rule="stable32")
    assert list(r.m) == list(ms)
    np.testing.assert_allclose(r.tau, [float(q[1]) for q in rows], rtol=1e-4)
    assert np.max(_half_units(np.sqrt(r.avar), [float(q[5]) for q in rows])) <= 1.0


@pytest.mark.parametrize("name", ["phase_dat_theo1_alpha0.txt", "phase_dat_theo1_alpha0_decade.txt"])
def test_stable32_raw_theo1_on_phase_dat(shared_data, name):
    base = shared_data / "stable32" / "phasedat"
    x = np.loadtxt(base / "PHASE.DAT")
    rows = _rows(base / name)
    ms = np.array([int(q[0]) for q in rows])
    r = allanite.avar(x, 1.0, input="angle", estimator="theo1", taus=0.75 * ms)
    assert list(r.m) == list(ms)
    np.testing.assert_allclose(r.tau, [float(q[1]) for q in rows])
    assert np.max(_half_units(r.n, [float(q[2]) for q in rows])) <= 1.0  # "Thêo1 #", printed to 5 digits
    assert np.max(_half_units(np.sqrt(r.avar), [float(q[5]) for q in rows])) <= 1.0


def test_allantools_theo1_equals_ours_at_corrected_tau():
    allantools = pytest.importorskip("allantools")
    y = rate_noises(300, 21)["white"]
    ms = np.array([10, 16, 32, 64, 128, 256])
    taus, dev = allantools.theo1(y, rate=1.0, data_type="freq", taus=ms.astype(float))[:2]
    ours = allanite.avar(y, 1.0, estimator="theo1", taus=0.75 * np.round(taus))
    np.testing.assert_array_equal(np.round(taus), ours.m)  # allantools labels τ = m·τ0 ...
    np.testing.assert_allclose(ours.tau, 0.75 * np.asarray(taus))  # ... the statistic is at 0.75·m·τ0
    assert rel(ours.avar, np.asarray(dev) ** 2) < 1e-12


# ----------------------------------------------------------------------------------------------
# DHVAR


@pytest.mark.parametrize("estimator", ["theoh", "theoh_a"])
def test_dhvar_matches_per_window_twin(estimator):
    y = rate_noises(1500, 17)["flicker_like"]
    window, hop = 401, 137
    d = allanite.davar(y, 25.0, window=window, hop=hop, estimator=estimator, taus="all")
    tw = ref.dhvar_reference(y, 25.0, window, hop, estimator=estimator)
    assert list(d.m) == list(tw.m) and list(d.source) == list(tw.source)
    assert d.avar.shape == tw.var.shape
    assert rel(d.avar, tw.var) < 1e-10
    assert rel(d.kf, tw.kf) < 1e-10
    np.testing.assert_allclose(d.t, (np.arange(d.t.size) * hop + window / 2) / 25.0)


def test_dhvar_window_equals_static_theoh_and_is_thread_independent():
    y = rate_noises(2000, 4)["white"]
    d1 = allanite.davar(y, 1.0, window=500, hop=250, estimator="theoh", taus="octave", workers=1)
    d2 = allanite.davar(y, 1.0, window=500, hop=250, estimator="theoh", taus="octave", workers=2)
    np.testing.assert_array_equal(d1.avar, d2.avar)
    for j in range(d1.t.size):
        s = allanite.avar(y[j * 250 : j * 250 + 500], 1.0, estimator="theoh", taus="octave")
        assert rel(d1.avar[:, j], s.avar) < 1e-12 and d1.kf[j] == pytest.approx(s.kf, rel=1e-12)


def test_dhvar_multi_axis_shapes():
    y = np.column_stack([rate_noises(800, s)["white"] for s in (1, 2, 3)])
    d = allanite.davar(y, 1.0, window=200, hop=50, estimator="theoh", taus="octave")
    assert d.avar.shape == (3, d.tau.size, d.t.size) and d.kf.shape == (3, d.t.size)


# ----------------------------------------------------------------------------------------------
# confidence and fitting


def test_edf_theo1_matches_twin():
    for alpha in (2, 1, 0, -1, -2):
        for m in (10, 100, 600, 1000):
            want = ref.theo1_edf(alpha, m, 1001)
            # the empirical fits leave their range at the longest τ (RWFM even goes negative): ν ≥ 1 there
            assert edf_theo1(alpha, m, 1001) == pytest.approx(max(want, 1.0), rel=1e-14)
    assert ref.theo1_edf(-2, 1000, 1001) < 0 and edf_theo1(-2, 1000, 1001) == 1.0


def test_theoh_confidence_intervals_use_each_estimators_edf():
    y = rate_noises(5000, 8)["white"]
    r = allanite.avar(y, 1.0, estimator="theoh", taus="octave").with_confidence(y)
    assert np.all(r.ci_low < r.avar) and np.all(r.avar < r.ci_high)
    theo = r.source == "theobr"
    np.testing.assert_allclose(r.edf[theo], edf_theo1(r.alpha[theo], r.m[theo], 5001))
    # Theo reaches τ where fewer than 30 intervals fit: its noise type is that of the longest τ
    # with ≥ 30 intervals, not a guess from a handful of averages (white rate here).
    assert np.all(r.alpha[theo] == 0)
    # the point of TheoH: at the same long τ, TheoBR has far more degrees of freedom than OAVAR
    th = allanite.avar(y, 1.0, estimator="theobr", taus=[1500.0]).with_confidence(y, alpha=0)
    oa = allanite.avar(y, 1.0, taus=[1500.0]).with_confidence(y, alpha=0)
    assert th.edf[0] > 2.0 * oa.edf[0]


def test_fit_on_theoh_recovers_terms():
    y = allanite.simulate(200_000, 100.0, N=0.01, B=1e-3, K=1e-4, seed=3)
    f = fit_mod.fit(allanite.avar(y, 100.0, estimator="theoh", taus="octave"), unit="deg/s")
    assert f.coefficients["N"].ieee == pytest.approx(0.6, rel=0.03)  # 0.01 °/√s
    assert f.coefficients["B"].ieee == pytest.approx(3.6, rel=0.3)  # 1e-3 °/s
    assert f.coefficients["K"].ieee == pytest.approx(6.0, rel=0.3)  # 1e-4 °/s^1.5
    with pytest.raises(ParameterError, match="raw Theo1 is biased"):
        fit_mod.fit(allanite.avar(y[:5000], 100.0, estimator="theo1"))


def test_fit_on_dhvar_gives_a_series():
    y = allanite.simulate(20_000, 25.0, N=0.01, seed=5)
    d = allanite.davar(y, 25.0, window=2001, hop=1000, estimator="theoh", taus="octave")
    s = fit_mod.fit(d, unit="deg/s")
    assert s.t.size == d.t.size
    assert np.median(s.ieee["N"]) == pytest.approx(0.6, rel=0.1)


# ----------------------------------------------------------------------------------------------
# errors


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(estimator="theo2"), "estimator"),
        (dict(estimator="theoh", kf_rule="nist"), "kf_rule"),
        (dict(estimator="theo1", taus=[3.0]), r"m = 4 .*even m from 10"),
        (dict(estimator="theo1", taus=[1e6]), "allowed for 500 samples"),
        (dict(estimator="theo1", taus="weekly"), "unknown τ grid"),
        (dict(estimator="theo1", taus=[30.0, 22.5]), "strictly increasing"),
        (dict(estimator="theo1", taus=[np.nan]), "positive τ"),
    ],
)
def test_static_errors(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        allanite.avar(np.random.default_rng(0).normal(size=500), 1.0, **kwargs)


def test_short_records_are_refused_with_the_reason():
    with pytest.raises(ParameterError, match="at least 90 phase points"):
        allanite.avar(np.ones(50), 1.0, estimator="theoh")
    with pytest.raises(ParameterError, match="at least 10 samples"):
        allanite.avar(np.ones(8), 1.0, estimator="theo1")
    with pytest.raises(ParameterError, match="at least 90 phase points"):
        allanite.davar(np.ones(500), 1.0, window=60, estimator="theoh")
    with pytest.raises(ParameterError, match="method='fast' only"):
        allanite.davar(np.ones(500), 1.0, window=200, estimator="theoh", method="naive")
    with pytest.raises(allanite.errors.InputError, match="non-finite"):
        allanite.avar(np.r_[np.ones(200), np.nan], 1.0, estimator="theoh")


def test_decimated_theobr_tracks_the_exact_one():
    y = np.random.default_rng(31).normal(size=20_000)
    exact = allanite.avar(y, 1.0, estimator="theoh", taus="octave")
    dec = allanite.avar(y, 1.0, estimator="theoh", taus="octave", decimate=4)
    allan = exact.source == "oavar"
    np.testing.assert_array_equal(dec.avar[dec.source == "oavar"], exact.avar[allan])  # Allan part untouched
    theo = dec.source == "theobr"
    assert np.all(dec.m[theo] % 8 == 0)  # m = m'·D with m' even
    np.testing.assert_allclose(dec.tau[theo], 0.75 * dec.m[theo])
    # same statistic from fewer terms: close to the exact TheoBR at the same τ
    common = np.intersect1d(dec.m[theo], exact.m[~allan])
    assert common.size >= 3
    a = exact.avar[np.isin(exact.m, common) & ~allan]
    b = dec.avar[np.isin(dec.m, common) & theo]
    assert np.max(np.abs(b / a - 1)) < 0.05
    auto = allanite.avar(np.random.default_rng(1).normal(size=250_000), 1.0, estimator="theobr", decimate="auto")
    assert np.all(auto.m % 6 == 0)  # D = ⌈250 000 / 100 000⌉ = 3


@pytest.mark.parametrize(
    "decimate, match",
    [(0, "decimate must be an integer ≥ 1"), ("fast", "positive integer or 'auto'"), (100, "leaves 20 samples")],
)
def test_decimate_errors(decimate, match):
    with pytest.raises(ParameterError, match=match):
        allanite.avar(np.random.default_rng(0).normal(size=2_000), 1.0, estimator="theoh", decimate=decimate)
    with pytest.raises(ParameterError, match="applies to the estimators .*theo1"):
        allanite.avar(np.random.default_rng(0).normal(size=2_000), 1.0, decimate=2)
    with pytest.raises(ParameterError, match="named τ grid"):
        allanite.avar(np.random.default_rng(0).normal(size=2_000), 1.0, estimator="theoh", taus=[1.0], decimate=2)


def test_to_xarray_carries_source_and_kf():
    pytest.importorskip("xarray")
    y = np.column_stack([rate_noises(3000, s)["white"] for s in (1, 2)])
    ds = allanite.avar(y, 10.0, estimator="theoh").to_xarray(unit="deg/s")
    assert list(ds["source"].values[-2:]) == ["theobr", "theobr"] and ds["kf"].dims == ("axis",)
    d = allanite.davar(y, 10.0, window=500, hop=250, estimator="theoh", taus="octave")
    dd = d.to_xarray()
    assert dd["kf"].dims == ("axis", "t")
    np.testing.assert_array_equal(dd["kf"].values, d.kf)


def test_theoh_tau_maps_to_one_estimator_on_both_paths():
    """davar's τ handed back to avar give the same estimator and value at every τ of every window —
    including the switch point (τ = 40.5 samples at k = 40 is TheoBR's m = 54, not Allan's m = 40;
    18 % apart when the explicit-τ rule and the grid's rule were two things)."""
    y = allanite.simulate(40_000, 10.0, N=1e-2, K=1e-4, seed=5)
    d = allanite.davar(y, 10.0, window=401, hop=50, estimator="theoh")
    assert d.tau.size == 65 and d.source[31] == "theobr" and d.m[31] == 54 and d.m[30] == 40
    for j in range(d.t.size):
        s = allanite.avar(y[j * 50 : j * 50 + 401], 10.0, estimator="theoh", taus=d.tau)
        assert list(s.source) == list(d.source)
        np.testing.assert_array_equal(s.m, d.m)
        np.testing.assert_allclose(s.avar, d.avar[:, j], rtol=1e-12, atol=0)


def test_theoh_a_tau_maps_to_one_estimator_on_both_paths():
    """TheoH-A has no whole-record form: each window equals the classic Allan variance at its Allan τ
    and TheoBR (the window's own kf) at its Theo τ, those τ mapped by the same rule as TheoH's."""
    y = allanite.simulate(40_000, 10.0, N=1e-2, K=1e-4, seed=5)
    d = allanite.davar(y, 10.0, window=401, hop=50, estimator="theoh_a")
    h = allanite.davar(y[:2000], 10.0, window=401, hop=50, estimator="theoh")
    np.testing.assert_array_equal(d.m, h.m)
    assert list(np.where(d.source == "avar", "oavar", d.source)) == list(h.source)
    short, long_ = d.source == "avar", d.source == "theobr"
    assert short.sum() == 31 and long_.sum() == 34
    for j in range(d.t.size):
        w = y[j * 50 : j * 50 + 401]
        a = allanite.avar(w, 10.0, estimator="avar", taus=d.tau[short])
        b = allanite.avar(w, 10.0, estimator="theobr", taus=d.tau[long_])
        np.testing.assert_array_equal(a.m, d.m[short])
        np.testing.assert_array_equal(b.m, d.m[long_])
        np.testing.assert_allclose(a.avar, d.avar[short, j], rtol=1e-12, atol=0)
        np.testing.assert_allclose(b.avar, d.avar[long_, j], rtol=1e-12, atol=0)
        assert b.kf == pytest.approx(d.kf[j], rel=1e-12)


@pytest.mark.parametrize("estimator", ["theoh", "theoh_a", "theobr", "theo1"])
def test_theo_grid_tau_map_back_to_their_own_m_and_source(estimator):
    """The one τ → (estimator, m) mapping is idempotent on its own output: for every window length and
    grid, the τ a result reports map back to the same (m, source)."""
    for fs in (10.0, 25.0, 1.0, 3.0, 7.3):
        for n in [*range(90, 700), 4001, 10_007, 99_999]:
            for grid in ("exp", "octave", "decade") + (("all",) if n < 2000 else ()):
                ms, src = theo_mod.theo_ms(grid, n, fs, estimator)
                tau = np.where(np.isin(src, theo_mod.THEO_SOURCES), 0.75 * ms, ms) / fs
                ms2, src2 = theo_mod.theo_ms(tau, n, fs, estimator)
                np.testing.assert_array_equal(ms2, ms)
                np.testing.assert_array_equal(src2, src)
