"""Time-frame DAVAR (``allanite.frames``, paper 004), the per-term forecast comparison
(``allanite.forecast.compare``) and the report's "Coefficient forecast" section, its JSON, text, page,
figures and command-line errors. Small records only: every test runs in about a second."""

from __future__ import annotations

import dataclasses
import json
import math
import re

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

import allanite  # noqa: E402
from allanite import cli  # noqa: E402
from allanite.errors import AllaniteError, InputError, ParameterError  # noqa: E402
from allanite.forecast import GM11, ImprovedGM11, Persistence, compare, default_methods, score  # noqa: E402
from allanite.model import frame_for_count  # noqa: E402
from allanite.report import build_report  # noqa: E402

FS = 50.0


@pytest.fixture(scope="module")
def record():
    """Two axes, 90 frames of 4 s (200 samples) + 37 left over: ARW rising 30 % along the record on axis 0,
    constant on axis 1."""
    n = 90 * 200 + 37
    rng = np.random.default_rng(15)
    ramp = 1.0 + 0.3 * np.arange(n) / n
    return np.column_stack([0.05 * ramp * rng.standard_normal(n), 0.05 * rng.standard_normal(n)])


@pytest.fixture(scope="module")
def frames2(record):
    return allanite.frames(record, FS, frame=4.0, terms=("N", "K"), unit="deg/s")


# ---------------------------------------------------------------------------------------------- frames


def test_frames_are_consecutive_davar_windows_fitted(record, frames2):
    assert isinstance(frames2, list) and len(frames2) == 2
    f = frames2[0]
    assert (f.n_frames, f.frame_samples, f.frame_s, f.dropped_samples) == (90, 200, 4.0, 37)
    np.testing.assert_allclose(f.t, 2.0 + 4.0 * np.arange(90))  # frame centres, s
    # the same as davar(window=F, hop=F) then fit, term for term
    d = allanite.davar(record, FS, window=200, hop=200)
    ref = allanite.fit(d, terms=("N", "K"), unit="deg/s")
    for k in range(2):
        for t in ("N", "K"):
            np.testing.assert_array_equal(frames2[k].series.values[t], ref[k].values[t])
            np.testing.assert_array_equal(frames2[k].series.ci_high[t], ref[k].ci_high[t])
    # white noise of SD 0.05 at 50 Hz: N = 0.05/√50 °/√s; axis 0 rises 30 % over the record
    n0 = frames2[0].series.values["N"]
    assert np.median(frames2[1].series.values["N"]) == pytest.approx(0.05 / math.sqrt(FS), rel=0.03)
    assert np.median(n0[-15:]) / np.median(n0[:15]) == pytest.approx(1.28, abs=0.06)


def test_one_axis_gives_one_object_and_units_follow_the_fit(record):
    f = allanite.frames(record[:, 0], FS, frame=4.0, terms=("N",), unit="deg/s")
    assert isinstance(f, allanite.TimeFrames) and f.terms == ("N",)
    assert f.units() == {"N": "°/√h"} and f.units(ieee=False) == {"N": None}
    np.testing.assert_allclose(f.values()["N"], f.series.values["N"] * 60.0)  # °/√s → °/√h
    lo, hi = f.intervals()
    np.testing.assert_allclose(hi["N"], f.series.ci_high["N"] * 60.0)
    assert np.all(lo["N"] < f.values()["N"]) and np.all(f.values()["N"] < hi["N"])
    se = f.standard_errors(ieee=False)["N"]
    # 200 samples per frame: the ARW estimate's relative SE is a few per cent
    assert 0.01 < np.median(se / f.series.values["N"]) < 0.15
    assert "90 frames of 4 s" in repr(f)


def test_a_term_the_frames_do_not_resolve_is_not_forecastable(frames2):
    f = frames2[1]  # white noise only: K is at 0 in most frames
    # its interval bounds still convert to IEEE units by the term's own factor (°/√s^3 → °/h^1.5: 60·3600)
    lo, hi = f.intervals()
    np.testing.assert_allclose(hi["K"], f.series.ci_high["K"] * 60.0 * 3600.0)
    assert f.forecastable["N"] is True
    assert f.forecastable["K"] is False and "frames (not resolved there)" in f.not_forecastable["K"]
    tab = f.forecast(60, 30)
    assert tab["terms"] == ["N"] and "K" in tab["skipped"] and "not forecastable" in tab["skipped"]["K"]
    assert all("K" not in tab["cells"][m] for m in tab["methods"])  # never fed to a model


def test_forecast_on_frames_matches_score_and_reports_the_noise_ratio(frames2):
    f = frames2[0]
    tab = f.forecast(60, 30)
    x = f.values()["N"]
    s = score(GM11, x[:60], x[60:90])
    cell = tab["cells"]["GM(1,1)"]["N"]
    assert cell["C"] == s.honest.C and cell["P"] == s.honest.P and cell["C_paper"] == s.paper_rule.C
    np.testing.assert_array_equal(cell["forecast"], s.forecast)
    se = f.standard_errors()["N"][60:90]
    assert tab["se_check"]["N"] == pytest.approx(math.sqrt(np.mean(se**2)))
    assert cell["rmse_over_se"] == pytest.approx(s.rmse / tab["se_check"]["N"])
    assert tab["units"]["N"] == "°/√h" and tab["frame_s"] == 4.0


def test_frames_figures_draw(frames2):
    from matplotlib.figure import Figure

    f = frames2[0]
    fig = Figure()
    axs = fig.subplots(2, 1)
    f.plot(axes=list(axs))
    assert axs[0].get_ylabel() == "N (°/√h)" and len(axs[0].lines) == 1
    fig2 = Figure()
    ax = fig2.subplots(1, 1)
    f.plot_forecast(f.forecast(60, 30), axes=[ax])
    labels = [ln.get_label() for ln in ax.lines]
    assert any(lb.startswith("GM(1,1): C = ") for lb in labels) and "wavelet-smoothed (build)" in labels


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"frame": 0.5}, "frame = 0.5 s is 25 samples at 50 Hz; at least 64"),
        ({"frame": -1.0}, "frame must be a positive finite number, got -1.0"),
        ({"frame": float("nan")}, "frame"),
        ({"frame": 1000.0}, "frame = 1000.0 s (50000 samples) is longer than the record (18037 samples"),
    ],
)
def test_bad_frames_name_the_value(record, kwargs, message):
    with pytest.raises(ParameterError) as e:
        allanite.frames(record, FS, **kwargs)
    assert message in str(e.value)


def test_a_split_that_does_not_fit_the_frames_names_both(frames2):
    with pytest.raises(ParameterError, match=r"build \+ check = 60 \+ 40 = 100 frames, but the record gives 90"):
        frames2[0].forecast(60, 40)
    with pytest.raises(ParameterError, match="build = 3 is too small"):
        frames2[0].forecast(3, 30)
    with pytest.raises(ParameterError, match="build = 6.5 must be an integer"):
        frames2[0].forecast(6.5, 30)


def test_frame_for_count():
    assert frame_for_count(1_000_000, 100.0, 90) == pytest.approx(111.11)
    assert frame_for_count(18_037, 50.0, 90) == 4.0
    with pytest.raises(ParameterError, match="count = 0 frames"):
        frame_for_count(100, 1.0, 0)


# ---------------------------------------------------------------------------------------------- compare


def test_compare_scores_every_method_like_score():
    rng = np.random.default_rng(3)
    x = 1.0 + 0.01 * np.arange(40) + 0.01 * rng.standard_normal(40)
    t = compare({"N": x}, 30, 10)
    assert t["methods"] == list(default_methods()) and t["terms"] == ["N"] and t["skipped"] == {}
    for name, factory in default_methods().items():
        s = score(factory, x[:30], x[30:40])
        cell = t["cells"][name]["N"]
        assert cell["C"] == s.honest.C and cell["P_paper"] == s.paper_rule.P and cell["rmse"] == s.rmse
        assert cell["grade"] == s.honest.grade and cell["grade_paper"] == s.paper_rule.grade
    assert "processed" in t["cells"]["improved GM(1,1)"]["N"]
    # successive differences of the noise: robust SD/√2 recovers the 0.01 (first differences remove the trend)
    assert t["scatter"]["N"] == pytest.approx(0.01, rel=0.35)


def test_compare_skips_non_positive_series_and_records_method_errors():
    x = np.linspace(1.0, 2.0, 20)
    y = x.copy()
    y[4] = 0.0

    def broken(_series):
        raise InputError("boom")

    t = compare({"N": x, "Q": y}, 12, 8, methods={"GM": GM11, "last": Persistence, "broken": broken})
    assert t["terms"] == ["N"] and "1 of 20 values at or below 0 (first at index 4)" in t["skipped"]["Q"]
    assert t["cells"]["broken"]["N"] == {"error": "boom"}
    assert t["cells"]["last"]["N"]["C"] == pytest.approx(1.0, abs=1e-12)  # a constant forecast: C = 1


@pytest.mark.parametrize(
    "series, build, check, err, message",
    [
        ({"N": [1.0, 2.0, 3.0]}, 2, 1, InputError, "series['N'] has 3 values; at least 4 are needed"),
        ({"N": np.ones(10)}, 8, 4, ParameterError, "build + check = 8 + 4 = 12 exceeds the series length (10)"),
        ({"N": np.ones(10)}, 3, 4, ParameterError, "build = 3 is too small"),
        ({"N": np.ones(10)}, 6, 1, ParameterError, "check = 1 is too small"),
        ({"N": [1.0, np.nan, 1.0, 1.0, 1.0]}, 4, 1, InputError, "series['N'][1] = nan is not finite"),
    ],
)
def test_compare_bad_input_names_the_value(series, build, check, err, message):
    with pytest.raises(err) as e:
        compare(series, build, check)
    assert message in str(e.value)


def test_compare_needs_enough_noise_values():
    with pytest.raises(InputError, match=r"noise\['N'\] has 5 values; 12 needed"):
        compare({"N": np.linspace(1, 2, 12)}, 8, 4, noise={"N": np.ones(5)})
    with pytest.raises(ParameterError, match="methods is empty"):
        compare({"N": np.linspace(1, 2, 12)}, 8, 4, methods={})


def test_improved_model_is_in_the_default_methods():
    assert default_methods()["improved GM(1,1)"] is ImprovedGM11


# ---------------------------------------------------------------------------------------------- report


@pytest.fixture(scope="module")
def report(record):
    return build_report(record, FS, unit="deg/s", window=3000, hop=1500, frames=4.0, forecast="60:30")


def test_report_summary_has_the_forecast_section(report, record):
    s = report.summary()
    fc = s["forecast"]
    assert (fc["frames"], fc["frame_s"], fc["build"], fc["check"], fc["dropped_samples"]) == (90, 4.0, 60, 30, 37)
    assert fc["methods"] == list(default_methods()) and fc["units"]["N"] == "°/√h"
    ax0 = fc["axes"][0]
    assert "N" in ax0["terms"] and ax0["forecastable"]["N"] is True
    cell = ax0["cells"]["GM(1,1)"]["N"]
    assert set(cell) >= {"C", "P", "c_grade", "grade", "C_paper", "P_paper", "c_grade_paper", "grade_paper"}
    assert len(cell["forecast"]) == 30 and cell["rmse_over_se"] > 0
    json.dumps(s, allow_nan=False)  # JSON-able, no NaN/inf
    # the report's frames are allanite.frames with the report's τ rule (tau_range="auto")
    # 200 samples per frame hold too few octaves for five terms: the report then fits every τ
    with pytest.raises(ParameterError, match=r"usable τ \(octave-spaced\)"):
        allanite.frames(record[:, 0], FS, frame=4.0, unit="deg/s", tau_range="auto")
    same = allanite.frames(record[:, 0], FS, frame=4.0, unit="deg/s", tau_range="auto", thin=False)
    np.testing.assert_array_equal(np.array(ax0["values"]["N"]), same.values()["N"])


def test_report_text_page_and_figures(report):
    text = report.text()
    assert "Coefficient forecast (paper 004): 90 frames of 4 s, build 60 / check 30" in text
    assert "axis 0 N: GM(1,1) " in text and "improved GM(1,1) " in text and "Holt " in text
    specs = [sp[0] for sp in report.figure_specs()]
    assert {"frames_axis0.png", "forecast_axis0.png", "frames_axis1.png"} <= set(specs)
    html = report.html({})
    assert '<section id="forecast"><h2>Coefficient forecast</h2>' in html and 'href="#forecast"' in html
    assert re.search(r"so no model is given them: axis 0: .*; axis 1: [^<]*K \(at 0 in \d+ of 90 frames\)", html)
    assert report.summary()["forecast"]["axes"][1]["frames_at_zero"]["K"] > 0


def test_report_without_frames_has_no_forecast_section(record):
    rep = build_report(record[:6000, :1], FS, window=3000, hop=1500, fit=False)
    assert rep.summary()["forecast"] is None and 'id="forecast"' not in rep.html({})


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"forecast": "60"}, "forecast = '60' must be BUILD:CHECK"),
        ({"forecast": "a:b"}, "forecast = 'a:b' must be BUILD:CHECK"),
        ({"forecast": "3:30"}, "build = 3 frames; GM(1,1) needs at least 4"),
        ({"forecast": "60:1"}, "check = 1 frames; C and P need at least 2"),
        ({"frames": 0}, "frames = 0 must be a positive frame length"),
        ({"frames": "x"}, "frames = 'x' must be a frame length in seconds"),
        ({"frames": 4.0, "forecast": (60, 40)}, "forecast = 60:40 needs 100 frames, but the record (18037 samples)"),
    ],
)
def test_report_bad_forecast_options(record, kwargs, message):
    with pytest.raises(AllaniteError) as e:
        build_report(record[:, :1], FS, window=3000, hop=3000, fit=False, **kwargs)
    assert message in str(e.value)


@pytest.mark.parametrize(
    "extra, message",
    [
        (["--forecast", "3:30"], "allanite: error: forecast = '3:30': build = 3 frames; GM(1,1) needs at least 4\n"),
        (["--frames", "-2"], "allanite: error: frames = -2.0 must be a positive frame length in seconds\n"),
        (["--frames", "4", "--forecast", "60:40"], "forecast = 60:40 needs 100 frames, but the record"),
        (["--frames", "abc"], "argument --frames: invalid float value: 'abc'"),
    ],
)
def test_cli_forecast_errors_exit_2_with_one_line(tmp_path, record, capsys, extra, message):
    np.save(tmp_path / "log.npy", record[:, 0])
    rc = cli.main(["report", str(tmp_path / "log.npy"), "--fs", "50", "--no-fit", "--out", str(tmp_path / "o"), *extra])
    assert rc == 2
    err = capsys.readouterr().err
    assert err.startswith("allanite: error: ") and message in err and err.count("\n") == 1
    assert not (tmp_path / "o").exists()


def test_cli_report_with_forecast(tmp_path, record, capsys):
    np.save(tmp_path / "log.npy", record[:, 0])
    out = tmp_path / "o"
    rc = cli.main(
        ["report", str(tmp_path / "log.npy"), "--fs", "50", "--unit", "deg/s", "--window", "3000", "--hop", "3000"]
        + ["--forecast", "60:30", "--out", str(out)]
    )
    assert rc == 0
    printed = capsys.readouterr().out
    assert "Coefficient forecast (paper 004): 90 frames of 4 s" in printed  # record cut into 60 + 30 frames
    s = json.loads((out / "summary.json").read_text())
    assert s["forecast"]["frame_rule"] == "record cut into build + check = 90 frames"
    assert (out / "forecast_axis0.png").stat().st_size > 10_000
    assert dataclasses.is_dataclass(allanite.TimeFrames)
