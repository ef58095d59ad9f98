"""The ``"line"`` check's words where a line's amplitude follows a channel (:mod:`allanite.model.refinement.
_line_channel`; docs/lines-and-outliers.md, "A line whose amplitude follows a channel"): the in-phase slope of the
block phasors on the channel's block means, F(1, d₂) on the blocks' own noise. Its false alarms on whole refines
of null records: benches/results/line_channel_null.md; here small seeded records (each well under 2 CPU s)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from allanite.analysis import avar
from allanite.model.refinement._line_channel import _one, block_means, follows_channel
from allanite.model.refinement._line_check import line_check
from allanite.model.refinement._line_constancy import line_constancy
from allanite.model.refinement.levels import alpha

FS, N, F0, A0 = 50.0, 40_000, 3.0, 0.5
ALPHA = alpha("unexplained:line", 0.05)


def _record(seed: int, g: float, step: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Unit white noise + a little random walk + a 3 Hz line of amplitude A0·(1 + g·(T − T̄)), T cycling 15–35 °C
    twice with 0.01 °C of sensor noise; with ``step``, a line that doubles at the record's middle while T warms once
    from 15 to 35 °C."""
    rng = np.random.default_rng(seed)
    t = np.arange(N) / FS
    temp = 15.0 + 20.0 * t / t[-1] if step else 25.0 - 10.0 * np.cos(2 * np.pi * t / (t[-1] / 2) + 0.3)
    temp = temp + 0.01 * rng.standard_normal(N)
    amp = A0 * (2.0 if step else 1.0) ** (t >= t[-1] / 2) * (1.0 + g * (temp - temp.mean()))
    y = rng.normal(size=N) + 1e-3 * np.cumsum(rng.normal(size=N)) + amp * np.sin(2 * np.pi * F0 * t + 0.7)
    return y, temp


def _tie(y, temp):
    r = line_constancy(y, FS, F0, ALPHA, phasors=True)
    args = (r["phasors"], r["phasor_unit"], r["noise_level"], r["noise_dof"], r["edges_s"], FS)
    return r, follows_channel(*args, {"temp": temp}, ALPHA)


def test_an_amplitude_that_follows_the_temperature_is_tied_to_it_with_its_slope():
    """±20 % over 15–35 °C (g = 0.02 per °C): the channel named, g within 15 %, its leftover not a change."""
    r, tie = _tie(*_record(7, 0.02))
    assert r["rejected"]
    assert tie is not None and tie["channel"] == "temp" and tie["g"] == pytest.approx(0.02, rel=0.15)
    assert tie["statistic"] > 3 * tie["threshold"] and tie["left"] < tie["left_threshold"]
    assert tie["mean"] == pytest.approx(25.0, abs=0.5)


def test_a_constant_line_and_a_step_in_time_are_not_tied_to_the_channel():
    """A constant line: no slope on the channel. A line that doubles at the middle while T warms once: its slope
    on T passes (the two are correlated), but what T leaves — the step less its line in T — is itself a change,
    so the line is not said to follow T. (A smaller step is not told from a slope on a channel that moves once:
    30 % here leaves F 1.19 against 2.32, and the words say the change goes with T — docs/lines-and-outliers.md.)"""
    assert _tie(*_record(7, 0.0))[1] is None
    y, temp = _record(7, 0.0, step=True)
    r, tie = _tie(y, temp)
    assert r["rejected"] and tie is None
    xk = block_means(temp, np.round(np.asarray(r["edges_s"]) * FS).astype(int))
    one = _one(np.asarray(r["phasors"]), np.asarray(r["phasor_unit"]), r["noise_level"], r["noise_dof"], xk, ALPHA)
    assert one["statistic"] > one["threshold"] and one["left"] > one["left_threshold"]


def test_the_check_says_the_channel_in_its_words():
    y, temp = _record(11, 0.02)
    ctx = SimpleNamespace(
        y=y, fs=FS, curve=avar(y, FS), effects=[("sinusoid", F0)], families=[], heldout_pct=2.0, unit="deg/s"
    )
    (bare,) = line_check(ctx, ALPHA)
    assert "follows" not in bare and "'temp'" not in bare["what"]
    ctx.channels = {"temp": temp}
    (ln,) = line_check(ctx, ALPHA)
    assert ln["follows"]["channel"] == "temp" and ln["what"].startswith(bare["what"][:-1])
    assert "; it follows 'temp': +2" in ln["what"] and "% of its amplitude per unit of 'temp' about 25" in ln["what"]
