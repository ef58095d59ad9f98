"""allanite on Dask: records larger than memory and fleets of logs (``pip install 'allanite[dask]'``).

:func:`davar`, :func:`avar` and :func:`wavelet_split` take a ``dask.array`` (a .npy on disk through
:func:`from_npy`, zarr, HDF5, …) and give the single-machine numbers; :func:`batch` writes one report
per log of a fleet, as Dask tasks, and a fleet summary. ``import allanite`` never imports this package (nor dask).
"""

from .arrays import avar, davar, from_npy, wavelet_split
from .fleet import FleetResult, batch

__all__ = ["avar", "davar", "wavelet_split", "from_npy", "batch", "FleetResult"]
