"""Reading sensor logs: CSV/TSV (optionally gzip), NumPy .npy/.npz, Parquet and ROS bags.

:func:`read_log` returns a :class:`Log` — the samples, the sampling rate, column names, unit, and
what was found about the timing (gaps, jitter).
"""

from ..errors import MissingDependencyError
from .reader import GAP_FACTOR, GAP_MODES, Gap, Log, read_log, sniff_format

__all__ = ["read_log", "Log", "Gap", "sniff_format", "MissingDependencyError", "GAP_MODES", "GAP_FACTOR"]
