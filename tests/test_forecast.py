"""allanite.forecast: GM(1,1) against textbook oracles, its numerics, the improved model's steps,
the baselines on series whose forecasts are known by hand, honest scoring, and bad input."""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from allanite.errors import InputError, ParameterError
from allanite.forecast import (
    GM11,
    BuildMean,
    Holt,
    ImprovedGM11,
    LinearTrend,
    Persistence,
    accuracy,
    c_grade,
    joint_grade,
    level_ratio_test,
    score,
    split,
)

CLASSIC = (2.874, 3.278, 3.337, 3.390, 3.679)
ROAD = (71.1, 72.4, 72.4, 72.1, 71.4, 72.0, 71.6)


def _reference_ab(x):
    """(a, b) straight from paper 004 eq. 6, P = (BᵀB)⁻¹BᵀY, with plain Python sums."""
    x1 = [sum(x[: k + 1]) for k in range(len(x))]
    z = [0.5 * (x1[k] + x1[k - 1]) for k in range(1, len(x))]
    y = list(x[1:])
    m = len(z)
    szz, sz, szy, sy = sum(v * v for v in z), sum(z), sum(u * v for u, v in zip(z, y)), sum(y)
    # BᵀB = [[szz, -sz], [-sz, m]], BᵀY = [-szy, sy]
    det = szz * m - sz * sz
    a = (m * -szy + sz * sy) / det
    b = (sz * -szy + szz * sy) / det
    return a, b


# ---------------------------------------------------------------------------------------------- oracles


def test_classic_oracle():
    m = GM11(CLASSIC)
    assert m.a == pytest.approx(-0.037204, abs=5e-7)
    assert m.b == pytest.approx(3.065363, abs=5e-7)
    a, b = _reference_ab(CLASSIC)
    assert m.a == pytest.approx(a, rel=1e-12) and m.b == pytest.approx(b, rel=1e-12)
    np.testing.assert_allclose(m.fitted, [2.874, 3.2320, 3.3545, 3.4817, 3.6137], atol=5e-5)
    assert m.fitted[0] == CLASSIC[0]
    assert m.C == pytest.approx(0.2125, abs=5e-5)
    assert m.P == 1.0
    assert (m.c_grade, m.grade) == (1, "good")
    assert m.shift_applied == 0.0 and m.level_ratio.passed and m.notes == []


def test_road_noise_oracle():
    m = GM11(ROAD)
    assert m.a == pytest.approx(0.002344, abs=5e-7)
    assert m.b == pytest.approx(72.65727, abs=5e-6)
    a, b = _reference_ab(ROAD)
    assert m.a == pytest.approx(a, rel=1e-10) and m.b == pytest.approx(b, rel=1e-12)
    assert m.C == pytest.approx(0.481, abs=5e-4)
    assert m.P == pytest.approx(6 / 7)
    assert (m.c_grade, m.grade) == (2, "qualified")


def test_which_conventions_reproduce_the_oracles():
    # With k = 1 counted, S1 and S2 run over the same n, so C does not depend on the SD convention, and
    # P does not either for these two series: both conventions reproduce both oracles.
    for series, C, P in ((CLASSIC, 0.2125, 1.0), (ROAD, 0.481, 6 / 7)):
        for sd in ("population", "sample"):
            m = GM11(series, sd=sd, include_first=True)
            assert m.C == pytest.approx(C, abs=5e-4) and m.P == pytest.approx(P)
    # Leaving k = 1 out (paper 004's rule) does not reproduce them.
    assert GM11(CLASSIC, include_first=False).C == pytest.approx(0.39857, abs=5e-5)
    assert GM11(ROAD, include_first=False).C == pytest.approx(0.64289, abs=5e-5)
    # ... and there the SD convention changes P through its threshold 0.6745·S1: 4 of 6 vs 5 of 6.
    assert GM11(ROAD, include_first=False, sd="population").P == pytest.approx(4 / 6)
    assert GM11(ROAD, include_first=False, sd="sample").P == pytest.approx(5 / 6)


def test_forecast_continues_the_time_response():
    m = GM11(CLASSIC)
    a, b, x0 = m.a, m.b, CLASSIC[0]
    n = len(CLASSIC)
    naive = [(1 - math.exp(a)) * (x0 - b / a) * math.exp(-a * k) for k in range(n, n + 4)]
    np.testing.assert_allclose(m.predict(4), naive, rtol=1e-13)
    # the restored values are differences of the 1-AGO time response
    x1 = [(x0 - b / a) * math.exp(-a * k) + b / a for k in range(n + 4)]
    np.testing.assert_allclose(m.predict(4), np.diff(x1)[n - 1 :], rtol=1e-11)
    assert m.predict(0).shape == (0,)


def test_grades():
    assert [c_grade(c) for c in (0.0, 0.3499, 0.35, 0.4999, 0.5, 0.6499, 0.65, 3.0)] == [1, 1, 2, 2, 3, 3, 4, 4]
    assert joint_grade(0.3, 0.96) == "good"
    assert joint_grade(0.3, 0.95) == "qualified"  # P must exceed 0.95
    assert joint_grade(0.49, 0.81) == "qualified"
    assert joint_grade(0.6, 0.99) == "barely"
    assert joint_grade(0.6, 0.70) == "fail"
    assert joint_grade(0.7, 1.0) == "fail"


# ---------------------------------------------------------------------------------------------- numerics


def test_constant_series_a_to_zero():
    # a is (nearly) 0 here; the textbook form (1 − e^a)(x0 − b/a) is 0·∞-like and returns 0 or garbage.
    x = np.full(12, 5.0)
    m = GM11(x)
    assert abs(m.a) < 1e-14
    np.testing.assert_allclose(m.fitted, x, rtol=1e-13)
    np.testing.assert_allclose(m.predict(5), 5.0, rtol=1e-13)
    assert m.C == 0.0 and m.P == 1.0  # S1, S2 at round-off: a perfect fit by the documented rule
    assert accuracy(x, x + 1e-3 * np.arange(12)).C == math.inf


@pytest.mark.parametrize("slope", [1e-13, 1e-9, 1e-6])
def test_tiny_trend_stays_exact(slope):
    x = 3.0 * (1.0 + slope * np.arange(20))
    m = GM11(x)
    assert abs(m.a) < 10 * slope + 1e-14
    # a linear series is fitted by GM(1,1) to O(a²); the error must not blow up as a → 0
    np.testing.assert_allclose(m.fitted, x, rtol=1e-9)
    np.testing.assert_allclose(m.predict(3), 3.0 * (1.0 + slope * np.arange(20, 23)), rtol=1e-9)


def test_exponential_series_recovers_its_rate():
    # For x⁰(k) = c·e^{−αk}, GM(1,1) gives a = 2·tanh(α/2)… approximately α for small α.
    alpha = 0.05
    x = 7.0 * np.exp(-alpha * np.arange(15))
    m = GM11(x)
    assert m.a == pytest.approx(alpha, rel=1e-3)
    np.testing.assert_allclose(m.predict(3), 7.0 * np.exp(-alpha * np.arange(15, 18)), rtol=1e-3)


# ---------------------------------------------------------------------------------------------- level ratio


def test_level_ratio_shift():
    x = np.array([1.0, 2.0, 1.0, 2.0, 1.0, 2.0])
    lr = level_ratio_test(x)
    n = x.size
    assert (lr.low, lr.high) == pytest.approx((math.exp(-2 / (n + 1)), math.exp(2 / (n + 1))))
    assert not lr.passed and lr.failing.tolist() == [0, 1, 2, 3, 4]
    m = GM11(x)
    c = m.shift_applied
    assert c > 0 and "level-ratio test failed" in m.notes[0] and f"{c:.6g}" in m.notes[0]
    assert m.level_ratio_shifted.passed
    # the smallest such shift: one ratio sits on the 10 %-shrunk bound
    r = (x[:-1] + c) / (x[1:] + c)
    theta = 0.9 * 2 / (n + 1)
    assert np.max(np.abs(np.log(r))) == pytest.approx(theta, rel=1e-9)
    # outputs are in the original units: the shift is a translation of the model
    ref = GM11(x + c, shift=None)
    np.testing.assert_allclose(m.fitted, ref.fitted - c, rtol=1e-12)
    np.testing.assert_allclose(m.predict(3), ref.predict(3) - c, rtol=1e-12)
    assert m.fitted[0] == pytest.approx(x[0])
    # shift=None keeps the series and says the test failed
    raw = GM11(x, shift=None)
    assert raw.shift_applied == 0.0 and "not shifted" in raw.notes[0]
    # an explicit shift is used as given
    assert GM11(x, shift=3.0).shift_applied == 3.0


def test_nonpositive_values_with_permission_are_shifted():
    x = np.array([-1.0, 0.5, 1.0, 1.5, 2.0, 2.5])
    m = GM11(x, allow_nonpositive=True)
    assert m.shift_applied > 1.0 and m.level_ratio_shifted.passed
    assert np.all(np.isfinite(m.predict(4)))
    assert m.fitted[0] == pytest.approx(-1.0)


# ---------------------------------------------------------------------------------------------- baselines


def test_baselines_on_a_line():
    x = 2.0 + 0.5 * np.arange(10)
    lt = LinearTrend(x)
    assert (lt.slope, lt.intercept) == pytest.approx((0.5, 2.0))
    np.testing.assert_allclose(lt.predict(3), [7.0, 7.5, 8.0])
    assert lt.C == pytest.approx(0.0, abs=1e-14) and lt.grade == "good"
    p = Persistence(x)
    np.testing.assert_array_equal(p.predict(3), [6.5, 6.5, 6.5])
    np.testing.assert_array_equal(p.fitted, np.r_[2.0, x[:-1]])
    bm = BuildMean(x)
    np.testing.assert_allclose(bm.predict(2), [4.25, 4.25])
    assert bm.C == pytest.approx(1.0)  # a constant explains nothing of the spread
    h = Holt(x)  # a line is followed exactly whatever α, β (the trend starts at x1 − x0)
    np.testing.assert_allclose(h.predict(3), [7.0, 7.5, 8.0], rtol=1e-12)
    np.testing.assert_allclose(h.fitted, x, rtol=1e-12)


def test_holt_by_hand():
    h = Holt([1.0, 2.0, 4.0, 7.0], alpha=0.5, beta=0.5)
    # ℓ, b: (1, 1) → (2, 1) → (3.5, 1.25) → (5.875, 1.8125)
    np.testing.assert_allclose(h.fitted, [1.0, 2.0, 3.0, 4.75])
    assert (h.level, h.trend) == pytest.approx((5.875, 1.8125))
    np.testing.assert_allclose(h.predict(2), [7.6875, 9.5])


def test_holt_fits_alpha_beta_by_least_squares():
    rng = np.random.default_rng(3)
    x = 10 + 0.2 * np.arange(40) + rng.standard_normal(40)
    h = Holt(x)

    def sse(a, b):
        f = Holt(x, alpha=a, beta=b).fitted
        return np.sum((x[1:] - f[1:]) ** 2)

    best = sse(h.alpha, h.beta)
    grid = np.linspace(0, 1, 21)
    assert best <= min(sse(a, b) for a in grid for b in grid) + 1e-9
    assert 0 <= h.alpha <= 1 and 0 <= h.beta <= 1


# ---------------------------------------------------------------------------------------------- improved


def _drifting(n=60, seed=0, noise=0.03):
    rng = np.random.default_rng(seed)
    k = np.arange(n)
    return 1.0 + 0.3 * (1 - np.exp(-k / 25.0)) + noise * rng.standard_normal(n)


def test_improved_with_every_step_off_is_gm11():
    x = _drifting()
    imp = ImprovedGM11(x, detect=False, smooth=False, metabolic=False, residual=False)
    ref = GM11(x)
    np.testing.assert_array_equal(imp.processed, x)
    np.testing.assert_allclose(imp.fitted, ref.fitted, rtol=1e-14)
    np.testing.assert_allclose(imp.predict(10), ref.predict(10), rtol=1e-14)
    assert imp.C == ref.C


def test_detect_replaces_a_spike():
    x = _drifting()
    bad = x.copy()
    bad[23] += 0.8
    on = ImprovedGM11(bad, detect=True, smooth=False, metabolic=False, residual=False)
    assert on.detection.bad.tolist() == [23] and on.detection.breaks.size == 0
    assert on.processed[23] == pytest.approx(0.5 * (x[22] + x[24]))
    np.testing.assert_array_equal(np.delete(on.processed, 23), np.delete(bad, 23))
    off = ImprovedGM11(bad, detect=False, smooth=False, metabolic=False, residual=False)
    assert off.processed[23] == bad[23] and off.detection is None
    # no false alarm on the clean series
    clean = ImprovedGM11(x, smooth=False, metabolic=False, residual=False)
    assert clean.detection.bad.size == 0 and clean.detection.breaks.size == 0


def test_detect_aligns_a_break():
    x = _drifting(noise=0.01)
    stepped = x.copy()
    stepped[35:] += 0.5
    m = ImprovedGM11(stepped, smooth=False, metabolic=False, residual=False)
    assert m.detection.breaks.tolist() == [34]
    assert m.detection.steps[0] == pytest.approx(0.5, abs=0.05)
    # the older part moved up by the step, the newer part untouched
    np.testing.assert_array_equal(m.processed[35:], stepped[35:])
    np.testing.assert_allclose(m.processed[:35] - stepped[:35], m.detection.steps[0])
    assert "breaks after [34]" in " ".join(m.notes)


def test_smooth_removes_roughness():
    x = _drifting(noise=0.05)
    m = ImprovedGM11(x, detect=False, smooth=True, metabolic=False, residual=False)

    def rough(v):
        return float(np.sum(np.diff(v, 2) ** 2))

    assert rough(m.processed) < 0.2 * rough(x)
    assert np.max(np.abs(m.processed - x)) < 0.2  # it smooths, it does not replace
    assert m.accuracy_processed.C < m.accuracy.C  # in-sample, the smoothed target is easier


def test_metabolic_refits_with_its_own_predictions():
    x = _drifting()
    off = ImprovedGM11(x, detect=False, smooth=False, metabolic=False, residual=False)
    on = ImprovedGM11(x, detect=False, smooth=False, metabolic=True, residual=False)
    f_on, f_off = on.predict(8), off.predict(8)
    assert f_on[0] == pytest.approx(f_off[0], rel=1e-14)  # the first step comes from the same model
    assert np.max(np.abs(f_on[1:] - f_off[1:])) > 1e-6
    # by hand: append the prediction, drop the oldest value, re-fit
    w = x.copy()
    for j in range(3):
        p = GM11(w).predict(1)[0]
        assert f_on[j] == pytest.approx(p, rel=1e-12)
        w = np.append(w[1:], p)


def test_residual_correction_from_index():
    x = _drifting(noise=0.0) + 0.02 * np.sin(np.arange(60) / 6.0)
    base = ImprovedGM11(x, detect=False, smooth=False, metabolic=False, residual=False)
    q = np.cumsum(x + base.model.shift_applied) - base.model._x1hat(np.arange(60))
    # this series: 1-AGO residuals negative to index 35, positive 36..58, the last one negative again
    sign = np.sign(q).astype(int)
    assert sign[1:36].tolist() == [-1] * 35 and sign[36:59].tolist() == [1] * 23 and sign[59] == -1
    i = 40
    m = ImprovedGM11(x, detect=False, smooth=False, metabolic=False, residual=True, residual_from=i)
    assert m._rc.applied and (m._rc.i, m._rc.end) == (40, 59)
    np.testing.assert_allclose(m._rc.model.series, q[40:59], rtol=1e-12)  # a GM(1,1) of sign·q
    np.testing.assert_array_equal(m.fitted[:i], base.fitted[:i])  # δ(k − i): nothing before i
    assert np.max(np.abs(m.fitted[i:] - base.fitted[i:])) > 1e-6
    assert np.max(np.abs(m.predict(5) - base.predict(5))) > 1e-6
    # x̂¹ + q̂ restored by differencing
    qhat = m._rc.model.fitted
    np.testing.assert_allclose(m.fitted[41:59] - base.fitted[41:59], np.diff(qhat), rtol=1e-9, atol=1e-15)
    # it shrinks the 1-AGO residual it models (whether that helps x̂⁰ is a separate matter: here the
    # in-sample C goes from 0.261 to 0.293, the arch of q from 40 on is no exponential)
    assert np.sum((q[40:59] - qhat) ** 2) < 0.5 * np.sum(q[40:59] ** 2)
    auto = ImprovedGM11(x, detect=False, smooth=False, metabolic=False, residual=True)
    assert (auto._rc.i, auto._rc.end) == (36, 59)
    with pytest.raises(ParameterError, match=r"residual_from = 1: the residuals from there change sign"):
        ImprovedGM11(x, detect=False, smooth=False, metabolic=False, residual_from=1)
    with pytest.raises(ParameterError, match=r"residual_from = 58 must be 'auto' or an index in 1\.\.54 \(6 residuals"):
        ImprovedGM11(x, detect=False, smooth=False, metabolic=False, residual_from=58)


def test_residual_guards():
    x = _drifting(noise=0.0) + 0.02 * np.sin(np.arange(60) / 6.0)
    base = ImprovedGM11(x, detect=False, smooth=False, metabolic=False, residual=False)
    m = ImprovedGM11(x, detect=False, smooth=False, metabolic=False, residual_from=40, residual_max_a=1e-6)
    assert not m._rc.applied
    assert "residual model |a'| = " in " ".join(m.notes) and "exceeds residual_max_a = 1e-06" in " ".join(m.notes)
    np.testing.assert_array_equal(m.fitted, base.fitted)
    # the run 36..58 has 23 residuals: a minimum of 24 rules it out
    long = ImprovedGM11(x, detect=False, smooth=False, metabolic=False, residual_min_len=24)
    assert not long._rc.applied and "no same-sign run of 24 or more" in " ".join(long.notes)
    with pytest.raises(ParameterError, match=r"residual_min_len = 3 must be an integer >= 4"):
        ImprovedGM11(x, residual_min_len=3)
    with pytest.raises(ParameterError, match=r"residual_max_a = -1\.0 must be a positive number"):
        ImprovedGM11(x, residual_max_a=-1.0)


def test_residual_skipped_is_said():
    x = np.array([1.0, 1.2, 1.1, 1.3, 1.2, 1.4, 1.3, 1.5])  # 1-AGO residuals alternate in sign
    m = ImprovedGM11(x, detect=False, smooth=False, metabolic=False, residual=True)
    assert not m._rc.applied
    assert "residual correction skipped: no same-sign run of 6" in " ".join(m.notes)
    np.testing.assert_allclose(m.fitted, GM11(x).fitted, rtol=1e-14)


# ---------------------------------------------------------------------------------------------- scoring


def test_score_is_against_raw_check_values():
    x = _drifting(90, noise=0.04)
    b, c = split(x, 60, 30)
    s = score(functools.partial(ImprovedGM11, metabolic=False, residual=False), b, c)
    want = accuracy(c, s.model.predict(30))
    assert s.honest == want
    # paper rule: a-posteriori values over build (against the smoothed series the model saw) + check,
    # x⁰(1) left out
    paper = accuracy(np.r_[s.model.processed, c], np.r_[s.model.fitted, s.forecast], include_first=False)
    assert s.paper_rule == paper
    assert s.differs
    assert s.rmse == pytest.approx(np.sqrt(np.mean((c - s.forecast) ** 2)))
    assert s.bias == pytest.approx(np.mean(c - s.forecast))


def test_constant_forecasts_have_c_one():
    x = _drifting(90, noise=0.04)
    b, c = split(x, 60, 30)
    for m in (Persistence, BuildMean):
        s = score(m, b, c)
        assert s.honest.C == pytest.approx(1.0, rel=1e-12)  # C ignores a constant offset ...
    assert score(BuildMean, b, c).bias > score(Persistence, b, c).bias  # ... bias does not


def test_sample_sd_in_score():
    x = _drifting(90, noise=0.04)
    b, c = split(x, 60, 30)
    s = score(LinearTrend, b, c, sd="sample")
    assert s.honest.sd == "sample"
    e = c - s.forecast
    assert s.honest.C == pytest.approx(np.std(e, ddof=1) / np.std(c, ddof=1))


# ---------------------------------------------------------------------------------------------- bad input


def test_too_short():
    with pytest.raises(InputError, match=r"series has 3 values; at least 4 are needed"):
        GM11([1.0, 2.0, 3.0])
    with pytest.raises(InputError, match=r"series has 3 values"):
        ImprovedGM11([1.0, 2.0, 3.0])


def test_nonpositive_names_the_value_and_offers_the_shift():
    with pytest.raises(InputError, match=r"series\[2\] = 0\.0 is not positive .*allow_nonpositive=True"):
        GM11([1.0, 2.0, 0.0, 3.0, 4.0])
    with pytest.raises(InputError, match=r"series\[0\] = -1\.0 is not positive"):
        ImprovedGM11([-1.0, 2.0, 3.0, 4.0, 5.0])
    with pytest.raises(ParameterError, match=r"shift = -1\.5 leaves min\(series\) \+ shift = -0\.5 <= 0"):
        GM11([1.0, 2.0, 3.0, 4.0], shift=-1.5)


def test_nan_and_inf():
    with pytest.raises(InputError, match=r"series\[1\] = nan is not finite"):
        GM11([1.0, float("nan"), 3.0, 4.0])
    with pytest.raises(InputError, match=r"series\[3\] = inf is not finite"):
        Holt([1.0, 2.0, 3.0, float("inf")])
    with pytest.raises(InputError, match=r"must be 1-D, got shape \(2, 3\)"):
        GM11(np.ones((2, 3)))


def test_split_that_does_not_fit():
    x = np.arange(1.0, 91.0)
    with pytest.raises(ParameterError, match=r"build \+ check = 60 \+ 40 = 100 exceeds the series length \(90\)"):
        split(x, 60, 40)
    with pytest.raises(ParameterError, match=r"build = 3 is too small"):
        split(x, 3, 30)
    with pytest.raises(ParameterError, match=r"check = 1 is too small"):
        split(x, 60, 1)
    with pytest.raises(ParameterError, match=r"build = 60\.0 must be an integer"):
        split(x, 60.0, 30)


def test_bad_options():
    with pytest.raises(ParameterError, match=r"sd = 'biased' is not allowed"):
        GM11(CLASSIC, sd="biased")
    with pytest.raises(ParameterError, match=r"shift = 'yes' is not allowed"):
        GM11(CLASSIC, shift="yes")
    with pytest.raises(ParameterError, match=r"h = -1 must be a non-negative integer"):
        GM11(CLASSIC).predict(-1)
    with pytest.raises(ParameterError, match=r"alpha = 1\.5 must lie in \[0, 1\]"):
        Holt(CLASSIC, alpha=1.5)
    with pytest.raises(ParameterError, match=r"wavelet = 'nope' is not a PyWavelets discrete wavelet"):
        ImprovedGM11(CLASSIC, wavelet="nope")
    with pytest.raises(ParameterError, match=r"detect_threshold = 0 must be a positive number"):
        ImprovedGM11(CLASSIC, detect_threshold=0)
    with pytest.raises(InputError, match=r"actual has 5 values but predicted has 4"):
        accuracy(CLASSIC, CLASSIC[:4])


# ---------------------------------------------------------------------------------------------- bench


def _bench():
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "benches" / "paper004_forecast.py"
    if not path.is_file():
        pytest.skip(f"{path} not found")
    spec = importlib.util.spec_from_file_location("paper004_forecast", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_bench_table_on_a_steady_drift():
    bench = _bench()
    coeffs, truth = bench.synthetic_coefficients(0, scenario="steady")
    coeffs["Zero"] = np.r_[np.full(10, 0.0), np.ones(80)]  # a term the fit did not resolve
    table = bench.forecast_table(coeffs, truth=truth)
    assert table["terms"] == ["Q", "N", "B", "K", "R"]
    assert "not forecastable" in table["skipped"]["Zero"]
    cells = table["cells"]
    assert set(cells) == set(bench.default_methods()) | {"true curve (oracle)"}
    n = {m: cells[m]["N"] for m in cells}
    # a constant forecast explains none of the check spread; a trend follower explains some of it
    assert n["persistence"]["C"] == pytest.approx(1.0) and n["build mean"]["C"] == pytest.approx(1.0)
    assert n["linear trend"]["C"] < 0.6 and n["GM(1,1)"]["C"] < 0.6
    assert n["true curve (oracle)"]["C"] <= min(c["C"] for c in n.values()) + 0.05
    # the paper's rule, dominated by the in-sample build fit, flatters every trend method
    assert n["GM(1,1)"]["C_paper"] < 0.5 * n["GM(1,1)"]["C"]
    md = bench.to_markdown(table, title="t")
    assert md.count("| GM(1,1) |") == 4 and "Zero: 10 frame(s) at or below 0" in md
    with pytest.raises(ParameterError, match=r"build \+ check = 60 \+ 30 = 90 exceeds the series length \(50\)"):
        bench.forecast_table({"N": np.ones(50)})


def test_docstring_examples():
    import doctest

    import allanite.forecast as mod

    failures, tried = doctest.testmod(mod, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert tried > 0 and failures == 0


def test_overflowing_horizon_is_an_error():
    m = GM11(np.exp(0.5 * np.arange(8)), shift=None)  # a ≈ −0.5: e^{0.5k} overflows near k = 1420
    assert np.all(np.isfinite(m.predict(100)))
    with pytest.raises(ParameterError, match=r"h = 2000: the forecast overflows at step 14\d\d"):
        m.predict(2000)


def test_residual_on_series_adds_the_residual_model():
    x = _drifting(noise=0.0) + 0.02 * np.sin(np.arange(60) / 6.0)
    base = ImprovedGM11(x, detect=False, smooth=False, metabolic=False, residual=False)
    e = x - base.fitted
    m = ImprovedGM11(x, detect=False, smooth=False, metabolic=False, residual_on="series")
    rc = m._rc
    assert rc.applied and rc.on == "series"
    s = np.sign(e[rc.end - 1])
    assert np.all(s * e[rc.i : rc.end] > 0) and rc.end - rc.i >= 6
    qhat = s * np.r_[rc.model.fitted, rc.model.predict(60 - rc.end)]
    np.testing.assert_allclose(m.fitted[rc.i :] - base.fitted[rc.i :], qhat, rtol=1e-9)
    np.testing.assert_array_equal(m.fitted[: rc.i], base.fitted[: rc.i])


def test_short_series_is_not_smoothed_and_says_so():
    m = ImprovedGM11(CLASSIC)
    assert "series too short for sym4 smoothing; not smoothed" in m.notes
    np.testing.assert_allclose(m.processed, CLASSIC)
    assert np.all(np.isfinite(m.predict(3)))


def test_improved_overflowing_horizon_is_an_error():
    x = np.exp(0.3 * np.arange(12))
    m = ImprovedGM11(x, detect=False, smooth=False, residual=False, metabolic=False, shift=None)
    with pytest.raises(ParameterError, match=r"h = 3000: the forecast overflows at step 2373"):
        m.predict(3000)
