"""A change point is located beside the windows' bound that found it, not at a short burst elsewhere in the span
(``changes._segment``), on plain noise and after a wandering family's tracked removal
(:mod:`allanite.model.wander`), whose residual keeps the record's level at its ends.

ADIS16405 run 1 acc_z (``benches/results/wander_measured.md``): a 6 s burst 2–8 s from the start (4× the level
of the τ 0.16 s differences, in the raw log) took the location of a bound at 1875 s once the search spanned every
window between the bound's neighbours: 7.8 s.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from allanite.model import periodic
from allanite.model.refinement import changes
from allanite.model.refinement.levels import alpha
from allanite.model.refinement.removals import _tracked, heldout_variance_ratio


def _stepped(seed: int, n: int, step_at: int, ratio: float, burst: slice, amp: float) -> np.ndarray:
    """Unit white noise whose level is ``ratio`` from sample ``step_at`` on, ``amp`` times it on ``burst``."""
    rng = np.random.default_rng(seed)
    s = np.where(np.arange(n) < step_at, 1.0, ratio)
    s[burst] *= amp
    return rng.standard_normal(n) * s


@pytest.mark.parametrize("seed", [0, 3])
def test_a_burst_at_the_start_does_not_take_a_level_steps_location(seed):
    fs, window = 100.0, 4096
    n, step_at = 16 * window, int(2.5 * window)  # the step inside window 2: the partition's bound is 2 or 3
    y = _stepped(seed, n, step_at, 1.15, slice(100, 140), 4.0)
    found = changes.change_points(y, fs, None)
    assert len(found) == 1, found
    c = found[0]
    assert abs(c["t"] - step_at / fs) < 0.1 * window / fs, c
    assert c["interval"][0] <= step_at / fs <= c["interval"][1] or abs(c["t"] - step_at / fs) < 2.0
    # the burst does win a two-segment likelihood over the whole record at that τ: what the span was hiding
    m = int(round(c["tau"] * fs))
    t_whole, _ = changes.locate(y, m, fs)
    assert t_whole < 2.0, t_whole


FS, N, F0, AMPS = 50.0, 1 << 17, 1.5, (0.5, 0.3, 0.2)


def _wandering(seed: int, ratio: float, burst: slice) -> np.ndarray:
    """Harmonics 1–3 of F0 wandering ±0.4 % over 1.5 periods on white noise stepping by ``ratio`` at 2.5/16 of
    the record, 4× on ``burst``."""
    t = np.arange(N) / FS
    f = F0 * (1.0 + 0.004 * np.sin(2 * np.pi * t / (N / FS / 1.5) + 0.4))
    ph = 2 * np.pi * np.cumsum(f) / FS
    y = _stepped(seed, N, int(2.5 * N / 16), ratio, burst, 4.0)
    return y + sum(a * np.sin(k * ph + k) for k, a in enumerate(AMPS, start=1))


def _tracked_residual(y: np.ndarray) -> tuple[np.ndarray, dict]:
    """The record less its strongest family, tracked as the ``"periodic"`` removal does; its params."""
    fam = periodic.periodic_search(y, FS, alpha("lines", 0.05))["families"][0]
    params: dict = {"fundamentals": [float(g) for g in fam.gens], "lines": int(fam.coefs.shape[0]), "rms": fam.rms}
    evidence: dict = {}
    ctx = SimpleNamespace(y=y, fs=FS, level=0.05)
    got = _tracked(ctx, fam, fam.component(), heldout_variance_ratio(y, fam.refit), (params, {}, evidence))
    assert got is not None, evidence.get("wander")
    assert params["wander_hz"] == pytest.approx(F0 * 0.004 / math.sqrt(2.0), rel=0.3)
    return y - got[0], params


def test_a_tracked_familys_residual_keeps_its_level_at_the_ends_and_has_no_change_point():
    resid, _params = _tracked_residual(_wandering(1, 1.0, slice(0, 0)))
    d2 = np.diff(resid) ** 2
    edge = int(60 * FS)  # 60 s, beyond 1/B of the tracked phase's band
    middle = float(d2[edge:-edge].mean())
    assert abs(d2[:edge].mean() / middle - 1) < 0.1 and abs(d2[-edge:].mean() / middle - 1) < 0.1
    assert changes.change_points(resid, FS, None) == []


def test_a_tracked_familys_level_step_is_located_beside_its_bound_not_at_a_burst():
    resid, _params = _tracked_residual(_wandering(1, 1.1, slice(100, 180)))
    found = changes.change_points(resid, FS, None)
    window_s = N / 16 / FS
    assert [round(c["t"] / window_s, 1) for c in found] == [pytest.approx(2.5, abs=0.1)]
    assert all(window_s < c["t"] < N / FS - window_s for c in found)


def test_locate_keeps_the_split_a_guard_from_the_spans_ends():
    # a 0.6 s burst at the span's start wins the two-segment likelihood against a 15 % step at 50 s; with the
    # guard (an eighth of a window in ``_segment``: a change nearer the span's end would be the next bound) the
    # split and its support stay at least that far in
    fs, n, guard = 100.0, 8192, 512
    y = _stepped(2, n, 5000, 1.15, slice(0, 60), 4.0)
    t_free, _ = changes.locate(y, 1, fs)
    assert t_free < 1.0
    t, (lo, hi) = changes.locate(y, 1, fs, guard=guard)
    assert guard / fs <= t <= (n - guard) / fs
    assert lo >= (guard - 1) / fs and hi <= (n - guard + 1) / fs
