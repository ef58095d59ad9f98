"""``allantools.realtime``: OADEV, OHDEV and TDEV/MDEV of a stream of phase or frequency points,
updated as each point arrives, on allanite's Rust core (:class:`allanite._core.StreamingVariance`).

A. Dobrogowski and M. Kasznia, *Real-time assessment of Allan deviation and time deviation*, Proc.
EFTF/IFCS 2007: each new point closes one term per averaging factor, O(1) amortised per point and
factor. After N points ``dev`` equals the batch estimator (:func:`~allanite.compat.oadev`,
:func:`~allanite.compat.ohdev`, :func:`~allanite.compat.tdev`) on those N points, for every averaging
factor — also for those added automatically (``auto_afs=True``), which start with every term the
points already held close (allantools' classes miss the first term of an averaging factor added on
the way, for OADEV and TDEV). ``dev`` is 0 where a factor has no term yet, as in allantools.
"""

from __future__ import annotations

import numpy as np

from .. import _core
from .._validate import check_count, check_positive

__all__ = ["dev_realtime", "oadev_realtime", "ohdev_realtime", "tdev_realtime"]

#: averaging factors scheduled in auto mode (far beyond any stream a computer holds)
_AUTO_DECADES = 19


def _auto_schedule(pts_per_decade: int) -> list[int]:
    """allantools' automatic averaging factors after 1: round(10^k·10^(j/p)), j = 0 … p − 1, in order."""
    p = check_count(pts_per_decade, "pts_per_decade", 1)
    steps = np.logspace(0, 1, p + 1)[:-1]
    factors = [int(np.round(10.0**k * s)) for k in range(_AUTO_DECADES) for s in steps]
    return factors[1:]


class dev_realtime:
    """Common part of the real-time deviations: ``afs`` (averaging factors, τ = af·tau0), ``tau0`` (s);
    with ``auto_afs`` the factors 1, 2, 3, 6, 10, 18, … (``pts_per_decade`` per decade) are added as
    soon as the stream holds 2·af + 1 points."""

    _kind = "oavar"

    def __init__(self, afs=[1], tau0=1.0, auto_afs=False, pts_per_decade=4):  # noqa: B006 (allantools' signature)
        self.tau0 = check_positive(tau0, "tau0")
        self.auto_afs = bool(auto_afs)
        self.af_taus = np.logspace(0, 1, check_count(pts_per_decade, "pts_per_decade", 1) + 1)[:-1]
        start = [1] if self.auto_afs else [check_count(a, "af", 1) for a in afs]
        pending = _auto_schedule(pts_per_decade) if self.auto_afs else []
        self._stream = _core.StreamingVariance(self._kind, start, pending)
        self._last = 0.0

    @property
    def afs(self):
        """The averaging factors (an array in auto mode, as allantools)."""
        f = self._stream.factors()
        return np.array(f) if self.auto_afs else f

    @property
    def x(self):
        """The phase points received (a list, as allantools keeps them)."""
        return self._stream.phase().tolist()

    @property
    def dev(self):
        """The current deviation at each averaging factor (0 before its first term)."""
        return np.nan_to_num(self._deviations(self._stream.values()), nan=0.0)

    def _deviations(self, var: np.ndarray) -> np.ndarray:
        return np.sqrt(var) / self.tau0

    def add_phase(self, xnew):
        """Adds one phase point (seconds)."""
        self._stream.push(float(xnew))
        self._last = float(xnew)

    def add_phases(self, phases):
        """Adds phase points in order — the same as :meth:`add_phase` on each, in one call (an allanite
        addition)."""
        x = np.ascontiguousarray(phases, dtype=np.float64).ravel()
        try:
            self._stream.extend(x)
        finally:
            if len(self._stream):
                self._last = float(self._stream.phase()[-1])

    def add_frequency(self, f):
        """Adds one frequency point: the phase steps by ``f`` (the first call starts the phase at 0).
        As in allantools the step is not multiplied by tau0, so use tau0 = 1 or phase points."""
        if not len(self._stream):
            self.add_phase(0.0)
        self.add_phase(self._last + f)

    def update_af(self):
        """Kept for allantools' interface: automatic factors are added by the stream itself."""

    def add_af(self):
        """Kept for allantools' interface (subclass hook there); nothing to do."""

    def taus(self):
        """τ = af·tau0 of each averaging factor, in seconds."""
        return self.tau0 * np.array(self._stream.factors(), dtype=np.float64)

    def devs(self):
        """The current deviations (see :attr:`dev`)."""
        return self.dev


class oadev_realtime(dev_realtime):
    """Overlapping Allan deviation of a growing phase record, as ``allantools.realtime.oadev_realtime``.

    Examples
    --------
    The 10-point NBS14 record (NIST SP 1065 Table 31: OADEV 91.22945, 85.95287):

    >>> from allanite.compat import realtime
    >>> rt = realtime.oadev_realtime(afs=[1, 2], tau0=1.0)
    >>> for x in [0, 103.11111, 123.22222, 157.33333, 166.44444, 48.55555, -96.33333, -2.22222, 111.88889, 0]:
    ...     rt.add_phase(x)
    >>> rt.dev.round(5).tolist()
    [91.22945, 85.95287]
    """

    _kind = "oavar"


class ohdev_realtime(dev_realtime):
    """Overlapping Hadamard deviation of a growing phase record, as ``allantools.realtime.ohdev_realtime``."""

    _kind = "ohvar"


class tdev_realtime(dev_realtime):
    """Time deviation (seconds) of a growing phase record, and MDEV from it, as
    ``allantools.realtime.tdev_realtime``."""

    _kind = "tvar"

    def _deviations(self, var: np.ndarray) -> np.ndarray:
        return np.sqrt(var)

    def mdev(self):
        """The current modified Allan deviation, √3·TDEV/(af·tau0)."""
        return self.dev * np.sqrt(3.0) / (np.array(self._stream.factors(), dtype=np.float64) * self.tau0)
