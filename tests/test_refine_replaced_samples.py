"""Samples the outliers step replaced are no longer in the record: the clipped and held checks of
``Refinement.unexplained`` leave them out (benches/refine_blind6.py's dropped packets: a logger writing 0.0 for
lost samples, in runs of 4, on an accelerometer reading 9.81 m/s² — replaced as impulsive noise, then said
"clipped at 0 … left in the record" though none of them was left)."""

from __future__ import annotations

import types

import numpy as np

import allanite
from allanite.model.refinement import _quality as qc
from allanite.model.refinement.levels import alpha

A_CLIP = alpha("unexplained:clipped", 0.05)
A_HELD = alpha("unexplained:held", 0.05)


def _dropped(n: int, seed: int, runs: int = 10, run: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """9.81 m/s² plus white noise, ``runs`` runs of ``run`` samples written as 0.0; and where they are."""
    rng = np.random.default_rng(seed)
    y = 9.81 + 1e-3 * rng.standard_normal(n)
    lost = np.zeros(n, dtype=bool)
    for s in rng.choice(np.arange(10, n // 10 - 10), runs, replace=False) * 10:
        lost[s : s + run] = True
    y[lost] = 0.0
    return y, lost


def _ctx(y, replaced=None):
    tau0 = types.SimpleNamespace(tau=np.array([0.01]))
    return types.SimpleNamespace(samples=y, fs=100.0, curve=tau0, unit=None, level=0.05, replaced=replaced)


def _said(ctx) -> list[str]:
    return [e["domain"] for e in qc.clipped_check(ctx, A_CLIP) + qc.held_check(ctx, A_HELD)]


def test_replaced_dropouts_are_neither_a_rail_nor_held_samples():
    y, lost = _dropped(20_000, 1)
    assert _said(_ctx(y)) == ["clipped"]  # as given: 40 samples at the smallest value, in 10 runs
    assert _said(_ctx(y, np.zeros(y.size, dtype=bool))) == ["clipped"]  # nothing replaced: the same
    assert _said(_ctx(y, lost)) == []


def test_a_rail_keeps_its_samples_that_were_not_replaced():
    y, _lost = _dropped(20_000, 2, runs=0)
    top = np.quantile(y, 0.99)
    y = np.minimum(y, top)  # clipped at its top 1 %: 200 samples at the rail
    replaced = np.zeros(y.size, dtype=bool)
    replaced[np.flatnonzero(y == top)[:50]] = True  # a quarter of them replaced by some removal
    entries = qc.clipped_check(_ctx(y, replaced), A_CLIP)
    assert [e["domain"] for e in entries] == ["clipped"]
    assert entries[0]["value"] == top and entries[0]["samples"] == 150


def test_refine_replaces_the_dropped_packets_and_leaves_nothing_unexplained():
    y, lost = _dropped(4_000, 3)
    r = allanite.refine(y, 100.0, unit=None, progress=False)
    assert r.found == ["outliers"]
    assert r.steps[0].params["rate"] == lost.mean()  # every dropped sample flagged, nothing else
    assert r.unexplained == []
