"""``fit`` and ``refine`` on an accelerometer's samples in its own unit (r9accfit). ``build_report(unit="m/s^2")``
took the unit, but ``fit`` and ``refine`` refused it with a ParameterError: a Python user got no velocity random
walk (m/s/√h), bias instability (µg) or acceleration random walk (m/s/h^1.5). The coefficients stay in base form
(the samples' unit and seconds, as for a gyro); ``Coefficient.ieee`` holds the accelerometer's report units."""

from __future__ import annotations

import numpy as np
import pytest

import allanite
from allanite.errors import ParameterError
from allanite.model.refinement import loop
from allanite.units import (
    STANDARD_GRAVITY,
    accel_unit_name,
    adev_unit_label,
    check_sensor_unit,
    coefficient_unit,
    report_unit,
)

FS = 100.0
N_ACC = 2e-3  # m/s²·√s: a velocity random walk of 0.12 m/s/√h
VRW = 60.0 * N_ACC  # m/s/√h


def _white(n=100_000, seed=5):
    """White acceleration noise of velocity random walk N_ACC, in m/s² (plus gravity: a constant, no noise)."""
    return allanite.simulate(n, FS, N=N_ACC, seed=seed) + STANDARD_GRAVITY


def _inside(c, truth, k=3.0):
    """``truth`` within the 68.3 % interval (report units) widened ``k`` times about the value (k = 3: ≈ 3σ)."""
    v, (lo, hi) = c.ieee, c.ieee_ci
    return v - k * (v - lo) <= truth <= v + k * (hi - v)


@pytest.mark.parametrize(("unit", "scale", "base"), [("m/s^2", 1.0, "m/s^1.5"), ("g", 1 / STANDARD_GRAVITY, "g·√s")])
def test_fit_gives_the_velocity_random_walk_in_m_s_per_root_hour(unit, scale, base):
    x = _white() * scale
    f = allanite.fit(allanite.avar(x, FS), terms=("N", "B", "K"), unit=unit)
    n, b, k = (f.coefficients[t] for t in "NBK")
    assert (n.ieee_unit, b.ieee_unit, k.ieee_unit) == ("m/s/√h", "µg", "m/s/h^1.5")
    assert n.unit == base  # base form: the samples' unit and seconds
    assert n.value == pytest.approx(N_ACC * scale, rel=0.03)
    assert n.ieee == pytest.approx(VRW, rel=0.03) and _inside(n, VRW), n
    assert n.ieee == pytest.approx(60.0 * n.value / scale)  # the base form's factor to m/s/√h
    # white noise: no bias instability, and its interval's upper end is small (tens of µg at most)
    assert b.ieee_ci[0] == 0.0 and b.ieee_ci[1] < 50.0, b
    text = repr(f)
    assert "m/s/√h" in text and "µg" in text
    table = f._summary().tables[0]
    assert "accelerometer units [interval]" in table.header and "IEEE-952 [interval]" not in table.header


def test_the_same_samples_in_g_and_in_m_s2_give_the_same_report_units():
    x = _white(40_000, seed=9)
    fm = allanite.fit(allanite.avar(x, FS), terms=("N", "B"), unit="m/s^2")
    fg = allanite.fit(allanite.avar(x / STANDARD_GRAVITY, FS), terms=("N", "B"), unit="g")
    fmg = allanite.fit(allanite.avar(x / STANDARD_GRAVITY * 1e3, FS), terms=("N", "B"), unit="mg")
    for t in "NB":
        assert fg.coefficients[t].ieee == pytest.approx(fm.coefficients[t].ieee, rel=1e-6, abs=1e-9)
        assert fmg.coefficients[t].ieee == pytest.approx(fm.coefficients[t].ieee, rel=1e-6, abs=1e-9)
        assert fg.coefficients[t].ieee_ci[1] == pytest.approx(fm.coefficients[t].ieee_ci[1], rel=1e-6)


def test_a_gyro_unit_keeps_ieee_952():
    y = allanite.simulate(20_000, FS, N=1e-3, seed=2)
    f = allanite.fit(allanite.avar(y, FS), terms=("N",), unit="deg/s")
    assert f.coefficients["N"].ieee_unit == "°/√h"
    assert "IEEE-952 [interval]" in f._summary().tables[0].header


def test_a_dynamic_fit_in_an_accelerometer_unit():
    x = _white(30_000, seed=4)
    dyn = allanite.davar(x, FS, window=10_000, hop=5_000)
    s = allanite.fit(dyn, terms=("N",), unit="m/s^2")
    assert s.ieee_units == {"N": "m/s/√h"}
    assert np.allclose(s.ieee["N"], 60.0 * np.asarray(s.values["N"]))
    assert np.all(np.abs(s.ieee["N"] / VRW - 1.0) < 0.1), s.ieee["N"]
    fr = allanite.frames(x / STANDARD_GRAVITY, FS, frame=50.0, terms=("N",), unit="g")  # its intervals convert too
    lo, hi = fr.intervals()
    assert fr.units() == {"N": "m/s/√h"} and np.all((lo["N"] < fr.values()["N"]) & (fr.values()["N"] < hi["N"]))
    assert np.all(lo["N"] < VRW * 1.3) and np.all(hi["N"] > VRW / 1.3)


def test_refine_takes_an_accelerometer_unit_and_reports_in_it():
    x = _white(20_000, seed=11)
    r = allanite.refine(x, FS, unit="m/s^2", progress=False)
    n = r.fit.coefficients["N"]
    assert n.ieee_unit == "m/s/√h" and _inside(n, VRW), n
    text = r.report()
    assert "m/s/√h" in text and "µg" in text and "m/s/h^1.5" in text
    assert "°/√h" not in text


def test_units_of_either_sensor():
    assert [accel_unit_name(u) for u in ("m/s²", "G", "mg", "µg", "deg/s", None, 3)] == [
        "m/s^2",
        "g",
        "mg",
        "ug",
        None,
        None,
        None,
    ]
    assert check_sensor_unit("mg") == "mg" and check_sensor_unit("rad/s") is None
    assert report_unit("B", 2e-5, "g") == (pytest.approx(20.0), "µg")
    assert report_unit("N", 0.0025, "deg/s") == (pytest.approx(0.15), "°/√h")
    assert [coefficient_unit(t, "m/s^2") for t in "QNBKR"] == ["m/s", "m/s^1.5", "m/s²", "m/s^2.5", "m/s³"]
    assert coefficient_unit("K", "ug") == "µg/√s"
    assert adev_unit_label("m/s^2") == "m/s²" and adev_unit_label("mg") == "mg"


def test_an_unknown_unit_names_both_sensors_units(monkeypatch):
    y = np.zeros(1000)
    r = allanite.avar(_white(5_000), FS)
    msg = r"unknown unit 'uT'; allowed rate units: deg/s.*\(a gyro's\), or m/s\^2, mm/s\^2, g, mg, ug \(an acc"
    with pytest.raises(ParameterError, match=msg):
        allanite.fit(r, unit="uT")
    monkeypatch.setattr(loop, "inputs", lambda *_a, **_k: pytest.fail("refine worked before checking its unit"))
    with pytest.raises(ParameterError, match=msg):
        allanite.refine(y, FS, unit="uT", progress=False)
    with pytest.raises(ParameterError, match=r"unit 'g' is an accelerometer's.*input='rate'.*got input='increment'"):
        allanite.refine(y, FS, unit="g", input="increment", progress=False)


def test_to_kalibr_takes_the_accelerometer_unit_the_fits_carry(tmp_path):
    yaml = pytest.importorskip("yaml")
    gyro = allanite.fit(allanite.avar(allanite.simulate(40_000, FS, N=1e-3, K=1e-5, seed=3), FS), unit="deg/s")
    a = allanite.avar(allanite.simulate(40_000, FS, N=N_ACC, K=1e-4, seed=6) / STANDARD_GRAVITY, FS)  # in g
    carried, bare = allanite.fit(a, terms=("N", "K"), unit="g"), allanite.fit(a, terms=("N", "K"))
    # the fits' own "g": before, to_kalibr took m/s² unless told, 9.8× too small
    p1 = allanite.to_kalibr(tmp_path / "a.yaml", gyro=gyro, accel=carried, update_rate=FS)
    p2 = allanite.to_kalibr(tmp_path / "b.yaml", gyro=gyro, accel=bare, update_rate=FS, accel_unit="g")
    y1, y2 = (yaml.safe_load(p.read_text(encoding="utf-8")) for p in (p1, p2))
    assert y1["accelerometer_noise_density"] == y2["accelerometer_noise_density"]
    assert y1["accelerometer_noise_density"] == pytest.approx(N_ACC, rel=0.05)
    with pytest.raises(
        ParameterError, match=r"accel_unit='m/s\^2', but the accelerometer fits were made with unit='g'"
    ):
        allanite.to_kalibr(tmp_path / "c.yaml", gyro=gyro, accel=carried, update_rate=FS, accel_unit="m/s^2")
    with pytest.raises(ParameterError, match=r"carry the unit 'deg/s', not an accelerometer's"):
        allanite.to_kalibr(tmp_path / "d.yaml", gyro=gyro, accel=gyro, update_rate=FS)
