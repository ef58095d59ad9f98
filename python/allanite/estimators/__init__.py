"""The estimators: one registry (:mod:`._registry`), filled by one module per family.

``allan`` (overlapping and classic Allan variance) and ``theo`` (Theo1, TheoBR, TheoH and the dynamic
TheoH) register their entries on import; ``confidence`` holds the equivalent degrees of freedom,
the noise identification and the χ² intervals; ``grid`` the τ grids. Nothing here builds result
objects — :mod:`allanite.analysis` does, above this package.
"""

from . import allan, deviations, taper, theo  # noqa: F401  (each registers its estimators / tapers)
from ._registry import Computed, Estimator, Taper, get, get_taper, names
from .grid import GRIDS, tau_grid

__all__ = ["Computed", "Estimator", "Taper", "get", "get_taper", "names", "tau_grid", "GRIDS"]
