"""The IEEE-952 noise terms — one registry entry each: name, meaning, noise type, Allan-variance column.

Model (``docs/FORMULAS.md`` §4.1, IEEE Std 952-1997 Annex C), τ in s, coefficients in the input unit's
base form:

    σ²(τ) = 3Q²/τ² + N²/τ + (2 ln2/π)·B² + K²·τ0(2m² + 1)/(6m) + R²τ²/2

The rate-random-walk column is the exact Allan variance of a *sampled* random walk (K²τ/3 for
m ≫ 1, 1.5× that at m = 1); the others are exact for sampled data (white angle, white rate, ramp)
or the usual asymptote (flicker's plateau).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError

__all__ = ["Term", "TERMS", "TERM_ALPHA", "TERM_NAMES", "REGISTRY", "design_matrix", "check_terms"]

_FLICKER = 2.0 * math.log(2.0) / math.pi


@dataclass(frozen=True)
class Term:
    """One noise term of the model.

    ``alpha``: its power-law noise type (α of S_y ∝ f^α), for the EDF of estimates it dominates;
    ``column(tau, m, tau0)``: its Allan variance per unit squared coefficient.
    """

    name: str
    long_name: str
    alpha: int
    column: Callable[[np.ndarray, np.ndarray, float], np.ndarray]


#: The IEEE-952 terms of the model by name (Q, N, B, K, R), each with its Allan form and units.
REGISTRY: dict[str, Term] = {
    t.name: t
    for t in (
        Term("Q", "quantization", 2, lambda tau, m, tau0: 3.0 / tau**2),
        Term("N", "angle random walk", 0, lambda tau, m, tau0: 1.0 / tau),
        Term("B", "bias instability", -1, lambda tau, m, tau0: np.full_like(tau, _FLICKER)),
        Term("K", "rate random walk", -2, lambda tau, m, tau0: tau0 * (2.0 * m**2 + 1.0) / (6.0 * m)),
        Term("R", "rate ramp", -2, lambda tau, m, tau0: tau**2 / 2.0),
    )
}

#: Terms of the model, in order.
TERMS = tuple(REGISTRY)
#: Power-law noise type (α of S_y ∝ f^α, in phase/angle terms) that each term is, for the EDF.
TERM_ALPHA = {t.name: t.alpha for t in REGISTRY.values()}
#: The terms' names in words.
TERM_NAMES = {t.name: t.long_name for t in REGISTRY.values()}


def design_matrix(tau: np.ndarray, m: np.ndarray, fs: float, terms: Iterable[str]) -> np.ndarray:
    """Columns of σ²(τ) per squared coefficient, one per term."""
    tau = np.asarray(tau, dtype=np.float64)
    m = np.asarray(m, dtype=np.float64)
    return np.column_stack([REGISTRY[t].column(tau, m, 1.0 / fs) for t in terms])


def check_terms(terms: object) -> tuple[str, ...]:
    """Distinct term names, in the model's order, or a ParameterError."""
    if isinstance(terms, str):
        terms = (terms,)
    try:
        given: tuple[str, ...] = tuple(terms)  # type: ignore[arg-type]
    except TypeError:
        raise ParameterError(f"terms must be a sequence of {TERMS}, got {terms!r}") from None
    bad = [t for t in given if t not in TERMS]
    if bad or not given or len(set(given)) != len(given):
        raise ParameterError(f"terms must be distinct names from {TERMS}, got {terms!r}")
    return tuple(t for t in TERMS if t in given)
