"""The loop of :func:`allanite.refine`: fit the starting model, remove what the samples show in time, then
add curve effects one at a time while a calibrated test asks for one and the held-out error falls; change
points last; every step scored with its error before and after.

The pieces live in modules of their own, each named for what it decides: the weighted fit with effects
(:mod:`.curvefit`), the errors in-sample and held out (:mod:`.scoring`), the curve test (:mod:`.calibrated`),
the false-alarm budget (:mod:`.levels`), the curve candidates and which one a step accepts
(:mod:`.candidates`), the removals in time (:mod:`.removals`), the change points (:mod:`.changes`), the
result with its report (:mod:`.result`), and the inputs checked (:mod:`._inputs`).
"""

from __future__ import annotations

import numpy as np

from ..._blas import one_thread
from ..._progress import StepBar
from ...analysis import avar
from ...errors import ParameterError
from .. import periodic, tracing
from .._recent import remembering
from ..channels import terms_before_after
from ..effects import EFFECTS, describe
from ..lines import remembering_spectra
from ..terms import check_terms
from ._family_fold import fold_wandering
from ._inputs import REFINE_SCALE, check_scale, check_truth, check_unit, heldout_note, inputs, resolve_tau_range
from ._rolloff import research_rolloff, sinc_chain_kept, sinc_named, without_sincs
from .calibrated import N_BOOT, curve_test, residual_evidence, tested
from .candidates import CURVE_CANDIDATES, Proposal, Round, bandwidth_grids, choose, families, final_params, prefetch
from .changes import change_point_step, change_points
from .curvefit import Curve, base_name, held_theta, noise_fit, solve, theta_terms
from .levels import LEVEL, alpha
from .missing import MissingContext, unexplained
from .removals import REMOVALS, Removal, RemovalContext
from .result import Refinement, Step, term_moves
from .scoring import (
    MATERIAL_Z,
    chain_metrics,
    curve_change_z,
    heldout_split,
    informative,
    segments_heldout,
    settle_chi2,
)

__all__ = ["refine", "CANDIDATES", "MAX_STEPS", "REFINE_SCALE"]

#: Effects refine can add, from the registry in :mod:`allanite.model.effects`.
CANDIDATES = tuple(EFFECTS)
#: Curve effects added at most (time-domain removals, spectral lines — their amplitude measured in the samples,
#: held in the curve's fits — and change points come on top): two injected curve effects, the bandwidth and a
#: resonance beside it (ADIS16405 run 1 z takes four) with room for one more.
MAX_STEPS = 6


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
    axis: int = 0,
    channels=None,
    level: float = LEVEL,
    progress=None,
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
        Effects to try (:data:`CANDIDATES`, the registry :data:`allanite.model.effects.EFFECTS`), with the
        parameters each step reports and their units ("rate unit": the samples' rate unit):

        {effects}
    unit : str, optional
        Unit of the samples, for IEEE-952 values of the terms: a gyro's rate or angle unit
        (:func:`allanite.units.parse_unit`), checked before any work. For an accelerometer, a magnetometer
        or another sensor give none: the terms are then in the samples' own unit and seconds.
    tau_range : (float, float) or "auto", optional
        τ (s) to use, as in :func:`allanite.fit`. Default: every τ — the shortest τ carry the sensor's
        bandwidth, which is a candidate effect; ``"auto"`` cuts them as ``fit`` does.
    channels : dict of str → array_like, optional
        Other channels of the same log (same length as the samples: temperature, other axes,
        accelerometers): the rate is regressed on each ("regression" effect; band by band where the
        coupling differs across frequency, the bands in the step's ``evidence["bands"]``).
    level : float
        False-alarm probability per record on a clean record (default 0.05), split between every
        calibrated test (:mod:`allanite.model.refinement.levels`): spectral lines, change points, the
        outliers, drift and regression removals, the checks behind ``unexplained`` and the Allan-curve
        test, which takes what the others leave.
    progress : bool, optional
        A ``tqdm.auto`` bar: None (default) in a notebook or a terminal only, True/False always/never.
    truth : dict, optional
        Known parameters per effect (``{"gauss_markov": {"sigma": …, "tc": …}}``, ``{"change_point":
        {"t": …}}``): each step then records its relative errors.
    axis : int
        Which axis of multi-axis input to refine.

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
    check_unit(unit, input, x_or_result)  # before any work: it was read only by the final fit
    check_truth(truth, tuple(EFFECTS))
    # each line spectrum once; curves, phasors and outlier scales of the same samples once; OpenBLAS on one
    # thread (its products here are small or thin: its threads cost more than they save, :mod:`allanite._blas`)
    with StepBar(progress, 1, "refine") as bar, remembering_spectra(), remembering(), one_thread():
        bar.step("fit, trace and test the candidates")
        start = check_terms(start)
        candidates = _check_candidates(candidates, level)
        y, result, chans = inputs(x_or_result, fs, input, points, axis, channels)
        run = _Run(y, result, start, tau_range, level, truth, unit)
        run.remove_in_time(candidates, chans)
        run.add_curve_effects(candidates)
        cp_steps = run.change_point_steps(candidates)
        return run.refinement(cp_steps, unit, confidence, run.unexplained(chans, cp_steps))


def _check_candidates(candidates, level) -> tuple:
    if isinstance(candidates, str):
        candidates = (candidates,)
    bad = [c for c in candidates if c not in CANDIDATES]
    if bad:
        raise ParameterError(f"unknown candidate effect {bad[0]!r}; allowed: {', '.join(CANDIDATES)}")
    if not (isinstance(level, (int, float)) and 0.0 < level < 1.0):
        raise ParameterError(f"level must be a probability in (0, 1), got {level!r}")
    return candidates


class _Run:
    """One refinement under way: the samples and their curve as removals change them, the model so far, the
    steps, and what was considered and turned down.

    Every step is scored on the original record's Allan curve (``curve0``) and held out on its alternate blocks
    (``split0``), along one chain: each step's "before" is the previous step's "after", the first "before" the
    start's, the last "after" the final model's. The curve effects come first in it, fitted on the record's
    own curve; then the removals in time (removed from the samples before the curve effects were searched, so
    that those are found on the corrected samples), each scored with every curve effect in the model — a
    removed component's exact Allan variance, AVAR(y) − AVAR(y − components), part of it, and held out with
    the removals refitted on each held-in part; change points last. The held-out comparison that accepted a
    step (on the samples as they were when it was tested, or per segment for change points) is kept in its
    ``evidence["heldout_test"]`` where it differs."""

    def __init__(self, y, result, start, tau_range, level, truth, unit=None):
        self.y, self.result, self.start, self.level, self.truth = y, result, start, level, truth
        self.y0 = y  # the samples as given: removals replace self.y, never change it in place
        self.unit = unit
        self.lo, self.hi = resolve_tau_range(tau_range, result, start)
        keep = (result.tau >= self.lo) & (result.tau <= self.hi) & (result.avar > 0)
        if keep.sum() < len(start) + 3:
            raise ParameterError(
                f"{int(keep.sum())} usable τ points; refining {len(start)} terms needs at least {len(start) + 3}"
            )
        self.keep = keep
        self.est = result.estimator if result.source is None else tuple(np.asarray(result.source)[keep])
        self.fs = result.fs
        self.curve, self.heldout = self.build(result, y)
        self.note = heldout_note(y, self.heldout)
        self.sol = self.start_sol = solve(self.curve, start, [])
        # the chain's χ² on the tests' thinned τ and covariance (exact for samples or overlapping estimates)
        self.thin = tracing.thin_indices(self.curve.tau)
        self.exact = y is not None or (isinstance(self.est, str) and self.est == "oavar")
        # in-sample RMS ADEV error: on the τ whose estimate is informative under the five-term fit (fixed for
        # the whole refinement, so every before/after compares the same τ)
        self.scored = informative(self.curve.tau, self.sol.nu)
        # the original record: what every step is scored on
        self.result0, self.curve0, self.split0 = result, self.curve, self.heldout
        self.raw = self.split0.raw_parts() if self.split0 is not None else None
        self.state = self.chain(self.sol, [])  # (metrics, GLS χ², terms' coefficients) of the model so far
        self.start_heldout = self.state[0]["heldout_rms_adev_pct"]
        self.effects: list = []  # curve effects [(key, nonlinear parameter)], steps[j] ↔ effects[j]
        self.steps: list = []
        self.lines: list = []  # per curve step: the spectral line it came from, or None
        # per time effect removed before the curve effects: (step, removal, its own change of the curve, the
        # curve after it, the held-out parts with the removals so far refitted on them)
        self.removed: list = []
        self.states: list = [self.state]  # the chain: the model before the first step and after each
        self.change_points: list = []
        self.considered: dict[str, list] = {}
        self.line_search: dict | None = None  # the periodic removal's line search, for the sinusoid candidate
        self.declined_families: list = []  # line families the removal in time turned down: their lines stay

    def build(self, res, samples):
        """The curve (and, with samples, the held-out split) of ``res``'s estimates in the τ range."""
        keep = self.keep
        c = Curve(res.tau[keep], res.m[keep].astype(np.float64), res.avar[keep], self.fs, res.n_samples + 1, self.est)
        if samples is None:
            return c, None
        m_all = np.asarray(res.m, dtype=np.int64)
        return c, heldout_split(samples, self.fs, m_all, self.lo, self.hi, self.start)

    def chain(self, sol, effects, curve=None, n_removed=0, parts=None) -> tuple:
        """The model ``sol`` (terms plus ``effects``, fitted on ``curve``: the record's, or the one the removals
        left, with ``n_removed`` numbers fitted by them) scored on the record's curve, held out with ``parts``
        (the raw parts when None): (metrics, GLS χ², the terms' coefficients √θ)."""
        curve = self.curve0 if curve is None else curve
        ho = None
        if self.split0 is not None:
            ho = self.split0.predict(self.raw if parts is None else parts, self.start, effects)
        change = self.curve0.avar - curve.avar
        metrics, pending = chain_metrics(self.curve0, sol, change, n_removed, ho, self.scored, self.thin)
        # χ² under the model's own covariance, as the calibrated test at that stage takes it (the removals'
        # components are fitted, not drawn: the residual on the record's curve is the corrected curve's)
        chi2 = settle_chi2(metrics, pending, curve_test(curve, self.thin, sol, self.start, effects, self.exact))
        return metrics, chi2, np.sqrt(np.maximum(theta_terms(sol, self.start, effects), 0.0))

    def advance(self, st: Step, state: tuple) -> None:
        """Score ``st`` from the chain's last state to ``state``."""
        st.before, st.after = dict(self.state[0]), dict(state[0])
        st.delta_chi2_eff = float(self.state[1] - state[1])
        self.state = state
        self.states.append(state)

    def consider(self, effect: str, entry: dict) -> None:
        self.considered.setdefault(effect, []).append(entry)

    def truth_error(self, effect: str, params: dict) -> dict | None:
        """Relative errors of the numeric parameters ``truth`` gives for ``effect``."""
        if not self.truth or effect not in self.truth:
            return None
        return {
            k: params[k] / v - 1
            for k, v in self.truth[effect].items()
            if k in params and isinstance(params[k], (int, float)) and v
        }

    # ---- time-domain removals, before the curve effects

    def remove_in_time(self, candidates, chans) -> None:
        """Every removal of :data:`REMOVALS` among ``candidates``, in order, each on the samples the ones
        before it left."""
        if self.y is None:
            return
        # the channels even where their regression may not be taken: a drift a channel explains is no drift (with
        # the regression a candidate the channel takes it; without, it is left to be said in ``unexplained``)
        ctx = RemovalContext(self.y, self.fs, self.curve, self.sol, self.start, chans, self.level, self.consider)
        for name, remover in REMOVALS.items():
            if name not in candidates:
                continue
            for rem in remover(ctx):
                if self.remove(rem):
                    ctx.y, ctx.curve, ctx.sol = self.y, self.curve, self.sol
                elif rem.family is not None:
                    self.declined_families.append(rem.family)
        self.line_search = ctx.lines

    def remove(self, rem: Removal) -> bool:
        """Remove ``rem.component`` if the held-out error falls (or its held-out test in time passes); else
        record it among the considered. Its step is scored once the curve effects are in (:meth:`score`)."""
        y, start, effects, heldout = self.y, self.start, self.effects, self.heldout
        assert y is not None
        y_new = y - rem.component
        res_new = avar(y_new, self.fs, taus=self.result.tau)
        c_new, h_new = self.build(res_new, y_new)
        ho_b = heldout.error(start, effects) if heldout is not None else None
        ho_a = heldout.error(start, effects, remove=rem.refit, on_raw=rem.on_raw) if heldout is not None else None
        if rem.heldout_in_time is not None:
            rem.evidence["heldout_variance_ratio"] = rem.heldout_in_time
            rejected = not rem.heldout_in_time < 1.0
        else:
            rejected = ho_b is not None and ho_a is not None and not ho_a < ho_b
        if rejected:
            why = f"held-out error {ho_b} → {ho_a} %, variance ratio {rem.heldout_in_time}"
            self.consider(rem.effect, rem.params | {"rejected": why, "test": rem.evidence["test"]})
            return False
        if ho_b is not None:  # on the samples as they were, the five terms alone
            rem.evidence["heldout_test"] = {"before": ho_b, "after": ho_a}
        params = dict(rem.params)
        s_new = solve(c_new, start, effects)
        if rem.on_curve and not self.moves_curve(rem, c_new):
            return False
        # the noise terms fitted with the component in the samples and without it, side by side: what the
        # start model had taken of it (a temperature swing into B, K and R)
        rem.evidence["terms_before_after"] = terms_before_after(
            noise_fit(self.curve, start, effects, self.sol, self.result, self.unit, 0.683),
            noise_fit(c_new, start, effects, s_new, res_new, self.unit, 0.683),
        )
        st = Step(
            effect=rem.effect,
            params=params,
            intervals=rem.intervals,
            evidence=rem.evidence,
            before={},
            after={},
            truth_error=self.truth_error(rem.effect, params),
            final_params=dict(params),
            final_intervals=dict(rem.intervals),
        )
        parts = None
        if self.split0 is not None:
            parts = self.split0.corrected(self.removed[-1][4] if self.removed else self.raw, rem.refit, rem.on_raw)
        self.removed.append((st, rem, self.curve.avar - c_new.avar, c_new, parts))
        self.y, self.result, self.curve, self.heldout = y_new, res_new, c_new, h_new
        self.sol = s_new
        return True

    def moves_curve(self, rem: Removal, c_new: Curve) -> bool:
        """Whether removing ``rem`` moves an estimate of the record's Allan curve by at least
        :data:`.scoring.MATERIAL_Z` of its standard errors (:func:`.scoring.curve_change_z`, under the model so
        far). A removal whose test is in time alone (impulsive noise: a tail beyond the Gaussian's) may be real
        yet immaterial to the curve — one sample of 10⁶ beyond 7 σ on an ADIS16405 accelerometer moves τ₀'s
        estimate by 0.04 of its standard error — and then is no step of the model. Not the curve's error: the
        model's white term takes white-like spikes, and removing true spikes can raise it (scoring's note)."""
        z, tau = curve_change_z(self.curve, self.sol, self.curve.avar - c_new.avar)
        if z >= MATERIAL_Z:
            rem.evidence["curve_change"] = {"z": z, "tau": tau, "material_z": MATERIAL_Z}
            return True
        why = f"moves the Allan curve by {z:.2g} standard errors at most (τ {tau:.3g} s), < {MATERIAL_Z:g}"
        self.consider(rem.effect, rem.params | {"rejected": why, "test": rem.evidence["test"]})
        return False

    # ---- curve effects

    def add_curve_effects(self, candidates) -> None:
        """Curve effects one per step (at most :data:`MAX_STEPS`) while one is accepted; then an effect whose
        amplitude a later one took over entirely is dropped, and the steps are scored along the chain. Where the
        bandwidth named a sinc^k the steps run again without the sinc^k kinds, and the chain
        :func:`._rolloff.sinc_chain_kept` prefers is kept."""
        y = self.y
        exact = y is not None or (isinstance(self.est, str) and self.est == "oavar")
        thin = tracing.thin_indices(self.curve.tau)
        lines = []
        if y is not None and "sinusoid" in candidates:
            # one line search for both line effects (one share of level): the periodic removal's, or now
            search = self.line_search
            if search is None:
                search = periodic.periodic_search(y, self.fs, alpha("lines", self.level))
            # every line a family removal did not take: all of them without the periodic candidate, else the
            # lines of the families it turned down (their phase does not carry across the record's parts, their
            # power is still on the curve)
            fams = True if "periodic" not in candidates else self.declined_families
            if any(rem.effect == "periodic" for _st, rem, *_rest in self.removed):
                # a family removed in time takes the part of its lines whose phase carries across the record;
                # what power they keep (a wandering phase) is searched again on the samples the removals left,
                # every line there offered (conditional on a family found: no share of level under the null)
                search, fams = periodic.periodic_search(y, self.fs, alpha("lines", self.level)), True
            lines = periodic.sinusoid_lines(search, families=fams)
        fork = self.fork()
        self.curve_loop(candidates, thin, exact, lines)
        if sinc_named(self.effects):  # the kinds without the sinc^k carried too: the whole chain decides
            with_sinc = self.fork()
            self.effects, self.steps, self.lines, self.sol, self.considered = fork
            with without_sincs():
                self.curve_loop(candidates, thin, exact, lines)
            self.keep_chain(with_sinc)
        self.score()

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

    def keep_chain(self, with_sinc: tuple) -> None:
        """The chain that named a sinc^k (``with_sinc``, :meth:`fork`) or the one just run without the sinc^k
        kinds, whichever :func:`._rolloff.sinc_chain_kept` prefers; the other's final χ²/dof and effects in the
        kept bandwidth step's ``evidence["kind_chains"]``."""
        tie = self.curve.tau.size / self.curve.n_eff
        without = self.fork()
        chains = {
            name: {"chi2_dof": float(fk[3].chi2_dof), "effects": [base_name(k) for k, _p in fk[0]]}
            for name, fk in (("with_sinc", with_sinc), ("without_sinc", without))
        }
        if sinc_chain_kept(with_sinc[3], without[3], tie):
            self.effects, self.steps, self.lines, self.sol, self.considered = with_sinc
        for st in self.steps:
            if st.effect == "bandwidth":
                st.evidence["kind_chains"] = chains

    def curve_step(self, n_step, candidates, thin, exact, lines) -> bool:
        """One step: every candidate's proposal, the one :func:`choose` accepts added; False if none."""
        sub = self.curve.subset(thin)
        test = curve_test(self.curve, thin, self.sol, self.start, self.effects, exact)
        fam = families(sub, candidates, self.y is not None)
        thr = test.threshold(fam, alpha("curve", self.level), N_BOOT, seed=n_step)
        rnd = Round(self.curve, self.start, self.effects, self.sol, sub, test, thr, self.heldout, self.y, lines)
        prefetch(rnd, candidates)  # every candidate's bounded searches, run together
        props = [pr for name, c in CURVE_CANDIDATES.items() if name in candidates for pr in c.propose(rnd)]
        for pr in props:
            pr.record = {"param": float(pr.p), "statistic": float(pr.stat), "threshold": float(pr.thr)}
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

    def curve_effect_step(self, pr: Proposal, rnd: Round, ho_b, ho_a) -> Step:
        """The step of an accepted curve proposal (scored along the chain once the loop is done)."""
        cand = CURVE_CANDIDATES[pr.effect]
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

    def score(self) -> None:
        """The chain: each curve step with the effects up to it, fitted on the record's own curve; then each
        removal in time, the samples corrected by it and the ones before it, with every curve effect in the
        model (the last state is the final model). Each curve step's parameters after the final joint refit."""
        final = Round(self.curve, self.start, self.effects, self.sol)
        for j, st in enumerate(self.steps):
            effects = self.effects[: j + 1]
            last = j == len(self.steps) - 1 and not self.removed
            sol = self.sol if last else solve(self.curve0, self.start, effects)
            self.advance(st, self.chain(sol, effects))
            key, p = self.effects[j]
            st.final_params, st.final_intervals = final_params(key, p, self.lines[j], st.intervals, j, final)
            # against the truth: the final joint fit's values, but a spectral line's amplitude from the samples
            st.truth_error = self.truth_error(st.effect, st.params if self.lines[j] is not None else st.final_params)
        n_removed = 0
        for i, (st, rem, _own, curve, parts) in enumerate(self.removed):
            n_removed += rem.n_fitted
            sol = self.sol if i == len(self.removed) - 1 else solve(curve, self.start, self.effects)
            self.advance(st, self.chain(sol, self.effects, curve, n_removed, parts))
            st.evidence["scored_with"] = [base_name(k) for k, _p in self.effects] or "the five terms"
            _say_heldout_rise(st, rem)
        fams = [st for st, rem, *_rest in self.removed if rem.effect == "periodic"]
        fold_wandering(self.steps, self.lines, fams, self.truth_error)  # a family's own lines found again: one effect

    # ---- change points

    def change_point_steps(self, candidates) -> list:
        """Steps of the change points the held-out error per segment confirms (:func:`.changes.change_point_step`:
        on the record's curve its before and after are the model so far, the same numbers by construction; what
        found it, a chain of its own, in its evidence)."""
        y = self.y
        if y is None or "change_point" not in candidates:
            return []
        cps = change_points(y, self.fs, self.start)
        chain = None  # the held-out error per segment without any change point, with the first, …, with all
        if cps and self.heldout is not None:
            m_all = np.asarray(self.result.m, dtype=np.int64)
            times = [c["t"] for c in cps]
            chain = segments_heldout(self.heldout, y, self.fs, m_all, self.lo, self.hi, self.start, self.effects, times)
        if chain is not None and not chain[-1] < chain[0]:
            for c in cps:
                why = f"held-out error {chain[0]:.3g} → {chain[-1]:.3g} %"
                self.consider("change_point", {"t": c["t"], "gain_chi2": c["gain"], "rejected": why})
            cps = []
        self.change_points = cps
        steps = []
        for n, c in enumerate(cps):
            truth = self.truth.get("change_point") if self.truth else None
            st = change_point_step(c, None if chain is None else chain[n : n + 2], truth, y.size / self.fs)
            self.advance(st, self.state)
            steps.append(st)
        return steps

    # ---- the result

    def unexplained(self, chans, cp_steps=()) -> list:
        """What the final model still misses, every domain's check at its own share of ``level`` (the noise
        level's between the change points ``cp_steps``)."""
        exact = self.y is not None or (isinstance(self.est, str) and self.est == "oavar")
        thin = tracing.thin_indices(self.curve.tau)
        ctx = MissingContext(
            self.curve, thin, self.sol, self.start, self.effects, self.y, self.fs, self.level, exact, chans, self.unit
        )
        ctx.change_times = [st.params["t"] for st in cp_steps]
        ctx.heldout_pct = self.state[0].get("heldout_rms_adev_pct")
        ctx.samples = self.y0
        ctx.replaced = _replaced([rem for _st, rem, *_rest in self.removed], self.y0.size if self.y0 is not None else 0)
        ctx.families = [
            (st.params["fundamentals"], st.evidence["frequencies_hz"], st.evidence["amplitudes"], rem.component)
            for st, rem, *_rest in self.removed
            if rem.effect == "periodic"
        ]
        return unexplained(ctx)

    def refinement(self, cp_steps, unit, confidence, missing) -> Refinement:
        """The result: the start and the final model on the original record's curve, the steps in order."""
        removed = None
        if self.removed:
            own = {_component_name(st): change for st, _rem, change, _c, _p in self.removed}
            n_removed = sum(rem.n_fitted for _st, rem, _change, _c, _p in self.removed)
            removed = (self.curve0.avar - self.curve.avar, n_removed, own)
        res0, c0 = self.result0, self.curve0
        start_fit = noise_fit(c0, self.start, [], self.start_sol, res0, unit, confidence)
        final_fit = noise_fit(c0, self.start, self.effects, self.sol, res0, unit, confidence, removed)
        steps = self.steps + [st for st, *_rest in self.removed] + cp_steps
        return Refinement(
            steps=steps,
            fit=final_fit,
            start=start_fit,
            result=res0,
            terms=self.start,
            effects=self.effects,
            change_points=self.change_points,
            considered=self.considered,
            heldout_note=self.note,
            start_heldout_rms_adev_pct=self.start_heldout,
            scored_tau=c0.tau[self.scored],
            tau_range=(self.lo, self.hi),
            unexplained=missing,
            corrected=self.result if self.removed else None,
            term_moves=term_moves(start_fit, final_fit, steps, [s[2] for s in self.states]),
            level=self.level,
            start_errors=dict(self.states[0][0]),
            final_errors=dict(self.state[0]),
        )


def _replaced(removals: list[Removal], n: int) -> np.ndarray | None:
    """True at the samples the accepted ``"outliers"`` removals replaced (their component is non-zero only
    there), None where none did: the clipped and held checks of ``unexplained`` leave them out."""
    out = None
    for rem in removals:
        if rem.effect == "outliers" and rem.component.size == n:
            out = (rem.component != 0) if out is None else out | (rem.component != 0)
    return out


def _component_name(st: Step) -> str:
    """A removal's name among the final fit's components ("regression_<channel>" for a regression)."""
    return st.effect if st.effect != "regression" else f"regression_{st.params['channel']}"


# the registry's list under ``candidates``, every item indented as that parameter's description (the site's
# API reference fills the same list in: docs/_site/griffe_roles.py)
refine.__doc__ = (refine.__doc__ or "").replace("        {effects}", describe(" " * 8))


def _say_heldout_rise(st: Step, rem: Removal) -> None:
    """A removal accepted by its own held-out test (``rem.heldout_in_time``: a slow channel's across frequency,
    impulsive noise's flags) whose chain held-out error on the Allan curve still rose: said in
    ``evidence["heldout_note"]``, so that the rise is never silent (a slow channel fitted at lag 0 on a lagged
    temperature rose 2.13 → 2.76 % that way before the lag was profiled, docs/channels.md)."""
    b, a = st.before.get("heldout_rms_adev_pct"), st.after.get("heldout_rms_adev_pct")
    if rem.heldout_in_time is None or b is None or a is None or a < b:
        return
    st.evidence["heldout_note"] = (
        f"the held-out error on the Allan curve rose {b:.3g} → {a:.3g} %: this step was accepted by its own "
        f"held-out test (variance ratio {rem.heldout_in_time:.3g} < 1), not by that error"
    )
