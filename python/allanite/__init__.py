"""allanite — static and dynamic Allan variance for gyroscopes, IMUs and clocks, with a Rust core.

Main entry points: :func:`avar` (static overlapping/classic Allan variance, Theo family), :func:`davar`
(dynamic Allan variance on a sliding window), :func:`tau_grid` (τ grids), :func:`fit` (the IEEE-952
noise model with intervals), :func:`refine` (what a fitted model lacks), :func:`frames` (time-frame
DAVAR, paper 004; its coefficient series are forecast by :mod:`allanite.forecast`). Errors are
:class:`AllaniteError` subclasses of ``ValueError``.
"""

from typing import TYPE_CHECKING

from ._core import __version__
from .analysis import avar, davar
from .combination import Combination, combine
from .datasets import default_record
from .errors import AllaniteError, InputError, MemoryBudgetError, ParameterError
from .estimators.confidence import chi2_interval, confidence_intervals, edf_greenhall, edf_sp1065, identify_alpha
from .estimators.grid import tau_grid
from .io import Log, read_log
from .kalibr import to_kalibr
from .model import CoefficientSeries, NoiseFit, TimeFrames, fit, frames, information_bound
from .results import AllanResult, DynamicAllanResult
from .simulation import simulate
from .wavelet import Split, wavelet_split

if TYPE_CHECKING:
    from .model import Refinement, refine


def __getattr__(name: str):
    if name in ("refine", "Refinement"):  # allanite.model loads the refinement package on first use
        from . import model

        return getattr(model, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "avar",
    "davar",
    "tau_grid",
    "default_record",
    "simulate",
    "read_log",
    "Log",
    "fit",
    "information_bound",
    "NoiseFit",
    "CoefficientSeries",
    "frames",
    "TimeFrames",
    "refine",
    "Refinement",
    "to_kalibr",
    "confidence_intervals",
    "identify_alpha",
    "edf_greenhall",
    "edf_sp1065",
    "chi2_interval",
    "AllanResult",
    "DynamicAllanResult",
    "AllaniteError",
    "InputError",
    "ParameterError",
    "MemoryBudgetError",
    "__version__",
    "wavelet_split",
    "Split",
    "combine",
    "Combination",
]
