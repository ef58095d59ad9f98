"""The report's memory budget and side files (issue 30 items 3–4).

A request over the budget is refused before any heavy work, naming its size and a hop that fits; a report of
more than SIDE_FILE_WINDOWS windows writes its per-window series to series.npz (and series.parquet with
pyarrow) and names them in summary.json, whose own per-window lists are then left out.
"""

from __future__ import annotations

import importlib.util
import json
import re

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

import allanite  # noqa: E402
from allanite import cli  # noqa: E402
from allanite.report import budget, build, build_report  # noqa: E402
from allanite.report.sidefiles import NPZ, PARQUET  # noqa: E402

#: a budget that holds the report's fixed part and a few thousand of these windows, not 39 001
SMALL = budget.FIXED_BYTES + 8 * 2**20


@pytest.fixture(scope="module")
def record():
    return allanite.simulate(40_000, 100.0, N=0.01, B=1e-3, seed=7)


def _no_heavy_work(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("heavy work started before the budget check")

    for name in ("avar", "davar", "fit_model"):
        monkeypatch.setattr(build, name, refuse)


def test_an_over_budget_request_is_refused_before_any_heavy_work(record, monkeypatch):
    _no_heavy_work(monkeypatch)
    with pytest.raises(allanite.MemoryBudgetError, match=r"report would hold about .* GiB .*39001 DAVAR windows") as e:
        build_report(record, 100.0, unit="deg/s", window=1000, hop=1, max_memory=SMALL)
    hop = int(re.search(r"use hop=(\d+) or more", str(e.value)).group(1))
    # the hop it names passes the check (the work then starts), the one before it does not
    with pytest.raises(AssertionError, match="heavy work started"):
        build_report(record, 100.0, unit="deg/s", window=1000, hop=hop, max_memory=SMALL)
    with pytest.raises(allanite.MemoryBudgetError):
        build_report(record, 100.0, unit="deg/s", window=1000, hop=hop - 1, max_memory=SMALL)


def test_the_budget_comes_from_the_environment(record, monkeypatch):
    _no_heavy_work(monkeypatch)
    monkeypatch.setenv("ALLANITE_MAX_MEMORY", str(SMALL))
    with pytest.raises(allanite.MemoryBudgetError, match=rf"over the memory budget of {SMALL / 2**30:.2f} GiB"):
        build_report(record, 100.0, window=1000, hop=1)


def test_a_budget_below_the_fixed_part_says_no_hop_helps(record, monkeypatch):
    _no_heavy_work(monkeypatch)
    with pytest.raises(allanite.MemoryBudgetError, match="even two windows do not fit"):
        build_report(record, 100.0, window=1000, hop=1, max_memory=2**20)


def test_the_command_line_refuses_with_a_hop_option(tmp_path, capsys):
    log = tmp_path / "y.npy"
    np.save(log, allanite.simulate(40_000, 100.0, N=0.01, seed=2))
    code = cli.main(["report", str(log), "--fs", "100", "--window", "1000", "--hop", "1", "--max-memory", str(SMALL)])
    err = capsys.readouterr().err
    assert code != 0
    assert re.search(r"use --hop \d+ or more, or raise --max-memory", err), err
    assert not (tmp_path / "report").exists() or not any((tmp_path / "report").iterdir())


def test_a_report_of_many_windows_writes_its_series_beside_summary_json(record, tmp_path):
    rep = build_report(record, 100.0, unit="deg/s", window=400, hop=15, progress=False)
    n_win = rep.dynamic.t.size
    assert n_win > budget.SIDE_FILE_WINDOWS
    paths = rep.write(tmp_path, progress=False)
    summary = json.loads((tmp_path / "summary.json").read_text())
    side = summary["side_files"]["series"]
    assert side["npz"] == NPZ and side["windows"] == n_win
    assert summary["files"]["side_files"] == [p.name for p in paths if p.suffix in (".npz", ".parquet")]
    # the JSON keeps statistics, not the per-window lists
    assert summary["dynamic"]["t_s"] is None
    ser = summary["fit"]["series"]["axes"][0]
    assert ser["per_window"] == "side_files" and ser["coefficients"]["N"]["value"] is None
    assert ser["coefficients"]["N"]["stats"]["median"] > 0
    data = np.load(tmp_path / NPZ)
    assert sorted(data.files) == sorted(side["columns"])
    np.testing.assert_array_equal(data["t_s"], rep.dynamic.t)
    np.testing.assert_array_equal(data["axis0_N_value"], rep.series[0].values["N"])
    np.testing.assert_array_equal(data["axis0_N_ci_high"], rep.series[0].ci_high["N"])
    assert data["axis0_N_ieee"][0] == pytest.approx(rep.series[0].ieee["N"][0], rel=1e-15)
    if importlib.util.find_spec("pyarrow") is not None:
        import pyarrow.parquet as pq

        table = pq.read_table(tmp_path / PARQUET)
        assert side["parquet"] == PARQUET and table.num_rows == n_win
        np.testing.assert_array_equal(table.column("axis0_B_value").to_numpy(), rep.series[0].values["B"])


def test_a_report_of_few_windows_keeps_its_series_in_the_json(record):
    rep = build_report(record[:20_000], 100.0, unit="deg/s", progress=False)
    assert rep.dynamic.t.size <= budget.SIDE_FILE_WINDOWS
    summary = rep.summary()
    assert summary["side_files"] is None
    assert len(summary["fit"]["series"]["axes"][0]["coefficients"]["N"]["value"]) == rep.dynamic.t.size
