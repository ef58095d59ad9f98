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
from .errors import AllaniteError, InputError, MemoryBudgetError, ParameterError
from .estimators.confidence import chi2_interval, confidence_intervals, edf_greenhall, edf_sp1065, identify_alpha
from .estimators.grid import tau_grid
from .io import Log, read_log
from .model import CoefficientSeries, NoiseFit, TimeFrames, fit, frames, information_bound
from .results import AllanResult, DynamicAllanResult

if TYPE_CHECKING:
    from .combination import Combination, combine
    from .datasets import default_record
    from .kalibr import to_kalibr
    from .model import Refinement, refine
    from .simulation import simulate
    from .wavelet import Split, wavelet_split

#: Names loaded on first use (module, relative to this package): what an avar/davar/fit needs is imported with
#: the package; these modules, and the refinement package behind ``allanite.model``'s refine, when asked for.
_LAZY = {
    "refine": ".model",
    "Refinement": ".model",
    "combine": ".combination",
    "Combination": ".combination",
    "default_record": ".datasets",
    "to_kalibr": ".kalibr",
    "simulate": ".simulation",
    "wavelet_split": ".wavelet",
    "Split": ".wavelet",
}


def __getattr__(name: str):
    if name in _LAZY:
        import importlib

        value = getattr(importlib.import_module(_LAZY[name], __name__), name)
        globals()[name] = value  # found directly from now on
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))


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
