"""Noise identification: the dominant power-law noise type α per τ, by Stable32's method.

The lag-1 autocorrelation method of Riley & Greenhall (EFTF 2004) where at least
:data:`ACF_MIN_POINTS` τ-intervals remain, Barnes' B1 ratio and R(n) = MVAR/AVAR below, and — as
Stable32 — no identification below :data:`ID_MIN_POINTS` intervals (there the nearest shorter τ's α).
:mod:`allanite.estimators.confidence` turns the α into equivalent degrees of freedom and intervals;
``docs/confidence.md`` compares the result with Stable32's tables row by row.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from .._validate import check_choice, check_input
from ..errors import ParameterError
from ._long_id import LONG_SAMPLES, LongRate

__all__ = ["ACF_MIN_POINTS", "ID_MIN_POINTS", "FALLBACKS", "INPUTS", "ESTIMATORS", "identify_alpha"]

#: Stable32 switches from the lag-1 ACF to the B1 ratio below this many points at a given τ.
ACF_MIN_POINTS = 30

#: Fewest τ-intervals (⌊samples/m⌋) at which Stable32 identifies the noise type from that τ's own
#: samples, per estimator; at longer τ it prints the α of the previous τ. Read off its tables (all 34
#: ADEV/OADEV tables of the shared data: docs/confidence.md): OADEV identifies at 8 intervals and
#: carries over at 7, ADEV identifies at 10 and carries over at 9.
ID_MIN_POINTS = {"oavar": 8, "avar": 10}

#: A rise of α that lasts to the longest τ stands (``fallback="conservative"``) only if its first τ holds this
#: many τ-intervals: two lag-1 ACF readings (≥ 30 intervals each) an octave apart. On a white series
#: the ACF's r1 scatters by ≈ 1/√n, so it reads a chance rise (r1 < −1/3: δ < −0.25) ≈ 5 % of the time at
#: 30 intervals and < 1 % from 60 (see :func:`identify_alpha`, ``docs/confidence.md``).
END_RISE_MIN_POINTS = 2 * ACF_MIN_POINTS

#: What happens at τ with too few intervals for their own identification (see :func:`identify_alpha`).
FALLBACKS = ("prudent", "previous", "none", "conservative")

#: Kinds of input samples: angle (phase) points, rate (frequency) samples, or angle increments.
INPUTS = ("angle", "rate", "increment")

#: The Allan estimators whose number of terms sets the B1 reference N.
ESTIMATORS = ("oavar", "avar")


def _lag1_acf(z: np.ndarray) -> float:
    """Lag-1 autocorrelation with Stable32's (n − 1)/n factor (Riley, Handbook §5.5.3)."""
    z = z - z.mean()
    # einsum, not np.dot: OpenBLAS's threaded dot took 8.8 ms of CPU for 2^20 elements on two busy cores,
    # einsum 0.8 ms (the same sum to rounding)
    den = float(np.einsum("i,i->", z, z))
    if den == 0.0:
        return 0.0
    return float(np.einsum("i,i->", z[:-1], z[1:])) / den * (z.size - 1) / z.size


def _acf_alpha(z: np.ndarray, phase: bool, dmax: int = 2) -> float:
    """Riley & Greenhall's lag-1 ACF algorithm on data already decimated/averaged to τ: difference
    until δ = r1/(1 + r1) < 0.25 (at most dmax times); p = −2(δ + d); α = p + 2 for phase data,
    p for frequency data. Returns the fractional estimate."""
    d = 0
    while True:
        r1 = _lag1_acf(z)
        delta = r1 / (1.0 + r1) if r1 > -1.0 else -1e9  # r1 → −1: as white as it gets
        if delta < 0.25 or d >= dmax or z.size < 4:
            p = -2.0 * (delta + d)
            return p + 2.0 if phase else p
        z = np.diff(z)
        d += 1


def _b1_expected(N: float, mu: int) -> float:
    """Barnes' B1(N, r = 1, μ): expected N-sample over 2-sample variance for the phase exponent μ."""
    if mu == 0:
        return N * math.log(N) / (2.0 * (N - 1.0) * math.log(2.0))
    return N * (1.0 - N**mu) / (2.0 * (N - 1.0) * (1.0 - 2.0**mu))


def _b1_rn_alpha(x: np.ndarray, y: np.ndarray, m: int, n_ref: int, long: LongRate | None = None) -> int:
    """B1 ratio, then R(n) = MVAR/AVAR to split WPM from FPM (Howe, Beard, Greenhall & Riley 2000).
    ``long``: a long rate record read in chunks (``x`` and ``y`` unused)."""
    k = (y.size if long is None else long.n) // m
    if k < 2:
        return 0
    ya = y[: k * m].reshape(k, m).mean(axis=1) if long is None else long.all_means(m)
    avar_classic = 0.5 * float(np.mean(np.diff(ya) ** 2))
    if avar_classic == 0.0:
        return 0
    b1 = float(np.var(ya, ddof=1)) / avar_classic
    # N at which the expected B1 is evaluated: the number of averages (Barnes), or what the caller
    # chose (Stable32: the estimator's number of terms).
    N = max(int(n_ref), 2)
    mus = (1, 0, -1, -2)  # RWFM, FFM, WFM, WPM/FPM
    mu = -2
    for hi, lo in zip(mus[:-1], mus[1:]):
        if b1 > math.sqrt(_b1_expected(N, hi) * _b1_expected(N, lo)):
            mu = hi
            break
    if mu != -2:
        return {1: -2, 0: -1, -1: 0}[mu]
    n = x.size if long is None else long.n + 1
    if n - 3 * m + 1 < 1:
        return 1  # R(n) needs 3m + 1 points; FPM is the conservative (smaller-ν) choice
    rn = _rn(x, m) if long is None else long.rn(m)
    if rn is None:
        return 2
    rn_wpm = 1.0 / m
    rn_fpm = 3.37 / (1.04 + 3.0 * math.log(math.pi * m))  # f_h = 1/(2τ0)
    return 1 if rn > math.sqrt(rn_wpm * rn_fpm) else 2


def _rn(x: np.ndarray, m: int) -> float | None:
    """R(n) = MVAR/AVAR at m from the phase ``x``; None where the AVAR is 0."""
    n = x.size
    dd = x[2 * m :] - 2.0 * x[m : n - m] + x[: n - 2 * m]
    oav = float(np.mean(dd * dd))
    if oav == 0.0:
        return None
    c = np.concatenate(([0.0], np.cumsum(dd)))
    mv = float(np.mean(((c[m:] - c[:-m]) / m) ** 2))
    return mv / oav


def identify_alpha(x, m, *, input="angle", estimator="oavar", method="auto", b1_n="terms", fallback="prudent"):
    """Dominant power-law noise type α at each averaging factor, by Stable32's method.

    At each m the data are brought to τ = m·τ0 — phase (angle) data decimated (every m-th point),
    rate (frequency) data averaged in non-overlapping blocks of m — and then:

    * ``"acf"``: the lag-1 autocorrelation method of Riley & Greenhall (EFTF 2004): difference the
      series d times (d ≤ 2) until δ = r1/(1 + r1) < 0.25; α = −2(δ + d) (+2 for phase data),
      rounded. Reliable from about 30 points.
    * ``"b1"``: the B1 ratio (sample variance of the m-averages over their Allan variance) against
      Barnes' expectation for each noise type, and where that says WPM-or-FPM, the ratio
      R(n) = MVAR/AVAR against 1/m (WPM) and 3.37/(1.04 + 3 ln(πm)) (FPM).
    * ``"auto"`` (default, Stable32's rule): ACF where the record holds at least 30 intervals of
      length τ (⌊M/m⌋ ≥ 30 for M samples), B1/R(n) below.

    Where too few samples remain — fewer than 8 τ-intervals for ``"oavar"``, 10 for ``"avar"``
    (:data:`ID_MIN_POINTS`) — α is not identified from that τ's samples but taken from the nearest
    shorter τ of ``m`` (``fallback="previous"``): Stable32's rule, which its Alpha columns follow
    row by row (``docs/confidence.md``). The default, ``fallback="prudent"``, adds one more rule on
    octave-spaced (or sparser) grids: α may rise above both neighbours' only on ≥ 30 τ-intervals
    (:data:`ACF_MIN_POINTS`) at every τ of the rise; a rise read on fewer falls back to the α before it.

    Parameters
    ----------
    x : array_like, 1-D
        Samples of one axis: cumulative angle (phase) points, or rate / increment samples, per
        ``input``. Offsets and scale do not matter.
    m : int or array_like of int
        Averaging factors (τ = m/fs).
    input : {"angle", "rate", "increment"}
        What ``x`` holds. ``"angle"`` follows Stable32's phase-data path (decimation), ``"rate"`` and
        ``"increment"`` its frequency-data path (block averages).
    estimator : {"oavar", "avar"}
        The estimator the α is for: its number of terms (``b1_n="terms"``) and its minimum of
        τ-intervals (``fallback``) depend on it.
    method : {"auto", "acf", "b1"}
    b1_n : {"terms", "averages"}
        The N at which Barnes' expected B1(N, μ) is evaluated. ``"terms"`` (default, Stable32's):
        the estimator's number of terms, N − 2m (overlapping) or ⌊(N − 1)/m⌋ − 1 (classic), the
        "#" column — with ``fallback="previous"`` it reproduces every Alpha of the Stable32
        ADEV/OADEV octave and decade tables in ``docs/confidence.md``. ``"averages"``: the number
        of τ-averages the measured ratio is made of — Barnes' definition. For the overlapping
        estimator the number of terms is far larger than the number of averages, so with
        ``"terms"`` the RWFM expectation (N/2) is out of reach and random-walk noise comes out as
        FFM: in simulation it identifies RWFM 0 % and FFM 24 % of the time at 7–26 averages,
        against 67 % and 59 % for ``"averages"``. Prefer ``"averages"`` to tell rate random walk
        from bias instability at long τ of an overlapping curve.
    fallback : {"prudent", "previous", "none", "conservative"}
        ``"previous"``: where too few samples remain (see above), α is that of the
        nearest shorter τ of ``m`` identified on its own samples; if ``m`` holds none, α is
        identified at the longest averaging factor that still has enough τ-intervals.
        ``"prudent"`` (default): the same, and on a grid whose neighbouring m are ≥ 2× apart a *peak*
        — consecutive τ whose α is above the α on both sides — stands only if each of its τ was
        identified on ≥ 30 τ-intervals; otherwise it takes the α before it. A sum of power-law noises
        has α fall as τ grows, and a higher α means a larger ν: a chance rise read on few points would
        give an interval too narrow where data are scarce (e.g. 2¹⁷ white-rate samples read as flicker
        phase at m = 4096 and 8192, ν 94 → 511). On the Stable32 tables of ``docs/confidence.md`` it
        changes no α. ``"conservative"``: ``"prudent"``, and a rise of α that lasts to the longest τ
        stands only if its first τ holds ≥ 60 τ-intervals (:data:`END_RISE_MIN_POINTS`, two lag-1 ACF
        readings an octave apart; Riley & Greenhall's ACF method wants ≥ 30). Otherwise it takes the α
        before it — the smaller ν, the wider interval. E.g. 10⁶ white-rate samples
        (``default_rng(3)``, octave grid) read as flicker phase from 30 intervals on: ν 720 → 44 at
        the first of those τ. In simulation (``benches/results/ci_few_points.md``) it brings the
        68 % coverage at 4 and 8 τ-intervals of white, flicker and random-walk FM from 50–68 % to
        63–80 % (62–74 % with the true α given);
        it departs from Stable32's Alpha column on 15 of its 2774 rows (OCXO octave, Sr87 decade:
        rises at 4–19 intervals), so it is not the default. ``"none"``: every τ on its own samples,
        however few (with 2 averages B1 is exactly 1, "white FM", whatever the noise).

    Returns
    -------
    int or ndarray of int
        α ∈ {2, 1, 0, −1, −2} per m (values beyond are clipped to that range).

    Notes
    -----
    The lag-1 ACF is exact on average for the white and random-walk types, but on averaged
    flicker noise its fractional estimate drifts towards the neighbouring type (≈ ±1.45 instead
    of ±1 from m ≈ 16 on), so flicker is sometimes reported as its neighbour at long τ — in
    Stable32 as here. With few averages (the B1 branch) any identification is uncertain: in
    simulation 55–80 % of the calls are right.

    Examples
    --------
    >>> import numpy as np
    >>> from allanite.estimators.confidence import identify_alpha
    >>> rng = np.random.default_rng(0)
    >>> identify_alpha(rng.normal(size=10_000), [1, 10, 100], input="rate")      # white rate
    array([0, 0, 0])
    >>> identify_alpha(np.cumsum(rng.normal(size=10_000)), [1, 10, 100], input="rate")  # rate random walk
    array([-2, -2, -2])
    """
    input = check_input(input)
    check_choice(estimator, "estimator", ESTIMATORS)
    check_choice(method, "method", ("auto", "acf", "b1"))
    check_choice(b1_n, "b1_n", ("averages", "terms"))
    check_choice(fallback, "fallback", FALLBACKS)
    arr = np.asarray(x)
    if arr.ndim != 1 or arr.dtype.kind not in "iuf":
        raise ParameterError(
            f"x must be a 1-D array of real numbers (one axis), got shape {arr.shape} dtype {arr.dtype}"
        )
    arr = np.asarray(arr, dtype=np.float64)  # no copy of a float64 record: nothing below writes into it
    # min and max are NaN if any sample is, ±inf if any is: no per-sample temporary
    if arr.size and not (np.isfinite(arr.min()) and np.isfinite(arr.max())):
        raise ParameterError("x contains NaN or infinite values; noise identification needs finite samples")
    phase, rate, long = _phase_and_rate(arr, input)
    n_phase = phase.size if long is None else arr.size + 1
    m_arr = _checked_m(m, n_phase)
    each = functools.partial(
        _identify_each,
        phase,
        rate,
        phase_input=input == "angle",
        estimator=estimator,
        method=method,
        b1_n=b1_n,
        long=long,
    )
    own = each(m_arr)
    out = own
    if fallback != "none":
        out = _fall_back(own, m_arr, n_phase - 1, ID_MIN_POINTS[estimator], each)
    if fallback in ("prudent", "conservative"):
        out = _level_weak_peaks(out, m_arr, (n_phase - 1) // m_arr, end_rise=fallback == "conservative")
    return int(out[0]) if np.ndim(m) == 0 else out


def _phase_and_rate(arr: np.ndarray, input: str):
    """The phase (from 0) and the centred rate of a checked record, or for a rate record over LONG_SAMPLES
    empty arrays and a :class:`LongRate` that reads it chunk by chunk (no copy of the record)."""
    long = None
    if input == "angle":
        if arr.size < 3:
            raise ParameterError(f"x has {arr.size} angle points; at least 3 are needed")
        phase = arr - arr[0]
        rate = np.diff(arr)
    else:
        if arr.size < 2:
            raise ParameterError(f"x has {arr.size} samples; at least 2 are needed")
        if arr.size > LONG_SAMPLES:  # chunk by chunk: no copy of the record (estimators/_long_id.py)
            long = LongRate(arr, arr.mean())
            rate = phase = arr[:0]
        else:
            rate = arr - arr.mean()
            phase = np.concatenate(([0.0], np.cumsum(rate)))
    return phase, rate, long


def _checked_m(m, n_phase: int) -> np.ndarray:
    """``m`` as int64 averaging factors, each ≥ 1 and at most half the record's samples."""
    m_arr = np.atleast_1d(np.asarray(m))
    if m_arr.dtype.kind not in "iuf" or np.any(m_arr % 1 != 0) or np.any(m_arr < 1):
        raise ParameterError(f"m must be integer averaging factors ≥ 1, got {m!r}")
    m_arr = m_arr.astype(np.int64)
    too_big = m_arr > (n_phase - 1) // 2
    if too_big.any():
        raise ParameterError(
            f"m = {int(m_arr[too_big][0])} is too large for {n_phase - 1} samples (largest: {(n_phase - 1) // 2})"
        )
    return m_arr


def _level_weak_peaks(alpha: np.ndarray, m: np.ndarray, points: np.ndarray, end_rise: bool = False) -> np.ndarray:
    """A peak — a run of consecutive τ (in order of m) whose α is above the α on both sides of it —
    stands only if every τ of the run was identified on at least :data:`ACF_MIN_POINTS` τ-intervals;
    otherwise the run takes the α before it. A sum of power-law noises has its α fall, never rise, as τ
    grows; a rise that falls back is a chance reading of few points, and a higher α gives a larger ν —
    an interval too narrow exactly where the data are scarce. Dips (a lower α, a wider interval) stay.

    Only on a grid whose neighbouring m are at least a factor 2 apart (octave, decade): on a denser
    grid neighbouring τ re-read nearly the same averages, so a neighbour is no second reading.

    ``end_rise`` (``fallback="conservative"``): a run that rises above the α before it and lasts to the
    longest τ is levelled too, unless its first τ holds ≥ :data:`END_RISE_MIN_POINTS` τ-intervals — on
    any grid: the rule asks for enough points at one τ, not for a second reading at its neighbour."""
    steps = np.diff(np.unique(m).astype(np.float64))
    sparse = not (steps.size and np.min(steps / np.unique(m)[:-1]) < 0.99)
    if not sparse and not end_rise:
        return alpha
    order = np.argsort(m, kind="stable")
    a = alpha[order].copy()
    weak = points[order] < ACF_MIN_POINTS
    i = 1
    while i < a.size:
        j = i
        while j + 1 < a.size and a[j + 1] == a[i]:
            j += 1
        # run i..j; a peak needs a neighbour on both sides, both below it; a rise to the end of the grid
        # needs its first τ read on ≥ END_RISE_MIN_POINTS (a second ACF reading an octave on)
        peak = sparse and j + 1 < a.size and a[i] > a[i - 1] and a[i] > a[j + 1] and weak[i : j + 1].any()
        weak_end = end_rise and j + 1 == a.size and a[i] > a[i - 1] and points[order][i] < END_RISE_MIN_POINTS
        if peak or weak_end:
            a[i : j + 1] = a[i - 1]
            i = max(1, i - 1)  # the run joined its left neighbour's: look at that run again
            while i > 1 and a[i - 1] == a[i]:
                i -= 1
            continue
        i = j + 1
    out = np.empty_like(alpha)
    out[order] = a
    return out


def _fall_back(own: np.ndarray, m: np.ndarray, n_intervals: int, min_points: int, identify) -> np.ndarray:
    """Stable32's rule for τ with too few samples (see :func:`identify_alpha`): every τ with fewer than
    ``min_points`` τ-intervals takes the α of the nearest shorter τ of ``m`` identified on its own; with
    none, the α identified at the longest averaging factor that still has ``min_points`` intervals."""
    needs = n_intervals // m < min_points
    if not needs.any():
        return own
    out = own.copy()
    donors = np.flatnonzero(~needs)
    if donors.size:
        # m need not be sorted: for each τ, the donor with the largest m below it
        order = donors[np.argsort(m[donors], kind="stable")]
        pos = np.searchsorted(m[order], m[needs], side="left") - 1
    else:
        pos = np.full(int(needs.sum()), -1)
    ref = None
    for i, p in zip(np.flatnonzero(needs), pos):
        if p >= 0:
            out[i] = own[order[p]]
        else:
            if ref is None:
                ref = int(identify(np.array([max(1, n_intervals // min_points)]))[0])
            out[i] = ref
    return out


def _identify_each(phase, rate, m_arr, *, phase_input, estimator, method, b1_n, long=None) -> np.ndarray:
    """α at each m on that τ's own samples (no fallback). ``long``: a long rate record read in chunks
    (:class:`~allanite.estimators._long_id.LongRate`; ``phase`` and ``rate`` unused)."""
    n_phase = phase.size if long is None else long.n + 1
    out = np.empty(m_arr.shape, dtype=np.int64)
    if long is not None and method != "b1":  # the ACF sums of every long m in one parallel core call
        long.prefetch([mi for mi in m_arr.tolist() if long.n // mi > max(long.chunk, ACF_MIN_POINTS - 1)])
    for i, mi in enumerate(m_arr.tolist()):
        points = (n_phase - 1) // mi  # τ-intervals in the record, for either kind of data
        use_acf = method == "acf" or (method == "auto" and points >= ACF_MIN_POINTS)
        if use_acf:
            if long is not None and long.n // mi > long.chunk:
                p = long.acf_alpha(mi)  # the block averages too many to hold: in chunks
            else:
                if phase_input:
                    z = phase[::mi]
                elif long is not None:
                    z = long.all_means(mi)
                else:
                    k = rate.size // mi
                    z = rate[: k * mi].reshape(k, mi).mean(axis=1)
                p = _acf_alpha(z, phase=phase_input)
            a = int(np.clip(round(p), -2, 2))
        else:
            if b1_n == "averages":
                n_ref = points
            elif estimator == "oavar":
                n_ref = n_phase - 2 * mi
            else:
                n_ref = (n_phase - 1) // mi - 1
            a = _b1_rn_alpha(phase, rate, mi, n_ref, long)
        out[i] = a
    return out
