"""The noise model: its terms (a registry), the covariance of Allan estimates across τ, the fit with
confidence intervals, the Cramér–Rao bound, and the loop that finds what a fitted model lacks
(:func:`refine`, with its effects as a registry of their own).
"""

from .effects import EFFECTS
from .fitting import CoefficientSeries, NoiseFit, fit, information_bound
from .refinement import Refinement, Step, refine
from .terms import TERM_NAMES, TERMS
from .timeframes import TimeFrames, frame_for_count, frames

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
