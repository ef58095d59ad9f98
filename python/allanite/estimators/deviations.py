"""The deviation family beyond the Allan variance — registry entries over the Rust core.

Modified (MVAR) and time (TVAR = τ²/3·MVAR) variances, the Hadamard variances (HVAR classic, OHVAR
overlapping; OHVAR also over sliding windows: a dynamic Hadamard variance insensitive to rate ramps),
the total variances (TOTVAR, MTOTVAR, TTOTVAR = τ²/3·MTOTVAR, HTOTVAR) and the clock/telecom measures
MTIE and TIE rms. Definitions: NIST SP 1065 §5.2 (formulas at the top of each kernel in
``rust/core/src/deviations.rs`` and in ``docs/FORMULAS.md``); values are the definitions' — no bias
correction (Stable32 divides TOTVAR, MTOTVAR/TTOTVAR and HTOTVAR by noise-dependent bias factors,
:mod:`allanite.estimators._edf_deviations` has them). Which to use when:

- rate ramp or drift in the record → Hadamard (``"ohvar"``; its dynamic form for a drifting sensor);
- white vs flicker angle (phase) noise, which the Allan variance cannot tell apart → modified (``"mvar"``);
- the longest τ with the most confidence → total variances (``"totvar"``, ``"mtotvar"``, ``"htotvar"``)
  or the Theo family;
- clock and telecom specifications → TDEV (``"tvar"``), MTIE, TIE rms.

All take rate (fractional-frequency) samples, as every allanite estimator; MTIE and TIE rms are of the
angle (phase) x = Σ y/fs, in angle units: ``result.adev`` holds them (``result.avar`` their square).
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from typing import Any

import numpy as np

from .. import _core
from .._validate import resolve_workers
from ..errors import ParameterError
from . import _edf_deviations as edf_dev
from ._registry import Computed, Estimator, register
from .confidence import edf_greenhall
from .grid import m_grid, resolve_taus

__all__ = ["max_m", "n_terms", "DEVIATIONS", "GAP_ESTIMATORS", "GAP_DYNAMIC_ESTIMATORS", "gap_static", "gap_dynamic"]


def max_m(estimator: str, n: int) -> int:
    """Largest averaging factor of ``estimator`` for ``n`` rate samples (SP 1065's ranges)."""
    if estimator in ("mvar", "tvar", "mtotvar", "ttotvar"):
        return (n + 1) // 3
    if estimator in ("hvar", "ohvar", "htotvar"):
        return n // 3
    return n  # totvar, mtie, tierms: up to the record


def n_terms(estimator: str, n: int, ms: np.ndarray) -> np.ndarray:
    """Terms averaged per τ — Stable32's "#" column (N = n + 1 phase points)."""
    ms = np.asarray(ms, dtype=np.int64)
    big_n = n + 1
    if estimator in ("mvar", "tvar", "mtotvar", "ttotvar"):
        out = big_n - 3 * ms + 1
    elif estimator == "hvar":
        out = n // ms - 2
    elif estimator == "ohvar":
        out = big_n - 3 * ms
    elif estimator == "totvar":
        out = np.full(ms.shape, big_n - 2)
    elif estimator == "htotvar":
        out = np.where(ms == 1, big_n - 3, n - 3 * ms + 1)
    else:  # mtie, tierms: windows of m + 1 phase points
        out = big_n - ms
    return out.astype(np.int64)


def _resolve(estimator: str, taus, n: int, fs: float) -> np.ndarray:
    """m for ``taus`` on ``n`` samples, within the estimator's range (named grids stop there)."""
    top = min(max_m(estimator, n), n // 2)
    if top < 1:
        raise ParameterError(f"{estimator}: a record or window of {n} samples is too short (no valid m)")
    if isinstance(taus, str):
        return m_grid(taus, n, fs=fs, m_max=None if taus == "exp" else top)
    ms = resolve_taus(taus, n, fs)
    if ms[-1] > top:
        i = int(np.flatnonzero(ms > top)[0])
        raise ParameterError(
            f"taus[{i}] = {ms[i] / fs:g} s (m = {int(ms[i])}) is beyond {estimator}'s range for {n} samples: "
            f"m ≤ {top} (τ ≤ {top / fs:g} s)"
        )
    return ms


def _static(cols, fs, taus, workers, *, estimator: str) -> Computed:
    n = cols[0].size
    ms = _resolve(estimator, taus, n, fs)
    w = resolve_workers(workers)
    mlist = [int(m) for m in ms]
    tau = ms / fs
    if estimator in ("mtie", "tierms"):
        phase = [np.concatenate(([0.0], np.cumsum(c) / fs)) for c in cols]
        # held squared, so that result.adev is MTIE (TIE rms) and result.avar its square, like every deviation
        values = (_core.mtie_phase if estimator == "mtie" else _core.tierms_phase)(phase, mlist, w) ** 2
    elif estimator == "ttotvar":
        values = _core.ttotvar_static(cols, mlist, 1.0 / fs, w)
    elif estimator == "tvar":
        values = _core.deviation_static(cols, mlist, "mvar", w) * (tau**2 / 3.0)
    else:
        values = _core.deviation_static(cols, mlist, estimator, w)
    return Computed(tau=tau, values=values, n=n_terms(estimator, n, ms), m=ms)


#: Estimators computed with ``gaps="skip"`` (NaN-marked missing samples): the core's gap-aware kernels.
GAP_ESTIMATORS = (
    "oavar",
    "avar",
    "mvar",
    "tvar",
    "ohvar",
    "hvar",
    "totvar",
    "mtotvar",
    "ttotvar",
    "htotvar",
    "mtie",
    "tierms",
)


def gap_static(cols, fs: float, taus, workers, estimator: str) -> Computed:
    """``estimator`` of whole records with NaN-marked missing rate samples: every term that touches a
    missing sample is skipped; ``n`` (axes, T) is the number of complete terms per axis (0 → NaN)."""
    if estimator not in GAP_ESTIMATORS:
        raise ParameterError(
            f'gaps="skip" is supported by the estimators {", ".join(GAP_ESTIMATORS)}; got estimator={estimator!r} '
            '(use gaps="error" and analyse a stretch without gaps)'
        )
    n = cols[0].size
    ms = resolve_taus(taus, n, fs) if estimator in ("oavar", "avar") else _resolve(estimator, taus, n, fs)
    if estimator in ("mtie", "tierms"):
        # the phase as without gaps (a missing rate sample counts 0: the offset after it is unknown, and
        # only windows whose rate samples are all present — exact phase differences — are kept)
        phase = [np.concatenate(([0.0], np.cumsum(np.where(np.isnan(c), 0.0, c)) / fs)) for c in cols]
        gaps = [np.concatenate(([0], np.cumsum(np.isnan(c)))).astype(np.uint64) for c in cols]
        values, counts = _core.tie_gaps(phase, gaps, [int(m) for m in ms], estimator, resolve_workers(workers))
        return Computed(tau=ms / fs, values=values**2, n=counts, m=ms)
    # classic AVAR and HVAR: the OAVAR and OHVAR terms that start at multiples of m (cluster boundaries)
    core_name = {"tvar": "mvar", "ttotvar": "mtotvar"}.get(estimator, estimator)
    values, counts = _core.deviation_gaps(cols, [int(m) for m in ms], core_name, resolve_workers(workers))
    tau = ms / fs
    if estimator in ("tvar", "ttotvar"):
        values = values * (tau**2 / 3.0)
    return Computed(tau=tau, values=values, n=counts, m=ms)


#: Sliding-window estimators computed with ``gaps="skip"``.
GAP_DYNAMIC_ESTIMATORS = ("oavar", "ohvar")


def gap_dynamic(cols, fs: float, window: int, hop: int, ms, workers, estimator: str) -> Computed:
    """``estimator`` of every window of records with NaN-marked missing rate samples: each window's
    terms that touch a missing sample are skipped; ``n`` (axes, T, windows) counts the complete ones."""
    if estimator not in GAP_DYNAMIC_ESTIMATORS:
        raise ParameterError(
            f'davar(gaps="skip") is supported by the estimators {", ".join(GAP_DYNAMIC_ESTIMATORS)}; got '
            f'estimator={estimator!r} (use gaps="error" and analyse a stretch without gaps)'
        )
    ms = np.asarray(ms, dtype=np.int64)
    values, counts = _core.deviation_gaps_dynamic(
        cols, int(window), int(hop), [int(m) for m in ms], estimator, resolve_workers(workers)
    )
    return Computed(tau=ms / fs, values=values, n=counts, m=ms)


def _dynamic_ohvar(cols, fs, window, hop, taus, method, workers) -> Computed:
    if method != "fast":
        raise ParameterError(f"estimator 'ohvar' is computed with method='fast' only, got method={method!r}")
    ms = _resolve("ohvar", taus, window, fs)
    values = _core.ohvar_dynamic(cols, window, hop, [int(m) for m in ms], resolve_workers(workers))
    return Computed(tau=ms / fs, values=values, n=n_terms("ohvar", window, ms), m=ms)


def _edf_greenhall(alpha, m, n_phase, *, estimator: str):
    d, overlapping, modified = edf_dev.GREENHALL_PARAMETERS[estimator]
    return edf_greenhall(alpha, d, m, n_phase, overlapping=overlapping, modified=modified)


def _edf_formula(alpha, m, n_phase, *, fn):
    a, mm = np.broadcast_arrays(np.asarray(alpha), np.asarray(m))
    return np.array([fn(int(x), int(y), int(n_phase)) for x, y in zip(a.ravel(), mm.ravel())]).reshape(a.shape)


def _edf_htotvar(alpha, m, n_phase):
    a, mm = np.broadcast_arrays(np.asarray(alpha), np.asarray(m))
    out = np.empty(a.shape, dtype=np.float64)
    for idx in np.ndindex(a.shape):
        ai, mi = int(a[idx]), int(mm[idx])
        if edf_dev.htotvar_uses_ohvar_edf(ai, mi):
            out[idx] = _edf_greenhall(np.array([ai]), np.array([mi]), n_phase, estimator="ohvar")[0]
        else:
            out[idx] = edf_dev.edf_htotvar(ai, mi, int(n_phase))
    return out


def _edf_totvar(alpha, m, n_phase):
    """SP 1065's TOTVAR EDF for α ∈ {0, −1, −2}; for white and flicker angle noise (no formula) the
    overlapping Allan EDF, within 2.6 % of Stable32's bounds."""
    a, mm = np.broadcast_arrays(np.asarray(alpha), np.asarray(m))
    out = np.empty(a.shape, dtype=np.float64)
    for idx in np.ndindex(a.shape):
        ai, mi = int(a[idx]), int(mm[idx])
        if ai in (0, -1, -2):
            out[idx] = edf_dev.edf_totvar(ai, mi, int(n_phase))
        else:
            out[idx] = edf_greenhall(np.array([ai]), 2, np.array([mi]), n_phase, overlapping=True)[0]
    return out


#: name → (label, edf, estimates the Allan variance?)
DEVIATIONS: dict[str, tuple[str, Callable[..., Any] | None, bool]] = {
    "mvar": ("modified Allan variance (MVAR)", partial(_edf_greenhall, estimator="mvar"), False),
    "tvar": ("time variance (TVAR = τ²/3·MVAR)", partial(_edf_greenhall, estimator="tvar"), False),
    "hvar": ("Hadamard variance (HVAR, classic)", partial(_edf_greenhall, estimator="hvar"), False),
    "ohvar": ("overlapping Hadamard variance (OHVAR)", partial(_edf_greenhall, estimator="ohvar"), False),
    "totvar": ("total variance (TOTVAR)", _edf_totvar, False),
    "mtotvar": ("modified total variance (MTOTVAR)", partial(_edf_formula, fn=edf_dev.edf_mtotvar), False),
    "ttotvar": ("time total variance (TTOTVAR = τ²/3·MTOTVAR)", partial(_edf_formula, fn=edf_dev.edf_ttotvar), False),
    "htotvar": ("Hadamard total variance (HTOTVAR)", _edf_htotvar, False),
    "mtie": ("maximum time interval error (MTIE), angle units", None, False),
    "tierms": ("time interval error, rms (TIE rms), angle units", None, False),
}

for _name, (_label, _edf, _allan) in DEVIATIONS.items():
    register(
        Estimator(
            name=_name,
            label=_label,
            family="total" if "tot" in _name else ("tie" if _name in ("mtie", "tierms") else "deviation"),
            static=partial(_static, estimator=_name),
            dynamic=_dynamic_ohvar if _name == "ohvar" else None,
            edf=_edf,
            estimates_allan=_allan,
            resolve_m=partial(_resolve, _name) if _name == "ohvar" else None,
            noise_id="oavar",
        )
    )
