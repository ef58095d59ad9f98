"""Channels as loggers write them — quantised in value, held in time — read back before the regression
(:mod:`allanite.model._staircase`, docs/channels.md "Quantised and held channels"). Small seeded records, each
well under 2 s."""

from __future__ import annotations

import numpy as np
import pytest

from allanite.model._staircase import ChannelForm, channel_form, reconstructed
from allanite.model.channels import regress_channel
from allanite.report._regression import regression_dict, regression_lines


def _sine(n: int, fs: float, period: float, mid=25.0, amp=5.0) -> np.ndarray:
    return mid + amp * np.sin(2 * np.pi * np.arange(n) / fs / period)


@pytest.mark.parametrize("q", [0.5, 0.125, 1 / 16, 1 / 340])
def test_quantum_read_from_the_channel(q):
    x = np.round(_sine(50_000, 10.0, 2000.0) / q) * q
    f = channel_form(x)
    assert f.quantum == pytest.approx(q, rel=1e-9) and f.hold == 1 and f.staircase
    assert f.words(10.0).startswith(f"quantised at {q:.4g}")


def test_hold_read_from_the_channel():
    fs, k = 100.0, 100  # read at 1 Hz, held on the 100 Hz stamps, starting part-way into a reading
    x = np.repeat(_sine(700, 1.0, 300.0), k)[37 : 37 + 60_000]
    f = channel_form(x)
    assert (f.hold, f.phase, f.quantum) == (k, k - 37, None)
    assert "held for 1 s (100 samples" in f.words(fs)


def test_plain_and_dithered_channels_stay_as_they_are():
    rng = np.random.default_rng(3)
    smooth = _sine(20_000, 10.0, 500.0) + 0.01 * rng.standard_normal(20_000)
    assert channel_form(smooth) == ChannelForm()
    assert reconstructed(smooth, channel_form(smooth)) is smooth
    # 0.3 °C of noise on a 0.1 °C quantum: quantised, but its steps reverse as often as not — dithered, not a
    # staircase; read as it is
    noisy = np.round((_sine(20_000, 10.0, 500.0) + 0.3 * rng.standard_normal(20_000)) * 10) / 10
    f = channel_form(noisy)
    assert f.quantum == pytest.approx(0.1) and not f.staircase and f.reversals > 0.4 and f.plain


def test_read_back_is_near_the_quantity_sampled():
    fs, n = 10.0, 200_000
    truth = _sine(n, fs, 8000.0)
    stairs = np.round(truth / 0.5) * 0.5
    err_as_logged = np.std(stairs - truth)  # ≈ q/√12 = 0.144
    err = np.std(reconstructed(stairs, channel_form(stairs)) - truth)
    assert err_as_logged > 0.13 and err < 0.2 * err_as_logged
    held = np.repeat(truth[::50], 50)[:n]  # 5 s hold: half a hold late on average
    err_held = np.std(reconstructed(held, channel_form(held)) - truth)
    assert err_held < 0.05 * np.std(held - truth)  # 0.022 here: the joining is linear


def test_staircase_keeps_no_lag():
    """A 0.5 °C staircase of a slow sine, the rate following the smooth temperature at no lag: on main a lag of
    25 s was kept (2Δℓ 48 against 14.9; 10 Hz × 2·10⁵ over an 8000 s period: 16 s) — the lag smoothed the
    staircase's sawtooth away."""
    rng = np.random.default_rng(1)
    fs, n = 10.0, 100_000
    temp = _sine(n, fs, 4000.0)
    y = 0.01 * rng.standard_normal(n) + 0.002 * temp
    r = regress_channel(y, np.round(temp / 0.5) * 0.5, fs, name="temp")
    assert r.accepted and set(r.params) == {"coefficient"}
    assert r.params["coefficient"] == pytest.approx(0.002, rel=0.03)
    assert r.terms["lag_s"]["statistic"] < 0.5 * r.terms["lag_s"]["threshold"]  # 3.6 against 21.4
    lines = regression_lines(regression_dict({"terms": r.terms, "channel_form": r.form.evidence(fs)}))
    assert "channel: quantised at 0.5 (a slow staircase: its crossings read back)" in lines


def test_quantised_channel_keeps_its_rate_term():
    """d(ch)/dt of a 0.125 °C staircase is a spike train: on main the true dT/dt term (0.3 per °C/s) was not kept
    (statistic 0.78 against 10.8) and a 2 s lag was kept in its place."""
    rng = np.random.default_rng(1)
    fs, n = 1.0, 100_000
    temp = _sine(n, fs, 10_000.0, mid=25.0, amp=15.0)
    y = 0.003 * rng.standard_normal(n) + 2e-4 * temp + 0.3 * np.gradient(temp) * fs
    r = regress_channel(y, np.round(temp * 8) / 8, fs, name="temp")
    assert set(r.params) == {"coefficient", "rate_coefficient"}
    assert r.params["rate_coefficient"] == pytest.approx(0.3, rel=0.05)
    assert r.params["coefficient"] == pytest.approx(2e-4, rel=0.05)


def test_real_steps_are_not_read_back():
    """A ±1 g multi-position profile turned on a fixed grid of samples looks held (its changes' gcd is the dwell),
    a heater switched on once looks like a one-step staircase: their steps are what they measure (the rate
    steps with them), and they stay as they are."""
    dwell = 3000  # 300 s at 10 Hz
    profile = np.repeat(np.where(np.arange(40) % 2 == 0, 1.0, -1.0), dwell)
    assert channel_form(profile).plain and reconstructed(profile, channel_form(profile)) is profile
    switch = np.where(np.arange(50_000) < 20_000, 0.0, 1.0)
    assert channel_form(switch).plain
    ramp_of_levels = np.repeat(np.arange(40) * 0.5, dwell)  # a slow staircase of many steps is read back
    assert channel_form(ramp_of_levels).staircase


def test_chatter_is_one_crossing():
    """A 0.5 °C staircase with 0.02 °C of noise chatters across each boundary as it passes: its transitions
    between the same two steps are one crossing, so it is still a slow staircase, read back as well as without
    the noise; with 0.1 °C of noise the quantisation dithers and the channel is used as it is."""
    rng = np.random.default_rng(0)
    truth = _sine(200_000, 10.0, 8000.0)
    quiet = np.round((truth + 0.02 * rng.standard_normal(truth.size)) / 0.5) * 0.5
    f = channel_form(quiet)
    assert f.staircase and f.reversals < 0.1
    assert np.std(reconstructed(quiet, f) - truth) < 0.03  # 0.023; as logged 0.140
    noisy = np.round((truth + 0.1 * rng.standard_normal(truth.size)) / 0.5) * 0.5
    assert not channel_form(noisy).staircase
