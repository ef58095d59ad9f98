"""The line-constancy test (model/refinement/_line_constancy.py): a line switched on halfway is flagged, a
constant line on white + random-walk noise is not, and its false-alarm rate is near alpha."""

import numpy as np

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
