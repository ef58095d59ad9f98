"""The report's merged figures hold what the per-axis figures they replace held (issue 30 item 2).

``coefficients.png`` (every axis' noise coefficients over time, one panel per term, one colour per axis) holds
every curve, interval band and whole-record line that axis K's former ``coefficients_axisK.png`` — one
:func:`allanite.plot.plot_coefficient_series` figure per axis — held; ``davar.png`` holds every axis' heat map
(the former ``davar_axisK.png``, :func:`allanite.plot.plot_davar` alone), with the window in each panel's title.
"""

import numpy as np
import pytest

import allanite
from allanite.plot import plot_coefficient_series, plot_davar
from allanite.report import build_report
from allanite.report.figures import coefficient_panels

matplotlib = pytest.importorskip("matplotlib")
from matplotlib.collections import PolyCollection, QuadMesh  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402


@pytest.fixture(scope="module")
def report():
    # two axes of different noise: their windows resolve different terms (only axis 1 has a rate random walk),
    # and axis 0's white noise is the larger (its panel's range is not the last axis drawn's)
    a = allanite.simulate(24_000, 100.0, N=0.02, seed=5)
    b = allanite.simulate(24_000, 100.0, N=0.01, K=2e-2, seed=6)
    y = np.column_stack([a, b])
    return build_report(y, 100.0, unit="deg/s", window=4_000, hop=800, axis_names=["gx", "gy"], progress=False)


def _spec(rep, name):
    return next(sp for sp in rep.figure_specs() if sp[0] == name)


def _drawn(spec):
    fig = Figure(figsize=spec[3])
    spec[4](fig)
    return fig


def _curves(ax):
    """(y data of every line with a finite point, the band polygons' vertices) of one panel."""
    lines = [np.asarray(ln.get_ydata(), dtype=float) for ln in ax.get_lines()]
    lines = [y for y in lines if np.isfinite(y).any()]
    bands = [p.vertices for c in ax.collections if isinstance(c, PolyCollection) for p in c.get_paths()]
    return lines, bands


def _contains(arrays, a) -> bool:
    return any(x.shape == a.shape and np.array_equal(x, a, equal_nan=True) for x in arrays)


def test_the_report_writes_one_coefficient_figure_for_all_axes(report):
    names = [sp[0] for sp in report.figure_specs()]
    assert "coefficients.png" in names
    assert not [n for n in names if n.startswith(("coefficients_axis", "davar_axis"))]
    assert names.count("davar.png") == 1


def test_coefficients_png_holds_every_axis_figure(report):
    fig = _drawn(_spec(report, "coefficients.png"))
    panels = coefficient_panels(report.series)
    assert len(fig.axes) == len(panels)  # one panel per term some axis resolves, no other axes
    by_term = dict(zip(panels, fig.axes))
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert labels[:2] == ["gx", "gy"] and "whole record" in labels
    tops: dict = {}
    for k, s in enumerate(report.series):
        alone = Figure()
        own = [t for t in s.terms if np.any(s.values[t] > 0)] or list(s.terms)
        axs = alone.subplots(len(own), 1, squeeze=False)[:, 0]
        plot_coefficient_series(s, axes=axs, reference=report.fits[k])  # the former coefficients_axisK.png
        for t, ax in zip(own, axs):
            merged = by_term[t]
            lines, bands = _curves(merged)
            old_lines, old_bands = _curves(ax)
            assert old_lines and old_bands
            for y in old_lines:  # the curve, the upper bounds of unresolved windows, the whole-record value
                assert _contains(lines, y), (k, t)
            for v in old_bands:
                assert _contains(bands, v), (k, t)
            assert merged.get_ylim()[0] == 0.0
            tops[t] = max(tops.get(t, 0.0), ax.get_ylim()[1])
            assert merged.get_ylabel() == ax.get_ylabel()
            mine = [ln for ln in merged.get_lines() if ln.get_label() == ["gx", "gy"][k]]
            assert len(mine) == 1 and mine[0].get_color() == f"C{k}"
    for t, top in tops.items():  # each panel's range the largest an axis' own figure had: no curve cut off
        assert by_term[t].get_ylim()[1] == pytest.approx(top, rel=1e-12)
    assert fig.axes[-1].get_xlabel() == "window centre t (s)"
    assert all(ax.get_xlabel() == "" for ax in fig.axes[:-1])


def test_a_term_no_window_of_an_axis_resolves_is_not_drawn_for_it(report):
    panels = coefficient_panels(report.series)
    each = [coefficient_panels([s]) for s in report.series]
    assert "K" in each[1] and "K" not in each[0]  # the case this test is about
    assert panels == [t for t in report.series[0].terms if any(t in e for e in each)]
    fig = _drawn(_spec(report, "coefficients.png"))
    for t, ax in zip(panels, fig.axes):
        drawn = {ln.get_label() for ln in ax.get_lines()}
        for k, name in enumerate(["gx", "gy"]):
            assert (name in drawn) == (t in each[k])


def test_davar_png_holds_every_axis_heat_map_with_its_window(report):
    fig = _drawn(_spec(report, "davar.png"))
    panels = [ax for ax in fig.axes if ax.get_label() != "<colorbar>"]
    assert len(panels) == 2
    window = f"window {report.dynamic.window / report.fs:g} s"
    for k, ax in enumerate(panels):
        assert ["gx", "gy"][k] in ax.get_title() and window in ax.get_title()
        alone = Figure()
        plot_davar(report.dynamic, ax=alone.add_subplot(), axis=k, unit="deg/s")  # the former davar_axisK.png
        (mesh,) = [c for c in ax.collections if isinstance(c, QuadMesh)]
        (old,) = [c for c in alone.axes[0].collections if isinstance(c, QuadMesh)]
        np.testing.assert_array_equal(mesh.get_array(), old.get_array())
        assert (mesh.norm.vmin, mesh.norm.vmax) == (old.norm.vmin, old.norm.vmax)


def test_plot_coefficient_series_colour_and_label():
    y = allanite.simulate(20_000, 100.0, N=0.01, K=1e-3, seed=2)
    s = allanite.fit(allanite.davar(y, 100.0, window=4_000, hop=1_000), unit="deg/s")
    fig = Figure()
    axs = fig.subplots(len(coefficient_panels([s])), 1, squeeze=False)[:, 0]
    plot_coefficient_series(s, axes=axs, color="C3", label="axis 3", legend=False)
    for ax in axs:
        assert ax.get_legend() is None
        (curve,) = [ln for ln in ax.get_lines() if ln.get_label() == "axis 3"]
        assert curve.get_color() == "C3"
