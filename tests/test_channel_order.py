"""A record's channels regressed strongest first (``allanite.model.refinement._channel_order``; blind suite 10's
humidity among three channels, lost to a temperature correlated with it when the channels were taken in the order
given)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

import allanite
from allanite.model.refinement._channel_order import margin, strongest_first
from sensors import first_order_lag


def test_margin_puts_t_and_likelihood_ratios_on_one_scale():
    assert margin({"t": 6.0, "threshold": 3.0, "alpha": 0.001}) == 4.0
    assert margin({"likelihood_ratio": 45.0, "threshold": 18.0, "alpha": 0.001, "dof": 13.0}) == 2.5


def _fake(strength: dict, taken: list):
    """A remover whose channel passes by ``strength[name]`` on samples that still hold it (``ctx.y`` lists the
    names not yet removed), and records a turned-down test through ``ctx.consider``."""

    def one(ctx, name, _ch):
        s = strength[name] if name in ctx.y else 0.5
        if s <= 1.0:
            ctx.consider("regression", {"channel": name, "statistic": s, "on": tuple(ctx.y)})
            return
        yield SimpleNamespace(name=name, evidence={"test": {"likelihood_ratio": s, "threshold": 1.0}})

    said: list = []
    ctx = SimpleNamespace(y=tuple(strength), channels=dict.fromkeys(strength), consider=lambda e, d: said.append(d))
    for rem in strongest_first(ctx, one):
        taken.append(rem.name)
        ctx.y = tuple(k for k in ctx.y if k != rem.name)  # accepted: the caller's loop replaces the samples
    return said


def test_strongest_first_offers_the_widest_margin_first_and_retests_the_rest():
    taken: list = []
    said = _fake({"a": 2.0, "b": 5.0, "c": 0.2}, taken)
    assert taken == ["b", "a"]
    # the channel never taken is recorded once, from its last test (on the samples both removals left)
    assert said == [{"channel": "c", "statistic": 0.2, "on": ("c",)}]


def test_nothing_offered_where_no_channel_passes():
    taken: list = []
    said = _fake({"a": 0.9, "b": 0.3}, taken)
    assert taken == []
    assert [d["channel"] for d in said] == ["a", "b"]


def test_the_coupled_channel_wins_over_a_correlated_one_given_first():
    """Humidity couples, the temperature does not, the two share a cycle (anti-correlated): given temperature
    first, the order given took the temperature (≈ −2.5× the humidity's coefficient, the humidity then below its
    threshold on what was left); strongest first takes the humidity, at its coefficient."""
    n, fs, c = 8_000, 1.0, 3e-4
    rng = np.random.default_rng(0)
    t = np.arange(n) / fs
    y = allanite.simulate(n, fs, N=3e-3, K=1e-5, seed=rng)

    def weather(lag):
        v = first_order_lag(np.cumsum(rng.standard_normal(n)), fs, lag)
        return (v - v.mean()) / np.ptp(v)

    cycle = np.sin(2 * np.pi * t / 2000.0)
    temp = 24 + 3 * cycle + 2 * weather(250.0)
    hum = 45 - 8 * cycle + 15 * weather(160.0)
    chans = {"temp": temp, "humidity": hum}
    r = allanite.refine(y + c * (hum - hum.mean()), fs, channels=chans, candidates=("regression",), progress=False)
    assert [s.params["channel"] for s in r.steps] == ["humidity"]
    assert abs(r.steps[0].params["coefficient"] / c - 1) < 0.1
