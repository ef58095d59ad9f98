"""A bias on (T − T₀)² with the turnover T₀ inside the temperature's swing (resonators, quartz, many MEMS): almost no
linear coupling, so the channel's own test cannot pass — the quadratic's nested test, at its own share, is run
when it fails (`allanite.model.channels.regress_channel`, docs/channels.md "A turnover temperature"). Calibration
at scale: the null counts in docs/channels.md; the suite's case: benches/refine_blind7.py --case turnover."""

from __future__ import annotations

import numpy as np
import pytest

import allanite
from allanite.model.channels import regress_channel

Q, T0 = 4e-5, 25.0  # rate unit per °C², °C


def _record(seed: int, q: float, n: int = 20_000, fs: float = 2.0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    temp = 25.0 + 10.0 * np.sin(2 * np.pi * t / (t[-1] / 3.0) - 0.5 * np.pi) + 0.01 * rng.standard_normal(n)
    y = allanite.simulate(n, fs, N=3e-3, B=4e-4, K=5e-6, seed=rng)
    return y + q * (temp - T0) ** 2, temp, fs


def test_a_turnover_is_taken_by_the_quadratic_where_the_channel_alone_reads_nothing():
    y, temp, fs = _record(3, Q)
    r = regress_channel(y, temp, fs, name="temp")
    # the channel and its quadrature: nothing (the square is even about 25 °C, the channel odd)
    assert r.test["statistic"] < r.test["threshold"]
    assert r.accepted and r.test["accepted_by"] == "quadratic"
    q = r.test["quadratic"]
    # its α: the quadratic's part of the coupling's own (FIRST_QUADRATIC), the pair the rest
    assert q["statistic"] > q["threshold"] and q["alpha"] == pytest.approx(0.2 * 0.075 * 0.05)
    assert r.test["alpha"] == pytest.approx(0.8 * 0.075 * 0.05)
    assert r.terms["quadratic"]["kept"] and "rate_coefficient" not in r.params and "lag_s" not in r.params
    assert abs(r.params["quadratic"] / Q - 1.0) < 0.1
    lo, hi = r.intervals["quadratic"]
    assert lo < r.params["quadratic"] < hi
    turn = r.terms["quadratic"]["turnover"]
    assert turn["inside"] and abs(turn["value"] - T0) < 0.5
    assert turn["interval"][0] < turn["value"] < turn["interval"][1]
    # what it removes is the bias: the component against the truth, within 10 % of its rms
    truth = Q * (temp - T0) ** 2
    err = r.component(temp) - (truth - truth.mean())
    assert np.std(err) < 0.1 * np.std(truth)


def test_no_coupling_takes_neither_the_channel_nor_its_square():
    y, temp, fs = _record(4, 0.0)
    r = regress_channel(y, temp, fs, name="temp")
    assert not r.accepted and "quadratic" not in r.params and r.terms == {}
    assert r.test["quadratic"]["statistic"] < r.test["quadratic"]["threshold"]
    assert "accepted_by" not in r.test


def test_without_the_quadratic_among_the_terms_the_turnover_is_not_taken():
    # unexplained's channel check asks for the coupling alone (terms=()): it is not tried there
    y, temp, fs = _record(3, Q)
    r = regress_channel(y, temp, fs, name="temp", terms=())
    assert not r.accepted and "quadratic" not in r.test


def test_a_bent_linear_coupling_reports_its_turnover_outside_the_range_without_an_interval():
    # T₀ far outside 15–35 °C: the curve is only bent; linear passes its own test first, as before
    y, temp, fs = _record(5, Q)
    y = y + 4e-3 * temp  # vertex at 25 − 4e-3/(2·4e-5) = −25 °C
    r = regress_channel(y, temp, fs, name="temp")
    assert r.accepted and r.test["accepted_by"] == "channel" and r.terms["quadratic"]["kept"]
    turn = r.terms["quadratic"]["turnover"]
    assert not turn["inside"] and turn["interval"] is None and abs(turn["value"] + 25.0) < 5.0


def test_beside_a_quadratic_the_coefficient_is_the_slope_at_the_whole_records_mean():
    # the Whittle fit uses the usable prefix (19 683 of 20 000 samples here: 5-smooth differences); the channel
    # rising 0 → 30 °C once (half a cosine), its mean over that prefix is 0.24 °C below the record's. The slope
    # b₁ + 2·b₂·(x − m) moves by 2·b₂·δm = 48 % of b₁ there (−49.6 % before r13swing, its interval 0.48–0.53·10⁻³
    # missing the truth), so the reference must be the record's mean (channels.centring)
    n, fs, c, q = 20_000, 2.0, 1e-3, 1e-3
    rng = np.random.default_rng(11)
    t = np.arange(n) / fs
    temp = 15.0 * (1.0 - np.cos(np.pi * t / t[-1])) + 0.01 * rng.standard_normal(n)
    d = temp - temp.mean()
    y = allanite.simulate(n, fs, N=1e-5, K=1e-8, seed=rng) + c * d + q * (d * d)
    r = regress_channel(y, temp, fs, name="temp")
    assert r.accepted and r.terms["quadratic"]["kept"]
    assert r.terms["quadratic"]["t_ref"] == pytest.approx(temp.mean(), abs=1e-9)
    assert abs(r.params["quadratic"] / q - 1.0) < 0.01
    assert abs(r.params["coefficient"] / c - 1.0) < 0.05
