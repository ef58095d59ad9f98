"""The report end to end — on the bundled record and on a real ADIS16405 run — and the notebook side
(``.plot()``, ``to_xarray()``, reprs).

The end-to-end checks: the command finishes, summary.json holds the library's own numbers (static
ADEV and its intervals, fitted coefficients, the coefficient time series), report.html is one
self-contained page whose images are the PNG files, and every PNG decodes.
"""

from __future__ import annotations

import base64
import contextlib
import io
import json
import sys
import time
from html.parser import HTMLParser

import matplotlib

matplotlib.use("Agg")

import matplotlib.image as mpimg  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import allanite  # noqa: E402
from allanite import cli  # noqa: E402
from allanite.report import build_report, default_hop, default_window  # noqa: E402

ADIS_RUN1 = "adis16405/adis16405_run1_100Hz.csv.gz"
ADIS_COLUMNS = ["gyro_x", "gyro_y", "gyro_z"]


# ------------------------------------------------------------------------------------------------
# helpers


def check_png(data_or_path, min_h=250, min_w=400):
    """Decode a PNG (path or bytes) and check it is a real, non-blank figure; returns the image."""
    src = io.BytesIO(data_or_path) if isinstance(data_or_path, bytes) else data_or_path
    img = mpimg.imread(src, format="png")
    assert img.ndim == 3 and img.shape[2] in (3, 4)
    assert img.shape[0] >= min_h and img.shape[1] >= min_w
    assert img.dtype == np.float32 and 0.0 <= img.min() and img.max() <= 1.0
    assert np.ptp(img[..., :3]) > 0.5  # not a blank canvas
    return img


class _Tags(HTMLParser):
    def __init__(self):
        super().__init__()
        self.tags = []

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))

    handle_startendtag = handle_starttag


def check_self_contained(html: str, out) -> list:
    """report.html references nothing outside itself; every <img> is a data: URI of a written PNG.
    Returns the image file names in page order."""
    assert html.startswith("<!DOCTYPE html>") and html.rstrip().endswith("</html>")
    low = html.lower()
    for bad in (
        'src="http',
        "src='http",
        'href="http',
        "href='http",
        'src="//',
        'href="//',
        "<script",
        "<link",
        "<iframe",
        "<object",
        "<embed",
        "@import",
        "url(",
        "file:",
    ):
        assert bad not in low, bad
    parser = _Tags()
    parser.feed(html)
    names = []
    for tag, attrs in parser.tags:
        assert tag not in ("script", "link", "iframe", "object", "embed", "base")
        for key, value in attrs.items():
            if key in ("href",):
                assert value.startswith("#"), value  # in-page anchors only
            if key in ("src", "srcset", "poster", "data", "action", "background"):
                assert tag == "img" and key == "src", (tag, key)
        if tag == "img":
            src = attrs["src"]
            assert src.startswith("data:image/png;base64,")
            png = base64.b64decode(src.split(",", 1)[1], validate=True)
            check_png(png)
            matches = [p for p in out.glob("*.png") if p.read_bytes() == png]
            assert len(matches) == 1, "an embedded image is not one of the written PNG files"
            names.append(matches[0].name)
            assert attrs.get("alt")
    return names


def run_cli(argv):
    """cli.main with stdout and stderr captured: (exit status, stdout, stderr, seconds)."""
    out, err = io.StringIO(), io.StringIO()
    t0 = time.perf_counter()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        rc = cli.main(argv)
    return rc, out.getvalue(), err.getvalue(), time.perf_counter() - t0


def _json_floats(v):
    """JSON list (None for non-finite) → float array (None → inf: the only non-finite the report writes is an
    unbounded interval)."""
    return np.array(
        [[np.inf if x is None else x for x in row] for row in v]
        if v and isinstance(v[0], list)
        else [np.inf if x is None else x for x in v],
        dtype=np.float64,
    )


def check_fit_matches(summary, static, unit):
    """summary.json's whole-record coefficients are allanite.fit's (tau_range="auto"), in base and IEEE-952 units."""
    fits = allanite.fit(static, unit=unit, tau_range="auto")
    assert summary["fit"]["terms"] == list(fits[0].terms)
    for ax, f in zip(summary["fit"]["axes"], fits):
        assert ax["chi2_dof"] == pytest.approx(f.chi2_dof, rel=1e-12)
        assert ax["notes"] == list(f.notes) and ax["method"] == f.method
        assert ax["dof"] == f.dof
        np.testing.assert_allclose(ax["tau_s"], f.tau, rtol=1e-15)
        for t, c in f.coefficients.items():
            got = ax["coefficients"][t]
            assert got["value"] == pytest.approx(c.value, rel=1e-12, abs=0)
            np.testing.assert_allclose(_json_floats(got["ci"]), c.ci, rtol=1e-12)
            if unit is None:
                assert got["ieee"] is None and got["ieee_unit"] is None
            else:
                assert got["ieee"] == pytest.approx(c.ieee, rel=1e-12, abs=0)
                np.testing.assert_allclose(_json_floats(got["ieee_ci"]), c.ieee_ci, rtol=1e-12)
                assert got["ieee_unit"] == c.ieee_unit and got["unit"] == c.unit
        assert ax["readoffs"]["adev_min"] == f.readoffs["adev_min"]
        assert ax["readoffs"]["tau_at_min_s"] == f.readoffs["tau_at_min"]
    return fits


def check_series_matches(summary, dynamic, unit, fits):
    """The coefficient series are allanite.fit's per axis, on the τ range of that axis's whole-record fit."""
    import dataclasses

    series = [
        allanite.fit(dataclasses.replace(dynamic, avar=row), unit=unit, tau_range=(f.tau[0] * (1 - 1e-9), None))
        for row, f in zip(dynamic.avar, fits)
    ]
    ser = summary["fit"]["series"]
    assert ser["terms"] == list(series[0].terms)
    for ax, s in zip(ser["axes"], series):
        np.testing.assert_array_equal(ax["t_s"], s.t)
        for t in s.terms:
            c = ax["coefficients"][t]
            np.testing.assert_allclose(c["value"], s.values[t], rtol=1e-12, atol=0)
            np.testing.assert_allclose(_json_floats(c["ci_low"]), s.ci_low[t], rtol=1e-12, atol=0)
            np.testing.assert_allclose(_json_floats(c["ci_high"]), s.ci_high[t], rtol=1e-12, atol=0)
            if unit is not None:
                np.testing.assert_allclose(c["ieee"], s.ieee[t], rtol=1e-12, atol=0)
                assert c["ieee_unit"] == s.ieee_units[t]


def expected_figures(n_axes, fit=True):
    names = {"adev.png", "davar.png"} | ({"coefficients.png"} if fit else set())
    for k in range(n_axes):
        names |= {f"adev_axis{k}.png", f"davar3d_axis{k}.png"}
    return names


# ------------------------------------------------------------------------------------------------
# the bundled record (the README's main job)


@pytest.fixture(scope="module")
def bundled(tmp_path_factory):
    out = tmp_path_factory.mktemp("report")
    rc, stdout, stderr, seconds = run_cli(["report", "--out", str(out)])
    return rc, out, stdout, stderr


def test_bundled_report_writes_every_file(bundled):
    rc, out, stdout, stderr = bundled
    assert rc == 0, stderr
    assert stderr == ""  # no progress bar: stderr is not a terminal here
    names = {p.name for p in out.iterdir()}
    assert names == {"report.html", "summary.json"} | expected_figures(3)
    for p in out.glob("*.png"):
        check_png(p)
    davar = check_png(out / "davar.png")
    assert davar.shape[0] > davar.shape[1]  # three stacked panels
    assert check_png(out / "adev.png").shape[1] > check_png(out / "adev.png").shape[0]


def test_bundled_report_html_is_self_contained(bundled):
    rc, out, stdout, stderr = bundled
    html = (out / "report.html").read_text(encoding="utf-8")
    shown = check_self_contained(html, out)
    # every figure written is on the page (issue 32: davar.png, all axes on one time axis, was a file only)
    assert set(shown) == expected_figures(3)
    for section in ('id="record"', 'id="static"', 'id="model"', 'id="davar"', 'id="series"'):
        assert section in html
    summary = json.loads((out / "summary.json").read_text())
    # numbers on the page come from summary.json: spot-check the coefficient table
    for ax in summary["fit"]["axes"]:
        n = ax["coefficients"]["N"]
        assert f"{n['ieee']:.4g} [{n['ieee_ci'][0]:.4g}, {n['ieee_ci'][1]:.4g}]" in html
        assert f"{ax['chi2_dof']:.4g}" in html
    assert "°/√h" in html and "°/h" in html and "µrad" in html


def test_bundled_report_summary_matches_the_library(bundled):
    rc, out, stdout, stderr = bundled
    summary = json.loads((out / "summary.json").read_text())
    x, fs, info = allanite.default_record()
    assert summary["schema"] == "allanite-report/1" and summary["allanite_version"] == allanite.__version__
    assert (summary["fs_hz"], summary["samples"], summary["axes"]) == (fs, x.shape[0], x.shape[1])
    assert summary["unit"] == info["unit"] == "deg/s"
    assert summary["record"]["adev_unit"] == "°/s" and summary["record"]["axis_names"] == ["x", "y", "z"]
    st = summary["static"]
    tau = np.array(st["tau_s"])
    np.testing.assert_array_equal(tau, allanite.tau_grid(x.shape[0], fs, "octave"))
    r = allanite.avar(x, fs, taus=tau).with_confidence(x)
    np.testing.assert_array_equal(st["n"], r.n)
    np.testing.assert_array_equal(st["adev"], r.adev)  # JSON round-trips doubles exactly
    np.testing.assert_allclose(st["adev_ci_low"], np.sqrt(r.ci_low), rtol=1e-12)
    np.testing.assert_allclose(st["adev_ci_high"], np.sqrt(r.ci_high), rtol=1e-12)
    np.testing.assert_array_equal(st["edf"], r.edf)
    np.testing.assert_array_equal(st["alpha"], r.alpha)
    assert st["confidence"] == 0.683

    dyn = summary["dynamic"]
    window, hop = dyn["window_samples"], dyn["hop_samples"]
    assert window == default_window(x.shape[0]) == x.shape[0] // 12 and hop == default_hop(window) == window // 25
    assert (dyn["window_rule"], dyn["hop_rule"]) == ("record/12", "window/25")
    assert dyn["windows"] == (x.shape[0] - window) // hop + 1
    d = allanite.davar(x, fs, window=window, hop=hop, taus="exp")
    np.testing.assert_array_equal(dyn["tau_s"], d.tau)
    np.testing.assert_array_equal(dyn["t_s"], d.t)
    # the bundled record's loud stretch (20–30 min, ARW ×4) is what the DAVAR summary must find
    for k, ax in enumerate(dyn["axes"]):
        assert 1200.0 <= ax["t_of_max_s"] <= 1800.0
        assert not 1200.0 - window / fs / 2 <= ax["t_of_min_s"] <= 1800.0 + window / fs / 2
        assert 3.5 < ax["max_over_min"] < 4.5
        np.testing.assert_allclose(ax["adev_max_over_time"], d.adev[k].max(axis=1), rtol=1e-15)

    fits = check_fit_matches(summary, r, "deg/s")
    check_series_matches(summary, d, "deg/s", fits)
    # the N time series sees the loud stretch too: 4× the quiet value in its middle
    n_series = summary["fit"]["series"]["axes"][0]["coefficients"]["N"]
    t = np.array(summary["fit"]["series"]["axes"][0]["t_s"])
    n_ieee = np.array(n_series["ieee"])
    quiet, loud = np.median(n_ieee[t < 900]), np.median(n_ieee[(t > 1450) & (t < 1550)])
    assert 3.5 < loud / quiet < 4.5
    assert quiet == pytest.approx(0.15, rel=0.05)  # the bundled record's N = 0.15 °/√h on axis x


def test_bundled_report_prints_tables_and_paths(bundled):
    rc, out, stdout, stderr = bundled
    summary = json.loads((out / "summary.json").read_text())
    assert stdout.startswith("[") and "] generating the bundled record\n" in stdout  # a line per step: no terminal
    assert "\nallanite report: bundled record" in stdout
    assert "Overlapping Allan deviation (°/s)" in stdout and "68.3% interval" in stdout
    # one table row per τ, with the ADEV of each axis as in summary.json
    st = summary["static"]
    for i, tau in enumerate(st["tau_s"]):
        row = next(line for line in stdout.splitlines() if line.split()[:2] == [f"{tau:.4g}", str(st["n"][i])])
        for k in range(3):
            assert f"{st['adev'][k][i]:.4g}" in row
    assert "Noise model (IEEE 952) in IEEE-952 units" in stdout
    for term, unit in (
        ("N angle random walk", "°/√h"),
        ("B bias instability", "°/h"),
        ("K rate random walk", "°/h^1.5"),
    ):
        line = next(line for line in stdout.splitlines() if term in line)
        assert unit in line
    n = summary["fit"]["axes"][0]["coefficients"]["N"]
    assert f"{n['ieee']:.3g} [{n['ieee_ci'][0]:.3g}, {n['ieee_ci'][1]:.3g}]" in stdout
    assert "Dynamic Allan deviation: window 30000 samples (300 s, record/12), hop 1200" in stdout
    assert f"wrote {out / 'report.html'}" in stdout and str(out / "summary.json") in stdout
    assert "adev.png" in stdout and "davar3d_axis2.png" in stdout


# ------------------------------------------------------------------------------------------------
# a real ADIS16405 run: 3 gyro axes × 10⁶ samples


@pytest.fixture(scope="module")
def adis(tmp_path_factory, shared_data):
    path = shared_data / ADIS_RUN1
    if not path.is_file():
        pytest.skip(f"ADIS16405 run 1 not found at {path}")
    out = tmp_path_factory.mktemp("adis")
    rc, stdout, stderr, seconds = run_cli(
        ["report", str(path), "--fs", "100", "--columns", ",".join(ADIS_COLUMNS), "--unit", "deg/s", "--out", str(out)]
    )
    return rc, out, stdout, stderr, seconds, path


def test_adis_report_end_to_end(adis):
    rc, out, stdout, stderr, seconds, path = adis
    assert rc == 0, stderr
    assert stderr == ""
    print(f"ADIS16405 run 1 report: {seconds:.1f} s")
    assert {p.name for p in out.iterdir()} == {"report.html", "summary.json"} | expected_figures(3)
    for p in out.glob("*.png"):
        check_png(p)
    html = (out / "report.html").read_text(encoding="utf-8")
    assert len(check_self_contained(html, out)) == len(expected_figures(3))  # davar.png too (issue 32)
    assert "adis16405_run1_100Hz.csv.gz" in html and "gyro_z" in html

    summary = json.loads((out / "summary.json").read_text())
    assert (summary["samples"], summary["axes"], summary["fs_hz"], summary["unit"]) == (1_000_000, 3, 100.0, "deg/s")
    assert summary["record"]["axis_names"] == ADIS_COLUMNS
    assert summary["record"]["source"]["format"] == "text" and summary["record"]["source"]["gaps"] == []

    log = allanite.read_log(path, fs=100, columns=ADIS_COLUMNS, unit="deg/s")
    x = np.asarray(log.data)
    tau = np.array(summary["static"]["tau_s"])
    r = allanite.avar(x, 100.0, taus=tau)
    np.testing.assert_allclose(summary["static"]["adev"], r.adev, rtol=1e-12, atol=0)
    rc_ = r.with_confidence(x)
    np.testing.assert_allclose(summary["static"]["adev_ci_high"], np.sqrt(rc_.ci_high), rtol=1e-12)
    np.testing.assert_array_equal(summary["static"]["alpha"], rc_.alpha)

    d = allanite.davar(x, 100.0, window=summary["dynamic"]["window_samples"], hop=summary["dynamic"]["hop_samples"])
    np.testing.assert_array_equal(summary["dynamic"]["t_s"], d.t)
    fits = check_fit_matches(summary, r, "deg/s")
    check_series_matches(summary, d, "deg/s", fits)
    # ARW of the ADIS16405: its datasheet says 2 °/√h; the fit is in that range on every axis, and B near the
    # ADEV minimum / 0.664 — because the report drops the filtered shortest τ (and says so): with them the
    # model gives χ²/dof > 1000 and B of ~200 °/h
    for ax in summary["fit"]["axes"]:
        assert 2.2 < ax["coefficients"]["N"]["ieee"] < 2.7
        assert 20 < ax["coefficients"]["B"]["ieee"] < 45
        assert ax["tau_s"][0] == pytest.approx(0.16) and "tau_range='auto'" in ax["notes"][0]
    assert sum("tau_range='auto'" in n for n in summary["notes"]) == 3
    for name in ADIS_COLUMNS:
        assert name in stdout


# ------------------------------------------------------------------------------------------------
# building blocks


def test_build_report_api_and_text(tmp_path):
    y = allanite.simulate(40_000, 100.0, N=0.01, K=1e-3, seed=4)
    rep = build_report(y, 100.0, unit="rad/s", window=8_000, hop=2_000)
    assert rep.n_axes == 1 and rep.axis_names == ["axis 0"] and rep.adev_unit == "rad/s"
    assert "Report(" in repr(rep) and "unit rad/s" in repr(rep)
    s = rep.summary()
    assert s["dynamic"]["windows"] == (40_000 - 8_000) // 2_000 + 1
    assert (s["dynamic"]["window_rule"], s["dynamic"]["hop_rule"]) == ("given", "given")
    c = s["fit"]["axes"][0]["coefficients"]["N"]
    assert c["unit"] == "rad/√s" and c["ieee_unit"] == "°/√h"
    assert c["value"] == pytest.approx(0.01, rel=0.05)
    assert "Q" in s["fit"]["axes"][0]["coefficients"] and "also" in s["fit"]["axes"][0]["coefficients"]["Q"]
    text = rep.text()
    assert "axis 0" in text and "rad/s" in text
    paths = rep.write(tmp_path / "r")
    assert paths[0].name == "report.html" and paths[1].name == "summary.json"
    assert {p.name for p in paths[2:]} == expected_figures(1)
    json.loads(paths[1].read_text())  # valid JSON (no NaN/Infinity tokens)


def test_report_with_unknown_unit_keeps_base_form():
    y = allanite.simulate(20_000, 50.0, N=0.02, seed=5)
    rep = build_report(y, 50.0, window=4_000, hop=1_000)
    s = rep.summary()
    assert s["unit"] is None and s["record"]["adev_unit"] is None and not s["fit"]["unit_known"]
    assert any("unit of the samples is unknown" in n for n in s["notes"])
    c = s["fit"]["axes"][0]["coefficients"]["N"]
    assert c["ieee"] is None and c["unit"] is None and c["value"] == pytest.approx(0.02, rel=0.1)
    assert "unit unknown" in rep.text() and "base form" in rep.text()


def test_report_without_fit_and_with_too_short_windows(tmp_path):
    y = np.random.default_rng(6).normal(size=3_000)
    rep = build_report(y, 10.0, unit="deg/s", fit=False)
    s = rep.summary()
    assert s["fit"]["requested"] is False and s["fit"]["axes"] is None and s["fit"]["series"] is None
    assert {sp[0] for sp in rep.figure_specs()} == expected_figures(1, fit=False)
    # a 250-sample window has too few octave τ for five terms: its windows are fitted on every τ
    rep = build_report(y, 10.0, unit="deg/s")
    assert rep.series is not None and rep.series_error is None
    # a 50-sample window has too few τ even then: the series is skipped with a note
    rep = build_report(y[:600], 10.0, unit="deg/s")
    s = rep.summary()
    assert s["fit"]["axes"] is not None and s["fit"]["series"]["axes"] is None
    assert "usable τ" in s["fit"]["series"]["error"]
    assert any("coefficients over time could not be fitted" in n for n in s["notes"])
    html = rep.html(rep.render_figures())
    assert "Not fitted" in html


def test_json_has_no_non_finite_numbers(tmp_path):
    # an interval without an upper bound (a term the data cannot bound) is written as null, not Infinity
    y = np.random.default_rng(7).normal(size=5_000)
    rep = build_report(y, 1.0, unit="deg/s", window=2_500, hop=500)
    rep.write(tmp_path)
    text = (tmp_path / "summary.json").read_text()
    assert "Infinity" not in text and "NaN" not in text
    json.loads(text, parse_constant=lambda c: pytest.fail(f"non-standard JSON constant {c}"))


# ------------------------------------------------------------------------------------------------
# notebook use: plots, to_xarray, reprs


def test_plots_draw_on_given_axes_and_on_their_own():
    import matplotlib.pyplot as plt

    x, fs, _ = allanite.default_record()
    x = x[:60_000]
    s = allanite.avar(x, fs).with_confidence(x)
    d = allanite.davar(x, fs, window=12_000, hop=2_000)
    f = allanite.fit(s, unit="deg/s")
    series = allanite.fit(d, unit="deg/s", terms=("N", "B", "K"))
    try:
        ax = s.plot(unit="deg/s")
        assert ax.get_ylabel() == "Allan deviation (°/s)"
        assert len(ax.collections) == 3  # one confidence band per axis
        ax = d.plot(axis=1, unit="deg/s")
        assert ax.get_yscale() == "log"
        ax = f[0].plot()
        assert any("N =" in t.get_text() for t in ax.get_legend().get_texts())
        axes = series[0].plot()
        assert axes[0].get_ylabel().endswith("(°/√h)")
        from allanite.plot import plot_davar3d

        ax3 = plot_davar3d(d, axis=2, unit="deg/s", max_points=20)
        assert ax3.name == "3d" and ax3.get_zlabel() == "log₁₀ ADEV (°/s)"
        fig, ax = plt.subplots()
        assert s.plot(ax=ax, axis=0) is ax and len(ax.lines) == 1
    finally:
        plt.close("all")


def test_plot_labels_name_each_line_and_only_the_lines():
    # issue 32: ``ax.legend(names)`` after ``r.plot()`` paired the names with the bands; ``labels=`` names lines
    import matplotlib.pyplot as plt

    x, fs, _ = allanite.default_record()
    x = x[:30_000]
    s = allanite.avar(x, fs).with_confidence(x)
    names = ["gyro_x", "gyro_y", "gyro_z"]
    try:
        ax = s.plot(labels=names)
        handles, texts = ax.get_legend_handles_labels()
        assert texts == names
        assert all(h in ax.lines for h in handles)  # lines, not the interval bands
        assert [t.get_text() for t in ax.get_legend().get_texts()] == names
        ax = s.plot(labels=names, axis=1)
        assert [t.get_text() for t in ax.get_legend().get_texts()] == ["gyro_y", "68.3% interval"]
        one = allanite.avar(x[:, 0], fs)
        ax = one.plot(labels="gyro_x")
        assert [t.get_text() for t in ax.get_legend().get_texts()] == ["gyro_x"]
        ax = s.plot()
        assert [t.get_text() for t in ax.get_legend().get_texts()] == ["axis 0", "axis 1", "axis 2"]
        with pytest.raises(allanite.AllaniteError, match="labels has 2 name.* of 3 axes: give one label per axis"):
            s.plot(labels=names[:2])
        with pytest.raises(allanite.AllaniteError, match="labels has 3 name.* of 1 axis"):
            one.plot(labels=names)
    finally:
        plt.close("all")


def test_to_xarray_static_and_dynamic():
    xr = pytest.importorskip("xarray")
    x, fs, _ = allanite.default_record()
    x = x[:50_000]
    s = allanite.avar(x, fs).with_confidence(x)
    ds = s.to_xarray(unit="deg/s", axis_names=["x", "y", "z"])
    assert isinstance(ds, xr.Dataset)
    assert ds["adev"].dims == ("axis", "tau") and list(ds["axis"].values) == ["x", "y", "z"]
    np.testing.assert_array_equal(ds["tau"].values, s.tau)
    np.testing.assert_array_equal(ds["adev"].sel(axis="y").values, s.adev[1])
    assert ds["adev"].attrs["units"] == "°/s" and ds["avar"].attrs["units"] == "(°/s)²"
    assert ds["tau"].attrs["units"] == "s" and ds.attrs["fs_hz"] == fs and ds.attrs["confidence"] == 0.683
    np.testing.assert_array_equal(ds["adev_high"].values, np.sqrt(s.ci_high))
    assert ds["edf"].dims == ("axis", "tau")

    d = allanite.davar(x, fs, window=10_000, hop=5_000)
    dd = d.to_xarray()
    assert dd["avar"].dims == ("axis", "tau", "t") and dd["t"].attrs["units"] == "s"
    np.testing.assert_array_equal(dd["t"].values, d.t)
    np.testing.assert_array_equal(dd["avar"].isel(axis=2).values, d.avar[2])
    assert dd["adev"].attrs["units"] == "rate unit" and dd.attrs["unit"] == "unknown"
    assert dd.attrs["window"] == 10_000 and dd.attrs["hop"] == 5_000
    one = allanite.avar(x[:, 0], fs).to_xarray(unit="rad/s")
    assert one["adev"].dims == ("tau",) and "axis" not in one.coords
    d1 = allanite.davar(x[:, 0], fs, window=10_000, hop=5_000).to_xarray(unit="deg")
    assert d1["adev"].dims == ("tau", "t") and d1["adev"].attrs["units"] == "°/s"  # increments in ° → °/s
    with pytest.raises(allanite.ParameterError, match="unknown unit"):
        s.to_xarray(unit="furlong/s")
    with pytest.raises(allanite.ParameterError, match="2 names for 3 axes"):
        s.to_xarray(axis_names=["a", "b"])


def test_to_xarray_without_xarray_says_how_to_install(monkeypatch):
    from allanite.io import MissingDependencyError

    monkeypatch.setitem(sys.modules, "xarray", None)  # makes `import xarray` fail
    r = allanite.avar(np.arange(100.0) % 3, 1.0)
    with pytest.raises(MissingDependencyError, match=r"pip install 'allanite\[xarray\]'"):
        r.to_xarray()
    d = allanite.davar(np.arange(100.0) % 3, 1.0, window=50, hop=10)
    with pytest.raises(ImportError):
        d.to_xarray()


def test_reprs_are_readable():
    x, fs, _ = allanite.default_record()
    x = x[:20_000]
    s = allanite.avar(x, fs)
    text = repr(s)
    assert text.startswith("AllanResult(oavar, ") and "3 axes" in text and "adev (axis 0)" in text
    assert " )" not in text and " ;" not in text
    assert "68.3% intervals" in repr(s.with_confidence(x))
    assert " )" not in repr(allanite.avar(x[:, 0], fs))
    d = allanite.davar(x, fs, window=5_000, hop=1_000)
    assert "window 5000, hop 1000 samples at 100 Hz, 3 axes" in repr(d)


def test_report_module_examples():
    import doctest

    import allanite.report.build

    failures, tried = doctest.testmod(allanite.report.build, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert tried > 0 and failures == 0
