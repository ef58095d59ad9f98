"""Every bad input gets an allanite error — a ValueError subclass — whose message says what was wrong.

Known gaps (library bugs) are collected at the end as strict xfails, each with a reproducer in its
reason; the fuzz test stays clear of exactly those inputs.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

import allanite
from allanite import AllaniteError, InputError, MemoryBudgetError, ParameterError


@pytest.fixture
def y(rng):
    return rng.normal(size=100)


def test_error_hierarchy():
    for cls in (InputError, ParameterError, MemoryBudgetError):
        assert issubclass(cls, AllaniteError)
    assert issubclass(AllaniteError, ValueError)
    assert allanite.errors.AllaniteError is AllaniteError


# --------------------------------------------------------------------------------------------------
# The samples
# --------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize("input", ["rate", "increment", "angle"])
def test_non_finite_sample_1d(y, bad, input):
    y = y.copy()
    y[17] = bad
    for call in (lambda: allanite.avar(y, 1.0, input=input), lambda: allanite.davar(y, 1.0, window=20, input=input)):
        with pytest.raises(InputError, match=rf"non-finite value \({re.escape(str(bad))}\) at sample 17;"):
            call()


def test_non_finite_sample_2d_names_sample_and_axis():
    x = np.zeros((50, 3))
    x[7, 2] = np.inf
    x[9, 1] = np.nan  # the first bad axis in order is axis 1
    with pytest.raises(InputError, match=r"non-finite value \(nan\) at sample 9 of axis 1"):
        allanite.avar(x, 1.0)
    x[9, 1] = 0.0
    with pytest.raises(InputError, match=r"non-finite value \(inf\) at sample 7 of axis 2"):
        allanite.davar(x, 1.0, window=10)


@pytest.mark.parametrize(
    "x, msg",
    [
        (np.array([]), r"record has 0 samples; at least 2 are needed"),
        ([], r"record has 0 samples; at least 2 are needed"),
        (np.zeros((0, 2)), r"record has 0 samples; at least 2 are needed"),
        ([1.0], r"record has 1 samples; at least 2 are needed"),
        (np.zeros((1, 3)), r"record has 1 samples; at least 2 are needed"),
    ],
)
def test_too_short_records(x, msg):
    with pytest.raises(InputError, match=msg):
        allanite.avar(x, 1.0)
    with pytest.raises(InputError, match=msg):
        allanite.davar(x, 1.0, window=2)


def test_angle_input_needs_three_points():
    with pytest.raises(InputError, match=r"record has 2 angle points; at least 3 are needed"):
        allanite.avar([0.0, 1.0], 1.0, input="angle")
    with pytest.raises(InputError, match=r"record has 1 angle points"):
        allanite.davar([0.0], 1.0, window=2, input="angle")
    # the shortest valid records, for contrast
    r = allanite.avar([0.0, 1.0, 3.0], 1.0, input="angle")
    assert r.avar.shape == (1,) and r.avar[0] == pytest.approx(0.5)  # ((3−1)−(1−0))² / 2
    assert allanite.avar([1.0, 2.0], 1.0).avar[0] == pytest.approx(0.5)


@pytest.mark.parametrize(
    "x, msg",
    [
        (np.zeros((10, 2, 2)), r"1-D \(samples,\) or 2-D \(samples, axes\), got 3-D with shape \(10, 2, 2\)"),
        (np.float64(3.0), r"got 0-D with shape \(\)"),
        (3.0, r"got 0-D"),
        (np.zeros((10, 0)), r"samples have shape \(10, 0\): at least one axis is needed"),
    ],
)
def test_bad_shapes(x, msg):
    with pytest.raises(InputError, match=msg):
        allanite.avar(x, 1.0)
    with pytest.raises(InputError, match=msg):
        allanite.davar(x, 1.0, window=2)


@pytest.mark.parametrize(
    "x, kind",
    [
        (np.arange(10) + 0j, r"complex128 \('c' kind\)"),
        (np.arange(10) > 4, r"bool \('bool' kind\)"),
        (np.array(["1", "2", "3"]), r"<U1 \('U' kind\)"),
        (np.array([b"1", b"2"]), r"\|S1 \('S' kind\)"),
        (np.array([1.0, 2.0, 3.0], dtype=object), r"object \('O' kind\)"),
        ([1, "2", 3.0], r"<U\d+ \('U' kind\)"),
        (None, r"object \('O' kind\)"),
        (np.arange(5).astype("datetime64[s]"), r"datetime64\[s\] \('M' kind\)"),
        ([10**400, 1, 2], r"object"),
    ],
)
def test_non_real_dtypes(x, kind):
    with pytest.raises(InputError, match=r"samples must be real numbers \(integer or float dtype\), got dtype " + kind):
        allanite.avar(x, 1.0)


def test_ragged_input():
    with pytest.raises(InputError, match=r"could not be read as a numeric array"):
        allanite.avar([[1.0, 2.0], [3.0]], 1.0)


# --------------------------------------------------------------------------------------------------
# fs, window, hop
# --------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "fs, shown",
    [
        (0, "0.0"),
        (0.0, "0.0"),
        (-1.0, "-1.0"),
        (-np.inf, "-inf"),
        (np.nan, "nan"),
        (np.inf, "inf"),
        ("100", "'100'"),
        (None, "None"),
        (True, "True"),
        (1 + 0j, r"\(1\+0j\)"),
        (np.array([1.0]), r"array\(\[1\.\]\)"),
    ],
)
def test_bad_fs(y, fs, shown):
    msg = rf"fs must be a positive finite number of samples per second, got {shown}"
    with pytest.raises(ParameterError, match=msg):
        allanite.avar(y, fs)
    with pytest.raises(ParameterError, match=msg):
        allanite.davar(y, fs, window=10)
    with pytest.raises(ParameterError, match=msg):
        allanite.tau_grid(100, fs)


def test_window_longer_than_record(y):
    with pytest.raises(ParameterError, match=r"window \(101 samples\) is longer than the record \(100 samples\)"):
        allanite.davar(y, 1.0, window=101)
    ang = np.concatenate([[0.0], np.cumsum(y)])  # 101 angle points = 100 intervals
    assert allanite.davar(ang, 1.0, window=100, input="angle").avar.shape[1] == 1
    with pytest.raises(ParameterError, match=r"window \(101 samples\) is longer than the record \(100 samples\)"):
        allanite.davar(ang, 1.0, window=101, input="angle")


@pytest.mark.parametrize("window, shown", [(1, "1"), (0, "0"), (-5, "-5"), (np.int64(1), "1")])
def test_window_below_two(y, window, shown):
    with pytest.raises(ParameterError, match=rf"window must be an integer ≥ 2, got {shown}$"):
        allanite.davar(y, 1.0, window=window)


@pytest.mark.parametrize(
    "window, shown",
    [
        (10.5, "10.5"),
        ("10", "'10'"),
        (None, "None"),
        (True, "True"),
        (np.nan, "nan"),
        (np.inf, "inf"),
        ([10], r"\[10\]"),
    ],
)
def test_window_not_an_integer(y, window, shown):
    with pytest.raises(ParameterError, match=rf"window must be an integer ≥ 2, got {shown}"):
        allanite.davar(y, 1.0, window=window)


@pytest.mark.parametrize(
    "hop, shown",
    [
        (0, "0"),
        (-1, "-1"),
        (1.5, "1.5"),
        ("2", "'2'"),
        (None, "None"),
        (False, "False"),
        (np.float64(0.5), r"(np\.float64\()?0\.5"),
    ],
)
def test_bad_hop(y, hop, shown):
    with pytest.raises(ParameterError, match=rf"hop must be an integer ≥ 1, got {shown}"):
        allanite.davar(y, 1.0, window=10, hop=hop)


def test_integral_floats_are_accepted_for_counts(y):
    a = allanite.davar(y, 1.0, window=10.0, hop=np.float64(3.0))
    b = allanite.davar(y, 1.0, window=10, hop=3)
    assert (a.window, a.hop) == (10, 3)
    assert np.array_equal(a.avar, b.avar)


def test_window_too_short_for_the_taus(y):
    with pytest.raises(
        ParameterError,
        match=r"taus\[0\] = 3 s \(m = 3\) is too long for 5 samples: "
        r"the largest τ is 2 s \(m = 2\)",
    ):
        allanite.davar(y, 1.0, window=5, taus=[3.0])
    with pytest.raises(ParameterError, match=r"taus\[0\] = 2 s \(m = 2\) is too long for 2 samples"):
        allanite.davar(y, 1.0, window=2, taus=[2.0])
    with pytest.raises(ParameterError, match=r"a record or window of 1 samples is too short for any τ"):
        allanite.tau_grid(1, 1.0, "octave")


# --------------------------------------------------------------------------------------------------
# τ
# --------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "taus, msg",
    [
        ([1.0, -2.0], r"taus\[1\] = .*-2\.0.* s: every τ must be a positive finite number of seconds"),
        ([0.0], r"taus\[0\] = .*0\.0.* s: every τ must be a positive finite number of seconds"),
        ([1.0, np.nan], r"taus\[1\] = .*nan.* s: every τ must be a positive finite number"),
        ([np.inf], r"taus\[0\] = .*inf.* s: every τ must be a positive finite number"),
        ([0.04], r"taus\[0\] = 0\.04 s is shorter than one sample \(1/fs = 0\.1 s\)"),
        ([1.0, 5.1], r"taus\[1\] = 5\.1 s \(m = 51\) is too long for 100 samples: the largest τ is 5 s \(m = 50\)"),
        (
            [0.21, 0.24],
            r"taus\[0\] = 0\.21 s and taus\[1\] = 0\.24 s map to m = 2 and 2; τ must map to strictly increasing",
        ),
        ([0.4, 0.2], r"taus\[0\] = 0\.4 s and taus\[1\] = 0\.2 s map to m = 4 and 2"),
        ([], r"taus must be a non-empty 1-D sequence of τ in seconds, got shape \(0,\)"),
        ([[0.1, 0.2]], r"got shape \(1, 2\)"),
        (["a"], r"taus must be a grid name \(all, octave, decade, exp\) or a sequence of τ in seconds"),
        ([1 + 1j], r"taus must be a grid name"),
        ({0.1, 0.2}, r"taus must be a grid name"),
        ("linear", r"unknown τ grid 'linear'; allowed: 'all', 'octave', 'decade', 'exp'"),
        ("Octave", r"unknown τ grid 'Octave'"),
        ("", r"unknown τ grid ''"),
    ],
)
def test_bad_taus(y, taus, msg):
    with pytest.raises(ParameterError, match=msg):
        allanite.avar(y, 10.0, taus=taus)
    with pytest.raises(ParameterError, match=msg):
        allanite.davar(y, 10.0, window=100, taus=taus)


# --------------------------------------------------------------------------------------------------
# Choices
# --------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("value", ["mdev", "OAVAR", "", None, b"oavar", 1])
def test_unknown_estimator(y, value):
    msg = rf"unknown estimator {re.escape(repr(value))}; allowed: 'oavar', 'avar'"
    with pytest.raises(ParameterError, match=msg):
        allanite.avar(y, 1.0, estimator=value)
    with pytest.raises(ParameterError, match=msg):
        allanite.davar(y, 1.0, window=10, estimator=value)


@pytest.mark.parametrize("value", ["slow", "Fast", None])
def test_unknown_method(y, value):
    with pytest.raises(ParameterError, match=rf"unknown method {re.escape(repr(value))}; allowed: 'fast', 'naive'"):
        allanite.davar(y, 1.0, window=10, method=value)


@pytest.mark.parametrize("value", ["phases", "Frequency", "Rate", None])
def test_unknown_input(y, value):
    msg = (
        rf"unknown input {re.escape(repr(value))}; allowed: 'rate', 'increment', 'angle', or 'phase' \(= 'angle'\), "
        r"'freq' \(= 'rate'\), 'frequency' \(= 'rate'\)"
    )
    with pytest.raises(ParameterError, match=msg):
        allanite.avar(y, 1.0, input=value)
    with pytest.raises(ParameterError, match=msg):
        allanite.davar(y, 1.0, window=10, input=value)


@pytest.mark.parametrize("value, ours", [("phase", "angle"), ("freq", "rate"), ("frequency", "rate")])
def test_another_tools_input_word_is_ours(y, value, ours):
    """allantools' and Stable32's words for the samples are allanite's: the same numbers, and the result says
    allanite's word (a clock's phase is input='angle', M + 1 points)."""
    x = np.concatenate([[0.0], np.cumsum(y)]) if ours == "angle" else y
    theirs, mine = allanite.avar(x, 1.0, input=value), allanite.avar(x, 1.0, input=ours)
    assert theirs.input == ours
    np.testing.assert_array_equal(theirs.avar, mine.avar)
    dyn = allanite.davar(x, 1.0, window=40, input=value)
    assert dyn.input == ours
    np.testing.assert_array_equal(dyn.avar, allanite.davar(x, 1.0, window=40, input=ours).avar)


@pytest.mark.parametrize("workers, shown", [(0, "0"), (-1, "-1"), (1.5, "1.5"), ("2", "'2'"), (True, "True")])
def test_bad_workers(y, workers, shown):
    with pytest.raises(ParameterError, match=rf"workers must be an integer ≥ 1, got {shown}"):
        allanite.avar(y, 1.0, workers=workers)
    with pytest.raises(ParameterError, match=rf"workers must be an integer ≥ 1, got {shown}"):
        allanite.davar(y, 1.0, window=10, workers=workers)


# --------------------------------------------------------------------------------------------------
# tau_grid options
# --------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "kwargs, msg",
    [
        (dict(kind="exp", growth=1.5, points=10), r"give either growth or points for the 'exp' grid, not both"),
        (dict(kind="exp", growth=1.0), r"growth must be a finite factor > 1, got 1\b"),
        (dict(kind="exp", growth=0.5), r"growth must be a finite factor > 1, got 0\.5"),
        (dict(kind="exp", growth=-2), r"growth must be a finite factor > 1, got -2"),
        (dict(kind="exp", growth=math.inf), r"growth must be a finite factor > 1, got inf"),
        (dict(kind="exp", growth=math.nan), r"growth must be a finite factor > 1, got nan"),
        (dict(kind="octave", growth=2.0), r"growth, points and tau_min apply to the 'exp' grid only, not 'octave'"),
        (dict(kind="all", points=5), r"apply to the 'exp' grid only, not 'all'"),
        (dict(kind="decade", tau_min=2.0), r"apply to the 'exp' grid only, not 'decade'"),
        (dict(kind="exp", points=1), r"points must be an integer ≥ 2, got 1"),
        (dict(kind="exp", points=2.5), r"points must be an integer ≥ 2, got 2\.5"),
        (dict(kind="exp", tau_min=0.0), r"tau_min = 0 s maps to m = 0; allowed is 1 ≤ m ≤ 111"),
        (dict(kind="exp", tau_min=500.0), r"tau_min = 500 s maps to m = 500; allowed is 1 ≤ m ≤ 111"),
        (dict(kind="exp", m_max=501), r"m_max = 501 exceeds 500, the largest m for 1000 samples"),
        (dict(kind="all", m_max=0), r"m_max must be an integer ≥ 1, got 0"),
        (dict(kind="bad"), r"unknown τ grid 'bad'"),
        (dict(kind=None), r"kind must be one of \('all', 'octave', 'decade', 'exp'\), got None"),
    ],
)
def test_tau_grid_option_misuse(kwargs, msg):
    with pytest.raises(ParameterError, match=msg):
        allanite.tau_grid(1000, 1.0, **kwargs)


@pytest.mark.parametrize("n, shown", [(0, "0"), (-3, "-3"), (2.5, "2.5"), ("10", "'10'")])
def test_tau_grid_bad_n(n, shown):
    with pytest.raises(ParameterError, match=rf"n must be an integer ≥ 1, got {shown}"):
        allanite.tau_grid(n, 1.0, "all")


# --------------------------------------------------------------------------------------------------
# Memory budget and environment
# --------------------------------------------------------------------------------------------------

_BUDGET_RE = re.compile(
    r"the output would take (\d+\.\d\d) GiB \((\d+) axes × (\d+) τ × (\d+) windows × 8 bytes\), "
    r"over the memory budget of (\d+\.\d\d) GiB; use hop ≥ (\d+), fewer τ"
)


def _budget_error(x, window, hop, max_memory, taus="exp"):
    with pytest.raises(MemoryBudgetError) as info:
        allanite.davar(x, 1.0, window=window, hop=hop, taus=taus, max_memory=max_memory)
    m = _BUDGET_RE.search(str(info.value))
    assert m, str(info.value)
    return m, str(info.value)


def test_memory_budget_error_and_its_suggested_hop():
    x = np.zeros((2_000_000, 2))
    window, n_tau = 1_000, allanite.tau_grid(1_000, 1.0, "exp").size
    budget = 0.5 * 2**30
    m, msg = _budget_error(x, window, 1, budget)
    n_win = 2_000_000 - window + 1
    nbytes = 2 * n_tau * n_win * 8
    assert float(m.group(1)) == pytest.approx(nbytes / 2**30, abs=0.005)
    assert (int(m.group(2)), int(m.group(3)), int(m.group(4))) == (2, n_tau, n_win)
    assert m.group(5) == "0.50"
    hop = int(m.group(6))
    # the suggestion fits, and is the smallest hop that does
    d = allanite.davar(x, 1.0, window=window, hop=hop, taus="exp", max_memory=budget)
    assert d.avar.nbytes <= budget and d.avar.shape == (2, n_tau, (2_000_000 - window) // hop + 1)
    assert 2 * n_tau * ((2_000_000 - window) // (hop - 1) + 1) * 8 > budget
    with pytest.raises(MemoryBudgetError):
        allanite.davar(x, 1.0, window=window, hop=hop - 1, taus="exp", max_memory=budget)


@settings(max_examples=40, deadline=None)
@given(
    n=st.integers(50, 5_000),
    window=st.integers(2, 50),
    hop=st.integers(1, 5),
    n_tau=st.integers(1, 10),
    windows_fitting=st.integers(1, 400),
    extra=st.integers(0, 7),
)
def test_suggested_hop_always_fits(n, window, hop, n_tau, windows_fitting, extra):
    """For any budget that holds at least one window's output, the suggested hop fits."""
    n_tau = min(n_tau, window // 2)
    taus = np.arange(1, n_tau + 1, dtype=float)
    budget = windows_fitting * n_tau * 8 + extra
    n_win = (n - window) // hop + 1
    if n_win * n_tau * 8 <= budget:
        return
    m, _ = _budget_error(np.zeros(n), window, hop, budget, taus=taus)
    suggested = int(m.group(6))
    assert suggested > hop
    d = allanite.davar(np.zeros(n), 1.0, window=window, hop=suggested, taus=taus, max_memory=budget)
    assert d.avar.nbytes <= budget


def test_max_memory_env_and_argument(monkeypatch, y):
    monkeypatch.setenv("ALLANITE_MAX_MEMORY", "1000")  # 1000 bytes: 51 windows × 5 τ × 8 = 2040 > 1000
    with pytest.raises(MemoryBudgetError, match=r"over the memory budget"):
        allanite.davar(y, 1.0, window=50, taus="octave")
    assert allanite.davar(y, 1.0, window=50, taus="octave", max_memory=10_000).avar.shape == (5, 51)
    monkeypatch.setenv("ALLANITE_MAX_MEMORY", "1e4")
    assert allanite.davar(y, 1.0, window=50, taus="octave").avar.shape == (5, 51)


@pytest.mark.parametrize(
    "value, msg",
    [
        ("abc", r"ALLANITE_NUM_THREADS='abc' must be a positive integer"),
        ("0", r"ALLANITE_NUM_THREADS='0' must be an integer from 1 to 4096"),
        ("-2", r"ALLANITE_NUM_THREADS='-2' must be an integer from 1 to 4096"),
        ("1.5", r"ALLANITE_NUM_THREADS='1\.5' must be a positive integer"),
    ],
)
def test_bad_num_threads_env(monkeypatch, y, value, msg):
    monkeypatch.setenv("ALLANITE_NUM_THREADS", value)
    with pytest.raises(ParameterError, match=msg):
        allanite.avar(y, 1.0)
    with pytest.raises(ParameterError, match=msg):
        allanite.davar(y, 1.0, window=10)
    assert allanite.avar(y, 1.0, workers=1).avar.size > 0  # an explicit value does not read the variable


@pytest.mark.parametrize(
    "value, msg",
    [
        ("lots", r"ALLANITE_MAX_MEMORY='lots' must be a positive number of bytes"),
        ("2GB", r"ALLANITE_MAX_MEMORY='2GB' must be a positive number of bytes"),
        ("0", r"ALLANITE_MAX_MEMORY='0' must be a positive number of bytes, got 0\.0"),
        ("-5", r"ALLANITE_MAX_MEMORY='-5' must be a positive number of bytes, got -5\.0"),
        ("nan", r"ALLANITE_MAX_MEMORY='nan' must be a positive number of bytes, got nan"),
        ("inf", r"ALLANITE_MAX_MEMORY='inf' must be a positive number of bytes, got inf"),
    ],
)
def test_bad_max_memory_env(monkeypatch, y, value, msg):
    monkeypatch.setenv("ALLANITE_MAX_MEMORY", value)
    with pytest.raises(ParameterError, match=msg):
        allanite.davar(y, 1.0, window=10)
    assert allanite.davar(y, 1.0, window=10, max_memory=1e9).avar.size > 0


@pytest.mark.parametrize(
    "value, shown",
    [(0, "0"), (-1, "-1"), (math.nan, "nan"), (math.inf, "inf"), ("1e9", "'1e9'"), (True, "True"), (None, None)],
)
def test_bad_max_memory_argument(y, value, shown):
    if value is None:
        assert allanite.davar(y, 1.0, window=10, max_memory=None).avar.size > 0
        return
    with pytest.raises(ParameterError, match=rf"max_memory must be a positive number of bytes, got {shown}"):
        allanite.davar(y, 1.0, window=10, max_memory=value)


# --------------------------------------------------------------------------------------------------
# Fuzz: either a consistent result or an AllaniteError, never anything else
# --------------------------------------------------------------------------------------------------


def _mostly(draw, good, bad, p_good=0.93):
    """Draw from ``good`` most of the time, so that many calls succeed, else from ``bad``."""
    return draw(good) if draw(st.floats(0, 1)) < p_good else draw(bad)


_real_dtypes = st.sampled_from([np.float64, np.float32, np.int16, np.uint8, ">f8", np.int64])
_other_dtypes = st.sampled_from([np.complex128, np.bool_])
_good_fs = st.one_of(st.sampled_from([1.0, 100.0, 0.37, 3, np.float32(2.0)]), st.floats(1e-3, 1e6))
_bad_fs = st.sampled_from([0, -1.0, math.nan, math.inf, "1", None])
_grid_names = st.sampled_from(["all", "octave", "decade", "exp"])
_bad_taus = st.one_of(
    st.sampled_from(["bogus", None, ""]),
    st.lists(st.one_of(st.floats(-2.0, 1e3), st.sampled_from([math.nan, math.inf, 0.0])), min_size=0, max_size=5),
    st.lists(st.integers(-2, 200), min_size=1, max_size=5),
)
_bad_count = st.one_of(st.integers(-3, 1), st.sampled_from([2.5, None, "4", True, math.nan, 10**6]))


@st.composite
def _calls(draw):
    ndim = _mostly(draw, st.integers(1, 2), st.sampled_from([0, 3]))
    shape = [draw(st.integers(0, 200)) if i == 0 else draw(st.integers(0, 4)) for i in range(ndim)]
    if ndim >= 1 and draw(st.floats(0, 1)) < 0.85:
        shape[0] = max(shape[0], 3)
    if ndim == 2 and draw(st.floats(0, 1)) < 0.85:
        shape[1] = max(shape[1], 1)
    dtype = _mostly(draw, _real_dtypes, _other_dtypes)
    seed = draw(st.integers(0, 2**16))
    x = np.random.default_rng(seed).normal(size=tuple(shape)) * 10
    x = x.astype(dtype) if np.dtype(dtype).kind != "b" else x > 0
    if x.size and draw(st.floats(0, 1)) < 0.1 and np.dtype(dtype).kind in "fc":
        x.flat[draw(st.integers(0, x.size - 1))] = draw(st.sampled_from([np.nan, np.inf]))
    if draw(st.floats(0, 1)) < 0.2 and x.ndim >= 1:
        x = x.tolist()
    n = shape[0] if ndim else 0
    fs = _mostly(draw, _good_fs, _bad_fs)
    good_taus = _grid_names
    if isinstance(fs, (int, float, np.floating)) and math.isfinite(fs) and fs > 0:
        # explicit τ that map to valid m for most records and windows: m/fs, m small
        good_taus = st.one_of(
            _grid_names,
            st.lists(st.integers(1, max(1, n // 4)), min_size=1, max_size=4, unique=True).map(
                lambda ms: np.sort(ms) / float(fs)
            ),
        )
    kw = dict(
        fs=fs,
        input=_mostly(draw, st.sampled_from(["rate", "increment", "angle"]), st.just("phases")),
        taus=_mostly(draw, good_taus, _bad_taus),
        estimator=_mostly(draw, st.sampled_from(["oavar", "avar"]), st.just("x")),
        workers=_mostly(draw, st.sampled_from([None, 1, 2]), st.sampled_from([0, -1, 1.5])),
    )
    dynamic = draw(st.booleans())
    if dynamic:
        kw.update(
            window=_mostly(draw, st.integers(max(2, n // 2), max(2, n)), _bad_count),
            hop=_mostly(draw, st.integers(1, max(1, n + 3)), _bad_count),
            method=_mostly(draw, st.sampled_from(["fast", "naive"]), st.just("?")),
            max_memory=_mostly(draw, st.sampled_from([None, 1e9]), st.sampled_from([1, 100, 0, -1, math.nan])),
        )
    return dynamic, x, kw


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(_calls())
def test_fuzz_only_allanite_errors(call):
    dynamic, x, kw = call
    fs = kw.pop("fs")
    try:
        r = (allanite.davar if dynamic else allanite.avar)(x, fs, **kw)
    except AllaniteError as exc:
        assert str(exc)  # a message, always
        event(f"{type(exc).__name__}")
        return
    event("success, " + ("davar" if dynamic else "avar"))
    arr = np.asarray(x)
    n = arr.shape[0] - (1 if kw["input"] == "angle" else 0)
    axes = arr.shape[1] if arr.ndim == 2 else None
    t = r.tau.size
    assert t >= 1 and r.m.shape == r.n.shape == r.tau.shape == (t,)
    assert np.all(np.diff(r.m) > 0) and r.m[0] >= 1
    assert np.array_equal(r.tau, r.m / float(fs))
    assert np.all(r.n >= 1)
    assert np.all(np.isfinite(r.avar)) and np.all(r.avar >= 0)
    assert r.n_samples == n
    if dynamic:
        j = (n - r.window) // r.hop + 1
        assert r.m[-1] <= r.window // 2
        assert r.avar.shape == ((t, j) if axes is None else (axes, t, j))
        assert r.t.shape == (j,)
    else:
        assert r.m[-1] <= n // 2
        assert r.avar.shape == ((t,) if axes is None else (axes, t))


# --------------------------------------------------------------------------------------------------
# Known gaps: inputs that escape as something other than an AllaniteError (library bugs)
# --------------------------------------------------------------------------------------------------


def _gap(call, reason):
    return pytest.param(call, marks=pytest.mark.xfail(strict=True, raises=AssertionError, reason=reason))


def _expect_allanite_error(call):
    try:
        call()
    except AllaniteError:
        return
    except Exception as exc:  # noqa: BLE001 — the point is to see which type escapes
        raise AssertionError(f"{type(exc).__name__} escaped instead of an AllaniteError: {exc}") from exc
    raise AssertionError("no error at all")


_Y = np.linspace(0.0, 1.0, 100) ** 2


@pytest.mark.parametrize(
    "call",
    [
        lambda: allanite.avar(_Y, 1.0, workers=2**64),
        lambda: allanite.tau_grid(1000, 1.0, "exp", tau_min=math.nan),
        lambda: allanite.tau_grid(1000, 1.0, "exp", tau_min=math.inf),
        lambda: allanite.tau_grid(1000, 1.0, "exp", tau_min=[2.0]),
        lambda: allanite.tau_grid(1000, 1.0, "exp", tau_min="2"),
        lambda: allanite.tau_grid(1000, 1.0, "exp", growth="abc"),
        lambda: allanite.tau_grid(1000, 1.0, "exp", growth="2"),
        lambda: allanite.avar(_Y, 1e-320),
    ],
    ids=[
        "workers=2**64",
        "tau_min=nan",
        "tau_min=inf",
        "tau_min=list",
        "tau_min=str",
        "growth=str",
        "growth=numeric-str",
        "fs=subnormal",
    ],
)
def test_formerly_escaping_inputs_raise_allanite_errors(call):
    _expect_allanite_error(call)


@pytest.mark.parametrize("hop", [2**63, 2**64, 1e30])
def test_hop_beyond_the_record_gives_one_window(hop):
    d = allanite.davar(_Y, 1.0, window=10, hop=hop)
    assert d.avar.shape[-1] == 1
    ref = allanite.avar(_Y[:10], 1.0, taus=d.tau)
    np.testing.assert_allclose(d.avar[:, 0], ref.avar, rtol=1e-12)


def test_huge_budget_and_tiny_growth_are_valid():
    assert allanite.davar(_Y, 1.0, window=10, max_memory=10**30).avar.shape[-1] == 91
    # growth so close to 1 that every m appears: the grid is every m up to n // 9, computed directly
    np.testing.assert_array_equal(allanite.tau_grid(1000, 1.0, "exp", growth=1 + 1e-15), np.arange(1, 112))


def test_huge_tau_is_reported_as_too_long(y):
    with pytest.raises(ParameterError, match=r"too long"):
        allanite.avar(y, 1.0, taus=[1e19])


def test_budget_below_one_window_says_so_instead_of_suggesting_a_hop():
    # One window of 50 τ (taus="all" on a 100-sample window) needs 400 bytes: no hop fits 50.
    with pytest.raises(MemoryBudgetError, match=r"even one window \(400 bytes\) does not fit: use fewer τ") as e:
        allanite.davar(np.zeros(1_000), 1.0, window=100, hop=1, taus="all", max_memory=50)
    assert "hop ≥" not in str(e.value)


def test_tiny_fs_gives_finite_tau_or_an_error(y):
    try:
        r = allanite.avar(y, 1e-320)
    except AllaniteError:
        return
    assert np.all(np.isfinite(r.tau))
