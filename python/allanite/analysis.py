"""Static and dynamic Allan variance — the public entry points: input checks, the estimator registry,
result objects.

Which estimators exist, what options each takes and how each is computed is the registry's business
(:mod:`allanite.estimators`); this module turns samples into rate columns, asks the entry, guards the
memory budget and wraps the arrays into :class:`~allanite.AllanResult` /
:class:`~allanite.DynamicAllanResult`.
"""

from __future__ import annotations

import dataclasses
import math
import textwrap
from typing import Any

import numpy as np

from . import estimators
from ._progress import StepBar, show_progress
from ._validate import as_rate_columns, check_choice, check_count, check_input, resolve_max_memory
from .errors import InputError, MemoryBudgetError, ParameterError
from .estimators.deviations import GAP_DYNAMIC_ESTIMATORS, GAP_ESTIMATORS, gap_dynamic, gap_static
from .results import AllanResult, DynamicAllanResult

__all__ = ["avar", "davar", "METHODS", "GAPS"]

#: ``gaps=`` of :func:`avar`: NaN is an error (default), or marks a missing sample whose terms are skipped.
GAPS = ("error", "skip")

#: ``method=`` of :func:`davar`: sliding sums, or every window recomputed (paper 000's DAVAR).
METHODS = ("fast", "naive")

#: Samples whose largest magnitude lies outside [2^-SAFE_EXP, 2^SAFE_EXP] are scaled by a power of two
#: (exact in floating point) before the core squares them, and the result is scaled back: squares of
#: 1e154 overflow and of 1e-160 underflow, while the Allan variance itself may be representable.
SAFE_EXP = 200


def _scale_columns(cols: list[np.ndarray], peaks: list[float] | None = None) -> tuple[list[np.ndarray], list[int]]:
    """Columns scaled into the safe range, and each column's power-of-two exponent e (sample = scaled·2^e).
    ``peaks``: the columns' largest magnitudes when the caller has them (``as_rate_columns(peaks=)``)."""
    out, exps = [], []
    for i, c in enumerate(cols):
        peak = peaks[i] if peaks is not None else _peak(c)
        if peak == 0.0 or 2.0**-SAFE_EXP < peak < 2.0**SAFE_EXP:
            out.append(c)
            exps.append(0)
            continue
        e = math.frexp(peak)[1]
        out.append(np.ldexp(c, -e))
        exps.append(e)
    return out, exps


def _peak(c: np.ndarray) -> float:
    """Largest magnitude of a column: two passes over the record, no temporary (``np.abs`` would copy it)."""
    return max(float(c.max()), -float(c.min())) if c.size else 0.0


def _unscale(
    values: np.ndarray, exps: list[int], power: int, cols: list[np.ndarray], what: str, ranges=None
) -> np.ndarray:
    """Values (axes first) scaled back by 2^(power·e) per axis, or an InputError when the result is not a
    float64 (overflow, or below the normal range) — naming the scale of the samples. ``ranges``: the rows'
    (max, min, non-finite flag) when the core noted them (``Computed.ranges``)."""
    out = []
    for a, (v, e) in enumerate(zip(values, exps)):
        where = f"axis {a}: " if len(values) > 1 else ""
        # binary exponent of the result: log2 of the scaled value plus power·e, judged before scaling back.
        # No temporary the size of the output (a hop-1 surface can be gigabytes): the core's row ranges, or a
        # max and a min pass; the smallest positive value from the min unless some value is ≤ 0 (then a
        # masked pass, row by row).
        hi, lo = _extremes(v, None if ranges is None else ranges[a])
        if lo > 0:
            lo_pos = lo
        elif not hi > 0:
            lo_pos = math.inf
        else:
            rows = v.reshape(-1, v.shape[-1])
            lo_pos = min((float(np.min(r, where=r > 0, initial=math.inf)) for r in rows), default=math.inf)
        top = math.log2(hi) + power * e if hi > 0 else -math.inf
        bottom = math.log2(lo_pos) + power * e if lo_pos < math.inf else math.inf
        if not math.isfinite(hi) or not math.isfinite(lo) or top >= 1024:
            peak = _peak(cols[a])
            raise InputError(
                f"{where}the {what} of samples of magnitude up to {peak:.3g} exceeds float64's range (≈1.8e308): "
                f"express the samples in a larger unit (e.g. divide them by 1e{max(1, int(math.log10(peak)) // 2)})"
            )
        if bottom < -1022:
            peak = _peak(cols[a])
            raise InputError(
                f"{where}the {what} (about 2^{bottom:.0f} ≈ 1e{bottom * math.log10(2):.0f}) is below float64's normal "
                f"range (2.2e-308) for samples of magnitude up to {peak:.3g}: express the samples in a smaller unit "
                f"(e.g. multiply them by 1e{max(1, int(-math.log10(peak)) // 2) if peak > 0 else 100})"
            )
        out.append(np.ldexp(v, power * e) if e else v)
    return np.stack(out) if any(exps) else values


def _extremes(v: np.ndarray, ranges) -> tuple[float, float]:
    """(largest, smallest) value of ``v`` — NaN as the largest when some value is not finite (as ``v.max()``
    gives for NaN; an infinite value is caught by the caller either way) — from the rows' noted ranges when
    given, else from two passes."""
    if not v.size:
        return 0.0, 0.0
    if ranges is not None:
        r = np.asarray(ranges, dtype=np.float64).reshape(-1, 3)
        return (math.nan if r[:, 2].any() else float(r[:, 0].max())), float(r[:, 1].min())
    return float(v.max()), float(v.min())  # NaN if any value is, inf if any is


def avar(
    x,
    fs,
    *,
    input: str = "rate",
    taus="octave",
    estimator: str = "oavar",
    workers=None,
    kf_rule: str = "textbook",
    decimate="auto",
    gaps: str = "error",
    taper: str = "rect",
) -> AllanResult:
    """Allan variance of a whole record.

    Parameters
    ----------
    x : array_like, shape (samples,) or (samples, axes)
        Samples: rate (e.g. °/s), increments (angle per sample) or cumulative angle, per ``input``.
        Any real dtype, any strides or byte order; computed in float64.
    fs : float
        Sampling rate, Hz (τ0 = 1/fs).
    input : {"rate", "increment", "angle"}
        What the samples are. Equivalent inputs give the same numbers: rate y, increments y/fs and
        angle ``[0, cumsum(y/fs)]`` (M + 1 points). Results are always in rate units. allantools' and
        Stable32's words are taken too: ``"phase"`` (a clock's time error) is ``"angle"``, ``"freq"`` and
        ``"frequency"`` are ``"rate"``; ``result.input`` holds allanite's word.
    taus : str or array_like
        A grid name (``"octave"``, default; ``"decade"``, ``"all"``, ``"exp"`` — see
        :func:`allanite.tau_grid`) or τ in seconds, each rounded to m = round(τ·fs) and required to be
        valid; ``result.tau`` holds the τ actually used.
    estimator : str
        ``"oavar"`` (default; NIST SP 1065 eq. 11) or ``"avar"``: overlapping or classic non-overlapping
        Allan variance. ``"theo1"`` (even m ≥ 10, τ = 0.75·m/fs, up to 75 % of the record), bias-removed
        ``"theobr"``, or ``"theoh"`` (overlapping Allan up to 10 % of the record, TheoBR beyond) — see
        :mod:`allanite.estimators.theo`; for these, named grids span m = 1 … M, ``result.source`` says which
        estimator each τ came from and ``result.kf`` holds the bias ratio. The rest of the deviation family
        (docs/deviations.md: which to use when): ``"mvar"`` modified, ``"tvar"`` time (τ²/3·MVAR),
        ``"hvar"``/``"ohvar"`` Hadamard (classic/overlapping; blind to a rate ramp), ``"totvar"``,
        ``"mtotvar"``, ``"ttotvar"``, ``"htotvar"`` total variances (definitions' values, no bias
        correction), ``"mtie"`` and ``"tierms"`` (of the angle; ``result.adev`` holds them).
    workers : int, optional
        Threads (default: ``ALLANITE_NUM_THREADS``, else all cores). Results do not depend on it.
    kf_rule : {"textbook", "stable32"}
        TheoBR/TheoH only: the range of the bias ratio kf — Howe's n = ⌊0.1·N/3 − 3⌋ (default) or
        Stable32's n = ⌊N/6 − 3⌋ (to reproduce Stable32's ThêoH numbers).
    decimate : int or "auto"
        Theo estimators only. Theo1 of a whole record costs O(N²) (≈ 2 s at N = 1e5, minutes at
        1e6). With D > 1 the Theo part and kf are computed on the rate averaged in blocks of D
        samples (the phase decimated by D: Taylor & Howe's fast TheoBR), at τ = 0.75·m'·D/fs,
        reported as m = m'·D; the Allan part stays exact. ``"auto"`` (default): on a named τ grid,
        the smallest D that leaves ≤ 100 000 samples (records up to 100 000 samples stay exact);
        explicit τ are computed exactly. ``decimate=1``: always exact (O(N²); Ctrl-C stops it).
    gaps : {"error", "skip"}
        ``"error"`` (default): a NaN sample is an :class:`~allanite.errors.InputError` naming its
        position. ``"skip"``: NaN marks a missing sample (e.g. rows ``read_log(..., gaps="nan")`` filled
        in); every term that touches a missing *rate* sample is left out (a missing angle point makes the
        two rate samples beside it missing), and ``result.n`` holds the complete terms per τ — shape (T,)
        when every axis has the same count, else (axes, T). A τ with no complete term has n = 0 and
        NaN; :func:`~allanite.confidence_intervals` takes the EDF of a gapless record with as many
        terms (give it ``alpha=``). Estimators ``"oavar"``, ``"avar"``, ``"mvar"``, ``"tvar"``, ``"ohvar"``,
        ``"hvar"``, ``"totvar"``, ``"mtotvar"``, ``"ttotvar"``, ``"htotvar"``, ``"mtie"``, ``"tierms"`` (the
        Theo family raises :class:`~allanite.errors.ParameterError`); the classic ``"avar"`` and ``"hvar"``
        keep their cluster grid from the first sample (clusters do not shift around a gap). The total family
        keeps a term when
        every original sample it reads is present: TOTVAR's reflected samples mirror samples inside the
        term's own range, so its term at phase point p needs rate samples [p − m, p + m) clipped to the
        record; MTOTVAR/TTOTVAR need their 3m-point phase subsequence, HTOTVAR its 3m rate samples; an
        MTIE window or TIE difference over phase points [k, k + m] needs rate samples [k, k + m).
        allantools' ``gradev`` instead skips a term when one of its own *phase* points is NaN: the same
        at m = 1, more terms kept for m > 1 (it uses phase differences across a gap, which are unknown
        when samples of rate are missing).
    taper : {"rect", "hann", "hann_signal"}
        Weighting of the terms (paper 002; docs/FORMULAS.md §10), ``estimator="oavar"`` only for the
        tapers: ``"rect"`` (default) weights every squared difference equally; ``"hann"`` weights them
        by a Hann taper (unbiased; the static counterpart of ``davar(..., taper="hann")``);
        ``"hann_signal"`` tapers the samples themselves (paper 002 eq. 1; biased, see docs/tapers.md).
        Named τ grids keep the m that leave at least 3 terms.

    Returns
    -------
    AllanResult
        ``tau``, ``avar``, ``adev``, ``n`` (terms per τ), ``m``; for 2-D input ``avar`` is
        (axes, tau).

    Examples
    --------
    >>> import numpy as np, allanite
    >>> y = np.random.default_rng(1).normal(size=100_000)      # white rate noise, σ = 1
    >>> r = allanite.avar(y, fs=100.0, taus=[0.01, 0.1, 1.0])
    >>> r.tau
    array([0.01, 0.1 , 1.  ])
    >>> np.round(r.adev * np.sqrt(r.m), 1)                      # white rate: adev·√m ≈ σ
    array([1., 1., 1.])
    """
    check_choice(gaps, "gaps", GAPS)
    input = check_input(input)
    if gaps == "skip":
        if taper != "rect":
            raise ParameterError(f"gaps='skip' works with taper='rect' only, got taper={taper!r}")
        return _avar_skipping_gaps(x, fs, input, taus, estimator, workers)
    entry = estimators.get(estimator, "static")
    tapered = estimators.get_taper(taper, estimator)
    options = entry.check_options({"kf_rule": kf_rule, "decimate": decimate})
    peaks: list[float] = []
    cols, fs, is_multi = as_rate_columns(x, fs, input, peaks=peaks)
    assert entry.static is not None
    scaled, exps = _scale_columns(cols, peaks)
    if tapered.static is None:
        out = entry.static(scaled, fs, taus, workers, **options)
    else:
        out = tapered.static(scaled, fs, taus, workers)
    values: np.ndarray = _unscale(out.values, exps, entry.unit_power, cols, entry.label)
    kf: np.ndarray | float | None = out.kf
    if not is_multi:
        values, kf = values[0], (None if out.kf is None else float(out.kf[0]))
    return AllanResult(
        tau=out.tau,
        avar=values,
        n=out.n,
        m=out.m,
        estimator=estimator,
        fs=fs,
        n_samples=cols[0].size,
        input=input,
        source=out.source,
        kf=kf,
        taper=taper,
    )


def gap_columns(x, fs, input):
    """Rate columns of a record whose NaN marks missing samples (a missing angle point makes the two
    rate samples beside it missing): (columns with NaN at the missing rate samples, fs, is_multi)."""
    arr = np.asarray(x)
    missing = np.isnan(arr) if arr.dtype.kind == "f" else np.zeros(arr.shape, dtype=bool)
    # validate the record with the gaps filled, then mark the missing rate samples again
    cols, fs, is_multi = as_rate_columns(np.where(missing, 0.0, arr) if missing.any() else arr, fs, input)
    miss2 = np.atleast_2d(missing.T).T  # (points, axes)
    out_cols = []
    for a, c in enumerate(cols):
        c = np.array(c, dtype=np.float64)  # own copy: never write into the caller's array
        mk = miss2[:, a]
        c[(mk[1:] | mk[:-1]) if input == "angle" else mk] = np.nan
        out_cols.append(c)
    return out_cols, fs, is_multi


def _avar_skipping_gaps(x, fs, input, taus, estimator, workers) -> AllanResult:
    """avar(..., gaps="skip"): NaN-marked missing samples, terms touching one skipped."""
    if estimator not in GAP_ESTIMATORS:
        raise ParameterError(
            f'gaps="skip" is supported by the estimators {", ".join(GAP_ESTIMATORS)}; got estimator={estimator!r}'
        )
    out_cols, fs, is_multi = gap_columns(x, fs, input)
    out = gap_static(out_cols, fs, taus, workers, estimator)
    counts = np.asarray(out.n, dtype=np.int64)
    n = counts[0] if np.all(counts == counts[0]) else counts
    values = out.values if is_multi else out.values[0]
    lost = np.array([int(np.count_nonzero(np.isnan(c))) for c in out_cols], dtype=np.int64)
    return AllanResult(
        tau=out.tau,
        avar=values,
        n=n,
        m=out.m,
        estimator=estimator,
        fs=fs,
        n_samples=out_cols[0].size,
        input=input,
        missing=lost if is_multi else int(lost[0]),
    )


def davar(
    x,
    fs,
    *,
    window,
    hop=1,
    taus="exp",
    method: str = "fast",
    estimator: str = "oavar",
    input: str = "rate",
    workers=None,
    max_memory=None,
    kf_rule: str = "textbook",
    progress=None,
    taper: str = "rect",
    gaps: str = "error",
) -> DynamicAllanResult:
    """Dynamic Allan variance: the Allan variance of every sliding window (DAVAR).

    Column j of the result is exactly the static Allan variance (:func:`avar`) of the ``window``
    samples starting at sample ``j·hop``, for every window that fits in the record, at the same τ.

    Parameters
    ----------
    x : array_like, shape (samples,) or (samples, axes)
        Samples, as for :func:`avar`.
    fs : float
        Sampling rate, Hz.
    window : int
        Window length in samples (rate or increment samples; for ``input="angle"`` in angle
        intervals). 2 ≤ window ≤ record length.
    hop : int
        Distance between window starts, samples (≥ 1).
    taus : str or array_like
        Grid name or τ in seconds, for the *window*: ``"exp"`` (default) is paper 000's exponential
        grid up to window/9 — with ``method="fast"`` this is the "improved fast DAVAR".
    method : {"fast", "naive"}
        ``"fast"``: sliding block sums, O(record) work per τ whatever the window and hop, exact to
        rounding (no drift, see the core's notes). ``"naive"``: recompute every window from
        scratch — paper 000's DAVAR, O(window) per τ per window; kept as a reference and baseline.
    estimator : str
        Every estimator of the registry with a dynamic form: {dynamic_estimators}.
        ``"oavar"`` (default) or ``"avar"``: overlapping or classic Allan variance inside each window;
        ``"ohvar"``: the overlapping Hadamard variance of each window (blind to a rate ramp); paper
        001's dynamic TheoH: ``"theoh"`` (DHVAR: overlapping Allan up to 10 % of the window, TheoBR
        with the window's own bias ratio beyond, to 75 % of the window) or ``"theoh_a"`` (DHVAR-A:
        classic Allan below the switch) — Theo values belong to τ = 0.75·m/fs; ``result.source``
        names the estimator of each τ, ``result.kf`` every window's bias ratio; ``method="fast"``
        only. The rest of the deviation family is static only (:func:`avar`): {static_only}.
    input : {"rate", "increment", "angle"}
    workers : int, optional
        Threads (default ``ALLANITE_NUM_THREADS``, else all cores); results are bit-identical for
        any value. The GIL is released while the core computes.
    max_memory : int, optional
        Byte budget for the output (default ``ALLANITE_MAX_MEMORY`` or 2 GiB). A larger request
        raises :class:`~allanite.errors.MemoryBudgetError` at once, with a hop that fits.
    kf_rule : {"textbook", "stable32"}
        DHVAR only: range of each window's bias ratio, as for :func:`avar`.
    progress : bool, optional
        DHVAR only (the slow dynamic estimator): a ``tqdm.auto`` bar over the windows — None (default)
        shows it in a notebook or a terminal when the windows hold ≥ ``DHVAR_BAR_SAMPLES`` samples in
        all, True always, False never. With a bar the windows are computed in up to 20 groups (each
        window is computed on its own samples either way).
    taper : {"rect", "hann", "hann_signal"}
        Weighting inside each window (paper 002; docs/FORMULAS.md §10), ``estimator="oavar"`` only for
        the tapers. ``"hann"``: the M = window − 2m + 1 squared differences weighted by
        w_i = ½ − ½·cos(2π(i + 1)/(M + 1)) and normalised by Σw — unbiased, O(1) per output (Rust core);
        window = record gives ``avar(..., taper="hann")``. ``"hann_signal"``: the window's samples
        tapered, then OAVAR (paper 002 eq. 1; biased, NumPy, O(window) per τ and window). Every τ
        must leave at least 3 terms.
    gaps : {"error", "skip"}
        As for :func:`avar`: ``"skip"`` treats NaN as a missing sample and every window averages only
        its terms that touch no missing rate sample; ``result.n`` is then the complete-term count of
        every window, shape (T, windows) — (axes, T, windows) when the axes' counts differ — and a
        window with no complete term at some τ holds NaN there (n = 0).
        :func:`~allanite.confidence_intervals` gives each window the EDF of a gapless window with as
        many terms (pass ``alpha=``). ``estimator="oavar"`` or ``"ohvar"`` (dynamic Hadamard, blind to
        rate ramps), ``method="fast"``, ``taper="rect"``. Exact as without gaps: each window's sum is
        formed from its own terms only (docs/compat.md).

    Returns
    -------
    DynamicAllanResult
        ``tau``, ``t`` (window centres, s), ``avar`` of shape (tau, t) — or (axes, tau, t) for 2-D
        input —, ``adev``, ``n`` (terms per window at each τ). A window whose samples are all equal
        (a sensor not yet streaming) has Allan variance 0; the result there may be its rounding residue,
        ~ε²·(value − record mean)² — some 1e-38 of the record's values — rather than an exact 0.

    Examples
    --------
    >>> import numpy as np, allanite
    >>> y = np.random.default_rng(2).normal(size=20_000)
    >>> y[10_000:] *= 10                                        # the noise grows tenfold
    >>> d = allanite.davar(y, 100.0, window=2_000, hop=500, taus=[0.01, 0.1])
    >>> d.avar.shape                                            # (tau, t)
    (2, 37)
    >>> np.round(d.adev[0, [0, -1]])                            # before and after, at τ = 0.01 s
    array([ 1., 10.])
    """
    entry = estimators.get(estimator, "dynamic")
    tapered = estimators.get_taper(taper, estimator)
    check_choice(method, "method", METHODS)
    check_choice(gaps, "gaps", GAPS)
    input = check_input(input)
    options = entry.check_options({"kf_rule": kf_rule})
    peaks: list[float] | None
    if gaps == "skip":
        _check_gap_davar(estimator, method, taper)
        cols, fs, is_multi = gap_columns(x, fs, input)
        peaks = None
    else:
        peaks = []
        cols, fs, is_multi = as_rate_columns(x, fs, input, peaks=peaks)
    n = cols[0].size
    window, hop = _check_window(entry, tapered, estimator, taper, method, window, hop, n)
    assert entry.dynamic is not None and entry.resolve_m is not None
    ms = entry.resolve_m(taus, window, fs)
    n_win = (n - window) // hop + 1
    value_bytes = 16 if gaps == "skip" else 8  # with gaps: values and counts
    _check_output_budget(len(cols), ms.size, n_win, value_bytes, max_memory, n, window, hop)
    # A hop beyond the record gives one window, as does the record length itself.
    hop_core = min(hop, n)
    t = (np.arange(n_win) * float(hop) + window / 2) / fs
    common: dict[str, Any] = dict(
        t=t, window=window, hop=hop, method=method, estimator=estimator, fs=fs, n_samples=n, input=input
    )
    if gaps == "skip":
        return _gap_davar(cols, fs, window, hop_core, ms, workers, estimator, is_multi, common)
    scaled, exps = _scale_columns(cols, peaks)
    out = _dynamic_core(entry, tapered, scaled, fs, window, hop_core, taus, method, workers, options, n_win, progress)
    values = _unscale(out.values, exps, entry.unit_power, cols, entry.label, out.ranges)
    out = dataclasses.replace(out, values=values)
    kf = out.kf
    return DynamicAllanResult(
        tau=out.tau,
        avar=out.values if is_multi else out.values[0],
        n=out.n,
        m=out.m,
        source=out.source,
        kf=kf if (kf is None or is_multi) else kf[0],
        taper=taper,
        **common,
    )


def _gap_davar(cols, fs, window, hop_core, ms, workers, estimator, is_multi, common) -> DynamicAllanResult:
    """DAVAR of records with NaN-marked gaps (``gaps="skip"``, :func:`gap_dynamic`): ``n`` counts each window's
    complete terms per τ — one axis's counts where every axis has the same, else every axis's."""
    out = gap_dynamic(cols, fs, window, hop_core, ms, workers, estimator)
    counts = np.asarray(out.n, dtype=np.int64)
    n_terms = counts[0] if np.all(counts == counts[0]) else counts
    return DynamicAllanResult(tau=out.tau, avar=out.values if is_multi else out.values[0], n=n_terms, m=out.m, **common)


def _dynamic_core(entry, tapered, scaled, fs, window, hop_core, taus, method, workers, options, n_win, progress):
    """The estimator's dynamic values of the scaled columns: the taper's form, DHVAR in groups behind a bar
    (``progress``; on large or asked-for runs) or the estimator's own call."""
    big = n_win * window >= DHVAR_BAR_SAMPLES
    if tapered.dynamic is not None:
        return tapered.dynamic(scaled, fs, window, hop_core, taus, method, workers)
    if entry.family == "theo" and n_win >= 2 and show_progress(progress) and (big or progress is True):
        return _in_groups(entry, scaled, fs, window, hop_core, taus, method, workers, options, n_win, progress)
    return entry.dynamic(scaled, fs, window, hop_core, taus, method, workers, **options)


def _check_window(entry, tapered, estimator, taper, method, window, hop, n) -> tuple[int, int]:
    """``window`` and ``hop`` as sample counts, the window within the record's ``n`` samples; ``method`` one
    that both the estimator and the taper compute."""
    window = check_count(window, "window", 2)
    hop = check_count(hop, "hop", 1)
    if window > n:
        raise ParameterError(f"window ({window} samples) is longer than the record ({n} samples)")
    if method not in entry.methods:
        raise ParameterError(
            f"estimator {estimator!r} is computed with method={entry.methods[0]!r} only, got method={method!r}"
        )
    if method not in tapered.methods:
        raise ParameterError(f"taper {taper!r} is computed with method in {tapered.methods}, got method={method!r}")
    return window, hop


def _check_gap_davar(estimator: str, method: str, taper: str) -> None:
    """davar(gaps="skip") needs the plain fast path of an estimator with a gap-skipping dynamic form."""
    if taper != "rect" or method != "fast":
        raise ParameterError(
            f"gaps='skip' works with taper='rect' and method='fast' only, got taper={taper!r}, method={method!r}"
        )
    if estimator not in GAP_DYNAMIC_ESTIMATORS:
        raise ParameterError(
            f'davar(gaps="skip") is supported by the estimators {", ".join(GAP_DYNAMIC_ESTIMATORS)}; got '
            f"estimator={estimator!r}"
        )


def _check_output_budget(n_axes, n_tau, n_win, value_bytes, max_memory, n, window, hop) -> None:
    """A MemoryBudgetError, with the smallest hop that fits, when a DAVAR output of ``n_axes`` × ``n_tau`` ×
    ``n_win`` values of ``value_bytes`` each would exceed ``max_memory``."""
    nbytes = n_axes * n_tau * n_win * value_bytes
    budget = resolve_max_memory(max_memory)
    if nbytes > budget:
        per_window = n_axes * n_tau * value_bytes
        size = (
            f"the output would take {nbytes / 2**30:.2f} GiB ({n_axes} axes × {n_tau} τ × {n_win} windows "
            f"× 8 bytes), over the memory budget of {budget / 2**30:.2f} GiB"
        )
        if per_window > budget:
            raise MemoryBudgetError(
                f"{size}; even one window ({per_window} bytes) does not fit: use fewer τ or raise "
                f"max_memory / ALLANITE_MAX_MEMORY"
            )
        # windows = (n − window)//hop + 1 ≤ budget/per_window: the smallest hop that fits.
        max_windows = budget // per_window
        suggest = n if max_windows <= 1 else max(hop + 1, -(-(n - window) // (max_windows - 1)))
        raise MemoryBudgetError(f"{size}; use hop ≥ {suggest}, fewer τ, or raise max_memory / ALLANITE_MAX_MEMORY")


#: DHVAR work (windows × window length) from which ``progress=None`` shows a bar (some seconds).
DHVAR_BAR_SAMPLES = 2_000_000


def _registry_words(text: str) -> str:
    """``text`` with ``{dynamic_estimators}`` and ``{static_only}`` filled from the estimator registry,
    each placeholder's line re-wrapped to the docstring's width."""
    dynamic = estimators.names("dynamic")
    fill = {
        "{dynamic_estimators}": ", ".join(f'``"{n}"``' for n in dynamic),
        "{static_only}": ", ".join(f'``"{n}"``' for n in estimators.names("static") if n not in dynamic),
    }
    lines = []
    for line in text.split("\n"):
        if any(k in line for k in fill):
            for k, v in fill.items():
                line = line.replace(k, v)
            indent = line[: len(line) - len(line.lstrip())]
            line = textwrap.fill(line.strip(), width=104, initial_indent=indent, subsequent_indent=indent)
        lines.append(line)
    return "\n".join(lines)


if davar.__doc__:  # the accepted names come from the registry, so help(davar) cannot fall behind it
    davar.__doc__ = _registry_words(davar.__doc__)


def _in_groups(entry, cols, fs, window, hop, taus, method, workers, options, n_win, progress):
    """The dynamic estimator on groups of consecutive windows, one bar step per group: window j of a
    group starting at window j0 is computed from samples j·hop … j·hop + window − 1 of the record, as
    in one call (the windows share no state: each has its own τ grid — fixed by the window length — and
    its own bias ratio)."""
    groups = np.array_split(np.arange(n_win), min(n_win, 20))
    parts = []
    with StepBar(progress, len(groups), "DHVAR") as bar:
        for g in groups:
            bar.step(f"windows {g[0] + 1}–{g[-1] + 1} of {n_win}")
            a, b = int(g[0]) * hop, int(g[-1]) * hop + window
            parts.append(entry.dynamic([c[a:b] for c in cols], fs, window, hop, taus, method, workers, **options))
    first = parts[0]
    return dataclasses.replace(
        first,
        values=np.concatenate([p.values for p in parts], axis=-1),
        kf=None if first.kf is None else np.concatenate([p.kf for p in parts], axis=-1),
    )
