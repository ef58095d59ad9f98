"""The ``allanite`` command line: options, log formats, units, quiet/progress, errors and help.

The full report on the bundled record and on a real ADIS16405 run is in test_report.py; these tests
use small logs so that each runs in a second or two.
"""

from __future__ import annotations

import io
import json
import re
import shutil
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")

import matplotlib.image as mpimg  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import allanite  # noqa: E402
from allanite import cli  # noqa: E402


def check_png(path, min_h=200, min_w=300):
    img = mpimg.imread(path)  # decodes the PNG: fails on a truncated or non-PNG file
    assert img.ndim == 3 and img.shape[2] in (3, 4)
    assert img.shape[0] >= min_h and img.shape[1] >= min_w
    assert img.dtype == np.float32 and 0.0 <= img.min() and img.max() <= 1.0
    assert np.ptp(img[..., :3]) > 0.5  # not a blank canvas
    return img


@pytest.fixture
def npy_log(tmp_path, rng):
    y = rng.normal(size=6_000) * 0.02 + 0.1
    path = tmp_path / "gyro.npy"
    np.save(path, y)
    return path, y


SMALL = ["--window", "1200", "--hop", "300"]  # 17 windows: quick fits and figures


# ------------------------------------------------------------------------------------------------
# logs, options and what the report says about them


def test_report_on_a_npy_log(tmp_path, npy_log, capsys):
    log, y = npy_log
    out = tmp_path / "out"
    rc = cli.main(["report", str(log), "--fs", "50", *SMALL, "--unit", "rad/s", "--out", str(out)])
    assert rc == 0
    captured = capsys.readouterr()
    printed = captured.out
    assert captured.err == ""
    # stdout is no terminal here: a line per step as it starts, then the summary (issue 32)
    stages = printed[: printed.index("allanite report: gyro.npy")].splitlines()
    assert [line.split("] ", 1)[1] for line in stages[:4]] == [
        "reading gyro.npy",
        "static Allan deviation",
        "dynamic Allan variance",  # before the intervals: a figure process can draw the DAVAR meanwhile
        "confidence intervals",
    ]
    assert all(line.startswith("[") and " s] " in line for line in stages)
    assert stages[-1].endswith("] writing report.html, summary.json")
    assert "6000 samples × 1 axis (col0) at 50 Hz" in printed and "unit rad/s" in printed
    assert "Overlapping Allan deviation (rad/s)" in printed
    assert "Dynamic Allan deviation: window 1200 samples (24 s, given), hop 300 (6 s, given)" in printed
    summary = json.loads((out / "summary.json").read_text())
    assert (summary["fs_hz"], summary["samples"], summary["axes"], summary["unit"]) == (50.0, 6_000, 1, "rad/s")
    assert summary["record"]["source"]["format"] == "npy" and summary["record"]["source"]["fs_from"] == "given"
    r = allanite.avar(y, 50.0, taus="octave")
    np.testing.assert_array_equal(summary["static"]["tau_s"], r.tau)
    np.testing.assert_array_equal(summary["static"]["adev"], [r.adev])
    d = allanite.davar(y, 50.0, window=1200, hop=300, taus="exp")
    assert summary["dynamic"]["windows"] == d.t.size == 17
    row = d.adev[0]
    ax = summary["dynamic"]["axes"][0]
    assert ax["adev_shortest_tau_median"] == float(np.median(row))
    assert ax["adev_shortest_tau_max"] == float(row.max()) and ax["t_of_max_s"] == float(d.t[row.argmax()])
    # coefficients in rad-based units: base form rad/√s, IEEE-952 °/√h
    n = summary["fit"]["axes"][0]["coefficients"]["N"]
    assert (n["unit"], n["ieee_unit"]) == ("rad/√s", "°/√h")
    assert n["ieee"] == pytest.approx(n["value"] * 180 / np.pi * 60, rel=1e-12)
    f = allanite.fit(allanite.avar(y[:, None], 50.0), unit="rad/s")[0]
    assert n["value"] == f.coefficients["N"].value and n["ieee"] == f.coefficients["N"].ieee
    for name in (
        "adev.png",
        "davar.png",
        "adev_axis0.png",
        "davar3d_axis0.png",
        "coefficients.png",
    ):
        check_png(out / name)
    assert str(out / "report.html") in printed


def test_report_on_a_csv_log_with_named_columns(tmp_path, rng):
    X = rng.normal(size=(3_000, 3))
    log = tmp_path / "imu.csv"
    np.savetxt(log, X, delimiter=",", header="gx,gy,acc", comments="")
    out = tmp_path / "out"
    assert (
        cli.main(
            ["report", str(log), "--fs", "10", "--columns", "gx,gy", "--unit", "deg/s", "--quiet", "--out", str(out)]
        )
        == 0
    )
    summary = json.loads((out / "summary.json").read_text())
    assert summary["axes"] == 2 and summary["record"]["axis_names"] == ["gx", "gy"]
    r = allanite.avar(X[:, :2], 10.0, taus="octave")
    np.testing.assert_allclose(summary["static"]["adev"], r.adev, rtol=1e-15, atol=0)
    # columns by 0-based index give the same record
    out2 = tmp_path / "out2"
    assert cli.main(["report", str(log), "--fs", "10", "--columns", "0,1", "--quiet", "--out", str(out2)]) == 0
    s2 = json.loads((out2 / "summary.json").read_text())
    assert s2["static"]["adev"] == summary["static"]["adev"]


def test_time_column_gives_fs_and_gaps_are_reported(tmp_path, rng, capsys):
    t = np.arange(3_000) / 50.0
    t[1_800:] += 2.0  # 2 s missing after sample 1799
    log = tmp_path / "gappy.csv"
    np.savetxt(log, np.c_[t, rng.normal(size=(3_000, 2))], delimiter=",", header="t,gx,gy", comments="")
    out = tmp_path / "out"
    rc = cli.main(["report", str(log), "--time-column", "t", "--unit", "deg/s", "--out", str(out)])
    assert rc == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "1 gap(s) in time column 't'" in err
    assert "Pass --gaps longest" in err and "--gaps split" in err  # options, not Python keywords
    assert not (out / "summary.json").exists()

    rc = cli.main(
        [
            "report",
            str(log),
            "--time-column",
            "t",
            "--unit",
            "deg/s",
            "--gaps",
            "longest",
            "--no-fit",
            "--out",
            str(out),
        ]
    )
    assert rc == 0
    printed = capsys.readouterr().out
    assert "only the longest gap-free stretch, samples 0–1799 of 3000" in printed
    summary = json.loads((out / "summary.json").read_text())
    src = summary["record"]["source"]
    assert summary["fs_hz"] == 50.0 and src["fs_from"] == "time column" and summary["samples"] == 1_800
    assert src["gaps"] == [
        {"after_sample": 1799, "time_s": pytest.approx(35.98), "duration_s": pytest.approx(2.0), "missing_samples": 100}
    ]
    assert src["kept"] == [0, 1_800]

    out3 = tmp_path / "out3"
    assert (
        cli.main(
            ["report", str(log), "--time-column", "0", "--gaps", "split", "--no-fit", "--quiet", "--out", str(out3)]
        )
        == 0
    )
    s3 = json.loads((out3 / "summary.json").read_text())
    assert s3["record"]["source"]["segments"] == [[0, 1_800], [1_800, 3_000]]
    assert s3["static"]["adev"] == summary["static"]["adev"]


def test_increment_input_with_an_angle_unit(tmp_path, rng):
    rate = rng.normal(size=5_000) * 2.0  # arcsec/s
    log = tmp_path / "inc.npy"
    np.save(log, rate / 100.0)  # arcsec per sample at 100 Hz
    out = tmp_path / "out"
    assert (
        cli.main(
            [
                "report",
                str(log),
                "--fs",
                "100",
                "--input",
                "increment",
                "--unit",
                "arcsec",
                *SMALL,
                "--quiet",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    summary = json.loads((out / "summary.json").read_text())
    assert summary["record"]["adev_unit"] == "arcsec/s" and summary["record"]["input"] == "increment"
    r = allanite.avar(rate, 100.0)
    np.testing.assert_allclose(summary["static"]["adev"], [r.adev], rtol=1e-12)
    n = summary["fit"]["axes"][0]["coefficients"]["N"]
    assert n["unit"] == "arcsec/√s" and n["ieee_unit"] == "°/√h"
    assert n["ieee"] == pytest.approx(n["value"] / 3600 * 60, rel=1e-12)


def test_unknown_unit_still_fits_in_base_form(tmp_path, npy_log, capsys):
    log, _ = npy_log
    out = tmp_path / "out"
    assert cli.main(["report", str(log), "--fs", "50", *SMALL, "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "unit unknown (give --unit)" in printed and "in base form (unit unknown)" in printed
    summary = json.loads((out / "summary.json").read_text())
    assert summary["unit"] is None and summary["fit"]["unit_known"] is False
    n = summary["fit"]["axes"][0]["coefficients"]["N"]
    assert n["value"] > 0 and n["ieee"] is None and n["ieee_unit"] is None
    html = (out / "report.html").read_text(encoding="utf-8")
    assert "unit of the samples is unknown" in html


def test_no_fit_and_explicit_taus(tmp_path, npy_log):
    log, y = npy_log
    out = tmp_path / "out"
    assert (
        cli.main(
            [
                "report",
                str(log),
                "--fs",
                "50",
                *SMALL,
                "--taus",
                "0.02,0.2,2,20",
                "--no-fit",
                "--quiet",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    summary = json.loads((out / "summary.json").read_text())
    assert summary["static"]["tau_s"] == [0.02, 0.2, 2.0, 20.0] and summary["static"]["grid"] == "explicit"
    np.testing.assert_array_equal(summary["static"]["adev"], [allanite.avar(y, 50.0, taus=[0.02, 0.2, 2, 20]).adev])
    assert summary["fit"]["requested"] is False and summary["fit"]["axes"] is None
    assert not list(out.glob("coefficients*.png"))
    assert "Not fitted (<code>--no-fit</code>)" in (out / "report.html").read_text(encoding="utf-8")
    out2 = tmp_path / "out2"
    assert (
        cli.main(
            ["report", str(log), "--fs", "50", *SMALL, "--taus", "decade", "--no-fit", "--quiet", "--out", str(out2)]
        )
        == 0
    )
    s2 = json.loads((out2 / "summary.json").read_text())
    np.testing.assert_array_equal(s2["static"]["tau_s"], allanite.tau_grid(6_000, 50.0, "decade"))


# ------------------------------------------------------------------------------------------------
# quiet, progress, warnings


def test_quiet_prints_nothing(tmp_path, npy_log, capfd):
    log, _ = npy_log
    out = tmp_path / "out"
    assert cli.main(["report", str(log), "--fs", "50", *SMALL, "--quiet", "--out", str(out)]) == 0
    captured = capfd.readouterr()
    assert captured.out == "" and captured.err == ""
    assert (out / "report.html").is_file() and (out / "summary.json").is_file()


class _Terminal(io.StringIO):
    def isatty(self):
        return True


def test_progress_bar_on_a_terminal_and_not_with_quiet(tmp_path, npy_log, monkeypatch, capsys):
    log, _ = npy_log
    err = _Terminal()
    monkeypatch.setattr(sys, "stderr", err)
    assert cli.main(["report", str(log), "--fs", "50", *SMALL, "--out", str(tmp_path / "a")]) == 0
    bar = err.getvalue()
    for step in (
        "reading gyro.npy",
        "static Allan deviation",
        "confidence intervals",
        "dynamic Allan variance",
        "noise-model fit",
        "figure adev.png",
        "figure davar3d_axis0.png",
        "writing report.html",
    ):
        assert step in bar
    assert "\r" in bar and "allanite: error" not in bar
    err = _Terminal()
    monkeypatch.setattr(sys, "stderr", err)
    assert cli.main(["report", str(log), "--fs", "50", *SMALL, "--quiet", "--out", str(tmp_path / "b")]) == 0
    assert err.getvalue() == ""


def test_reader_warnings_are_one_line_and_in_the_report(tmp_path, rng, capfd):
    t = np.arange(3_000) / 50.0
    t[100] += 0.006  # one step 30 % long: irregular sampling, not a gap
    log = tmp_path / "jitter.csv"
    np.savetxt(log, np.c_[t, rng.normal(size=3_000)], delimiter=",", header="t,g", comments="")
    out = tmp_path / "out"
    assert cli.main(["report", str(log), "--time-column", "t", "--no-fit", "--out", str(out)]) == 0
    err = capfd.readouterr().err
    assert err.startswith("allanite: warning: ") and "irregular sampling" in err and err.count("\n") == 1
    summary = json.loads((out / "summary.json").read_text())
    assert any("irregular sampling" in n for n in summary["notes"])
    assert cli.main(["report", str(log), "--time-column", "t", "--no-fit", "--quiet", "--out", str(out)]) == 0
    captured = capfd.readouterr()
    assert captured.err == "" and captured.out == ""


# ------------------------------------------------------------------------------------------------
# errors: exit status 2 and one line on stderr


@pytest.mark.parametrize(
    "args, message",
    [
        (["report", "missing.npy", "--fs", "1"], "missing.npy: no such file"),
        (
            ["report", "{log}"],
            "give the sampling rate (--fs HZ) or the time column (--time-column C) — neither was passed",
        ),
        (
            ["report", "{log}", "--fs", "abc"],
            "argument --fs: invalid float value: 'abc' (see 'allanite report --help')",
        ),
        (["report", "{log}", "--fs", "0"], "fs must be a positive finite number"),
        (["report", "{log}", "--fs", "-5"], "fs must be a positive finite number"),
        (["report", "{log}", "--fs", "nan"], "fs must be a positive finite number"),
        (["report", "{log}", "--fs", "1", "--unit", "furlongs"], "unknown unit 'furlongs'; allowed rate units: deg/s"),
        (["report", "{log}", "--fs", "1", "--unit", "deg"], "(--input rate needs a rate unit)"),
        (["report", "{log}", "--fs", "1", "--input", "increment", "--unit", "deg/s"], "an angle unit is needed"),
        (["report", "{log}", "--fs", "1", "--input", "phase", "--unit", "deg/s"], "an angle unit is needed"),
        (["report", "{log}", "--fs", "1", "--input", "phases"], "argument --input: invalid choice: 'phases'"),
        (["report", "{bad}", "--fs", "1"], "column 'col0': non-finite value nan"),
        (["report", "{log}", "--fs", "1", "--window", "5000"], "window (5000 samples) is longer than the record (100"),
        (["report", "{log}", "--fs", "1", "--window", "x"], "argument --window: invalid int value: 'x'"),
        (["report", "{log}", "--fs", "1", "--hop", "0"], "hop must be an integer ≥ 1, got 0"),
        (["report", "{log}", "--fs", "1", "--taus", "fortnightly"], "unknown τ grid 'fortnightly'"),
        (["report", "{log}", "--fs", "1", "--taus", "0.5,x"], "is neither a grid name"),
        (["report", "{log}", "--fs", "1", "--taus", "1000"], "is too long for 100 samples"),
        (["report", "{log}", "--fs", "1", "--columns", "gx"], "no column named 'gx'"),
        (["report", "{log}", "--fs", "1", "--columns", "a,,b"], "empty name"),
        (["report", "{log}", "--fs", "1", "--gaps", "ignore"], "argument --gaps: invalid choice: 'ignore'"),
        (["report", "{text}", "--fs", "1"], "'world' is not a number"),
        (["report", "{log}", "--fs", "1", "--bogus"], "unrecognized arguments: --bogus"),
        (["report", "--fs", "100"], "--fs describes a LOG file; without LOG the bundled record"),
        (["report", "--unit", "deg/s", "--columns", "a"], "--columns, --unit describe a LOG file"),
        (["frobnicate"], "invalid choice: 'frobnicate'"),
        (["report", "{log}", "--fs", "1", "--out", "{file}"], "exists and is not a folder"),
    ],
)
def test_report_errors_exit_2_with_one_line(tmp_path, monkeypatch, capsys, args, message):
    monkeypatch.chdir(tmp_path)
    np.save(tmp_path / "log.npy", np.arange(100.0) % 7)
    bad = np.arange(100.0)
    bad[3] = np.nan
    np.save(tmp_path / "bad.npy", bad)
    (tmp_path / "text.txt").write_text("hello\nworld\n")
    (tmp_path / "afile").write_text("")
    paths = {
        "log": str(tmp_path / "log.npy"),
        "bad": str(tmp_path / "bad.npy"),
        "text": str(tmp_path / "text.txt"),
        "file": str(tmp_path / "afile"),
    }
    argv = [a.format(**paths) for a in args]
    if "--out" not in argv:
        argv += ["--out", str(tmp_path / "out")] if argv[0] == "report" else []
    rc = cli.main(argv)
    assert rc == 2
    captured = capsys.readouterr()
    err = captured.err
    assert err.startswith("allanite: error: ") and message in err
    assert err.count("\n") == 1 and "Traceback" not in err
    # stdout is no terminal here: at most the steps reached before the error, one line each
    assert all(re.fullmatch(r"\[ *\d+\.\d s\] .+", line) for line in captured.out.splitlines()), captured.out
    assert not (tmp_path / "out").exists()


def test_unwritable_output_folder_is_a_one_line_error(tmp_path, npy_log, capsys):
    log, _ = npy_log
    blocker = tmp_path / "file"
    blocker.write_text("")
    rc = cli.main(["report", str(log), "--fs", "50", "--no-fit", "--out", str(blocker / "sub")])
    assert rc == 2
    err = capsys.readouterr().err
    assert err.startswith("allanite: error: ") and err.count("\n") == 1 and "sub" in err


def test_python_m_allanite_exit_status_and_no_traceback(tmp_path):
    proc = subprocess.run(
        [sys.executable, "-m", "allanite", "report", str(tmp_path / "nope.csv"), "--fs", "100"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 2
    assert proc.stderr == f"allanite: error: {tmp_path / 'nope.csv'}: no such file\n"
    assert proc.stdout == ""


# ------------------------------------------------------------------------------------------------
# help and version


def test_top_level_help(capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(["--help"])
    assert info.value.code == 0
    out = capsys.readouterr().out
    assert out.startswith("usage: allanite [-h] [--version] COMMAND [ARGS ...]")
    assert "commands:\n  report" in out and "--version" in out
    assert "exit status:" in out and "2    usage or input error" in out
    assert "allanite report --help" in out


def test_report_help_reads_like_a_unix_tool(capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(["report", "--help"])
    assert info.value.code == 0
    out = capsys.readouterr().out
    assert out.startswith("usage: allanite report [-h]") and "[LOG]" in out
    # option groups, examples, the files written and the exit status, in this order
    heads = [
        "positional arguments:",
        "input (LOG only):",
        "analysis:",
        "output:",
        "examples:",
        "files written to DIR:",
        "exit status:",
    ]
    positions = [out.index(h) for h in heads]
    assert positions == sorted(positions)
    for option in (
        "--fs HZ",
        "--columns",
        "--time-column",
        "--unit U",
        "--input {rate,increment,angle}",
        "--gaps {error,longest,split,nan}",
        "--taus GRID",
        "--window N",
        "--hop N",
        "--no-fit",
        "--out DIR",
        "-q, --quiet",
    ):
        assert option in out
    assert "1/12 of the record" in out and "1/25 of the window" in out  # the defaults are documented
    assert "allanite report imu.csv.gz --fs 100 --columns gyro_x,gyro_y,gyro_z --unit deg/s" in out
    for name in ("report.html", "summary.json", "adev.png", "davar.png", "davar3d_axisK.png", "coefficients.png"):
        assert name in out
    assert max(len(line) for line in out.splitlines()) <= 100


def test_no_command_prints_help_and_returns_2(capsys):
    assert cli.main([]) == 2
    assert "commands:" in capsys.readouterr().out


def test_version(capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(["--version"])
    assert info.value.code == 0
    assert capsys.readouterr().out.strip() == f"allanite {allanite.__version__}"


def test_console_script_is_installed():
    exe = shutil.which("allanite")
    if exe is None:
        pytest.skip("the 'allanite' console script is not on PATH (package not installed?)")
    proc = subprocess.run([exe, "--help"], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith("usage: allanite") and "report" in proc.stdout
