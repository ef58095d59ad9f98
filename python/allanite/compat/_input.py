"""What every allantools-shaped estimator does first: read the samples as phase and rate, pick the
averaging factors from ``taus`` the way allantools does, and drop τ with too few terms.

Written from allantools' documented behaviour (no allantools code is used); the conventions are
listed in ``docs/compat.md``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..errors import InputError, ParameterError

Arrays = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]


class RateError(ParameterError, RuntimeError):
    """A sampling rate that is not a positive finite number (allantools raises ``RuntimeError`` for 0):
    both a :class:`~allanite.errors.ParameterError` and a ``RuntimeError``."""


class NoTauError(ParameterError, UserWarning):
    """No τ of the requested ones has more than one term (allantools raises ``UserWarning``): both a
    :class:`~allanite.errors.ParameterError` and a ``UserWarning``."""


def check_rate(rate) -> float:
    try:
        r = float(rate)
    except (TypeError, ValueError):
        raise RateError(f"rate must be a positive finite sampling rate in Hz, got {rate!r}") from None
    if not np.isfinite(r) or r <= 0:
        raise RateError(f"rate must be a positive finite sampling rate in Hz, got {rate!r}")
    return r


def check_data_type(data_type) -> str:
    if data_type not in ("phase", "freq"):
        raise ParameterError(f'data_type must be "phase" or "freq", got {data_type!r}')
    return data_type


def trimmed(a: np.ndarray) -> np.ndarray:
    """``a`` without its leading and trailing NaN (interior NaN kept)."""
    finite = np.flatnonzero(~np.isnan(a))
    return a[finite[0] : finite[-1] + 1] if finite.size else a[:0]


def integrated(freq: np.ndarray, rate: float) -> np.ndarray:
    """allantools' frequency → phase: trim NaN at the ends, remove the (NaN-ignoring) mean, integrate,
    start at 0: ``[0, cumsum(y − ȳ)/rate]`` (N + 1 points for N frequency samples)."""
    y = trimmed(np.asarray(freq, dtype=np.float64).ravel())
    if y.size == 0:
        return np.zeros(1)
    return np.concatenate(([0.0], np.cumsum(y - np.nanmean(y)) * (1.0 / rate)))


def refuse_nonfinite(a: np.ndarray) -> None:
    bad = np.flatnonzero(~np.isfinite(a))
    if bad.size:
        raise InputError(
            f"data[{int(bad[0])}] = {float(a[bad[0]])!r}: allanite.compat takes finite samples only "
            '(gradev() skips missing phase points; or use allanite.avar(..., gaps="skip"))'
        )


class Record:
    """One input as phase points (N of them) and rate samples (N − 1), per allantools' conversion."""

    def __init__(self, data, rate, data_type: str, *, finite: bool = True) -> None:
        self.rate = check_rate(rate)
        self.data_type = check_data_type(data_type)
        a = np.asarray(data, dtype=np.float64).ravel()
        if data_type == "freq":
            a = trimmed(a)
        if finite:
            refuse_nonfinite(a)
        if a.size < 2:
            raise InputError(f"data has {a.size} usable sample(s): at least 2 are needed")
        if data_type == "freq":
            self.freq = a
            self.y = a - np.nanmean(a)
            self.phase = np.concatenate(([0.0], np.cumsum(self.y) * (1.0 / self.rate)))
        else:
            self.phase = a
            self.y = np.diff(a) * self.rate
            self.freq = self.y
        self.n = self.phase.size


def tau_seconds(taus, length: int, rate: float) -> np.ndarray:
    """τ (seconds) before rounding to m, for ``taus`` on a record of ``length`` points."""
    if taus is None or (isinstance(taus, list) and not taus):
        taus = "octave"
    if isinstance(taus, str):
        if taus == "all":
            return np.linspace(1.0, length, length) / rate
        if taus == "octave":
            top = int(np.floor(np.log2(length)))
            return np.logspace(0, top, top + 1, base=2.0) / rate
        if taus == "log10":
            top = np.log10(length)
            return np.logspace(0, top, int(10 * top), base=10.0) / rate
        if taus == "decade":
            return np.array([f * 10.0**k / rate for k in range(int(np.floor(np.log10(length))) + 1) for f in (1, 2, 4)])
        raise ParameterError(f'taus must be None, "all", "octave", "decade", "log10" or τ in seconds, got {taus!r}')
    out = np.asarray(taus, dtype=np.float64).ravel()
    if not np.all(np.isfinite(out)):
        raise ParameterError(f"taus must be finite, got {out[~np.isfinite(out)][0]!r}")
    return out


def averaging_factors(taus, length: int, rate: float, *, top: float | None = None, even: bool = False) -> np.ndarray:
    """allantools' m selection: m = round(τ·rate) (half to even), 0 < m < length (≤ top), unique and
    sorted; even m only for Theo1. Float array, as allantools' ``tau_generator`` returns it."""
    m = np.round(tau_seconds(taus, length, rate) * rate)
    keep = (m > 0) & (m < length)
    if top is not None:
        keep &= m <= top
    m = np.unique(m[keep])
    if even:
        m = m[m % 2 == 0]
    return m


def finish(name: str, ms: np.ndarray, ns: np.ndarray, rate: float, value_fn: Callable[[list[int]], np.ndarray]):
    """Drop τ with ns ≤ 1 (allantools' rule), compute the deviations of the rest: (taus, devs, ns)."""
    keep = ns > 1
    ms, ns = ms[keep], ns[keep]
    if ms.size == 0:
        raise NoTauError(f"{name}: no τ of the requested ones has more than one term for this record")
    devs = np.asarray(value_fn([int(m) for m in ms]), dtype=np.float64)
    return ms / rate, devs, ns.astype(np.float64)


def with_errs(t: np.ndarray, d: np.ndarray, n: np.ndarray) -> Arrays:
    """(taus, devs, devs/√ns, ns): allantools' "error" column."""
    return t, d, d / np.sqrt(n), n
