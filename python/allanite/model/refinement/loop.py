"""The loop of :func:`allanite.refine`: fit the starting model, remove what the samples show in time, then
add curve effects one at a time while a calibrated test asks for one and the held-out error falls; change
points last; every step scored with its error before and after.

The pieces live in modules of their own, each named for what it decides: the weighted fit with effects
(:mod:`.curvefit`), the errors in-sample and held out (:mod:`.scoring`), the curve test (:mod:`.calibrated`),
the false-alarm budget (:mod:`.levels`), the curve candidates and which one a step accepts
(:mod:`.candidates`), the removals in time (:mod:`.removals`), the change points (:mod:`.changes`), the
result with its report (:mod:`.result`), and the inputs checked (:mod:`._inputs`). The refinement under way
and the chain it is scored along are :mod:`._run`'s, its removals' sequencing :mod:`._in_time`'s, the chain
scored after the final joint refit, the change points' steps and the result's assembly :mod:`._final`'s;
here are :func:`refine` and the curve steps (with a second chain where the first took an option the whole chain
decides: :data:`ALTERNATIVES`).
"""

from __future__ import annotations

from collections.abc import Callable
from contextlib import AbstractContextManager
from dataclasses import dataclass

import numpy as np

from ..._blas import one_thread
from ..._progress import StepBar
from ..._validate import check_input
from ...errors import ParameterError
from .. import periodic, tracing
from .._counter import counter_quantisation, detect_counter
from .._declared import DeclaredFilter, declared_filter, declaring
from .._quantiser import detect_output_quantiser, output_quantisation
from .._recent import remembering
from ..effects import EFFECTS, describe
from ..lines import remembering_spectra
from ..terms import check_terms
from ._bumps import bandpass_chain_kept, bandpass_named, without_bandpass
from ._final import FinalModel
from ._in_time import TimeRemovals
from ._inputs import REFINE_SCALE, check_scale, check_truth, check_unit, inputs
from ._line_gain import line_gain
from ._rolloff import research_rolloff, sinc_chain_kept, sinc_named, without_sincs
from ._sinusoid import gain_key
from .calibrated import N_BOOT, curve_test, residual_evidence, tested
from .candidates import CURVE_CANDIDATES, Proposal, Round, bandwidth_grids, choose, families, prefetch
from .curvefit import Solution, base_name, held_theta, solve
from .levels import LEVEL, alpha
from .result import Refinement, Step

__all__ = ["refine", "CANDIDATES", "MAX_STEPS", "REFINE_SCALE"]

#: Effects refine can add, from the registry in :mod:`allanite.model.effects`.
CANDIDATES = tuple(EFFECTS)
#: Curve effects added at most (time-domain removals, spectral lines — their amplitude measured in the samples,
#: held in the curve's fits — and change points come on top): two injected curve effects, the bandwidth and a
#: resonance beside it (ADIS16405 run 1 z takes four) with room for one more.
MAX_STEPS = 6


@dataclass(frozen=True)
class Alternative:
    """An option a curve step may take whose choice the whole chain decides (:meth:`_Run.curve_chains`): ``named``
    says whether the curve effects [(key, p)] hold it, ``withdrawn`` is a context in which no step takes it,
    ``kept`` (the final solutions of the chain that took it and of the one without, one effective point) whether
    the chain that took it stays; both chains' final χ²/dof and effects go into ``evidence[key]`` of the kept steps of
    ``effect``, under ``labels`` (the chain that took it, the other)."""

    named: Callable[[list], bool]
    withdrawn: Callable[[], AbstractContextManager]
    kept: Callable[[Solution, Solution, float], bool]
    key: str
    effect: str
    labels: tuple[str, str]


#: The options decided on whole chains, innermost first: a sinc^k bandwidth kind (the kinds without it,
#: :func:`._rolloff.sinc_chain_kept`) within each resonance shape's chain (the Lorentzian alone,
#: :func:`._bumps.bandpass_chain_kept`). The rules are looked up when asked (tests replace them).
ALTERNATIVES = (
    Alternative(
        sinc_named,
        without_sincs,
        lambda taken, other, tie: sinc_chain_kept(taken, other, tie),
        "kind_chains",
        "bandwidth",
        ("with_sinc", "without_sinc"),
    ),
    Alternative(
        bandpass_named,
        without_bandpass,
        lambda taken, other, tie: bandpass_chain_kept(taken, other, tie),
        "shape_chains",
        "resonance",
        ("with_bandpass", "lorentzian_only"),
    ),
)


def refine(
    x_or_result,
    fs=None,
    *,
    start=("Q", "N", "B", "K", "R"),
    candidates=CANDIDATES,
    unit=None,
    input: str = "rate",
    tau_range=None,
    truth=None,
    confidence: float = 0.683,
    points: int = 300,
    axis: int | None = None,
    channels=None,
    level: float = LEVEL,
    progress=None,
    gaps: str = "error",
    filter=None,
) -> Refinement:
    """Fit the starting model, find what it lacks, add it, repeat; report the error before and after.

    Parameters
    ----------
    x_or_result : array_like or AllanResult
        Samples (then ``fs`` is needed; the Allan variance is computed on a dense exponential grid of
        ``points`` τ so that a sinusoid's nulls are resolved, the PSD and the record along time are
        searched too, and the held-out error is computed), or a static :class:`~allanite.AllanResult`
        (curve effects only; no held-out error).
    fs : float, optional
        Sampling rate, Hz (samples only).
    start : tuple of str
        The starting model's terms (``"Q"``, ``"N"``, ``"B"``, ``"K"``, ``"R"``).
    candidates : tuple of str
        Effects to try (:data:`CANDIDATES`, the registry :data:`allanite.model.effects.EFFECTS`); no step
        takes an effect left out (a line removed in time is a ``"sinusoid"``; one of few cycles found but
        left is said in ``unexplained``). The parameters each step reports and their units ("rate unit":
        the samples' rate unit):

        {effects}
    unit : str, optional
        Unit of the samples, for IEEE-952 values of the terms: a gyro's rate or angle unit
        (:func:`allanite.units.parse_unit`), checked before any work. An accelerometer's (``"m/s^2"``,
        ``"g"``, ``"mg"``, … with ``input="rate"``) gives the terms in its report units (velocity random walk
        in m/s/√h, bias instability in µg, acceleration random walk in m/s/h^1.5). For a magnetometer or
        another sensor give none: the terms are then in the samples' own unit and seconds.
    input : {"rate", "increment", "angle"}
        What the samples are, as for :func:`allanite.avar` (allantools' ``"phase"`` is ``"angle"``: a clock's
        time error, M + 1 points; ``"freq"`` is ``"rate"``).
    tau_range : (float, float) or "auto", optional
        τ (s) to use, as in :func:`allanite.fit`. Default: every τ — the shortest τ carry the sensor's
        bandwidth, which is a candidate effect; ``"auto"`` cuts them as ``fit`` does.
    channels : dict of str → array_like, optional
        Other channels of the same log (same length as the samples: temperature, other axes,
        accelerometers; with ``input="angle"`` also read at the angle's M + 1 instants, each interval
        then taking the mean of its two ends): the rate is regressed on each ("regression" effect; band
        by band where the coupling differs across frequency, the bands in the step's
        ``evidence["bands"]``).
    level : float
        False-alarm probability per record on a clean record (default 0.05), split between every
        calibrated test (:mod:`allanite.model.refinement.levels`): spectral lines, change points, the
        outliers, drift and regression removals, the checks behind ``unexplained`` and the Allan-curve
        test, which takes what the others leave.
    progress : bool, optional
        A ``tqdm.auto`` bar: None (default) in a notebook or a terminal only, True/False always/never.
    gaps : {"error", "skip"}
        ``"error"`` (default): NaN in the samples is an :class:`~allanite.errors.InputError`. ``"skip"``: NaN marks
        a missing sample (``read_log(..., gaps="nan")``; the channels' NaN at the same gaps too). At most
        5 % may be missing and no gap may be longer than 1 % of the record (else a
        :class:`~allanite.errors.DataGapError`): each gap is filled by the straight line between the medians of its
        neighbours (as many samples each side as the gap is long, at least 8) — the searches along time, the
        held-out split and the Allan curve all see the filled record — and ``Refinement.filled`` says which samples
        were filled, how, and how far the fill moved the Allan curve from the one that skips the gaps
        (``curve_change_pct``). On 60 clean records with 1 % dropped in 20 gaps the fill added and flagged nothing
        (0 of 60, 95 % CP 0–6 %; a sinusoid through the gaps: 10 of 10 within 11 %) — ``benches/refine_gaps.py``,
        docs/guide.md ("Logs with dropped samples").
    truth : dict, optional
        Known parameters per effect (``{"gauss_markov": {"sigma": …, "tc": …}}``, ``{"change_point":
        {"t": …}}``): each step then records its relative errors.
    axis : int, optional
        Which axis of multi-axis input to refine; without it the first (a warning says so when there are
        others).
    filter : array_like, (array_like, array_like) or dict, optional
        The sensor's own digital filter, as its data sheet or driver gives it: FIR taps (1-D), an IIR's
        ``(b, a)``, or a dict ``{"taps": …}`` / ``{"b": …, "a": …}`` with ``"rate"`` (Hz it runs at) and/or
        ``"decimation"`` (it runs at ``decimation``·fs and every ``decimation``-th output is kept; default 1,
        the output rate). The bandwidth effect's kind is then this filter alone, its exact Allan variance for
        white noise (aliasing included; :mod:`allanite.model._declared`), its shape fixed — the bandwidth's test
        asks only whether the curve needs it; ``cutoff`` (its −3 dB frequency) is reported without an interval,
        ``filter`` is ``"declared"`` and the white floor after it (a quantised output) is kept as beside a
        Butterworth. ``Refinement.declared_filter`` says what was declared. Checked before any work (a
        :class:`~allanite.errors.ParameterError` for an empty, non-finite or wrongly shaped filter, an unstable
        IIR, a rate that is not decimation × fs, a filter that passes no power at DC). Default: none — the
        bandwidth's kinds are searched.

    Returns
    -------
    Refinement

    Examples
    --------
    >>> import allanite
    >>> y = allanite.simulate(1_000_000, 100.0, N=2e-3, K=2e-5, gauss_markov=[(5e-3, 10.0)], seed=11)
    >>> r = allanite.refine(y, 100.0)               # the generator's GM is not in the starting model
    >>> r.found, round(r.steps[0].params["tc"], 0)
    (['gauss_markov'], 10.0)
    """
    check_scale(x_or_result)
    input = check_input(input)
    check_unit(unit, input, x_or_result)  # before any work: it was read only by the final fit
    check_truth(truth, tuple(EFFECTS))
    decl = _declared(filter, fs, x_or_result)  # before any work
    # each line spectrum once; curves, phasors and outlier scales of the same samples once; OpenBLAS on one
    # thread (its products here are small or thin: its threads cost more than they save, :mod:`allanite._blas`)
    with StepBar(progress, 1, "refine") as bar, remembering_spectra(), remembering(), one_thread():
        bar.step("fit, trace and test the candidates")
        start = check_terms(start)
        candidates = _check_candidates(candidates, level)
        y, result, chans, filled = inputs(x_or_result, fs, input, points, axis, channels, gaps)
        # a delta-angle counter's samples: every Q column is its exact one (allanite.model._counter)
        counter = detect_counter(y, result.fs) if y is not None and "Q" in start else None
        # a rate quantised at the output, coarse beside its filtered change per sample: the floor after a filter
        # is its error's exact Allan variance (allanite.model._quantiser)
        quant = detect_output_quantiser(y, result.fs) if y is not None and counter is None else None
        with counter_quantisation(counter), output_quantisation(quant), declaring(decl):
            run = _Run(y, result, start, tau_range, level, truth, unit)
            run.remove_in_time(candidates, chans)
            run.channels = chans or {}
            run.add_curve_effects(candidates)
            after = run.after_curve()  # the samples both see: a line's gain taken out once
            cp_steps = run.change_point_steps(candidates, after)
            out = run.refinement(cp_steps, unit, confidence, run.unexplained(chans, after, cp_steps))
        out.filled = filled
        out.counter = counter
        out.declared_filter = None if decl is None else decl.describe() | {"words": decl.words()}
        return out


def _declared(spec, fs, x_or_result) -> DeclaredFilter | None:
    """The filter ``refine(..., filter=spec)`` declares, checked against the output rate (None without one)."""
    if spec is None:
        return None
    out_fs = fs if fs is not None else getattr(x_or_result, "fs", None)
    if out_fs is None:
        raise ParameterError("filter= needs the output rate: pass fs (Hz) with samples")
    return declared_filter(spec, float(out_fs))


def _check_candidates(candidates, level) -> tuple:
    if isinstance(candidates, str):
        candidates = (candidates,)
    bad = [c for c in candidates if c not in CANDIDATES]
    if bad:
        raise ParameterError(f"unknown candidate effect {bad[0]!r}; allowed: {', '.join(CANDIDATES)}")
    if not (isinstance(level, (int, float)) and 0.0 < level < 1.0):
        raise ParameterError(f"level must be a probability in (0, 1), got {level!r}")
    return candidates


class _Run(TimeRemovals, FinalModel):
    """One refinement under way (:class:`._run.RunState`, the chain every step is scored along): its removals in
    time (:class:`._in_time.TimeRemovals`), then the curve effects one step at a time (here), then the chain
    scored, the change points and the result (:class:`._final.FinalModel`)."""

    def add_curve_effects(self, candidates) -> None:
        """Curve effects one per step (at most :data:`MAX_STEPS`) while one is accepted; then an effect whose
        amplitude a later one took over entirely is dropped, and the steps are scored along the chain. Where the
        chain took an option of :data:`ALTERNATIVES` (a sinc^k bandwidth kind, a band-pass resonance) the steps
        run again without it and the chain its rule prefers is kept (:meth:`curve_chains`)."""
        y = self.y
        exact = y is not None or (isinstance(self.est, str) and self.est == "oavar")
        thin = tracing.thin_indices(self.curve.tau)
        lines = []
        if y is not None and "sinusoid" in candidates:
            # one line search for both line effects (one share of level): the periodic removal's, or now
            search = self.line_search
            if search is None:
                search = periodic.periodic_search(
                    y, self.fs, alpha("lines", self.level), alpha("slow_lines", self.level)
                )
            # every line a family removal did not take: all of them without the periodic candidate, else the
            # lines of the families it turned down (their phase does not carry across the record's parts, their
            # power is still on the curve)
            fams = True if "periodic" not in candidates else self.declined_families
            if any(rem.effect == "periodic" for _st, rem, *_rest in self.removed):
                # a family removed in time takes the part of its lines whose phase carries across the record;
                # what power they keep (a wandering phase) is searched again on the samples the removals left,
                # every line there offered (conditional on a family found: no share of level under the null)
                # (a line of few cycles, tested once in time, is carried over: the family took none of it)
                again = periodic.periodic_search(y, self.fs, alpha("lines", self.level))
                search, fams = again | {"slow": search.get("slow", []), "slow_test": search.get("slow_test")}, True
            lines = periodic.sinusoid_lines(search, families=fams)
            if any(rem.effect == "sinusoid" for _st, rem, *_rest in self.removed):  # a line of few cycles, removed
                lines = [ln for ln in lines if not ln.get("slow")]
            self.offered_lines = [float(ln["f0"]) for ln in lines]
        self.curve_chains(self.fork(), ALTERNATIVES, (candidates, thin, exact, lines))
        self.score()

    def curve_chains(self, fork: tuple, alts: tuple, args: tuple) -> None:
        """The curve steps (:meth:`curve_loop` of ``args``) from the state ``fork`` (:meth:`fork`), every option of
        ``alts`` (innermost first) decided on whole chains: where the chain took the outermost one, the steps (with
        the options inside it decided as here) run again from ``fork`` with it withdrawn, and :meth:`keep_chain`
        keeps one of the two."""
        if not alts:
            self.curve_loop(*args)
            return
        *inner, alt = alts
        self.curve_chains(fork, tuple(inner), args)
        if alt.named(self.effects):  # the chain without it carried too: the whole chain decides
            taken = self.fork()
            self.restore(fork)
            with alt.withdrawn():
                self.curve_chains(fork, tuple(inner), args)
            self.keep_chain(alt, taken)

    def keep_chain(self, alt: Alternative, taken: tuple) -> None:
        """The chain that took the option ``alt`` (``taken``, :meth:`fork`) or the one just run without it, whichever
        its rule prefers; both chains' final χ²/dof and effects in every kept step of its effect's evidence."""
        tie = self.curve.tau.size / self.curve.n_eff
        other = self.fork()
        chains = {
            name: {"chi2_dof": float(fk[3].chi2_dof), "effects": [base_name(k) for k, _p in fk[0]]}
            for name, fk in zip(alt.labels, (taken, other))
        }
        if alt.kept(taken[3], other[3], tie):
            self.restore(taken)
        for st in self.steps:
            if st.effect == alt.effect:
                st.evidence[alt.key] = chains

    def curve_loop(self, candidates, thin, exact, lines) -> None:
        """The curve steps while one is accepted, the absorbed dropped, the roll-off searched again."""
        n_step = 0
        while sum(held_theta(k) is None for k, _p in self.effects) < MAX_STEPS:
            if not self.curve_step(n_step, candidates, thin, exact, lines):
                break
            n_step += 1
        self.drop_absorbed()
        grids = bandwidth_grids(self.curve)
        self.effects, self.sol = research_rolloff(self.curve, self.start, self.effects, self.sol, grids, self.y)

    def fork(self) -> tuple:
        """The curve steps' state so far (effects, steps, lines, solution, considered), copied."""
        considered = {k: list(v) for k, v in self.considered.items()}
        return list(self.effects), list(self.steps), list(self.lines), self.sol, considered

    def restore(self, state: tuple) -> None:
        """Set the curve steps' state to a copy of ``state`` (:meth:`fork`): a chain run from it leaves it as it was,
        for the next chain run from it."""
        effects, steps, lines, self.sol, considered = state
        self.effects, self.steps, self.lines = list(effects), list(steps), list(lines)
        self.considered = {k: list(v) for k, v in considered.items()}

    def curve_step(self, n_step, candidates, thin, exact, lines) -> bool:
        """One step: every candidate's proposal, the one :func:`choose` accepts added; False if none."""
        sub = self.curve.subset(thin)
        test, thr = self.step_test(n_step, candidates, thin, exact)
        rnd = Round(
            self.curve,
            self.start,
            self.effects,
            self.sol,
            sub,
            test,
            thr,
            self.heldout,
            self.y,
            lines,
            self.level,
            thin,
            exact,
        )
        prefetch(rnd, candidates)  # every candidate's bounded searches, run together
        props = [pr for name, c in CURVE_CANDIDATES.items() if name in candidates for pr in c.propose(rnd)]
        for pr in props:
            pr.record = {"param": float(pr.p), "statistic": float(pr.stat), "threshold": float(pr.thr)} | pr.notes
            self.consider(pr.effect, pr.record)
        chosen = choose(props, rnd, candidates)
        for other in props:  # a test that passed says why it was not taken (choose says it where it can)
            if other.stat > other.thr and "rejected" not in other.record and (chosen is None or other is not chosen[0]):
                other.record["rejected"] = "not taken: " + (f"{chosen[0].effect} was" if chosen else "nothing")
                other.record["rejected"] += " taken at this step"
        if chosen is None:
            return False
        pr, ho_b, ho_a = chosen
        self.steps.append(self.curve_effect_step(pr, rnd, ho_b, ho_a))
        self.lines.append(pr.line)
        self.effects, self.sol = self.effects + [(pr.key, pr.p)], pr.sol
        return True

    def step_test(self, n_step, candidates, thin, exact) -> tuple:
        """The step's curve test under the model so far and its bootstrap threshold over every candidate's family
        (:func:`.candidates.families`, once per refinement: its columns depend on the thinned curve and the
        candidates alone), remembered by the curve under the model (its effects and solution), the candidates, the
        share of level and the step's seed — everything they are computed from: a chain run again without an
        option (:meth:`curve_chains`) passes through the first chain's states until it parts from it, and its
        steps there get the same test and threshold without their bootstrap."""
        sol, a = self.sol, alpha("curve", self.level)
        model = (tuple(self.start), tuple((k, float(p)) for k, p in self.effects))
        fit = (sol.theta.tobytes(), sol.nu.tobytes(), sol.model.tobytes())
        cands = (np.asarray(thin).tobytes(), bool(exact), tuple(candidates), self.y is not None)
        key = ("step_test", model, fit, cands, a, n_step)
        got = self.curve.cached(key)
        if got is None:
            fam = self.curve.cached(("families", cands))
            if fam is None:
                fam = self.curve.remember(("families", cands), families(self.curve.subset(thin), *cands[2:]))
            test = curve_test(self.curve, thin, sol, self.start, self.effects, exact)
            got = self.curve.remember(key, (test, test.threshold(fam, a, N_BOOT, seed=n_step)))
        return got

    def curve_effect_step(self, pr: Proposal, rnd: Round, ho_b, ho_a) -> Step:
        """The step of an accepted curve proposal (scored along the chain once the loop is done)."""
        cand = CURVE_CANDIDATES[pr.effect]
        if pr.line is not None and self.channels and self.y is not None and "gain" not in pr.line:
            # its nested option: the amplitude following a channel, at its conditional share over the lines offered
            a = alpha("sinusoid:gain", self.level) / max(1, len(self.offered_lines or []))
            pr.line["gain"] = line_gain(self.y, self.fs, float(pr.line["f0"]), self.channels, a)
            if pr.line["gain"]:  # its term the modulated line's exact Allan variance (._sinusoid.gain_key)
                pr.key = gain_key(pr.line, rnd.curve, self.y.size, self.channels)
                pr.sol = solve(rnd.curve, rnd.start, rnd.effects + [(pr.key, pr.p)])
        params, intervals = cand.params(pr, rnd)
        evidence = residual_evidence(self.curve, self.sol)
        evidence["domain"] = EFFECTS[pr.effect].domain
        if pr.line is not None:
            evidence["test"] = tested("psd_ratio", pr.stat, pr.thr, alpha("lines", self.level))
        else:
            evidence["test"] = tested("gls_score", pr.stat, pr.thr, alpha("curve", self.level))
        evidence.update(cand.evidence(pr, rnd))
        if pr.pair_note is not None:
            evidence["held_out"] = pr.pair_note
        if ho_b is not None and self.removed:  # held out on the samples after the removals, not the record's
            evidence["heldout_test"] = {"before": ho_b, "after": ho_a}
        return Step(effect=pr.effect, params=params, intervals=intervals, evidence=evidence, before={}, after={})

    def drop_absorbed(self) -> None:
        """Drop an effect whose amplitude a later one took over entirely (refit without it)."""
        k = len(self.start)
        dead = [j for j in range(len(self.effects)) if self.sol.theta[k + j] <= 0]
        if dead:
            for j in reversed(dead):
                key, p = self.effects[j]
                self.consider(base_name(key), {"param": float(p), "absorbed": True})
                del self.effects[j], self.steps[j], self.lines[j]
            self.sol = solve(self.curve, self.start, self.effects)


# the registry's list under ``candidates``, every item indented as that parameter's description (the site's
# API reference fills the same list in: docs/_site/griffe_roles.py)
refine.__doc__ = (refine.__doc__ or "").replace("        {effects}", describe(" " * 8))
