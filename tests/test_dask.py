"""allanite.dask: the single-machine numbers on a Dask cluster (issue 19).

A LocalCluster of 2 in-process workers on loopback. DAVAR: every block hands the Rust core its part of
the record with the record's centring value (the core's compensated sum, chained over the chunks in
order) and its first window, and the core follows the record's own path: bit for bit. Where the
record's call streams its sums (the classic estimator; the overlapping one beyond 2^26 samples × axes,
i.e. every record larger than memory) the part forms the same terms and sums in the same order (these
small test records show it with the classic estimator; rust/core/src/allan.rs tests the overlapping
streaming path part by part). Below 2^26 the single machine builds a double-word phase per segment of
max(2^22, 16 · window) samples' worth of windows, and the chunks are whole segments: one chunk for the
small records here, two and more in ``test_davar_phase_segments_across_chunks``. The static variance on
the exact angle agrees to rounding (≤ 1e-12; another order of sums).
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import allanite

pytest.importorskip("dask", reason="allanite.dask needs dask (pip install 'allanite[dask]')")
pytest.importorskip("distributed", reason="allanite.dask needs distributed (pip install 'allanite[dask]')")

import dask.array as da  # noqa: E402
from distributed import Client, LocalCluster  # noqa: E402

from allanite import dask as adask  # noqa: E402
from allanite.errors import InputError, ParameterError  # noqa: E402

REL = 1e-12


@pytest.fixture(scope="module")
def client():
    with (
        LocalCluster(
            n_workers=2,
            threads_per_worker=1,
            processes=False,
            dashboard_address=None,  # inproc: no sockets
        ) as cluster,
        Client(cluster, timeout="20s") as c,
    ):
        yield c


def _record(n=20_011, axes=3, seed=0):
    rng = np.random.default_rng(seed)
    y = rng.normal(size=(n, axes)) * np.array([1.0, 1e-3, 50.0])[:axes]
    y += np.array([0.0, 7.0, 1e4])[:axes]  # a bias far above the noise on two axes
    y[: n // 2] *= 3.0  # the noise level changes along the record
    return y


def _rel(a, b):
    return float(np.max(np.abs(a / b - 1.0)))


def test_importing_allanite_does_not_import_dask():
    code = "import sys, allanite; allanite.avar([1.0, 2.0, 4.0], 1.0); print('dask' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


@pytest.mark.parametrize("estimator", ["oavar", "avar"])
@pytest.mark.parametrize("chunk", [997, 20_011])
def test_static_equals_single_machine(client, estimator, chunk):
    y = _record()
    x = da.from_array(y, chunks=(1234, 2))
    ref = allanite.avar(y, 100.0, estimator=estimator)
    got = adask.avar(x, 100.0, estimator=estimator, chunk=chunk, client=client)
    assert got.avar.shape == ref.avar.shape == (3, ref.tau.size)
    np.testing.assert_array_equal(got.tau, ref.tau)
    np.testing.assert_array_equal(got.n, ref.n)
    assert _rel(got.avar, ref.avar) <= REL
    # 1-D, m up to n/2 (the three slices span many chunks), odd length
    y1 = y[:1001, 2]
    ref1 = allanite.avar(y1, 10.0, estimator=estimator, taus="exp")
    got1 = adask.avar(da.from_array(y1, chunks=300), 10.0, estimator=estimator, taus="exp", chunk=97, client=client)
    assert got1.avar.shape == ref1.avar.shape
    assert _rel(got1.avar, ref1.avar) <= REL


@pytest.mark.parametrize("classic", [False, True])
def test_static_kernel_equals_its_numpy_twin(classic):
    # the Rust per-task kernel forms the same exact second differences as the NumPy code it replaced
    # (allanite._reference.angle_term_sums); only the summation of d² differs
    from allanite._reference import angle_term_sums as twin
    from allanite.estimators.allan import angle_term_sums

    y = _biased(40_003, seed=5)
    q_exp = math.frexp(float(np.max(np.abs(y))))[1] - adask.arrays.QUANTUM_BITS
    cut = [0, 9_000, 17_000, 26_000, 40_003]
    whole = np.rint(np.ldexp(y, -q_exp)).astype(np.int64)
    rest = np.ldexp(y, -q_exp) - np.rint(np.ldexp(y, -q_exp))
    off_w = [whole[:c].sum(axis=0) for c in cut[:-1]]
    off_r = [np.array([math.fsum(rest[:c, a]) for a in range(3)]) for c in cut[:-1]]
    blocks = [y[a:b] for a, b in zip(cut, cut[1:])]
    for ks, plan in [
        ([0, 1, 2], [(1, 0, 9_000), (7, 100, 9_000), (4_000, 0, 9_000), (8_499, 0, 9_000), (333, 5_000, 9_000)]),
        ([0, 2], [(8_600, 8_500, 8_601)]),  # the three slices in two runs of chunks
        ([0, 2, 3], [(8_500, 8_500, 9_000)]),
    ]:
        args = ([blocks[k] for k in ks], [cut[k] for k in ks], [off_w[k] for k in ks], [off_r[k] for k in ks])
        got = angle_term_sums(*args, q_exp, plan, classic, 1)
        want = twin(*args, q_exp, plan, classic)
        assert got.shape == want.shape == (len(plan), 3)
        assert _rel(got, want) <= 1e-13
        # and bit-identical for any number of threads
        np.testing.assert_array_equal(angle_term_sums(*args, q_exp, plan, classic, 2), got)


def test_static_increment_input_and_scale(client):
    y = _record(5_003, 2) * 1e-100  # tiny increments: the quantum is a power of two, exact
    ref = allanite.avar(y, 50.0, input="increment")
    got = adask.avar(da.from_array(y, chunks=1000), 50.0, input="increment", chunk=1001, client=client)
    assert _rel(got.avar, ref.avar) <= REL


@pytest.mark.parametrize(
    ("window", "hop", "chunk"),
    [(5_000, 333, 4_000), (2_001, 7, 3_000), (20_011, 1, 4_000), (3, 1, 1_000), (1_000, 1_500, 2_000)],
)
def test_davar_equals_single_machine(client, window, hop, chunk):
    y = _record()
    x = da.from_array(y, chunks=(1777, 3))
    ref = allanite.davar(y, 100.0, window=window, hop=hop)
    with client.as_current():
        got = adask.davar(x, 100.0, window=window, hop=hop, chunk=chunk)
    assert got.avar.shape == ref.avar.shape
    np.testing.assert_array_equal(got.t, ref.t)
    np.testing.assert_array_equal(got.tau, ref.tau)
    # the single machine's phase path: one segment here (the record is < 2^22 samples), one chunk
    np.testing.assert_array_equal(got.avar, ref.avar)
    # the classic estimator streams on one machine too: bit for bit, the 7000 σ axis included
    ref = allanite.davar(y, 100.0, window=window, hop=hop, estimator="avar")
    with client.as_current():
        got = adask.davar(x, 100.0, window=window, hop=hop, chunk=chunk, estimator="avar")
    np.testing.assert_array_equal(got.avar, ref.avar)


def _biased(n=30_001, seed=7):
    """Three axes: a mean at 7000 σ, a noise level that changes along the record, a slow swing."""
    rng = np.random.default_rng(seed)
    t = np.arange(n)
    y = rng.normal(size=(n, 3)) * np.array([1e-3, 2.0, 0.5])
    y[:, 0] += 7.0  # 7000 σ
    y[: n // 3, 1] *= 40.0
    y[:, 2] += 300.0 * np.sin(2 * np.pi * t / 9_000.0)
    return y


@pytest.mark.parametrize("estimator", ["oavar", "avar"])
@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_davar_on_a_biased_record(client, estimator, dtype):
    # odd length, hops that divide neither the caller's chunks nor the plan's target, several axes,
    # float32 samples (widened exactly on both sides), windows across every block boundary
    y = _biased().astype(dtype)
    x = da.from_array(y, chunks=(2_345, 3))
    for window, hop, chunk, taus in [(4_001, 37, 5_000, "exp"), (2_500, 333, 2_600, "octave"), (999, 1, 1_200, [0.5])]:
        ref = allanite.davar(y, 50.0, window=window, hop=hop, taus=taus, estimator=estimator)
        with client.as_current():
            got = adask.davar(x, 50.0, window=window, hop=hop, taus=taus, chunk=chunk, estimator=estimator)
        np.testing.assert_array_equal(got.avar, ref.avar)
        np.testing.assert_array_equal(got.n, ref.n)
    if dtype is np.float32:
        return  # float32 samples at 7000 σ: sums of 24-bit values are mostly exact in any order
    # the equality is not a property of any block: a block's windows computed on their own (their own
    # mean, their own alignment) differ from the whole record's in the last bits (measured: 41–73 of
    # the 88 values per axis, up to 4e-14 relative)
    block = y[2 * 2_664 : 3 * 2_664 + 2_499]  # the third block of the (2_500, 333) plan, with its overlap
    alone = allanite.davar(block, 50.0, window=2_500, hop=333, taus="octave", estimator=estimator)
    whole = allanite.davar(y, 50.0, window=2_500, hop=333, taus="octave", estimator=estimator)
    first = 2 * 2_664 // 333
    part = whole.avar[:, :, first : first + alone.avar.shape[2]]
    assert np.count_nonzero(alone.avar != part) > part.size // 4
    assert float(np.max(np.abs(alone.avar / part - 1))) < 1e-12


def test_davar_naive_increment_and_scaled(client):
    y = _biased(12_007, seed=3)
    x = da.from_array(y, chunks=(1_000, 3))
    with client.as_current():
        # increments (converted per sample as on one machine), the naive method
        ref = allanite.davar(y * 1e-2, 100.0, window=1_500, hop=250, input="increment", method="naive")
        got = adask.davar(x * 1e-2, 100.0, window=1_500, hop=250, input="increment", method="naive", chunk=1_600)
        np.testing.assert_array_equal(got.avar, ref.avar)
        # samples beyond 2^200: both sides scale the columns by the same power of two, exactly
        for scale in (1e70, 1e-70):
            ref = allanite.davar(y * scale, 100.0, window=1_500, hop=250, estimator="avar")
            got = adask.davar(x * scale, 100.0, window=1_500, hop=250, chunk=1_600, estimator="avar")
            np.testing.assert_array_equal(got.avar, ref.avar)
            ref = allanite.davar(y * scale, 100.0, window=1_500, hop=250)
            got = adask.davar(x * scale, 100.0, window=1_500, hop=250, chunk=1_600)
            assert _rel(got.avar, ref.avar) <= 1e-14


def test_unaligned_blocks(client):
    # blocks that arrive from another worker may sit at odd addresses (seen on a process cluster):
    # the same numbers as from aligned memory
    y = _biased(6_007)
    raw = bytearray(y.nbytes + 1)
    u = np.frombuffer(raw, dtype=np.float64, offset=1).reshape(y.shape)
    u[...] = y
    x = da.from_array(u, chunks=(1_000, 3))
    with client.as_current():
        np.testing.assert_array_equal(
            adask.davar(x, 10.0, window=1_500, hop=100, chunk=1_200, estimator="avar").avar,
            allanite.davar(y, 10.0, window=1_500, hop=100, estimator="avar").avar,
        )
        np.testing.assert_array_equal(
            adask.wavelet_split(x, 10.0, level=3, chunk=1_000).high, allanite.wavelet_split(y, 10.0, level=3).high
        )
    assert _rel(adask.avar(x, 10.0, chunk=1_000, client=client).avar, allanite.avar(y, 10.0).avar) <= REL


def test_scale_exponent_is_the_single_machine_rule():
    # the exponent by which allanite.davar scales a column (allanite.analysis) for the same peaks
    from allanite.analysis import SAFE_EXP

    for peak, e in [(0.0, 0), (1.0, 0), (2.0**SAFE_EXP, SAFE_EXP + 1), (1e70, 233), (1e-70, -232)]:
        assert adask.arrays.scale_exponent(peak) == e


@pytest.mark.parametrize(
    ("wavelet", "level", "trend", "chunk"),
    [("db5", 5, "a5", 3_000), ("sym8", 6, "none", 2_000), ("haar", 7, "a5", 500), ("db5", 5, "none", 100_000)],
)
def test_wavelet_split_equals_single_machine(client, wavelet, level, trend, chunk):
    # odd length, the caller's chunks off the 2^level grid, three axes (one at 7000 σ)
    y = _biased(20_011)
    x = da.from_array(y, chunks=(1_777, 3))
    ref = allanite.wavelet_split(y, 100.0, wavelet=wavelet, level=level, trend=trend)
    with client.as_current():
        got = adask.wavelet_split(x, 100.0, wavelet=wavelet, level=level, trend=trend, chunk=chunk)
    for part in ("trend", "low", "high"):
        np.testing.assert_array_equal(getattr(got, part), getattr(ref, part))  # bit for bit
    assert got.bands == ref.bands and (got.wavelet, got.level, got.fs) == (ref.wavelet, ref.level, ref.fs)
    if chunk < y.shape[0] and wavelet != "haar":  # Haar's sums never leave an aligned block of 2^level
        # the overlap is needed: with less than half of it the samples next to the block edges change
        overlap = adask.arrays.wavelet_overlap(pywt_dec_len(wavelet), level)
        half = (overlap // 2 >> level << level) - (1 << level)
        short = _split_with_overlap(y, wavelet, level, trend, chunk, half)
        assert not np.array_equal(short, np.concatenate([ref.trend, ref.low, ref.high], axis=1))


def pywt_dec_len(wavelet):
    import pywt

    return pywt.Wavelet(wavelet).dec_len


def _split_with_overlap(y, wavelet, level, trend, chunk, overlap):
    """[trend | low | high] as allanite.dask forms them, with a given overlap (a shorter one fails)."""
    chunks = adask.arrays.wavelet_chunks(y.shape[0], level, overlap, chunk)
    out, start = [], 0
    for c in chunks:
        a, b = max(0, start - overlap), min(y.shape[0], start + c + overlap)
        s = allanite.wavelet_split(y[a:b], 100.0, wavelet=wavelet, level=level, trend=trend)
        keep = slice(start - a, start - a + c)
        out.append(np.concatenate([s.trend[keep], s.low[keep], s.high[keep]], axis=1))
        start += c
    return np.concatenate(out)


def test_wavelet_split_1d_lazy_float32_and_custom_bands(client):
    y = _biased(9_001)[:, 1].astype(np.float32)
    bands = {"trend": ("a4",), "low": ("d4",), "high": ("d3", "d2", "d1")}
    ref = allanite.wavelet_split(y, 10.0, level=4, bands=bands)
    with client.as_current():
        lazy = adask.wavelet_split(da.from_array(y, chunks=1_000), 10.0, level=4, bands=bands, compute=False)
        assert isinstance(lazy.high, da.Array) and lazy.high.shape == y.shape
        parts = da.compute(lazy.trend, lazy.low, lazy.high)
    for got, want in zip(parts, (ref.trend, ref.low, ref.high)):
        np.testing.assert_array_equal(got, want)
    assert lazy.bands == ref.bands


def test_wavelet_split_refuses_what_it_cannot_chunk(client):
    x = da.from_array(np.ones(1_000), chunks=100)
    with pytest.raises(ParameterError, match="periodic"):
        adask.wavelet_split(x, 1.0, trend="periodic")
    with pytest.raises(ParameterError, match="unknown wavelet"):
        adask.wavelet_split(x, 1.0, wavelet="morl")
    with pytest.raises(ParameterError, match="too deep"):
        adask.wavelet_split(x, 1.0, level=9)
    with pytest.raises(ParameterError, match="partition"):
        adask.wavelet_split(x, 1.0, bands={"low": ("d5",)})
    y = np.ones(5_000)
    y[4_321] = np.nan
    with client.as_current(), pytest.raises(InputError, match="sample 4321"):
        adask.wavelet_split(da.from_array(y, chunks=700), 1.0, level=3, chunk=700)
    assert adask.arrays.wavelet_overlap(10, 5) == 320  # db5 at level 5: the 320 samples


def test_davar_phase_segments_across_chunks(client):
    # a record past one phase segment (2^22 samples at these windows): the chunks are whole segments
    # (the core's part grid), each block rebuilds its segments' phases — bit for bit, several blocks
    n = 9_000_013
    y = np.random.default_rng(11).normal(size=n) * 0.3 + 5.0
    y[n // 2 :] *= 1e3  # the noise level changes by 10³ half-way
    for window, hop, taus in [(50_000, 1_000, "exp"), (2_000, 64, [1.0, 10.0]), (1_000, 3, [0.5, 2.0])]:
        grid = allanite._core.part_grid(n, 1, window, hop, "oavar", "fast")
        assert grid % hop == 0 and 2 <= -(-n // grid) <= 3
        ref = allanite.davar(y, 100.0, window=window, hop=hop, taus=taus)
        with client.as_current():
            x = da.from_array(y, chunks=1_000_000)
            got = adask.davar(x, 100.0, window=window, hop=hop, taus=taus, compute=False)
            assert got.numblocks[2] >= 2
            np.testing.assert_array_equal(got.compute(), ref.avar[None])


def test_davar_chunk_plan_is_exact():
    for n, w, h, t in [(20_011, 5_000, 333, 4_000), (10, 10, 1, 3), (1_000_003, 10_000, 1_000, 65_536)]:
        chunks, counts = adask.arrays.davar_chunks(n, w, h, t)
        assert sum(chunks) == n and sum(counts) == (n - w) // h + 1
        assert all(c % h == 0 and c >= w - 1 for c in chunks[:-1])
        chunks, counts = adask.arrays.davar_chunks(n, w, h, t, unit=7 * h)
        assert sum(chunks) == n and sum(counts) == (n - w) // h + 1
        assert all(c % (7 * h) == 0 and c >= w - 1 for c in chunks[:-1])
    with pytest.raises(ParameterError, match="multiple of the hop"):
        adask.arrays.davar_chunks(100, 10, 3, 20, unit=10)


def test_davar_1d_lazy(client):
    y = _record(9_001, 1)[:, 0]
    ref = allanite.davar(y, 10.0, window=2_000, hop=250, taus=[0.1, 1.0, 10.0])
    with client.as_current():
        lazy = adask.davar(
            da.from_array(y, chunks=500), 10.0, window=2_000, hop=250, taus=[0.1, 1.0, 10.0], compute=False
        )
        assert lazy.shape == (1, 3, ref.t.size)
        assert _rel(lazy.compute()[0], ref.avar) <= 1e-14


def test_bad_input_is_named(client):
    y = np.ones(100)
    y[57] = np.nan
    with pytest.raises(InputError, match="sample 57"):
        adask.avar(da.from_array(y, chunks=10), 1.0, client=client)
    with pytest.raises(ParameterError, match="theo1"):
        adask.avar(da.from_array(np.ones(100), chunks=10), 1.0, estimator="theo1")
    with pytest.raises(ParameterError, match="longer than the record"):
        adask.davar(da.from_array(np.ones(100), chunks=10), 1.0, window=101)
    # the centring pass finds the first non-finite sample in record order, with its record index
    y2 = np.ones((1_000, 2))
    y2[733, 1] = np.inf
    with client.as_current(), pytest.raises(InputError, match="sample 733 of axis 1"):
        adask.davar(da.from_array(y2, chunks=(100, 2)), 1.0, window=50, hop=10, chunk=100)


# ------------------------------------------------------------------------------------------------
# fleets


def _fleet(root, n_good=3, seed=1):
    import gzip

    rng = np.random.default_rng(seed)
    for i in range(n_good):
        d = root / "logs" / ("a" if i < 2 else "b")
        d.mkdir(parents=True, exist_ok=True)
        y = rng.normal(size=(4_000, 2)) * (30.0 if i == n_good - 1 else 1.0)
        with gzip.open(d / f"s{i}.csv.gz", "wt") as f:
            f.write("gx,gy\n")
            np.savetxt(f, y, fmt="%.8e", delimiter=",")
    (root / "logs" / "b").mkdir(parents=True, exist_ok=True)
    (root / "logs" / "b" / "bad.csv.gz").write_bytes(b"not gzip at all")
    return str(root / "logs" / "**" / "*.csv.gz")


def test_batch_reports_each_file_and_survives_a_malformed_one(client, tmp_path):
    import csv

    from allanite.report import from_log

    pattern = _fleet(tmp_path)
    out = tmp_path / "res"
    res = adask.batch(pattern, out=out, fs=100.0, unit="deg/s", client=client)
    status = {Path(f["path"]).name: f["status"] for f in res.files}
    assert status == {"s0.csv.gz": "ok", "s1.csv.gz": "ok", "s2.csv.gz": "ok", "bad.csv.gz": "error"}
    assert "gzip" in res.failed[0]["error"]
    for rel in ("a/s0", "a/s1", "b/s2"):
        assert (out / rel / "report.html").is_file() and (out / rel / "summary.json").is_file()
    assert not list(out.rglob(".*tmp-*"))  # nothing half-written
    # the fleet table: the same N as `allanite report` on one file
    rows = list(csv.DictReader((out / "fleet.csv").open(encoding="utf-8")))
    assert len(rows) == 3 * 2 + 1
    one = from_log(allanite.read_log(tmp_path / "logs" / "a" / "s1.csv.gz", fs=100.0, unit="deg/s"))
    r = next(r for r in rows if r["file"].endswith("s1.csv.gz") and r["axis"] == "gy")
    assert float(r["N"]) == pytest.approx(one.fits[1].coefficients["N"].ieee, rel=1e-12)
    bad = next(r for r in rows if r["status"] == "error")
    assert "gzip" in bad["error"]
    assert (out / "fleet.html").read_text(encoding="utf-8").count("bad.csv.gz") >= 1
    # --resume: nothing newer, nothing redone
    again = adask.batch(pattern, out=out, fs=100.0, unit="deg/s", client=client, resume=True)
    assert sorted(f["status"] for f in again.files) == ["error", "skipped", "skipped", "skipped"]


def test_batch_reports_an_accelerometer_log_in_its_units(client, tmp_path):
    # `allanite batch --unit g` on ax, ay, az was "unknown unit 'g'" for every file (read_log takes a gyro's unit):
    # now read as allanite report reads it, the report an accelerometer's (m/s/√h, µg, m/s/h^1.5)
    import csv

    from allanite.report import from_log

    n, fs = 6_000, 100.0
    acc = np.column_stack([allanite.simulate(n, fs, N=1e-3, seed=1) + 1.0, np.arange(n) / fs])  # az, t (s)
    (tmp_path / "logs").mkdir()
    np.savetxt(tmp_path / "logs" / "acc.csv", acc, delimiter=",", header="az,t", comments="")
    np.savetxt(tmp_path / "logs" / "gyro.csv", acc, delimiter=",", header="gz (deg/s),t", comments="")
    res = adask.batch(str(tmp_path / "logs" / "*.csv"), out=tmp_path / "res", time_column="t", unit="g", client=client)
    status = {Path(f["path"]).name: f for f in res.files}
    assert status["acc.csv"]["status"] == "ok"
    # a log whose names give a gyro's unit is an error row naming both, not a gyro read in g
    assert status["gyro.csv"]["status"] == "error"
    assert (
        "--unit g is an accelerometer's, and the names of columns gz (deg/s) give a gyro's (deg/s)"
        in status["gyro.csv"]["error"]
    )
    rows = [r for r in csv.DictReader((tmp_path / "res" / "fleet.csv").open(encoding="utf-8")) if r["status"] == "ok"]
    assert [r["axis"] for r in rows] == ["az"]  # one axis: a report's figures are most of its cost
    assert {(r["N_unit"], r["B_unit"], r["K_unit"]) for r in rows} == {("m/s/√h", "µg", "m/s/h^1.5")}
    one = from_log(allanite.read_log(tmp_path / "logs" / "acc.csv", time_column="t"), unit="g")  # report --unit g
    for r, ax in zip(rows, one.summary()["fit"]["axes"]):
        assert float(r["N"]) == pytest.approx(ax["coefficients"]["N"]["ieee"], rel=1e-12)
        assert float(r["N"]) == pytest.approx(1e-3 * 9.80665 * 60.0, rel=0.1)  # 1 mg·√s = 0.588 m/s/√h


def test_batch_reports_a_mixed_logs_accelerometer_in_its_own_units(client, tmp_path):
    # allanite batch on a gyro + accelerometer log analysed the gyro's columns alone (allanite report writes the
    # accelerometer's in accelerometer/): now each file's accelerometer columns have their report and fleet rows
    import csv
    import json

    from allanite.report import from_log

    n, fs = 4_000, 100.0
    g = allanite.simulate(n, fs, N=2e-3, seed=1)  # °/s·√s: 0.12 °/√h
    a = allanite.simulate(n, fs, N=1e-3, seed=2) + 1.0  # g·√s: 0.588 m/s/√h
    (tmp_path / "logs").mkdir()
    np.savetxt(tmp_path / "logs" / "imu.csv", np.c_[np.arange(n) / fs, g, a], delimiter=",", comments="",
               header="t,gyro_z,acc_z")  # fmt: skip
    res = adask.batch(str(tmp_path / "logs" / "*.csv"), out=tmp_path / "res", time_column="t", unit="deg/s",
                      accel_unit="g", window=1000, hop=500, client=client)  # fmt: skip
    assert [f["status"] for f in res.files] == ["ok"]
    rows = list(csv.DictReader((tmp_path / "res" / "fleet.csv").open(encoding="utf-8")))
    assert [(r["axis"], r["sensor"], r["N_unit"], r["B_unit"], r["K_unit"]) for r in rows] == [
        ("gyro_z", "gyro", "°/√h", "°/h", "°/h^1.5"),
        ("acc_z", "accelerometer", "m/s/√h", "µg", "m/s/h^1.5"),
    ]
    assert float(rows[0]["N"]) == pytest.approx(2e-3 * 60.0, rel=0.1)
    assert float(rows[1]["N"]) == pytest.approx(1e-3 * 9.80665 * 60.0, rel=0.1)
    # the accelerometer's report is allanite report's (--unit deg/s --accel-unit g): same numbers, linked pages
    acc_dir = tmp_path / "res" / "imu" / "accelerometer"
    assert rows[1]["out"] == str(acc_dir) and (acc_dir / "report.html").is_file()
    log = allanite.read_log(tmp_path / "logs" / "imu.csv", time_column="t", columns=["acc_z"])
    one = from_log(log, unit="g", window=1000, hop=500).summary()["fit"]["axes"][0]["coefficients"]
    assert float(rows[1]["N"]) == pytest.approx(one["N"]["ieee"], rel=1e-12)
    summary = json.loads((tmp_path / "res" / "imu" / "summary.json").read_text(encoding="utf-8"))
    assert summary["record"]["source"]["accelerometer_report"] == "accelerometer/report.html"
    assert summary["record"]["axis_names"] == ["gyro_z"]
    with pytest.raises(ParameterError, match=r"accel_unit='deg/s' is no accelerometer's unit; allowed: m/s\^2"):
        adask.batch(str(tmp_path / "logs" / "*.csv"), out=tmp_path / "r2", accel_unit="deg/s", client=client)


def test_batch_refuses_a_time_unit_no_time_column_is_read_in(tmp_path, capsys):
    # --fs with --time-unit and no --time-column: once, before any file (it was silently unused)
    from allanite.dask.fleet import main

    np.savetxt(tmp_path / "a.csv", np.zeros((50, 1)), header="gx", comments="")
    with pytest.raises(ParameterError, match=r"time_unit='ms' .* fs=100 without time_column= reads no time column"):
        adask.batch(str(tmp_path / "*.csv"), out=tmp_path / "res", fs=100.0, time_unit="ms")
    assert main([str(tmp_path / "*.csv"), "--fs", "100", "--time-unit", "ms", "--out", str(tmp_path / "res")]) == 2
    err = capsys.readouterr().err
    assert "--time-unit ms is the unit of a time column, but --fs 100 without --time-column reads no time" in err
    assert not (tmp_path / "res").exists()


def test_robust_z_flags_the_outlier():
    from allanite.dask.fleet import robust_z

    z = robust_z([1.0, 1.1, 0.9, 1.05, 0.95, 30.0])
    assert abs(z[-1]) > 3.5 and np.all(np.abs(z[:-1]) < 3.5)


def test_batch_survives_a_killed_worker(tmp_path):
    import os
    import signal
    import threading
    import time

    pattern = _fleet(tmp_path, n_good=4, seed=2)
    out = tmp_path / "res"
    with (
        LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=":0"
        ) as cluster,
        Client(cluster, timeout="30s") as c,
    ):
        pids = list(c.run(os.getpid).values())
        killed = []

        def killer():
            deadline = time.monotonic() + 60
            while time.monotonic() < deadline and not killed:
                if list(out.rglob(".*tmp-*")):  # a report is being written: kill its worker mid-run
                    os.kill(pids[0], signal.SIGKILL)
                    killed.append(pids[0])
                time.sleep(0.01)

        t = threading.Thread(target=killer, daemon=True)
        t.start()
        res = adask.batch(pattern, out=out, fs=100.0, client=c, retries=3)
        t.join()
    assert killed, "no worker was killed"
    assert sorted(f["status"] for f in res.files) == ["error", "ok", "ok", "ok", "ok"]
    for rel in ("a/s0", "a/s1", "b/s2", "b/s3"):
        assert (out / rel / "summary.json").is_file()
    assert not list(out.rglob(".*tmp-*"))


def test_cli_batch_on_a_given_scheduler(tmp_path):
    """`allanite batch ... --scheduler ADDRESS` runs its reports on that cluster (not a LocalCluster of its own)."""
    import csv
    import json

    pattern = _fleet(tmp_path, n_good=2, seed=4)  # logs/a/s0, logs/a/s1 and a malformed logs/b/bad
    out = tmp_path / "res"
    with (
        LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=":0"
        ) as cluster,
        Client(cluster, timeout="30s") as c,
    ):
        cmd = [sys.executable, "-m", "allanite", "batch", pattern, "--fs", "100", "--unit", "deg/s", "--out", str(out)]
        run = subprocess.run(
            [*cmd, "--scheduler", cluster.scheduler_address], capture_output=True, text=True, timeout=300
        )
        # the reports ran as tasks of this scheduler, on its workers
        prefixes = c.run_on_scheduler(lambda dask_scheduler: sorted(dask_scheduler.task_prefixes))
        workers = c.run_on_scheduler(
            lambda dask_scheduler: sorted(
                ws.address for ws in dask_scheduler.workers.values() if ws.metrics.get("task_counts") is not None
            )
        )
    assert run.returncode == 3, run.stderr  # 3: some files failed (the malformed one)
    assert "3 files: 2 reported, 0 skipped (resume), 1 failed" in run.stdout
    assert "allanite batch:" not in run.stderr and "\r" not in run.stderr  # no progress bar into a pipe (issue 32)
    assert "bad.csv.gz" in run.stdout
    assert "allanite-report" in prefixes and len(workers) == 2
    for rel in ("a/s0", "a/s1"):
        summary = json.loads((out / rel / "summary.json").read_text(encoding="utf-8"))
        assert summary["record"]["axes"] == 2
        assert (out / rel / "report.html").is_file()
    assert not (out / "b" / "bad").exists()
    rows = list(csv.DictReader((out / "fleet.csv").open(encoding="utf-8")))
    assert [(Path(r["file"]).name, r["axis"], r["status"]) for r in rows] == [
        ("s0.csv.gz", "gx", "ok"),
        ("s0.csv.gz", "gy", "ok"),
        ("s1.csv.gz", "gx", "ok"),
        ("s1.csv.gz", "gy", "ok"),
        ("bad.csv.gz", "", "error"),
    ]
    # white rate noise of σ = 1 °/s (s0) and 30 °/s (s1) at 100 Hz: N = σ/√fs = 0.1 and 3 °/√s = 6 and 180 °/√h
    for r in rows[:4]:
        want = 6.0 if r["file"].endswith("s0.csv.gz") else 180.0
        assert r["N_unit"] == "°/√h" and float(r["N"]) == pytest.approx(want, rel=0.1)
    assert (out / "fleet.parquet").is_file() and (out / "fleet.html").is_file()


def test_zarr_record(client, tmp_path):
    zarr = pytest.importorskip("zarr", reason="zarr not installed")
    y = _record(12_345, 2)
    z = zarr.create_array(store=str(tmp_path / "rec.zarr"), shape=y.shape, chunks=(1000, 2), dtype="f8")
    z[:] = y
    x = da.from_zarr(str(tmp_path / "rec.zarr"))
    ref = allanite.avar(y, 100.0)
    assert _rel(adask.avar(x, 100.0, chunk=3000, client=client).avar, ref.avar) <= REL
    refd = allanite.davar(y[:, :1], 100.0, window=3_001, hop=500)
    with client.as_current():
        got = adask.davar(x[:, :1], 100.0, window=3_001, hop=500, chunk=2_000)
    assert _rel(got.avar, refd.avar) <= 1e-14


def test_from_npy_reads_rows_in_the_tasks(client, tmp_path):
    import pickle

    y = _record(12_345, 2)
    np.save(tmp_path / "rec.npy", y)
    x = adask.from_npy(tmp_path / "rec.npy", chunk=3_000)
    assert x.shape == y.shape and x.chunks[0] == (3_000,) * 4 + (345,)
    # the graph names the file, it does not carry the samples (a pickled memmap would: 197 kB)
    assert len(pickle.dumps(dict(x.__dask_graph__()))) < 20_000
    assert np.array_equal(x.compute(), y)
    ref = allanite.avar(y, 100.0)
    assert _rel(adask.avar(x, 100.0, client=client).avar, ref.avar) <= REL
    np.save(tmp_path / "cube.npy", np.zeros((4, 3, 2)))
    with pytest.raises(InputError, match=r"3-D array of shape \(4, 3, 2\)"):
        adask.from_npy(tmp_path / "cube.npy")
    (tmp_path / "bad.npy").write_text("not a npy")
    with pytest.raises(InputError, match="not a readable .npy"):
        adask.from_npy(tmp_path / "bad.npy")
    with pytest.raises(ParameterError, match="chunk"):
        adask.from_npy(tmp_path / "rec.npy", chunk=0)


def test_cli_batch_help(capsys):
    from allanite.cli import main

    with pytest.raises(SystemExit) as exc:
        main(["batch", "--help"])
    assert exc.value.code == 0
    assert "--dask-workers" in (out := capsys.readouterr().out) and "--accel-unit" in out
