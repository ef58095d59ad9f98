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
  standard errors (as impulsive noise below; a line visible only in a filter's noise null moves none). Each entry
  says why the ``"sinusoid"`` candidate did not keep it (``"not_kept"``, also in ``"what"``: :func:`why_not_kept`)
  — the reason it turned down a line it tested there (the held-out error, …), its search found it but no step
  reached it, its search did not find it, or the candidate was not run — so a line named here is never one refine
  seems not to have looked at.
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
  the change points refine accepted; a split of the record or a stretch louder or quieter than the rest): an entry
  with the time region ``"t"`` (lo, hi) s where the level is higher (or the stretch), where the change exceeds the
  final model's held-out error.
- ``"line"`` — an accepted line whose complex amplitude changes along the final samples (:mod:`._line_check`:
  each sinusoid, and the strongest line of each family removed in time), said where the change moves the
  Allan deviation beyond the final model's held-out error; ``"t"`` the side after the change.
- ``"channels"`` — a coupling to a channel of ``channels=`` left in the final samples (the regression's tests:
  the Whittle GLS for a slow channel — the pair of any phase and the in-phase test, each at 0.8/1.8 of the share,
  and where the pair fails the quadratic's at 0.2/1.8, :data:`SLOW_SPLIT` —, within blocks for a fast one).
- ``"channel_shape"`` (domain ``"channels"``) — the final samples' dependence on a slow channel's *value* beyond
  the terms kept for it (:mod:`._channel_shape`, :func:`allanite.model._shape.shape_test`: steps of the rate where
  the channel crosses its quantiles, or its square where not kept, the best two by a greedy search calibrated on
  draws of their scores): a staircase, a thermostat, a compensation table with steps that a straight line leaves
  uncorrelated with the channel; ``"channel"``, ``"cuts"`` [(value, step)] where it departs.
- ``"follows"`` (domain ``"channels"``) — an accepted line (a ``"periodic"`` family removed in time, its strongest
  line; a ``"sinusoid"``) that a channel no regression step uses carries coherently (:mod:`._channel_follows`: the
  coherence over segments against its Beta null and the channel's own line at f0, both at the share split over the
  pairs): one effect read twice, a regression on the channel may be the better reading; ``"channel"``,
  ``"effect"``, ``"f0"``, ``"coherence"``. Its share is conditional on the line (:data:`.levels.CONDITIONAL_SHARES`).
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

import numpy as np
from scipy.stats import t as t_dist

from .. import channels, lines, tracing
from .._shares import FIRST_QUADRATIC
from ._channel_follows import follows_check
from ._channel_shape import channel_shape_check
from ._curve_checks import MAX_REGIONS, allan_check, allan_family, fit_check
from ._line_check import line_check
from ._mean_step import mean_step_check
from ._mean_steps import steps_check
from ._missing_context import MissingContext
from ._quality import clipped_check, held_check
from ._segments import explained_regions
from ._time_checks import drift_check, level_check, outliers_check
from .curvefit import base_name, chi2_dof_between
from .levels import alpha
from .scoring import MATERIAL_Z, curve_change_z

__all__ = ["MissingContext", "CHECKS", "unexplained", "MAX_REGIONS", "allan_family", "why_not_kept"]

#: Leftover lines closer than 1/LINE_GAP of their frequency, or LINE_GAP_BINS bins, are reported as one band.
LINE_GAP = 16
LINE_GAP_BINS = 8


# read here by _lines and _channels (a test patches it here); the other families take
# :func:`._missing_context.chi2_dof`, the same
def _chi2_dof(ctx: MissingContext, lo: float, hi: float) -> float:
    return chi2_dof_between(ctx.curve.tau, ctx.sol.z, lo, hi)


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
        band = (f_lo - 2 * grp[0]["bin_hz"], f_hi + 2 * grp[-1]["bin_hz"])  # as a sinusoid accounts for a line
        why = why_not_kept(ctx, band, len(grp))
        out.append(
            {
                "domain": "psd",
                "tau": (lo, hi),
                "band_hz": (f_lo - grp[0]["bin_hz"], f_hi + grp[-1]["bin_hz"]),
                "chi2_dof": _chi2_dof(ctx, lo, hi) if hi >= lo else None,
                "what": f"{what} — {why}",
                "not_kept": why,
                "lines": len(grp),
                "rms": rms,
                "amplitude": float(amps.max()),
                "statistic": float(top["psd_ratio"]),
                "threshold": float(top["threshold"]),
                "alpha": a,
            }
        )
    return out + [_slow_line(ctx, ln) for ln in ctx.slow_lines]


#: why a line is left where no step could take it: the words of :func:`why_not_kept` and :func:`_slow_line`
NO_SINUSOID = "the sinusoid candidate was not among the candidates refine ran"


def _slow_line(ctx: MissingContext, ln: dict) -> dict:
    """A line of few cycles the line search found by its test in time (at that test's own share of ``level``) and
    no step took (the ``"sinusoid"`` candidate left out, or it turned the line down: a line of few cycles and a
    drift or the noise's slow terms are nearly collinear): below the spectrum's reach, so the PSD's lines never name
    it — its band, the τ of its signature (0.2/f0 … 1/f0, as a line's, period/2 within), its test's numbers and
    p-value, and why no step kept it."""
    f0, slow = float(ln["f0"]), ln["slow"]
    lo, hi = max(0.2 / f0, float(ctx.curve.tau[0])), min(1.0 / f0, float(ctx.curve.tau[-1]))
    why = NO_SINUSOID if ctx.offered_lines is None else why_not_kept(ctx, tuple(ln["f0_interval"]))
    p = slow.get("p_value")
    line = (
        f"a line of few cycles at {f0:.4g} Hz ({slow['cycles']:.1f} cycles in the record, amplitude "
        f"{float(ln['amplitude']):.3g}), found by its test in time (χ² {slow['statistic']:.3g} against "
        f"{slow['threshold']:.3g}" + ("" if p is None else f", p = {p:.2g}") + f") — {why}"
    )
    what = line if ctx.offered_lines is None else f"a slow periodic component may be present: {line}"
    return {
        "domain": "psd",
        "tau": (lo, hi),
        "band_hz": tuple(float(v) for v in ln["f0_interval"]),
        "chi2_dof": _chi2_dof(ctx, lo, hi) if hi >= lo else None,
        "what": what,
        "not_kept": why,
        "p_value": p,
        "lines": 1,
        "amplitude": float(ln["amplitude"]),
        "statistic": float(slow["statistic"]),
        "threshold": float(slow["threshold"]),
        "alpha": float(slow["alpha"]),
    }


def why_not_kept(ctx: MissingContext, band: tuple, n_lines: int = 1) -> str:
    """Why the ``"sinusoid"`` candidate did not keep the line(s) in ``band`` (Hz), in words: the reason it gave
    for turning down a line it tested there (``ctx.considered``: the held-out error, a parameter at its range's
    edge, another effect taken at that step), or that its search found the line but no step offered it (a step
    offers the strongest line not yet held that moves the Allan curve by MATERIAL_Z standard errors, and the
    steps end when one is turned down), or that its search did not find it, or that the candidate was left out —
    and first, that a line of few cycles there was left to the channel that explains it in time
    (:mod:`._slow_lines`)."""
    it = "it" if n_lines == 1 else "them"
    considered = ctx.considered.get("sinusoid", [])
    by_channel = [e for e in considered if "explained_by" in e and band[0] <= e["f0"] <= band[1]]
    if by_channel:  # a line of few cycles the removal in time left to a channel (:mod:`._slow_lines`)
        e = by_channel[0]
        f0, ch = e["f0"], e["explained_by"]
        return f"a line of few cycles there ({f0:.4g} Hz) was left to channel {ch!r}, which explains it in time"
    tried = [e for e in considered if "param" in e and band[0] <= e["param"] <= band[1]]
    if tried:
        e = max(tried, key=lambda e: e["statistic"] / max(e["threshold"], 1e-300))
        why = e.get("rejected", "not taken")
        must = " (a step must lower it)" if why.startswith("held-out error") else ""
        return f"tested as a sinusoid ({e['param']:.4g} Hz) and not kept: {why}{must}"
    if ctx.offered_lines is None:
        return f"{NO_SINUSOID}, so no line was tested"
    if any(band[0] <= f <= band[1] for f in ctx.offered_lines):
        return (
            f"the sinusoid search found {it} but no step tested {it}: a step offers the strongest line not yet held "
            f"that moves the Allan curve by {MATERIAL_Z:g} standard errors, and the steps ended before {it}"
        )
    return f"the sinusoid search (at the lines' share of level) did not find {it} before the final model's removals"


def _lines_move_curve(ctx: MissingContext, freqs: np.ndarray, amps: np.ndarray) -> bool:
    """Whether lines of amplitudes ``amps`` at ``freqs`` (Hz) move an estimate of the final curve by at least
    :data:`.scoring.MATERIAL_Z` standard errors under the final model — refine's own rule for a removal, as for
    impulsive noise (:func:`._time_checks.outliers_check`). Their Allan variance, averages of m samples:
    Σ A²·D_m(ν)²·sin²(πνm), D_m = sin(πνm)/(m·sin πν), ν = f/f_s (a sampled sinusoid's, exact, near f_s/2 too).
    Lines a moving average's noise nulls show (a sawtooth's folded harmonics of order ≈ 2000 at 100 Hz, amplitude
    3·10⁻⁵ against noise 0.04 per sample) are real but move no estimate of the curve: nothing the model misses."""
    m = np.maximum(np.round(ctx.curve.tau * ctx.fs), 1.0)[:, None]
    nu = np.asarray(freqs, dtype=np.float64)[None, :] / ctx.fs
    s1 = np.sin(np.pi * nu)
    dm = np.where(np.abs(s1) > 1e-300, np.sin(np.pi * nu * m) / (m * np.where(np.abs(s1) > 1e-300, s1, 1.0)), 1.0)
    change = np.sum(np.asarray(amps, dtype=np.float64) ** 2 * dm**2 * np.sin(np.pi * nu * m) ** 2, axis=1)
    return curve_change_z(ctx.curve, ctx.sol, change)[0] >= MATERIAL_Z


#: A slow channel's three tests share a_ch/SLOW_SPLIT each way: the pair and the in-phase test each at
#: (1 − FIRST_QUADRATIC) of it, the quadratic at FIRST_QUADRATIC of it — (2 − FIRST_QUADRATIC)·a_ch/SLOW_SPLIT ≤ a_ch.
SLOW_SPLIT = 2.0 - FIRST_QUADRATIC


def _channels(ctx: MissingContext, a: float) -> list[dict]:
    """A coupling to a channel of ``channels=`` left in the final samples (the regression candidate turned
    down or left out): a slow channel by the Whittle GLS of :func:`allanite.model.channels.regress_channel` — the
    pair, the in-phase test and, where the pair fails, the quadratic's (:data:`SLOW_SPLIT`) —, a fast one by the
    within-block t test — each at ``a`` split over the channels."""
    if ctx.y is None or not ctx.channels:
        return []
    a_ch, out = a / len(ctx.channels), []
    t_lo, t_hi = float(ctx.curve.tau[0]), float(ctx.curve.tau[-1])
    for name, ch in ctx.channels.items():
        coef_words = None
        if channels.is_slow(ch):
            # the coupling's test (channel and quadrature, 2 dof: any phase), the in-phase test alone (1 dof: more
            # power on a coupling without lag), each at 1 − FIRST_QUADRATIC of a_ch/SLOW_SPLIT, and where the pair
            # fails the quadratic's (a coupling mostly on (ch − mean)², whose linear part neither sees) at
            # FIRST_QUADRATIC of it, as the regression candidate decides: together at most a_ch
            r = channels.regress_channel(
                ctx.y, ch, ctx.fs, name=name, alpha=a_ch / SLOW_SPLIT, level=ctx.level, terms=("quadratic",)
            )
            hit, stat, thr = r.accepted, float(r.test["statistic"]), float(r.test["threshold"])
            one, quad = r.test["in_phase"], r.test.get("quadratic")
            if r.test.get("accepted_by") == "quadratic" and quad is not None:
                stat, thr = float(quad["statistic"]), float(quad["threshold"])
            if not hit and one["statistic"] > one["threshold"]:
                hit, stat, thr = True, float(one["statistic"]), float(one["threshold"])
            coef = float(r.params.get("coefficient", float("nan")))
            if r.test.get("accepted_by") == "quadratic" and "quadratic" in r.params:
                q = float(r.params["quadratic"])
                coef_words = f"through its square (≈ {q:.3g} {ctx.unit or 'rate unit'} per channel unit²)"
            lo = max(t_lo, min(t_hi, 0.1 * ctx.y.size / ctx.fs))  # a slow channel moves the longest τ
        else:
            rg = tracing.regression_fit(ctx.y, ch, 8)
            stat = abs(rg["coefficient"]) / rg["se"] if rg["se"] > 0 else 0.0
            thr = float(t_dist.isf(a_ch / 2, rg["dof"]))
            hit, coef, lo = stat > thr, float(rg["coefficient"]), t_lo
        if hit:
            how = coef_words or f"(≈ {coef:.3g} {ctx.unit or 'rate unit'} per channel unit)"
            what = f"the rate still follows channel {name!r} {how}"
            out.append(
                {"domain": "channels", "tau": (lo, t_hi), "band_hz": None, "chi2_dof": _chi2_dof(ctx, lo, t_hi)}
                | {"what": what, "statistic": stat, "threshold": thr, "alpha": a_ch}
            )
    return out


#: The checks, by the name of their share in :data:`.levels.SHARES` (``"unexplained:<name>"``; ``"follows"``'s is
#: conditional on an accepted line, :data:`.levels.CONDITIONAL_SHARES`).
CHECKS: dict[str, Callable[[MissingContext, float], list[dict]]] = {
    "allan": allan_check,
    "fit": fit_check,
    "psd": _lines,
    "time": drift_check,
    "mean": mean_step_check,
    "steps": steps_check,
    "level": level_check,
    "line": line_check,
    "channels": _channels,
    "channel_shape": channel_shape_check,
    "follows": follows_check,
    "outliers": outliers_check,
    "clipped": clipped_check,
    "held": held_check,
}


def unexplained(ctx: MissingContext) -> list[dict]:
    """Every check's regions, the largest misfit (statistic over threshold) first."""
    found = {name: check(ctx, alpha(f"unexplained:{name}", ctx.level)) for name, check in CHECKS.items()}
    # with change points: the departures only the louder segments carry are theirs (said on their steps)
    found["allan"], ctx.memo["change_point_regions"] = explained_regions(
        ctx, found["allan"], alpha("unexplained:allan", ctx.level)
    )
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
