"""The ``"mean"`` check of ``Refinement.unexplained``: one step of the mean along the record (issue 29, item 4).

A bias step leaves the first differences alone and looks like rate random walk on the Allan curve, so the final
fit absorbs it; the check's null comes from the model refitted without the located step. Records of 10⁵–2·10⁵
samples keep each test to a second or two (the check on a context built as refine builds its own; one default
``refine`` call); the false-alarm rate over 300 clean records is in ``benches/results/refine_mean_step_null.md``.
"""

from __future__ import annotations

import html as html_mod
import math
import re

import numpy as np
import pytest

import allanite
from allanite.estimators.grid import tau_grid
from allanite.model import tracing
from allanite.model.refinement import _mean_step as ms
from allanite.model.refinement.curvefit import Curve, solve
from allanite.model.refinement.levels import LEVEL, alpha
from allanite.model.refinement.missing import CHECKS, MissingContext
from allanite.model.refinement.words import describe_region

FS = 50.0
START = ("Q", "N", "B", "K", "R")
A = alpha("unexplained:mean", 0.05)


def _record(n: int, step: float, seed: int, at: float = 0.55) -> np.ndarray:
    """White + flicker + a little rate random walk (blind2's bias-step noise), the mean stepping by ``step`` at
    ``at`` of the record."""
    y = allanite.simulate(n, FS, N=2e-3, B=3e-4, K=2e-6, seed=seed)
    y[int(at * n) :] += step
    return y


def _context(y: np.ndarray, heldout_pct: float | None = 2.5) -> MissingContext:
    """The state the check sees after refine: its dense curve of ``y`` and the five terms fitted to it."""
    res = allanite.avar(y, FS, taus=tau_grid(y.size, FS, "exp", points=300, m_max=y.size // 9))
    cur = Curve(res.tau, res.m.astype(np.float64), res.avar, FS, res.n_samples + 1, res.estimator)
    ctx = MissingContext(cur, np.arange(cur.tau.size), solve(cur, START, []), START, [], y, FS, 0.05, True)
    ctx.unit, ctx.heldout_pct = "deg/s", heldout_pct
    return ctx


def test_the_step_avar_is_the_allan_variance_of_a_step_exactly():
    n = 20_000
    for index in (11_000, 300, 19_950):
        y = np.zeros(n)
        y[index:] = 0.3
        res = allanite.avar(y, FS)
        got = ms.step_avar(n, index, 0.3, res.m)
        assert np.allclose(got, res.avar, rtol=1e-12, atol=0)


def test_the_split_statistic_is_the_two_segment_mean_change():
    b = np.r_[np.zeros(30), np.ones(18)]
    stat, k = ms.split_statistic(b)
    assert k[0] == 30 and stat[0] == pytest.approx(np.sqrt(30 * 18) / 48)


def test_a_step_of_the_mean_is_said_and_located():
    n = 200_000  # 4000 s; the step at 2200 s
    ctx = _context(_record(n, 5e-3, seed=3))
    assert ctx.sol.theta[START.index("K")] > 10 * (2e-6) ** 2  # the plain fit took the step as random walk
    out = ms.mean_step_check(ctx, A)
    assert len(out) == 1
    e = out[0]
    assert e["domain"] == "mean" and e["alpha"] == A
    assert e["statistic"] > e["threshold"] > 0
    assert abs(e["t_step"] - 2200.0) <= 0.02 * 4000.0  # within 2 % of the record
    assert e["step"] == pytest.approx(5e-3, rel=0.2)
    assert e["t"] == (e["t_step"], 4000.0) and e["departure_pct"] > 2.5
    assert e["tau"][0] < e["tau"][1] and e["band_hz"] == pytest.approx((0.5 / e["tau"][1], 0.5 / e["tau"][0]))
    text = describe_region(e)
    assert "the mean steps by 0.005 deg/s at t ≈ 22" in text and "held-out error 2.5 %" in text


def test_a_clean_flicker_and_random_walk_record_is_silent():
    # the gate off (no held-out error): the test alone, and at 5 % rather than its own α
    ctx = _context(_record(200_000, 0.0, seed=11), heldout_pct=None)
    assert ms.mean_step_check(ctx, 0.05) == []


def test_a_step_smaller_than_the_held_out_error_is_not_said():
    ctx = _context(_record(200_000, 5e-3, seed=3), heldout_pct=None)
    assert ms.mean_step_check(ctx, A)  # the test rejects
    ctx.heldout_pct = 1e4  # but nothing it moves exceeds an error this large
    assert ms.mean_step_check(ctx, A) == []


def test_the_check_is_registered_and_needs_the_samples():
    assert CHECKS["mean"] is ms.mean_step_check
    ctx = _context(_record(100_000, 0.0, seed=1))
    ctx.y = None
    assert ms.mean_step_check(ctx, A) == []


def test_refine_says_the_step_in_every_surface():
    y = _record(100_000, 8e-3, seed=4)  # 2000 s, the step at 1100 s
    r = allanite.refine(y, FS, unit="deg/s", progress=False)
    got = [u for u in r.unexplained if u["domain"] == "mean"]
    assert len(got) == 1 and abs(got[0]["t_step"] - 1100.0) <= 40.0
    said = re.compile(r"the mean steps by 0\.00[78]\d* deg/s at t ≈ 1(09\d|10\d|11\d)")
    assert said.search(r.report()) and said.search(html_mod.unescape(r._repr_html_()))


def test_a_small_level_does_not_simulate_a_record_beyond_the_cap(monkeypatch):
    """refine accepts any level in (0, 1); at level 10⁻⁴ the check's α is 3.1·10⁻⁷ and 5/α null records would
    be 7.7·10⁸ block-rate samples (gigabytes). The draws stop at :data:`MAX_BOOT`; below what they resolve the
    threshold is their largest statistic (the rank rule's last index)."""
    asked = []
    real = tracing.block_rate_record  # the nulls' records (allanite.simulate's numbers, model/_null_records.py)

    def counted(n, *args, **kw):
        asked.append(n)
        assert n <= tracing.SIM_CHUNK, f"{n} block-rate samples asked for at once"
        return real(n, *args, **kw)

    monkeypatch.setattr(tracing, "block_rate_record", counted)
    theta = [0.0, 4e-6, 9e-8, 4e-12, 0.0]
    thr = ms.mean_step_threshold(200_000, FS, START, theta, alpha("unexplained:mean", 1e-4))
    # MAX_BOOT records, a chunk of records at a time (each chunk a whole long record: the last one's spare pieces
    # are simulated too)
    each = tracing.SIM_CHUNK // ms.MEAN_BLOCKS
    assert asked == [ms.MEAN_BLOCKS * each] * math.ceil(ms.MAX_BOOT / each)
    assert thr == ms.null_statistics(200_000, FS, START, theta, ms.MAX_BOOT)[-1] > 0
    # at the default level the number of draws is unchanged (5/α)
    assert ms.MAX_BOOT >= math.ceil(ms.BOOT_PER_ALPHA / A)


def _plain_locate(y: np.ndarray) -> dict:
    """:func:`ms.locate_step` written out: exactly rounded block means (``math.fsum``), every split's statistic
    by its definition, the fine split searched within ±1 block of the best block split, the step from the sums."""
    n, nb = y.size, ms.MEAN_BLOCKS
    nf, per, per_f = nb * ms.FINE, y.size // nb, y.size // (nb * ms.FINE)
    b = [math.fsum(y[i * per : (i + 1) * per]) / per for i in range(nb)]
    gains = [
        math.sqrt(k * (nb - k)) / nb * abs(math.fsum(b[:k]) / k - math.fsum(b[k:]) / (nb - k)) for k in range(1, nb)
    ]
    k = 1 + max(range(nb - 1), key=lambda i: gains[i])
    f = [math.fsum(y[i * per_f : (i + 1) * per_f]) / per_f for i in range(nf)]
    fine = {
        kk: math.sqrt(kk * (nf - kk)) * abs(math.fsum(f[:kk]) / kk - math.fsum(f[kk:]) / (nf - kk))
        for kk in range(max(1, (k - 1) * ms.FINE), min(nf - 1, (k + 1) * ms.FINE) + 1)
    }
    index = max(fine, key=lambda kk: (fine[kk], -kk)) * per_f  # the first of equal maxima, as argmax
    d = math.fsum(y[index:]) / (n - index) - math.fsum(y[:index]) / index
    return {"statistic": max(gains), "index": index, "d": d, "block": per}


@pytest.mark.parametrize(
    "n, step, at, seed",
    [(200_000, 0.01, 0.55, 1), (200_017, 0.0, 0.5, 2), (123_457, 0.004, 0.03, 3), (300_001, -0.02, 0.97, 4)],
)
def test_the_block_sum_location_equals_a_plain_reference(n, step, at, seed):
    # a step, none, one in the first and one in the last block; lengths not a multiple of the 1536 fine blocks
    y = _record(n, step, seed, at)
    got, ref = ms.locate_step(y), _plain_locate(y)
    assert got["index"] == ref["index"] and got["block"] == ref["block"]
    assert got["statistic"] == pytest.approx(ref["statistic"], rel=1e-12)
    assert got["d"] == pytest.approx(ref["d"], rel=1e-12, abs=1e-12 * float(np.std(y)))
    if step:
        assert abs(got["index"] - int(at * n)) <= 2 * (n // (ms.MEAN_BLOCKS * ms.FINE))


def test_locating_the_step_holds_no_copy_of_the_record():
    # the block means are reductions of views (strided too): memory O(blocks), not O(samples) — at 10⁸ samples
    # a record-length temporary is 0.8 GB
    import tracemalloc

    y = _record(2_000_000, 0.01, 5)
    for samples in (y, y[::2]):
        tracemalloc.start()
        try:
            ms.locate_step(samples)
            peak = tracemalloc.get_traced_memory()[1]
        finally:
            tracemalloc.stop()
        assert peak < 200_000, peak  # the record is 16 MB (the strided view 8 MB)


def _clock_record() -> np.ndarray:
    """refine_blind6's clock (1 Hz × 10⁵ of fractional frequency: white 10⁻¹², flicker 10⁻¹⁴, random walk
    10⁻¹⁷) whose frequency steps by 10⁻¹³ at 0.4 T, drawn as that suite draws it (seed 611)."""
    from allanite.simulation import kasdin_walter

    n, rng = 100_000, np.random.default_rng(611)
    y = allanite.simulate(n, 1.0, N=1e-12, K=1e-17, seed=rng) + 1e-14 * kasdin_walter(4 * n, 1.0, rng)[-n:]
    y[40_000:] += 1e-13
    return y


def _clock_context() -> MissingContext:
    y = _clock_record()
    res = allanite.avar(y, 1.0, taus=tau_grid(y.size, 1.0, "exp", points=300, m_max=y.size // 9))
    cur = Curve(res.tau, res.m.astype(np.float64), res.avar, 1.0, res.n_samples + 1, res.estimator)
    ctx = MissingContext(cur, np.arange(cur.tau.size), solve(cur, START, []), START, [], y, 1.0, 0.05, True)
    ctx.heldout_pct = 5.9  # the final model's in that suite
    return ctx


def _chi2_rise(curve: Curve, sol, theta: np.ndarray) -> float:
    """χ² of the five terms ``theta`` on ``curve`` (the fit's weights) over its minimum, in effective points."""
    from allanite.model import fitting
    from allanite.model.refinement._columns import design

    a, _ = design(curve, START, [])
    w = np.sqrt(sol.nu / (2.0 * sol.model**2))
    aw, yw = a * w[:, None], curve.avar * w
    best = float(np.sum((yw - aw @ fitting.nnls(aw, yw)) ** 2))
    return (float(np.sum((yw - aw @ theta) ** 2)) - best) * curve.n_eff / curve.tau.size


def test_the_null_is_profiled_over_models_the_curve_allows():
    """Each null model is one slow term at its upper end with the others refitted there — χ² within its 4
    effective points — where raising flicker and random walk at once (upper_theta) is a corner the clock's
    curve does not allow."""
    from allanite.model.refinement.curvefit import theta_terms, upper_theta

    loc, sol, _dep = ms.located(_clock_context())
    corner = upper_theta(loc["curve"], sol, START, [], theta_terms(sol, START, []))
    b, k = START.index("B"), START.index("K")
    assert len(loc["thetas"]) == 2
    by_b, by_k = loc["thetas"]
    assert by_b[b] == corner[b] and by_k[k] == corner[k] > 100 * (1e-17) ** 2  # the same upper ends
    assert by_b[k] < corner[k] and by_k[b] < corner[b]  # the other slow term refitted below its upper end
    for theta in loc["thetas"]:
        assert _chi2_rise(loc["curve"], sol, theta) <= 4.0 + 1e-9
    assert _chi2_rise(loc["curve"], sol, corner) > 4.0


def test_a_clocks_frequency_step_is_said():
    """refine_blind6's clock row: the corner null's threshold was 1.05× the statistic (5.25·10⁻¹⁴ against
    4.99·10⁻¹⁴; silent); the profile's largest is 0.93× it."""
    out = ms.mean_step_check(_clock_context(), alpha("unexplained:mean", LEVEL))
    assert len(out) == 1
    e = out[0]
    assert e["statistic"] == pytest.approx(4.99e-14, rel=0.01) and e["threshold"] < 0.95 * e["statistic"]
    assert abs(e["t_step"] - 40_000.0) <= 100.0 and e["step"] == pytest.approx(1e-13, rel=0.05)


def test_the_profile_threshold_is_the_largest_and_stops_once_the_statistic_is_covered(monkeypatch):
    thetas = [np.array([0.0, 4e-6, 9e-8, 0.0, 0.0]), np.array([0.0, 4e-6, 0.0, 1e-9, 0.0])]
    each = [ms.mean_step_threshold(100_000, FS, START, t, 0.01) for t in thetas]
    assert each[1] > each[0] > 0  # the random walk's end the larger here
    assert ms.profile_threshold(100_000, FS, START, thetas, 0.01) == max(each)
    asked = []
    real = ms.mean_step_threshold
    monkeypatch.setattr(ms, "mean_step_threshold", lambda *a, **k: asked.append(a[3]) or real(*a, **k))
    # a statistic the last model's threshold already covers: the test holds, the other null is not drawn
    assert ms.profile_threshold(100_000, FS, START, thetas, 0.01, stop_at=each[1]) == each[1]
    assert len(asked) == 1 and asked[0] is thetas[1]
