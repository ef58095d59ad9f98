"""The final samples' checks of ``unexplained`` along the record: ``"level"``, the noise level between the change
points (:func:`level_check`); ``"time"``, a warm-up drift left (:func:`drift_check`); ``"outliers"``, impulsive
noise left where removing it would move the curve (:func:`outliers_check`). What they say and why is
:mod:`.missing`'s docstring.
"""

from __future__ import annotations

import math

import numpy as np

from ...analysis import avar
from .. import noise_level, outliers, tracing
from ._missing_context import MissingContext, chi2_dof
from .changes import locate
from .curvefit import theta_terms, upper_theta
from .scoring import MATERIAL_Z, curve_change_z
from .words import heldout_clause, span_text

__all__ = ["level_check", "drift_check", "outliers_check"]


def level_check(ctx: MissingContext, a: float) -> list[dict]:
    """The noise level along the final samples (:func:`allanite.model.noise_level.level_test`: the Allan
    variance at τ₀ in blocks, the largest studentised sum over a run of blocks against its simulated null: a split
    of the record or a stretch louder or quieter than the rest), between the change points refine accepted (``a``
    split over the segments). Where it rejects: one entry with ``"t"`` the side of the largest change where the
    level is higher (s; the split located to the sample by :func:`.changes.locate` within its two blocks), or the
    stretch (each end located so; louder or quieter, its ratio read on the located stretch's squared
    differences), the ratio of the Allan deviations at τ₀ and
    ``"departure_pct"``, how far the side further from the record's level (the length-weighted mean) departs
    from it in Allan deviation at τ₀.

    A change is said only where that departure exceeds the final model's held-out RMS ADEV error
    (``heldout_pct``): on 10⁶ samples the test resolves level changes of 1–2 % (the ADIS16405 gyros'), real
    but smaller than what the model already misses on held-out data — not the thing to tell first. With change
    points accepted the yardstick is the held-out error per segment with all of them
    (``segments_heldout_pct``): the record's curve held out by alternate blocks is the same with and without
    them by construction, so it counts the level changes they explain as missed (blind5's noise growing 5×
    smoothly: 19.6 % on the curve, 5.3 % per segment once four change points cut it; its growth within the
    segments, 10–20 %, went unsaid)."""
    if ctx.y is None:
        return []
    fs, y = ctx.fs, ctx.y
    cuts = [0] + sorted(int(round(t * fs)) for t in ctx.change_times if 0 < t * fs < y.size) + [y.size]
    a_seg, out = a / (len(cuts) - 1), []
    held = ctx.segments_heldout_pct if ctx.segments_heldout_pct is not None else ctx.heldout_pct
    clause = heldout_clause(held) if ctx.segments_heldout_pct is None else f"; held-out error per segment {held:.2g} %"
    for i0, i1 in zip(cuts[:-1], cuts[1:]):
        r = noise_level.level_test(y[i0:i1], fs, a_seg, t0=i0 / fs)
        if r is None or not r["rejected"]:
            continue
        span = (r["left_s"][0], r["right_s"][1])
        block = (span[1] - span[0]) / r["blocks"]
        if r.get("stretch_s") is None:
            split = _located(y, fs, r["split_s"], block, i0, i1)
            left, right = (span[0], split), (split, span[1])
            hi_side, lo_side, ratio = (right, left, r["ratio"]) if r["ratio"] >= 1 else (left, right, 1 / r["ratio"])
            share_hi = (hi_side[1] - hi_side[0]) / max(span[1] - span[0], 1e-300)
        else:  # a stretch louder or quieter than the rest: each of its ends located within its two blocks
            run = (_located(y, fs, r["stretch_s"][0], block, i0, i1), _located(y, fs, r["stretch_s"][1], block, i0, i1))
            d2 = np.diff(y[i0:i1]) ** 2
            inside = np.zeros(d2.size, dtype=bool)
            inside[int(run[0] * fs) - i0 : int(run[1] * fs) - i0] = True
            in_out = math.sqrt(d2[inside].mean() / d2[~inside].mean()) if 0 < inside.sum() < d2.size else r["ratio"]
            hi_side, lo_side, ratio = run, span, max(in_out, 1 / in_out)  # on the located stretch, not its blocks'
            share_hi = (run[1] - run[0]) / max(span[1] - span[0], 1e-300)
            share_hi = share_hi if in_out >= 1 else 1 - share_hi
            where = f"within t {span_text(*run)} s: {in_out:.2f}× the rest of the record's"
        mean = share_hi * ratio**2 + (1 - share_hi)  # the record's AVAR at τ₀ in units of the lower side's
        departure = 100 * max(ratio / math.sqrt(mean) - 1, 1 - 1 / math.sqrt(mean))
        if held is not None and not departure > held:
            continue
        tau = float(ctx.curve.tau[0])
        what = (
            (
                f"the noise level changes along the record: {ratio:.2f}× the Allan deviation at τ₀ of t "
                f"{span_text(*lo_side)} s"
                if r.get("stretch_s") is None
                else f"the noise level changes along the record: the Allan deviation at τ₀ {where}"
            )
            + f" ({departure:.2g} % off the record's level"
            + clause
            + ")"
        )
        out.append(
            {"domain": "level", "tau": (tau, tau), "t": hi_side, "band_hz": None, "chi2_dof": None}
            | {"what": what, "ratio": ratio, "departure_pct": departure, "heldout_pct": held}
            | {"statistic": r["statistic"], "threshold": r["threshold"], "alpha": a_seg}
        )
    return out


def _located(y: np.ndarray, fs: float, t: float, block: float, i0: int, i1: int) -> float:
    """A change of the noise level found at the block boundary ``t`` (s), located to the sample within the block
    on either side of it (:func:`.changes.locate`), within the samples ``i0:i1``."""
    lo_i = max(i0, int((t - block) * fs))
    return lo_i / fs + locate(y[lo_i : min(i1, int((t + block) * fs))], 1, fs)[0]


def drift_check(ctx: MissingContext, a: float) -> list[dict]:
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
            "chi2_dof": chi2_dof(ctx, lo, hi),
            "what": f"a warm-up-like drift along the record (T ≈ {dr['T']:.3g} s)",
            "statistic": float(dr["statistic"]),
            "threshold": float(thr),
            "alpha": a,
        }
    ]


def outliers_check(ctx: MissingContext, a: float) -> list[dict]:
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
    reg = {"domain": "outliers", "tau": (tau, tau), "band_hz": None, "chi2_dof": chi2_dof(ctx, tau, tau)}
    return [reg | {"what": what, "statistic": float(best["count"]), "threshold": 2.0 * best["expected"], "alpha": a}]


def _moves_curve(ctx: MissingContext, clean: np.ndarray) -> bool:
    """Whether replacing the final samples by ``clean`` moves an estimate of the final curve by at least
    :data:`.scoring.MATERIAL_Z` standard errors under the final model (refine's own rule for the removal)."""
    cur = ctx.curve
    change = cur.avar - avar(clean, ctx.fs, taus=cur.tau).avar
    return curve_change_z(cur, ctx.sol, change)[0] >= MATERIAL_Z
