"""IMU logs unlike the ADIS16405 as a new user runs them (r9review): a ``rostopic echo -p`` CSV of a sensor_msgs/Imu
(its ``field.header.frame_id`` text column stopped the reader, its REP 103 units were not taken, dropped packets left
a sliver analysed without saying its share), a EuRoC log's two reports warned of, the channel note's words, and a
constant axis's figures — each test a small record that failed before its fix."""

from __future__ import annotations

import numpy as np
import pytest

from allanite import read_log
from allanite.errors import InputError
from allanite.io._units import column_unit


def _rostopic_csv(path, n=400, fs=100.0, seed=5):
    rng = np.random.default_rng(seed)
    t = 1_600_000_000_000_000_000 + np.arange(n) * int(1e9 / fs)
    w, a = rng.normal(0, 1e-3, (n, 3)), rng.normal((0.0, 0.0, 9.81), 1e-2, (n, 3))
    head = (
        "%time,field.header.seq,field.header.stamp,field.header.frame_id,field.angular_velocity.x,"
        "field.angular_velocity.y,field.angular_velocity.z,field.linear_acceleration.x,"
        "field.linear_acceleration.y,field.linear_acceleration.z"
    )
    rows = [f"{t[i] + 7},{i},{t[i]},imu_link," + ",".join(f"{v:.9g}" for v in (*w[i], *a[i])) for i in range(n)]
    path.write_text(head + "\n" + "\n".join(rows) + "\n")
    return path, w


@pytest.mark.filterwarnings("ignore:.*count the rows")  # field.header.seq: its own test
def test_a_text_column_is_no_axis_and_rostopic_units_are_read(tmp_path):
    p, w = _rostopic_csv(tmp_path / "imu.csv")
    with pytest.warns(UserWarning, match=r"'field.header.frame_id' hold text \('imu_link' on the first data row\)"):
        log = read_log(p)
    assert "field.header.frame_id" not in log.columns and log.fs == 100.0
    assert log.groups["rad/s"] == [f"field.angular_velocity.{c}" for c in "xyz"]
    assert log.groups["m/s^2"] == [f"field.linear_acceleration.{c}" for c in "xyz"]
    gyro = log.take(log.groups["rad/s"])
    assert gyro.unit.name == "rad/s" and "REP 103" in gyro.unit_source
    np.testing.assert_allclose(gyro.data, w, rtol=1e-8)
    with pytest.raises(InputError, match=r"'imu_link' is not a number"):  # asked for by name: still refused
        read_log(p, columns=["field.header.frame_id", "field.angular_velocity.x"])


def test_rostopic_field_units():
    assert column_unit("field.angular_velocity.z").name == "rad/s"
    assert column_unit("field.linear_acceleration.x").name == "m/s^2"
    assert column_unit("field.orientation.x") is None and column_unit("field.angular_velocity.w") is None


def test_a_stretch_far_shorter_than_the_log_is_said(tmp_path, capsys):
    # 2 % dropped packets: --gaps longest analysed 0.3 % of a 20-minute ROS log and said only "samples a–b of n"
    from allanite import cli

    p, _ = _rostopic_csv(tmp_path / "imu.csv", n=3000)
    lines = p.read_text().splitlines()
    keep = [ln for k, ln in enumerate(lines) if k == 0 or k % 50 != 7]  # every 50th row dropped: gaps of one sample
    p.write_text("\n".join(keep) + "\n")
    args = ["report", str(p), "--columns", "field.angular_velocity.x", "--gaps", "longest", "--no-fit"]
    assert cli.main([*args, "--out", str(tmp_path / "o")]) == 0
    printed = capsys.readouterr().out
    assert "60 gap(s); only the longest gap-free stretch, samples 6–54 of 2940, is analysed" in printed
    assert "— 1.7 % of the log: its gaps are many or long, each result is of this stretch alone" in printed
    assert "(--gaps split lists every stretch)" in printed
    assert "Time column '%time' was read in ns, the unit its name gives" in printed and "ends in" not in printed


def test_the_channel_note_says_the_coefficient_is_per_the_channels_unit(monkeypatch):
    # the note read "its regression on other channels, which the channels imply; a channel's unit is not known to
    # allanite" beside a column named temp [degC] — as if the coefficient's unit were unknowable
    from allanite.report import _sections

    class Progress:
        def step(self, what):
            pass

    monkeypatch.setattr(_sections, "refine_axes", lambda *a: [None])  # the note, not the refinement, is tested
    notes: list = []
    settings: dict = {}
    asked = (("regression",), ["temp [degC]"])
    out = _sections.refinement_section(None, 10.0, "rate", "deg/s", None, ["gx"], asked, notes, settings, Progress())
    assert out == [None] and settings["channels"] == ["temp [degC]"]
    assert notes == [
        "Channel temp [degC] passed to every axis's model refinement, for its regression on it; a coefficient is "
        "per unit of the channel's samples, as logged (its name's unit, where it gives one, e.g. [degC]): allanite "
        "converts no channel's unit."
    ]


def test_an_imu_logs_two_reports_are_no_warning(tmp_path, capsys):
    # EuRoC's gyro and accelerometer, every column taken, were also printed as "allanite: warning: columns …"
    from allanite import cli

    rng = np.random.default_rng(4)
    t = 1_403_636_579_758_555_392 + np.arange(1000) * 5_000_000
    p = _csv_rows(tmp_path / "data.csv", "#timestamp [ns],w_RS_S_x [rad s^-1],a_RS_S_x [m s^-2]", t, rng)
    assert cli.main(["report", str(p), "--no-fit", "--out", str(tmp_path / "o")]) == 0
    out, err = capsys.readouterr()
    assert "a_RS_S_x [m s^-2] in m/s^2 in a report of their own (accelerometer/report.html)" in out
    assert "warning" not in err


def _csv_rows(path, header, t, rng):
    rows = [f"{s}," + ",".join(f"{v:.6g}" for v in rng.normal(size=header.count(","))) for s in t]
    path.write_text(header + "\n" + "\n".join(rows) + "\n")
    return path


def test_a_constant_axis_draws_its_figures_without_matplotlibs_warnings():
    # a logged axis that never moves (an unused channel; a simulator's constant accelerometer) printed
    # matplotlib's "Data has no positive values, and therefore cannot be log-scaled" twice per figure
    import warnings

    from allanite.report import build_report
    from allanite.report.rendering import png

    x = np.c_[np.random.default_rng(1).normal(size=1200), np.full(1200, 9.81)]
    rep = build_report(x, 100.0, window=300, hop=100, progress=False)
    assert any("Allan variance of zero at every τ" in n for n in rep.summary()["notes"])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        drawn = [png(spec, 40) for spec in rep.figure_specs()]
    assert len(drawn) >= 5 and all(d.startswith(b"\x89PNG") for d in drawn)


def test_a_dropped_packet_reads_as_one_sample_of_the_step(tmp_path):
    # a ROS log's dropped packets were listed as "0.00999998 s (≈1 samples) missing" (a ns epoch stamp's rounding)
    from allanite.errors import DataGapError

    p, _ = _rostopic_csv(tmp_path / "imu.csv", n=400)
    lines = p.read_text().splitlines()
    p.write_text("\n".join(lines[:101] + lines[102:]) + "\n")  # data row 100 dropped
    with pytest.raises(
        DataGapError, match=r"1 gap\(s\).*: 0\.01 s \(≈1 sample\) missing after sample 99 at t = 0\.99 s"
    ):
        read_log(p, columns=["field.angular_velocity.x"])
