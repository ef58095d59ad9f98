"""How good a forecast is: the posterior-variance ratio C, the small-error probability P, their grades.

Paper 004 eqs. 10–15 and Table 2; the conventions (``sd``, ``include_first``) are described in
:mod:`allanite.forecast`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import InputError
from ._series import as_series, check_sd

__all__ = ["C_GRADE_BOUNDS", "JOINT_GRADES", "Accuracy", "accuracy", "c_grade", "joint_grade"]

#: Paper 004 Table 2 as printed: grade 1 C < 0.35, grade 2 C < 0.5, grade 3 C < 0.65, grade 4 otherwise.
C_GRADE_BOUNDS = (0.35, 0.5, 0.65)

#: The common joint C/P labels, best first: (label, P must exceed, C must stay below).
JOINT_GRADES = (("good", 0.95, 0.35), ("qualified", 0.80, 0.50), ("barely", 0.70, 0.65))


def c_grade(C: float) -> int:
    """Paper 004 Table 2 grade of a posterior-variance ratio: 1 (C < 0.35), 2 (< 0.5), 3 (< 0.65), else 4."""
    if not np.isfinite(C):
        return 4
    for g, bound in enumerate(C_GRADE_BOUNDS, start=1):
        if C < bound:
            return g
    return 4


def joint_grade(C: float, P: float) -> str:
    """The common joint label: "good" (P > 0.95, C < 0.35), "qualified" (P > 0.80, C < 0.50),
    "barely" (P > 0.70, C < 0.65), else "fail"."""
    for label, p_min, c_max in JOINT_GRADES:
        if P > p_min and C < c_max:
            return label
    return "fail"


@dataclass(frozen=True)
class Accuracy:
    """Posterior-variance check of predictions against actual values (paper 004 eqs. 10–15).

    Attributes
    ----------
    C : float
        S2/S1, the residual SD over the data SD. For constant data (S1 at round-off level) C = 0 and
        P = 1 when S2 is at round-off level too, else C = inf and P = 0.
    P : float
        Small-error probability: share of residuals with |e − ē| < 0.6745·S1.
    c_grade : int
        Paper 004 Table 2 grade of C (1 best … 4).
    grade : str
        Joint C/P label ("good", "qualified", "barely", "fail").
    S1, S2 : float
        SD of the actual values and of the residuals.
    n : int
        Number of values counted.
    sd : str
        "population" or "sample".
    include_first : bool
        Whether the first value counted.
    """

    C: float
    P: float
    c_grade: int
    grade: str
    S1: float
    S2: float
    n: int
    sd: str
    include_first: bool


def accuracy(actual: Any, predicted: Any, *, sd: str = "population", include_first: bool = True) -> Accuracy:
    """C, P and grades of ``predicted`` against ``actual``.

    Parameters
    ----------
    actual, predicted : array_like
        Same length, at least 2 values (3 if ``include_first`` is False).
    sd : {"population", "sample"}
        Divide the sums of squares by n or by n − 1.
    include_first : bool
        Count the first pair. Set False for paper 004's rule (x⁰(1) left out).

    Returns
    -------
    Accuracy
    """
    ddof = check_sd(sd)
    x = as_series(actual, name="actual", min_len=2)
    p = as_series(predicted, name="predicted", min_len=2)
    if x.shape != p.shape:
        raise InputError(f"actual has {x.size} values but predicted has {p.size}")
    if not include_first:
        x, p = x[1:], p[1:]
    if x.size < 2 + ddof:
        raise InputError(f"{x.size} value(s) left to score; at least {2 + ddof} needed for sd={sd!r}")
    e = x - p
    S1 = float(np.std(x, ddof=ddof))
    S2 = float(np.std(e, ddof=ddof))
    # Constant data (S1 at round-off level): C is 0/0. Call a residual spread at round-off level a
    # perfect fit (C = 0, P = 1) and anything more an infinitely bad one (C = inf, P = 0).
    tol = 64 * np.finfo(np.float64).eps * max(float(np.max(np.abs(x))), float(np.max(np.abs(p))), 1e-300)
    if S1 > tol:
        C = S2 / S1
        P = float(np.mean(np.abs(e - e.mean()) < 0.6745 * S1))
    elif S2 <= tol:
        C, P = 0.0, 1.0
    else:
        C, P = math.inf, 0.0
    return Accuracy(C, P, c_grade(C), joint_grade(C, P), S1, S2, int(x.size), sd, bool(include_first))
