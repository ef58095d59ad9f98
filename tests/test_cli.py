"""The ``allanite`` command line: ``allanite report`` on the bundled record and on log files."""

from __future__ import annotations

import json
import shutil
import subprocess

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


@pytest.fixture(scope="module")
def default_report(tmp_path_factory):
    out = tmp_path_factory.mktemp("report")
    rc = cli.main(["report", "--out", str(out)])
    return rc, out


def test_report_on_the_bundled_record(default_report, capsys):
    rc, out = default_report
    assert rc == 0
    assert sorted(p.name for p in out.iterdir()) == ["adev.png", "davar.png", "summary.json"]
    adev_png = check_png(out / "adev.png")
    davar_png = check_png(out / "davar.png")
    # one DAVAR panel per axis: three stacked panels make the figure taller than wide
    assert davar_png.shape[0] > davar_png.shape[1] > 0 and adev_png.shape[1] > adev_png.shape[0]


def test_report_summary_matches_the_library(default_report):
    rc, out = default_report
    summary = json.loads((out / "summary.json").read_text())
    x, fs, info = allanite.default_record()
    assert (summary["fs_hz"], summary["samples"], summary["axes"]) == (fs, x.shape[0], x.shape[1])
    assert summary["unit"] == info["unit"] == "deg/s"
    static = summary["static"]
    tau = np.array(static["tau_s"])
    r = allanite.avar(x, fs, taus=tau)
    np.testing.assert_array_equal(tau, allanite.tau_grid(x.shape[0], fs, "octave"))
    np.testing.assert_array_equal(r.tau, tau)
    np.testing.assert_array_equal(static["n"], r.n)
    assert static["estimator"] == "oavar"
    adev = np.array(static["adev"])
    assert adev.shape == (3, tau.size)
    np.testing.assert_array_equal(adev, r.adev)  # JSON round-trips doubles exactly
    dyn = summary["dynamic"]
    window, hop = dyn["window_samples"], dyn["hop_samples"]
    assert window == x.shape[0] // 12 and hop == window // 25
    assert dyn["windows"] == (x.shape[0] - window) // hop + 1
    np.testing.assert_array_equal(dyn["tau_s"], allanite.tau_grid(window, fs, "exp"))
    # the bundled record's loud stretch (20–30 min, ARW ×4) is what the DAVAR summary must find
    for ax in dyn["axes"]:
        assert 1200.0 <= ax["t_of_max_s"] <= 1800.0
        assert not 1200.0 - window / fs / 2 <= ax["t_of_min_s"] <= 1800.0 + window / fs / 2
        assert 3.5 < ax["adev_shortest_tau_max"] / ax["adev_shortest_tau_min"] < 4.5


def test_report_on_a_npy_log(tmp_path, rng, capsys):
    y = rng.normal(size=6_000) * 0.02 + 0.1
    log = tmp_path / "gyro.npy"
    np.save(log, y)
    out = tmp_path / "out"
    rc = cli.main(["report", str(log), "--fs", "50", "--window", "1200", "--hop", "300", "--unit", "rad/s",
                   "--out", str(out)])
    assert rc == 0
    printed = capsys.readouterr().out
    assert "gyro.npy" in printed and "rad/s" in printed and "window 1200 samples" in printed
    summary = json.loads((out / "summary.json").read_text())
    assert (summary["fs_hz"], summary["samples"], summary["axes"], summary["unit"]) == (50.0, 6_000, 1, "rad/s")
    r = allanite.avar(y, 50.0, taus="octave")
    np.testing.assert_array_equal(summary["static"]["tau_s"], r.tau)
    np.testing.assert_array_equal(summary["static"]["adev"], [r.adev])
    d = allanite.davar(y, 50.0, window=1200, hop=300, taus="exp")
    assert summary["dynamic"]["windows"] == d.t.size == 17
    row = d.adev[0]
    ax = summary["dynamic"]["axes"][0]
    assert ax["adev_shortest_tau_median"] == float(np.median(row))
    assert ax["adev_shortest_tau_max"] == float(row.max()) and ax["t_of_max_s"] == float(d.t[row.argmax()])
    check_png(out / "adev.png")
    check_png(out / "davar.png")


def test_report_on_a_csv_log(tmp_path, rng):
    X = rng.normal(size=(3_000, 2))
    log = tmp_path / "imu.csv"
    np.savetxt(log, X, delimiter=",", header="gx,gy")
    out = tmp_path / "out"
    assert cli.main(["report", str(log), "--fs", "10", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["axes"] == 2
    r = allanite.avar(np.loadtxt(log, delimiter=","), 10.0, taus="octave")
    np.testing.assert_allclose(summary["static"]["adev"], r.adev, rtol=1e-15, atol=0)


@pytest.mark.parametrize("args, message", [
    (["report", "missing.npy", "--fs", "1"], "missing.npy: no such file"),
    (["report", "{log}"], "--fs is required for a log file"),
    (["report", "{bad}", "--fs", "1"], "non-finite value (nan) at sample 3"),
    (["report", "{log}", "--fs", "0"], "fs must be a positive finite number"),
    (["report", "{log}", "--fs", "1", "--window", "5000"], "window (5000 samples) is longer than the record (100 samples)"),
    (["report", "{text}", "--fs", "1"], "cannot read numeric samples"),
])
def test_report_errors_exit_2_with_one_line(tmp_path, monkeypatch, capsys, args, message):
    monkeypatch.chdir(tmp_path)
    np.save(tmp_path / "log.npy", np.arange(100.0) % 7)
    bad = np.arange(100.0)
    bad[3] = np.nan
    np.save(tmp_path / "bad.npy", bad)
    (tmp_path / "text.txt").write_text("hello\nworld\n")
    paths = {"log": str(tmp_path / "log.npy"), "bad": str(tmp_path / "bad.npy"), "text": str(tmp_path / "text.txt")}
    rc = cli.main([a.format(**paths) for a in args] + ["--out", str(tmp_path / "out")])
    assert rc == 2
    err = capsys.readouterr().err
    assert err.startswith("allanite: error: ") and message in err
    assert err.count("\n") == 1
    assert not (tmp_path / "out" / "summary.json").exists()


def test_help_exits_zero(capsys):
    for argv in (["--help"], ["report", "--help"]):
        with pytest.raises(SystemExit) as info:
            cli.main(argv)
        assert info.value.code == 0
    out = capsys.readouterr().out
    assert "usage: allanite" in out and "report" in out and "--window" in out


def test_no_command_prints_help_and_returns_2(capsys):
    assert cli.main([]) == 2
    assert "Commands:" in capsys.readouterr().out


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
