"""A line family whose fundamental wanders: tracked, its wander measured, nothing left; a steady one left steady
(:mod:`allanite.model.wander`, through the ``"periodic"`` removal's ``_tracked``)."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from allanite.model import periodic
from allanite.model.refinement.levels import alpha
from allanite.model.refinement.removals import _tracked, heldout_variance_ratio

FS, N, F0, AMPS = 50.0, 1 << 17, 1.5, (0.5, 0.3, 0.2)


def _record(wander: float, seed: int = 11) -> np.ndarray:
    """Unit white noise plus harmonics 1–3 of F0, the fundamental wandering ±``wander`` over 1.5 periods."""
    rng = np.random.default_rng(seed)
    t = np.arange(N) / FS
    f = F0 * (1.0 + wander * np.sin(2 * np.pi * t / (N / FS / 1.5) + 0.4))
    ph = 2 * np.pi * np.cumsum(f) / FS
    return rng.standard_normal(N) + sum(a * np.sin(k * ph + k) for k, a in enumerate(AMPS, start=1))


def _step(y: np.ndarray):
    """What the periodic removal does with the record's strongest family: (tracked or None, params, evidence)."""
    search = periodic.periodic_search(y, FS, alpha("lines", 0.05))
    fam = search["families"][0]
    params: dict = {"fundamentals": [float(g) for g in fam.gens], "lines": int(fam.coefs.shape[0]), "rms": fam.rms}
    intervals: dict = {}
    evidence: dict = {}
    ctx = SimpleNamespace(y=y, fs=FS, level=0.05)
    comp = fam.component()
    got = _tracked(ctx, fam, comp, heldout_variance_ratio(y, fam.refit), (params, intervals, evidence))
    return got, params, evidence


def test_a_wandering_family_is_tracked_and_nothing_is_left():
    y = _record(0.004)
    got, params, evidence = _step(y)
    assert got is not None, evidence.get("wander")
    component, _refit, ratio = got
    assert ratio < evidence["wander"]["heldout_variance_ratio"]["steady"]
    assert params["lines"] == 3 and abs(params["fundamentals"][0] / F0 - 1) < 1e-3
    truth = F0 * 0.004 / math.sqrt(2.0)  # rms of a sinusoidal wander
    assert params["wander_hz"] == pytest.approx(truth, rel=0.3)
    assert params["wander_pct"] == pytest.approx(100 * 0.004 / math.sqrt(2.0), rel=0.3)
    assert params["rms"] == pytest.approx(math.sqrt(sum(a * a for a in AMPS) / 2), rel=0.05)
    assert "wanders" in evidence["wander"]["note"]
    left = periodic.periodic_search(y - component, FS, alpha("lines", 0.05))["lines"]
    near = [d["f"] for d in left if min(abs(d["f"] - k * F0) for k in (1, 2, 3)) < 0.05 * F0]
    assert near == []


def test_a_steady_family_is_not_called_wandering():
    y = _record(0.0)
    got, params, evidence = _step(y)
    assert got is None
    test = evidence["wander"]["test"]
    assert test["ratio"] < test["threshold"] and not test["accepted"]
    assert "wander_hz" not in params
