"""refine on a record with NaN-marked gaps (``gaps="skip"``): the fill (the line between the gap's neighbourhood
medians), the limits it refuses beyond, what ``Refinement.filled`` and the report say, and a sinusoid still found
through the gaps (benches/refine_gaps.py: the false-alarm side on clean records)."""

from __future__ import annotations

import numpy as np
import pytest

import allanite
from allanite.errors import DataGapError, InputError, ParameterError
from allanite.model.refinement._gapfill import check_gaps, fill_gaps, gap_runs
from sensors import dropped

FS = 100.0


def test_gap_runs_and_the_fill_of_a_line_is_the_line():
    t = np.arange(200, dtype=np.float64)
    y = 3.0 + 0.5 * t
    z = y.copy()
    z[[0, 1, 50, 51, 52, 120, 199]] = np.nan
    runs = gap_runs(np.isnan(z))
    np.testing.assert_array_equal(runs, [[0, 2], [50, 3], [120, 1], [199, 1]])
    # inside the record: the line through each side's median of a straight line is that line
    out = fill_gaps(z, runs)
    np.testing.assert_allclose(out[2:199], y[2:199], rtol=0, atol=1e-12)
    # at its ends one side only: flat at that side's median (8 samples)
    np.testing.assert_allclose(out[:2], np.median(y[2:10]))
    np.testing.assert_allclose(out[199], np.median(y[191:199]))


def test_the_fill_is_the_neighbourhood_medians_not_the_single_neighbours():
    y = np.zeros(100)
    y[39] = 50.0  # a spike beside the gap: one neighbour; the median of the 8 before it ignores it
    y[40:44] = np.nan
    out = fill_gaps(y, gap_runs(np.isnan(y)))
    np.testing.assert_array_equal(out[40:44], 0.0)


def test_too_many_missing_or_a_gap_too_long_is_a_data_gap_error():
    miss = np.zeros(1_000, dtype=bool)
    miss[::15] = True  # 6.7 % in gaps of one sample
    with pytest.raises(DataGapError, match=r"67 of 1000 samples \(6.7 %\) are missing.*at most 5 %"):
        check_gaps(miss, FS)
    miss = np.zeros(1_000, dtype=bool)
    miss[100:112] = True  # 1.2 % of the record in one gap
    with pytest.raises(DataGapError, match=r"a gap of 12 samples \(0.12 s\) from sample 100 is longer than 1 %"):
        check_gaps(miss, FS)
    assert issubclass(DataGapError, ValueError)


def test_a_channels_gaps_are_filled_as_the_samples():
    from allanite.model.refinement._gapfill import fill_channel

    temp = np.linspace(20.0, 25.0, 1_000)
    gappy = temp.copy()
    gappy[[10, 11, 500]] = np.nan  # read_log(gaps="nan") marks the channels at the same gaps
    np.testing.assert_allclose(fill_channel("temp", gappy, FS), temp, atol=1e-12)
    assert fill_channel("temp", temp, FS) is temp
    gappy[600:620] = np.nan
    with pytest.raises(DataGapError, match="channel 'temp': a gap of 20 samples"):
        fill_channel("temp", gappy, FS)


def test_nan_without_gaps_skip_is_an_input_error_naming_it():
    y = allanite.simulate(4_096, FS, N=0.01, seed=1)
    y[77] = np.nan
    with pytest.raises(InputError, match=r"first at sample 77\): refine\(\.\.\., gaps='skip'\)"):
        allanite.refine(y, FS)
    with pytest.raises(ParameterError, match="unknown gaps"):
        allanite.refine(y, FS, gaps="nan")
    r = allanite.avar(y, FS, gaps="skip")
    with pytest.raises(ParameterError, match="not its AllanResult"):
        allanite.refine(r)


def test_a_sinusoid_is_found_through_the_gaps_and_the_fill_is_stated():
    y = allanite.simulate(2**13, FS, N=0.01, sinusoid=[(0.02, 2.3)], seed=3)
    z = dropped(y, 4)
    r = allanite.refine(z, FS, gaps="skip", candidates=("sinusoid",))
    assert r.found == ["sinusoid"]
    st = r.steps[0]
    assert st.params["amplitude"] == pytest.approx(0.02, rel=0.2)
    assert st.params["f0"] == pytest.approx(2.3, rel=0.01)
    f = r.filled
    assert f["samples"] == int(np.isnan(z).sum()) == 80 and f["gaps"] == 20 and f["longest_s"] == 0.04
    assert f["fraction"] == pytest.approx(80 / 2**13)
    assert [tuple(g) for g in gap_runs(np.isnan(z))] == f["runs"]
    assert 0.0 < f["curve_change_pct"] < 5.0
    assert "Gaps: 80 samples missing (0.98 %) in 20 gap(s)" in r.report()
    # a gapless record says nothing of gaps (refine's inputs: its samples as given, no fill)
    from allanite.model.refinement._inputs import inputs

    got, _res, _ch, filled = inputs(y, FS, "rate", 300, None, None, "skip")
    assert filled is None and np.array_equal(got, y)


def test_report_of_a_log_with_gaps_marked_nan(tmp_path, capsys):
    import json

    from allanite import cli

    n = 4_000
    t = np.arange(n) / 50.0
    y = allanite.simulate(n, 50.0, N=0.01, seed=7)
    keep = np.ones(n, dtype=bool)
    keep[[700, 701, 702, 2500, 2501]] = False  # two gaps: 3 and 2 rows missing
    log = tmp_path / "gappy.csv"
    np.savetxt(log, np.c_[t[keep], y[keep]], delimiter=",", header="t,gx", comments="")
    out = tmp_path / "out"
    args = ["report", str(log), "--time-column", "t", "--unit", "deg/s", "--gaps", "nan", "--quiet", "--out", str(out)]
    assert cli.main(args) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["samples"] == n
    notes = " ".join(summary["notes"])
    assert "The log has 2 gap(s): 5 missing rows marked NaN (--gaps nan)" in notes
    assert "gx: 5 of 4000 samples missing (0.12 %)" in notes
    assert "could not be fitted" not in notes and summary["fit"]["error"] is None
    n_coef = summary["fit"]["axes"][0]["coefficients"]["N"]
    assert n_coef["value"] == pytest.approx(0.01, rel=0.05) and n_coef["ci"][0] < 0.01 < n_coef["ci"][1]


def test_the_report_identifies_the_noise_through_the_gaps_on_the_same_fill():
    # the report joined a gap's two single neighbours to identify each τ's noise type behind the intervals: a spike
    # beside each gap became a ramp across it, and white noise read as flicker and random-walk FM at the shortest τ
    # (-1, -2, -2). It fills as refine does now (filled_columns): the types of the record before the drop
    from allanite.model.refinement._gapfill import filled_columns
    from allanite.report.build import build_report

    y = allanite.simulate(20_000, FS, N=0.01, K=1e-3, seed=0)
    z = dropped(y, 0)
    nan = np.isnan(z)
    z[np.flatnonzero(nan[1:] & ~nan[:-1])] += 3.0  # a 30σ spike before each gap (a logger's glitch as it drops)
    st = build_report(z, FS, unit="deg/s", gaps="skip", fit=False).static
    before = st.with_confidence(np.where(nan, y, z)[:, None])  # the same spikes, the gaps' samples present
    np.testing.assert_array_equal(st.alpha, before.alpha)
    assert list(st.alpha[0, :3]) == [0, 0, 0]  # white FM at τ0..4τ0
    np.testing.assert_allclose(st.ci_high, before.ci_high, rtol=1e-12)
    # the filler: each column's runs as fill_gaps fills them, an all-NaN column left NaN
    two = filled_columns(np.column_stack([z, np.full(z.size, np.nan)]))
    np.testing.assert_array_equal(two[:, 0], fill_gaps(z, gap_runs(nan)))
    assert np.isnan(two[:, 1]).all() and not np.isnan(two[:, 0]).any()


def test_angle_channel_read_at_the_angle_instants_is_averaged_per_interval():
    """A clock's temperature logged with each of its M + 1 phase readings: refine's input check takes the mean of
    each interval's two ends (it refused the channel, M + 1 samples against M rates); M samples stay as given."""
    from allanite.model.refinement._inputs import inputs

    rng = np.random.default_rng(3)
    phase = np.cumsum(rng.standard_normal(4001)) * 1e-9
    temp = 20.0 + np.cumsum(rng.standard_normal(4001)) * 0.01
    y, _res, chans, _f = inputs(phase, 1.0, "angle", 50, None, {"temp": temp, "v": temp[1:]})
    assert y.size == 4000
    np.testing.assert_array_equal(chans["temp"], 0.5 * (temp[1:] + temp[:-1]))
    np.testing.assert_array_equal(chans["v"], temp[1:])
    with pytest.raises(ValueError, match="has 4001 samples; the rate has 4000"):
        inputs(np.diff(phase), 1.0, "rate", 50, None, {"temp": temp})


def test_refine_takes_a_clocks_phase_word():
    """``input="phase"`` (allantools' and Stable32's word) is ``input="angle"``: refine's curve is the angle record's
    (it refused the word, naming 'angle')."""
    rng = np.random.default_rng(4)
    phase = np.cumsum(rng.standard_normal(5001)) * 1e-9
    theirs = allanite.refine(phase, 1.0, input="phase", candidates=("gauss_markov",), progress=False)
    mine = allanite.avar(phase, 1.0, input="angle", taus=theirs.result.tau)
    np.testing.assert_allclose(theirs.result.avar, mine.avar, rtol=1e-12)
    assert theirs.result.n_samples == 5000
