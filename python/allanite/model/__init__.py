"""The noise model: its terms (a registry), the covariance of Allan estimates across τ, the fit with
confidence intervals, the Cramér–Rao bound, and the loop that finds what a fitted model lacks
(:func:`refine`, with its effects as a registry of their own).
"""

from typing import TYPE_CHECKING

from .effects import EFFECTS
from .fitting import CoefficientSeries, NoiseFit, fit, information_bound
from .terms import TERM_NAMES, TERMS
from .timeframes import TimeFrames, frame_for_count, frames

if TYPE_CHECKING:
    from .refinement import Refinement, Step, refine

#: Names of the refinement package, loaded on first use: it brings scipy.signal and scipy.stats, about
#: half of what ``import allanite`` would otherwise cost, which an avar/davar/fit/report never needs.
_LAZY = ("refine", "Refinement", "Step")


def __getattr__(name: str):
    if name in _LAZY:
        from . import refinement

        return getattr(refinement, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "fit",
    "information_bound",
    "NoiseFit",
    "CoefficientSeries",
    "refine",
    "Refinement",
    "Step",
    "TERMS",
    "TERM_NAMES",
    "EFFECTS",
    "frames",
    "frame_for_count",
    "TimeFrames",
]
