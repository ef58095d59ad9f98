"""What a new user meets on the command line (issue 32 item 5): --kalibr without --unit answered in
the command's words, gyro columns chosen by name (or asked for), --refine's help from the effect
registry, no empty --out folder after Ctrl-C, and help(allanite.davar) listing every estimator."""

from __future__ import annotations

import json

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

import allanite  # noqa: E402
from allanite import cli  # noqa: E402
from allanite.estimators import names  # noqa: E402
from allanite.model.effects import EFFECTS  # noqa: E402
from allanite.report import Report  # noqa: E402

SMALL = ["--window", "1200", "--hop", "300", "--no-fit", "-q"]


def _imu_csv(path, header, rng, n=3_000):
    cols = header.split(",")
    rows = np.c_[np.arange(n) / 50.0, rng.normal(size=(n, len(cols) - 1))]
    np.savetxt(path, rows, delimiter=",", header=header, comments="", fmt="%.6f")
    return path


def test_kalibr_without_unit_says_unit(tmp_path, rng, capsys):
    log = _imu_csv(tmp_path / "g.csv", "t,gyro_x,gyro_y", rng)
    out = tmp_path / "out"
    rc = cli.main(["report", str(log), "--time-column", "t", "--kalibr", str(tmp_path / "k.yaml"), "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2
    assert err.strip() == (
        "allanite: error: --kalibr needs the gyro's unit to write SI values: give --unit (e.g. --unit deg/s or "
        "--unit rad/s)"
    )
    assert "allanite.fit" not in err and "gyro_unit" not in err
    assert not out.exists()  # asked before any work


@pytest.mark.parametrize(
    "header, chosen",
    [
        ("t,gyro_x,gyro_y,gyro_z,acc_x,acc_y,acc_z,temp", ["gyro_x", "gyro_y", "gyro_z"]),
        ("time,wx,wy,wz,ax,ay,az", ["wx", "wy", "wz"]),
        ("t,AngularVelocity_Z,LinearAccel_Z", ["AngularVelocity_Z"]),
    ],
)
def test_gyro_columns_are_chosen_by_name(tmp_path, rng, capsys, header, chosen):
    log = _imu_csv(tmp_path / "imu.csv", header, rng)
    out = tmp_path / "out"
    tc = header.split(",")[0]
    assert cli.main(["report", str(log), "--time-column", tc, "--unit", "deg/s", *SMALL, "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["record"]["axis_names"] == chosen and summary["axes"] == len(chosen)
    assert any(f"columns {', '.join(chosen)} analysed, chosen by their names (gyro)" in n for n in summary["notes"])
    # --columns still chooses anything, accelerometers included
    out2 = tmp_path / "out2"
    acc = [c for c in header.split(",")[1:] if c not in chosen][:1]
    argv = ["report", str(log), "--time-column", tc, "--columns", ",".join(acc), *SMALL, "--out", str(out2)]
    assert cli.main(argv) == 0
    assert json.loads((out2 / "summary.json").read_text())["record"]["axis_names"] == acc


def test_unclear_columns_are_asked_for(tmp_path, rng, capsys):
    log = _imu_csv(tmp_path / "imu.csv", "t,a,b,c,acc_x,acc_y,acc_z", rng)
    rc = cli.main(["report", str(log), "--time-column", "t", *SMALL, "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert rc == 2
    assert (
        "imu.csv has accelerometer columns (acc_x, acc_y, acc_z) beside others, and its header names none as a "
        "gyro: give the gyro's with --columns (the columns are: a, b, c, acc_x, acc_y, acc_z)"
    ) in err
    # a log without accelerometer names is analysed whole, as before; so is one of accelerometers only
    for header in ("t,a,b", "t,acc_x,acc_y"):
        log = _imu_csv(tmp_path / "plain.csv", header, rng)
        out = tmp_path / f"plain{len(header)}"
        assert cli.main(["report", str(log), "--time-column", "t", *SMALL, "--out", str(out)]) == 0
        assert json.loads((out / "summary.json").read_text())["record"]["axis_names"] == header.split(",")[1:]


def test_refine_help_lists_the_registry(capsys):
    with pytest.raises(SystemExit):
        cli.main(["report", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    for e in EFFECTS.values():
        if e.domain != "channels":  # the report refines each axis on its own: no other channels
            assert e.label in text, e.label
    assert "Gauss–Markov, sinusoid, sensor bandwidth (low-pass), resonance" in text


def test_ctrl_c_leaves_no_out_folder(tmp_path, monkeypatch, capsys):
    def interrupted(self, progress=None, dpi=100):
        raise KeyboardInterrupt

    monkeypatch.setattr(Report, "render_figures", interrupted)
    out = tmp_path / "new" / "out"
    assert cli.main(["report", "--window", "30000", "--hop", "30000", "--no-fit", "--out", str(out)]) == 130
    assert "allanite: interrupted" in capsys.readouterr().err
    assert not out.exists()
    # a folder that was there before stays, with what it held
    keep = tmp_path / "keep"
    keep.mkdir()
    (keep / "mine.txt").write_text("x")
    assert cli.main(["report", "--window", "30000", "--hop", "30000", "--no-fit", "--out", str(keep)]) == 130
    assert [p.name for p in keep.iterdir()] == ["mine.txt"]


def test_ctrl_c_while_writing_removes_the_half_written_folder(tmp_path, monkeypatch):
    from allanite.report import result as result_module  # Report.write

    def interrupted_dumps(*args, **kwargs):
        raise KeyboardInterrupt

    x, fs, _ = allanite.default_record()
    rep = allanite.report.build_report(x[:20_000], fs, unit="deg/s", fit=False, window=5_000, hop=2_500)
    monkeypatch.setattr(result_module.json, "dumps", interrupted_dumps)
    monkeypatch.setattr(cli, "build_report", lambda *a, **k: rep)
    out = tmp_path / "out"
    assert cli.main(["report", "--out", str(out), "-q"]) == 130
    assert not out.exists()


def test_help_davar_lists_every_estimator():
    doc = allanite.davar.__doc__
    for name in names("dynamic"):
        assert f'``"{name}"``' in doc
    assert '``"ohvar"``' in doc
    static_only = [n for n in names("static") if n not in names("dynamic")]
    assert static_only and all(f'``"{n}"``' in doc for n in static_only)
    assert "{" not in doc.split("estimator : str", 1)[1].split("input :", 1)[0]  # no placeholder left
