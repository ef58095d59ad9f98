"""A context variable set to a value within a ``with`` block and put back after it (the refine call's settings that
reach its deep helpers: a counter's Q column, a declared filter, a withdrawn bandwidth kind or resonance shape)."""

from __future__ import annotations

import contextlib
import contextvars
from collections.abc import Iterator
from typing import TypeVar

__all__ = ["scoped"]

T = TypeVar("T")


@contextlib.contextmanager
def scoped(var: contextvars.ContextVar[T], value: T) -> Iterator[None]:
    """Within it ``var`` holds ``value``; after it (however the block ends) what it held before."""
    token = var.set(value)
    try:
        yield
    finally:
        var.reset(token)
