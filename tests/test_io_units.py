"""Other people's logs read straight from the file (r9io): units from the column names (EuRoC / TUM-VI / Kalibr
``w_RS_S_x [rad s^-1]``, ``(deg/s)``, ``_dps``, ``[g]`` …), gyro and accelerometer columns apart, ``unit=`` winning
over a header it contradicts; time columns whose unit nothing names read by the plausibility rule (epoch
magnitudes, a span no log has, a rate under 1 Hz); and the streamed text reader's values equal to NumPy's."""

from __future__ import annotations

import gzip
import warnings

import numpy as np
import pytest

from allanite import InputError, ParameterError, read_log
from allanite.cli import gyro_columns
from allanite.io import _text
from allanite.io._units import column_unit

EUROC = (
    "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
    "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]"
)


def _euroc(path, n=2000, fs=200.0):
    rng = np.random.default_rng(5)
    t = 1403636579758555392 + np.arange(n, dtype=np.int64) * int(1e9 / fs)
    w = rng.normal(0.0, 0.01, (n, 3))
    a = rng.normal(0.0, 0.05, (n, 3)) + [9.81, 0.0, 0.0]
    rows = [
        f"{t[i]},{float(w[i, 0])!r},{float(w[i, 1])!r},{float(w[i, 2])!r},{float(a[i, 0])!r},{float(a[i, 1])!r},{float(a[i, 2])!r}"
        for i in range(n)
    ]
    path.write_text(EUROC + "\n" + "\n".join(rows) + "\n")
    return path, w, a


def _csv(path, header, t, x, tfmt="%d"):
    cols = np.column_stack([t, x])
    np.savetxt(path, cols, delimiter=",", header=header, comments="", fmt=[tfmt] + ["%.6g"] * (cols.shape[1] - 1))
    return path


@pytest.mark.parametrize(
    ("name", "unit", "kind"),
    [
        ("w_RS_S_x [rad s^-1]", "rad/s", "rate"),
        ("a_RS_S_y [m s^-2]", "m/s^2", "acceleration"),
        ("gyro_x [rad/s]", "rad/s", "rate"),
        ("gx (deg/s)", "deg/s", "rate"),
        ("gz_dps", "deg/s", "rate"),
        ("wx [°/s]", "deg/s", "rate"),
        ("gy [mdps]", "mdeg/s", "rate"),
        ("rate (µrad/s)", "urad/s", "rate"),
        ("acc_z [g]", "g", "acceleration"),
        ("ax [m.s-2]", "m/s^2", "acceleration"),
        ("ay [m·s⁻²]", "m/s^2", "acceleration"),
        ("acc_x_mps2", "m/s^2", "acceleration"),
        ("dtheta [rad]", "rad", "angle"),
    ],
)
def test_the_grammar_reads_units_from_names(name, unit, kind):
    cu = column_unit(name)
    assert cu is not None and (cu.name, cu.kind) == (unit, kind)


@pytest.mark.parametrize("name", ["gx", "T [degC]", "x [counts]", "t [ms]", "gyro_x", "a [LSB]", "dps"])
def test_names_without_a_unit_give_none(name):
    assert column_unit(name) is None


def test_euroc_columns_are_grouped_by_their_units(tmp_path):
    p, w, a = _euroc(tmp_path / "imu0.csv")
    log = read_log(p)
    assert log.fs == 200.0 and log.time_unit == "ns" and log.data.shape == (2000, 6)
    assert log.unit is None  # two kinds in one block: no one unit for all
    assert list(log.groups) == ["rad/s", "m/s^2"] and log.groups["rad/s"][0] == "w_RS_S_x [rad s^-1]"
    assert "rad/s: w_RS_S_x [rad s^-1]" in repr(log) and "m/s^2: a_RS_S_x [m s^-2]" in repr(log)
    gyro = log.take(log.groups["rad/s"])
    assert gyro.unit.name == "rad/s" and gyro.unit_source == "from the column names: [rad s^-1]"
    assert np.array_equal(gyro.data, w) and "unit: rad/s (rate; from the column names: [rad s^-1])" in repr(gyro)
    acc = log.take(log.groups["m/s^2"])
    assert acc.unit is None and np.array_equal(acc.data, a) and [c.name for c in acc.column_units] == ["m/s^2"] * 3
    one = log.take("w_RS_S_y [rad s^-1]")
    assert one.data.shape == (2000,) and one.unit.name == "rad/s"
    with pytest.raises(ParameterError, match="'gx' is not one of the log's columns"):
        log.take(["gx"])


def test_the_cli_analyses_the_gyro_columns_in_their_unit(tmp_path):
    p, w, _ = _euroc(tmp_path / "imu0.csv")
    gyro, note = gyro_columns(read_log(p))
    assert gyro.columns == [f"w_RS_S_{k} [rad s^-1]" for k in "xyz"] and gyro.unit.name == "rad/s"
    assert np.array_equal(gyro.data, w)
    assert "chosen by the rate unit their names give (rad/s)" in note and "a_RS_S_x [m s^-2] (m/s^2)" in note
    # one unit for every column: analysed whole, no note
    q = tmp_path / "g.csv"
    _csv(q, "time_ms,gx [deg/s],gy [deg/s]", np.arange(50) * 10, np.ones((50, 2)))
    log = read_log(q)
    assert log.unit.name == "deg/s" and log.fs == 100.0 and gyro_columns(log) == (log, None)


def test_given_unit_wins_over_a_contradicting_header(tmp_path):
    p, _, _ = _euroc(tmp_path / "imu0.csv", n=200)
    with pytest.warns(UserWarning, match=r"unit='deg/s' was given, but the header names another unit .*rad/s"):
        log = read_log(p, unit="deg/s", columns=["w_RS_S_x [rad s^-1]", "w_RS_S_y [rad s^-1]"])
    assert log.unit.name == "deg/s" and log.unit_source == "given as unit=, overriding the header's rad/s"
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # agreeing: nothing to say
        same = read_log(p, unit="rad/s", columns=["w_RS_S_x [rad s^-1]"])
    assert same.unit.name == "rad/s" and same.unit_source == "given as unit="
    kept = log.take("w_RS_S_y [rad s^-1]")  # a given unit stays given
    assert kept.unit.name == "deg/s" and kept.unit_source.startswith("given as unit=")
    assert kept.column_units[0].name == "rad/s"


@pytest.mark.parametrize(("unit", "scale"), [("s", 1.0), ("ms", 1e3), ("us", 1e6), ("ns", 1e9)])
def test_epoch_magnitudes_name_their_unit(tmp_path, unit, scale):
    t = np.round((1.7e9 + np.arange(300) / 100.0) * scale, 6)
    p = _csv(tmp_path / "e.csv", "time,gx", t, np.ones(300), tfmt="%.6f" if unit == "s" else "%d")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        log = read_log(p)
    assert log.fs == 100.0 and log.time_unit == unit and abs(log.t0 - 1.7e9) < 1e-3
    assert log.time_unit_source == "epoch magnitude"
    assert f"in {unit} (read from its epoch magnitude)" in repr(log)


def test_ms_relative_time_warns_and_time_unit_fixes_it(tmp_path):
    # 0, 10, 20 … ms at 100 Hz: read as seconds it was fs = 0.1 Hz, "55.6 h", silently
    p = _csv(tmp_path / "ms.csv", "time,gx", np.arange(20_000) * 10, np.zeros(20_000))
    with pytest.warns(
        UserWarning,
        match=r"'time' names no unit .* step 10 \(integer steps\) gives fs = 0\.1 Hz.*"
        r"in ms: 100 Hz.*time_unit='ms' \(--time-unit ms",
    ):
        log = read_log(p)
    assert log.fs == 0.1 and log.time_unit_source == "default"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert read_log(p, time_unit="ms").fs == 100.0
        assert read_log(p, time_unit="s").fs == 0.1  # seconds said: no warning


def test_a_span_no_log_has_is_an_error(tmp_path):
    # ns from boot at 100 Hz, 2·10⁴ rows: 2·10¹¹ "s", 6000 years
    p = _csv(tmp_path / "ns.csv", "time,gx", 5e11 + np.arange(20_000) * 1e7, np.zeros(20_000))
    with pytest.raises(
        InputError, match=r"'time' spans 1\.9999e\+11 .*6\.34e\+03 years read as seconds.*in ns: 100 Hz.*time_unit='ns'"
    ):
        read_log(p)
    assert read_log(p, time_unit="ns").fs == 100.0
    # ns from boot at 10¹² (16 min), 200 Hz: epoch ms by magnitude, but 0.2 Hz so: not taken, an error again
    q = _csv(tmp_path / "boot.csv", "time,gx", 1e12 + np.arange(20_000) * 5e6, np.zeros(20_000))
    with pytest.raises(InputError, match=r"in ns: 200 Hz.*time_unit='ns'"):
        read_log(q)
    # a few rows of the same: no error (a short span), but the stamps over 10¹¹ s are said
    r = _csv(tmp_path / "short.csv", "time,gx", 1e12 + np.arange(50) * 5e6, np.zeros(50))
    with pytest.warns(UserWarning, match=r"reads 1\.00024e\+12 s \(over 3000 years\) as seconds.*time_unit='ns'"):
        read_log(r)


def test_slow_or_short_logs_in_seconds_say_nothing(tmp_path):
    # the false-alarm side: a 1 Hz logger in whole seconds over 5.6 h, a short 0.1 Hz log, a 100 Hz log
    cases = [(np.arange(20_000), 1.0), (np.arange(500) * 10.0, 0.1), (np.arange(20_000) / 100.0, 100.0)]
    for k, (t, fs) in enumerate(cases):
        p = _csv(tmp_path / f"s{k}.csv", "time,gx", t, np.zeros(t.size), tfmt="%.2f")
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            log = read_log(p)
        assert log.fs == fs and log.time_unit == "s" and log.time_unit_source == "default"
        assert "in s (by default: neither its name nor an epoch magnitude gives one)" in repr(log)


@pytest.mark.parametrize(("gz", "hint"), [(False, None), (True, None), (False, 16), (True, 16)])
def test_the_streamed_body_is_numpys_bit_for_bit(tmp_path, monkeypatch, gz, hint):
    """Pieces of 1 kB (not 4 MiB): lines cut at piece ends, comments and CRLF; the arrays cut to the rows read,
    or grown where the rows outnumber the hint (16)."""
    monkeypatch.setattr(_text, "CHUNK_BYTES", 1000)
    if hint is not None:
        monkeypatch.setattr(_text._Text, "rows_hint", lambda self, offset: hint)
    rng = np.random.default_rng(2)
    x = rng.normal(size=(3000, 2)) * [1e-3, 1e4]
    lines = ["t,a,b"] + [f"{i / 50:.2f},{float(a)!r},{b:.9g}" for i, (a, b) in enumerate(x)]
    lines[700] += "  # a comment"
    lines.insert(1500, "# a comment line")
    raw = ("\r\n".join(lines) + "\r\n").encode("ascii")
    assert len(raw) > _text.HEAD_CHARS
    p = tmp_path / ("s.csv.gz" if gz else "s.csv")
    p.write_bytes(gzip.compress(raw) if gz else raw)
    log = read_log(p, time_column="t")
    ref = np.loadtxt(lines[1:], delimiter=",")
    assert log.data.shape == (3000, 2) and np.array_equal(log.data.view(np.uint64), ref[:, 1:].view(np.uint64))
    assert log.fs == 50.0 and log.t0 == 0.0 and np.array_equal(log.time, ref[:, 0] - ref[0, 0])
    assert log.data.flags.owndata and log.data.base is None  # exactly the rows: no view of a larger block
    one = read_log(p, time_column="t", columns="b")
    assert one.data.shape == (3000,) and np.array_equal(one.data, ref[:, 2])


def test_kalibr_takes_the_accelerometer_unit_the_header_gives(tmp_path):
    """``--kalibr --accel-columns`` without ``--accel-unit``: an accelerometer in g by its names ([g]) is written
    in SI (×9.80665; taken as m/s² before, 9.8× too small)."""
    import argparse
    import re
    import types

    from allanite import avar, fit
    from allanite.cli import _kalibr

    rng = np.random.default_rng(11)
    n = 20_000
    gyro = 1e-3 * np.sqrt(100.0) * rng.standard_normal((n, 3))  # rad/s, density 1e-3 rad/s/√Hz
    acc = 2e-3 * np.sqrt(100.0) * rng.standard_normal((n, 3)) / 9.80665  # g, density 2e-3 m/s²/√Hz
    p = _csv(
        tmp_path / "imu.csv",
        "t,gx [rad/s],gy [rad/s],gz [rad/s],ax [g],ay [g],az [g]",
        np.arange(n) / 100.0,
        np.c_[gyro, acc],
        tfmt="%.2f",
    )
    log = read_log(p).take(["gx [rad/s]", "gy [rad/s]", "gz [rad/s]"])
    assert log.unit.name == "rad/s"
    rep = types.SimpleNamespace(unit="rad/s", fits=fit(avar(log.data, log.fs), unit="rad/s"), fs=log.fs)
    args = argparse.Namespace(
        kalibr=str(tmp_path / "imu.yaml"), accel_columns="ax [g],ay [g],az [g]", log=str(p), time_unit=None,
        fs=None, time_column=None, gaps=None, kalibr_aggregate="worst", accel_unit=None,
    )  # fmt: skip
    text = _kalibr(args, rep, types.SimpleNamespace(step=lambda *a: None)).read_text()
    density = float(re.search(r"accelerometer_noise_density: ([0-9.e+-]+)", text).group(1))
    assert density == pytest.approx(2e-3, rel=0.1) and "samples in g" in text


def test_a_long_log_with_a_utf8_header_is_read_from_its_head(tmp_path):
    """``[°/s]`` in the header: the head decodes alone (UTF-8), the body streams — the unit and NumPy's values."""
    rng = np.random.default_rng(4)
    x = rng.normal(size=(5000, 2))
    lines = ["t,wx [°/s],wy [°/s]"] + [f"{i / 100:.2f},{a:.6f},{b:.6f}" for i, (a, b) in enumerate(x)]
    p = tmp_path / "deg.csv"
    p.write_bytes(("\n".join(lines) + "\n").encode("utf-8"))
    assert p.stat().st_size > _text.HEAD_CHARS
    doc = _text._Text.open(p, gz=False)
    assert doc.head()[0][0] == lines[0] and doc.byte_offset(1) == len(lines[0].encode("utf-8")) + 1
    assert "raw" not in doc.__dict__ and "_decoded" not in doc.__dict__  # the file was not read whole
    log = read_log(p)
    assert log.unit.name == "deg/s" and log.unit_source == "from the column names: [°/s]" and log.fs == 100.0
    assert np.array_equal(log.data, np.loadtxt(lines[1:], delimiter=",")[:, 1:])


def test_time_unit_with_fs_and_no_time_column_is_an_error(tmp_path, capsys):
    # read_log(p, fs=100, time_unit="ms", columns=["gx"]) read no time column and dropped time_unit silently
    from allanite import cli

    p = _csv(tmp_path / "ms.csv", "t,gx", np.arange(500) * 10, np.zeros(500))
    with pytest.raises(ParameterError, match=r"time_unit='ms' .* fs=100 without time_column= reads no time column"):
        read_log(p, fs=100, time_unit="ms", columns=["gx"])
    assert issubclass(ParameterError, ValueError)
    # with the time column named, the unit is used: its stamps (10 ms apart) agree with fs, no gap
    log = read_log(p, fs=100, time_column="t", time_unit="ms", columns=["gx"])
    assert log.fs == 100.0 and log.time_unit == "ms" and log.time_unit_source == "time_unit="
    assert read_log(p, fs=100, columns=["gx"]).time_unit is None  # neither given: no time column read, no error
    out = tmp_path / "o"
    args = ["report", str(p), "--fs", "100", "--time-unit", "ms", "--columns", "gx", "--no-fit", "--out", str(out)]
    assert cli.main(args) == 2
    err = capsys.readouterr().err
    assert "--time-unit ms is the unit of a time column, but --fs 100 without --time-column reads no time" in err
    assert not out.exists()
