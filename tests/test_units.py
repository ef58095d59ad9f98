"""Units of samples and the IEEE-952 report units of Allan-model coefficients (allanite.units)."""

from __future__ import annotations

import doctest
import math

import numpy as np
import pytest

import allanite.units as units
from allanite import ParameterError
from allanite.units import adev_unit_label, convert, ieee952, parse_unit, rate_unit, to_deg_per_s

D2R = math.pi / 180.0


@pytest.mark.parametrize(
    "spelling, name, kind",
    [
        ("deg/s", "deg/s", "rate"),
        ("°/s", "deg/s", "rate"),
        ("dps", "deg/s", "rate"),
        ("DEG / SEC", "deg/s", "rate"),
        ("degrees/second", "deg/s", "rate"),
        ("rad/s", "rad/s", "rate"),
        ("rad/sec", "rad/s", "rate"),
        ("deg/h", "deg/h", "rate"),
        ("°/h", "deg/h", "rate"),
        ("dph", "deg/h", "rate"),
        ("deg/hr", "deg/h", "rate"),
        ("mrad/s", "mrad/s", "rate"),
        ("urad/s", "urad/s", "rate"),
        ("\u00b5rad/s", "urad/s", "rate"),
        ("\u03bcrad/s", "urad/s", "rate"),
        ("arcsec/s", "arcsec/s", "rate"),
        ("rpm", "rpm", "rate"),
        ("rev/s", "rev/s", "rate"),
        ("mdps", "mdeg/s", "rate"),
        ("deg", "deg", "angle"),
        ("°", "deg", "angle"),
        ("rad", "rad", "angle"),
        ("mrad", "mrad", "angle"),
        ("urad", "urad", "angle"),
        ("µrad", "urad", "angle"),
        ("arcsec", "arcsec", "angle"),
        ("arcmin", "arcmin", "angle"),
    ],
)
def test_parse_unit_aliases(spelling, name, kind):
    u = parse_unit(spelling)
    assert (u.name, u.kind) == (name, kind)
    assert str(u) == name
    assert parse_unit(u) is u


@pytest.mark.parametrize(
    "name, factor",
    [
        ("deg/s", 1.0),
        ("rad/s", 180 / math.pi),
        ("deg/h", 1 / 3600),
        ("mrad/s", 0.180 / math.pi),
        ("urad/s", 1.8e-4 / math.pi),
        ("arcsec/s", 1 / 3600),
        ("rpm", 6.0),
        ("rev/s", 360.0),
        ("deg", 1.0),
        ("rad", 180 / math.pi),
        ("mrad", 0.180 / math.pi),
        ("urad", 1.8e-4 / math.pi),
        ("arcsec", 1 / 3600),
        ("arcmin", 1 / 60),
    ],
)
def test_unit_factors_to_degrees(name, factor):
    assert parse_unit(name).factor == pytest.approx(factor, rel=1e-15)


def test_convert_rate_units():
    assert float(convert(math.pi, "rad/s", "deg/s")) == pytest.approx(180.0, rel=1e-15)
    assert float(convert(180.0, "deg/s", "rad/s")) == pytest.approx(math.pi, rel=1e-15)
    assert float(convert(1.0, "deg/s", "deg/h")) == pytest.approx(3600.0, rel=1e-15)
    assert float(convert(1.0, "rad/s", "urad/s")) == pytest.approx(1e6, rel=1e-15)
    assert float(convert(1.0, "arcsec/s", "deg/h")) == pytest.approx(1.0, rel=1e-15)
    assert float(convert(60.0, "rpm", "rev/s")) == pytest.approx(1.0, rel=1e-15)
    assert float(convert(1.0, "deg", "arcsec")) == pytest.approx(3600.0, rel=1e-15)
    assert float(convert(1.0, "mrad", "urad")) == pytest.approx(1000.0, rel=1e-15)
    x = np.array([0.5, -2.0, 4.0])
    np.testing.assert_allclose(convert(convert(x, "deg/s", "rad/s"), "rad/s", "deg/s"), x, rtol=1e-15)
    np.testing.assert_allclose(convert(x, "deg/s", "rad/s"), x * D2R, rtol=1e-15)


def test_convert_rejects_mixed_kinds():
    with pytest.raises(ParameterError, match=r"cannot convert rate unit 'deg/s' to angle unit 'deg'"):
        convert(1.0, "deg/s", "deg")


def test_to_deg_per_s():
    np.testing.assert_allclose(to_deg_per_s([3600.0, -7200.0], "deg/h"), [1.0, -2.0], rtol=1e-15)
    np.testing.assert_allclose(to_deg_per_s(np.array([1.0, 2.0]), "rad/s"), [180 / math.pi, 360 / math.pi], rtol=1e-15)
    out = to_deg_per_s([1, 2], "deg/s")
    assert out.dtype == np.float64 and out.tolist() == [1.0, 2.0]


def test_to_deg_per_s_needs_a_rate_unit():
    with pytest.raises(ParameterError, match=r"unit 'deg' is an angle unit, but a rate unit is needed.*rad/s"):
        to_deg_per_s([1.0], "deg")


@pytest.mark.parametrize("bad", ["furlong/fortnight", "deg/s/s", "", "g"])
def test_unknown_unit_lists_allowed(bad):
    with pytest.raises(
        ParameterError,
        match=rf"unknown unit {bad!r}; allowed rate units: deg/s, .*rad/s.*"
        rf"angle units: deg, .*arcsec",
    ):
        parse_unit(bad)


def test_unit_must_be_string():
    with pytest.raises(ParameterError, match=r"a unit must be a string such as 'deg/s', got 3"):
        parse_unit(3)


def test_parse_unit_kind_restriction():
    assert parse_unit("rad", kind="angle").name == "rad"
    with pytest.raises(
        ParameterError,
        match=r"unit 'rad/s' is a rate unit, but an angle unit is needed here; "
        r"allowed angle units: deg",
    ):
        parse_unit("rad/s", kind="angle")
    with pytest.raises(ParameterError, match=r"unknown unit kind 'speed'"):
        parse_unit("rad/s", kind="speed")


def test_rate_unit_of_angles():
    assert rate_unit("deg").name == "deg/s"
    assert rate_unit("urad").name == "urad/s"
    assert rate_unit("arcsec").name == "arcsec/s"
    assert rate_unit("rad/s").name == "rad/s"
    assert rate_unit("arcmin").factor == pytest.approx(1 / 60)  # arcmin/s, not in the table


# IEEE-952 factors (docs/FORMULAS.md §4.2), from °/s samples
@pytest.mark.parametrize(
    "term, to, factor, label",
    [
        ("N", None, 60.0, "°/√h"),  # 1 °/√s = 60 °/√h
        ("B", None, 3600.0, "°/h"),  # 1 °/s = 3600 °/h
        ("K", None, 216000.0, "°/h^1.5"),  # 1 °/s^1.5 = 216000 °/h^1.5
        ("R", None, 1.296e7, "°/h²"),  # 1 °/s² = 1.296e7 °/h²
        ("Q", None, 1.0, "°"),
        ("Q", "arcsec", 3600.0, "arcsec"),  # Q[arcsec] = 3600 Q[°]
        ("Q", "urad", 1e6 * math.pi / 180, "µrad"),
        ("N", "deg/sqrt(s)", 1.0, "°/√s"),
        ("N", "deg/h/sqrt(Hz)", 3600.0, "°/h/√Hz"),
        ("B", "rad/s", math.pi / 180, "rad/s"),
    ],
)
def test_ieee952_factors_from_deg_per_s(term, to, factor, label):
    q = ieee952(term, 1.0, "deg/s", to=to)
    assert q.value == pytest.approx(factor, rel=1e-14)
    assert q.unit == label


def test_ieee952_from_other_units():
    # rad/s samples: N in rad/√s → °/√h is 60·180/π
    assert ieee952("N", 1.0, "rad/s").value == pytest.approx(60 * 180 / math.pi, rel=1e-14)
    # deg/h samples: B in °/h stays the same number
    assert ieee952("B", 2.5, "deg/h").value == pytest.approx(2.5, rel=1e-14)
    # increments in deg: the Allan deviation is in °/s, so the factors are those of °/s
    assert ieee952("N", 1.0, "deg").value == pytest.approx(60.0, rel=1e-14)
    # urad/s samples: K
    assert ieee952("K", 1.0, "urad/s").value == pytest.approx(216000 * 1e-6 * 180 / math.pi, rel=1e-14)
    # arrays keep their shape
    out = ieee952("arw", np.array([1.0, 2.0]), "deg/s")
    np.testing.assert_allclose(out.value, [60.0, 120.0], rtol=1e-15)
    # long names and case
    assert ieee952("bias_instability", 1.0, "deg/s").value == pytest.approx(3600.0)
    assert ieee952("rrw", 1.0, "deg/s").value == pytest.approx(216000.0)
    assert ieee952("q", 1.0, "deg/s", to="arcsec").value == pytest.approx(3600.0)


def test_ieee952_consistent_with_closed_forms():
    # white rate noise σ per sample at fs: N = σ/√fs in (unit)·√s; ADEV(τ) = N/√τ. 0.15 °/√h ARW is
    # 0.0025 °/√s; at fs = 100 Hz that is σ = 0.025 °/s.
    sigma, fs = 0.025, 100.0
    assert ieee952("N", sigma / math.sqrt(fs), "deg/s").value == pytest.approx(0.15, rel=1e-14)


def test_ieee952_errors():
    with pytest.raises(ParameterError, match=r"unknown IEEE-952 term 'X'; allowed: 'Q'.*'R' \(rate ramp\)"):
        ieee952("X", 1.0, "deg/s")
    with pytest.raises(ParameterError, match=r"unknown report unit 'furlong' for term B; allowed: deg/h, deg/s, rad/s"):
        ieee952("B", 1.0, "deg/s", to="furlong")
    with pytest.raises(ParameterError, match=r"unknown unit 'parsec'"):
        ieee952("B", 1.0, "parsec")


def test_adev_unit_label():
    assert adev_unit_label("deg/s") == "°/s"
    assert adev_unit_label("dph") == "°/h"
    assert adev_unit_label("rad") == "rad/s"
    assert adev_unit_label("µrad") == "µrad/s"
    assert adev_unit_label(None) == "rate unit"


def test_unit_tables_are_consistent():
    assert set(units.RATE_UNITS).isdisjoint(units.ANGLE_UNITS)
    for name in units.RATE_UNITS:
        assert parse_unit(name).kind == "rate"
        assert parse_unit(parse_unit(name).label).name == name  # labels parse back
    for name in units.ANGLE_UNITS:
        assert parse_unit(name).kind == "angle"
        assert parse_unit(parse_unit(name).label).name == name


def test_docstring_examples():
    failures, tried = doctest.testmod(units, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert tried > 0 and failures == 0
