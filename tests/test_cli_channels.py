"""``allanite report --channels`` and ``build_report(channels=)``: a log's temperature column reaches every axis's
``refine`` (its regression on other channels, issue 29) — read with the samples (same rate, span and gaps), shown in
summary.json, on the page and on the console; bad channel columns are one-line errors with exit status 2."""

from __future__ import annotations

import json
import re

import markupsafe
import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

import allanite  # noqa: E402
from allanite import cli  # noqa: E402
from allanite.errors import InputError, ParameterError  # noqa: E402
from allanite.report import build_report  # noqa: E402

FS, N, COEF = 10.0, 10_000, 0.02  # 10 Hz, 1000 s; deg/s per unit of temp on g_x only
SMALL = ["--window", "1000", "--hop", "250"]


def _temperature(n: int, seed: int) -> np.ndarray:
    """A slow swing of ±5 units (1.5 periods over the record) plus a little sensor noise."""
    t = np.arange(n) / FS
    rng = np.random.default_rng(seed)
    return 20.0 + 5.0 * np.sin(2 * np.pi * 1.5 * t / (n / FS)) + 0.02 * rng.standard_normal(n)


@pytest.fixture(scope="module")
def coupled_log(tmp_path_factory):
    """g_x = noise + COEF·(temp − mean), g_y = noise alone, temp: a CSV with a header."""
    temp = _temperature(N, 7)
    gx = allanite.simulate(N, FS, N=0.01, K=1e-4, seed=11) + COEF * (temp - temp.mean())
    gy = allanite.simulate(N, FS, N=0.01, K=1e-4, seed=12)
    path = tmp_path_factory.mktemp("channels") / "log.csv"
    np.savetxt(path, np.c_[gx, gy, temp], delimiter=",", header="g_x,g_y,temp", comments="")
    return path


@pytest.fixture(scope="module")
def cli_run(coupled_log, tmp_path_factory):
    """The brief's command line (no --refine: --channels implies it), run once for the module's tests."""
    out = tmp_path_factory.mktemp("out")
    args = ["report", str(coupled_log), "--fs", "10", "--columns", "g_x,g_y", "--unit", "deg/s"]
    return out, args + ["--channels", "temp", *SMALL, "--out", str(out)]


def test_cli_channels_finds_the_coupling_on_the_coupled_axis_only(cli_run, capsys):
    out, argv = cli_run
    assert cli.main(argv) == 0
    printed = capsys.readouterr().out
    s = json.loads((out / "summary.json").read_text())
    assert s["record"]["axis_names"] == ["g_x", "g_y"]  # temp is a channel, not an axis
    gx, gy = s["refinement"]["axes"]
    reg = [st for st in gx["steps"] if st["effect"] == "regression"]
    assert len(reg) == 1 and not [st for st in gy["steps"] if st["effect"] == "regression"]
    st = reg[0]
    assert st["params"]["channel"] == "temp"
    assert st["final_params"]["coefficient"] == pytest.approx(COEF, rel=0.2)
    assert st["units"]["coefficient"] == "°/s per unit of temp"
    ev = st["regression"]
    assert set(ev["terms_before_after"]) == {"before", "after"}
    assert {"N", "K"} <= set(ev["terms_before_after"]["after"])
    assert ev["terms_before_after"]["after"]["N"]["unit"] == "°/√h"
    # the white noise is the simulated one (0.01 deg/s/√Hz = 0.6 °/√h) once the temperature is removed
    assert ev["terms_before_after"]["after"]["N"]["value"] == pytest.approx(0.6, rel=0.05)
    assert set(ev["optional_terms"]) >= {"lag_s", "quadratic", "rate_coefficient"}
    assert all(isinstance(t["kept"], bool) for t in ev["optional_terms"].values())
    assert any("Channel temp passed" in n for n in s["notes"])
    # the console and the page say it
    assert "regression: channel = temp; coefficient = " in printed and "°/s per unit of temp" in printed
    assert "noise terms before → after the removal: " in printed and "optional terms: " in printed
    html = (out / "report.html").read_text()
    assert "regressed on channel" in html and "°/s per unit of temp" in html
    assert "noise terms before → after the removal" in html


def test_build_report_channels_imply_refine_and_match_the_cli(coupled_log):
    d = np.loadtxt(coupled_log, delimiter=",", skiprows=1)
    rep = build_report(
        d[:, :1], FS, unit="deg/s", axis_names=["g_x"], window=1000, hop=250, channels={"temp": d[:, 2]}, progress=False
    )
    assert rep.settings["channels"] == ["temp"] and rep.refinements is not None
    (r,) = rep.refinements
    (st,) = [st for st in r.steps if st.effect == "regression"]
    assert st.params["coefficient"] == pytest.approx(COEF, rel=0.2)
    from test_report_words import _shown  # its notebook display names the regression step

    assert f"g_x {', '.join(s.effect for s in r.steps)} " in _shown(rep)
    assert "No refinement was asked for: the channels imply it (its regression is their only use)." in rep.notes


def test_build_report_channel_errors_name_the_channel():
    y = allanite.simulate(2_000, FS, N=0.01, seed=1)
    temp = _temperature(2_000, 2)
    bad = temp.copy()
    bad[17] = np.nan
    with pytest.raises(InputError, match=r"channel 'temp' has non-finite samples .* index 17"):
        build_report(y, FS, channels={"temp": bad}, progress=False)
    with pytest.raises(ParameterError, match=r"channel 'temp' has 1999 samples; the rate has 2000"):
        build_report(y, FS, channels={"temp": temp[1:]}, progress=False)
    with pytest.raises(ParameterError, match=r"only used by the 'regression' effect.*\['drift'\]"):
        build_report(y, FS, refine=("drift",), channels={"temp": temp}, progress=False)
    with pytest.raises(ParameterError, match="channels must be a dict"):
        build_report(y, FS, channels=[temp], progress=False)


def test_channel_is_cut_at_the_same_gaps_as_the_samples(tmp_path):
    """--gaps longest: the channel keeps exactly the samples' stretch (read in the same call)."""
    n = 1_000
    t = np.arange(n) / FS
    t[600:] += 5.0  # a 5 s gap after sample 599: the longest stretch is 0..599
    temp = np.arange(n, dtype=float)
    path = tmp_path / "gap.csv"
    np.savetxt(path, np.c_[t, np.sin(t), np.cos(t), temp], delimiter=",", header="t,g_x,g_y,temp", comments="")
    for extra in ([], ["--columns", "g_x,g_y"]):
        args = cli.build_parser().parse_args(
            ["report", str(path), "--time-column", "t", "--gaps", "longest", "--channels", "temp", *extra]
        )
        log, _, channels = cli._read(args, cli._Progress(quiet=True))
        assert log.columns == ["g_x", "g_y"] and log.data.shape == (600, 2)
        np.testing.assert_array_equal(channels["temp"], np.arange(600.0))


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--columns", "g_x", "--channels", "tmp"], r"log\.csv: no column named 'tmp'; available: 'g_x', 'g_y', "),
        (["--channels", "tmp"], r"log\.csv.*'label'"),  # without --columns every column is read: 'label' is text
        (["--columns", "g_x,g_y", "--channels", "g_x"], r"column 'g_x' is given in both --columns and --channels"),
        (["--columns", "g_x,g_y", "--channels", "0"], r"column 'g_x' is both a sample column and a channel"),
        # by index without --columns: the file's column 4, 'hot' (the text column 'label' is no axis, left out)
        (["--channels", "4"], r"log\.csv: line 52, channel column 'hot': infinite value inf"),
        (["--columns", "g_x,g_y", "--channels", "temp,temp"], r"column 'temp' is given twice in --channels"),
        (["--columns", "g_x,g_y", "--channels", "label"], r"log\.csv.*'label'"),  # a text column
        (["--columns", "g_x,g_y", "--channels", "hot"], r"log\.csv: line 52, channel column 'hot': infinite value inf"),
        (["--refine-candidates", "drift", "--channels", "temp"], r"regression effect, which --refine-candidates drift"),
    ],
)
def test_bad_channel_columns_are_one_line_errors_exit_2(tmp_path, capsys, extra, message):
    n = 200
    rng = np.random.default_rng(3)
    rows = ["g_x,g_y,temp,label,hot"] + [
        f"{a:.5f},{b:.5f},{20 + i / n:.4f},{'ab'[i % 2]},{'inf' if i == 50 else f'{i / n:.3f}'}"
        for i, (a, b) in enumerate(rng.normal(size=(n, 2)))
    ]
    path = tmp_path / "log.csv"
    path.write_text("\n".join(rows) + "\n")
    rc = cli.main(["report", str(path), "--fs", "10", *extra, "--out", str(tmp_path / "o"), "-q"])
    err = capsys.readouterr().err
    assert rc == 2, err
    assert err.startswith("allanite: error: ") and err.count("\n") == 1 and "Traceback" not in err
    assert re.search(message, err), err


def test_channels_describe_a_log_file(capsys):
    assert cli.main(["report", "--channels", "temp", "-q"]) == 2
    assert "--channels describes a LOG file" in capsys.readouterr().err


def test_help_lists_channels(capsys):
    with pytest.raises(SystemExit):
        cli.main(["report", "--help"])
    text = capsys.readouterr().out
    assert "--channels C1,C2,..." in text and "implies --refine" in text
    assert "--channels temp" in text  # the epilogue's example


def test_channels_of_a_cumulative_angle_are_averaged_onto_its_rates():
    """input="angle": n angle samples give n − 1 rates; the channel is averaged over each rate's two samples."""
    n = 4_000
    temp = _temperature(n, 5)
    rate = allanite.simulate(n, FS, N=0.01, seed=4) + COEF * (temp - temp.mean())
    angle = np.concatenate([[0.0], np.cumsum(rate[1:]) / FS])  # θ[i] − θ[i−1] = rate[i]/fs
    rep = build_report(
        angle, FS, unit="deg", input="angle", window=800, hop=200, channels={"temp": temp}, progress=False
    )
    (r,) = rep.refinements
    (st,) = [st for st in r.steps if st.effect == "regression"]
    assert st.params["coefficient"] == pytest.approx(COEF, rel=0.2)


@pytest.mark.parametrize("n", [3_999, 4_000, 20_001])
def test_whittle_bands_parametric_ones_are_the_lowest(n):
    """A last band cut short by the Nyquist bin is narrow but not parametric (n = 3999 raised an IndexError in
    refine's held-out split across frequency, found through the angle input's n − 1 rates)."""
    from allanite.model import _whittle as wh

    y = allanite.simulate(n, FS, N=0.01, seed=9)
    for parity in (None, 0, 1):
        b = wh.spectra(y, [_temperature(n, 1)], FS, parity=parity)
        assert b.par.sum() > 0 and not np.any(np.diff(b.par.astype(int)) > 0)  # True… then False…
        assert b.basis.shape[0] == int(b.par.sum())


def test_an_unresolved_lag_and_a_heldout_rise_are_said_everywhere(tmp_path):
    """8000 samples: the lag's test does not keep it but the profile is used for the removal (evidence["lag"]),
    and the chain's held-out error rose (evidence["heldout_note"]): summary.json, the console, the page and
    Refinement.report() all say both, the coefficient per unit of temp."""
    n = 8_000
    temp = _temperature(n, 3)
    y = allanite.simulate(n, FS, N=0.01, seed=2) + COEF * (temp - temp.mean())
    rep = build_report(y, FS, unit="deg/s", window=1600, hop=400, channels={"temp": temp}, progress=False)
    (r,) = rep.refinements
    (st,) = [st for st in r.steps if st.effect == "regression"]
    said = {k: st.evidence[k] for k in ("lag", "heldout_note") if st.evidence.get(k)}
    # the case exercises both notes at these seeds — the held-out rise's the default run's only one since the FOG's
    # lag-0 removal (tests/test_channels.py) went to the slow set
    assert set(said) == {"lag", "heldout_note"} and "rose" in said["heldout_note"]
    (js,) = [s for s in rep.summary()["refinement"]["axes"][0]["steps"] if s["effect"] == "regression"]
    text = rep.text()
    paths = rep.write(tmp_path / "out")
    html = next(p for p in paths if p.name == "report.html").read_text()
    for key, words in said.items():
        assert js["regression"][key] == words
        assert words in text
        assert str(markupsafe.escape(words)) in html  # as Jinja2 escapes it
    assert "°/s per unit of temp" in text and "deg/s per unit of temp" in r.report()
