"""``unexplained``'s check of a coupling's shape (:mod:`allanite.model._shape`, the ``"channel_shape"`` check): the
residual's dependence on a channel's value beyond the terms kept for it — a bias staircase in temperature that a
straight line leaves uncorrelated with it. Its false alarms over 1500 null records:
benches/results/channel_shape_null.md; here small seeded records (each well under 2 CPU s)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

import allanite
from allanite.model._shape import shape_test
from allanite.model.refinement import levels
from allanite.model.refinement._channel_shape import channel_shape_check, kept_terms

FS, N = 10.0, 12_000
A = 0.05 * levels.UNEXPLAINED_SHARES["channel_shape"]


def _cycle(rng) -> np.ndarray:
    """A 10–40 °C temperature cycling three times, with 0.01 °C of sensor noise."""
    t = np.arange(N) / FS
    return 25.0 - 15.0 * np.cos(2 * np.pi * t / (t[-1] / 3)) + 0.01 * rng.standard_normal(N)


def _less_line(temp, comp):
    a = np.c_[np.ones(temp.size), temp]
    return comp - a @ np.linalg.lstsq(a, comp, rcond=None)[0]


@pytest.fixture(scope="module")
def record():
    rng = np.random.default_rng(29)
    y = allanite.simulate(N, FS, seed=rng, N=1e-3, K=2e-5, B=1e-4)
    return y, _cycle(rng)


def test_the_share_is_carved_from_the_channels_check():
    """The two channel checks spend what the linear one alone did (levels.py, docs/channels.md)."""
    sh = levels.UNEXPLAINED_SHARES
    assert sh["channels"] + sh["channel_shape"] == pytest.approx(0.0125)
    assert "channel_shape" in levels.SAMPLE_CHECKS


def test_a_clean_record_is_not_flagged(record):
    y, temp = record
    r = shape_test(y, temp, FS, A)
    assert not r["fired"] and r["named"] == []
    assert 0.0 <= r["statistic"] < 0.7 * r["threshold"]


def test_a_staircase_left_by_a_straight_line_is_said_where_it_steps(record):
    """Steps of 1.5σ·√… at 20 and 30 °C, less their straight line in T (what a linear removal leaves): found, and
    the cuts it names are within 1.5 °C of a true step; the threshold is the same as on the clean record (it
    depends on the channel and the noise, not on the residual's shape)."""
    y, temp = record
    stair = _less_line(temp, 1.5e-3 * ((temp > 20.0).astype(float) + (temp > 30.0)))
    r = shape_test(y + stair, temp, FS, A)
    assert r["fired"] and r["statistic"] > 1.5 * r["threshold"]
    assert all(min(abs(c - 20.0), abs(c - 30.0)) < 1.5 for c, _s in r["named"])
    assert all(s > 0 for _c, s in r["named"])  # the steps go up, as injected


def test_a_quadratic_the_kept_terms_explain_is_not_said(record):
    """A linear + quadratic coupling: the kept quadratic's column is in the null (nothing to say); without it kept
    the curvature is a departure."""
    y, temp = record
    z = y + 2e-4 * temp + 2.5e-3 * ((temp - 25.0) / 15.0) ** 2
    assert not shape_test(z, temp, FS, A, kept=("quadratic",))["fired"]
    r = shape_test(z, temp, FS, A)
    assert r["fired"] and "curvature" in [c for c, _v in r["named"]]


def test_the_check_names_the_channel_and_reads_the_kept_terms(record):
    y, temp = record
    stair = _less_line(temp, 1.5e-3 * ((temp > 20.0).astype(float) + (temp > 30.0)))
    effects = [("regression", {"channel": "temp", "coefficient": 1e-4, "quadratic": 1e-6})]
    ctx = SimpleNamespace(
        y=y + stair,
        fs=FS,
        channels={"temp": temp},
        effects=effects,
        unit="°/s",
        curve=SimpleNamespace(tau=np.geomspace(0.1, 300.0, 20)),
        sol=SimpleNamespace(z=np.ones(20)),
    )
    assert kept_terms(ctx, "temp") == ("quadratic",) and kept_terms(ctx, "other") == ()
    (e,) = channel_shape_check(ctx, A)
    assert e["domain"] == "channels" and e["channel"] == "temp" and "'temp'" in e["what"] and "°/s" in e["what"]
    assert e["statistic"] > e["threshold"] and e["alpha"] == A
    ctx.channels = {}
    assert channel_shape_check(ctx, A) == []


def test_the_words_name_steps_and_curvature():
    from allanite.model.refinement._channel_shape import _where

    w = _where([(29.8, 1.3e-3), (20.4, 1.5e-3)], "°/s", "temp")
    assert w == "the rate depends on 'temp' beyond its kept terms: steps near 20.4 and 29.8 (largest ≈ 0.0015 °/s)"
    w = _where([("curvature", 1e-5), (14.0, -2e-4)], None, "T")
    assert "steps near 14 (largest ≈ 0.0002 rate unit); curvature its kept terms do not model" in w


def test_the_null_draws_reach_beyond_a_small_alpha():
    """At a small α (many channels, a small level) the draws are enough for 20 of them beyond it: the 1 − α
    quantile is never the largest draw. With two independent candidates the statistic is χ²₂ exactly (both are
    chosen): its quantile at α = 10⁻⁵ is −2·ln α = 23.0."""
    from allanite.model._shape import _null_draws

    draws = _null_draws(np.eye(2), float("inf"), 1e-5)
    assert draws.size == 2_000_000
    assert np.quantile(draws, 1 - 1e-5) == pytest.approx(-2 * np.log(1e-5), rel=0.1)
    assert _null_draws(np.eye(2), float("inf"), 0.05).size == 100_000
