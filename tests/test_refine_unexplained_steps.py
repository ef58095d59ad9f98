"""The ``"steps"`` check of ``Refinement.unexplained``: steps of the mean at one or several times (issue 29).

Steps of opposite signs at several times mix in one split's two sides and keep a refitted K high, so the one-step
``"mean"`` check stayed silent on them (blind3's bias-steps row). This check takes the block means' largest
increment over their own robust scale; its null is nearly pivotal (it does not hang on K). The false-alarm rate
over 300 clean records is in ``benches/results/refine_mean_step_null.md``.
"""

from __future__ import annotations

import html as html_mod
import re

import numpy as np
import pytest

import allanite
from allanite.estimators.grid import tau_grid
from allanite.model.refinement import _mean_step as ms
from allanite.model.refinement import _mean_steps as mss
from allanite.model.refinement.curvefit import Curve, solve
from allanite.model.refinement.levels import SAMPLE_CHECKS, UNEXPLAINED_SHARES, alpha
from allanite.model.refinement.missing import CHECKS, MissingContext, unexplained
from allanite.model.tracing import block_means
from allanite.simulation import kasdin_walter

FS = 20.0
START = ("Q", "N", "B", "K", "R")
A = alpha("unexplained:steps", 0.05)
THREE = ((0.2, 2.5e-3), (0.5, -4e-3), (0.8, 3e-3))


def _three_steps(n: int, seed: int) -> np.ndarray:
    """blind3's bias-steps record: white 3·10⁻³, flicker 3·10⁻⁴, random walk 10⁻⁶ at 20 Hz, +2.5, −4,
    +3·10⁻³ at 0.2, 0.5, 0.8 of the record."""
    y = allanite.simulate(n, FS, N=3e-3, B=3e-4, K=1e-6, seed=seed)
    for frac, d in THREE:
        y[int(frac * n) :] += d
    return y


def _context(y: np.ndarray, heldout_pct: float | None = 2.5, fs: float = FS) -> MissingContext:
    """The state the check sees after refine: its dense curve of ``y`` and the five terms fitted to it."""
    res = allanite.avar(y, fs, taus=tau_grid(y.size, fs, "exp", points=300, m_max=y.size // 9))
    cur = Curve(res.tau, res.m.astype(np.float64), res.avar, fs, res.n_samples + 1, res.estimator)
    ctx = MissingContext(cur, np.arange(cur.tau.size), solve(cur, START, []), START, [], y, fs, 0.05, True)
    ctx.unit, ctx.heldout_pct = "deg/s", heldout_pct
    return ctx


def test_the_share_is_half_of_the_mean_checks_and_needs_the_samples():
    assert UNEXPLAINED_SHARES["steps"] == UNEXPLAINED_SHARES["mean"] == 0.003125
    assert "steps" in SAMPLE_CHECKS and CHECKS["steps"] is mss.steps_check
    ctx = _context(_three_steps(100_000, seed=1))
    ctx.y = None
    assert mss.steps_check(ctx, A) == []


def test_the_increments_statistic_is_free_of_scale_and_ramp():
    rng = np.random.default_rng(3)
    half = rng.normal(size=(256, 4))
    z, _ = mss.increment_z(half, mss.STEP_BLOCKS)
    ramp = np.arange(256.0)[:, None] * 0.37
    z2, _ = mss.increment_z(7.5 * half + ramp - 2.0, mss.STEP_BLOCKS)
    assert np.allclose(z, z2, rtol=1e-10)
    # one half-block boundary stepping by 12 σ of the increments: the 32-block length's largest z is that step
    stepped = half.copy()
    stepped[128:] += 12.0 * np.sqrt(2.0 / 8.0)  # increments of 8-half means of unit noise: SD √(2/8)
    z3, incs = mss.increment_z(stepped, mss.STEP_BLOCKS)
    assert np.all(z3[0] > 7.0) and np.all(np.argmax(incs[0], axis=0) == 128 // 4 - 2)


def test_the_null_hardly_depends_on_the_noise_model():
    # the statistic is a ratio of the record's own increments: white alone, flicker alone or random walk alone
    # give thresholds within 15 % (K — which steps left in the record inflate — barely moves it)
    thr = [
        mss.null_ratios(300_000, FS, ("N", "B", "K"), th, A)["threshold"]
        for th in ([9e-6, 0.0, 0.0], [0.0, 9e-8, 0.0], [0.0, 0.0, 1e-12], [9e-6, 9e-8, 1e-10])
    ]
    assert max(thr) / min(thr) < 1.15, thr
    assert 2.0 < min(thr) < 4.0


def test_noiseless_steps_are_located_to_the_fine_block_and_sized_exactly():
    n = 2**17
    y = np.zeros(n)
    for index, d in ((20_000, 1.0), (70_001, -2.0), (110_000, 0.5)):
        y[index:] += d
    y += 1e-3 * np.random.default_rng(0).normal(size=n)
    half, _ = block_means(y, 2 * 64)
    z, incs = mss.increment_z(half, (32, 64))
    got = mss.locate_steps(y, 32, incs[0][:, 0], 50.0)
    fine = 2 * (n // 64) // mss.FINE
    assert [round(k / fine) for k, _ in got] == [round(k / fine) for k in (20_000, 70_001, 110_000)]
    assert [d for _, d in got] == pytest.approx([1.0, -2.0, 0.5], rel=1.0 / mss.FINE)  # a step inside a fine mean


def test_three_bias_steps_are_said_and_located():
    # blind3's configuration at half its length (15 000 s): the one-split check was silent on such records
    n = 300_000
    y = _three_steps(n, seed=6)
    ctx = _context(y)
    assert ms.mean_step_check(ctx, alpha("unexplained:mean", 0.05)) == []  # what main said: nothing
    out = mss.steps_check(ctx, A)
    assert len(out) == 1
    e = out[0]
    assert e["domain"] == "steps" and e["alpha"] == A and e["statistic"] > e["threshold"] > 0
    span = n / FS
    assert len(e["steps"]) == 3
    for (t, d), (frac, true) in zip(e["steps"], THREE):
        assert abs(t - frac * span) <= 0.01 * span and d == pytest.approx(true, rel=0.3)
    assert e["t"] == (e["steps"][0][0], span) and e["departure_pct"] > 2.5
    said = r"the mean steps by 0\.00\d+ deg/s at t ≈ [23]\d{3}.*; by -0\.00\d+ deg/s at t ≈ 7\d{3}.*; and by 0\.00\d+ deg/s at t ≈ 1[12]\d{3}"
    assert re.search(said, e["what"])


@pytest.mark.parametrize("seed", [11, 12, 13, 14])
def test_clean_flicker_random_walk_and_gauss_markov_records_are_silent(seed):
    # the gate off (no held-out error): the test alone, at its own α
    rng = np.random.default_rng(seed)
    n = 200_000
    y = allanite.simulate(n, FS, N=2e-3, K=3e-6, gauss_markov=[(2e-3, 300.0)] if seed % 2 else (), seed=rng)
    y = y + 4e-4 * kasdin_walter(4 * n, 1.0, rng)[-n:]  # stationary flicker
    assert mss.steps_check(_context(y, heldout_pct=None), A) == []


@pytest.mark.slow  # steps said: test_refine_says_the_steps_in_every_surface
def test_one_step_is_said_once_by_the_mean_check():
    n = 200_000
    y = allanite.simulate(n, 50.0, N=2e-3, B=3e-4, K=2e-6, seed=3)
    y[int(0.55 * n) :] += 6e-3
    ctx = _context(y, fs=50.0)
    got = [u["domain"] for u in unexplained(ctx) if u["domain"] in ("mean", "steps")]
    assert got == ["mean"]
    assert mss.steps_check(ctx, A)  # it found the step too, and it is not repeated


def test_refine_says_the_steps_in_every_surface():
    y = _three_steps(300_000, seed=6)
    r = allanite.refine(y, FS, unit="deg/s", progress=False)
    got = [u for u in r.unexplained if u["domain"] == "steps"]
    assert len(got) == 1 and len(got[0]["steps"]) >= 2
    said = re.compile(r"the mean steps by 0\.00\d+ deg/s at t ≈ [23]\d{3}.*; by -0\.00[34]\d* deg/s at t ≈ 7[45]\d\d")
    assert said.search(r.report()) and said.search(html_mod.unescape(r._repr_html_()))


def test_degenerate_records_and_models_say_nothing_rather_than_divide_by_zero():
    # most increments exactly zero (a record stuck between rounding levels): no scale, no evidence
    stuck = np.zeros(100_000)
    stuck[::5000] = 1.0
    z, _ = mss.increment_z(block_means(stuck, 2 * 128)[0], mss.STEP_BLOCKS)
    assert np.all(np.isfinite(z))
    # a model with nothing at the block rate: the null is drawn as white noise (the statistic is free of scale)
    null = mss.null_ratios(100_000, FS, ("Q", "N"), [1e-6, 0.0], 0.01)
    assert np.all(null["q"] > 1.0) and 1.2 < null["threshold"] < 4.0  # at α 1 %: 1.69


def test_a_small_level_does_not_simulate_beyond_the_cap():
    null = mss.null_ratios(100_000, FS, ("N",), [1e-6], alpha("unexplained:steps", 1e-4))
    assert null["n_boot"] == mss.MAX_BOOT and null["threshold"] == null["draws"][-1]


def test_the_steps_block_means_are_the_component_s_exactly():
    steps = [(1000, 0.5), (2503, -1.25), (7999, 2.0)]
    comp = np.zeros(8192)
    for index, d in steps:
        comp[index:] += d
    for per in (1, 64, 100, 512):
        count = comp.size // per
        want = comp[: count * per].reshape(count, per).mean(axis=1)
        assert np.allclose(mss._step_means(steps, per, count), want, rtol=0, atol=1e-13)
