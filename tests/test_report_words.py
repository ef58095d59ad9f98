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


# ------------------------------------------------------------------------------------------------
# the report in a notebook: Report._repr_html_ (it showed as its repr)


def _shown(rep) -> str:
    from test_display import parse

    p = parse(rep._repr_html_())  # the tags balance
    return " ".join(" ".join(p.text).split())


def test_a_report_shows_its_numbers_units_and_files_in_a_notebook(tmp_path):
    from allanite.report import build_report

    y = allanite.simulate(6000, 100.0, N=0.01, K=1e-3, seed=2)
    rep = build_report(np.c_[y, 1.1 * y], 100.0, unit="deg/s", progress=False, axis_names=["gx", "gy"])
    text = _shown(rep)
    assert "6000 samples × 2 axes (gx, gy) at 100 Hz = 1 min" in text
    assert "samples' unit deg/s, rate input" in text and "Allan deviation in °/s" in text
    assert "noise model in IEEE-952 units" in text
    n_gx, n_gy = (rep.summary()["fit"]["axes"][k]["coefficients"]["N"]["ieee"] for k in (0, 1))
    assert f"N angle random walk °/√h {n_gx:.3g} [" in text and f" {n_gy:.3g} [" in text
    assert "not written yet: rep.write(folder)" in text and "model refinement" not in text
    assert "<svg" in rep._repr_html_()  # the inline figure
    unfitted = build_report(y[:1500], 100.0, progress=False, fit=False)
    text = _shown(unfitted)
    assert "samples' unit unknown (not given)" in text and "The unit of the samples is unknown" in text
    unfitted.write(tmp_path / "out", progress=False, dpi=30)
    assert f"files {tmp_path / 'out' / 'report.html'}, summary.json and the figures beside it" in _shown(unfitted)


def test_an_accelerometers_report_shows_its_units_in_a_notebook():
    from allanite.report import build_report

    y = allanite.simulate(6000, 100.0, N=0.002, K=1e-4, seed=2)
    text = _shown(build_report(y, 100.0, unit="m/s^2", progress=False, fit=True))
    assert "samples' unit m/s^2 (an accelerometer's), rate input" in text and "Allan deviation in m/s²" in text
    assert "noise model in the accelerometer's units (m/s/√h, µg, m/s/h^1.5; samples in m/s^2)" in text
    assert "N velocity random walk m/s/√h" in text and "B bias instability µg" in text and "°" not in text


def test_a_refined_report_shows_the_effects_and_what_is_left_in_a_notebook():
    # a line, outliers and a drift: refine adds steps of the periodic and outliers effects
    from allanite.report import build_report

    n, fs = 4000, 100.0
    rng = np.random.default_rng(5)
    t = np.arange(n) / fs
    y = allanite.simulate(n, fs, N=0.01, seed=5) + 0.05 * np.sin(2 * np.pi * 7.3 * t)
    y += 0.03 * np.sin(2 * np.pi * t / 30.0)
    y[rng.choice(n, 8, replace=False)] += 1.5
    rep = build_report(y, fs, unit="deg/s", refine=("periodic", "outliers"), progress=False)
    (ax,) = rep.summary()["refinement"]["axes"]
    assert {st["effect"] for st in ax["steps"]} == {"periodic", "outliers"}
    text = _shown(rep)
    a, b = ax["start"]["chi2_dof"], ax["final"]["chi2_dof"]
    assert f"axis 0 {', '.join(st['effect'] for st in ax['steps'])} {a:.3g} → {b:.3g}" in text
    assert f"axis 0: {' '.join(ax['still_missing'])}" in text


# ------------------------------------------------------------------------------------------------
# an accelerometer's coefficients over the windows: its units (they were in base form, m/s^1.5, …)


def test_an_accelerometers_coefficients_over_time_are_in_its_units(tmp_path):
    from matplotlib.figure import Figure

    from allanite.report import build_report
    from allanite.report.sidefiles import series_columns
    from allanite.units import accel_report_unit

    y = allanite.simulate(6000, 100.0, N=0.002, K=1e-4, seed=4)
    rep = build_report(y, 100.0, unit="g", progress=False, window=1500, hop=500)
    s = rep.summary()
    (ax,) = s["fit"]["series"]["axes"]
    n = ax["coefficients"]["N"]
    assert (n["name"], n["unit"], n["ieee_unit"], n["stats"]["unit"]) == (
        "velocity random walk",
        "g·√s",
        "m/s/√h",
        "m/s/√h",
    )
    assert ax["coefficients"]["B"]["stats"]["unit"] == "µg" and ax["coefficients"]["K"]["ieee_unit"] == "m/s/h^1.5"
    values = rep.series[0].values["N"]
    assert n["ieee"] == pytest.approx(accel_report_unit("N", values, "g").value, rel=1e-12)
    assert np.median(n["ieee"]) == pytest.approx(0.002 * 9.80665 * 60, rel=0.1)  # N's truth, m/s/√h
    cols = series_columns(rep)
    assert cols["axis0_N_ieee"] == pytest.approx(n["ieee"], rel=1e-12)
    assert "noise coefficients in the accelerometer's units over the windows" in rep.text()
    (spec,) = [sp for sp in rep.figure_specs() if sp[0] == "coefficients.png"]
    fig = Figure(figsize=spec[3])
    spec[4](fig)
    labels = [a.get_ylabel() for a in fig.axes if a.get_ylabel()]
    assert "N (m/s/√h)" in labels and all("°" not in lb and "g·" not in lb for lb in labels), labels


def test_the_cli_takes_an_accelerometers_unit_for_an_accelerometers_log(tmp_path, capsys):
    from allanite import cli

    y = allanite.simulate(3000, 100.0, N=0.002, seed=6)
    t = np.arange(y.size) / 100.0
    log = _csv(tmp_path / "acc.csv", "time,ax,ay", t, np.c_[y, y[::-1]])
    args = ["report", str(log), "--no-fit", "--out", str(tmp_path / "o")]
    for given, unit in ((["--unit", "m/s^2"], "m/s^2"), (["--accel-unit", "g"], "g")):  # --unit was refused
        assert cli.main([*args, *given]) == 0
        printed = capsys.readouterr().out
        assert f"unit {unit} (an accelerometer's), rate input" in printed
    gyro = _csv(tmp_path / "gyro.csv", "time,gx [deg/s],gy [deg/s]", t, np.c_[y, y])
    assert cli.main(["report", str(gyro), "--unit", "g", "--no-fit", "--out", str(tmp_path / "p")]) == 2
    assert "--unit g is an accelerometer's, and the names of columns gx [deg/s], gy [deg/s] give a gyro's" in (
        capsys.readouterr().err
    )


# ------------------------------------------------------------------------------------------------
# a slow sinusoid absorbed as R: "passes every calibrated check" beside a curve χ²/dof well above 1


def test_passing_every_check_beside_a_large_misfit_says_both():
    from allanite.model.refinement.words import MISFIT_CHI2_DOF

    # 1.5 periods of a 133 s sinusoid in 200 s of an ADIS-like gyro: R takes it, every calibrated check passes
    y = allanite.simulate(20_000, 100.0, Q=3.5e-4, N=2e-3, B=1e-3, K=6e-5, sinusoid=[(2e-2, 3 / 400.0, 0.7)], seed=3)
    r = allanite.refine(y, 100.0, unit="deg/s", progress=False)
    assert r.unexplained == [] and r.steps == []
    chi2 = r.final_errors["chi2_dof"]
    assert chi2 == pytest.approx(2.24, abs=0.01) and chi2 >= MISFIT_CHI2_DOF
    passes, misfit, where, stand_in = r.missing_sentences()
    assert passes.startswith("The final model passes every calibrated check")
    assert misfit.startswith(f"Yet its curve χ²/dof is {chi2:.3g} (p = {r.final_errors['p_value']:.2g} under χ²(dof)")
    assert "not for the size of the whole misfit" in misfit
    assert max(abs(r.fit.z)) < 2 and where.startswith(f"No single τ is far off (|z| ≤ {max(abs(r.fit.z)):.2g}")
    c = r.fit.coefficients["R"]
    assert c.ci[0] > 0 and stand_in.startswith(f"R (rate ramp, {c.ieee:.3g} °/h²) is resolved")
    assert "(22 s of a 200 s record): it may stand in for a slow periodic or a drift" in stand_in
