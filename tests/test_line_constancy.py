"""The line-constancy test (model/refinement/_line_constancy.py): a line switched on halfway is flagged, a
constant line on white + random-walk noise is not, and its false-alarm rate is near alpha."""

import numpy as np
import pytest
from scipy import stats

from allanite.model.refinement._line_constancy import line_constancy

FS = 200.0
T = np.arange(200_000) / FS


def _record(seed: int, switched: bool) -> np.ndarray:
    rng = np.random.default_rng(seed)
    line = 0.3 * np.sin(2 * np.pi * 4.3 * T + 1.0)
    if switched:
        line = line * (T > T[-1] / 2)
    return rng.normal(size=T.size) + 0.02 * np.cumsum(rng.normal(size=T.size)) + line


def test_switched_line_flagged() -> None:
    r = line_constancy(_record(9, True), FS, 4.3, 0.01)
    assert r is not None and r["rejected"]
    amp = np.asarray(r["amplitude"])
    assert np.all(amp[: r["blocks"] // 2] < 0.06) and np.all(np.abs(amp[r["blocks"] // 2 :] - 0.3) < 0.06)


def test_constant_line_not_flagged() -> None:
    ps = np.array([line_constancy(_record(s, False), FS, 4.3, 0.05)["p_value"] for s in range(40)])
    assert np.mean(ps < 0.05) <= 0.15  # 40 records at alpha 5 %: 2 expected, 6 is p ≈ 0.05
    assert 0.3 < np.median(ps) < 0.7


def test_too_short_is_none() -> None:
    assert line_constancy(np.zeros(1000), FS, 4.3, 0.05) is None


def test_block_phasors_equal_the_direct_least_squares_at_global_time():
    # each block's phasor is fitted on one basis per block length in block-local time, then rotated by its start
    # time: the same complex amplitude as the least squares on the block's own absolute times
    from allanite.model.refinement._line_constancy import _phasors

    rng = np.random.default_rng(3)
    for fs, n, f0 in ((100.0, 123_457, 0.55), (200.0, 200_001, 4.3), (1000.0, 300_000, 47.5)):
        t = np.arange(n) / fs
        y = rng.standard_normal(n) + 0.3 * np.sin(2 * np.pi * f0 * t + 1) * (t > 0.6 * t[-1])
        r = line_constancy(y, fs, f0, 0.01, phasors=True)
        edges = np.round(np.asarray(r["edges_s"]) * fs).astype(int)
        for b in range(r["blocks"]):
            yb = y[edges[b] : edges[b + 1]]
            direct = _phasors(yb, np.arange(edges[b], edges[b + 1]) / fs, np.array([f0]))[0]
            assert abs(r["phasors"][b] - direct) <= 1e-8 * abs(direct)


def test_off_line_noise_is_the_local_psd_under_a_random_walk():
    # a random walk's in-block trend leaked through a rectangular block's sidelobes into every phasor: on white
    # noise plus a unit-step walk at 4.3 Hz of 100 Hz the off-line noise read 28× the white noise's where the
    # walk's own PSD there is 1/(2 sin(π f0/fs))² = 13.8 white-noise levels (the untapered test, 3637a85); the
    # Hann-tapered blocks read the local PSD itself
    fs, n, f0 = 100.0, 100_000, 4.3
    rng = np.random.default_rng(5)
    white, walk = rng.normal(size=n), np.cumsum(rng.normal(size=n))
    base = np.mean(line_constancy(white, fs, f0, 0.01, phasors=True)["phasor_var"])
    for k in (0.1, 1.0):
        local = 1 + k**2 / (2 * np.sin(np.pi * f0 / fs)) ** 2
        got = np.mean(line_constancy(white + k * walk, fs, f0, 0.01, phasors=True)["phasor_var"]) / base
        assert got == pytest.approx(local, rel=0.1)


def test_threshold_counts_the_correlated_off_line_phasors():
    # the tapered off-line phasors at f0 ± 2…5 bins are correlated (Hann: 2/3 at one bin, 1/6 at two): their
    # Satterthwaite degrees of freedom are 2·8²/(8 + 2·(3·4/9 + 2/36)·2) ≈ 9.44 per block, not 16
    r = line_constancy(np.random.default_rng(2).normal(size=200_000), FS, 4.3, 0.01)
    d2 = 16 * 2 * 64 / (8 + 4 * (3 * 4 / 9 + 2 / 36))
    assert r["blocks"] == 16
    assert r["threshold"] == pytest.approx(stats.f.ppf(0.99, 30, d2), rel=2e-3)
