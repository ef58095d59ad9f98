"""The ``"channels"`` check of ``unexplained`` (a coupling left in the final samples): the coupling's test of any
phase (channel and quadrature, 2 dof) and the in-phase test alone (1 dof, more power on a coupling without lag),
each at 0.8/1.8 of the check's share, and where the pair fails the quadratic's at 0.2/1.8 (a coupling on the
channel's square) — blind suite 2's 2 kHz MEMS refined without the regression read 18.0 against the pair's 19.4
(nothing said) and 17.8 against the in-phase 17.05 at half the share; blind10's float32 quadratic coupling without
its candidate read the pair 1.9 against 21.7 and the quadratic 43.0 against 38.6."""

from __future__ import annotations

import types

import numpy as np
import pytest

from allanite.model import channels
from allanite.model.refinement import missing


def _ctx(fs=10.0, n=20_000):
    curve = types.SimpleNamespace(tau=np.array([0.1, 100.0]))
    y = np.zeros(n)
    return types.SimpleNamespace(
        y=y, fs=fs, channels={"temp": np.linspace(0.0, 1.0, n)}, curve=curve, level=0.05, unit="deg/s"
    )


def _fake(accepted, pair, one, seen, quad=None):
    def regress(y, ch, fs, *, name, alpha, level, terms):
        seen.append((alpha, terms))
        test = {"statistic": pair[0], "threshold": pair[1], "in_phase": {"statistic": one[0], "threshold": one[1]}}
        params = {"coefficient": 2e-4}
        if quad is not None:  # the pair failed, the quadratic's test ran
            test["quadratic"] = {"statistic": quad[0], "threshold": quad[1]}
            if quad[0] > quad[1]:
                test["accepted_by"], params = "quadratic", params | {"quadratic": 1.5e-5}
        return types.SimpleNamespace(accepted=accepted, test=test, params=params)

    return regress


@pytest.mark.parametrize(
    ("accepted", "pair", "one", "quad", "said", "stat"),
    [
        (False, (18.0, 19.4), (17.8, 17.05), (1.0, 38.6), True, 17.8),  # in phase: the 1-dof test takes it
        (True, (45.0, 19.4), (6.8, 17.05), None, True, 45.0),  # lagged: the pair takes it
        (True, (1.9, 21.7), (1.9, 16.6), (43.0, 38.6), True, 43.0),  # on the square: the quadratic takes it
        (False, (10.0, 19.4), (9.0, 17.05), (3.0, 38.6), False, None),  # none
    ],
)
def test_any_of_the_three_tests_says_the_channel(monkeypatch, accepted, pair, one, quad, said, stat):
    seen: list = []
    monkeypatch.setattr(channels, "is_slow", lambda ch: True)
    monkeypatch.setattr(channels, "regress_channel", _fake(accepted, pair, one, seen, quad))
    monkeypatch.setattr(missing, "_chi2_dof", lambda ctx, lo, hi: 1.0)
    out = missing._channels(_ctx(), 0.002)
    # regress_channel at a/1.8: the pair and the in-phase test each at 0.8 of it, the quadratic at 0.2 — a in all
    assert seen == [(pytest.approx(0.002 / 1.8), ("quadratic",))] and missing.SLOW_SPLIT == pytest.approx(1.8)
    assert bool(out) is said
    if said:
        assert out[0]["statistic"] == stat and "channel 'temp'" in out[0]["what"]
        assert ("through its square (≈ 1.5e-05 deg/s per channel unit²)" in out[0]["what"]) is (stat == 43.0)
