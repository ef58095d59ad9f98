"""allanite — static and dynamic Allan variance for gyroscopes, IMUs and clocks, with a Rust core.

Main entry points: :func:`avar` (static overlapping/classic Allan variance), :func:`davar` (dynamic
Allan variance on a sliding window, naive or fast), :func:`tau_grid` (τ grids). Errors are
:class:`AllaniteError` subclasses of ``ValueError``.
"""

from ._core import __version__
from .allan import avar, davar
from .confidence import chi2_interval, confidence_intervals, edf_greenhall, edf_sp1065, identify_alpha
from .datasets import default_record
from .errors import AllaniteError, InputError, MemoryBudgetError, ParameterError
from .fit import CoefficientSeries, NoiseFit, fit, information_bound
from .grid import tau_grid
from .io import Log, read_log
from .refine import Refinement, refine
from .results import AllanResult, DynamicAllanResult
from .simulate import simulate

__all__ = [
    "avar", "davar", "tau_grid", "default_record", "simulate",
    "read_log", "Log", "fit", "information_bound", "NoiseFit", "CoefficientSeries", "refine", "Refinement",
    "confidence_intervals", "identify_alpha", "edf_greenhall", "edf_sp1065", "chi2_interval",
    "AllanResult", "DynamicAllanResult",
    "AllaniteError", "InputError", "ParameterError", "MemoryBudgetError",
    "__version__",
]
