"""The exceptions allanite raises for bad input.

Every one subclasses :class:`ValueError`, so ``except ValueError`` keeps working; catch
:class:`AllaniteError` to tell allanite's complaints from others. Messages name the value that was
wrong and what is allowed.
"""

from __future__ import annotations

__all__ = ["AllaniteError", "InputError", "ParameterError", "MemoryBudgetError"]


class AllaniteError(ValueError):
    """Base class of every allanite error (a ``ValueError``)."""


class InputError(AllaniteError):
    """The samples themselves are unusable: wrong type or shape, NaN/inf, too short."""


class ParameterError(AllaniteError):
    """An option is outside what is allowed: fs, window, hop, taus, estimator, method, …"""


class MemoryBudgetError(AllaniteError):
    """The requested output would exceed the memory budget (``max_memory``)."""
