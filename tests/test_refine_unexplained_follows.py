"""``unexplained``'s ``"follows"`` check: an accepted line that a channel no regression uses carries coherently
(:mod:`allanite.model.refinement._channel_follows`) — blind12's heater with its regression candidate left out took
the temperature's 60 s sawtooth as a line family and said nothing; the check says it (coherence 0.96 over 27
segments), and stays silent where the channel does not carry the line or a regression already uses it."""

from __future__ import annotations

import math
import types

import numpy as np
import pytest
from scipy import signal

from allanite.model.refinement import _channel_follows as cf
from allanite.model.refinement.levels import CONDITIONAL_SHARES, alpha
from allanite.model.refinement.missing import CHECKS
from allanite.model.refinement.words import describe_region

FS, N, PERIOD = 10.0, 60_000, 60.0  # 6000 s: 100 periods of the line


def _heater(seed=0, coupled=True):
    """A rate on a 60 s sawtooth temperature through a 20 s lag (or a rate with its own line at the same period and
    a temperature that does not carry it), white noise; the temperature."""
    rng = np.random.default_rng(seed)
    t = np.arange(N) / FS
    temp = 25 + 0.6 * signal.sawtooth(2 * np.pi * t / PERIOD) + 0.01 * rng.standard_normal(N)
    a = math.exp(-1.0 / (FS * 20.0))
    lagged = signal.lfilter([1 - a], [1, -a], temp - temp[0]) + temp[0]
    line = 7e-3 * (lagged - lagged.mean()) if coupled else 2e-3 * np.sin(2 * np.pi * t / PERIOD + 1.0)
    if not coupled:
        temp = 25 + 3 * np.sin(2 * np.pi * t / 4000.0) + 0.01 * rng.standard_normal(N)  # slow, no 60 s line
    return 0.01 * rng.standard_normal(N) + line, temp, line


def _ctx(y, temp, comp=None, effects=()):
    """The final state after a family at 1/60 Hz was removed in time (``comp`` its removed samples)."""
    fams = [] if comp is None else [([1 / PERIOD], [1 / PERIOD, 2 / PERIOD], [1.0, 0.5], comp)]
    return types.SimpleNamespace(
        y=y if comp is None else y - comp,
        fs=FS,
        channels={"temp": temp},
        effects=list(effects),
        families=fams,
        curve=types.SimpleNamespace(tau=np.geomspace(0.1, 600.0, 12)),
        sol=types.SimpleNamespace(z=np.zeros(12)),
    )


def test_a_removed_family_the_channel_carries_is_said_with_its_channel_and_frequency():
    y, temp, line = _heater()
    a = alpha("unexplained:follows", 0.05)
    out = cf.follows_check(_ctx(y, temp, comp=line), a)
    assert len(out) == 1 and out[0]["domain"] == "channels" and out[0]["channel"] == "temp"
    assert out[0]["f0"] == pytest.approx(1 / PERIOD) and out[0]["effect"] == "periodic"
    assert out[0]["coherence"] > 0.8 and out[0]["p_coherence"] < a and out[0]["p_line"] < a
    assert out[0]["segments"] == 16 and out[0]["statistic"] > out[0]["threshold"]  # 100 periods / 6 per segment
    assert "follows channel 'temp'" in out[0]["what"] and "regression on 'temp'" in out[0]["what"]
    assert out[0]["chi2_dof"] is None  # the evidence is the channel's, not the curve's
    assert describe_region(out[0]).startswith("τ 12–60 s, ≈ 0.017 Hz: the periodic line the model took at 0.01667 Hz")


def test_silent_where_a_regression_uses_the_channel_or_the_channel_does_not_carry_the_line():
    y, temp, line = _heater()
    a = alpha("unexplained:follows", 0.05)
    assert cf.follows_check(_ctx(y, temp, comp=line, effects=[("regression", {"channel": "temp"})]), a) == []
    y2, temp2, line2 = _heater(coupled=False)
    r = cf.coherence_test(y2, temp2, FS, 1 / PERIOD)
    assert r is not None and r["p_line"] > 0.01  # the slow temperature holds no 60 s line
    assert cf.follows_check(_ctx(y2, temp2, comp=line2), a) == []
    assert cf.follows_check(_ctx(y2, temp2, effects=[("sinusoid", 1 / PERIOD)]), a) == []  # a sinusoid: same


def test_the_coherence_null_is_beta_and_too_few_periods_are_not_tested():
    """Under a channel independent of the rate the coherence is Beta(1, K − 1): its p-values spread over (0, 1)."""
    y, _temp, _line = _heater()
    rng = np.random.default_rng(5)
    p = np.array([cf.coherence_test(y, rng.standard_normal(N), FS, 1 / PERIOD)["p_coherence"] for _ in range(40)])
    assert 0.2 < np.median(p) < 0.8 and np.sum(p < 0.05) <= 7  # 2 expected; ≥ 8 of 40 has probability < 0.1 %
    assert cf.coherence_test(y[:3000], _temp[:3000], FS, 1 / PERIOD) is None  # 5 periods: fewer than 6 × 6


def test_its_share_is_conditional_on_a_line_and_it_is_among_the_checks():
    assert CHECKS["follows"] is cf.follows_check and CONDITIONAL_SHARES["unexplained:follows"] == 0.02
    assert alpha("unexplained:follows", 0.05) == pytest.approx(1e-3)
