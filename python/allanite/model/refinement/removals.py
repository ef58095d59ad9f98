"""Effects removed from the samples in time — one registry entry each, all through one protocol.

A remover looks at the current samples (after the removals before it) and yields a :class:`Removal` for each
component its calibrated test finds: the component itself (removed from the samples), how to refit it on
the held-in part's samples (for the held-out error), its parameters and intervals, its evidence with the
test's statistic, threshold and α (its share of ``level``, :mod:`.levels`), and how many numbers it fitted.
The loop accepts a removal when the held-out error falls (or its own held-out test in time passes: a white-like
component's, a warm-up's, a slow channel's, a line family's), and scores it on the original record's curve: the
model after the removal plus what the removal changed in the Allan curve, AVAR(y) − AVAR(y − component), cross
terms included.

- ``"drift"`` — a warm-up a·e^{−t/T} on block means, tested against block means drawn from the five-term fit
  with its slow terms at the upper end of what the curve allows (:func:`allanite.model.tracing.drift_fit`);
  a and T and their intervals by generalised least squares against the block means' covariance under the
  record's own noise terms (:mod:`allanite.model.warmup`: flicker and random walk tie the block means together,
  and an ordinary fit's intervals then miss the truth); held out in time on its own time scale
  (:func:`allanite.model.warmup.warmup_heldout`: groups of block means no longer than T/2 interleaved, the
  held-out part's conditional χ² under that noise with and without the held-in part's fit); left to a channel
  whose regression, accepted on the samples as they are, leaves a record the drift test no longer accepts (a cold
  start's temperature swing);
- ``"regression"`` — the rate regressed on each channel of ``channels=``: a fast channel within blocks in time
  (t test with the blocks' effective dof), band by band where the coupling differs across frequency; a slow one
  (:func:`allanite.model.channels.is_slow`: a temperature), or a fast one whose within-block test has fewer
  than :data:`COLLAPSED_DOF` dof (its changes within one or two blocks), against the record's own noise by a
  Whittle GLS, with its optional terms (:func:`allanite.model.channels.regress_channel`); so is a fast channel
  whose within-block test accepts when that fit keeps an optional term (d(ch)/dt, a lag, a square: a chamber
  cycling many times).
- ``"outliers"`` — samples beyond what Gaussian noise predicts, replaced (:mod:`allanite.model.outliers`); first,
  since a spike reaches every other test;
- ``"periodic"`` — each family of spectral lines (harmonics, sidebands) removed by least squares at its frequencies
  (:mod:`allanite.model.periodic`), a family of harmonics by its waveform folded on the period where that predicts
  held-out samples better (:mod:`allanite.model.template`); last, on the samples the others left: a channel that
  cycles (a temperature) is its regression, not a line. The search's lone lines go to the ``"sinusoid"`` curve
  candidate (:attr:`RemovalContext.lines`): one search, one share of ``level``; so do the lines of a family whose
  removal is turned down (its phase does not carry across the record: narrowband power, not a line). A lone line
  whose frequency wanders is removed here instead, a family of one order with its phase tracked; and first, a family
  whose fundamental hunts — each harmonic found as several peaks across its smear, which the lattices split — is
  gathered on one lattice of its fundamental and removed with its phase tracked (:func:`._family_parts.hunting`).
- ``"telegraph"`` — a rate switching between two levels, its switches decoded and removed (:mod:`._telegraph`).

Removals run before the curve effects (a component left in the samples bends the curve every curve effect is
fitted against), in the order of :data:`REMOVALS`. A new one is one entry here and one share in
:data:`.levels.TIME_SHARES`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

import numpy as np
from scipy.stats import t as t_dist

from ...analysis import avar
from .. import channels, linefit, outliers, periodic, tracing, wander, warmup
from ._channel_order import strongest_first
from ._family_parts import family_out, folded_waveform, hunting, sinusoid_at
from ._slow_lines import explained_by_channel, slow_line_removal
from ._telegraph import telegraph_removal
from ._tracking import heldout_variance_ratio
from ._tracking import tracked as _tracked
from .calibrated import tested
from .curvefit import Curve, Solution, theta_terms, upper_theta
from .levels import alpha
from .scoring import HELDOUT_BLOCKS

__all__ = ["Removal", "RemovalContext", "REMOVALS", "REGRESSION_BLOCKS"]

#: Blocks in time of a regression (each de-meaned; SE from the blocks' scores, t with at most blocks − 1 dof).
REGRESSION_BLOCKS = 8


@dataclass
class Removal:
    """A component to remove from the samples.

    Attributes
    ----------
    effect : str
        The effect's name (a key of :data:`allanite.model.effects.EFFECTS`).
    component : ndarray
        What is removed: the samples become ``y - component``.
    refit : callable
        ``refit(samples, indices)`` fits the component on the held-in part's samples (at those sample indices
        of the record) and returns it as a function of sample indices, for the held-out error.
    params, intervals : dict
        The step's parameters and the intervals of the numeric ones.
    evidence : dict
        Where it was found, with ``"test"``: the statistic, its threshold and α.
    n_fitted : int
        Numbers fitted (for the degrees of freedom of χ²/dof after the removal).
    on_raw : bool
        Held out, the other part's *raw* curve is predicted either way; ``on_raw`` adds back the change the
        held-in part's correction made to its own curve (a component the two parts share, e.g. a multi-position
        profile's steps), else the change the held-in fit makes to the held-out part's curve (a slow channel, a
        warm-up: :meth:`.scoring.Split.corrected`).
    heldout_in_time : float, optional
        A held-out test in time that decides instead of the held-out Allan curve (accepted when < 1): for a
        white-like component, which changes the curve's level, not how well one part predicts the other's.
    on_curve : bool
        Judged on the record's Allan curve as well: accepted only when it moves an estimate there by at least
        :data:`.scoring.MATERIAL_Z` standard errors (a component found by a test in time alone — impulsive
        noise — may not matter to the curve at all).
    family : LineFamily, optional
        The periodic removal's family; if the removal is turned down, its lines stay for the ``"sinusoid"``
        curve candidate.
    """

    effect: str
    component: np.ndarray
    refit: Callable
    params: dict
    intervals: dict
    evidence: dict
    n_fitted: int
    on_raw: bool = False
    heldout_in_time: float | None = None
    on_curve: bool = False
    family: periodic.LineFamily | None = None


@dataclass
class RemovalContext:
    """What a remover sees: the current samples ``y`` (updated by the loop after each accepted removal),
    their curve and noise fit, the starting terms, the channels, ``level``, and ``consider(effect, entry)``
    to record a candidate its test turned down."""

    y: np.ndarray
    fs: float
    curve: Curve
    sol: Solution
    start: tuple
    channels: dict
    level: float
    consider: Callable[[str, dict], None]
    effects: list = field(default_factory=list)
    #: The line search's result (:func:`allanite.model.periodic.periodic_search`), once the periodic removal ran.
    lines: dict | None = None


def _drift(ctx: RemovalContext) -> Iterator[Removal]:
    """A warm-up drift: its time-domain evidence is unambiguous, and left in the samples it bends the long-τ
    curve that every curve effect is fitted against (its threshold comes from the five-term fit, which the
    drift itself inflates: conservative)."""
    y, fs = ctx.y, ctx.fs
    dr = tracing.drift_fit(y, fs)
    theta_null = upper_theta(ctx.curve, ctx.sol, ctx.start, ctx.effects, theta_terms(ctx.sol, ctx.start, ctx.effects))
    a = alpha("drift", ctx.level)
    thr_d = tracing.drift_threshold(y.size, fs, ctx.start, theta_null, a)
    if not (dr["statistic"] > thr_d and not dr["at_edge"]):
        ctx.consider("drift", {"T": dr["T"], "statistic": dr["statistic"], "threshold": thr_d})
        return
    t_s = np.arange(y.size) / fs
    span = y.size / fs
    pieces = HELDOUT_BLOCKS // 2
    w = warmup.warmup_fit(y, fs, warmup.noise_terms(y, fs), refit_noise=lambda z: warmup.noise_terms(z, fs))
    if w["at_edge"]:
        ctx.consider("drift", {"T": w["T"], "statistic": dr["statistic"], "threshold": thr_d, "at_edge": True})
        return
    channel = _channel_explaining(ctx, thr_d)
    if channel is not None:
        ctx.consider("drift", {"T": w["T"], "statistic": dr["statistic"], "threshold": thr_d} | channel)
        return

    # held out in time on the warm-up's own time scale (the Allan curve's alternate eighths put a warm-up shorter
    # than one into one part alone: tests/test_warmup_heldout.py)
    held = warmup.warmup_heldout(y, fs, w["noise"], w["T"], w["ramp"])
    held_ev = {
        "ratio": float(held["ratio"]),
        "z": float(held["z"]),
        "z_min": warmup.HELDOUT_Z,
        "group_s": float(held["group_s"]),
        "fits": [(float(a), float(t_c)) for a, t_c in held["fits"]],
    }
    if not held["z"] >= warmup.HELDOUT_Z:
        why = f"held out in time: z {held['z']:.3g} < {warmup.HELDOUT_Z:g} (ratio {held['ratio']:.3g})"
        ctx.consider("drift", {"T": w["T"], "statistic": dr["statistic"], "threshold": thr_d, "rejected": why})
        return

    def refit(z, idx):
        g = warmup.warmup_component(z, idx / fs, w["noise"], span, pieces, ramp=w["ramp"])
        return lambda i: g(i / fs)

    yield Removal(
        "drift",
        w["amplitude"] * np.exp(-t_s / w["T"]),
        refit,
        {"amplitude": w["amplitude"], "T": w["T"]},
        {"amplitude": w["amplitude_interval"], "T": w["T_interval"]},
        {
            "domain": "time",
            "test": tested("statistic", dr["statistic"], thr_d, a),
            "noise": w["noise"],  # the noise terms the block means were weighed against (base form)
            # the Cramér–Rao bound of T and a under those terms (relative sd): what any unbiased estimate can do
            "bound": warmup.warmup_crlb(span, w["amplitude"], w["T"], w["noise"], ramp=w["ramp"]),
            "heldout_in_time": held_ev,
        },
        2,
        heldout_in_time=held["ratio"],
    )


#: Below this many degrees of freedom (the blocks' effective number − 1) the within-block t test of a channel is
#: powerless — its changes sit within one or two of the blocks (a temperature swinging at a cold start), the t
#: threshold 20–170 — and the channel is tested as a slow one, by the Whittle GLS, in its stead.
COLLAPSED_DOF = 2.0


def _channel_explaining(ctx: RemovalContext, thr_d: float) -> dict | None:
    """The channel that explains a warm-up the drift test found, or None: a regression on it accepted by its own
    test on the samples as they are, after whose removal the drift test no longer accepts (a gyro's warm-up is
    its temperature settling; given the temperature, a cold start's swing is its coupling, not a drift in time —
    and a warm-up the channel does not carry stays a drift: tested first, as before, the regression then on
    what the drift left). Only through the terms the regression claims: a lag profiled for the removal but not
    resolved by its test does not count."""
    if not ctx.channels:
        return None
    quiet = dataclasses.replace(ctx, consider=lambda _effect, _entry: None)
    for rem in _regression(quiet):
        if "lag" in rem.evidence:
            # through a lag its test did not resolve, a cold start's temperature is itself a warm-up of the lag's
            # time constant: what the record cannot tell apart is no reason to give the drift up
            continue
        after = tracing.drift_fit(ctx.y - rem.component, ctx.fs)
        if not after["statistic"] > thr_d:
            return {"explained_by": rem.params["channel"], "statistic_without_channel": after["statistic"]}
    return None


def _regression(ctx: RemovalContext) -> Iterator[Removal]:
    """Each channel on the samples with the channels taken before it removed, the strongest first
    (:mod:`._channel_order`): a component a channel explains (a multi-position profile's steps, a temperature's
    swing) bends the curve as a Gauss–Markov term or a random walk would, and fitted first those would take it;
    its test is in time (within blocks), independent of the curve."""
    yield from strongest_first(ctx, _one_channel)


def _one_channel(ctx: RemovalContext, name: str, ch: np.ndarray) -> Iterator[Removal]:
    """One channel's regression on the current samples, at its share of the regression's α (at most one)."""
    fs, a = ctx.fs, alpha("regression", ctx.level)
    rg = None if channels.is_slow(ch) else tracing.regression_fit(ctx.y, ch, REGRESSION_BLOCKS)
    if rg is None or rg["dof"] < COLLAPSED_DOF:
        yield from _slow_regression(ctx, name, ch, a / len(ctx.channels))
        return
    # t with the blocks' effective number − 1 degrees of freedom (≤ REGRESSION_BLOCKS − 1)
    t_thr = t_dist.isf(a / (2 * len(ctx.channels)), rg["dof"])
    t_stat = abs(rg["coefficient"]) / rg["se"] if rg["se"] > 0 else 0.0
    ev = {"domain": "channels", "test": tested("t", t_stat, float(t_thr), a)}
    if not t_stat > t_thr:
        ctx.consider("regression", {"channel": name, "t": t_stat, "threshold": t_thr})
        return
    # the optional terms (d(ch)/dt, a lag, a square) by their own nested tests, as on a slow channel: a
    # thermal chamber cycling 7 times is fast by its share, and a within-block coefficient cannot carry them
    r = _with_terms(ctx, name, ch, a / len(ctx.channels), rg, t_thr)
    if r is not None:
        yield from _slow_regression(ctx, name, ch, a / len(ctx.channels), r)
        return
    # band by band where the coupling differs across frequency (the whole-record coefficient elsewhere)
    br = tracing.band_regression(ctx.y, ch, fs, a)
    own = [b for b in br["bands"] if b["own"]]
    if own:
        ev["bands"] = own

    def refit(z, idx, ch=ch, banded=bool(own)):
        if banded:
            used = tracing.band_regression(z, ch[idx], fs, a)["used"]
            return lambda i: tracing.band_component(ch[i] - ch.mean(), used)
        cf = tracing.regression_fit(z, ch[idx], 2)["coefficient"]
        return lambda i: cf * (ch[i] - ch.mean())

    # the held-out test in time: the residual variance of each half with the other half's coefficient
    held = tracing.regression_heldout(ctx.y, ch, fs, a) if own else tracing.regression_heldout(ctx.y, ch)
    yield Removal(
        "regression",
        tracing.band_component(ch - ch.mean(), br["used"]),
        refit,
        {"channel": name, "coefficient": rg["coefficient"]},
        {"coefficient": (rg["coefficient"] - rg["se"], rg["coefficient"] + rg["se"])},
        ev,
        1 + len(own),
        on_raw=True,
        heldout_in_time=held,
    )


def _with_terms(ctx: RemovalContext, name: str, ch: np.ndarray, a: float, rg: dict, t_thr: float):
    """A fast channel whose within-block test accepted (``rg``, at the t threshold ``t_thr``), fitted by the
    Whittle GLS with the optional terms: the fit when its coupling test accepts too, it keeps one of them (each
    at its own share of ``level``) and it carries over to the within-block test — its component regressed within
    blocks on the channel gives the rate's own within-block coefficient, within ``t_thr`` of its standard error
    (what the fit predicts that test to read); else None (the within-block coefficient stands). The coupling
    must pass both tests, so its level is not spent twice; a multi-position profile keeps no term (its nested
    tests at their null rate).

    Why the last check: a coupling that differs across frequency is no single coefficient, and the Whittle fit
    then follows the bands where the rate is quietest — the ADIS16405 run 2 gyro_x on acc_z read −8.9 °/s per g
    with a 0.02 s lag where the within-block coupling is +0.3 ± 0.06 (docs/channels.md)."""
    r = channels.regress_channel(ctx.y, ch, ctx.fs, name=name, alpha=a, level=ctx.level)
    if not (r.accepted and any(t.get("kept") for t in r.terms.values())):
        return None
    implied = tracing.regression_fit(r.component(ch), ch, REGRESSION_BLOCKS)["coefficient"]
    return r if abs(implied - rg["coefficient"]) <= t_thr * rg["se"] else None


def _slow_regression(
    ctx: RemovalContext, name: str, ch: np.ndarray, a: float, r: channels.ChannelRegression | None = None
) -> Iterator[Removal]:
    """A slow channel (most of its variance between the blocks' means, where the within-block test is blind),
    or a fast one whose optional terms are kept (``r``, :func:`_with_terms`): Whittle GLS against the record's
    own noise, the noise refitted on y − ĉ·ch; optional terms by their own tests; held out across frequency
    (a temperature that moves once moves in one part of any split in time)."""
    fast = r is not None
    if r is None:
        r = channels.regress_channel(ctx.y, ch, ctx.fs, name=name, alpha=a, level=ctx.level)
    test = tested("likelihood_ratio", r.test["statistic"], r.test["threshold"], r.test["alpha"]) | {
        "dof": r.test["dof"]
    }
    if r.test.get("accepted_by") == "quadratic":  # a turnover: the channel's square, its own share (docs/channels.md)
        q = r.test["quadratic"]
        test = tested("likelihood_ratio", q["statistic"], q["threshold"], q["alpha"])
        test |= {"dof": q["dof"], "accepted_by": "quadratic", "channel_test": r.test["statistic"]}
    if not r.accepted:
        ctx.consider("regression", {"channel": name} | test)
        return
    ev = {
        "domain": "channels",
        "test": test,
        "method": ("fast channel with optional terms" if fast else "slow channel")
        + ": Whittle GLS against the record's own noise (docs/channels.md)",
        "slow_share": channels.slow_share(ch),
        "terms": r.terms,
        "signal_bands_hz": r.signal_bands,
        "heldout": "even ↔ odd DFT bins",
    }
    if not r.form.plain:  # quantised and slow against its quantum, or held: read back first (docs/channels.md)
        ev["channel_form"] = r.form.evidence(ctx.fs)
    if r.lag_note():  # a lag its test cannot claim, profiled for the removal (docs/channels.md)
        ev |= {"lag": r.lag_note(), "removal_lag_s": r.removal_lag_s}
    yield Removal(
        "regression",
        r.component(ch),
        lambda z, idx, r=r, ch=ch: r.refit(z, idx, ch),
        {"channel": name} | r.params,
        r.intervals,
        ev,
        len(r.params),
        # held out on the chain as a drift is: the coupling fitted on the held-in part, its component built from
        # the held-out part's own channel samples. Not the held-in part's change of the curve (``on_raw``): a slow
        # channel swings differently in the two parts (a temperature cycling three times over 8 blocks), so that
        # change does not carry over — even the true coupling removed scored 6.0 → 6.4 % that way, 6.0 → 1.0 %
        # this way (tests/sensors.py, the 300 s lag case)
        on_raw=False,
        heldout_in_time=channels.heldout_ratio(ctx.y, ch, ctx.fs, r),
    )


def _outliers(ctx: RemovalContext) -> Iterator[Removal]:
    """Samples beyond the Gaussian noise, replaced by a draw from what Gaussian noise puts there. Held out in
    time: each part of alternate blocks (even, odd) flagged on its own at the cut found on the whole record;
    the Gaussian share of those flags, λ/flags, must stay below 1 (the flagged are outliers there too)."""
    y, a = ctx.y, alpha("outliers", ctx.level)
    r = outliers.outlier_test(y, ctx.fs, a)
    best = min(r["cuts"], key=lambda c: c["p_value"]) if r["cuts"] else None
    test = tested("clusters", best["count"], 2.0 * best["expected"], a) if best else {"alpha": a}
    if not r["accepted"]:
        entry = {"cuts": r["cuts"], "test": test} | ({"note": r["note"]} if "note" in r else {})
        ctx.consider("outliers", entry)
        return
    r, clean, passes = _flag_passes(y, ctx.fs, a, r)
    flags, cut = r["flags"], r["cut"]
    per = y.size // HELDOUT_BLOCKS
    lam = count = 0.0
    for parity in (0, 1):
        part = np.concatenate([y[j * per : (j + 1) * per] for j in range(HELDOUT_BLOCKS) if j % 2 == parity])
        f_p, l_p = outliers.flag_at(part, cut)
        lam, count = lam + l_p, count + int(f_p.sum())

    def refit(z, idx, flags=flags, comp=y - clean):
        # the flags come from the whole record's neighbourhoods; the held-in part's samples set nothing new
        return lambda i: comp[i]

    k = int(flags.sum())
    taus = 2.0 ** np.arange(0, int(np.log2(max(2, y.size // 9))) + 1) / ctx.fs
    evidence = {
        "domain": "time",
        "test": test,
        "cut_sigma": cut,
        "rule": r["rule"],
        "passes": passes,
        "flagged": k,
        "flagged_s": [float(i / ctx.fs) for i in np.flatnonzero(flags)[:50]],
        "expected_gaussian_flags": r["expected_gaussian_flags"],
        "cuts": r["cuts"],
        "adev_tau_s": [float(t) for t in taus],
        "adev_before": [float(v) for v in avar(y, ctx.fs, taus=taus).adev],
        "adev_after": [float(v) for v in avar(clean, ctx.fs, taus=taus).adev],
    }
    sd = np.sqrt(max(k, 1)) / y.size
    yield Removal(
        "outliers",
        y - clean,
        refit,
        {"rate": r["rate"], "threshold": r["threshold"]},
        {"rate": (max(0.0, r["rate"] - sd), r["rate"] + sd)},
        evidence,
        2,
        heldout_in_time=lam / max(count, 1e-12),
        on_curve=True,
    )


#: Passes of the outlier test at most: each on the samples the ones before left.
OUTLIER_PASSES = 4


def _flag_passes(y, fs, a, r) -> tuple[dict, np.ndarray, int]:
    """The accepted test ``r`` of the samples ``y`` carried on while the samples left still fail it: each pass
    tests the record with every sample flagged so far replaced, its flags join them, and the replacement is
    made again from ``y`` (at most :data:`OUTLIER_PASSES`). Sparse spikes are one pass. A continuous heavy
    tail is not: cut at c* σ of its own robust scale, what is left has a smaller scale and still a tail beyond
    the Gaussian's (white, 20 % of samples 6× wider: 10.8 % flagged at 3 σ, then 122 samples beyond 4.5 σ of
    the new scale, enough to move τ₀'s estimate by 2 standard errors). Returns the last pass's test with the
    union of the flags and its rate, the replaced samples and the number of passes."""
    flags = r["flags"].copy()
    clean = outliers.replace_outliers(y, flags)
    passes = 1
    while passes < OUTLIER_PASSES:
        again = outliers.outlier_test(clean, fs, a)
        if not again["accepted"] or not np.any(again["flags"] & ~flags):
            break
        flags |= again["flags"]
        r = again
        clean = outliers.replace_outliers(y, flags)
        passes += 1
    return r | {"flags": flags, "rate": float(np.count_nonzero(flags)) / y.size}, clean, passes


def _periodic(ctx: RemovalContext) -> Iterator[Removal]:
    """Every family of spectral lines, strongest first, each removed by least squares at its lattice's
    frequencies (refitted on the held-in blocks with the frequencies fixed for the held-out error) — or, for a
    family of harmonics, by its waveform folded on the period (:func:`allanite.model.template.fit_template`:
    every harmonic at once, the folded ones too) where that predicts held-out samples better; the lone lines
    are left to the ``"sinusoid"`` curve candidate, and so are a turned-down family's (``family``) — but a lone line
    whose frequency wanders, removed along its tracked phase (:func:`_lone_tracked`)."""
    a = alpha("lines", ctx.level)
    search = periodic.periodic_search(ctx.y, ctx.fs, a, alpha("slow_lines", ctx.level))
    ctx.lines = search
    searched = ctx.y
    families = search["families"]
    hunt = hunting(ctx, search, a)  # a family whose fundamental hunts, split by the search: one family, tracked
    if hunt is not None:
        comp, refit, ratio, params, intervals, evidence, _fam, covered = hunt  # declined: its parts are offered
        yield Removal("periodic", comp, refit, params, intervals, evidence, 1, heldout_in_time=ratio)
        if ctx.y is not searched:  # taken: its parts are not offered again
            families = [f for f in families if not any(f is c for c in covered)]
            search["sinusoids"] = [f for f in search["sinusoids"] if not any(f is c for c in covered)]
    for i, fam in enumerate(families):
        if ctx.y is not searched:  # a family removed before: this one's amplitudes on what it left
            fam = _refit_family(fam, ctx.y)
        params, intervals, evidence = family_out(fam, a, search)
        component, refit, ratio = fam.component(), fam.refit, heldout_variance_ratio(ctx.y, fam.refit)
        tracked = _tracked(ctx, fam, component, ratio, (params, intervals, evidence))
        wave = None if tracked is not None else folded_waveform(ctx, fam, ratio, families[i + 1 :])
        if tracked is not None:
            component, refit, ratio = tracked
        if wave is not None:
            tpl, ratio_t, refit = wave
            component = tpl.component()
            params["rms"], intervals["rms"] = tpl.rms, (max(0.0, tpl.rms - tpl.rms_sd), tpl.rms + tpl.rms_sd)
            evidence["waveform"] = {
                "method": "epoch folding: the mean of the samples in each phase bin of the period",
                "bins": tpl.bins,
                "heldout_variance_ratio": {"lines": ratio, "waveform": ratio_t},
                "heldout_by_bins": {int(b): float(v) for b, v in tpl.heldout.items()},
            }
            ratio = ratio_t
        yield Removal(
            "periodic",
            component,
            refit,
            params,
            intervals,
            evidence,
            # what the removal fitted that the Allan curve resolves: its generators (where the lines are);
            # the amplitudes and phases (or the waveform's bins) of narrow lines take 2 of the record's N
            # degrees of freedom each, at frequencies no τ of the curve isolates — counted against the curve's
            # few hundred points they would leave it none (a sawtooth's 325 lines: χ²/dof 157 = its χ²)
            len(fam.gens),
            heldout_in_time=ratio,
            family=fam,
        )
    for sin in search["sinusoids"]:
        rem = _lone_tracked(ctx, sin if ctx.y is searched else _refit_family(sin, ctx.y), a, search)
        if rem is not None:
            yield rem
    for ln in list(search["slow"]):  # a line of few cycles, below the spectrum's reach: its test was in time
        quiet = dataclasses.replace(ctx, consider=lambda _effect, _entry: None)
        why = explained_by_channel(ctx.y, ctx.fs, ln, _regression(quiet)) if ctx.channels else None
        if why is not None:  # a channel's, as a drift a channel explains: no line (``unexplained`` says the channel)
            search["slow"].remove(ln)
            ctx.consider("sinusoid", {"f0": ln["f0"], "amplitude": ln["amplitude"], "rejected": "a channel's"} | why)
            continue
        component, refit, params, intervals, evidence = slow_line_removal(ctx.y, ctx.fs, ln)
        ratio = heldout_variance_ratio(ctx.y, refit)
        yield Removal(
            "sinusoid", component, refit, params, intervals, evidence, 3, heldout_in_time=ratio, on_curve=True
        )


def _lone_tracked(ctx: RemovalContext, sin: periodic.LineFamily, a: float, search: dict) -> Removal | None:
    """A lone line (a family of one order) removed in time along its tracked phase where the tracker's nested test
    says its frequency wanders and the tracked form predicts held-out samples better than the fixed sinusoid
    (:func:`._tracking.tracked`, as a family's fundamental), and the tracked form takes at least
    :data:`allanite.model.wander.MIN_EXPLAINED` of the excess the fixed sinusoid left around it (a line whose
    amplitude changes at a steady frequency leaves that excess in its envelope), and a fixed sinusoid at the tracked
    mean frequency still fails the nested test (a strong steady line whose searched frequency is off by a hair leaves
    an excess the tracker takes as a "wander" of 3·10⁻⁵ %: ``refine_blind9.py``'s 4 Hz line 8× the noise's σ, F 3.9
    against 1.64): a ``"periodic"`` step of one line with its mean frequency and wander. Else None: the line stays
    the ``"sinusoid"`` curve candidate's, held on the curve at its power in the spectrum (a motor's, a fan's or a
    pump's single tone whose speed wanders would otherwise leave its incoherent power there and nothing of it
    removed from the samples)."""
    out = family_out(sin, a, search)
    got = _tracked(ctx, sin, sin.component(), lambda: heldout_variance_ratio(ctx.y, sin.refit), out)
    if got is None:
        if out[2].get("wander", {}).get("test", {}).get("accepted"):  # its test passed, the held-out ratio did not
            ctx.consider("periodic", out[0] | {"rejected": "a lone line not tracked", "wander": out[2]["wander"]})
        return None
    component, refit, ratio = got
    wv = out[2]["wander"]
    wv["explained_share"] = share = wander.explained_share(ctx.y, component, ctx.fs, wv["test"], float(sin.gens[0]))
    mean = float(out[0]["fundamentals"][0])
    wv["at_mean"] = again = wander.wander_test(
        ctx.y - sinusoid_at(ctx.y, ctx.fs, mean), ctx.fs, mean, wv["test"]["bandwidth_hz"], mean, wv["test"]["alpha"]
    )
    why = None
    if not share >= wander.MIN_EXPLAINED:  # what the steady fit left is its amplitude changing, not its phase
        why = "its tracked phase takes little of what the fixed sinusoid left: its amplitude changes, not its frequency"
    elif not again["accepted"]:  # the steady fit's frequency was off: a better one leaves nothing to track
        why = "a fixed sinusoid at the tracked mean frequency leaves nothing beyond the noise around it"
    if why is not None:
        ctx.consider("periodic", out[0] | {"rejected": why, "wander": wv})
        return None
    out[2]["lone_line"] = True
    return Removal("periodic", component, refit, out[0], out[1], out[2], 1, heldout_in_time=ratio)


def _refit_family(fam: periodic.LineFamily, y: np.ndarray) -> periodic.LineFamily:
    """``fam`` with its amplitudes and phases refitted on ``y`` (the samples an earlier family's removal left), its
    frequencies as found. Every family is found on the same samples; a line two families share was removed twice
    when each kept the amplitudes fitted there (a consumer IMU's 35th harmonic of 0.19 Hz, taken by that family's
    folded waveform, is the 6.65 Hz sideband of the other: the second removal left it at −its amplitude, which a
    sinusoid then held, ``tests/sensors.py``)."""
    a, b = linefit.solve(y, np.arange(y.size), fam.gens / fam.fs, fam.coefs)
    return dataclasses.replace(fam, a=a, b=b)


def _switching(ctx: RemovalContext) -> Iterator[Removal]:
    """Random telegraph noise, last: a channel, a line family or spikes explain jumps first (:mod:`._telegraph`)."""
    for fields in telegraph_removal(ctx):
        yield Removal(**fields)


#: The time-domain removals, in the order they run (each before the curve effects).
REMOVALS: dict[str, Callable[[RemovalContext], Iterator[Removal]]] = {
    "outliers": _outliers,
    "drift": _drift,
    "regression": _regression,
    "periodic": _periodic,
    "telegraph": _switching,
}
