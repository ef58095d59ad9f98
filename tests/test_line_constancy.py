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
