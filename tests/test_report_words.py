"""What the report says — its notes, its notebook display and its units — is true of the log it was given:
each way of giving time, a report's own display, a misfit the calibrated checks do not see, an accelerometer's
coefficients over time."""

from __future__ import annotations

import numpy as np
import pytest

import allanite
from allanite.report.build import _time_notes


def _csv(path, header, t, y):
    np.savetxt(path, np.c_[t, y], delimiter=",", header=header, comments="")
    return path


@pytest.fixture(scope="module")
def samples():
    return allanite.simulate(2000, 100.0, N=0.01, K=1e-3, seed=3)


def test_the_time_note_is_said_only_when_true(tmp_path, samples):
    # `allanite report log.csv --time-unit ms` said "Neither fs nor a time column was given" — the time unit was
    t = np.arange(samples.size) / 100.0
    ms = _csv(tmp_path / "ms.csv", "t,gx", 1000 * t, samples)
    notes = _time_notes(allanite.read_log(ms, time_unit="ms"))
    assert len(notes) == 1 and "Neither" not in notes[0]
    assert "column 't' was taken as the time column by its name, read in ms as given (--time-unit" in notes[0]
    assert notes[0].endswith("fs = 100 Hz from its steps.")
    secs = _csv(tmp_path / "s.csv", "time,gx", t, samples)
    (note,) = _time_notes(allanite.read_log(secs))  # nothing given: the name chose it, in seconds
    assert "No time column was named (--time-column / time_column=) nor fs given: column 'time'" in note
    assert "as given" not in note
    assert _time_notes(allanite.read_log(secs, time_column="time")) == []  # named: nothing to say
    assert _time_notes(allanite.read_log(ms, time_column="t", time_unit="ms")) == []
    assert _time_notes(allanite.read_log(secs, fs=100.0, columns=["gx"])) == []  # fs given: no time column read
    named = _csv(tmp_path / "n.csv", "time_ms,gx", 1000 * t, samples)
    recognised, unit = _time_notes(allanite.read_log(named))
    assert "column 'time_ms' was taken" in recognised and "as given" not in recognised
    assert unit.startswith("Time column 'time_ms' was read in ms, the unit its name gives")
    assert _time_notes(allanite.read_log(named, time_column="time_ms"))[0].startswith("Time column 'time_ms' was read")


def test_the_cli_report_says_how_time_was_read(tmp_path, samples, capsys):
    from allanite import cli

    t = np.arange(samples.size) / 100.0
    ms = _csv(tmp_path / "ms.csv", "t,gx", 1000 * t, samples)
    assert cli.main(["report", str(ms), "--time-unit", "ms", "--no-fit", "--out", str(tmp_path / "o")]) == 0
    printed = capsys.readouterr().out
    assert "Neither fs" not in printed and "read in ms as given (--time-unit" in printed
    page = (tmp_path / "o" / "report.html").read_text(encoding="utf-8")
    assert "t, in ms (recognised by its name: none was named, nor fs given)" in page
