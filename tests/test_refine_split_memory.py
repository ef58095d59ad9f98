"""The held-out split's parts and indices made when asked (:class:`allanite.model.refinement.scoring.Split`): the same
indices, samples, curves and held-out errors as the arrays it held before, and no record-size array held."""

from __future__ import annotations

import numpy as np
import pytest

from allanite.model.refinement import scoring


def _old_idx(n: int, n_blocks: int) -> list[np.ndarray]:  # Split.idx as it was built and held
    per = n // n_blocks
    idx = [
        np.concatenate([np.arange(j * per, (j + 1) * per) for j in range(n_blocks) if j % 2 == parity])
        for parity in (0, 1)
    ]
    size = min(i.size for i in idx)
    return [i[:size] for i in idx]


@pytest.mark.parametrize(("n", "seed"), [(200_000, 1), (300_017, 2), (1_000_003, 3)])
def test_parts_and_indices_are_the_old_ones(n, seed):
    rng = np.random.default_rng(seed)
    y = rng.normal(size=n) + np.cumsum(rng.normal(size=n)) * 1e-3
    m_all = np.unique(np.round(np.geomspace(1, n // 20, 80)).astype(np.int64))
    split = scoring.heldout_split(y, 100.0, m_all, 0.0, np.inf, ("N", "B", "K"))
    old = _old_idx(n, scoring.HELDOUT_BLOCKS)
    for f in (0, 1):
        assert np.array_equal(split.idx[f], old[f])
        assert np.array_equal(split.part(f), y[old[f]])
    raw = split.raw_parts()
    assert all(p["zf"] is None and p["zh"] is None for p in raw)  # the raw parts' samples: made when asked

    def remove(z, idx):  # a removal fitted on the held-in part: its mean and a slope in the sample index
        c = np.polyfit(idx.astype(np.float64), z, 1)
        return lambda i: np.polyval(c, i.astype(np.float64))

    terms = ("N", "B", "K")
    got = [split.error(terms, []), split.error(terms, [], remove), split.error(terms, [], remove, on_raw=True)]
    want = []
    for rem in (None, remove):
        for on_raw in (False, True) if rem is not None else (False,):
            errs = []
            for f, h in ((0, 1), (1, 0)):
                yf, yh = y[old[f]], y[old[h]]
                extra = 0.0
                if rem is None:
                    cf, ch = split.curves[f], split.curves[h]
                else:
                    g = rem(yf, old[f])
                    cf = split.curve(yf - g(old[f]))
                    # the held-out part's raw curve is the target either way (r13heldout): plus the held-in part's
                    # change (on_raw) or the held-out part's own change under the held-in fit
                    ch = split.curves[h]
                    extra = split.curves[f].avar - cf.avar if on_raw else ch.avar - split.curve(yh - g(old[h])).avar
                sol = scoring.solve(cf, terms, [])
                a_h, _ = scoring.design(ch, terms, [])
                pred = np.maximum(a_h @ sol.theta + extra, 1e-300)
                errs.append(scoring.rms_adev_pct(ch.avar[split.scored], pred[split.scored]))
            want.append(float(np.mean(errs)))
    assert got == want
    fixed = split.corrected(raw, remove, on_raw=False)
    for (f, h), p in zip(((0, 1), (1, 0)), fixed):
        g = remove(y[old[f]], old[f])
        assert np.array_equal(p["zf"], y[old[f]] - g(old[f])) and np.array_equal(p["zh"], y[old[h]] - g(old[h]))


def test_split_holds_no_copy_of_the_record():
    y = np.random.default_rng(4).normal(size=400_000)
    m_all = np.unique(np.round(np.geomspace(1, 20_000, 60)).astype(np.int64))
    split = scoring.heldout_split(y, 100.0, m_all, 0.0, np.inf, ("N", "B", "K"))
    raw = split.raw_parts()
    held = {id(a): a.nbytes for p in raw for a in (p["zf"], p["zh"]) if a is not None}
    held.update({id(a): a.nbytes for a in vars(split).values() if isinstance(a, np.ndarray) and a is not y})
    # before: the parts twice and their int64 indices, three times the record
    assert sum(held.values()) <= 4096
