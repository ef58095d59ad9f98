"""An IMU log's gyro and accelerometer in one ``allanite report``: each in its own unit (r9acc). A log whose column
names give a gyro's and an accelerometer's units (EuRoC, TUM-VI) gets the gyro's report where it always was and the
accelerometer's in ``accelerometer/`` — Allan deviation in m/s², velocity random walk in m/s/√h, bias instability in
µg, acceleration random walk in m/s/h^1.5; names without units (the ADIS16405's ``acc_x``) stay as before."""

from __future__ import annotations

import json
import math
import re
import warnings

import numpy as np
import pytest

from allanite import cli
from allanite._cli_columns import sensor_columns
from allanite.errors import ParameterError
from allanite.io import read_log
from allanite.report import build_report
from allanite.report.build import log_accel_unit
from allanite.report.result import Report
from allanite.units import STANDARD_GRAVITY, accel_report_unit

FS = 200.0
N_GYRO = 2e-3  # rad/s·√s (angle random walk)
N_ACC = 2e-3  # m/s²·√s (velocity random walk): 0.12 m/s/√h


def _euroc(path, n=6_000, seed=7, axes="xyz"):
    """An EuRoC-style imu0.csv: ns stamps, the gyro's rad/s and the accelerometer's m/s² (gravity on z), white."""
    rng = np.random.default_rng(seed)
    t = 1_403_636_579_758_555_392 + (np.arange(n) * (1e9 / FS)).astype(np.int64)
    w = rng.standard_normal((n, len(axes))) * N_GYRO * math.sqrt(FS)
    a = rng.standard_normal((n, len(axes))) * N_ACC * math.sqrt(FS) + np.r_[[0.0] * (len(axes) - 1), 9.81]
    head = ["#timestamp [ns]", *(f"w_RS_S_{k} [rad s^-1]" for k in axes), *(f"a_RS_S_{k} [m s^-2]" for k in axes)]
    with open(path, "w") as f:
        f.write(",".join(head) + "\n")
        for i in range(n):
            f.write(f"{t[i]}," + ",".join(f"{v:.9g}" for v in (*w[i], *a[i])) + "\n")
    return path


@pytest.fixture
def no_figures(monkeypatch):
    """The report's files without its PNGs (drawing them is a second a report; the numbers are the subject)."""
    monkeypatch.setattr(Report, "figure_specs", lambda self: [])
    monkeypatch.setattr(cli, "start_figure_worker", lambda: False)


def _inside(c, truth, k=2.0):
    """Whether ``truth`` lies in the coefficient's 68.3 % interval (IEEE units) widened ``k`` times about the value:
    k = 2 is about 95 % — six axes' 68.3 % intervals all hold the truth only 1 time in 10."""
    v, (lo, hi) = c["ieee"], c["ieee_ci"]
    return v - k * (v - lo) <= truth <= v + k * (hi - v)


def test_accelerometer_units():
    assert accel_report_unit("N", 0.002, "m/s^2") == (pytest.approx(0.12), "m/s/√h")
    assert accel_report_unit("vrw", 1.0, "m/s^2", to="m/s/sqrt(s)").value == 1.0
    b = accel_report_unit("B", 3e-5, "g")
    assert b.unit == "µg" and b.value == pytest.approx(30.0)
    assert accel_report_unit("B", 3e-5, "g", to="mg").value == pytest.approx(0.03)
    assert accel_report_unit("B", STANDARD_GRAVITY * 1e-6, "m/s^2").value == pytest.approx(1.0)
    assert accel_report_unit("K", 1e-6, "m/s^2") == (pytest.approx(0.216), "m/s/h^1.5")
    assert accel_report_unit("R", 1e-7, "mg").value == pytest.approx(1e-7 * 1e-3 * STANDARD_GRAVITY * 3600.0**2)
    assert accel_report_unit("N", 1e-3, "m/s^2", to="ug/sqrt(Hz)").value == pytest.approx(1e-3 / 9.80665e-6)
    with pytest.raises(ParameterError, match=r"noise term 'arw'; allowed: 'Q' \(velocity quantization\)"):
        accel_report_unit("arw", 1.0, "g")  # a gyro's angle random walk is no accelerometer term
    with pytest.raises(ParameterError, match=r"report unit 'deg/h' for term B; allowed: ug, mg, m/s\^2"):
        accel_report_unit("B", 1.0, "g", to="deg/h")
    with pytest.raises(ParameterError, match=r"accelerometer unit 'deg/s'"):
        accel_report_unit("N", 1.0, "deg/s")


def test_build_report_in_an_accelerometer_unit_gives_its_terms():
    rng = np.random.default_rng(3)
    n_g = 5e-5  # g·√s: VRW 5e-5 · 9.80665 · 60 = 0.0294 m/s/√h
    x = rng.standard_normal((8_000, 1)) * n_g * math.sqrt(FS)
    rep = build_report(x, FS, unit="g", axis_names=["acc_x"], window=2_000, hop=1_000, progress=False)
    assert rep.unit is None and rep.accel_unit == "g" and rep.adev_unit == "g"
    s = rep.summary()
    assert s["fit"]["sensor"] == "accelerometer" and s["record"]["accel_unit"] == "g"
    c = s["fit"]["axes"][0]["coefficients"]
    assert c["N"]["name"] == "velocity random walk" and c["N"]["ieee_unit"] == "m/s/√h"
    assert _inside(c["N"], n_g * STANDARD_GRAVITY * 60.0, k=1.0)
    assert c["N"]["ieee"] == pytest.approx(n_g * STANDARD_GRAVITY * 60.0, rel=0.03)
    assert c["B"]["ieee_unit"] == "µg" and c["K"]["ieee_unit"] == "m/s/h^1.5" and c["N"]["unit"] == "(g)·√s"
    text = rep.text()
    assert "unit g (an accelerometer's)" in text and "Noise model (IEEE 952) in the accelerometer's units" in text
    assert "N velocity random walk     m/s/√h" in text and "unknown" not in text
    with pytest.raises(ParameterError, match=r"unit 'g' is an accelerometer's, analysed as rate input only"):
        build_report(x, FS, unit="g", input="increment", progress=False)


def test_report_writes_the_gyro_and_the_accelerometer_each_in_its_unit(tmp_path, capsys, no_figures):
    log = _euroc(tmp_path / "imu0.csv")
    out = tmp_path / "out"
    assert cli.main(["report", str(log), "--window", "1200", "--hop", "600", "--out", str(out)]) == 0
    console = capsys.readouterr().out
    gyro = json.loads((out / "summary.json").read_text())
    acc = json.loads((out / "accelerometer" / "summary.json").read_text())
    assert gyro["record"]["axis_names"] == [f"w_RS_S_{k} [rad s^-1]" for k in "xyz"] and gyro["unit"] == "rad/s"
    assert gyro["record"]["source"]["accelerometer_report"] == "accelerometer/report.html"
    arw = N_GYRO * 180.0 / math.pi * 60.0  # °/√h
    assert all(_inside(ax["coefficients"]["N"], arw) for ax in gyro["fit"]["axes"])
    assert acc["record"]["axis_names"] == [f"a_RS_S_{k} [m s^-2]" for k in "xyz"]
    assert acc["record"]["accel_unit"] == "m/s^2" and acc["record"]["adev_unit"] == "m/s²" and acc["unit"] is None
    for ax in acc["fit"]["axes"]:
        n = ax["coefficients"]["N"]
        assert n["ieee_unit"] == "m/s/√h" and _inside(n, N_ACC * 60.0), n
        assert ax["coefficients"]["B"]["ieee_unit"] == "µg"
    assert 'href="accelerometer/report.html"' in (out / "report.html").read_text()
    page = (out / "accelerometer" / "report.html").read_text()
    assert "m/s^2 (an accelerometer" in page and 'href="../report.html"' in page  # ' escaped; the gyro's linked
    # the console: both summaries, both reports listed
    assert "unit rad/s, rate input" in console and "unit m/s^2 (an accelerometer's), rate input" in console
    assert f"wrote {out / 'report.html'}" in console
    assert f"the accelerometer's report: {out / 'accelerometer' / 'report.html'}" in console


def test_refine_runs_on_both(tmp_path, no_figures):
    log = _euroc(tmp_path / "imu0.csv", n=2_000, axes="z")
    out = tmp_path / "out"
    argv = ["report", str(log), "--window", "500", "--hop", "250", "--refine-candidates", "none", "-q"]
    assert cli.main([*argv, "--out", str(out)]) == 0
    for summary in (out / "summary.json", out / "accelerometer" / "summary.json"):
        ref = json.loads(summary.read_text())["refinement"]
        assert ref is not None and len(ref["axes"]) == 1


def _adis(path, n=4_000, n_acc=1e-4):
    """The ADIS16405's layout (t, gyro_*, acc_*, no units in the names) at 100 Hz: the accelerometer's white
    noise ``n_acc`` g·√s."""
    rng = np.random.default_rng(5)
    g, a = rng.normal(size=(n, 3)) * 0.01, rng.normal(size=(n, 3)) * n_acc * 10.0 + [0.0, 0.0, 1.0]
    np.savetxt(path, np.c_[np.arange(n) / 100.0, g, a], delimiter=",", comments="", fmt="%.9g",
               header="t,gyro_x,gyro_y,gyro_z,acc_x,acc_y,acc_z")  # fmt: skip
    return path


def test_names_without_units_keep_the_gyro_alone(tmp_path):
    """Without a unit for each, the gyro's columns only, as before (an --accel-unit without the gyro's --unit too)."""
    log = read_log(_adis(tmp_path / "adis.csv", n=400), time_column="t")
    for accel_unit in (None, "g"):
        gyro, accel, note = sensor_columns(log, accel_unit)
        assert accel is None and gyro.columns == ["gyro_x", "gyro_y", "gyro_z"]
        assert note.startswith("columns gyro_x, gyro_y, gyro_z analysed, chosen by their names (gyro); left out: acc_x")


def test_a_unit_given_for_each_reports_both(tmp_path, capsys, no_figures):
    p, out = _adis(tmp_path / "adis.csv"), tmp_path / "out"
    argv = ["report", str(p), "--time-column", "t", "--unit", "deg/s", "--window", "1000", "--hop", "500"]
    assert cli.main([*argv, "--accel-unit", "g", "-q", "--out", str(out)]) == 0
    acc = json.loads((out / "accelerometer" / "summary.json").read_text())
    assert acc["record"]["axis_names"] == ["acc_x", "acc_y", "acc_z"] and acc["record"]["accel_unit"] == "g"
    assert acc["record"]["source"]["unit"] is None  # the gyro's --unit is not the accelerometer's
    for ax in acc["fit"]["axes"]:
        assert _inside(ax["coefficients"]["N"], 1e-4 * STANDARD_GRAVITY * 60.0), ax["coefficients"]["N"]
    gyro = json.loads((out / "summary.json").read_text())
    assert gyro["record"]["axis_names"] == ["gyro_x", "gyro_y", "gyro_z"] and gyro["unit"] == "deg/s"
    assert "acc_x, acc_y, acc_z in g in a report of their own (accelerometer/report.html)" in gyro["notes"][0]
    # the gyro's --unit alone: its report only, as before
    assert cli.main([*argv, "-q", "--out", str(tmp_path / "one")]) == 0
    assert not (tmp_path / "one" / "accelerometer").exists()


def test_a_given_gyro_unit_is_not_the_accelerometers(tmp_path):
    """--unit rad/s on an EuRoC log is the gyro's: the accelerometer's columns keep the m/s² their names give."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the header names m/s^2 for the a_ columns: said by read_log
        log = read_log(_euroc(tmp_path / "imu0.csv", n=400), unit="rad/s")
    gyro, accel, _ = sensor_columns(log)
    assert gyro.unit.name == "rad/s" and accel.unit is None and log_accel_unit(accel) == "m/s^2"


def test_kalibr_takes_the_accelerometer_report_fits(tmp_path, no_figures):
    """--kalibr on an EuRoC log: imu.yaml's accelerometer noise from the accelerometer's report (no --accel-columns)."""
    log, out, yml = _euroc(tmp_path / "imu0.csv"), tmp_path / "out", tmp_path / "imu.yaml"
    argv = ["report", str(log), "--window", "1200", "--hop", "600", "--kalibr", str(yml), "-q", "--out", str(out)]
    assert cli.main(argv) == 0
    text = yml.read_text()
    density = float(re.search(r"accelerometer_noise_density: ([0-9.e+-]+)", text).group(1))  # m/s²/√Hz
    gyro_density = float(re.search(r"gyroscope_noise_density: ([0-9.e+-]+)", text).group(1))  # rad/s/√Hz
    assert density == pytest.approx(N_ACC, rel=0.05) and gyro_density == pytest.approx(N_GYRO, rel=0.05)
    assert (out / "accelerometer" / "summary.json").exists()
