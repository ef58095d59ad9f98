"""The notebook display: every result's ``_repr_html_`` (issue 21).

Checked for each result type: the HTML parses and its tags balance, it holds the numbers and units
the result holds (formatted as shown), it has an inline SVG figure when matplotlib is importable and
none when it is not, and it stays small (a DAVAR of 10⁴ windows renders as small as one of 10).
"""

from __future__ import annotations

import dataclasses
import math
import sys
from html.parser import HTMLParser

import numpy as np
import pytest

import allanite
from allanite import _display

FS = 100.0
MAX_BYTES = 120_000  # a result's HTML, figure included
VOID = {"br", "hr", "img", "input", "meta", "link", "col", "area", "base", "source", "wbr"}


class _Checker(HTMLParser):
    """Parses HTML, keeping the text and failing on unbalanced tags (SVG's self-closing ones allowed)."""

    def __init__(self):
        super().__init__()
        self.stack: list[str] = []
        self.text: list[str] = []
        self.tags: list[str] = []
        self.errors: list[str] = []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        if tag not in VOID:
            self.stack.append(tag)

    def handle_startendtag(self, tag, attrs):
        self.tags.append(tag)

    def handle_endtag(self, tag):
        if not self.stack or self.stack[-1] != tag:
            self.errors.append(f"</{tag}> closes {self.stack[-1:] or 'nothing'}")
        else:
            self.stack.pop()

    def handle_data(self, data):
        self.text.append(data)


def parse(html: str) -> _Checker:
    p = _Checker()
    p.feed(html)
    p.close()
    assert p.errors == [], p.errors[:5]
    assert p.stack == [], f"unclosed: {p.stack}"
    return p


@pytest.fixture(scope="module")
def record():
    return allanite.simulate(100_000, FS, N=2e-3, B=1e-4, K=2e-5, seed=21)


@pytest.fixture(scope="module")
def static(record):
    return allanite.avar(record, FS).with_confidence(record)


@pytest.fixture(scope="module")
def dynamic(record):
    return allanite.davar(record, FS, window=10_000, hop=1_000)


def _results(record, static, dynamic):
    """name → (result, strings its HTML must hold)."""
    fit = allanite.fit(static, unit="deg/s", tau_range="auto")
    # what a fit decided itself is shown as a note (a real cut needs a record the model misses at short τ)
    fit = dataclasses.replace(fit, notes=("fitted from τ ≥ 0.16 s (tau_range='auto')",) + fit.notes)
    series = allanite.fit(dynamic, unit="deg/s")
    ref = allanite.refine(record, FS, unit="deg/s")
    lo, hi = static.adev_ci
    k = static.tau.size // 2
    n = fit.coefficients["N"]
    out = {
        "AllanResult": (
            static,
            [
                f"{static.tau[0]:.4g}",
                f"{static.adev[0]:.4g} [{lo[0]:.4g}, {hi[0]:.4g}]",
                f"{static.adev[k]:.4g} [{lo[k]:.4g}, {hi[k]:.4g}]" if k < 8 else f"{static.tau[-1]:.4g}",
                "100000 samples at 100 Hz",
                "68.3%",
                "τ (s)",
            ],
        ),
        "DynamicAllanResult": (
            dynamic,
            [f"{dynamic.t.size}, centred", f"{np.median(dynamic.adev[0]):.4g}", "10000 and 1000 samples"],
        ),
        "NoiseFit": (
            fit,
            [
                f"{n.value:.4g} [{n.ci[0]:.4g}, {n.ci[1]:.4g}]",
                f"{n.ieee:.4g} [{n.ieee_ci[0]:.4g}, {n.ieee_ci[1]:.4g}]",
                "°/√h",
                "°/h",
                "fitted from τ ≥ 0.16 s (tau_range='auto')",
                f"{fit.tau[0]:.4g}–{fit.tau[-1]:.4g} s",
                f"χ²/dof = {fit.chi2_dof:.3g}",
            ],
        ),
        "CoefficientSeries": (
            series,
            [
                f"{np.median(series.ieee['N'][series.values['N'] > 0]):.4g}",
                "°/√h",
                f"{series.t.size}, centred",
                f"{int(np.sum(series.values['N'] > 0))} of {series.t.size}",
            ],
        ),
        "Refinement": (ref, ["Q+N+B+K+R", f"{ref.curve_errors(ref.fit)['chi2_dof']:.3g}", "final model", "°/√h"]),
    }
    return out


@pytest.fixture(scope="module")
def results(record, static, dynamic):
    return _results(record, static, dynamic)


NAMES = ["AllanResult", "DynamicAllanResult", "NoiseFit", "CoefficientSeries", "Refinement"]


@pytest.mark.parametrize("name", NAMES)
def test_html_is_valid_holds_the_numbers_and_is_small(results, name):
    obj, expected = results[name]
    assert type(obj).__name__ == name
    html = obj._repr_html_()
    p = parse(html)
    text = " ".join(" ".join(p.text).split())
    for s in expected:
        assert s in text, f"{name}: {s!r} not in the HTML text"
    assert "svg" in p.tags, f"{name}: no inline figure although matplotlib is importable"
    assert len(html.encode()) < MAX_BYTES, f"{name}: {len(html.encode())} bytes"
    assert repr(obj) != html  # the plain repr is not the HTML


@pytest.mark.parametrize("name", NAMES)
def test_no_figure_without_matplotlib(results, name, monkeypatch):
    for mod in [m for m in sys.modules if m == "matplotlib" or m.startswith("matplotlib.")]:
        monkeypatch.setitem(sys.modules, mod, None)  # import matplotlib… now raises ImportError
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    obj, expected = results[name]
    html = obj._repr_html_()
    p = parse(html)
    assert "svg" not in p.tags
    text = " ".join(" ".join(p.text).split())
    assert all(s in text for s in expected)


def test_size_does_not_grow_with_the_record():
    """Many windows and τ: the table is thinned and the figure capped, so the HTML stays small."""
    y = allanite.simulate(400_000, FS, N=2e-3, seed=2)
    d = allanite.davar(y, FS, window=4_000, hop=100, taus="all")
    assert d.t.size > 3_000 and d.tau.size > 1_000
    html = d._repr_html_()
    parse(html)
    assert len(html.encode()) < MAX_BYTES
    assert f"{_display.MAX_ROWS} of {d.tau.size} rows shown" in html


def test_multi_axis_and_theo_columns():
    y = allanite.simulate(20_000, FS, N=2e-3, seed=3)
    x = np.column_stack([y, 2 * y, 3 * y, 4 * y])
    r = allanite.avar(x, FS)
    text = " ".join(parse(r._repr_html_()).text)
    assert "ADEV axis 2" in text and "ADEV axis 3" not in text and "axes 0–2 of 4 shown" in text
    th = allanite.avar(y, FS, estimator="theoh")
    text = " ".join(parse(th._repr_html_()).text)
    assert "estimator" in text and "theobr" in text


def test_text_is_escaped():
    s = _display.Summary(title="<b>x</b>", facts=[("a&b", "<script>")], notes=["1 < 2"])
    html = _display.render(s)
    assert "<script>" not in html and "&lt;script&gt;" in html and "&lt;b&gt;" in html


def test_a_failing_figure_is_left_out():
    def boom(ax):
        raise RuntimeError("no")

    html = _display.render(_display.Summary(title="t", figure=boom))
    assert "<svg" not in html and "t" in html


def test_thin_and_fmt():
    assert _display.thin(5, 10).tolist() == [0, 1, 2, 3, 4]
    i = _display.thin(1001, 300)
    assert i[0] == 0 and i[-1] == 1000 and i.size <= 300
    assert _display.fmt(float("inf")) == "∞" and _display.fmt(np.float32(1.23456)) == "1.235"
    assert _display.fmt(np.int64(7)) == "7" and _display.fmt(None) == "—"


def test_to_xarray_attrs_label_xarrays_own_plots(static, dynamic):
    """CF-style ``units``/``long_name`` on every variable and coordinate: xarray's .plot() labels axes."""
    pytest.importorskip("xarray")
    figure = pytest.importorskip("matplotlib.figure")
    ds = static.to_xarray(unit="deg/s")
    for name in ("avar", "adev", "adev_low", "adev_high", "edf", "tau", "m", "n"):
        assert {"units", "long_name"} <= set(ds[name].attrs), name
    ax = figure.Figure().add_subplot()
    ds.adev.plot(ax=ax, xscale="log", yscale="log")
    assert ax.get_xlabel() == "averaging time τ [s]" and ax.get_ylabel() == "Allan deviation [°/s]"
    dd = dynamic.to_xarray(unit="deg/s")
    ax = figure.Figure().add_subplot()
    mesh = dd.adev.plot(ax=ax, x="t", y="tau", yscale="log")
    assert " ".join(ax.get_xlabel().split()) == "window centre from the start of the record [s]"  # xarray wraps
    assert ax.get_ylabel() == "averaging time τ [s]"
    assert mesh.colorbar.ax.get_ylabel() == "dynamic Allan deviation [°/s]"


def test_coefficient_series_leaves_unresolved_windows_out():
    """A window whose fit put a term at 0 has only an upper bound: not a zero in the median, min or max."""
    from allanite.model.fitting import CoefficientSeries

    t = np.arange(6.0)
    values = {"N": np.array([1.0, 1.1, 0.9, 1.0, 1.2, 1.0]), "K": np.array([0.5, 0.0, 0.6, 0.0, 0.0, 0.4])}
    s = CoefficientSeries(
        t=t,
        terms=("N", "K"),
        values=values,
        ci_low={k: 0.8 * v for k, v in values.items()},
        ci_high={k: 1.2 * v + 0.3 for k, v in values.items()},
        chi2_dof=np.ones(6),
        confidence=0.683,
    )
    p = parse(s._repr_html_())
    cells = [c.strip() for c in p.text if c.strip()]
    k = cells.index("K")
    assert cells[k + 1 : k + 7] == ["rate random walk", "3 of 6", "0.5", "0.4", "0.6", "1.5"]


def test_forecast_models_and_scores_render():
    """The forecast models (one base: every GM(1,1) variant and baseline) and their scores."""
    from allanite import forecast

    x = [2.874, 3.278, 3.337, 3.390, 3.679]
    m = forecast.GM11(x)
    p = parse(m._repr_html_())
    text = " ".join(" ".join(p.text).split())
    assert "GM(1,1)" in text and f"{m.a:.6g}" in text and f"{m.b:.6g}" in text
    assert f"{m.C:.4g}" in text and m.grade in text and "svg" in p.tags
    series = 1.0 + 0.05 * np.arange(40) + 0.02 * np.sin(np.arange(40))
    for model in (forecast.ImprovedGM11(series), forecast.Holt(series), forecast.Persistence(series)):
        text = " ".join(parse(model._repr_html_()).text)
        assert f"{model.C:.4g}" in text and "40 values" in text
    build, check = forecast.split(series, 30, 10)
    sc = forecast.score(forecast.GM11, build, check)
    text = " ".join(" ".join(parse(sc._repr_html_()).text).split())
    assert f"{sc.rmse:.4g}" in text and f"{sc.honest.C:.4g}" in text and f"{sc.paper_rule.C:.4g}" in text


def test_one_number_format_for_tables_and_parameters():
    """``_display.fmt`` formats table cells and every refine step's parameters (``effects.format_param``)."""
    from fractions import Fraction

    from allanite.model.effects import format_param

    fmt = _display.fmt
    assert fmt(None) == "—" and fmt("boxcar") == "boxcar" and fmt(True) == "True" and fmt(np.bool_(False)) == "False"
    assert fmt(12) == "12" and fmt(np.int64(-3)) == "-3" and fmt(10**20) == str(10**20)
    assert fmt(0.123456789) == "0.1235" and fmt(0.123456789, 2) == "0.12" and fmt(2.5e-7) == "2.5e-07"
    assert fmt(np.float32(0.25)) == "0.25" and fmt(np.float64(1234567.0)) == "1.235e+06"
    assert fmt(np.array(0.123456789)) == "0.1235" and fmt(np.array(7)) == "7"  # 0-d arrays as their number
    assert fmt(math.inf) == "∞" and fmt(-np.inf) == "−∞" and fmt(np.float32("nan")) == "NaN"
    assert fmt(Fraction(1, 3)) == "0.3333"  # any real
    assert fmt([0.123456, 2, None]) == "0.1235, 2, —" and fmt((1.5,)) == "1.5" and fmt([]) == ""
    assert fmt(np.array([1e-3, 2.0 / 3.0])) == "0.001, 0.6667"
    assert fmt({"a": 1}) == "{'a': 1}"  # anything else as str
    # a parameter's value and interval go through the same function
    assert format_param("x", np.float32(0.123456), (np.float64(0.1), 1), "s") == "x = 0.1235 [0.1, 1] s"
    assert format_param("x", None) == "x = —" and format_param("x", np.bool_(True)) == "x = True"
    assert format_param("x", [np.int64(2), 0.5]) == "x = 2, 0.5"
