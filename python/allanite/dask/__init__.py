"""allanite on Dask: records larger than memory and fleets of logs (``pip install 'allanite[dask]'``).

:func:`davar` and :func:`avar` take a ``dask.array`` (a memory-mapped .npy, zarr, HDF5, …) and give the
single-machine numbers; :func:`batch` writes one report per log of a fleet, as Dask tasks, and a fleet
summary. ``import allanite`` never imports this package (nor dask).
"""

from .arrays import avar, davar
from .fleet import FleetResult, batch

__all__ = ["avar", "davar", "batch", "FleetResult"]
