"""Theo1, TheoBR and TheoH — whole records and sliding windows (DHVAR) — over the Rust core.

Definitions (Howe & Peppler 2003; Howe 2006; Taylor & Howe 2010; NIST SP 1065 §5.2.16–18), for a
record of M rate samples, i.e. N = M + 1 phase (angle) points, τ0 = 1/fs, T = M·τ0:

- **Theo1** at even m, 10 ≤ m ≤ N − 1, belongs to τ = 0.75·m·τ0 (not m·τ0 — allantools' label):
  Theo1 = Σ_{i=0}^{N−m−1} Σ_{δ=0}^{m/2−1} [(x_i − x_{i−δ+m/2}) + (x_{i+m} − x_{i+δ+m/2})]² / (m/2 − δ)
  / (0.75·(N − m)·(m·τ0)²). Invariant to a constant and a linear phase (frequency offset).
- **TheoBR** = kf·Theo1 with kf = (n + 1)⁻¹ Σ_{i=0}^{n} AVAR(m = 9 + 3i) / Theo1(m = 12 + 4i), both at
  τ = (9 + 3i)·τ0, AVAR the overlapping Allan variance, n = ⌊0.1·N/3 − 3⌋ (N phase points; needs
  N ≥ 90). kf removes Theo1's noise-type-dependent bias against the Allan variance. Stable32 averages
  over n = ⌊N/6 − 3⌋ instead (``kf_rule="stable32"`` reproduces its tables).
- **TheoH**: the overlapping Allan variance for τ ≤ k = 0.1·T, TheoBR for 0.75·m·τ0 > k up to
  0.75·T. ``"theoh_a"`` (paper 001's DHVAR-A) uses the classic Allan variance below k instead.

In sliding windows (paper 001's DHVAR), every window of W samples is a record of its own: N = W + 1,
its own kf, its own switch point 0.1·W·τ0. The Theo1 sums are computed by the Rust core (an O(N²)
all-m algorithm for whole records, per-(d, m) sliding sums for windows; see ``rust/core/src/theo.rs``)
and agree with the direct double sum to ≲ 1e-11 relative.
"""

from __future__ import annotations

import math
from functools import partial

import numpy as np

from .. import _core
from .._validate import check_count, check_fs, resolve_workers
from ..errors import ParameterError
from ._registry import Computed, Estimator, register
from .allan import allan_values
from .confidence import edf_theo1
from .grid import GRIDS, m_grid

__all__ = ["theo_ms", "kf_indices", "switch_m", "static_theo", "dynamic_theo", "resolve_decimation", "THEO_SOURCES"]

#: The estimators whose values belong to τ = 0.75·m/fs.
THEO_SOURCES = ("theo1", "theobr")
#: Howe's lower limit on the Theo1 averaging factor.
THEO1_MIN_M = 10
#: TheoBR's bias ratio needs n = ⌊0.1·N/3 − 3⌋ ≥ 0, i.e. N ≥ 90 phase points.
THEOBR_MIN_POINTS = 90
#: TheoH switches from Allan to TheoBR above this fraction of the span T.
THEOH_SWITCH = 0.1


#: Rules for the range of TheoBR's bias ratio: last index n for N phase points, and the least N.
KF_RULES = {
    "textbook": (lambda n_phase: (n_phase - 90) // 30, 90),  # ⌊0.1·N/3 − 3⌋ (Howe; Taylor & Howe)
    "stable32": (lambda n_phase: (n_phase - 18) // 6, 18),
}  # ⌊N/6 − 3⌋ (what Stable32 does)


def kf_indices(n_rate: int, rule: str = "textbook") -> tuple[np.ndarray, np.ndarray]:
    """The averaging factors of TheoBR's bias ratio for ``n_rate`` rate samples: (AVAR m = 9 + 3i,
    Theo1 m = 12 + 4i), i = 0 … n, N = n_rate + 1 phase points.

    ``rule="textbook"``: n = ⌊0.1·N/3 − 3⌋ (Howe, Tasset & Taylor; the ratio covers τ up to ≈ 10 % of
    T). ``rule="stable32"``: n = ⌊N/6 − 3⌋ — what Stable32 uses for its ThêoH and bias-removed Thêo1
    (found by reproducing its Sr87 and PHASE.DAT tables to printed precision; on Sr87 it gives kf
    2.43 % larger in variance than the textbook rule).
    """
    if rule not in KF_RULES:
        raise ParameterError(f"kf_rule must be one of {tuple(KF_RULES)}, got {rule!r}")
    last, least = KF_RULES[rule]
    n_phase = int(n_rate) + 1
    if n_phase < least:
        raise ParameterError(
            f"TheoBR/TheoH need at least {least} phase points ({least - 1} samples) for the bias ratio "
            f"(kf_rule={rule!r}), got {n_rate} samples"
        )
    n = int(last(n_phase))
    i = np.arange(n + 1, dtype=np.int64)
    return 9 + 3 * i, 12 + 4 * i


def switch_m(n_rate: int) -> int:
    """Largest Allan averaging factor of TheoH: m·τ0 ≤ 0.1·T, T = n_rate·τ0."""
    return max(1, int(math.floor(THEOH_SWITCH * n_rate + 1e-9)))


def _even_theo(ms: np.ndarray, n_rate: int) -> np.ndarray:
    """Grid factors made valid Theo1 factors: rounded up to even, ≥ 10, ≤ the largest even ≤ N − 1."""
    top = int(n_rate) - int(n_rate) % 2
    ev = ms + (ms % 2)
    ev = ev[(ev >= THEO1_MIN_M) & (ev <= top)]
    return np.unique(ev)


def theo_ms(taus, n_rate: int, fs: float, estimator: str) -> tuple[np.ndarray, np.ndarray]:
    """(m, source) for a TheoH-family estimate on ``n_rate`` samples — THE τ → (estimator, m) mapping:
    :func:`static_theo`, :func:`dynamic_theo` and the registry's ``resolve_m`` all call it, and a named
    grid is first laid out as τ and then mapped by the same rule as explicit τ (:func:`_map_tau`), so
    the τ a result reports, handed back as ``taus=``, give the same estimator and m on either path.

    Named grids (``"all"``, ``"octave"``, ``"decade"``, ``"exp"``) are laid out over m = 1 … M and end
    at the largest even m ≤ M (Theo reaches τ = 0.75·M·τ0); Theo1 factors are rounded up to even and
    kept in 10 … N − 1. For TheoH,
    grid points with m·τ0 ≤ 0.1·T are Allan ("oavar"/"avar"), the rest TheoBR at τ = 0.75·m·τ0 > 0.1·T.
    Explicit τ (s) map to the nearest valid factor of the estimator that covers them and must then
    be honoured exactly (as :func:`allanite.tau_grid`'s rules for Allan τ).
    """
    n_rate = int(n_rate)
    if n_rate < THEO1_MIN_M:
        raise ParameterError(f"Theo1 needs at least {THEO1_MIN_M} samples (m ≥ {THEO1_MIN_M}, m ≤ N − 1), got {n_rate}")
    if isinstance(taus, str):
        if taus not in GRIDS:
            raise ParameterError(f"unknown τ grid {taus!r}; allowed: {', '.join(map(repr, GRIDS))} or τ in s")
        s = _grid_samples(taus, n_rate, fs, estimator)
        return _map_tau(s, s / fs, n_rate, fs, estimator)
    arr = np.atleast_1d(np.asarray(taus, dtype=np.float64))
    if arr.ndim != 1 or arr.size == 0 or not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        raise ParameterError(f"taus must be a grid name or a non-empty 1-D sequence of positive τ in s, got {taus!r}")
    return _map_tau(arr * fs, arr, n_rate, fs, estimator)


def _grid_samples(name: str, n_rate: int, fs: float, estimator: str) -> np.ndarray:
    """A named grid laid out as τ in samples: Allan m (τ = m·τ0) up to the switch, then Theo1's even m
    at τ = 0.75·m·τ0 beyond it (no gap at the switch), ending at Theo's last point 0.75·T."""
    hybrid = estimator in ("theoh", "theoh_a")
    k = switch_m(n_rate) if hybrid else 0
    grid = m_grid(name, 2 * n_rate, fs=fs, m_max=n_rate)
    a = grid[grid <= k] if hybrid else np.empty(0, np.int64)
    # Theo part: τ = 0.75 m τ0 > k τ0 ⇔ m > k/0.75.
    t = _even_theo(grid, n_rate)
    if hybrid:
        t = t[0.75 * t > k]
        first = int(math.floor(k / 0.75)) + 1
        first += first % 2
        first = max(first, THEO1_MIN_M)
        if first <= n_rate - n_rate % 2 and (t.size == 0 or t[0] > first):
            t = np.concatenate([[first], t])  # no gap at the switch
    top = n_rate - n_rate % 2
    if top >= THEO1_MIN_M and (t.size == 0 or t[-1] < top):
        t = np.concatenate([t, [top]])  # Theo's point: reach 0.75·T, as Stable32's grids do
    return np.concatenate([a.astype(np.float64), 0.75 * t.astype(np.float64)])


def _map_tau(s: np.ndarray, taus: np.ndarray, n_rate: int, fs: float, estimator: str) -> tuple[np.ndarray, np.ndarray]:
    """τ in samples ``s`` (``taus`` in s, for messages) → (m, source), one rule for every τ.

    TheoH/TheoH-A: a τ that is exactly a TheoBR point above the switch k (τ = 0.75·m·τ0, even m ≥ 10,
    0.75·m > k) is that point; any other τ ≤ (k + ½)·τ0 is the Allan factor m = round(τ/τ0); the rest
    map to Theo1's even m = 2·round(τ/(1.5·τ0)). So every τ a result reports maps back to its own (m,
    source): an Allan m ≤ k is never 0.75·m' of an even m' above the switch, and a Theo point is
    recognised as such (τ = 40.5 samples at k = 40 is TheoBR's m = 54, not Allan's m = 40).
    """
    theo_src = "theo1" if estimator == "theo1" else "theobr"
    allan_src = "avar" if estimator == "theoh_a" else "oavar"
    hybrid = estimator in ("theoh", "theoh_a")
    k = switch_m(n_rate) if hybrid else 0
    top = n_rate - n_rate % 2
    far = ~(s < 2.0**62)  # far beyond any record (also inf): no int conversion of it
    if np.any(far):
        i = int(np.flatnonzero(far)[0])
        raise ParameterError(
            f"taus[{i}] = {taus[i]:g} s is beyond the record: Theo τ reach 0.75·{top}/fs = {0.75 * top / fs:g} s"
        )
    m_theo = 2 * np.floor(s / 1.5 + 0.5).astype(np.int64)
    exact_theo = (m_theo >= THEO1_MIN_M) & (np.abs(0.75 * m_theo - s) <= 1e-9 * s)
    if hybrid:
        exact_theo &= 0.75 * m_theo > k
    is_allan = (s <= k + 0.5) & ~exact_theo if hybrid else np.zeros(s.size, dtype=bool)
    m_allan = np.floor(s + 0.5).astype(np.int64)
    short = is_allan & (m_allan < 1)
    if np.any(short):
        i = int(np.flatnonzero(short)[0])
        raise ParameterError(f"taus[{i}] = {taus[i]:g} s is shorter than one sample (1/fs = {1 / fs:g} s)")
    bad = ~is_allan & ((m_theo < THEO1_MIN_M) | (m_theo > top) | ((0.75 * m_theo <= k) if hybrid else False))
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        lo = max(THEO1_MIN_M, 2 * (int(math.floor(k / 1.5)) + 1)) if hybrid else THEO1_MIN_M
        raise ParameterError(
            f"taus[{i}] = {taus[i]:g} s maps to Theo1 m = {m_theo[i]} (τ = 0.75·m/fs); allowed for {n_rate} samples: "
            f"even m from {lo} to {top}, i.e. τ from {0.75 * lo / fs:g} s to {0.75 * top / fs:g} s"
        )
    ms = np.where(is_allan, m_allan, m_theo)
    src = np.where(is_allan, allan_src, theo_src)
    tau_used = np.where(src == theo_src, 0.75 * ms, ms.astype(float))
    if np.any(np.diff(tau_used) <= 0):
        i = int(np.flatnonzero(np.diff(tau_used) <= 0)[0])
        raise ParameterError(
            f"taus[{i}] = {taus[i]:g} s and taus[{i + 1}] = {taus[i + 1]:g} s map to the same or decreasing τ "
            f"({tau_used[i] / fs:g} s, {tau_used[i + 1] / fs:g} s); τ must be strictly increasing"
        )
    return ms, src


def _tau(ms: np.ndarray, src: np.ndarray, fs: float) -> np.ndarray:
    is_theo = np.isin(src, THEO_SOURCES)
    return np.where(is_theo, 0.75 * ms, ms.astype(np.float64)) / fs


def _n_terms(ms: np.ndarray, src: np.ndarray, n_rate: int) -> np.ndarray:
    """Terms per estimate: (N − m)·m/2 for Theo1 (Stable32's "Thêo1 #"), N − 2m / K − 1 for Allan."""
    n_phase = n_rate + 1
    out = np.empty(ms.size, dtype=np.int64)
    for i, (m, s) in enumerate(zip(ms, src)):
        if s in THEO_SOURCES:
            out[i] = (n_phase - m) * (m // 2)
        elif s == "oavar":
            out[i] = n_rate + 1 - 2 * m
        else:
            out[i] = n_rate // m - 1
    return out


def _check_kf_rule(rule) -> None:
    if not isinstance(rule, str) or rule not in KF_RULES:
        raise ParameterError(f"kf_rule must be one of {tuple(KF_RULES)}, got {rule!r}")


def _kf(avar_ka: np.ndarray, theo1_kt: np.ndarray) -> np.ndarray:
    """Mean of AVAR/Theo1 over the bias-ratio factors (axis 1). A record with no variation at all
    (Theo1 = 0 there) has nothing to correct: kf = 1, so its zeros stay zeros rather than NaN."""
    ratio = np.divide(avar_ka, theo1_kt, out=np.ones_like(avar_ka), where=theo1_kt > 0)
    return np.mean(ratio, axis=1)


#: Records longer than this are decimated for the Theo part under ``decimate="auto"``: Theo1 of all
#: the bias-ratio factors is O(N²) (≈ 2 s at N = 1e5 on two cores, ≈ 2 min at 1e6).
THEO_AUTO_POINTS = 100_000


def resolve_decimation(decimate, n_rate: int, taus) -> int:
    """The block length D for the Theo part: 1 (exact), a given integer, or ``"auto"``:
    the smallest D with ⌊M/D⌋ ≤ ``THEO_AUTO_POINTS`` on a named τ grid (explicit τ: exact, D = 1)."""
    if decimate is None:
        return 1
    if isinstance(decimate, str):
        if decimate != "auto":
            raise ParameterError(f"decimate must be a positive integer or 'auto', got {decimate!r}")
        if not isinstance(taus, str):
            return 1
        d = max(1, -(-int(n_rate) // THEO_AUTO_POINTS))
    else:
        d = check_count(decimate, "decimate", 1)
    if d > 1 and not isinstance(taus, str):
        raise ParameterError(
            "decimate > 1 works with a named τ grid ('octave', 'decade', 'all', 'exp'), not with "
            "explicit τ: the Theo τ of a decimated record are multiples of 0.75·D/fs"
        )
    if d > 1 and int(n_rate) // d < THEOBR_MIN_POINTS:
        raise ParameterError(
            f"decimate = {d} leaves {int(n_rate) // d} samples of the {n_rate}; TheoBR needs "
            f"at least {THEOBR_MIN_POINTS - 1}"
        )
    return d


def _theo_part(cols, ms, src, n, estimator, kf_rule, w):
    """Theo1 (× kf for TheoBR) at the Theo entries of (ms, src) for records of n samples, and kf."""
    is_theo = np.isin(src, THEO_SOURCES)
    theo_m = ms[is_theo]
    need_kf = estimator in ("theobr", "theoh", "theoh_a")
    values = np.empty((len(cols), theo_m.size))
    kf = None
    all_theo = theo_m
    if need_kf:
        ka, kt = kf_indices(n, kf_rule)
        all_theo = np.unique(np.concatenate([theo_m, kt]))
    if all_theo.size:
        th = _core.theo1_static(cols, [int(m) for m in all_theo], w)
        values[:] = th[:, np.searchsorted(all_theo, theo_m)]
    if need_kf:
        av = allan_values(cols, n, 1, ka, "oavar", "fast", w)[:, :, 0]
        kf = _kf(av, th[:, np.searchsorted(all_theo, kt)])
        values *= kf[:, None]
    return values, kf


def static_theo(cols, fs: float, taus, workers, *, estimator: str, kf_rule: str = "textbook", decimate=1) -> Computed:
    """Theo1/TheoBR/TheoH of whole records: values (axes, T), per-τ ``source``, kf (axes,) or None.

    With ``decimate`` D > 1 the Theo part (and kf) is computed on the rate averaged in blocks of D
    samples — the phase decimated by D, Taylor & Howe's "fast TheoBR" — at τ = 0.75·m'·D/fs for even
    m' of the decimated record (reported as m = m'·D); the Allan part stays at full resolution.
    """
    fs = check_fs(fs)
    _check_kf_rule(kf_rule)
    n = cols[0].size
    d = resolve_decimation(decimate, n, taus)
    ms, src = theo_ms(taus, n, fs, estimator)
    w = resolve_workers(workers)
    is_theo = np.isin(src, THEO_SOURCES)
    allan = ~is_theo
    if d > 1:
        nd = n // d
        cols_d = [np.ascontiguousarray(c[: nd * d].reshape(nd, d).mean(axis=1)) for c in cols]
        md, srcd = theo_ms(taus, nd, fs / d, estimator)
        keep = np.isin(srcd, THEO_SOURCES)
        md, srcd = md[keep], srcd[keep]
        if estimator in ("theoh", "theoh_a"):
            k = switch_m(n)
            ok = 0.75 * md * d > k
            md, srcd = md[ok], srcd[ok]
        theo_vals, kf = _theo_part(cols_d, md, srcd, nd, estimator, kf_rule, w)
        ms = np.concatenate([ms[allan], md * d]).astype(np.int64)
        src = np.concatenate([src[allan], srcd])
        n_terms = np.concatenate([_n_terms(ms[: allan.sum()], src[: allan.sum()], n), _n_terms(md, srcd, nd)])
        tau = np.concatenate([ms[: allan.sum()] / fs, 0.75 * md * d / fs])
        values = np.empty((len(cols), ms.size))
        values[:, allan.sum() :] = theo_vals
        is_theo = np.isin(src, THEO_SOURCES)
        allan = ~is_theo
    else:
        values = np.empty((len(cols), ms.size))
        values[:, is_theo], kf = _theo_part(cols, ms, src, n, estimator, kf_rule, w)
        tau, n_terms = _tau(ms, src, fs), _n_terms(ms, src, n)
    if np.any(allan):
        est = str(src[allan][0])
        values[:, allan] = allan_values(cols, n, 1, ms[allan], est, "fast", w)[:, :, 0]
    return Computed(tau=tau, values=values, n=n_terms, m=ms, source=src, kf=kf)


def dynamic_theo(
    cols, fs: float, window: int, hop: int, taus, method: str, workers, *, estimator: str, kf_rule: str = "textbook"
) -> Computed:
    """TheoH (DHVAR) or TheoH-A (DHVAR-A) of every window: values (axes, T, J), per-τ ``source``, kf
    (axes, J). Every window has its own bias ratio kf and its switch at 0.1·window·τ0."""
    if method != "fast":
        raise ParameterError(f"estimator {estimator!r} is computed with method='fast' only, got method={method!r}")
    fs = check_fs(fs)
    _check_kf_rule(kf_rule)
    ms, src = theo_ms(taus, window, fs, estimator)
    w = resolve_workers(workers)
    ka, kt = kf_indices(window, kf_rule)
    is_theo = src == "theobr"
    theo_m = ms[is_theo]
    all_theo = np.unique(np.concatenate([theo_m, kt]))
    th = _core.theo1_dynamic(cols, window, hop, [int(m) for m in all_theo], w)
    av = allan_values(cols, window, hop, ka, "oavar", "fast", w)
    kf = _kf(av, th[:, np.searchsorted(all_theo, kt), :])  # (axes, J)
    n_win = th.shape[2]
    values = np.empty((len(cols), ms.size, n_win))
    values[:, is_theo, :] = th[:, np.searchsorted(all_theo, theo_m), :] * kf[:, None, :]
    allan = ~is_theo
    if np.any(allan):
        est = str(src[allan][0])
        values[:, allan, :] = allan_values(cols, window, hop, ms[allan], est, "fast", w)
    return Computed(tau=_tau(ms, src, fs), values=values, n=_n_terms(ms, src, window), m=ms, source=src, kf=kf)


def _theoh_m(estimator: str):
    return lambda taus, n, fs: theo_ms(taus, n, fs, estimator)[0]


_THEO_OPTIONS = {"kf_rule": "textbook", "decimate": "auto"}
register(
    Estimator(
        name="theo1",
        label="Theo1",
        family="theo",
        static=partial(static_theo, estimator="theo1"),
        edf=edf_theo1,
        estimates_allan=False,
        theo_tau=True,
        options=_THEO_OPTIONS,
    )
)
register(
    Estimator(
        name="theobr",
        label="bias-removed Theo1 (TheoBR)",
        family="theo",
        static=partial(static_theo, estimator="theobr"),
        edf=edf_theo1,
        theo_tau=True,
        options=_THEO_OPTIONS,
    )
)
register(
    Estimator(
        name="theoh",
        label="TheoH (overlapping Allan ≤ 10 % of the span, TheoBR beyond)",
        family="theo",
        static=partial(static_theo, estimator="theoh"),
        dynamic=partial(dynamic_theo, estimator="theoh"),
        options=_THEO_OPTIONS,
        resolve_m=_theoh_m("theoh"),
    )
)
register(
    Estimator(
        name="theoh_a",
        label="TheoH-A (classic Allan ≤ 10 % of the window, TheoBR beyond)",
        family="theo",
        dynamic=partial(dynamic_theo, estimator="theoh_a"),
        options={"kf_rule": "textbook"},
        noise_id="avar",
        resolve_m=_theoh_m("theoh_a"),
    )
)
