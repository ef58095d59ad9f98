"""The change points' segments (``refinement._segments``): which τ each change point changed and by what factor,
and which of the record's Allan-curve departures only its louder segments carry (said on the change points'
steps, not in ``unexplained``) — a band noise switched on and off, against one that is on all along."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import allanite
from allanite.model import tracing
from allanite.model.refinement._curve_checks import allan_check
from allanite.model.refinement._segments import Segments, explained_regions
from allanite.model.refinement.curvefit import Curve, solve
from allanite.model.refinement.levels import alpha
from allanite.model.refinement.missing import MissingContext

FS, N, NW = 100.0, 200_000, 1e-3  # 2000 s of white noise
START = ("Q", "N", "B", "K", "R")
ON = ((600.0, 900.0), (1400.0, 1700.0))


def _band(rng, n: int, psd_ratio: float) -> np.ndarray:
    """Band noise 10–20 Hz at ``psd_ratio``× the white PSD (one-sided N²) there."""
    from scipy import signal

    v = signal.sosfilt(signal.butter(4, [10.0, 20.0], btype="bandpass", fs=FS, output="sos"), rng.standard_normal(n))
    return np.sqrt(psd_ratio * NW**2 * 10.0) * v / np.std(v)


def _context(y: np.ndarray, times) -> MissingContext:
    res = allanite.avar(y, FS)
    cur = Curve(res.tau, res.m.astype(np.float64), res.avar, FS, res.n_samples + 1, res.estimator)
    ctx = MissingContext(cur, tracing.thin_indices(cur.tau), solve(cur, START, []), START, [], y, FS, 0.05, True)
    ctx.memo["segments"] = Segments.of(y, FS, times)
    return ctx


def test_band_noise_on_for_stretches_is_the_change_points_and_said_on_them():
    rng = np.random.default_rng(11)
    y = allanite.simulate(N, FS, N=NW, seed=rng)
    t = np.arange(N) / FS
    on = np.zeros(N, dtype=bool)
    for a, b in ON:
        on |= (t >= a) & (t < b)
    y = y + np.where(on, _band(rng, N, 20.0), 0.0)
    times = [s for ab in ON for s in ab]
    ctx = _context(y, times)
    seg = ctx.memo["segments"]
    assert seg.base.tolist() == [True, False, True, False, True]  # the quiet stretches are the base
    up = seg.ratio_across(0)
    # the band 10–20 Hz is read at τ ≈ 1/(2f) = 25–50 ms: the largest change there, 95 % interval above 1
    assert 0.02 <= up["largest"]["tau_s"] <= 0.08 and up["largest"]["interval95"][0] > 1.5
    assert seg.ratio_across(1)["largest"]["ratio"] < 1 / 1.5  # and back down after the stretch
    a = alpha("unexplained:allan", 0.05)
    regions = allan_check(ctx, a)
    assert regions  # the whole record's curve departs from the five terms
    kept, taken = explained_regions(ctx, regions, a)
    assert kept == [] and len(taken) == len(regions)
    assert all(
        r["louder"]["adev_ratio"] > 1.5 and r["louder"]["segments"] == [(600.0, 900.0), (1400.0, 1700.0)] for r in taken
    )


def test_band_noise_all_along_stays_said_beside_a_change_point():
    rng = np.random.default_rng(12)
    y = allanite.simulate(N, FS, N=NW, seed=rng) + _band(rng, N, 20.0)
    y[N // 2 :] += np.sqrt(3.0) * NW * np.sqrt(FS) * rng.standard_normal(N - N // 2)  # white ×2 in ADEV after 1000 s
    ctx = _context(y, [1000.0])
    assert ctx.memo["segments"].base.tolist() == [True, False]
    a = alpha("unexplained:allan", 0.05)
    regions = allan_check(ctx, a)
    assert regions
    kept, taken = explained_regions(ctx, regions, a)
    assert taken == [] and kept == regions  # the quiet segment departs too: not the change point's


def test_no_change_point_takes_nothing():
    rng = np.random.default_rng(13)
    y = allanite.simulate(N, FS, N=NW, seed=rng)
    assert Segments.of(y, FS, []) is None and Segments.of(y, FS, [1000.0, 1000.2]) is None  # 20 samples: too short
    ctx = _context(y, [])
    regions = [{"domain": "allan", "tau": (0.02, 0.05), "what": "the Allan curve departs from the model"}]
    assert explained_regions(ctx, regions, 0.05) == (regions, [])


def test_a_base_shorter_than_half_the_record_takes_nothing():
    rng = np.random.default_rng(14)
    y = allanite.simulate(N, FS, N=NW, seed=rng)
    y[80_000:] += _band(rng, N - 80_000, 20.0)  # loud from 800 s on: the quiet base is 40 % of the record
    ctx = _context(y, [800.0])
    seg = ctx.memo["segments"]
    assert seg.base.tolist() == [True, False] and abs(seg.base_share() - 0.4) < 1e-9
    regions = [{"domain": "allan", "tau": (0.025, 0.05), "what": "the Allan curve departs from the model"}]
    assert explained_regions(ctx, regions, 0.05) == (regions, [])


@pytest.mark.parametrize("n, nper", [(200_000, 2**13), (9_000, 512), (300, 512)])
def test_band_spectrum_is_scipys_linear_detrended_welch(n, nper):
    """The ``"allan"`` check's band spectrum (``_curve_checks._welch_linear``: the segments' lines off in closed
    form) is ``scipy.signal.welch(detrend="linear")``'s to rounding — on a random walk, whose segments' lines are
    most of their power; a record shorter than a segment is SciPy's own."""
    from scipy import signal

    from allanite.model.refinement._curve_checks import _welch_linear

    y = 5.0 + 1e-3 * np.cumsum(np.random.default_rng(n).standard_normal(n))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # SciPy's note that a segment longer than the record is cut to it
        f, p = _welch_linear(y, 3.0, nper)
        f_ref, p_ref = signal.welch(y - y.mean(), fs=3.0, nperseg=nper, detrend="linear")
    np.testing.assert_array_equal(f, f_ref)
    np.testing.assert_allclose(p, p_ref, rtol=1e-11)
