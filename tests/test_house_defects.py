"""The defects a new user met in the first hour (issue 13), each with the test that would have caught it."""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

import allanite  # noqa: E402
from allanite import cli  # noqa: E402
from allanite.estimators.confidence import edf_of  # noqa: E402
from allanite.model.fitting import READOFF_MIN_EDF  # noqa: E402
from allanite.report import build_report  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


# 3. the TheoH report ------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def theoh_report():
    y = allanite.simulate(200_000, 100.0, N=2e-3, B=5e-4, K=2e-5, seed=4)[:, None]
    return build_report(y, 100.0, unit="deg/s", estimator="theoh", window=200)


def test_dhvar_hop_never_skips_samples(theoh_report):
    s = theoh_report.summary()["dynamic"]
    # about 400 windows would need a hop of 500 > window 200: the hop stops at the window
    assert s["hop_samples"] == s["window_samples"] == 200
    assert "at most the window" in s["hop_rule"]
    assert 0 <= s["unused_samples"] < s["hop_samples"]
    n_samples = theoh_report.static.n_samples
    assert (s["windows"] - 1) * s["hop_samples"] + s["window_samples"] + s["unused_samples"] == n_samples


def test_theo_n_column_never_exceeds_the_record(theoh_report):
    st = theoh_report.summary()["static"]
    n_samples = theoh_report.static.n_samples
    assert max(st["n"]) <= n_samples + 1
    theo = [i for i, src in enumerate(st["source"]) if src == "theobr"]
    assert theo and all(st["n_stable32"][i] > st["n"][i] for i in theo if st["m"][i] > 2)
    assert "n_stable32" in st


def test_dhvar_coefficient_series_is_fitted(theoh_report):
    assert theoh_report.series is not None, theoh_report.series_error
    assert theoh_report.series_error is None


def test_bias_instability_readoff_ignores_points_with_one_degree_of_freedom():
    y = np.random.default_rng(5).normal(size=100_000) * 1e-3  # white rate: ADEV falls to the last τ
    h = allanite.avar(y, 100.0, estimator="theoh")
    f = allanite.fit(h, terms=("N",), unit="deg/s")
    ro = f.readoffs
    assert ro["tau_at_min"] == ro["readoff_tau_max"] < h.tau[-1]
    i = int(np.flatnonzero(np.isclose(h.tau, ro["tau_at_min"]))[0])
    nu = edf_of(h.source[i : i + 1], np.array([-1]), h.m[i : i + 1], h.n_samples + 1)
    assert nu[0] >= READOFF_MIN_EDF
    nu_last = edf_of(h.source[-1:], np.array([-1]), h.m[-1:], h.n_samples + 1)
    assert nu_last[0] < READOFF_MIN_EDF  # the point the read-off used to take


def test_fit_advice_names_thin_only_when_it_helps():
    y = np.random.default_rng(6).normal(size=4_000)
    r = allanite.avar(y, 1.0, taus="octave")
    with pytest.raises(allanite.ParameterError, match=r"or fit every τ \(thin=False\)"):
        allanite.fit(r, terms=("Q", "N", "B", "K", "R"), tau_range=(50, None))
    with pytest.raises(allanite.ParameterError) as exc:
        allanite.fit(r, terms=("Q", "N", "B", "K", "R"), tau_range=(200, None), thin=False)
    assert "thin=False" not in str(exc.value)


# 4. refinement in the report ----------------------------------------------------------------------


@pytest.fixture(scope="module")
def refined_report():
    y = allanite.simulate(300_000, 100.0, N=2e-3, K=2e-5, gauss_markov=[(5e-3, 10.0)], seed=11)
    y[150_000:] *= 1.0  # one stationary record: the GM is what the model lacks
    return build_report(y[:, None], 100.0, unit="deg/s", refine=True, window=30_000, hop=3_000)


def test_refinement_json_says_which_statistic_and_moves_final(refined_report):
    ref = refined_report.summary()["refinement"]
    ax = ref["axes"][0]
    assert [st["effect"] for st in ax["steps"] if st["statistic"] == "allan_curve"] == ["gauss_markov"]
    assert ax["final"]["chi2_dof"] < ax["start"]["chi2_dof"]
    assert ax["final"]["rms_adev_pct"] < ax["start"]["rms_adev_pct"]
    step = next(st for st in ax["steps"] if st["effect"] == "gauss_markov")
    assert step["units"] == {"sigma": "°/s", "tc": "s"}
    assert set(ref["statistics"]) == {"allan_curve", "window_levels"}


def test_refinement_is_printed_on_the_console(refined_report):
    text = refined_report.text()
    assert "Model refinement" in text and "gauss_markov: sigma = " in text and "tc = " in text


# 5. the command line ------------------------------------------------------------------------------


def test_cli_refuses_a_hop_longer_than_the_record(tmp_path, capsys):
    rc = cli.main(["report", "--hop", "10000000", "--out", str(tmp_path / "r"), "--quiet"])
    err = capsys.readouterr().err
    assert rc == 2
    assert "hop (10000000 samples) is longer than the record (360000 samples)" in err


def test_cli_says_a_binary_file_is_not_a_log(tmp_path, capsys):
    path = tmp_path / "capture.dat"
    path.write_bytes(bytes(range(256)) * 8)
    rc = cli.main(["report", str(path), "--fs", "100", "--out", str(tmp_path / "r"), "--quiet"])
    err = capsys.readouterr().err
    assert rc == 2
    assert "not a log allanite can read" in err and "binary data" in err
    assert "text (CSV/TSV, optionally .gz), .npy, .npz, Parquet and ROS bag" in err


def test_readme_marks_placeholders_and_says_where_test_data_lives():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert "gyro.csv.gz" in readme
    lines = readme.splitlines()
    for i, line in enumerate(lines):
        if "gyro.csv.gz" in line or "imu.csv.gz" in line:
            near = " ".join(lines[max(0, i - 1) : i + 2]).lower()
            assert "placeholder" in near or "your own" in near, line
    assert "../shared/data" in readme and "ALLANITE_SHARED_DATA" in readme and "skip" in readme


# 6. help(refine) ----------------------------------------------------------------------------------


def test_refine_help_lists_every_candidate_with_parameters_and_units():
    doc = allanite.refine.__doc__
    for effect in allanite.model.EFFECTS.values():
        assert f"``{effect.name!r}``" in doc
        for name, unit, _ in effect.params:
            assert f"``{name}`` ({unit})" in doc


def test_refine_help_lists_every_candidate_under_the_candidates_parameter():
    """help() and the numpydoc parse see the effects as one list inside ``candidates``'s description: every
    item indented alike, deeper than the parameter names (the registry's lines were once indented 8 where the
    docstring's placeholder stood at 4, so all but the first fell out to the parameters' column)."""
    import inspect

    lines = inspect.getdoc(allanite.refine).splitlines()
    items = [ln for ln in lines if ln.lstrip().startswith("- ``'")]
    assert len(items) == len(allanite.model.EFFECTS)
    assert {len(ln) - len(ln.lstrip()) for ln in items} == {4}
    start, end = lines.index("candidates : tuple of str"), lines.index("unit : str, optional")
    assert all(start < lines.index(ln) < end for ln in items)


# 7. coefficient series with unresolved windows ----------------------------------------------------


def test_unresolved_coefficients_are_gaps_with_upper_bounds_not_zeros():
    from allanite.model.fitting import CoefficientSeries

    t = np.arange(6.0)
    values = {"N": np.array([1.0, 1.1, 0.9, 1.0, 1.2, 1.0]), "K": np.array([0.5, 0.0, 0.6, 0.0, 0.0, 0.4])}
    lo = {k: 0.8 * v for k, v in values.items()}
    hi = {"N": 1.2 * values["N"], "K": np.array([0.7, 0.3, 0.8, 0.35, 0.2, 0.6])}
    s = CoefficientSeries(
        t=t, terms=("N", "K"), values=values, ci_low=lo, ci_high=hi, chi2_dof=np.ones(6), confidence=0.683
    )
    axes = s.plot(ieee=False)
    line = axes[1].get_lines()[0]
    shown = np.asarray(line.get_ydata(), dtype=float)
    assert np.isnan(shown[[1, 3, 4]]).all() and np.allclose(shown[[0, 2, 5]], [0.5, 0.6, 0.4])
    markers = [ln for ln in axes[1].get_lines() if ln.get_marker() == "v"]
    assert len(markers) == 1
    up = np.asarray(markers[0].get_ydata(), dtype=float)
    assert np.allclose(up[[1, 3, 4]], [0.3, 0.35, 0.2]) and np.isnan(up[[0, 2, 5]]).all()
    assert not np.any(axes[0].get_lines()[0].get_marker() == "v")


def test_summary_json_of_the_bundled_report_is_valid(tmp_path):
    rc = cli.main(["report", "--out", str(tmp_path / "r"), "--quiet", "--no-fit"])
    assert rc == 0
    s = json.loads((tmp_path / "r" / "summary.json").read_text())
    assert s["dynamic"]["hop_rule"] == "window/25" and s["dynamic"]["window_rule"] == "record/12"
