"""The deviation family through the public API (``avar(estimator=...)``, ``davar(estimator="ohvar")``,
confidence intervals): equal to the plain NumPy twins, the NBS14 values, and refused where it must be.
The kernels themselves are checked against every Stable32 table in tests/test_deviations_core.py."""

from __future__ import annotations

import numpy as np
import pytest

import allanite
import twins_deviations as T

NBS14_9 = np.array([892, 809, 823, 798, 671, 644, 883, 903, 677], float)


@pytest.mark.parametrize(
    "estimator, expected",
    [
        ("mvar", (91.22945, 74.78849)),
        ("hvar", (70.80607, 116.7980)),
        ("tvar", (52.67135, 86.35831)),
        ("totvar", (91.22945, 93.90379)),
    ],
)
def test_nbs14_nine_point_set(estimator, expected):
    r = allanite.avar(NBS14_9, 1.0, estimator=estimator, taus=[1, 2])
    np.testing.assert_allclose(r.adev, expected, rtol=6e-7)


TWINS = {
    "mvar": T.mvar,
    "hvar": T.hvar,
    "ohvar": T.ohvar,
    "totvar": T.totvar,
    "mtotvar": T.mtotvar,
    "htotvar": T.htotvar,
}


@pytest.mark.parametrize("estimator", sorted(TWINS) + ["tvar", "ttotvar", "mtie", "tierms"])
def test_api_equals_the_twins(estimator):
    fs = 4.0
    y = np.random.default_rng(7).normal(size=600) + 3.0
    taus = np.array([1, 2, 3, 5, 8, 20, 50]) / fs
    r = allanite.avar(y, fs, estimator=estimator, taus=taus)
    if estimator in TWINS:
        twin = [TWINS[estimator](y, int(m)) for m in r.m]
    elif estimator == "tvar":
        twin = [T.tvar(y, int(m), 1.0 / fs) for m in r.m]
    elif estimator == "ttotvar":
        twin = [T.ttotvar(y, int(m), 1.0 / fs) for m in r.m]
    else:
        x = np.concatenate(([0.0], np.cumsum(y) / fs))
        twin = [(T.mtie if estimator == "mtie" else T.tierms)(x, int(m)) ** 2 for m in r.m]
    np.testing.assert_allclose(r.avar, twin, rtol=1e-9)
    assert r.estimator == estimator and r.n.shape == r.m.shape


def test_dynamic_hadamard_equals_the_static_one_per_window_and_ignores_a_ramp():
    rng = np.random.default_rng(8)
    y = rng.normal(size=5_000)
    d = allanite.davar(y, 10.0, window=1_000, hop=250, estimator="ohvar", taus="octave")
    for j in (0, 7, d.t.size - 1):
        s = allanite.avar(y[j * 250 : j * 250 + 1_000], 10.0, estimator="ohvar", taus=d.tau)
        np.testing.assert_allclose(d.avar[:, j], s.avar, rtol=1e-10)
    ramp = y + 1e-2 * np.arange(y.size)  # a rate ramp: Allan grows with τ², Hadamard does not see it
    h = allanite.davar(ramp, 10.0, window=1_000, hop=250, estimator="ohvar", taus="octave")
    np.testing.assert_allclose(h.avar, d.avar, rtol=1e-6)
    a = allanite.davar(ramp, 10.0, window=1_000, hop=250, taus=d.tau)
    assert np.all(a.avar[-1] > 10 * h.avar[-1])


def test_confidence_intervals_use_each_estimators_edf():
    y = np.random.default_rng(9).normal(size=20_000)
    for est in ("mvar", "ohvar", "hvar", "totvar", "htotvar", "mtotvar"):
        r = allanite.avar(y, 1.0, estimator=est, taus=[1, 4, 16, 64]).with_confidence(y)
        assert np.all(np.isfinite(r.edf)) and np.all(r.ci_low < r.avar) and np.all(r.avar < r.ci_high)
    with pytest.raises(allanite.ParameterError, match="confidence intervals are implemented for"):
        allanite.avar(y, 1.0, estimator="mtie", taus=[1, 4]).with_confidence(y)


def test_ranges_and_names_are_checked():
    y = np.random.default_rng(10).normal(size=300)
    with pytest.raises(allanite.ParameterError, match=r"beyond mvar's range for 300 samples: m ≤ 100"):
        allanite.avar(y, 1.0, estimator="mvar", taus=[101.0])
    with pytest.raises(allanite.ParameterError, match="unknown estimator 'mdev'; allowed: 'oavar', 'avar'"):
        allanite.avar(y, 1.0, estimator="mdev")
    with pytest.raises(allanite.ParameterError, match="unknown estimator 'mvar'; allowed: 'oavar', 'avar', .*'ohvar'"):
        allanite.davar(y, 1.0, window=100, estimator="mvar")
    with pytest.raises(allanite.ParameterError, match="fit supports the estimators"):
        allanite.fit(allanite.avar(y, 1.0, estimator="hvar"))
