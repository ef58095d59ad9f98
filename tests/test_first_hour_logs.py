"""Logs of sensors unlike the ADIS16405, as a new user reads them (issue 29; r8review): a time column in ns named
so, epoch time stamps whose float rounding biased fs, … — each test a small file that failed before its fix."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from allanite import read_log


def _csv(path, header, cols, fmt="%.10g"):
    np.savetxt(path, np.column_stack(cols), delimiter=",", header=header, comments="", fmt=fmt)
    return path


@pytest.mark.parametrize(
    ("name", "scale", "unit"), [("time_ns", 1e9, "ns"), ("timestamp_us", 1e6, "us"), ("t [ms]", 1e3, "ms")]
)
def test_time_column_unit_from_its_name(tmp_path, name, scale, unit):
    # 200 Hz epoch stamps: read as seconds, time_ns gave fs = 2e-7 Hz and a record of 5e8 h
    t = (1.7e9 + np.arange(400) / 200.0) * scale
    p = _csv(tmp_path / "g.csv", f"{name},gx", [t, np.ones(400)], fmt=["%d", "%g"])
    log = read_log(p)
    assert log.fs == 200.0 and log.time_unit == unit and log.time_unit_from_name
    assert log.time[1] == pytest.approx(0.005, rel=1e-4)  # float64 keeps 256 ns of 1.7e18 ns
    assert f"in {unit} (its name says so)" in repr(log)
    over = read_log(p, time_unit="s")  # given: the name does not override it
    assert over.fs == pytest.approx(200.0 / scale) and over.time_unit == "s" and not over.time_unit_from_name


def test_plain_time_name_stays_seconds_and_warns_when_implausible(tmp_path):
    t = np.arange(100) / 50.0
    log = read_log(_csv(tmp_path / "s.csv", "time,gx", [t, np.ones(100)]))
    assert log.fs == 50.0 and log.time_unit == "s" and not log.time_unit_from_name
    secs = read_log(_csv(tmp_path / "secs.csv", "time_s,gx", [t, np.ones(100)]))  # seconds by name: nothing to say
    assert secs.fs == 50.0 and secs.time_unit == "s" and not secs.time_unit_from_name and " in s " not in repr(secs)
    p = _csv(tmp_path / "ns.csv", "time,gx", [(1.7e9 + t) * 1e9, np.ones(100)], fmt=["%d", "%g"])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        # epoch ns (1.7e18) name their unit by magnitude (read as seconds before: a warning, fs = 5e-8 Hz)
        log = read_log(p)
        assert log.fs == 50.0 and log.time_unit == "ns" and log.time_unit_source == "epoch magnitude"
        assert read_log(p, time_unit="ns").fs == 50.0


@pytest.mark.parametrize("fs", [400.0, 1000.0])
def test_epoch_seconds_give_the_nominal_rate(tmp_path, fs):
    # float64 rounds 1.7e9 s + k/fs to 2.4e-7 s: the median step read 399.991 Hz at 400 Hz
    t = 1.7e9 + np.arange(20_000) / fs
    p = tmp_path / "e.npy"
    np.save(p, np.c_[t, np.ones(t.size)])
    log = read_log(p, time_column=0)
    assert log.fs == fs and log.gaps == []


def test_console_tables_keep_their_columns_apart():
    # an unknown unit's base-form values with tight intervals ("2.37e-05 [2.37e-05, 2.37e-05]", 29 characters)
    # ran into the next axis's column in the noise-model table
    from allanite import simulate
    from allanite.report import build_report

    y = np.c_[simulate(20_000, 200.0, N=2.4e-5, B=3e-6, seed=1), simulate(20_000, 200.0, N=2.4e-5, B=3e-6, seed=2)]
    text = build_report(y, 200.0, window=4000, hop=2000).text()
    # unknown unit (a clock's fractional frequency among such logs): the terms' frequency-stability names beside
    assert "  (for a clock's fractional frequency the same terms are Q ↔ white/flicker PM, N ↔ white FM" in text
    table = [r for r in text[text.index("Noise model") : text.index("Dynamic Allan")].splitlines()[4:] if r.strip()]
    for row in table:
        cells = [c for c in row[37:].split("  ") if c.strip()]
        assert len(cells) == 2, row  # two axes: two cells, each kept apart by ≥ 2 spaces
    assert not any("][" in row or "]0" in row or "]1" in row for row in table)


def test_decimal_comma_is_named(tmp_path):
    from allanite.errors import InputError

    p = tmp_path / "eu.csv"
    p.write_text("# logger export\ntime;gx\n0,00;0,0125\n0,02;-0,0031\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"line 3, column 1 \('time'\): '0,00' is not a number; a decimal comma"):
        read_log(p)
    p.write_text("time;gx\n0;abc\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"'abc' is not a number$"):
        read_log(p)


def test_refinement_repr_and_console_line_are_short_and_say_the_heldout_error():
    # the default dataclass repr printed every field (arrays, the proposals tried): ~10⁴ characters in a terminal;
    # the console's axis line left out the held-out error, the one refine decides by
    import allanite
    from allanite.report import build_report

    n, fs = 20_000, 100.0
    y = allanite.simulate(n, fs, N=2e-3, K=2e-5, seed=3) + 3e-3 * np.sin(2 * np.pi * 1.3 * np.arange(n) / fs)
    rep = build_report(y[:, None], fs, unit="deg/s", refine=("bandwidth",), fit=False, window=4000, hop=4000)
    r = rep.refinements[0]
    text = repr(r)
    assert text.startswith("Refinement(20000 samples at 100 Hz, start Q+N+B+K+R; nothing added")
    assert len(text.splitlines()) == 3 + len(r.unexplained) and len(text) < 1500
    assert f"held-out {r.start_heldout_rms_adev_pct:.3g} → {r.final_heldout_rms_adev_pct:.3g} %" in text
    axis_line = next(ln for ln in rep.text().splitlines() if ln.startswith("  axis 0: nothing added"))
    assert axis_line.endswith(f", held-out {r.start_heldout_rms_adev_pct:.3g} → {r.final_heldout_rms_adev_pct:.3g} %")
    assert rep.summary()["refinement"]["axes"][0]["final_heldout_rms_adev_pct"] == r.final_heldout_rms_adev_pct
    # the page and summary.json said the chain's χ²/dof weighted each τ independently: it is the tests' GLS χ²
    import html as html_mod

    page = html_mod.unescape(rep.html({}))
    words = rep.summary()["refinement"]["statistics"]["allan_curve"]
    assert "χ²/dof is the calibrated tests' own: the generalised least-squares χ²" in page
    assert "generalised least-squares χ² of the residual on ~4 τ per octave" in words
    assert "independently" not in page + words


def test_batch_takes_the_gyro_columns_and_fills_the_fleet_rows_without_a_unit(tmp_path):
    # allanite batch analysed an IMU log's accelerometer columns as gyro axes (allanite report chose the gyro
    # ones by name), and without --unit every N, B, K of fleet.csv was empty
    pytest.importorskip("distributed")
    import json

    from allanite.dask.fleet import _flag, _rows, run_one

    rng = np.random.default_rng(5)
    n = 4000
    p = _csv(tmp_path / "imu.csv", "t,gyro_x,gyro_y,acc_x,acc_y", [np.arange(n) / 50.0, *rng.normal(size=(4, n))])
    st = run_one(str(p), str(tmp_path / "out"), {}, {"window": 2000, "hop": 1000})
    assert st["status"] == "ok", st
    summary = json.loads((tmp_path / "out" / "summary.json").read_text(encoding="utf-8"))
    assert summary["record"]["axis_names"] == ["gyro_x", "gyro_y"]
    assert any("chosen by their names (gyro)" in note for note in summary["notes"])
    rows = _rows(st)
    _flag(rows)
    n_fit = summary["fit"]["axes"][0]["coefficients"]["N"]
    assert [r["axis"] for r in rows] == ["gyro_x", "gyro_y"]
    assert rows[0]["N"] == n_fit["value"] and rows[0]["N_unit"] == "base form" and rows[0]["N_low"] is not None
    st2 = run_one(
        str(_csv(tmp_path / "acc.csv", "t,acc_x,w", [np.arange(50) / 50.0, np.ones(50), np.ones(50)])),
        str(tmp_path / "out2"),
        {},
        {},
    )
    assert st2["status"] == "error" and "names none as a gyro" in st2["error"]  # a row, not a failed task


def test_a_tight_interval_is_not_printed_as_zero_percent():
    from allanite.report.fmt import pct

    assert pct(0.3162, 0.3162 * (1 + 3.2e-4)) == "0.03"  # 10⁷ samples at τ0: "0.0" read as no interval at all
    assert pct(1.0, 1.0012) == "0.1" and pct(1.0, 1.05) == "5.0" and pct(1.0, 1.3) == "30" and pct(1.0, 1.0) == "0.0"


def test_refine_on_several_columns_says_it_took_one():
    # refine(log.data, log.fs) on a 6-column IMU log refined column 0 alone and said nothing
    import allanite

    y = np.c_[allanite.simulate(4000, 100.0, N=0.01, seed=1), allanite.simulate(4000, 100.0, N=0.02, seed=2)]
    with pytest.warns(UserWarning, match=r"refine refines one axis: axis 0 of 2; pass axis= for another"):
        r = allanite.refine(y, 100.0, candidates=(), progress=False)
    assert r.start.coefficients["N"].value == pytest.approx(0.01, rel=0.1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r1 = allanite.refine(y, 100.0, axis=1, candidates=(), progress=False)  # asked: nothing to say
        allanite.refine(y[:, 0], 100.0, candidates=(), progress=False)
    assert r1.start.coefficients["N"].value == pytest.approx(0.02, rel=0.1)
    with pytest.warns(UserWarning, match="axis 0 of 2"):
        allanite.refine(allanite.avar(y, 100.0), candidates=(), progress=False)


def test_a_row_counter_is_no_axis(tmp_path):
    # pandas' to_csv writes its unnamed index first: it was analysed as a gyro axis 'col0' (0, 1, 2, …)
    rng = np.random.default_rng(3)
    p = tmp_path / "pd.csv"
    t = np.arange(3000) / 100.0
    rows = np.c_[np.arange(3000), t, rng.normal(size=(3000, 2))]
    np.savetxt(p, rows, delimiter=",", header=",time,gx,gy", comments="", fmt=["%d", "%.2f", "%.6g", "%.6g"])
    with pytest.warns(UserWarning, match=r"column\(s\) 'col0' count the rows \(0, 1, 2, …"):
        log = read_log(p)
    assert log.columns == ["gx", "gy"] and log.data.shape == (3000, 2) and log.fs == 100.0
    assert read_log(p, columns=["col0", "gx"]).columns == ["col0", "gx"]  # asked for: analysed
    seq = tmp_path / "seq.npy"
    np.save(seq, np.c_[np.arange(5, 3005), rng.normal(size=3000)])  # a sequence counter from 5, then one axis
    with pytest.warns(UserWarning, match="'col0' count the rows"):
        one = read_log(seq, fs=100.0)
    assert one.data.shape == (3000,) and one.columns == ["col1"]
    late = np.c_[np.r_[np.arange(1500), np.arange(1500) + 2000], rng.normal(size=3000)]  # counts, then jumps
    np.save(seq, late)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert read_log(seq, fs=100.0).data.shape == (3000, 2)


def test_an_iso_8601_time_column_is_read(tmp_path):
    # a logger's date-time stamps were "not a number" (and 'datetime' no time column by its name)
    from allanite.errors import InputError

    t = np.datetime64("2026-11-27T10:00:00", "ns") + (np.arange(2000) * 20_000_000).astype("timedelta64[ns]")
    t[1000:] += np.timedelta64(2, "s")  # a 2 s gap
    stamps = [str(s)[:23] + "Z" for s in t]
    p = tmp_path / "iso.csv"
    p.write_text("datetime,gx\n" + "".join(f"{s},{v:.5f}\n" for s, v in zip(stamps, np.sin(np.arange(2000)))))
    log = read_log(p, gaps="longest")
    assert log.fs == 50.0 and log.time_column == "datetime" and len(log.gaps) == 1
    assert log.gaps[0].duration == pytest.approx(2.0) and log.t0 == pytest.approx(1795773600.0)
    np.testing.assert_allclose(log.time[:3], [0.0, 0.02, 0.04])
    p.write_text("time;gx\n2026-11-27 10:00:00.00;1\n2026-11-27 10:00:00.02;2\n10:00:00.04;3\n")
    with pytest.raises(InputError, match=r"line 4, time column: '10:00:00.04' is not an ISO 8601 date-time"):
        read_log(p)


def test_batch_prints_a_files_error_in_the_commands_words(monkeypatch, capsys):
    # allanite batch printed "Pass gaps='longest'" where its option is --gaps longest
    pytest.importorskip("distributed")
    from allanite.dask import fleet

    err = "DataGapError: g.csv: 1 gap(s) … Pass gaps='longest' to keep the longest gap-free stretch"
    files = [{"path": "g.csv", "out": "o/g", "status": "error", "error": err}]
    monkeypatch.setattr(fleet, "batch", lambda *a, **k: fleet.FleetResult(rows=[], files=files, paths={}))
    assert fleet.main(["g.csv", "--out", "o"]) == 3
    assert "  failed: g.csv: DataGapError: g.csv: 1 gap(s) … Pass --gaps longest to keep" in capsys.readouterr().out
