"""A harmonic family whose fundamental hunts (an engine's, a pump's idle speed): the line search finds each
harmonic as several peaks across its smear and splits them among lattices of two close "fundamentals"; the
``"periodic"`` removal gathers them as one family and tracks its phase (:func:`allanite.model.periodic.
hunting_family`, :func:`allanite.model.refinement._family_parts.hunting`)."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from allanite.model import periodic
from allanite.model.refinement._family_parts import hunting
from allanite.model.refinement.levels import alpha

FS, N, F0, PARTS = 100.0, 1 << 16, 6.25, ((1, 0.3), (2, 0.8), (4, 0.4))


def _record(depth: float, seed: int = 3) -> np.ndarray:
    """Unit white noise plus harmonics 1, 2 and 4 of F0, the fundamental hunting ±``depth`` with a 97 s period."""
    rng = np.random.default_rng(seed)
    t = np.arange(N) / FS
    f = F0 * (1.0 + depth * np.sin(2 * np.pi * t / 97.0 + 0.3))
    ph = 2 * np.pi * np.cumsum(f) / FS
    return rng.standard_normal(N) + sum(a * np.sin(k * ph + k) for k, a in PARTS)


def _hunt(y: np.ndarray):
    a = alpha("lines", 0.05)
    search = periodic.periodic_search(y, FS, a)
    return search, hunting(SimpleNamespace(y=y, fs=FS, level=0.05), search, a)


def test_a_hunting_family_of_three_members_is_one_periodic_with_its_fundamental():
    search, got = _hunt(_record(0.003))
    assert got is not None
    component, _refit, ratio, params, _intervals, evidence, fam, covered = got
    assert params["fundamentals"][0] == pytest.approx(F0, rel=2e-4)
    assert evidence["coefficients"] == [[1], [2], [4]]
    assert params["rms"] == pytest.approx(math.sqrt(sum(a * a for _k, a in PARTS) / 2), rel=0.05)
    assert params["wander_hz"] == pytest.approx(F0 * 0.003 / math.sqrt(2.0), rel=0.3)  # a sinusoid's rms
    assert ratio < evidence["wander"]["heldout_variance_ratio"]["steady"]
    assert covered and all(any(u is c for c in covered) for u in search["families"] + search["sinusoids"])
    assert np.std(_record(0.003) - component) == pytest.approx(1.0, rel=0.02)  # the lines all taken


def test_a_steady_family_is_left_to_the_lattice():
    _search, got = _hunt(_record(0.0))
    assert got is None  # single peaks: the search's own harmonic family takes it
