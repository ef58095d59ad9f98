"""refine's speed-ups of round r13cost give the numbers of the computations they stand for, bit for bit.

The Whittle spectra with their taper and band layout remembered, against the layout made afresh; a channel read
again (its form, floor and signal bands remembered), against a fresh read; a line family's unit phases and a
template's phase bins remembered, against ``np.mod`` and the bins made afresh; the held-out parts' indices in one
broadcast sum, against the blocks' ranges joined; a remembered array's fingerprint compared before the array.
No timings here: ``benches/bench_refine_cost.py``.
"""

from __future__ import annotations

import numpy as np
import pytest

from allanite.model import _recent, _regressors, _whittle, linefit, template
from allanite.model._recent import Recent, remembering
from allanite.model.refinement.scoring import _PartIndex


def _spectra_afresh(y, regs, fs, parity):
    """:func:`_whittle.spectra` with nothing remembered (outside a refine the memories keep nothing)."""
    return _whittle.spectra(y, regs, fs, parity)


@pytest.mark.parametrize("n", [20, 3999, 40_001])
def test_spectra_with_the_layout_remembered_equal_fresh_ones(n):
    rng = np.random.default_rng(n)
    y = np.cumsum(rng.standard_normal(n))
    regs = [rng.standard_normal(n), np.cumsum(rng.standard_normal(n))]
    fresh = {p: _spectra_afresh(y, regs, 50.0, p) for p in (None, 0, 1)}
    fresh_20 = _spectra_afresh(y, regs, 20.0, None)
    with remembering():
        for _ in range(2):  # the second time the taper and layout come from the memory
            for parity, want in fresh.items():
                got = _whittle.spectra(y, regs, 50.0, parity)
                for name in ("m", "f", "q", "g", "G", "par", "basis"):
                    np.testing.assert_array_equal(getattr(got, name), getattr(want, name))
                assert got.m.flags.writeable and got.par.flags.writeable  # its own copies, not the memory's
        assert not _whittle._taper(n - 1).flags.writeable
        # another rate is another layout (the bands' frequencies), not the remembered one
        np.testing.assert_array_equal(_whittle.spectra(y, regs, 20.0).f, fresh_20.f)
        assert not np.array_equal(fresh_20.f, fresh[None].f)


def test_a_channel_read_again_equals_a_fresh_read():
    rng = np.random.default_rng(3)
    n = 24_000
    held = np.repeat(np.round(np.cumsum(rng.standard_normal(n // 4)) * 0.02, 2), 4)  # a held, quantised channel
    for x in (np.cumsum(rng.standard_normal(n)) * 1e-2 + 1e-3 * rng.standard_normal(n), held):
        want = _regressors.read_channel(x, 100.0)
        with remembering():
            first = _regressors.read_channel(x, 100.0)
            if first[2] is not None:
                first[2].append((1.0, 2.0))  # a caller's own list: the memory keeps its own
            again = _regressors.read_channel(x.copy(), 100.0)
            other = _regressors.read_channel(x, 50.0)  # another rate: read afresh
        assert again[0] == want[0] and again[1] == want[1] and again[2] == want[2]
        np.testing.assert_array_equal(again[3], want[3])
        assert other[2] == _regressors.read_channel(x, 50.0)[2]
    assert want[0].hold == 4  # the held channel's form was detected


def test_remembered_unit_phases_and_phase_bins_equal_fresh_ones():
    idx = np.arange(3, 50_003, dtype=np.int64)
    nu = 0.0313
    want_u = np.mod(idx * nu, 1.0)
    want_k = template._phase_bins(idx, nu, 512)
    with remembering():
        for _ in range(2):
            u = linefit._unit_phase(idx, nu)
            np.testing.assert_array_equal(u, want_u)
            assert not u.flags.writeable
            np.testing.assert_array_equal(template._phase_bins(idx.copy(), nu, 512), want_k)
        # another fundamental, another grid: not the remembered ones
        np.testing.assert_array_equal(linefit._unit_phase(idx, 0.25), np.mod(idx * 0.25, 1.0))
        assert not np.array_equal(template._phase_bins(idx, nu, 256), want_k)
    # np.modf's fractional part (ν > 0) and x − ⌊x⌋ (ν = 0) are np.mod's numbers to the bit, up to 10⁸·ν
    far = np.concatenate([idx, np.arange(10**8 - 7, 10**8, dtype=np.int64)])
    for f in (0.0313, 1.0 / 3.0, 7.77, 0.0):
        assert linefit._unit_phase(far, f).tobytes() == np.mod(far * f, 1.0).tobytes()


def test_part_indices_equal_the_blocks_ranges_joined():
    for per, blocks, cut in ((7, 8, 0), (125, 8, 3), (1, 9, 0), (1000, 8, 999)):
        size = per * (blocks // 2) - cut
        idx = _PartIndex(per, blocks, size)
        for parity in (0, 1):
            want = np.concatenate([np.arange(j * per, (j + 1) * per) for j in idx.blocks(parity)])[:size]
            got = idx[parity]
            assert got.dtype == np.int64
            np.testing.assert_array_equal(got, want)


def test_recent_compares_the_fingerprint_then_the_whole_array():
    memo = Recent(4, 10_000)
    a = np.random.default_rng(1).standard_normal(5_000)
    inner = a.copy()
    inner[1] += 1.0  # not among the 16 sampled elements: the fingerprint agrees, the whole array does not
    assert _recent._fingerprint(inner) == _recent._fingerprint(a)
    with remembering():
        memo.put(a, (), "a")
        assert memo.get(a.copy()) == "a"
        assert memo.get(inner) is None
        assert memo.get(a + 1.0) is None
        assert memo.get(a, ("other key",)) is None
