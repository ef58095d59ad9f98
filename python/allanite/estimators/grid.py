"""τ grids: which averaging times to evaluate.

Every τ is an integer multiple of the sampling interval, τ = m/fs. Named grids limit themselves to
what the estimator can compute for the record or window they are built for; explicitly given τ are
rounded to the nearest m and must then be valid — they are never silently replaced.
"""

from __future__ import annotations

import math

import numpy as np

from .._validate import check_count, check_fs, check_real, resolve_max_memory
from ..errors import MemoryBudgetError, ParameterError

__all__ = ["tau_grid", "GRIDS", "resolve_taus", "max_m", "m_grid"]

#: Names accepted by :func:`tau_grid` and by the ``taus=`` argument of the estimators.
GRIDS = ("all", "octave", "decade", "exp")

#: Paper 000 §4.2 keeps at least 9 clusters at the largest τ (≈ 25 % estimate error).
EXP_MIN_CLUSTERS = 9
#: Sample counts beyond this (4.6e18) are no record: m and term counts must fit in int64.
MAX_SAMPLES = 2**62
#: Paper 000's example uses 100 points.
EXP_DEFAULT_POINTS = 100


def max_m(n: int) -> int:
    """Largest averaging factor the Allan estimators accept for ``n`` rate samples (N − 2m ≥ 1
    angle differences, at least two clusters): ``n // 2``."""
    return int(n) // 2


def _check_budget(count: int, kind: str, n: int) -> None:
    """Refuse a grid whose m array alone would exceed the memory budget, before allocating it. Grids
    up to 64 MiB (8 million τ) are never refused: the outputs they size are budgeted where they are made."""
    nbytes = 8 * int(count)
    if nbytes <= 64 * 2**20:
        return
    budget = resolve_max_memory(None)
    if nbytes > budget:
        raise MemoryBudgetError(
            f"the {kind!r} τ grid for {n} samples has {count} τ ({nbytes / 2**30:.3g} GiB as int64), over the "
            f"memory budget of {budget / 2**30:.3g} GiB (ALLANITE_MAX_MEMORY): "
            + ("use a larger growth or fewer points" if kind == "exp" else "use the 'exp', 'octave' or 'decade' grid")
            + ", or m_max"
        )


def m_grid(kind: str, n: int, *, growth=None, points=None, tau_min=None, fs=1.0, m_max=None) -> np.ndarray:
    """Averaging factors m of a named grid on ``n`` samples (see :func:`tau_grid`)."""
    limit = max_m(n)
    if limit < 1:
        raise ParameterError(f"a record or window of {n} samples is too short for any τ: at least 2 samples are needed")
    if m_max is not None:
        m_max = check_count(m_max, "m_max", 1)
        if m_max > limit:
            raise ParameterError(f"m_max = {m_max} exceeds {limit}, the largest m for {n} samples")
        top = m_max
    elif kind == "exp":
        top = max(1, int(n) // EXP_MIN_CLUSTERS)
    else:
        top = limit
    if kind != "exp" and (growth is not None or points is not None or tau_min is not None):
        raise ParameterError(f"growth, points and tau_min apply to the 'exp' grid only, not {kind!r}")
    if kind == "all":
        _check_budget(top, kind, n)
        return np.arange(1, top + 1, dtype=np.int64)
    if kind == "octave":
        return 2 ** np.arange(0, int(math.floor(math.log2(top))) + 1, dtype=np.int64)
    if kind == "decade":
        out: list[int] = []
        dec = 1
        while dec <= top:
            out.extend(v for v in (dec, 2 * dec, 4 * dec) if v <= top)
            dec *= 10
        return np.asarray(out, dtype=np.int64)
    if kind == "exp":
        m0 = 1
        if tau_min is not None:
            tmin = check_real(tau_min, "tau_min", "a positive finite number of seconds")
            m0 = int(math.floor(tmin * fs + 0.5)) if 0 < tmin * fs < 2.0**62 else 0
            if m0 < 1 or m0 > top:
                raise ParameterError(
                    f"tau_min = {tmin:g} s maps to m = {m0}; allowed is 1 ≤ m ≤ {top} (τ from "
                    f"{1 / fs:g} s to {top / fs:g} s)"
                )
        if growth is not None and points is not None:
            raise ParameterError("give either growth or points for the 'exp' grid, not both")
        if growth is None:
            points = EXP_DEFAULT_POINTS if points is None else check_count(points, "points", 2)
            growth = (top / m0) ** (1.0 / (points - 1)) if top > m0 else 2.0
        else:
            growth = check_real(growth, "growth", "a finite factor > 1")
            if growth <= 1.0:
                raise ParameterError(f"growth must be a finite factor > 1, got {growth:g}")
        # τ(i) = τ_con·τ_g^(i−1) (paper 000 §4.2), rounded to m, duplicates dropped. Points below
        # 1/(g − 1) are less than one sample from the next, so every m up to m* = ⌊1/(g − 1)⌋ appears:
        # take those directly rather than generating (possibly billions of) duplicates. (Not ⌈1/(g − 1)⌉:
        # g = 1.23828125 steps from 4.4 to 5.5, rounding to 4 and 6, and m = 5 is not on the grid.)
        # The grid ends at its last point ≤ top, which may round below top: the dense part stops there too
        # (n = 20, m_max = 3, g = 1.25 ends at round(1.25⁴) = 2, not 3).
        count = int(math.floor(math.log(top / m0) / math.log(growth) + 1e-9)) + 1
        last = int(math.floor(m0 * growth ** (count - 1) + 0.5))
        m_star = min(top, last, max(m0, int(math.floor(1.0 / (growth - 1.0))) if growth - 1.0 > 1.0 / top else top))
        _check_budget(m_star - m0 + 1, kind, n)
        dense = np.arange(m0, m_star + 1, dtype=np.int64)
        i0 = max(0, int(math.floor(math.log(m_star / m0) / math.log(growth))))
        raw = np.floor(m0 * growth ** np.arange(i0, max(i0, count)) + 0.5).astype(np.int64)
        raw = raw[(raw > m_star) & (raw <= top)]
        return np.unique(np.concatenate([dense, raw]))
    raise ParameterError(f"unknown τ grid {kind!r}; allowed: {', '.join(map(repr, GRIDS))} or an array of τ in s")


def tau_grid(
    n: int,
    fs: float,
    kind: str = "exp",
    *,
    growth: float | None = None,
    points: int | None = None,
    tau_min: float | None = None,
    m_max: int | None = None,
) -> np.ndarray:
    """Averaging times (s) of a named grid for a record or window of ``n`` rate samples.

    Parameters
    ----------
    n : int
        Number of rate (or increment) samples the estimator will see: the record length for
        :func:`allanite.avar`, the window length for :func:`allanite.davar`.
    fs : float
        Sampling rate in Hz; τ = m / fs.
    kind : {"exp", "all", "octave", "decade"}
        ``"all"``: every m from 1 to ``n // 2``. ``"octave"``: m = 1, 2, 4, … ≤ ``n // 2``.
        ``"decade"``: m = 1, 2, 4, 10, 20, 40, … ≤ ``n // 2`` (Stable32's decade grid).
        ``"exp"``: paper 000 §4.2's exponential grid m(i) = m0·g^(i−1), rounded, duplicates removed,
        up to ``n // 9`` so that the largest τ keeps at least 9 clusters (about 25 % error).
    growth, points : float, int, optional
        For ``"exp"``: the growth factor g, or the number of points before de-duplication
        (default 100, which gives g = (m_max/m0)^(1/99)). Not both.
    tau_min : float, optional
        For ``"exp"``: first τ in seconds (default one sample).
    m_max : int, optional
        Upper bound on m instead of the grid's default (at most ``n // 2``).

    Returns
    -------
    numpy.ndarray
        Strictly increasing τ in seconds, exactly m / fs.

    Examples
    --------
    >>> import allanite
    >>> allanite.tau_grid(1000, 1.0, "octave")
    array([  1.,   2.,   4.,   8.,  16.,  32.,  64., 128., 256.])
    >>> allanite.tau_grid(1000, 10.0, "decade")
    array([ 0.1,  0.2,  0.4,  1. ,  2. ,  4. , 10. , 20. , 40. ])
    >>> taus = allanite.tau_grid(10_000, 1.0, "exp")  # paper 000's example: 100 points, g = 1.073
    >>> len(taus), float(taus[-1])                     # 24 duplicates at small m were dropped
    (76, 1111.0)
    """
    fs = check_fs(fs)
    n = check_count(n, "n", 1, MAX_SAMPLES)
    if not isinstance(kind, str):
        raise ParameterError(f"kind must be one of {GRIDS}, got {kind!r}")
    return m_grid(kind, n, growth=growth, points=points, tau_min=tau_min, fs=fs, m_max=m_max) / fs


def resolve_taus(taus, n: int, fs: float) -> np.ndarray:
    """The averaging factors m for ``taus`` (a grid name or τ in seconds) on ``n`` samples.

    Explicit τ map to m = round(τ·fs); each must give 1 ≤ m ≤ n // 2 and the m must be strictly
    increasing — otherwise a :class:`ParameterError` says which τ and why.
    """
    if isinstance(taus, str):
        return m_grid(taus, n, fs=fs)
    if taus is None:
        raise ParameterError(f"taus must be a grid name ({', '.join(GRIDS)}) or a sequence of τ in seconds, got None")
    try:
        arr = np.asarray(taus, dtype=np.float64)
    except (TypeError, ValueError):
        raise ParameterError(
            f"taus must be a grid name ({', '.join(GRIDS)}) or a sequence of τ in seconds, got {taus!r}"
        ) from None
    arr = np.atleast_1d(arr)
    if arr.ndim != 1 or arr.size == 0:
        raise ParameterError(f"taus must be a non-empty 1-D sequence of τ in seconds, got shape {arr.shape}")
    bad = np.flatnonzero(~np.isfinite(arr) | (arr <= 0))
    if bad.size:
        i = int(bad[0])
        raise ParameterError(f"taus[{i}] = {float(arr[i])!r} s: every τ must be a positive finite number of seconds")
    limit = max_m(n)
    scaled = arr * fs
    too_long = np.flatnonzero(~(scaled < limit + 0.5))
    if too_long.size:
        i = int(too_long[0])
        m_i = f"m = {int(math.floor(scaled[i] + 0.5))}" if scaled[i] < 2.0**62 else f"m ≫ {limit}"
        raise ParameterError(
            f"taus[{i}] = {arr[i]:g} s ({m_i}) is too long for {n} samples: the largest τ is "
            f"{limit / fs:g} s (m = {limit})"
        )
    ms = np.floor(scaled + 0.5).astype(np.int64)
    for i, (t, m) in enumerate(zip(arr, ms)):
        if m < 1:
            raise ParameterError(
                f"taus[{i}] = {t:g} s is shorter than one sample (1/fs = {1 / fs:g} s) and cannot be honoured"
            )
        if m > limit:
            raise ParameterError(
                f"taus[{i}] = {t:g} s (m = {m}) is too long for {n} samples: the largest τ is "
                f"{limit / fs:g} s (m = {limit})"
            )
    dup = np.flatnonzero(np.diff(ms) <= 0)
    if dup.size:
        i = int(dup[0])
        raise ParameterError(
            f"taus[{i}] = {arr[i]:g} s and taus[{i + 1}] = {arr[i + 1]:g} s map to m = {ms[i]} and {ms[i + 1]}; "
            f"τ must map to strictly increasing m = round(τ·fs) (try np.unique(np.round(taus * fs)) / fs)"
        )
    return ms
