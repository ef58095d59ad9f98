"""The exceptions allanite raises for bad input.

Every one subclasses :class:`ValueError`, so ``except ValueError`` keeps working; catch
:class:`AllaniteError` to tell allanite's complaints from others. Messages name the value that was
wrong and what is allowed. The Rust core's errors arrive as the same classes.
"""

from __future__ import annotations

__all__ = [
    "AllaniteError",
    "InputError",
    "ParameterError",
    "MemoryBudgetError",
    "DataGapError",
    "MissingDependencyError",
]


class AllaniteError(ValueError):
    """Base class of every allanite error (a ``ValueError``)."""


class InputError(AllaniteError):
    """The samples themselves are unusable: wrong type or shape, NaN/inf, too short, malformed files."""


class DataGapError(InputError):
    """A log's time stamps have gaps (samples missing) and the call was not told how to handle them."""


class ParameterError(AllaniteError):
    """An option is outside what is allowed: fs, window, hop, taus, estimator, method, …"""


class MemoryBudgetError(AllaniteError):
    """The requested output would exceed the memory budget (``max_memory``)."""


class MissingDependencyError(AllaniteError, ImportError):
    """An optional package needed for this call is not installed (the message names the ``pip install``
    extra)."""
