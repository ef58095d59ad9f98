"""What a check of ``unexplained`` is given (:class:`MissingContext`: the final state) and the dense curve's
χ²/dof over a τ range, below :mod:`.missing` and its families of checks (:mod:`._curve_checks`,
:mod:`._time_checks`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .curvefit import Curve, Solution, chi2_dof_between

__all__ = ["MissingContext", "chi2_dof"]


@dataclass
class MissingContext:
    """The final state a check looks at: the curve and its fitted solution (terms ``start`` + ``effects``), the
    thinned τ, the final samples (None for curve-only input) and their rate, the channels, ``level``, and
    whether the five terms' covariance across τ is exact; ``unit`` the rate's unit when known."""

    curve: Curve
    thin: np.ndarray
    sol: Solution
    start: tuple
    effects: list
    y: np.ndarray | None
    fs: float
    level: float
    exact: bool
    channels: dict = field(default_factory=dict)
    unit: str | None = None
    #: what the checks computed once from the final samples (the Welch PSD of :func:`._curve_checks._band`)
    memo: dict = field(default_factory=dict)
    #: times (s) of the change points refine accepted: the noise level is checked between them
    change_times: list = field(default_factory=list)
    #: the final model's held-out RMS ADEV error (%), the yardstick of a level change's size (None: not known)
    heldout_pct: float | None = None
    #: with change points accepted, the held-out RMS ADEV error per segment with all of them (each segment's
    #: held-out part predicted by its own held-in part's model): what the model misses given the change points,
    #: the yardstick of a level change between them (None: no change point, ``heldout_pct`` is)
    segments_heldout_pct: float | None = None
    #: the ``"periodic"`` families removed in time, as (fundamentals, line frequencies, line amplitudes, the
    #: removed component's samples): the ``"line"`` check tests each one's strongest line (:mod:`._line_check`)
    families: list = field(default_factory=list)
    #: the samples as refine was given them, before any removal in time (None for curve-only input): the
    #: clipped and held samples are looked for there (:mod:`._quality`)
    samples: np.ndarray | None = None
    #: True at the samples an accepted removal replaced (the ``"outliers"`` step's; None: none): the clipped
    #: and held checks leave them out
    replaced: np.ndarray | None = None
    #: every proposal refine tried, by effect (``Refinement.considered``), and the lines (Hz) the ``"sinusoid"``
    #: candidate's search found (None: the candidate was left out or had no samples): the ``"psd"`` check says why
    #: a line it names was not kept
    considered: dict = field(default_factory=dict)
    offered_lines: list | None = None
    #: the line search's lines of few cycles (each found by its test in time, :mod:`allanite.model.slowline`) left
    #: in the samples because no step took them (the ``"sinusoid"`` candidate left out or turning them down): the
    #: ``"psd"`` check names them
    slow_lines: list = field(default_factory=list)


def chi2_dof(ctx: MissingContext, lo: float, hi: float) -> float:
    return chi2_dof_between(ctx.curve.tau, ctx.sol.z, lo, hi)
