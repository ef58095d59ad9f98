"""``allanite report --estimator theoh``: TheoH for the record and DHVAR over time in the report."""

from __future__ import annotations

import json
from html import unescape

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

import allanite  # noqa: E402
from allanite import cli  # noqa: E402
from allanite.report import build_report  # noqa: E402


@pytest.fixture(scope="module")
def record():
    y = allanite.simulate(12_000, 50.0, N=0.01, B=2e-3, seed=4)
    return y


def test_build_report_theoh_numbers_match_the_library(record):
    rep = build_report(record, 50.0, unit="deg/s", window=1_000, hop=250, estimator="theoh")
    s = rep.summary()
    st, dy = s["static"], s["dynamic"]
    assert st["estimator"] == "theoh" and dy["estimator"] == "theoh" and dy["grid"] == "octave"
    lib = allanite.avar(record, 50.0, estimator="theoh", taus="octave")
    np.testing.assert_allclose(st["tau_s"], lib.tau)
    np.testing.assert_allclose(np.asarray(st["adev"])[0], lib.adev, rtol=1e-12)
    assert st["source"] == [str(v) for v in lib.source] and st["kf"][0] == pytest.approx(lib.kf)
    assert st["theo_decimation"] == 1
    d = allanite.davar(record, 50.0, window=1_000, hop=250, estimator="theoh", taus="octave")
    np.testing.assert_allclose(dy["tau_s"], d.tau)
    assert dy["source"] == [str(v) for v in d.source]
    assert dy["kf_median"][0] == pytest.approx(float(np.median(d.kf)))


def test_cli_estimator_theoh(tmp_path, record):
    log = tmp_path / "g.npy"
    np.save(log, record)
    out = tmp_path / "out"
    rc = cli.main(
        [
            "report",
            str(log),
            "--fs",
            "50",
            "--unit",
            "deg/s",
            "--estimator",
            "theoh",
            "--window",
            "1000",
            "--out",
            str(out),
            "--quiet",
        ]
    )
    assert rc == 0
    s = json.loads((out / "summary.json").read_text())
    assert s["static"]["estimator"] == "theoh" and s["dynamic"]["estimator"] == "theoh"
    html = unescape((out / "report.html").read_text())
    assert "TheoH deviation" in html and "Dynamic TheoH (DHVAR)" in html and "Howe's Theo1" in html
    # default hop keeps about 400 windows at most (each window is fitted)
    assert s["dynamic"]["windows"] <= 401


def test_cli_rejects_an_unknown_estimator(tmp_path, record, capsys):
    log = tmp_path / "g.npy"
    np.save(log, record)
    rc = cli.main(["report", str(log), "--fs", "50", "--estimator", "theo9", "--out", str(tmp_path / "o")])
    assert rc == 2
    assert "theo9" in capsys.readouterr().err


def test_long_record_uses_fast_theobr_and_says_so():
    y = allanite.simulate(250_000, 100.0, N=0.01, seed=2)
    rep = build_report(y, 100.0, unit="deg/s", window=1_000, hop=50_000, estimator="theoh", fit=False)
    st = rep.summary()["static"]
    assert st["theo_decimation"] == 3
    lib = allanite.avar(y, 100.0, estimator="theoh", taus="octave", decimate=3)
    np.testing.assert_allclose(np.asarray(st["adev"])[0], lib.adev, rtol=1e-12)
