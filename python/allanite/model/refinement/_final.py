"""The end of a refinement: the chain scored (each curve step, then each removal in time, the last state the
final model after the joint refit, with each step's parameters after it), the change points the held-out error
per segment confirms, what the final model still misses (:mod:`.missing`), and the :class:`.result.Refinement`
assembled.
"""

from __future__ import annotations

import numpy as np

from .. import tracing
from ._family_fold import fold_wandering
from ._line_gain import gain_component
from ._run import RunState
from ._segments import Segments
from .candidates import Round, final_params
from .changes import change_point_step, change_points
from .curvefit import base_name, noise_fit, solve
from .missing import MissingContext, unexplained
from .removals import Removal
from .result import Refinement, Step, term_moves
from .scoring import heldout_split, segments_heldout

__all__ = ["FinalModel"]


class FinalModel(RunState):
    """A refinement's chain scored, its change points, what it misses and its result, on
    :class:`._run.RunState`."""

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

    def change_point_steps(self, candidates, y: np.ndarray | None) -> list:
        """Steps of the change points the held-out error per segment confirms (:func:`.changes.change_point_step`:
        on the record's curve its before and after are the model so far, the same numbers by construction; what
        found it, a chain of its own, in its evidence), searched on ``y``, :meth:`after_curve`."""
        if y is None or "change_point" not in candidates:
            return []
        cps = change_points(y, self.fs, self.start)
        chain = None  # the held-out error per segment without any change point, with the first, …, with all
        if cps and self.heldout is not None:
            m_all = np.asarray(self.result.m, dtype=np.int64)
            times = [c["t"] for c in cps]
            whole = self.heldout if y is self.y else heldout_split(y, self.fs, m_all, self.lo, self.hi, self.start)
            if whole is not None:
                chain = segments_heldout(whole, y, self.fs, m_all, self.lo, self.hi, self.start, self.effects, times)
        if chain is not None and not chain[-1] < chain[0]:
            for c in cps:
                why = f"held-out error {chain[0]:.3g} → {chain[-1]:.3g} %"
                self.consider("change_point", {"t": c["t"], "gain_chi2": c["gain"], "rejected": why})
            cps = []
        self.change_points = cps
        self.segments = Segments.of(y, self.fs, [c["t"] for c in cps])
        steps = []
        for n, c in enumerate(cps):
            truth = self.truth.get("change_point") if self.truth else None
            st = change_point_step(c, None if chain is None else chain[n : n + 2], truth, y.size / self.fs)
            if self.segments is not None and n + 1 < len(self.segments.bounds):
                st.evidence["adev_ratio"] = self.segments.ratio_across(n)
            self.advance(st, self.state)
            steps.append(st)
        return steps

    def after_curve(self) -> np.ndarray | None:
        """The samples the steps after the curve effects see (the change points, the checks of ``unexplained``):
        the samples the removals left, less the part of each accepted line's term that its gain on a channel
        models, g·(x̃(t) − x̄)·Re(A·e^{2πif0t}) (:func:`._line_gain.gain_component`). The line itself stays in
        the samples, as every line the ``"sinusoid"`` curve candidate holds does (held on the curve at the exact
        Allan variance of the modelled component, the gain's part with it: :func:`._sinusoid.gain_key`); its
        modulation would
        otherwise read as the noise level changing along the record (``tests/test_line_gain.py``'s 2 Hz line
        ±20 % with a temperature cycling 1.5 times: two change points at 215 and 436 s of 600). The record's
        own samples as they were when no accepted line has a gain. An O(n) pass per line with a gain: the caller
        computes it once for both (:func:`.loop.refine`)."""
        y = self.y
        if y is None:
            return None
        for ln in self.lines:
            if ln is not None and ln.get("gain"):
                g = ln["gain"]
                y = y - gain_component(y.size, self.fs, float(ln["f0"]), g, self.channels[g["channel"]])
        return y

    def slow_line_kept(self, ln: dict) -> bool:
        """Whether a step took the line of few cycles ``ln`` (a ``"sinusoid"`` step at its frequency whose evidence
        holds its test in time)."""
        steps = list(self.steps) + [st for st, *_rest in self.removed]
        f0 = float(ln["f0"])
        return any(
            st.effect == "sinusoid" and "slow_line" in st.evidence and abs(st.params["f0"] - f0) <= 1e-9 * f0
            for st in steps
        )

    def unexplained(self, chans, y: np.ndarray | None, cp_steps=()) -> list:
        """What the final model still misses on ``y`` (:meth:`after_curve`), every domain's check at its own share
        of ``level`` (the noise level's between the change points ``cp_steps``)."""
        exact = self.y is not None or (isinstance(self.est, str) and self.est == "oavar")
        thin = tracing.thin_indices(self.curve.tau)
        ctx = MissingContext(
            self.curve, thin, self.sol, self.start, self.effects, y, self.fs, self.level, exact, chans, self.unit
        )
        ctx.change_times = [st.params["t"] for st in cp_steps]
        ctx.heldout_pct = self.state[0].get("heldout_rms_adev_pct")
        per_segment = [(st.evidence.get("heldout_test") or {}).get("after") for st in cp_steps]
        if per_segment and per_segment[-1] is not None:  # with every change point: the chain's last after
            ctx.segments_heldout_pct = per_segment[-1]
        ctx.samples = self.y0
        ctx.considered, ctx.offered_lines = self.considered, self.offered_lines
        if self.line_search is not None:  # the lines of few cycles no step took (all, without the sinusoid candidate)
            ctx.slow_lines = [ln for ln in self.line_search.get("slow", []) if not self.slow_line_kept(ln)]
        ctx.replaced = _replaced([rem for _st, rem, *_rest in self.removed], self.y0.size if self.y0 is not None else 0)
        ctx.families = [
            (st.params["fundamentals"], st.evidence["frequencies_hz"], st.evidence["amplitudes"], rem.component)
            for st, rem, *_rest in self.removed
            if rem.effect == "periodic"
        ]
        if cp_steps and self.segments is not None:
            ctx.memo["segments"] = self.segments
        missing = unexplained(ctx)
        for st in cp_steps:  # the departures of the record's curve only the louder segments carry
            st.evidence["explains"] = list(ctx.memo.get("change_point_regions") or [])
        return missing

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
