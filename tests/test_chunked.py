"""The chunked forms of refine's record-length checks (:mod:`allanite.model._chunked`) against the whole-array
forms they replace (copied here as they were): the same numbers on several records, and memory beyond the input
of a chunk or a segment, not of the record."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest
from scipy import signal

from allanite.model import _chunked, lines, outliers


def _lattice_step_whole(x: np.ndarray) -> float:  # outliers._lattice_step before the chunked form
    a = np.abs(x)
    nz = a[a > 0]
    if nz.size == 0:
        return 0.0
    scale = float(nz.max())
    nz = nz[nz > _chunked.TINY * scale]  # rounding residues count as zero
    vals, counts = np.unique(np.round(nz / scale, 12), return_counts=True)
    recurring = vals[(counts >= 3) & (vals > 0)]
    if recurring.size == 0:
        return 0.0
    step = float(np.min(nz[np.abs(nz / scale - recurring[0]) <= 1e-12]))
    q = nz / step
    on = np.abs(q - np.round(q)) <= 1e-6 * np.maximum(1.0, q)
    return step if np.mean(on) >= 0.99 else 0.0


def _welch_whole(x: np.ndarray, fs: float, win: np.ndarray, nper: int) -> tuple[np.ndarray, np.ndarray]:
    step = nper // 2  # lines._welch before the chunked form
    k = (x.size - nper) // step + 1
    t = np.arange(nper) - (nper - 1) / 2.0
    tt = float(t @ t)
    scale = 1.0 / (fs * float(win @ win))
    p = np.zeros(nper // 2 + 1)
    for a in range(0, k, 16):
        idx = (np.arange(a, min(k, a + 16)) * step)[:, None] + np.arange(nper)[None, :]
        seg = x[idx]
        seg = seg - seg.mean(axis=1, keepdims=True) - np.outer(seg @ t / tt, t)
        p += np.sum(np.abs(np.fft.rfft(seg * win, axis=1)) ** 2, axis=0)
    p *= scale / k
    p[1:-1] *= 2.0
    return np.arange(p.size) * fs / nper, p


def _edof_whole(win: np.ndarray, n: int, nper: int) -> tuple[float, float, int]:
    h = win / np.sqrt(float(win @ win))  # lines._edof before the chunked form
    step = nper // 2
    k = (n - nper) // step + 1
    rho = [float(h[: nper - m * step] @ h[m * step :]) for m in range(1, min(k, nper // step))]
    dof = 2.0 * k / (1.0 + 2.0 * sum((1 - (m + 1) / k) * r * r for m, r in enumerate(rho)))
    corr = np.abs(np.fft.rfft(h * h)[1 : 2 * lines.LOBE]) ** 2
    return dof, 1.0 + 2.0 * float(np.sum(corr)), k


def _records() -> list[np.ndarray]:
    rng = np.random.default_rng(5)
    n = 3 * _chunked.CHUNK + 12_345  # several chunks and a partial one
    white = rng.normal(size=n)
    return [
        white,
        np.diff(np.round(np.cumsum(rng.normal(size=n)) / 0.15) * 0.15),  # a quantised random walk's differences
        np.diff(np.round(rng.normal(size=n) * 20) / 7),  # a lattice of 1/7
        np.concatenate([np.round(white[:5000] / 0.15) * 0.15, [0.4371, 2.91]]),  # a lattice and two outliers
        np.concatenate([np.zeros(n), [1.0, 1.0, 1.0]]),  # nearly all zero
        np.zeros(7),
        np.round(white * 1e3) / 1e3 + 1e-5 * white,  # off any lattice
    ]


@pytest.mark.parametrize("k", range(7))
def test_lattice_step_equals_the_whole_array_form(k):
    x = _records()[k]
    assert _chunked.lattice_step(x) == _lattice_step_whole(x)
    assert outliers._lattice_step(x) == _lattice_step_whole(x)


def test_lattice_step_finds_the_lattices():
    recs = _records()
    assert _chunked.lattice_step(recs[1]) == pytest.approx(0.15)
    assert _chunked.lattice_step(recs[2]) == pytest.approx(1 / 7)
    assert _chunked.lattice_step(recs[0]) == 0.0
    assert _chunked.lattice_step(recs[6]) == 0.0  # off any lattice: no step of its rounding residues (was 4.3e-13)


def test_lattice_step_of_a_rate_differenced_from_an_offset_angle():
    # a counter's angle at 10⁴ °: its rate carries float residues of ~10⁻⁹ beside the lattice of 0.03; the
    # residues, taken for the step, made the outliers test flag a quarter of the samples and refine fail
    rng = np.random.default_rng(1)
    q, fs = 1.5e-5, 2000.0
    angle = np.round((1e4 + np.cumsum(0.01 * rng.standard_normal(50_000)) / fs) / q) * q
    rate = np.diff(angle) * fs
    assert _chunked.lattice_step(np.diff(rate)) == pytest.approx(q * fs, rel=1e-6)
    assert outliers.lattice_step(np.diff(rate)) == pytest.approx(q * fs, rel=1e-6)


@pytest.mark.parametrize(
    ("n", "nper"),
    [(200_000, 100_000), (600_000, 300_000), (3 * _chunked.CHUNK + 7, 2 * ((3 * _chunked.CHUNK + 7) // 4)),
     (300_000, 4096), (100_000, 32768)],
)  # fmt: skip
def test_welch_equals_the_whole_array_form(n, nper):
    rng = np.random.default_rng(n)
    x = 3.0 + np.cumsum(rng.normal(size=n)) * 1e-3 + rng.normal(size=n) + np.sin(0.01 * np.arange(n))
    win = signal.get_window(lines.WINDOW, nper)
    f0, p0 = _welch_whole(x - x.mean(), 50.0, win, nper)  # line_spectrum de-meaned the record first, as a copy
    f1, p1, _spread = lines._welch(x, 50.0, win, nper, float(x.mean()))  # now each segment as it is taken
    assert np.array_equal(f0, f1)
    if 16 * nper <= _chunked.CHUNK:  # the grouped path: the same bits
        assert np.array_equal(p0, p1)
    np.testing.assert_allclose(p1, p0, rtol=1e-12, atol=0)
    e0, e1 = _edof_whole(win, n, nper), lines._edof(win, n, nper)
    assert e0[2] == e1[2]
    np.testing.assert_allclose(e1[:2], e0[:2], rtol=1e-12, atol=0)


def test_memory_beyond_the_input_is_a_chunk_or_a_segment():
    rng = np.random.default_rng(2)
    x = rng.normal(size=8 * _chunked.CHUNK)  # 64 MB
    lat = np.round(x / 0.01) * 0.01
    tracemalloc.start()
    try:
        tracemalloc.reset_peak()
        assert _chunked.lattice_step(lat) == pytest.approx(0.01)
        peak_lattice = tracemalloc.get_traced_memory()[1]
        nper = 2 * (x.size // 4)
        win = signal.get_window(lines.WINDOW, nper)
        tracemalloc.reset_peak()
        _chunked.welch_detrended(x, win, nper, 0.5)
        peak_welch = tracemalloc.get_traced_memory()[1] - win.nbytes
        tracemalloc.reset_peak()
        _chunked.window_overlap(win, nper, 7)
        peak_overlap = tracemalloc.get_traced_memory()[1] - win.nbytes
    finally:
        tracemalloc.stop()
    # one sorted copy of the quotients (the record's size) and a few chunks; the whole-array form made ≈ 5 copies
    assert peak_lattice < x.nbytes + 8 * 8 * _chunked.CHUNK
    # per segment (half the record): the detrended copy, its transform (complex, half as many bins) and the power
    # so far — ≈ 2.5 × a segment; the three-segment group was ≈ 6 × a segment's worth of copies
    assert peak_welch < 2.6 * nper * 8 + 4 * 8 * _chunked.CHUNK  # and a few chunks' temporaries
    assert peak_overlap < 16 * _chunked.CHUNK  # a few sixteenth-chunks of complex exponentials


@pytest.mark.parametrize(("n", "nper"), [(100_000, 4096), (3 * _chunked.CHUNK + 5, 4096), (10_001, 1024), (5000, 256)])
def test_rolloff_welch_equals_scipys(n, nper):
    rng = np.random.default_rng(n)
    x = 5.0 + np.cumsum(rng.normal(size=n)) * 1e-2 + rng.normal(size=n)
    f0, p0 = signal.welch(x - x.mean(), fs=50.0, nperseg=nper)  # tracing._rolloff_welch before the chunked form
    f1, p1 = _chunked.welch_mean(x, 50.0, nper, float(x.mean()))
    assert np.array_equal(f0, f1)
    np.testing.assert_allclose(p1, p0, rtol=1e-12, atol=0)


def _lines_before():
    """lines.py as it was before the chunked Welch and the long pass cut to its searched bins (git: 478e6dd)."""
    import importlib.util
    import subprocess
    from pathlib import Path

    repo = Path(__file__).resolve().parents[1]
    try:
        src = subprocess.run(
            ["git", "-C", str(repo), "show", "478e6dd:python/allanite/model/lines.py"], capture_output=True, check=True
        ).stdout.decode()
    except (OSError, subprocess.CalledProcessError):
        pytest.skip("needs the repository's history (git) for the earlier lines.py")
    spec = importlib.util.spec_from_loader("allanite.model._lines_before", loader=None)
    mod = importlib.util.module_from_spec(spec)
    mod.__package__ = "allanite.model"
    exec(compile(src, "lines_before.py", "exec"), mod.__dict__)
    return mod


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_find_lines_as_before(seed):
    """The lines found, their amplitudes and tests, the Bonferroni count and the p-value as before, on records
    with lines low (the long pass's bins) and high, on flicker and random walk; the long pass's arrays now end
    where its search reaches."""
    old = _lines_before()
    rng = np.random.default_rng(seed)
    n, fs = 400_000 + 1237 * seed, 100.0
    t = np.arange(n) / fs
    y = rng.normal(size=n) + np.cumsum(rng.normal(size=n)) * 0.01 * seed
    y += 0.3 * np.sin(2 * np.pi * 0.02 * seed * t) + 0.3 * np.sin(2 * np.pi * 0.011 * t + 1.0)  # low: long pass
    y += 0.03 * np.sin(2 * np.pi * 7.3 * t) + 0.02 * np.sin(2 * np.pi * 14.6 * t) + 0.05 * np.sin(2 * np.pi * 31.0 * t)
    got, want = lines.find_lines(y, fs, 0.05), old.find_lines(y, fs, 0.05)
    assert got["bins"] == want["bins"] and got["p_value"] == pytest.approx(want["p_value"], rel=1e-9, abs=1e-300)
    assert len(got["lines"]) == len(want["lines"]) >= 4
    for a, b in zip(got["lines"], want["lines"]):
        assert a["pass"] == b["pass"] and a["bin_hz"] == b["bin_hz"]
        for key in ("f", "amplitude", "amplitude_sd", "psd_ratio", "threshold", "noise"):
            assert a[key] == pytest.approx(b[key], rel=1e-10), key
    long_new, long_old = got["passes"][0], want["passes"][0]
    assert long_new["p"].size < long_old["p"].size / 20  # the long pass cut to the bins its search reaches
    k = long_new["p"].size
    np.testing.assert_allclose(long_new["p"], long_old["p"][:k], rtol=1e-12, atol=0)
    assert np.array_equal(
        np.isfinite(long_old["noise"]),
        np.concatenate([np.isfinite(long_new["noise"]), np.zeros(long_old["noise"].size - k, bool)]),
    )
    assert np.isnan(long_new["noise"][-1])


@pytest.mark.parametrize(
    "values",
    [
        np.array([1.0, np.inf, -3.0, np.nan]),
        np.zeros((5, 3)),
        (np.random.default_rng(1).normal(size=(_chunked.CHUNK + 5, 3)) * 1e3).astype(np.float32),
        np.random.default_rng(2).normal(size=2 * _chunked.CHUNK + 3)[::2],  # a strided view
        np.arange(10),
        [1, 2, -7.5],
        np.array([np.nan, np.inf]),
    ],
)
def test_refine_scale_check_peak_as_before(values):
    from allanite.model.refinement import _inputs

    a = np.asarray(values, dtype=np.float64)  # check_scale before: the float64 copy, its finite values, |…|
    finite = a[np.isfinite(a)] if a.size else a
    want = float(np.max(np.abs(finite))) if finite.size else 0.0
    assert _inputs._finite_peak(np.asarray(values)) == want


def test_refine_scale_check_still_refuses():
    from allanite.errors import InputError
    from allanite.model.refinement import _inputs

    with pytest.raises(InputError, match="1e\\+101"):
        _inputs.check_scale(np.array([1.0, -1e101, np.nan], dtype=np.float64))
    with pytest.raises(InputError, match="1e-101"):
        _inputs.check_scale(np.full(10, 1e-101))
    _inputs.check_scale(np.ones(10, dtype=np.float32))  # within the range: nothing said
