"""χ² confidence intervals and SP 1065's simple EDF, shared by :mod:`allanite.compat.ci` and
``gradev`` (which sits below ``ci`` in the import order)."""

from __future__ import annotations

import math

import numpy as np

from ..errors import ParameterError
from ..estimators.confidence import chi2_interval, edf_sp1065

#: erf(1/√2) = 0.682689…, the one-sigma confidence allantools and Stable32 use
ONE_SIGMA_CI = math.erf(1.0 / math.sqrt(2.0))


def confidence_interval(dev, edf, ci=ONE_SIGMA_CI):
    """χ² confidence interval (dev_min, dev_max) of a deviation ``dev`` with ``edf`` degrees of
    freedom, NIST SP 1065 eq. 45: ``dev·√(edf/χ²(1 − p/2, edf))``, ``dev·√(edf/χ²(p/2, edf))`` with
    p = 1 − ci. ``ci`` and 1 − ci give the same interval, as in allantools.

    Examples
    --------
    >>> from allanite.compat import confidence_interval
    >>> lo, hi = confidence_interval(1.0, 10.0, 0.9)
    >>> round(float(lo), 4), round(float(hi), 4)
    (0.7391, 1.5931)
    """
    c = check_ci(ci)
    lo, hi = chi2_interval(np.square(dev), edf, max(c, 1.0 - c))
    return np.sqrt(lo), np.sqrt(hi)


def check_ci(ci) -> float:
    c = float(ci)
    if not 0.0 < c < 1.0:
        raise ParameterError(f"ci must be a probability in (0, 1), got {ci!r}")
    return c


def edf_simple(N, m, alpha):
    """Equivalent degrees of freedom of the overlapping ADEV by the simple formulas of NIST SP 1065
    Table 5 (Howe, Allan & Barnes 1981), for α = 2, 1, 0, −1, −2 (the exponent of S_y ∝ f^α); any
    other ``alpha`` (also None) gives N − 1. ``N`` phase points, τ = m·τ0.

    allantools writes the flicker-FM formula at m = 1 as 2(N − 2)/(2.3N − 4.9); SP 1065 has
    2(N − 2)²/(2.3N − 4.9), which this function uses.

    Examples
    --------
    >>> from allanite.compat import edf_simple
    >>> round(float(edf_simple(1001, 100, 0)), 2)
    13.0
    """
    if alpha is None or alpha not in (2, 1, 0, -1, -2):
        return float(N) - 1.0
    return edf_sp1065(int(alpha), m, N)
