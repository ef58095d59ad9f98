"""What a curve candidate (:mod:`.candidates`) is given and gives at a step: the :class:`Round` (the curve, the
current model, the curve test, the held-out split, the samples and their spectral lines), its :class:`Proposal`
(the best column, its statistic and threshold), the :class:`CurveCandidate` entry's shape, and the helpers every
domain's entry shares: a column's amplitude with its ±1 SD, a proposal judged by the curve test, the registry's
search grid, an (amplitude, parameter) pair with its intervals. Below the domains' modules and :mod:`.candidates`,
which re-exports these names."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from .. import tracing
from ..effects import EFFECTS
from .curvefit import Curve, Solution, base_name, column, profile_interval
from .levels import LEVEL
from .scoring import Split

__all__ = [
    "Round",
    "Proposal",
    "CurveCandidate",
    "column_amplitude",
    "with_stat",
    "search_grid",
    "amplitude_and_profile",
]


@dataclass
class Round:
    """What one step of the loop offers every curve candidate: the curve, the current model (terms ``start``
    plus ``effects``, solution ``sol``), the thinned curve with the curve test and its threshold, the held-out
    split, the samples (None for curve-only input), the spectral lines found in them, the record's false-alarm
    ``level`` and the curve test's thinning and covariance (for a candidate's own nested test). (A round that
    only reads an effect's parameters off a solution needs the first four.)"""

    curve: Curve
    start: tuple
    effects: list
    sol: Solution
    sub: Curve | None = None
    test: tracing.ScoreTest | None = None
    thr: float = math.nan
    split: Split | None = None
    y: np.ndarray | None = None
    lines: list = field(default_factory=list)
    level: float = LEVEL
    #: the thinned τ's indices and whether the test's covariance is exact (a candidate's own nested test)
    thin: np.ndarray | None = None
    exact: bool = False

    @property
    def tmin(self) -> float:
        """Shortest τ of the curve (s)."""
        return float(self.curve.tau[0])

    @property
    def tmax(self) -> float:
        """Longest τ of the curve (s)."""
        return float(self.curve.tau[-1])


@dataclass
class Proposal:
    """One candidate's best column at a step: ``key`` (effect, with its kind), nonlinear parameter ``p``,
    the solution with it, whether ``p`` sits at the edge of its range, the statistic and its threshold,
    the held-out split to judge it on, the spectral line it came from (if any), and its entry in
    ``Refinement.considered``."""

    key: str
    p: float
    sol: Solution
    edge: bool
    stat: float
    thr: float
    split: Split | None
    line: dict | None = None
    pair_note: str | None = None
    record: dict = field(default_factory=dict)
    #: what the candidate's own comparisons said at this step, for its step's evidence (a resonance's shape)
    notes: dict = field(default_factory=dict)
    #: its column in ``sol`` (the last while it is proposed; its place in the final model afterwards)
    column: int = -1

    @property
    def effect(self) -> str:
        """The effect's name (``key`` without its kind)."""
        return base_name(self.key)


@dataclass(frozen=True)
class CurveCandidate:
    """A curve effect's entry: ``family(sub, has_samples)`` its columns on the thinned curve for the
    bootstrap of the maximum statistic; ``propose(round)`` its proposals at a step; ``params(pr, round)``
    the step's parameters and intervals; ``evidence(pr, round)`` what another domain says (or {});
    ``amplitude`` the parameter that is the column's amplitude, updated from the final joint fit (None:
    none, or it came from the samples); ``searches(round)`` the bounded searches ``propose`` will ask for,
    ``(key, grid, continuous)`` each, run beforehand with every other candidate's (:func:`prefetch`)."""

    name: str
    family: Callable[[Curve, bool], list]
    propose: Callable[[Round], list]
    params: Callable[[Proposal, Round], tuple]
    evidence: Callable[[Proposal, Round], dict] = lambda pr, rnd: {}
    amplitude: Callable[[Proposal], str | None] = lambda pr: None
    searches: Callable[[Round], list] = lambda rnd: []


def column_amplitude(sol: Solution, i: int) -> tuple[float, float, tuple[float, float]]:
    """Amplitude of column ``i`` (√θ), its SD, and the ±1 SD interval clipped at 0."""
    amp = math.sqrt(max(sol.theta[i], 0.0))
    var_i = sol.cov[i, i]
    sd = math.sqrt(max(var_i, 0.0)) / (2 * amp) if amp > 0 and np.isfinite(var_i) else float("nan")
    return amp, sd, (max(0.0, amp - sd), amp + sd)


def with_stat(rnd: Round, key: str, p: float, sol: Solution, edge: bool, bump: np.ndarray | None = None):
    """A proposal judged by the curve test (its column on the thinned τ, less ``bump`` if given)."""
    assert rnd.sub is not None and rnd.test is not None
    col = column(key, p, rnd.sub) if bump is None else column(key, p, rnd.sub) - bump
    return Proposal(key, p, sol, edge, rnd.test.statistic(rnd.sub.avar, col), rnd.thr, rnd.split)


def search_grid(effect: str, tmin, tmax):
    """The registry's search grid of a curve effect's nonlinear parameter over the τ range [tmin, tmax]."""
    grid = EFFECTS[effect].search
    assert grid is not None
    return grid(tmin, tmax)


def amplitude_and_profile(pr: Proposal, rnd: Round) -> tuple:
    """(amplitude, nonlinear parameter) with the amplitude's ±1 SD and the parameter's profile interval."""
    names = EFFECTS[pr.effect].param_names
    amp, _sd, amp_int = column_amplitude(pr.sol, pr.column)
    p_int = profile_interval(rnd.curve, rnd.start, rnd.effects, pr.key, pr.p, pr.sol)
    return {names[0]: amp, names[1]: pr.p}, {names[0]: amp_int, names[1]: p_int}
