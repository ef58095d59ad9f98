"""A long or memory-mapped record in the report (issue 30 item 4): never materialised whole.

A memory-mapped ``.npy`` is read through its file (allanite._mapped: none of the map's pages enters the
process), one axis at a time (allanite.report.axes), with the same numbers as the in-memory report; the noise
identification of a long rate record works in chunks (allanite.estimators._long_id) and agrees with the
whole-array code; the report's memory budget counts the record's analysis and takes the axis-by-axis path
where all axes at once would not fit. Small records throughout: the sizes at which these paths matter are
measured in benches/bench_pipeline.py, not here.
"""

from __future__ import annotations

import sys
import tracemalloc
from pathlib import Path

import numpy as np
import pytest

import allanite
from allanite import _mapped
from allanite._mapped import column, columns, file_layout, read_rows
from allanite.estimators import _long_id, confidence, noise_id
from allanite.report import axes, budget, build_report
from allanite.report import build as report_build
from allanite.report.build import from_log

N = 120_000


@pytest.fixture(scope="module")
def npy(tmp_path_factory) -> Path:
    rng = np.random.default_rng(11)
    y = np.column_stack(
        [
            allanite.simulate(N, 100.0, N=0.01, K=1e-3, seed=1),
            allanite.simulate(N, 100.0, N=0.02, B=1e-3, seed=2),
            0.3 + rng.normal(size=N) * 0.05,
        ]
    )
    path = tmp_path_factory.mktemp("mapped") / "rec.npy"
    np.save(path, y)
    return path


def _mapped_rss_kb(path: Path) -> int | None:
    """Resident kB of this process's mappings of ``path`` (Linux /proc/self/smaps), None elsewhere."""
    smaps = Path("/proc/self/smaps")
    if not smaps.exists():
        return None
    total, inside = 0, False
    for line in smaps.read_text().splitlines():
        head = line.split()
        if head and "-" in head[0] and len(head) >= 5:  # a mapping's header line
            inside = line.rstrip().endswith(str(path))
        elif inside and line.startswith("Rss:"):
            total += int(head[1])
    return total


def test_rows_and_columns_of_a_mapped_npy_come_from_the_file(npy):
    x = np.load(npy, mmap_mode="r")
    full = np.load(npy)
    for view, ref in ((x, full), (x[:, 1:], full[:, 1:]), (x[17:, :], full[17:, :]), (x[3:999:4], full[3:999:4])):
        assert file_layout(view) is not None
        for k in range(view.shape[1]):
            got = column(view, k, chunk=1001)
            assert got.flags.c_contiguous and np.array_equal(got, ref[:, k])
        assert np.array_equal(read_rows(view, 5, 40), ref[5:40])
    assert np.array_equal(read_rows(x[:, 2], 10, 20), full[10:20, 2])
    # not a read-only map of a file: NumPy's copy
    assert file_layout(full) is None and np.array_equal(column(full, 0), full[:, 0])
    if sys.platform.startswith("linux"):
        assert _mapped_rss_kb(npy) == 0  # the checks above compared against `full`, never touching `x`


def test_one_pass_over_the_file_gives_each_axis_exactly(npy):
    x = np.load(npy, mmap_mode="r")
    for view in (x, x[7:, 1:], x[3:999:4]):
        for chunk in (1001, 4096, None):
            got = columns(view, list(range(view.shape[1]))[::-1], chunk=chunk)
            for k, c in zip(list(range(view.shape[1]))[::-1], got):
                assert c.flags.c_contiguous and np.array_equal(c, column(view, k, chunk=777))
    assert np.array_equal(columns(x[:, 2], [None])[0], column(x, 2))
    if sys.platform.startswith("linux"):
        assert _mapped_rss_kb(npy) == 0


def test_axes_read_in_one_pass_where_the_budget_holds_them(npy, monkeypatch):
    """The report reads as many axes per pass as the budget holds beside one axis's analysis, with the same
    numbers as one pass per axis."""
    n = N
    cost = budget.check_report_memory(n, 3, 12_000, 3_000, 10, 10, 5, False, record=axes.record_bytes(n, 3, True))
    one = cost["total"]
    assert axes.axes_per_read(n, 3, one, one) == 1
    assert axes.axes_per_read(n, 3, one, one + 8 * n) == 2
    assert axes.axes_per_read(n, 3, one, 10 * one) == 3
    passes: list[list] = []
    monkeypatch.setattr(axes, "columns", lambda x, ks: passes.append(ks) or columns(x, ks))
    x = np.load(npy, mmap_mode="r")
    kw = dict(window=12_000, hop=3_000, progress=False, fit=False)
    together = build_report(x, 100.0, **kw)
    assert passes == [[0, 1, 2]]
    monkeypatch.setattr(report_build, "axes_per_read", lambda *a: 1)
    apart = build_report(x, 100.0, **kw)
    assert passes[1:] == [[0], [1], [2]]
    for a, b in ((together.static, apart.static), (together.dynamic, apart.dynamic)):
        for name in ("avar", "edf", "ci_low", "ci_high", "alpha"):
            va, vb = getattr(a, name), getattr(b, name)
            assert (va is None and vb is None) or np.array_equal(va, vb), name


@pytest.fixture(scope="module")
def reports(npy):
    log = allanite.read_log(npy, fs=100.0, unit="deg/s")
    mapped = from_log(log, window=12_000, hop=3_000, progress=False)
    rss = _mapped_rss_kb(npy)
    in_memory = build_report(
        np.load(npy), 100.0, unit="deg/s", window=12_000, hop=3_000, progress=False, axis_names=["col0", "col1", "col2"]
    )
    return mapped, in_memory, rss


def test_a_mapped_record_is_analysed_axis_by_axis_from_its_file(reports):
    mapped, in_memory, rss = reports
    assert mapped.settings["by_axis"] and not in_memory.settings["by_axis"]
    if rss is not None:
        assert rss == 0, f"{rss} kB of the mapped record were read into the process"


def test_axis_by_axis_gives_the_all_axes_numbers(reports):
    mapped, in_memory, _ = reports
    for a, b in ((mapped.static, in_memory.static), (mapped.dynamic, in_memory.dynamic)):
        assert type(a) is type(b)
        for name in ("tau", "avar", "n", "m", "edf", "ci_low", "ci_high", "alpha"):
            va, vb = getattr(a, name), getattr(b, name)
            assert (va is None and vb is None) or (np.shape(va) == np.shape(vb) and np.array_equal(va, vb)), name
    sa, sb = mapped.summary(), in_memory.summary()
    assert sa["fit"] == sb["fit"]


def test_the_report_of_a_mapped_record_never_holds_all_its_axes(npy, monkeypatch):
    """Traced allocations (NumPy's) stay below one copy of every axis, which the all-axes path makes: one
    axis at a time, read in small chunks, identified in chunks (what a long record gets, whose axes the
    budget does not hold together: one axis per pass)."""
    monkeypatch.setattr(report_build, "axes_per_read", lambda *a: 1)
    monkeypatch.setattr(_mapped, "CHUNK_BYTES", 1 << 16)
    monkeypatch.setattr(noise_id, "LONG_SAMPLES", 1000)
    monkeypatch.setattr(_long_id, "CHUNK", 4096)
    x = np.load(npy, mmap_mode="r")
    tracemalloc.start()
    try:
        rep = build_report(x, 100.0, window=12_000, hop=3_000, progress=False, fit=False)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert rep.settings["by_axis"]
    assert peak < x.nbytes, f"peak {peak / 2**20:.2f} MiB for a {x.nbytes / 2**20:.2f} MiB record"


def test_the_budget_counts_the_record_and_goes_axis_by_axis_where_all_axes_do_not_fit(npy):
    y = np.load(npy)  # in memory
    n, n_axes = y.shape
    ms = allanite.estimators.get("oavar").resolve_m("exp", 12_000, 100.0)
    req = (n, n_axes, 12_000, 3_000, ms.size, ms.size, 5, False)
    one = budget.check_report_memory(*req, record=axes.record_bytes(n, n_axes, True))
    assert one["record"] == 8 * n + 16 * n  # one axis, and the core's double-word phase of it
    every = budget.report_memory(37, n_axes, ms.size, ms.size, 5, False, axes.record_bytes(n, n_axes, False))
    assert every["record"] == 8 * n * 3 + 16 * n * 3
    between = (one["total"] + every["total"]) // 2  # one axis at a time fits, all axes at once do not
    rep = build_report(y, 100.0, window=12_000, hop=3_000, fit=False, progress=False, max_memory=between)
    assert rep.settings["by_axis"]
    full = build_report(y, 100.0, window=12_000, hop=3_000, fit=False, progress=False, max_memory=every["total"])
    assert not full.settings["by_axis"]
    with pytest.raises(allanite.MemoryBudgetError, match=r"the record's analysis 0\.00 GiB\), over the memory"):
        build_report(y, 100.0, window=12_000, hop=3_000, fit=False, progress=False, max_memory=one["total"] - 1)


@pytest.mark.parametrize("kind", ["white", "random walk", "white phase", "flicker phase"])
def test_the_chunked_noise_identification_agrees_with_the_whole_array(kind, monkeypatch):
    rng = np.random.default_rng(3)
    n = 60_000
    x = {
        "white": rng.normal(size=n),
        "random walk": np.cumsum(rng.normal(size=n)) * 1e-2 + rng.normal(size=n),
        "white phase": np.diff(rng.normal(size=n + 1)),
        "flicker phase": np.diff(np.cumsum(rng.normal(size=n + 1)) * 0.01 + rng.normal(size=n + 1)),
    }[kind]
    ms = 2 ** np.arange(14)  # up to n/4: the B1/R(n) branch at the longest
    whole = confidence.identify_alpha(x, ms, input="rate")
    monkeypatch.setattr(noise_id, "LONG_SAMPLES", 1000)
    monkeypatch.setattr(_long_id, "CHUNK", 777)  # every m in chunks, chunks not aligned with anything
    assert np.array_equal(confidence.identify_alpha(x, ms, input="rate"), whole)
    # the pieces: block averages and phase bit for bit, sums to rounding
    lr = _long_id.LongRate(x, x.mean())
    rate = x - x.mean()
    phase = np.concatenate(([0.0], np.cumsum(rate)))
    assert np.array_equal(lr.phase(), phase)
    for m in (1, 3, 64):
        z = rate[: n // m * m].reshape(-1, m).mean(axis=1)
        assert np.array_equal(_long_id.LongRate(x, x.mean()).all_means(m), z)  # from the record: bit for bit
        np.testing.assert_allclose(lr.all_means(m), z, rtol=1e-13, atol=1e-15 * np.abs(z).max())  # from m = 1's
        got = lr.lag1_acfs(m)
        for d in (0, 1, 2):
            w = np.diff(z, n=d) if d else z
            assert got[d] == (pytest.approx(noise_id._lag1_acf(w), abs=1e-12), w.size)
    for m in (5, 1000, 9000, 19_000):
        assert lr.rn(m) == pytest.approx(noise_id._rn(phase, m), rel=1e-11)


def test_the_cores_block_acf_sums_refuse_a_factor_longer_than_the_record():
    from allanite import _core

    with pytest.raises(allanite.AllaniteError, match=r"averaging factor 4 for 3 samples: 1 ≤ m ≤ samples"):
        _core.block_lag1_sums(np.arange(3.0), 0.0, [4], 2, 1)
    with pytest.raises(allanite.AllaniteError, match=r"averaging factor 0 for 3 samples"):
        _core.block_lag1_sums(np.arange(3.0), 0.0, [1, 0], 2, 1)
