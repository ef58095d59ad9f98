"""What the final model still misses — ``Refinement.unexplained``, domain by domain, each at its share of ``level``.

After the last step every domain's calibrated test is run once more against the final model, whether or not its
candidate was allowed: what a test still finds is reported, not added. Each check spends its own share of
``level`` (:data:`.levels.SHARES`, the ``"unexplained:…"`` entries), so on a complete model the list is empty but
at that rate. Entries are dicts (largest misfit first) with ``"domain"``, ``"tau"`` (lo, hi) s, ``"t"`` (lo, hi) s
for a region along the record (the ``"level"`` check's; absent elsewhere), ``"band_hz"``
(lo, hi) or None (curve-only input), ``"chi2_dof"`` over that τ range of the dense curve (None where the evidence
is not on the curve), ``"what"`` in words, and the test's ``"statistic"``, ``"threshold"`` and ``"alpha"``.

- ``"allan"`` — the acceptance test itself (:class:`allanite.model.tracing.ScoreTest`: GLS score of one more
  non-negative column, the maximum over every curve candidate's family — sinusoids' nulls for curve-only input;
  with samples a line is the ``"psd"`` check's — and the start terms' own columns, bootstrapped under the final
  model, :func:`allan_family`); the region is where the winning column, with
  the model's fitted directions projected out, carries its weight, and further regions follow with the winner
  added to the model, at the same threshold; a region is reported only where the dense curve's χ²/dof there
  exceeds 1, and a region that overlaps one already found widens it (one region per misfit). The test adds
  non-negative columns, so it sees where the curve stands above the model: once it has fired, the runs of
  same-signed |z| > 2 on the dense curve that no region covers are reported too ("the model lies above the
  Allan curve" / "the Allan curve lies above the model"; no share of ``level`` spent). With samples the
  frequency band is refined on the PSD of the final residual samples: the part of ≈ 1/(2τ_hi) … 1/(2τ_lo)
  (widened ×2) that stands above the spectrum's running median.
- ``"fit"`` — curve-only input: the whole curve's GLS χ² once the model's fitted directions are refitted,
  two-sided (a model *above* the curve too), against the same bootstrap; it spends the shares of the checks
  that need samples (:data:`.levels.SAMPLE_CHECKS`). Its regions are the runs of same-signed |z| > 2 (domain
  ``"allan"``); a region the ``"allan"`` check already named is not repeated.
- ``"psd"`` — spectral lines of the final samples (:func:`allanite.model.lines.find_lines`: the line search of
  the periodic effect, afresh) that no sinusoid of the model accounts for; neighbouring lines (gaps ≤ f/16 or
  8 bins) are one entry, with its band, ``lines`` (how many), ``rms`` and the largest ``amplitude`` — where
  their Allan variance would move an estimate of the final curve by :data:`.scoring.MATERIAL_Z` of its
  standard errors (as impulsive noise below; a line visible only in a filter's noise null moves none).
- ``"time"`` — a warm-up drift left in the final samples (:func:`allanite.model.tracing.drift_fit` against its
  bootstrap threshold under the final model's slow terms).
- ``"mean"`` — one step of the mean along the final samples (:mod:`._mean_step`: the best split of its block
  means against a null from the final model refitted without the located step), said where the step moves the
  Allan deviation beyond the final model's held-out error; ``"t"`` the side after the step.
- ``"steps"`` — steps of the mean at one or several times (:mod:`._mean_steps`: outlying increments of the block
  means over their robust scale, several block lengths, a step-down; its null simulated under the final model,
  its slow terms at the upper end, and nearly pivotal — it does not hang on K), said where the located steps
  together move the Allan deviation beyond the held-out error; ``"steps"`` [(t, size)]. Not repeated where the
  ``"mean"`` check already said the one step it found.
- ``"level"`` — the noise level along the final samples (:func:`allanite.model.noise_level.level_test`, between
  the change points refine accepted): an entry with the time region ``"t"`` (lo, hi) s where the level is
  higher, where the change exceeds the final model's held-out error.
- ``"line"`` — an accepted line whose complex amplitude changes along the final samples (:mod:`._line_check`:
  each sinusoid, and the strongest line of each family removed in time), said where the change moves the
  Allan deviation beyond the final model's held-out error; ``"t"`` the side after the change.
- ``"channels"`` — a coupling to a channel of ``channels=`` left in the final samples (the regression's tests:
  the Whittle GLS for a slow channel — the pair of any phase and the in-phase test, each at half the share —,
  within blocks for a fast one).
- ``"outliers"`` — impulsive noise left in the final samples (:func:`allanite.model.outliers.outlier_test`).
- ``"clipped"`` — samples piled at the record's largest or smallest value, or held at one value longer than
  the record's quantisation gives, in the samples as given (:mod:`._quality`); ``"t"`` their first and last
  time, ``"value"``, ``"samples"``, ``"runs"``. Left in the record: said, not removed.
- ``"held"`` — consecutive equal samples beyond the ties the quantisation step predicts (:mod:`._quality`):
  a driver that repeats an output; ``"repeats"``, ``"expected"``, ``"fraction"``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from scipy import signal
from scipy.linalg import solve_triangular
from scipy.stats import t as t_dist

from ...analysis import avar
from .. import channels, lines, noise_level, outliers, tracing
from ..terms import design_matrix
from ._line_check import line_check
from ._mean_step import mean_step_check
from ._mean_steps import steps_check
from ._quality import clipped_check, held_check
from .calibrated import N_BOOT, curve_test
from .candidates import CURVE_CANDIDATES, families
from .changes import locate
from .curvefit import Curve, Solution, base_name, chi2_dof_between, theta_terms, upper_theta
from .levels import alpha
from .scoring import MATERIAL_Z, curve_change_z
from .words import heldout_clause, span_text

__all__ = ["MissingContext", "CHECKS", "unexplained", "MAX_REGIONS", "allan_family"]

#: Regions the curve check reports at most.
MAX_REGIONS = 3
#: A column's projected weight counts towards its region where it is at least this share of its peak.
REGION_SHARE = 0.3
#: Leftover lines closer than 1/LINE_GAP of their frequency, or LINE_GAP_BINS bins, are reported as one band.
LINE_GAP = 16
LINE_GAP_BINS = 8


@dataclass
class MissingContext:
    """The final state a check looks at: the curve and its fitted solution (terms ``start`` + ``effects``), the
    thinned τ, the final samples (None for curve-only input) and their rate, the channels, ``level``, and
    whether the five terms' covariance across τ is exact; ``unit`` the rate's unit when known."""

    curve: Curve
    thin: np.ndarray
    sol: Solution
    start: tuple
    effects: list
    y: np.ndarray | None
    fs: float
    level: float
    exact: bool
    channels: dict = field(default_factory=dict)
    unit: str | None = None
    #: what the checks computed once from the final samples (the Welch PSD of :func:`_band`)
    memo: dict = field(default_factory=dict)
    #: times (s) of the change points refine accepted: the noise level is checked between them
    change_times: list = field(default_factory=list)
    #: the final model's held-out RMS ADEV error (%), the yardstick of a level change's size (None: not known)
    heldout_pct: float | None = None
    #: the ``"periodic"`` families removed in time, as (fundamentals, line frequencies, line amplitudes, the
    #: removed component's samples): the ``"line"`` check tests each one's strongest line (:mod:`._line_check`)
    families: list = field(default_factory=list)
    #: the samples as refine was given them, before any removal in time (None for curve-only input): the
    #: clipped and held samples are looked for there (:mod:`._quality`)
    samples: np.ndarray | None = None
    #: True at the samples an accepted removal replaced (the ``"outliers"`` step's; None: none): the clipped
    #: and held checks leave them out
    replaced: np.ndarray | None = None


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


def _chi2_dof(ctx: MissingContext, lo: float, hi: float) -> float:
    return chi2_dof_between(ctx.curve.tau, ctx.sol.z, lo, hi)


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
    terms = design_matrix(sub.tau, sub.m, sub.fs, start)
    return np.column_stack([fam, terms]) if fam.size else terms


def _curve(ctx: MissingContext, a: float) -> list[dict]:
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
        if not _chi2_dof(ctx, lo, hi) > 1.0:
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
        "chi2_dof": _chi2_dof(ctx, lo, hi),
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
            reg["chi2_dof"] = _chi2_dof(ctx, a, b)
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
        ctx.memo["welch"] = signal.welch(y - y.mean(), fs=fs, nperseg=nper, detrend="linear")
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


def _line_groups(found: list[dict]) -> list[list[dict]]:
    """Lines sorted by frequency, in groups of neighbours: a line joins the group before it when the gap is at
    most 1/:data:`LINE_GAP` of its frequency or :data:`LINE_GAP_BINS` bins (a comb of leftover lines is one
    band to report, not one entry per line)."""
    groups: list[list[dict]] = []
    for ln in sorted(found, key=lambda d: d["f"]):
        if groups and ln["f"] - groups[-1][-1]["f"] <= max(ln["f"] / LINE_GAP, LINE_GAP_BINS * ln["bin_hz"]):
            groups[-1].append(ln)
        else:
            groups.append([ln])
    return groups


def _lines(ctx: MissingContext, a: float) -> list[dict]:
    """Lines of the final samples that no sinusoid of the model accounts for, one entry per group of neighbours
    (:func:`_line_groups`): its band, its number of ``lines``, their ``rms`` (√(Σ A²/2), rate unit) and largest
    ``amplitude``; the statistic and threshold of its strongest line."""
    if ctx.y is None:
        return []
    have = [p for k, p in ctx.effects if base_name(k) == "sinusoid"]
    left = [
        ln
        for ln in lines.find_lines(ctx.y, ctx.fs, a)["lines"]
        if not any(abs(ln["f"] - f) <= 2 * ln["bin_hz"] for f in have)
    ]
    out = []
    for grp in _line_groups(left):
        f_lo, f_hi = float(grp[0]["f"]), float(grp[-1]["f"])
        top = max(grp, key=lambda d: d["psd_ratio"])
        amps = np.array([d["amplitude"] for d in grp])
        if not _lines_move_curve(ctx, np.array([d["f"] for d in grp]), amps):
            continue
        rms = float(math.sqrt(np.sum(amps**2) / 2.0))
        lo, hi = max(0.2 / f_hi, float(ctx.curve.tau[0])), min(1.0 / f_lo, float(ctx.curve.tau[-1]))
        if len(grp) == 1:
            what = f"a spectral line at {f_lo:.4g} Hz (amplitude {amps[0]:.3g})"
        else:
            what = f"{len(grp)} spectral lines at {f_lo:.4g}–{f_hi:.4g} Hz (rms {rms:.3g}, largest {amps.max():.3g})"
        out.append(
            {
                "domain": "psd",
                "tau": (lo, hi),
                "band_hz": (f_lo - grp[0]["bin_hz"], f_hi + grp[-1]["bin_hz"]),
                "chi2_dof": _chi2_dof(ctx, lo, hi) if hi >= lo else None,
                "what": what,
                "lines": len(grp),
                "rms": rms,
                "amplitude": float(amps.max()),
                "statistic": float(top["psd_ratio"]),
                "threshold": float(top["threshold"]),
                "alpha": a,
            }
        )
    return out


def _lines_move_curve(ctx: MissingContext, freqs: np.ndarray, amps: np.ndarray) -> bool:
    """Whether lines of amplitudes ``amps`` at ``freqs`` (Hz) move an estimate of the final curve by at least
    :data:`.scoring.MATERIAL_Z` standard errors under the final model — refine's own rule for a removal, as for
    impulsive noise (:func:`_moves_curve`). Their Allan variance, averages of m samples: Σ A²·D_m(ν)²·sin²(πνm),
    D_m = sin(πνm)/(m·sin πν), ν = f/f_s (a sampled sinusoid's, exact, near f_s/2 too). Lines a moving average's
    noise nulls show (a sawtooth's folded harmonics of order ≈ 2000 at 100 Hz, amplitude 3·10⁻⁵ against
    noise 0.04 per sample) are real but move no estimate of the curve: nothing the model misses."""
    m = np.maximum(np.round(ctx.curve.tau * ctx.fs), 1.0)[:, None]
    nu = np.asarray(freqs, dtype=np.float64)[None, :] / ctx.fs
    s1 = np.sin(np.pi * nu)
    dm = np.where(np.abs(s1) > 1e-300, np.sin(np.pi * nu * m) / (m * np.where(np.abs(s1) > 1e-300, s1, 1.0)), 1.0)
    change = np.sum(np.asarray(amps, dtype=np.float64) ** 2 * dm**2 * np.sin(np.pi * nu * m) ** 2, axis=1)
    return curve_change_z(ctx.curve, ctx.sol, change)[0] >= MATERIAL_Z


def _fit(ctx: MissingContext, a: float) -> list[dict]:
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


def _level(ctx: MissingContext, a: float) -> list[dict]:
    """The noise level along the final samples (:func:`allanite.model.noise_level.level_test`: the Allan
    variance at τ₀ in blocks, a studentised CUSUM against its simulated null), between the change points refine
    accepted (``a`` split over the segments). Where it rejects: one entry with ``"t"`` the side of the largest
    change where the level is higher (s; the split located to the sample by
    :func:`.changes.locate` within its two blocks), the ratio of the Allan deviations at τ₀ and
    ``"departure_pct"``, how far the side further from the record's level (the length-weighted mean) departs
    from it in Allan deviation at τ₀.

    A change is said only where that departure exceeds the final model's held-out RMS ADEV error
    (``heldout_pct``): on 10⁶ samples the test resolves level changes of 1–2 % (the ADIS16405 gyros'), real
    but smaller than what the model already misses on held-out data — not the thing to tell first."""
    if ctx.y is None:
        return []
    fs, y = ctx.fs, ctx.y
    cuts = [0] + sorted(int(round(t * fs)) for t in ctx.change_times if 0 < t * fs < y.size) + [y.size]
    a_seg, out = a / (len(cuts) - 1), []
    for i0, i1 in zip(cuts[:-1], cuts[1:]):
        r = noise_level.level_test(y[i0:i1], fs, a_seg, t0=i0 / fs)
        if r is None or not r["rejected"]:
            continue
        block = (r["right_s"][1] - r["left_s"][0]) / r["blocks"]
        lo_i = max(i0, int((r["split_s"] - block) * fs))
        split = lo_i / fs + locate(y[lo_i : min(i1, int((r["split_s"] + block) * fs))], 1, fs)[0]
        left, right = (r["left_s"][0], split), (split, r["right_s"][1])
        hi_side, lo_side, ratio = (right, left, r["ratio"]) if r["ratio"] >= 1 else (left, right, 1 / r["ratio"])
        share_hi = (hi_side[1] - hi_side[0]) / max(r["right_s"][1] - r["left_s"][0], 1e-300)
        mean = share_hi * ratio**2 + (1 - share_hi)  # the record's AVAR at τ₀ in units of the lower side's
        departure = 100 * max(ratio / math.sqrt(mean) - 1, 1 - 1 / math.sqrt(mean))
        if ctx.heldout_pct is not None and not departure > ctx.heldout_pct:
            continue
        tau = float(ctx.curve.tau[0])
        what = (
            f"the noise level changes along the record: {ratio:.2f}× the Allan deviation at τ₀ of "
            f"t {span_text(*lo_side)} s ({departure:.2g} % off the record's level"
            + heldout_clause(ctx.heldout_pct)
            + ")"
        )
        out.append(
            {"domain": "level", "tau": (tau, tau), "t": hi_side, "band_hz": None, "chi2_dof": None}
            | {"what": what, "ratio": ratio, "departure_pct": departure, "heldout_pct": ctx.heldout_pct}
            | {"statistic": r["statistic"], "threshold": r["threshold"], "alpha": a_seg}
        )
    return out


def _drift(ctx: MissingContext, a: float) -> list[dict]:
    if ctx.y is None:
        return []
    y, fs = ctx.y, ctx.fs
    dr = tracing.drift_fit(y, fs)
    theta_null = upper_theta(ctx.curve, ctx.sol, ctx.start, ctx.effects, theta_terms(ctx.sol, ctx.start, ctx.effects))
    thr = tracing.drift_threshold(y.size, fs, ctx.start, theta_null, a, seed=7919)
    if not (dr["statistic"] > thr and not dr["at_edge"]):
        return []
    lo, hi = min(dr["T"] / 2, float(ctx.curve.tau[-1])), float(ctx.curve.tau[-1])
    return [
        {
            "domain": "time",
            "tau": (lo, hi),
            "band_hz": (0.0, 1.0 / dr["T"]),
            "chi2_dof": _chi2_dof(ctx, lo, hi),
            "what": f"a warm-up-like drift along the record (T ≈ {dr['T']:.3g} s)",
            "statistic": float(dr["statistic"]),
            "threshold": float(thr),
            "alpha": a,
        }
    ]


def _channels(ctx: MissingContext, a: float) -> list[dict]:
    """A coupling to a channel of ``channels=`` left in the final samples (the regression candidate turned
    down or left out): a slow channel by the Whittle GLS of :func:`allanite.model.channels.regress_channel`, a
    fast one by the within-block t test — each at ``a`` split over the channels."""
    if ctx.y is None or not ctx.channels:
        return []
    a_ch, out = a / len(ctx.channels), []
    t_lo, t_hi = float(ctx.curve.tau[0]), float(ctx.curve.tau[-1])
    for name, ch in ctx.channels.items():
        if channels.is_slow(ch):
            # the coupling's test (channel and quadrature, 2 dof: any phase) and the in-phase test alone (1 dof: more
            # power on a coupling without lag), each at half the share — one of them may take a left coupling
            r = channels.regress_channel(ctx.y, ch, ctx.fs, name=name, alpha=a_ch / 2, level=ctx.level, terms=())
            hit, stat, thr = r.accepted, float(r.test["statistic"]), float(r.test["threshold"])
            one = r.test["in_phase"]
            if not hit and one["statistic"] > one["threshold"]:
                hit, stat, thr = True, float(one["statistic"]), float(one["threshold"])
            coef = float(r.params.get("coefficient", float("nan")))
            lo = max(t_lo, min(t_hi, 0.1 * ctx.y.size / ctx.fs))  # a slow channel moves the longest τ
        else:
            rg = tracing.regression_fit(ctx.y, ch, 8)
            stat = abs(rg["coefficient"]) / rg["se"] if rg["se"] > 0 else 0.0
            thr = float(t_dist.isf(a_ch / 2, rg["dof"]))
            hit, coef, lo = stat > thr, float(rg["coefficient"]), t_lo
        if hit:
            what = f"the rate still follows channel {name!r} (≈ {coef:.3g} {ctx.unit or 'rate unit'} per channel unit)"
            out.append(
                {"domain": "channels", "tau": (lo, t_hi), "band_hz": None, "chi2_dof": _chi2_dof(ctx, lo, t_hi)}
                | {"what": what, "statistic": stat, "threshold": thr, "alpha": a_ch}
            )
    return out


def _outliers(ctx: MissingContext, a: float) -> list[dict]:
    """Samples beyond the Gaussian noise left in the final samples (:func:`allanite.model.outliers.outlier_test`
    on them): impulsive noise the model's Gaussian terms cannot describe — where removing it would move the
    final curve beyond its estimates' scatter, as refine asks of the removal itself; impulsive samples too
    few to move the curve are not something the model misses."""
    if ctx.y is None:
        return []
    r = outliers.outlier_test(ctx.y, ctx.fs, a)
    if not r["accepted"] or not _moves_curve(ctx, outliers.replace_outliers(ctx.y, r["flags"])):
        return []
    best = min(r["cuts"], key=lambda c: c["p_value"])
    tau = float(ctx.curve.tau[0])
    what = (
        f"impulsive noise: {int(r['flags'].sum())} samples ({r['rate']:.2g} of the record) beyond the Gaussian "
        f"noise's cut at {r['cut']:g} σ"
    )
    reg = {"domain": "outliers", "tau": (tau, tau), "band_hz": None, "chi2_dof": _chi2_dof(ctx, tau, tau)}
    return [reg | {"what": what, "statistic": float(best["count"]), "threshold": 2.0 * best["expected"], "alpha": a}]


def _moves_curve(ctx: MissingContext, clean: np.ndarray) -> bool:
    """Whether replacing the final samples by ``clean`` moves an estimate of the final curve by at least
    :data:`.scoring.MATERIAL_Z` standard errors under the final model (refine's own rule for the removal)."""
    cur = ctx.curve
    change = cur.avar - avar(clean, ctx.fs, taus=cur.tau).avar
    return curve_change_z(cur, ctx.sol, change)[0] >= MATERIAL_Z


#: The checks, by the name of their share in :data:`.levels.SHARES` (``"unexplained:<name>"``).
CHECKS: dict[str, Callable[[MissingContext, float], list[dict]]] = {
    "allan": _curve,
    "fit": _fit,
    "psd": _lines,
    "time": _drift,
    "mean": mean_step_check,
    "steps": steps_check,
    "level": _level,
    "line": line_check,
    "channels": _channels,
    "outliers": _outliers,
    "clipped": clipped_check,
    "held": held_check,
}


def unexplained(ctx: MissingContext) -> list[dict]:
    """Every check's regions, the largest misfit (statistic over threshold) first."""
    found = {name: check(ctx, alpha(f"unexplained:{name}", ctx.level)) for name, check in CHECKS.items()}
    if found["allan"]:  # the score test's regions and misfit runs already say where the curve departs
        found["fit"] = [r for r in found["fit"] if not any(_overlap(r, q) for q in found["allan"])]
    if found["mean"]:  # one step already said: the steps check repeats it unless it found others
        found["steps"] = [r for r in found["steps"] if not _same_step(r, found["mean"][0])]
    out = [reg for regs in found.values() for reg in regs]
    out.sort(key=lambda r: -r["statistic"] / max(r["threshold"], 1e-300))
    return out


def _same_step(steps: dict, mean: dict) -> bool:
    """Whether the ``"steps"`` entry ``steps`` holds only the ``"mean"`` entry's step (within one of its blocks)."""
    return all(abs(t - mean["t_step"]) <= steps["block_s"] for t, _d in steps["steps"])


def _overlap(r: dict, q: dict) -> bool:
    return bool(r["tau"][0] <= q["tau"][1] * (1 + 1e-9) and q["tau"][0] <= r["tau"][1] * (1 + 1e-9))
