"""Parity: the Rust core against the NumPy twins (allanite._reference) and allantools; equivalent
inputs, dtypes, layouts, axes and thread counts; τ grids; numerics on an adversarial record;
exact invariants."""

from __future__ import annotations

import math
import os

import allantools
import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

import allanite
from allanite import _reference

GRIDS = ("all", "octave", "decade", "exp")
ESTIMATORS = ("oavar", "avar")
METHODS = ("fast", "naive")


def max_rel(a, b) -> float:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    assert a.shape == b.shape, (a.shape, b.shape)
    assert np.all(b > 0), "reference values must be positive for a relative comparison"
    return float(np.max(np.abs(a - b) / b))


def assert_same_result(r1, r2):
    """Bit-identical results (values and bookkeeping)."""
    np.testing.assert_array_equal(r1.tau, r2.tau)
    np.testing.assert_array_equal(r1.m, r2.m)
    np.testing.assert_array_equal(r1.n, r2.n)
    assert r1.avar.shape == r2.avar.shape
    assert np.array_equal(r1.avar, r2.avar), f"max |diff| {np.max(np.abs(r1.avar - r2.avar))}"


# --------------------------------------------------------------------------------------------------
# davar against the per-window NumPy recomputation
# --------------------------------------------------------------------------------------------------


def check_davar_against_reference(y, fs, window, hop, taus, estimator, methods=METHODS, rtol=1e-9):
    for method in methods:
        d = allanite.davar(y, fs, window=window, hop=hop, taus=taus, method=method, estimator=estimator)
        n_win = (len(y) - window) // hop + 1
        assert d.avar.shape == (d.m.size, n_win)
        assert d.t.shape == (n_win,)
        np.testing.assert_allclose(d.t, (np.arange(n_win) * hop + window / 2) / fs, rtol=1e-15)
        np.testing.assert_array_equal(d.tau, d.m / fs)
        expected_n = window + 1 - 2 * d.m if estimator == "oavar" else window // d.m - 1
        np.testing.assert_array_equal(d.n, expected_n)
        assert (d.window, d.hop, d.method, d.estimator) == (window, hop, method, estimator)
        ref = _reference.davar_reference(y, fs, window, hop, d.m, estimator)
        err = max_rel(d.avar, ref)
        assert err <= rtol, f"{method}/{estimator}: max relative error {err:.3g} > {rtol:g}"


@st.composite
def davar_cases(draw):
    n = draw(st.integers(2, 260))
    window = draw(st.integers(2, n))
    hop = draw(st.integers(1, n + 5))
    fs = draw(st.sampled_from([1.0, 100.0, 0.37, 2048.0]))
    if draw(st.booleans()):
        taus = draw(st.sampled_from(GRIDS))
    else:
        ms = draw(st.lists(st.integers(1, window // 2), min_size=1, max_size=8, unique=True))
        taus = np.array(sorted(ms)) / fs
    estimator = draw(st.sampled_from(ESTIMATORS))
    seed = draw(st.integers(0, 2**32 - 1))
    scale = draw(st.sampled_from([1.0, 1e-6, 3e4]))
    offset = draw(st.sampled_from([0.0, 1.0, -50.0])) * scale
    return n, window, hop, fs, taus, estimator, seed, scale, offset


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(davar_cases())
def test_davar_matches_reference_random(case):
    n, window, hop, fs, taus, estimator, seed, scale, offset = case
    y = np.random.default_rng(seed).normal(size=n) * scale + offset
    check_davar_against_reference(y, fs, window, hop, taus, estimator)


FIXED_CASES = [
    # n, window, hop, taus (m list or grid), id
    (500, 60, 1, "all", "hop=1"),
    (500, 60, 75, "all", "hop>window"),
    (500, 60, 61, [1, 2, 30], "hop=window+1"),
    (500, 500, 1, "all", "window=record"),
    (500, 500, 7, [1, 3, 250], "window=record,hop>1"),
    (500, 2, 1, [1], "window=2"),
    (500, 2, 3, [1], "window=2,hop=3"),
    (501, 101, 25, [1, 13, 50], "terms multiple of hop"),
    (20_000, 8_000, 2_500, [1, 7, 1_000, 1_023, 1_025, 3_999, 4_000], "hop>1024 runs"),
    (6_000, 3_000, 1_100, "exp", "long blocks, exp grid"),
    (3_001, 1_000, 999, [1, 2, 333, 499, 500], "hop=window-1"),
]


@pytest.mark.parametrize("estimator", ESTIMATORS)
@pytest.mark.parametrize("n, window, hop, taus, label", FIXED_CASES, ids=[c[-1] for c in FIXED_CASES])
def test_davar_matches_reference_fixed(rng, n, window, hop, taus, label, estimator):
    y = rng.normal(size=n) * 0.3 + 2.0
    fs = 50.0
    taus = taus if isinstance(taus, str) else np.array(taus) / fs
    check_davar_against_reference(y, fs, window, hop, taus, estimator)


@pytest.mark.parametrize("estimator", ESTIMATORS)
@pytest.mark.parametrize("taus", GRIDS)
def test_window_equal_to_record_is_static_avar(rng, estimator, taus):
    y = rng.normal(size=777) + 5.0
    fs = 12.5
    s = allanite.avar(y, fs, taus=taus, estimator=estimator)
    for hop in (1, 5, 10_000):
        d = allanite.davar(y, fs, window=y.size, hop=hop, taus=taus, estimator=estimator)
        assert d.avar.shape == (s.tau.size, 1)
        np.testing.assert_array_equal(d.tau, s.tau)
        np.testing.assert_array_equal(d.n, s.n)
        assert np.array_equal(d.avar[:, 0], s.avar)  # same core routine: bit-identical
        assert d.t[0] == y.size / 2 / fs
    naive = allanite.davar(y, fs, window=y.size, taus=taus, estimator=estimator, method="naive")
    assert max_rel(naive.avar[:, 0], s.avar) <= 1e-12


def test_every_davar_column_is_the_static_avar_of_its_window(rng):
    y = rng.normal(size=3_000).cumsum() * 1e-2 + rng.normal(size=3_000)
    fs, window, hop = 10.0, 700, 230
    d = allanite.davar(y, fs, window=window, hop=hop, taus="octave")
    for j in range(d.t.size):
        s = allanite.avar(y[j * hop : j * hop + window], fs, taus=d.tau)
        assert max_rel(d.avar[:, j], s.avar) <= 1e-12


# --------------------------------------------------------------------------------------------------
# allantools
# --------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "estimator, fn", [("oavar", allantools.oadev), ("avar", allantools.adev)], ids=["oadev", "adev"]
)
@pytest.mark.parametrize("grid, n", [("octave", 5_000), ("decade", 5_000), ("exp", 5_000), ("all", 301), ("all", 300)])
@pytest.mark.parametrize("fs", [1.0, 250.0])
def test_avar_matches_allantools(rng, estimator, fn, grid, n, fs):
    y = rng.normal(size=n) * 2e-3 + 0.5 + np.cumsum(rng.normal(size=n)) * 1e-4
    r = allanite.avar(y, fs, taus=grid, estimator=estimator)
    taus, devs, _errs, ns = fn(y, rate=fs, data_type="freq", taus=r.tau)
    # allantools stops a little earlier at the long end (its own m limits); the rest must agree.
    k = len(taus)
    assert k >= min(len(r.tau), 3) and k >= 0.6 * len(r.tau)
    np.testing.assert_array_equal(taus, r.tau[:k])
    np.testing.assert_array_equal(ns, r.n[:k])
    err = max_rel(r.avar[:k], np.asarray(devs) ** 2)
    assert err <= 1e-10, f"max relative difference to allantools {err:.3g}"


# --------------------------------------------------------------------------------------------------
# Equivalent inputs
# --------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("estimator", ESTIMATORS)
@pytest.mark.parametrize("fs", [1.0, 100.0, 0.25])
def test_rate_increment_angle_inputs_agree(rng, estimator, fs):
    y = rng.normal(size=4_000) * 0.01 + 0.3 + 0.002 * np.sin(np.arange(4_000) / 50)
    inc = y / fs
    ang = np.concatenate([[0.0], np.cumsum(y / fs)])
    # Every m with at least 9 terms. (Beyond that the *angle record itself* limits agreement: the
    # rounded cumsum perturbs each rate sample by ~1e-13, and a classic estimate from one or two
    # nearly cancelling cluster differences amplifies that to ~3e-9 — see the next test, which
    # shows the library adds nothing to it.)
    taus = allanite.tau_grid(y.size, fs, "all", m_max=y.size // 10)
    results = {
        inp: allanite.avar(x, fs, input=inp, taus=taus, estimator=estimator)
        for inp, x in (("rate", y), ("increment", inc), ("angle", ang))
    }
    base = results["rate"]
    for inp in ("increment", "angle"):
        r = results[inp]
        assert r.input == inp and r.n_samples == y.size
        np.testing.assert_array_equal(r.tau, base.tau)
        np.testing.assert_array_equal(r.n, base.n)
        assert max_rel(r.avar, base.avar) <= 1e-10
    dyn = {
        inp: allanite.davar(x, fs, input=inp, window=900, hop=170, taus="exp", estimator=estimator)
        for inp, x in (("rate", y), ("increment", inc), ("angle", ang))
    }
    for inp in ("increment", "angle"):
        np.testing.assert_array_equal(dyn[inp].t, dyn["rate"].t)
        np.testing.assert_array_equal(dyn[inp].tau, dyn["rate"].tau)
        assert max_rel(dyn[inp].avar, dyn["rate"].avar) <= 1e-10


@pytest.mark.parametrize("estimator", ESTIMATORS)
def test_angle_input_is_exact_for_the_record_it_is_given(rng, estimator):
    """Over the whole 'all' grid (down to single-term estimates), angle input equals the
    extended-precision Allan variance of the rate samples that angle record encodes."""
    fs = 4.0
    y = rng.normal(size=4_000) * 0.01 + 0.3
    ang = np.concatenate([[0.0], np.cumsum(y / fs)])
    r = allanite.avar(ang, fs, input="angle", taus="all", estimator=estimator)
    assert r.m[-1] == 2_000 and r.n_samples == 4_000
    ref = _reference.avar_reference(np.diff(ang) * fs, fs, r.m, estimator, dtype=np.longdouble)
    assert max_rel(r.avar, ref.astype(float)) <= 1e-12


# --------------------------------------------------------------------------------------------------
# dtypes and memory layouts
# --------------------------------------------------------------------------------------------------


def both(x, fs=20.0, **kw):
    """avar and davar of x (same options)."""
    return (allanite.avar(x, fs, taus="all", **kw), allanite.davar(x, fs, window=64, hop=9, taus="all", **kw))


def assert_both_equal(a, b):
    assert_same_result(a[0], b[0])
    assert_same_result(a[1], b[1])


@pytest.mark.parametrize("estimator", ESTIMATORS)
def test_float32_input_is_computed_in_float64(rng, estimator):
    y32 = (rng.normal(size=1_000) * 0.1 + 3.0).astype(np.float32)
    assert_both_equal(both(y32, estimator=estimator), both(y32.astype(np.float64), estimator=estimator))
    # and it is not the float32 arithmetic of a rounded result: compare with the float64 reference
    ref = _reference.avar_reference(y32.astype(np.float64), 20.0, np.arange(1, 501), estimator)
    assert max_rel(allanite.avar(y32, 20.0, taus="all", estimator=estimator).avar, ref) <= 1e-9


@pytest.mark.parametrize("dtype", [np.int16, np.int32, np.int64, np.uint8, np.float16, ">f8", ">f4", "<f8"])
def test_dtypes(rng, dtype):
    if np.dtype(dtype).kind in "iu":
        info = np.iinfo(dtype)
        x = rng.integers(max(info.min, -1000), min(info.max, 1000), size=300).astype(dtype)
    else:
        x = (rng.normal(size=300) * 4).astype(dtype)
    assert x.dtype == np.dtype(dtype)
    assert_both_equal(both(x), both(x.astype(np.float64)))


def test_unaligned_memory(rng):
    # float64 samples at an odd byte offset, as arrays received from a network buffer can be (a Dask
    # task's input): used as they are, not refused as "not contiguous"
    y = rng.normal(size=(300, 2))
    raw = bytearray(y.nbytes + 1)
    x = np.frombuffer(raw, dtype=np.float64, offset=1).reshape(300, 2)
    x[...] = y
    assert not x.flags["ALIGNED"]
    assert_both_equal(both(x), both(y))


def test_python_lists_and_tuples(rng):
    y = rng.normal(size=200)
    assert_both_equal(both(y.tolist()), both(y))
    assert_both_equal(both(tuple(y.tolist())), both(y))
    X = rng.normal(size=(200, 2))
    assert_both_equal(both(X.tolist()), both(X))
    assert_both_equal(both(list(range(200))), both(np.arange(200.0)))


def test_strided_reversed_and_readonly_views(rng):
    big = rng.normal(size=2_001)
    assert_both_equal(both(big[::2]), both(big[::2].copy()))
    assert_both_equal(both(big[5::3]), both(np.ascontiguousarray(big[5::3])))
    assert_both_equal(both(big[::-1]), both(big[::-1].copy()))
    ro = big.copy()
    ro.flags.writeable = False
    assert_both_equal(both(ro), both(big))


def test_two_dimensional_layouts(rng):
    X = rng.normal(size=(600, 3)) + [0.0, 10.0, -3.0]
    base = both(X)
    assert_both_equal(both(np.asfortranarray(X)), base)
    assert_both_equal(both(X.astype(">f8")), base)
    assert_both_equal(both(X.astype(np.float32)), both(X.astype(np.float32).astype(np.float64)))
    wide = rng.normal(size=(300, 8))
    assert_both_equal(both(wide[:, ::3]), both(np.ascontiguousarray(wide[:, ::3])))
    assert_both_equal(both(wide[::2, 1:4]), both(wide[::2, 1:4].copy()))
    assert_both_equal(both(np.asfortranarray(wide)[::-1]), both(wide[::-1].copy()))


# --------------------------------------------------------------------------------------------------
# Multiple axes
# --------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("estimator", ESTIMATORS)
def test_multi_axis_equals_stacked_single_axes(rng, estimator, method):
    X = rng.normal(size=(2_500, 3)) * [1.0, 1e-3, 50.0] + [0.0, 2.0, -7.0]
    fs = 40.0
    s = allanite.avar(X, fs, taus="octave", estimator=estimator)
    assert s.avar.shape == (3, s.tau.size) and s.n_axes == 3
    assert s.n.shape == s.tau.shape == s.m.shape
    for k in range(3):
        sk = allanite.avar(X[:, k], fs, taus="octave", estimator=estimator)
        assert sk.n_axes is None and sk.avar.shape == (s.tau.size,)
        assert np.array_equal(s.avar[k], sk.avar)
    d = allanite.davar(X, fs, window=400, hop=130, taus="exp", estimator=estimator, method=method)
    assert d.avar.shape == (3, d.tau.size, d.t.size) and d.n_axes == 3
    stacked = np.stack(
        [
            allanite.davar(X[:, k], fs, window=400, hop=130, taus="exp", estimator=estimator, method=method).avar
            for k in range(3)
        ]
    )
    assert np.array_equal(d.avar, stacked)
    one = allanite.avar(X[:, :1], fs, taus="octave", estimator=estimator)
    assert one.avar.shape == (1, s.tau.size)
    assert np.array_equal(one.avar[0], s.avar[0])


# --------------------------------------------------------------------------------------------------
# Threads
# --------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("method", METHODS)
def test_worker_count_does_not_change_a_bit(rng, monkeypatch, method):
    X = rng.normal(size=(30_000, 2)) * [1.0, 1e-4] + [0.0, 3.0]
    kw = dict(window=5_000, hop=333, taus="exp", method=method)
    ref = allanite.davar(X, 100.0, workers=1, **kw)
    for workers in (2, 3, None):
        assert np.array_equal(allanite.davar(X, 100.0, workers=workers, **kw).avar, ref.avar)
    Xs = X[:3_000]
    s1 = allanite.avar(Xs, 100.0, taus="all", workers=1)
    assert np.array_equal(allanite.avar(Xs, 100.0, taus="all", workers=2).avar, s1.avar)
    assert np.array_equal(allanite.avar(Xs, 100.0, taus="all").avar, s1.avar)
    for env in ("1", "2"):
        monkeypatch.setenv("ALLANITE_NUM_THREADS", env)
        assert np.array_equal(allanite.davar(X, 100.0, **kw).avar, ref.avar)
        assert np.array_equal(allanite.avar(Xs, 100.0, taus="all").avar, s1.avar)


def test_num_threads_env_is_read_and_explicit_workers_win(rng, monkeypatch):
    y = rng.normal(size=500)
    monkeypatch.setenv("ALLANITE_NUM_THREADS", "0")
    with pytest.raises(allanite.ParameterError, match="ALLANITE_NUM_THREADS"):
        allanite.avar(y, 1.0)  # the variable is honoured (here: rejected)
    # an explicit workers= takes precedence and the variable is not consulted
    r = allanite.avar(y, 1.0, workers=1)
    monkeypatch.setenv("ALLANITE_NUM_THREADS", " 1 ")
    assert np.array_equal(allanite.avar(y, 1.0).avar, r.avar)


# --------------------------------------------------------------------------------------------------
# τ grids
# --------------------------------------------------------------------------------------------------


def grid_ms(taus, fs):
    ms = np.rint(np.asarray(taus) * fs).astype(np.int64)
    np.testing.assert_array_equal(taus, ms / fs)  # exact multiples m/fs
    return ms


@settings(max_examples=60, deadline=None)
@given(n=st.integers(2, 2_000_000), fs=st.sampled_from([1.0, 100.0, 0.1, 3.0, 1e4, 400.0]), kind=st.sampled_from(GRIDS))
def test_named_grids_properties(n, fs, kind):
    taus = allanite.tau_grid(n, fs, kind)
    ms = grid_ms(taus, fs)
    assert ms.size >= 1 and ms[0] == 1
    assert np.all(np.diff(ms) > 0)
    top = n // 9 if kind == "exp" else n // 2
    top = max(top, 1)
    assert ms[-1] <= top
    if kind == "all":
        np.testing.assert_array_equal(ms, np.arange(1, top + 1))
    elif kind == "octave":
        np.testing.assert_array_equal(ms, 2 ** np.arange(int(math.log2(top)) + 1))
    elif kind == "decade":
        expected = [d * f for d in 10 ** np.arange(8) for f in (1, 2, 4) if d * f <= top]
        np.testing.assert_array_equal(ms, expected)
    else:
        assert ms[-1] == top  # the default exp grid reaches n // 9
        assert ms.size <= 100


@settings(max_examples=60, deadline=None)
@given(n=st.integers(20, 500_000), fs=st.sampled_from([1.0, 100.0, 0.5]), data=st.data())
def test_exp_grid_options(n, fs, data):
    limit = n // 2
    m_max = data.draw(st.one_of(st.none(), st.integers(1, limit)))
    top = m_max if m_max is not None else max(1, n // 9)
    m0 = data.draw(st.integers(1, top))
    tau_min = data.draw(st.sampled_from([None, m0 / fs, (m0 + 0.3) / fs]))
    first = 1 if tau_min is None else m0
    if data.draw(st.booleans()):
        growth = data.draw(st.floats(1.05, 10.0))
        taus = allanite.tau_grid(n, fs, "exp", growth=growth, tau_min=tau_min, m_max=m_max)
        ms = grid_ms(taus, fs)
        count = int(math.floor(math.log(top / first) / math.log(growth) + 1e-9)) + 1
        expected = np.unique(np.floor(first * growth ** np.arange(count) + 0.5).astype(np.int64))
        np.testing.assert_array_equal(ms, expected[expected <= top])
    else:
        points = data.draw(st.one_of(st.none(), st.integers(2, 300)))
        taus = allanite.tau_grid(n, fs, "exp", points=points, tau_min=tau_min, m_max=m_max)
        ms = grid_ms(taus, fs)
        assert ms.size <= (100 if points is None else points)
        if top > first:
            assert ms[-1] == top  # geometric from first to top
    assert ms[0] == first
    assert np.all(np.diff(ms) > 0) and ms[-1] <= top


def exp_rule(n, growth, m0=1, m_max=None):
    """Paper 000 §4.2's grid written out: m = round(m0·g^(i−1)) up to the top, duplicates dropped."""
    top = m_max if m_max is not None else max(1, n // 9)
    count = int(math.floor(math.log(top / m0) / math.log(growth) + 1e-9)) + 1
    ms = np.unique(np.floor(m0 * growth ** np.arange(count) + 0.5).astype(np.int64))
    return ms[ms <= top]


@settings(max_examples=200, deadline=None)
# found by hypothesis outside CI: m = 5 was pulled into the dense part (⌈1/(g − 1)⌉ = 5; the points step
# 4.4 → 5.5, rounding to 4 and 6)
@example(n=54, growth=1.23828125, m0=1)
@example(n=10_000, growth=1111 ** (1 / 99), m0=1)
@example(n=900, growth=1.25, m0=3)
@given(n=st.integers(20, 2_000_000), growth=st.floats(1.0005, 4.0), m0=st.integers(1, 40))
def test_exp_grid_follows_the_rule(n, growth, m0):
    top = max(1, n // 9)
    m0 = min(m0, top)
    ms = grid_ms(allanite.tau_grid(n, 1.0, "exp", growth=growth, tau_min=float(m0)), 1.0)
    np.testing.assert_array_equal(ms, exp_rule(n, growth, m0))


def test_exp_grid_dense_part_stops_below_one_sample_steps():
    np.testing.assert_array_equal(allanite.tau_grid(54, 1.0, "exp", growth=1.23828125), [1, 2, 3, 4, 6])


def test_grid_docstring_examples():
    np.testing.assert_array_equal(allanite.tau_grid(1000, 1.0, "octave"), 2.0 ** np.arange(9))
    np.testing.assert_array_equal(
        allanite.tau_grid(1000, 10.0, "decade"), np.array([1, 2, 4, 10, 20, 40, 100, 200, 400]) / 10.0
    )
    # Paper 000's example (N = 10 000, 100 points, m_max = N/9 = 1111, g = 1111^(1/99) ≈ 1.073):
    # m = round(g^i), duplicates dropped, leaves 76 distinct m.
    g = 1111 ** (1 / 99)
    assert round(g, 3) == 1.073
    expected = np.unique(np.floor(g ** np.arange(100) + 0.5))
    np.testing.assert_array_equal(allanite.tau_grid(10_000, 1.0, "exp"), expected)
    assert expected.size == 76 and expected[-1] == 1111
    np.testing.assert_array_equal(allanite.tau_grid(100, 1.0, "all", m_max=5), [1, 2, 3, 4, 5])


@pytest.mark.parametrize("fs", [1.0, 100.0, 0.37, 3e3])
def test_explicit_taus_are_rounded_to_whole_samples(rng, fs):
    y = rng.normal(size=5_000)
    ms = np.array([1, 2, 3, 10, 57, 400, 2_500])
    delta = np.array([0.0, 0.3, -0.4, 0.49, -0.49, 0.1, -0.2])
    taus = (ms + delta) / fs
    for estimator in ESTIMATORS:
        r = allanite.avar(y, fs, taus=taus, estimator=estimator)
        np.testing.assert_array_equal(r.m, ms)
        np.testing.assert_array_equal(r.tau, ms / fs)
        exact = allanite.avar(y, fs, taus=ms / fs, estimator=estimator)
        assert np.array_equal(r.avar, exact.avar)
        ref = _reference.avar_reference(y, fs, ms, estimator)
        assert max_rel(r.avar, ref) <= 1e-9
    d = allanite.davar(y, fs, window=5_000, taus=taus)
    np.testing.assert_array_equal(d.m, ms)
    np.testing.assert_array_equal(d.tau, ms / fs)


@pytest.mark.parametrize("kind", GRIDS)
def test_results_report_the_grid_they_used(rng, kind):
    y = rng.normal(size=3_000)
    fs = 25.0
    r = allanite.avar(y, fs, taus=kind)
    np.testing.assert_array_equal(r.tau, allanite.tau_grid(3_000, fs, kind))
    np.testing.assert_array_equal(r.tau, r.m / fs)
    d = allanite.davar(y, fs, window=700, hop=100, taus=kind)
    np.testing.assert_array_equal(d.tau, allanite.tau_grid(700, fs, kind))  # grid of the *window*
    np.testing.assert_array_equal(d.tau, d.m / fs)


# --------------------------------------------------------------------------------------------------
# Numerics: the adversarial record (docs/FORMULAS.md §3.3: plain prefix sums lose every digit here)
# --------------------------------------------------------------------------------------------------

ADV_N = 2_100_000
ADV_WINDOW = 100_000
ADV_HOP = 10_000
ADV_OFFSET = 5.0


@pytest.fixture(scope="module")
def adversarial_record():
    """White noise whose std is 1e-3, then 1e3, then 1e-3 again (a 10⁶ jump each way), + offset 5."""
    rng = np.random.default_rng(7)
    third = ADV_N // 3
    std = np.full(ADV_N, 1e-3)
    std[third : 2 * third] = 1e3
    return rng.standard_normal(ADV_N) * std + ADV_OFFSET


def adversarial_windows(n_win):
    third = ADV_N // 3
    first_quiet_after = -(-2 * third // ADV_HOP)  # first window entirely after the loud part
    last_quiet_before = (third - ADV_WINDOW) // ADV_HOP
    js = {
        0,
        last_quiet_before,  # quiet, before
        (third + 1) // ADV_HOP + 5,
        n_win // 2,  # inside the loud part
        (2 * third) // ADV_HOP - 3,  # straddling the loud→quiet edge
        first_quiet_after,
        first_quiet_after + 1,
        first_quiet_after + 7,
        n_win - 10,
        n_win - 1,
    }  # quiet, long after
    return sorted(j for j in js if 0 <= j < n_win)


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_adversarial_dynamic_range(adversarial_record, dtype):
    y = adversarial_record.astype(dtype)
    y64 = y.astype(np.float64)  # what the library computes on
    d = allanite.davar(y, 1.0, window=ADV_WINDOW, hop=ADV_HOP, taus="exp", method="fast")
    n_win = (ADV_N - ADV_WINDOW) // ADV_HOP + 1
    assert d.avar.shape == (d.m.size, n_win) and d.m.size > 50 and d.m[-1] == ADV_WINDOW // 9
    assert np.all(np.isfinite(d.avar)) and np.all(d.avar > 0)
    js = adversarial_windows(n_win)
    third = ADV_N // 3
    assert any(j * ADV_HOP >= 2 * third for j in js)  # windows fully in the quiet part after the loud part
    worst = 0.0
    for j in js:
        s = j * ADV_HOP
        ref = _reference.davar_reference(y64[s : s + ADV_WINDOW], 1.0, ADV_WINDOW, ADV_HOP, d.m, dtype=np.longdouble)[
            :, 0
        ]
        worst = max(worst, max_rel(d.avar[:, j], ref))
    assert worst <= 1e-9, f"max relative error against extended precision: {worst:.3g}"


def test_adversarial_record_defeats_plain_prefix_sums(adversarial_record):
    """The test above is meaningful: the textbook vectorised NumPy DAVAR (global prefix sums) gets the
    quiet windows after the loud stretch completely wrong on the same record."""
    y = adversarial_record
    ms = np.array([1, 100, 10_000])
    j = (ADV_N - ADV_WINDOW) // ADV_HOP  # last window, quiet
    s = j * ADV_HOP
    naive_prefix = _reference.davar_prefix(y[: s + ADV_WINDOW], 1.0, ADV_WINDOW, ADV_HOP, ms)[:, j]
    ref = _reference.davar_reference(y[s : s + ADV_WINDOW], 1.0, ADV_WINDOW, ADV_HOP, ms, dtype=np.longdouble)[:, 0]
    assert np.max(np.abs(naive_prefix - ref) / ref) > 1e-2
    ours = allanite.davar(y[: s + ADV_WINDOW], 1.0, window=ADV_WINDOW, hop=ADV_HOP, taus=ms.astype(float)).avar[:, j]
    assert max_rel(ours, ref) <= 1e-9


def test_fast_survives_a_single_huge_outlier(rng):
    """The drift scenario of docs/FORMULAS.md §3.3, scaled down: one 1e6 outlier long before the windows checked."""
    y = rng.normal(size=400_000)
    y[1_000] = 1e6
    d = allanite.davar(y, 1.0, window=1_000, hop=1, taus=[1.0, 10.0, 100.0])
    for j in (5_000, 200_000, d.t.size - 1):
        ref = _reference.davar_reference(y[j : j + 1_000], 1.0, 1_000, 1, d.m, dtype=np.longdouble)[:, 0]
        assert max_rel(d.avar[:, j], ref) <= 1e-12


# --------------------------------------------------------------------------------------------------
# Exact invariants
# --------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("c", [0.0, 1.0, -3.3, 0.1, 1 / 3, 1e6 + 0.1, math.pi, 7e-300, 1e300])
@pytest.mark.parametrize("estimator", ESTIMATORS)
def test_constant_rate_has_zero_allan_variance(c, estimator):
    y = np.full(1_001, c)
    assert np.all(allanite.avar(y, 3.0, taus="all", estimator=estimator).avar == 0.0)
    for method in METHODS:
        d = allanite.davar(y, 3.0, window=100, hop=7, taus="all", estimator=estimator, method=method)
        assert np.max(np.abs(d.avar)) <= 1e-30


@pytest.mark.parametrize("fs", [1.0, 100.0, 3.0])
@pytest.mark.parametrize("slope, offset", [(0.1, 3.0), (1 / 3, -7.0), (1e3, 1e6)])
def test_linear_angle_has_zero_allan_variance(fs, slope, offset):
    x = offset + slope * np.arange(5_001) / fs  # constant rate `slope`, rounded to doubles
    r = allanite.avar(x, fs, input="angle", taus="all")
    # Only the rounding of x is left: each rate sample is off by at most ~1 ulp(max|x|)·fs.
    bound = (2 * np.spacing(np.max(np.abs(x))) * fs) ** 2
    assert np.all(r.avar >= 0) and np.max(r.avar) <= bound
    exact = 0.5 * np.arange(1_001)  # every difference exactly 0.5
    for estimator in ESTIMATORS:
        assert np.all(allanite.avar(exact, fs, input="angle", taus="all", estimator=estimator).avar == 0.0)
        assert np.all(
            allanite.davar(exact, fs, input="angle", window=300, hop=11, taus="all", estimator=estimator).avar == 0.0
        )


@pytest.mark.parametrize("c", [3.7, -2.0, 1e-5, 1e5])
@pytest.mark.parametrize("estimator", ESTIMATORS)
def test_scaling_by_a_constant(rng, c, estimator):
    y = rng.normal(size=5_000) + np.cumsum(rng.normal(size=5_000)) * 0.01 + 1.0
    # m with ≥ 9 terms: a classic estimate from one or two cluster differences is ill-conditioned
    # (the rounding of c·y alone moves it by 2e-14, and float64 block sums by up to ~1e-12).
    taus = allanite.tau_grid(5_000, 10.0, "all", m_max=500)
    a = allanite.avar(y, 10.0, taus=taus, estimator=estimator)
    b = allanite.avar(c * y, 10.0, taus=taus, estimator=estimator)
    assert max_rel(b.avar, c * c * a.avar) <= 1e-12
    da = allanite.davar(y, 10.0, window=1_200, hop=301, taus="exp", estimator=estimator)
    db = allanite.davar(c * y, 10.0, window=1_200, hop=301, taus="exp", estimator=estimator)
    assert max_rel(db.avar, c * c * da.avar) <= 1e-12


def test_white_noise_level(rng):
    """A statistical sanity check with a generous margin: white rate noise of std σ gives
    σ²(τ) = σ²·τ0/τ; 10⁶ samples pin it to a few % up to m = 1000."""
    sigma = 0.7
    y = rng.normal(size=1_000_000) * sigma
    r = allanite.avar(y, 50.0, taus=np.array([1, 10, 100, 1000]) / 50.0)
    np.testing.assert_allclose(r.avar * r.m, sigma**2, rtol=0.1)
    np.testing.assert_allclose(r.adev, np.sqrt(r.avar), rtol=0)


# --------------------------------------------------------------------------------------------------
# The static classic estimator: cluster sums gathered from one double-word prefix (rust/core/src/gather.rs)
# --------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_static_classic_gather_on_the_adversarial_record(adversarial_record, dtype):
    y = adversarial_record.astype(dtype)
    ms = np.unique(np.round(np.geomspace(1, ADV_N // 2, 40)).astype(np.int64))
    r = allanite.avar(y, 1.0, taus=ms.astype(float), estimator="avar")
    ref = _reference.avar_reference(y.astype(np.float64), 1.0, r.m, "avar", dtype=np.longdouble)
    assert r.m.size == ms.size
    assert max_rel(r.avar, ref) <= 1e-9


def test_static_classic_gather_dense_taus_several_axes(rng):
    # a dense linear τ list (every m up to N/2, as ROS/Kalibr users ask for) on three axes of different
    # level and offset: each axis equals its plain twin, and the same as its single-axis call
    n = 20_011
    X = rng.normal(size=(n, 3)) * [1.0, 1e-5, 1e4] + [0.0, 7.0, -3e4]
    ms = np.arange(1, n // 2 + 1)
    r = allanite.avar(X, 10.0, taus=ms / 10.0, estimator="avar")
    assert r.avar.shape == (3, ms.size)
    for a in range(3):
        ref = _reference.avar_reference(X[:, a], 10.0, ms, "avar", dtype=np.longdouble)
        assert max_rel(r.avar[a], ref) <= 1e-11
        single = allanite.avar(X[:, a], 10.0, taus=ms / 10.0, estimator="avar").avar
        assert np.array_equal(single, r.avar[a])
    for workers in (1, 2, 3):
        assert np.array_equal(allanite.avar(X, 10.0, taus=ms / 10.0, estimator="avar", workers=workers).avar, r.avar)


def test_static_classic_gather_equals_the_sliding_path(rng):
    # two windows take the streaming (sliding-sum) path, one window the gather: same numbers
    y = rng.normal(size=12_000) + 2.0
    ms = np.array([1, 2, 5, 64, 999, 2_500])
    two = allanite.davar(y, 1.0, window=10_000, hop=2_000, taus=ms.astype(float), estimator="avar").avar
    one = allanite.avar(y[:10_000], 1.0, taus=ms.astype(float), estimator="avar").avar
    assert max_rel(one, two[:, 0]) <= 1e-12


# --------------------------------------------------------------------------------------------------
# The static overlapping estimator: every m from one double-word phase (rust/core/src/oavar.rs)
# --------------------------------------------------------------------------------------------------


def _growth_ms(n, growth=1.2):
    k = np.arange(int(np.log(n / 2) / np.log(growth)) + 2)
    ms = np.unique(np.round(growth**k).astype(np.int64))
    return ms[ms <= n // 2]


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_static_oavar_phase_on_the_adversarial_record(adversarial_record, dtype):
    # 10⁶ level changes (2.1·10⁶ samples, offset 5), float64 and float32 input, m up to N/2
    y = adversarial_record.astype(dtype)
    ms = _growth_ms(ADV_N, 1.5)
    r = allanite.avar(y, 1.0, taus=ms.astype(float))
    ref = _reference.avar_reference(y.astype(np.float64), 1.0, r.m, "oavar", dtype=np.longdouble)
    assert np.array_equal(r.m, ms)
    assert max_rel(r.avar, ref) <= 1e-9


def test_static_oavar_phase_small_noise_on_a_large_slow_swing(rng):
    # a rate swing 10⁴ × the noise over the record: the phase reaches ~10⁸·σ while the terms at short m
    # are ~σ — a plain f64 prefix loses ~1e-8 relative there; the double-word phase keeps every digit
    n = 400_003
    t = np.arange(n)
    y = 1e4 * np.sin(2 * np.pi * t / n) + rng.normal(size=n)
    ms = _growth_ms(n)
    r = allanite.avar(y, 1.0, taus=ms.astype(float))
    ref = _reference.avar_reference(y, 1.0, ms, "oavar", dtype=np.longdouble)
    assert max_rel(r.avar, ref) <= 1e-11
    x = np.concatenate(([0.0], np.cumsum(y)))  # what the plain prefix gives, to show the test can fail
    plain = np.array([np.mean((x[2 * m :] - 2 * x[m:-m] + x[: -2 * m]) ** 2) / (2.0 * m * m) for m in ms[:3]])
    assert max_rel(plain, ref[:3]) > 1e-10


def test_static_oavar_phase_several_axes_and_any_thread_count(rng):
    # axes of different level and offset, a length that is no multiple of the chunks: each axis equals
    # its plain twin and its single-axis call, bit for bit whatever the thread count
    n = 300_007
    X = rng.normal(size=(n, 3)) * [1.0, 1e-5, 1e4] + [0.0, 7.0, -3e4]
    ms = _growth_ms(n)
    r = allanite.avar(X, 10.0, taus=ms / 10.0)
    for a in range(3):
        ref = _reference.avar_reference(X[:, a], 10.0, ms, "oavar", dtype=np.longdouble)
        assert max_rel(r.avar[a], ref) <= 1e-11
        assert np.array_equal(allanite.avar(X[:, a], 10.0, taus=ms / 10.0).avar, r.avar[a])
    for workers in (1, 2, 3):
        assert np.array_equal(allanite.avar(X, 10.0, taus=ms / 10.0, workers=workers).avar, r.avar)


def test_static_oavar_phase_equals_the_sliding_path(rng):
    # two windows take the streaming (sliding-sum) path, one window the phase: same numbers
    y = rng.normal(size=12_000) + 2.0
    ms = np.array([1, 2, 5, 8, 9, 64, 999, 4_096, 5_000])
    two = allanite.davar(y, 1.0, window=10_000, hop=2_000, taus=ms.astype(float)).avar
    one = allanite.avar(y[:10_000], 1.0, taus=ms.astype(float)).avar
    assert max_rel(one, two[:, 0]) <= 1e-12


@pytest.mark.parametrize("hop", [1, 2, 63, 64, 65, 500, 2_999, 3_000, 7_001])
def test_every_hop_regime_matches_the_reference(rng, hop):
    """The phase paths of the engine (every term kept for hops < 64, block sums tile by tile above; a
    hop longer than the window's terms leaves q = 0 whole blocks) against the plain per-window
    recomputation in extended precision, on a record with a large offset and a 10⁴ level step."""
    y = rng.normal(size=21_000) * np.where(np.arange(21_000) < 9_000, 1e2, 1e-2) + 50.0
    window = 3_000
    ms = np.array([1, 2, 7, 64, 100, 333, 1_000, 1_499])
    d = allanite.davar(y, 1.0, window=window, hop=hop, taus=ms.astype(float))
    n_win = (y.size - window) // hop + 1
    assert d.avar.shape == (ms.size, n_win)
    for j in sorted({0, 1, n_win // 3, n_win // 2, n_win - 2, n_win - 1} & set(range(n_win))):
        s = j * hop
        ref = _reference.davar_reference(y[s : s + window], 1.0, window, window, ms, dtype=np.longdouble)[:, 0]
        assert max_rel(d.avar[:, j], ref) <= 1e-10, (hop, j)


def test_short_hop_long_m_streams_and_matches_the_reference(rng):
    """Short hops take m ≤ 8 192 from the phase and longer m from the streaming block sums: both kinds
    of row in one call, against the plain recomputation."""
    y = rng.normal(size=24_000) + 1e3
    window = 20_000
    ms = np.array([3, 8_192, 8_193, 9_999])
    d = allanite.davar(y, 1.0, window=window, hop=7, taus=ms.astype(float))
    for j in (0, d.t.size // 2, d.t.size - 1):
        s = j * 7
        ref = _reference.davar_reference(y[s : s + window], 1.0, window, window, ms, dtype=np.longdouble)[:, 0]
        assert max_rel(d.avar[:, j], ref) <= 1e-10, j


def test_property_tests_run_on_fixed_inputs_by_default():
    # tests/conftest.py: the same examples on every run and no example database, unless ALLANITE_EXPLORE is set
    from hypothesis import settings as current

    exploring = os.environ.get("ALLANITE_EXPLORE", "").strip() not in ("", "0")
    assert current.default.derandomize is not exploring
    assert (current.default.database is None) is not exploring


@pytest.mark.parametrize("n, window", [(3_000, 40), (3_001, 41), (2_500, 1_000), (700, 233)])
def test_hop1_surface_matches_the_per_window_recomputation(rng, n, window):
    """The hop-1 rows (terms formed segment by segment, two lanes of segments, each window written once:
    rust/core/src/window_sums.rs) against every window recomputed from its own samples, to 1e-12 — rows of
    one to ~100 segments, even and odd counts, on an offset record."""
    y = rng.normal(size=n) * 0.3 + 2.0
    ms = np.unique(np.linspace(1, window // 2, 9).astype(int))
    fast = allanite.davar(y, 10.0, window=window, hop=1, taus=ms / 10.0, method="fast")
    naive = allanite.davar(y, 10.0, window=window, hop=1, taus=ms / 10.0, method="naive")
    assert max_rel(fast.avar, naive.avar) <= 1e-12
