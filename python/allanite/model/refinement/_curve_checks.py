"""The Allan curve's checks of ``unexplained``: ``"allan"``, the acceptance test itself against the final model
(:func:`allan_check`, its columns :func:`allan_family`), its regions, their bands and the misfit runs beside them;
``"fit"``, the whole curve's two-sided GLS χ² for curve-only input (:func:`fit_check`). What they say and why is
:mod:`.missing`'s docstring.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import signal
from scipy.linalg import solve_triangular

from .. import tracing
from .._chunked import welch_detrended
from ._missing_context import MissingContext, chi2_dof
from .calibrated import N_BOOT, curve_test
from .candidates import CURVE_CANDIDATES, families
from .curvefit import Curve, term_columns

__all__ = ["MAX_REGIONS", "allan_family", "allan_check", "fit_check"]

#: Regions the curve check reports at most.
MAX_REGIONS = 3
#: A column's projected weight counts towards its region where it is at least this share of its peak.
REGION_SHARE = 0.3


def _region_of(test: tracing.ScoreTest, col: np.ndarray) -> tuple[int, int]:
    """Indices (i, j) of the thinned τ run where column ``col``, the model's directions projected out, carries
    its weight (≥ REGION_SHARE of its peak, contiguous around the peak, in units of each estimate's SD)."""
    cw = solve_triangular(test.chol, col, lower=True)
    if test.q.shape[1]:
        cw = cw - test.q @ (test.q.T @ cw)
    back = np.abs(test.chol @ cw) / np.sqrt(np.maximum(np.sum(test.chol**2, axis=1), 1e-300))
    k = int(np.argmax(back))
    keep = back >= REGION_SHARE * back[k]
    i = k
    while i > 0 and keep[i - 1]:
        i -= 1
    j = k
    while j + 1 < back.size and keep[j + 1]:
        j += 1
    return i, j


def allan_family(sub: Curve, start: tuple, has_samples: bool) -> np.ndarray:
    """The columns the ``"allan"`` check maximises its score over on the thinned curve ``sub``: every curve
    candidate's family as the steps bootstrap it (a sinusoid by its nulls for curve-only input only) and the
    start terms' own columns.

    With samples a line is the ``"psd"`` check's, in the spectrum, as at the steps: on the thinned curve the
    sinusoids' nulls are contrasts between neighbouring τ, whose null distribution hangs on the estimates'
    correlation from one τ to the next — which the bootstrap takes from the *fitted* terms. A clean white
    record whose fit took a little flicker gets a correlation above its own, and the nulls alone gave p ≤ 0.05
    on 15 of 200 clean records (benches/results/refine_calibration.md)."""
    fam = families(sub, tuple(CURVE_CANDIDATES), has_samples)
    terms = term_columns(sub, start)
    return np.column_stack([fam, terms]) if fam.size else terms


def allan_check(ctx: MissingContext, a: float) -> list[dict]:
    sub = ctx.curve.subset(ctx.thin)
    fam = allan_family(sub, ctx.start, ctx.y is not None)
    test = curve_test(ctx.curve, ctx.thin, ctx.sol, ctx.start, ctx.effects, ctx.exact)
    thr = test.threshold(fam, a, N_BOOT, seed=7919)
    out: list[dict] = []
    for _ in range(MAX_REGIONS):
        stats = _statistics(test, fam, sub.avar - test.model)
        c = int(np.argmax(stats))
        if not stats[c] > thr:
            break
        i, j = _region_of(test, fam[:, c])
        lo, hi = float(sub.tau[i]), float(sub.tau[j])
        test = _with_column(test, fam[:, c])
        if not chi2_dof(ctx, lo, hi) > 1.0:
            continue  # a column the residual leans on where the curve itself is within its scatter
        if _merged(ctx, out, lo, hi, float(stats[c])):
            continue
        out.append(_allan_region(ctx, lo, hi, "the Allan curve departs from the model", float(stats[c]), thr, a))
    if out:  # the test rejected the model: say too where the curve's largest misfits are
        _misfit_runs(ctx, out, thr, a)
    return out


def _allan_region(ctx: MissingContext, lo: float, hi: float, what: str, statistic: float, thr: float, a: float) -> dict:
    """An ``"allan"`` entry of ``unexplained``: the τ region, its band (with samples), χ²/dof there, in words."""
    return {
        "domain": "allan",
        "tau": (lo, hi),
        "band_hz": None if ctx.y is None else _band(ctx, lo, hi),
        "chi2_dof": chi2_dof(ctx, lo, hi),
        "what": what,
        "statistic": statistic,
        "threshold": thr,
        "alpha": a,
    }


def _misfit_runs(ctx: MissingContext, out: list[dict], thr: float, a: float) -> None:
    """Once the curve test has rejected the final model, add (up to :data:`MAX_REGIONS` regions in all) the runs
    of same-signed normalised residuals beyond 2 on the dense curve that no region covers, the largest Σz²
    first, as regions of their own (statistic Σz², the test's threshold). The test adds one *non-negative*
    column at a time, so it sees where the curve stands above the model; a model held above the curve over a
    range (its terms pinned by the short τ: LN200 accelerometer y, z ≈ −68 … −4 at τ 1.3–655 s, χ²/dof 1785
    overall) would otherwise go unnamed while a small region elsewhere is reported. No share of ``level`` is
    spent: nothing is added unless the calibrated test already fired."""
    z, tau = ctx.sol.z, ctx.curve.tau
    runs, i = [], 0
    while i < z.size:
        j = i
        while j + 1 < z.size and abs(z[j + 1]) > 2 and np.sign(z[j + 1]) == np.sign(z[i]):
            j += 1
        if abs(z[i]) > 2:
            runs.append((float(np.sum(z[i : j + 1] ** 2)), i, j))
        i = j + 1
    for chi2, i, j in sorted(runs, reverse=True):
        lo, hi = float(tau[i]), float(tau[j])
        if len(out) >= MAX_REGIONS or chi2 <= thr:
            break
        if any(lo < reg["tau"][1] and reg["tau"][0] < hi for reg in out):
            continue
        what = "the model lies above the Allan curve" if z[i] < 0 else "the Allan curve lies above the model"
        out.append(_allan_region(ctx, lo, hi, what, chi2, thr, a))


def _merged(ctx: MissingContext, out: list[dict], lo: float, hi: float, stat: float) -> bool:
    """Whether τ (lo, hi) overlaps a region already in ``out``; if so that region becomes the union (its χ²/dof
    and band over the union, its statistic the larger). A later column that finds the same misfit again is
    one region, not two overlapping ones (IMAR gyro y: τ 0.005–0.08 s and 0.005–1.28 s)."""
    for reg in out:
        a, b = reg["tau"]
        if lo <= b * (1 + 1e-9) and a <= hi * (1 + 1e-9):
            a, b = min(a, lo), max(b, hi)
            reg["tau"] = (a, b)
            reg["chi2_dof"] = chi2_dof(ctx, a, b)
            reg["band_hz"] = None if ctx.y is None else _band(ctx, a, b)
            reg["statistic"] = max(reg["statistic"], stat)
            return True
    return False


def _statistics(test: tracing.ScoreTest, fam: np.ndarray, resid: np.ndarray) -> np.ndarray:
    """:meth:`ScoreTest.statistic` of every column of ``fam`` at once (0 for a column the model already spans)."""
    cw = solve_triangular(test.chol, fam, lower=True)
    rw = solve_triangular(test.chol, resid, lower=True)
    if test.q.shape[1]:
        cw = cw - test.q @ (test.q.T @ cw)
        rw = rw - test.q @ (test.q.T @ rw)
    nrm = np.linalg.norm(cw, axis=0)
    ok = nrm > 1e-3 * np.maximum(np.linalg.norm(solve_triangular(test.chol, fam, lower=True), axis=0), 1e-300)
    return np.where(ok, np.maximum(cw.T @ rw, 0.0) / np.maximum(nrm, 1e-300), 0.0) ** 2


def _with_column(test: tracing.ScoreTest, col: np.ndarray) -> tracing.ScoreTest:
    """``test`` with ``col`` among the model's fitted directions (a found region is not found again)."""
    cw = solve_triangular(test.chol, col[:, None], lower=True)
    basis = np.hstack([test.q, cw]) if test.q.shape[1] else cw
    test.q = np.linalg.qr(basis)[0]
    return test


def _band(ctx: MissingContext, tau_lo: float, tau_hi: float) -> tuple[float, float]:
    """≈ 1/(2τ_hi) … 1/(2τ_lo), narrowed to the part of it (widened ×2) where the final samples' Welch PSD
    stands above its running median by more than its own scatter; the nominal band where nothing does."""
    y, fs = ctx.y, ctx.fs
    assert y is not None
    f_lo, f_hi = 0.5 / tau_hi, min(0.5 / tau_lo, 0.5 * fs)
    nper = int(min(2**14, 2 ** int(math.log2(max(y.size // 16, 256)))))
    if "welch" not in ctx.memo:  # one spectrum for every region
        ctx.memo["welch"] = _welch_linear(y, fs, nper)
    f, p = ctx.memo["welch"]
    nseg = max(1, (y.size - nper) // (nper // 2) + 1)
    sel = (f >= f_lo / 2) & (f <= min(2 * f_hi, 0.5 * fs)) & (f > 0)
    if np.count_nonzero(sel) < 8:
        return (f_lo, f_hi)
    lp = np.log(p[sel])
    width = max(5, int(lp.size // 8) | 1)
    med = signal.medfilt(lp, width)
    up = np.flatnonzero(lp - med > 3.0 / math.sqrt(nseg) + 0.5)
    if up.size == 0:
        return (f_lo, f_hi)
    fsel = f[sel]
    return (float(fsel[up[0]]), float(fsel[up[-1]]))


def _welch_linear(y: np.ndarray, fs: float, nper: int) -> tuple[np.ndarray, np.ndarray]:
    """``scipy.signal.welch(y − mean, fs, nperseg=nper, detrend="linear")`` (Hann, one-sided density): the segments'
    least-squares lines taken off in closed form (:func:`allanite.model._chunked.welch_detrended`, as the line
    search's spectra) — the same numbers to rounding, without SciPy's least-squares solve over every segment (≈ 40 %
    of this spectrum's time on 10⁶ samples)."""
    if y.size < nper:
        return signal.welch(y - y.mean(), fs=fs, nperseg=nper, detrend="linear")
    win = signal.get_window("hann", nper)
    p = welch_detrended(y, win, nper, float(y.mean()))
    p *= 1.0 / (fs * float(win @ win)) / ((y.size - nper) // (nper // 2) + 1)
    p[1:-1] *= 2.0  # one-sided (the Nyquist bin of an even nper once)
    return np.arange(p.size) * fs / nper, p


def fit_check(ctx: MissingContext, a: float) -> list[dict]:
    """Curve-only input: the GLS χ² of the whole thinned curve once the model's fitted directions are refitted
    (:meth:`allanite.model.tracing.ScoreTest.gls_chi2`, two-sided), against its bootstrap under the final
    model (the draws of the ``"allan"`` check). Where it rejects, the runs of same-signed |z| > 2 on the curve
    are the regions (the largest Σz² first; the whole τ range where the misfit is spread thin), whichever side
    of the model the curve lies. With samples its share goes to the checks that need them
    (:data:`.levels.SAMPLE_CHECKS`): the dense curve's neighbouring τ are contrasts whose null distribution the
    bootstrap does not reproduce (see :func:`allan_family`)."""
    if ctx.y is not None:
        return []
    test = curve_test(ctx.curve, ctx.thin, ctx.sol, ctx.start, ctx.effects, ctx.exact)
    stat = test.gls_chi2(ctx.curve.subset(ctx.thin).avar)
    null = np.sort(test.null_chi2(N_BOOT, seed=7919))
    thr = float(null[min(math.ceil((null.size + 1) * (1.0 - a) - 1e-9), null.size) - 1])
    if not stat > thr:
        return []
    base = {"domain": "allan", "band_hz": None, "statistic": stat, "threshold": thr, "alpha": a}
    out: list[dict] = []
    _misfit_runs(ctx, out, 0.0, a)
    for reg in out:
        reg |= base | {"what": reg["what"] + " (two-sided test of the whole curve)"}
    if not out:  # spread thin: no run beyond 2 — its size is the GLS χ², not the diagonal χ²/dof over τ
        lo, hi = float(ctx.curve.tau[0]), float(ctx.curve.tau[-1])
        dof = ctx.thin.size - test.q.shape[1]
        what = (
            f"the Allan curve departs from the model over its whole range, no τ by more than 2 SE: GLS χ² "
            f"{stat:.3g} on {dof} dof under the estimates' covariance (threshold {thr:.3g}; two-sided test of the "
            "whole curve)"
        )
        out.append(base | {"tau": (lo, hi), "chi2_dof": None, "what": what})
    return out
