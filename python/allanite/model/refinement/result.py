"""What :func:`allanite.refine` found: each added effect (:class:`Step`) and the whole refinement
(:class:`Refinement`) with its report, its notebook summary and its figures."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from ..._display import RichDisplay, Summary, Table, fmt_ci, thin
from ...results import AllanResult
from ...units import report_unit
from .. import fitting
from .._fitresult import report_header
from ..effects import EFFECTS, format_params
from ..terms import TERM_NAMES
from ._family_fold import folded
from ._gapfill import filled_words
from .levels import LEVEL
from .words import MISFIT_CHI2_DOF, declared_sentence, misfit_sentences, missing_sentences

if TYPE_CHECKING:  # the counter's module loads SciPy: not for a summary
    from .._counter import Counter

__all__ = ["Step", "Refinement", "term_moves", "term_move_text"]

#: The errors each step reports before and after it.
ERRORS = ("chi2_dof", "rms_z", "rms_adev_pct", "heldout_rms_adev_pct")


@dataclass
class Step:
    """One effect added by :func:`refine`.

    ``params`` in the input unit's base form, at acceptance (see :data:`allanite.model.effects.EFFECTS` for each
    effect's parameters and units: Gauss–Markov ``sigma`` rate unit, ``tc`` s; sinusoid ``amplitude`` rate unit,
    ``f0`` Hz; bandwidth ``cutoff`` Hz, ``taps``, ``filter``, where a floor is modelled (beside a Butterworth;
    another kind where the spectrum shows one) ``floor`` rate unit·√s; resonance ``sigma`` rate unit, ``f0`` Hz,
    ``q``; periodic ``fundamentals`` (a list, Hz), ``lines``, ``rms`` rate unit and, where its fundamental wanders
    and is tracked, ``wander_hz``, ``wander_pct``, ``wander_half_span_hz``; outliers ``rate`` (share of the
    samples), ``threshold`` rate unit; drift ``amplitude`` rate unit, ``T`` s; regression ``channel``,
    ``coefficient`` rate unit per channel unit and, where their tests keep them, ``quadratic``,
    ``rate_coefficient``, ``lag_s`` — beside a ``rate_coefficient`` alone ``coefficient`` only where its test
    keeps it; change point ``t`` s);
    ``intervals`` the numeric keys → (low, high); ``final_params``/``final_intervals`` the same after the final
    joint refit (a curve effect's amplitude refitted beside every other effect — a bandwidth's cutoff searched
    again beside them —, its nonlinear parameter's interval profiled again; what was measured in the time
    domain as accepted: a spectral line's amplitude and f0 — held in every fit of the curve —, a removal in
    time, a change point). ``before``/``after``:
    ``chi2_dof``, ``rms_z``, ``rms_adev_pct`` (on ``Refinement.scored_tau``), ``p_value``, ``deviance`` and ``aic``
    (χ² + ln det Σ under the χ²'s covariance — −2 ln L less n ln 2π — and that + 2 per fitted number: only their
    differences along one chain mean anything, :func:`allanite.model.refinement.scoring.settle_chi2`) and
    ``heldout_rms_adev_pct`` (None for curve-only input) of the model before and after the step, all on the
    original record's Allan curve — each step's ``before`` is the previous step's ``after`` (the steps in the
    chain's order: curve effects, then the removals in time, which were searched first, then change points);
    ``evidence``: where in τ, f or t the residual was and the test that accepted it (``heldout_test``: the held-out
    comparison on the samples as they were, where that is not the chain's — for a removal in time, the five terms
    alone without → with it, the other part's raw curve predicted both times (the removal is decided by its own
    test in time, ``heldout_variance_ratio``); a change point — whose before and after on the
    record's curve are the same numbers: a change of noise level leaves the curve's model as it is — has its
    statistic on the windows' levels in ``window_levels``, without → with it, every other change point in both,
    and held out per segment in ``heldout_test``, without → with it, the earlier change points in both; what it
    changed in ``adev_ratio``, the Allan deviation after / before it per τ with 95 % intervals, and in
    ``explains`` the Allan-curve departures only the louder segments carry, said there and not in ``unexplained``
    — :mod:`._segments`);
    ``truth_error``: relative parameter errors when ``truth`` was given.
    """

    effect: str
    params: dict
    intervals: dict
    evidence: dict
    before: dict
    after: dict
    delta_chi2_eff: float = 0.0
    truth_error: dict | None = None
    final_params: dict = field(default_factory=dict)
    final_intervals: dict = field(default_factory=dict)


def term_moves(start: fitting.NoiseFit, final: fitting.NoiseFit, steps: list, along: list) -> list:
    """The terms whose refined interval no longer overlaps the plain fit's, and which steps moved them: [{term,
    start, start_interval, final, final_interval, unit, moves: [{step, effect, before, after}]}] (base form;
    ``along[i]`` the terms' coefficients after ``i`` steps). The moves of at least a tenth of the whole change, in
    step order."""
    out = []
    for i, t in enumerate(start.terms):
        s, f = start.coefficients[t], final.coefficients[t]
        if f.ci[0] <= s.ci[1] and s.ci[0] <= f.ci[1]:
            continue
        vals = [float(v[i]) for v in along]
        moves = [
            {"step": k + 1, "effect": st.effect, "before": vals[k], "after": vals[k + 1]}
            for k, st in enumerate(steps)
            if k + 1 < len(vals) and vals[k + 1] != vals[k]
        ]
        moves.sort(key=lambda m: -abs(m["after"] - m["before"]))
        whole = abs(f.value - s.value)
        moves = sorted(
            [m for m in moves if abs(m["after"] - m["before"]) >= 0.1 * whole] or moves[:1], key=lambda m: m["step"]
        )
        out.append(
            {
                "term": t,
                "start": s.value,
                "start_interval": tuple(s.ci),
                "final": f.value,
                "final_interval": tuple(f.ci),
                "unit": s.unit,
                "moves": moves,
            }
        )
    return out


def term_move_text(m: dict, unit) -> str:
    """One sentence: which term the refinement moved away from the plain fit, and which steps moved it."""
    t = m["term"]
    conv, u = (lambda v: v), m["unit"] or "(base form)"
    if unit is not None:
        u = report_unit(t, 1.0, unit).unit
        conv = lambda v: report_unit(t, v, unit).value if np.isfinite(v) else v  # noqa: E731
    s0, (a0, b0) = conv(m["start"]), map(conv, m["start_interval"])
    s1, (a1, b1) = conv(m["final"]), map(conv, m["final_interval"])
    moves = ", ".join(
        f"step {mv['step']} ({mv['effect']}) {conv(mv['before']):.3g} → {conv(mv['after']):.3g}" for mv in m["moves"]
    )
    return (
        f"{t} ({TERM_NAMES.get(t, t)}) is {s1:.3g} [{a1:.3g}, {b1:.3g}] {u} refined, {s0:.3g} [{a0:.3g}, {b0:.3g}] "
        f"in the plain fit — the intervals do not overlap: the effects added took over (or gave back) part of "
        f"the curve the term had described; moved by {moves}."
    )


def _effect_name(steps, i) -> str:
    st = steps[i]
    same = [j for j, s in enumerate(steps) if s.effect == st.effect]
    return st.effect if len(same) == 1 else f"{st.effect} {same.index(i) + 1}"


@dataclass
class Refinement(RichDisplay):
    """What :func:`refine` found. ``fit`` is the final model (a NoiseFit whose ``coefficients`` also hold the
    curve effects' amplitudes, and whose ``components`` hold what each removal in time changed in the curve),
    ``start`` the starting model, ``steps`` the effects added — both fits, and every step's before/after, on
    the original record's Allan curve ``result``; ``corrected`` the curve of the samples after the removals in
    time (None when nothing was removed). ``heldout_note`` says how (or why not) the held-out error was
    computed; ``scored_tau`` the τ the RMS ADEV errors are scored on (:meth:`rms_adev_pct` gives a fit's);
    ``term_moves`` the terms whose refined interval no longer overlaps the plain fit's, and the steps that
    moved them; ``level`` the false-alarm level the tests spent. ``unexplained`` lists what the final model
    still misses — empty when every domain's calibrated check passes (at its share of ``level``), else one dict
    per region, largest misfit first: ``"domain"``, ``"tau"`` (lo, hi) s, ``"t"`` (lo, hi) s where the region
    is one along the record (the mean, steps, level, line, clipped and held checks), ``"band_hz"`` (lo, hi) or
    None, ``"chi2_dof"`` over that τ range, ``"what"``, and the test's ``"statistic"``, ``"threshold"``, ``"alpha"``
    (:mod:`allanite.model.refinement.missing`); :meth:`missing_sentences` says it in words. ``considered``: per
    effect, every proposal tried (its parameter, statistic and threshold); one whose test passed but that was not
    taken says why under ``"rejected"`` (χ²/dof not falling, a parameter at the edge of its range, the held-out
    error, another candidate taken at that step). ``effects`` the final model's curve columns [(key, nonlinear
    parameter)], steps[j] ↔ effects[j] (a spectral line's key,
    ``"sinusoid:held:<A²>:<its variance>:<coherent share>"``, carries the amplitude it is held at and the share
    of its power whose phase holds across the record: :func:`allanite.model.refinement.curvefit.held_key`).
    ``start_errors`` and ``final_errors``: the chain's errors of the starting and the final model (the first
    step's ``before`` and the last one's ``after``: χ²/dof on the tests' covariance,
    :func:`allanite.model.refinement.scoring.settle_chi2`) — what :meth:`report`, the summary and the report
    page say; ``fit.chi2_dof`` stays the weighted fit's own
    (EDF variances, the one its intervals are inflated by). ``counter``: the record read as a delta-angle counter's
    (:class:`allanite.model._counter.Counter`: its angle step, noise per sample, mean rate's phases), every Q column
    then its exact Allan variance; None otherwise."""

    steps: list
    fit: fitting.NoiseFit
    start: fitting.NoiseFit
    result: AllanResult
    terms: tuple
    effects: list = field(default_factory=list)
    change_points: list = field(default_factory=list)
    considered: dict = field(default_factory=dict)
    heldout_note: str = ""
    start_heldout_rms_adev_pct: float | None = None
    tau_range: tuple = (0.0, math.inf)
    scored_tau: np.ndarray | None = None
    unexplained: list = field(default_factory=list)
    corrected: AllanResult | None = None
    term_moves: list = field(default_factory=list)
    level: float = LEVEL
    start_errors: dict | None = None
    final_errors: dict | None = None
    #: ``refine(..., gaps="skip")`` on a record with missing samples: how many (``"samples"``, ``"fraction"``), in
    #: how many gaps (``"gaps"``, ``"longest_s"``, ``"runs"``: (start, length) each), filled how (``"method"``), and
    #: the largest change (%) the fill made to the Allan curve against the curve that skips the gaps
    #: (``"curve_change_pct"``); None for a gapless record.
    filled: dict | None = None
    #: The record read as a delta-angle counter's (:func:`allanite.model._counter.detect_counter`): its angle step,
    #: noise per sample and phase — every Q column was then the counter's exact Allan variance; None otherwise.
    counter: Counter | None = None
    #: ``refine(..., filter=...)``: the filter declared (``"type"`` FIR/IIR, ``"rate_hz"``, ``"decimation"``,
    #: ``"taps"`` or ``"order"``, ``"cutoff_hz"``, ``"words"``) — the bandwidth effect's one kind; None otherwise.
    declared_filter: dict | None = None

    def curve_errors(self, fit) -> dict:
        """χ²/dof, RMS z and RMS ADEV error (%) of ``start`` or ``fit`` on the record's curve: the chain's
        (``start_errors``/``final_errors``, the numbers every step's before/after carry), else the fit's own."""
        errs = self.start_errors if fit is self.start else self.final_errors if fit is self.fit else None
        if errs is not None:
            return {k: errs[k] for k in ("chi2_dof", "rms_z", "rms_adev_pct")}
        return {
            "chi2_dof": fit.chi2_dof,
            "rms_z": float(np.sqrt(np.mean(fit.z**2))),
            "rms_adev_pct": self.rms_adev_pct(fit),
        }

    def rms_adev_pct(self, fit) -> float:
        """RMS ADEV error (%) of a fit (``start`` or ``fit``) on the τ the steps' errors are scored on
        (``scored_tau``: 4 per octave, each estimate within ±10 %, EDF ≥ 50 under the five-term fit)."""
        sel = np.isin(fit.tau, self.scored_tau) if self.scored_tau is not None else slice(None)
        from .scoring import rms_adev_pct  # scoring loads scipy.stats and the tracing: not for a summary

        return rms_adev_pct(fit.avar[sel], fit.model[sel])

    @property
    def found(self) -> list:
        """Names of the effects kept, in the order they were added."""
        return [s.effect for s in self.steps]

    @property
    def final_heldout_rms_adev_pct(self) -> float | None:
        """The held-out error of the final model (the last step's after; the start's if nothing was added)."""
        return self.steps[-1].after.get("heldout_rms_adev_pct") if self.steps else self.start_heldout_rms_adev_pct

    def __repr__(self) -> str:
        """A few lines (the dataclass's own printed every field, arrays and the proposals tried included — pages
        in a terminal): what was found, the chain's errors start → final, what is still missing."""
        e0, e1 = self.curve_errors(self.start), self.curve_errors(self.fit)
        found = ", ".join(self.found) if self.steps else self._nothing_added()
        r = self.result
        lines = [
            f"Refinement({r.n_samples} samples at {r.fs:g} Hz, start {'+'.join(self.terms)}; {found}",
            f"  χ²/dof {e0['chi2_dof']:.3g} → {e1['chi2_dof']:.3g}, RMS ADEV error {e0['rms_adev_pct']:.3g} → "
            f"{e1['rms_adev_pct']:.3g} %, held-out {_fmt(self.start_heldout_rms_adev_pct)} → "
            f"{_fmt(self.final_heldout_rms_adev_pct)} %",
            *(f"  {st.effect}: {self.params_text(st, final=True)}" for st in self.steps),
            *(f"  {t}" for t in (self.missing_sentences() if self.unexplained else [])),
            "  .report(): the whole account; .fit: the final model; .steps: each effect with its test)",
        ]
        return "\n".join(lines)

    def _rate_unit(self) -> str | None:
        return self.fit.unit

    def params_text(self, st: Step, final: bool = False, digits: int = 4) -> str:
        """A step's parameters (at acceptance, or after the final joint refit) with intervals and units."""
        p, iv = (st.final_params, st.final_intervals) if final and st.final_params else (st.params, st.intervals)
        return format_params(st.effect, p, iv, self._rate_unit(), digits)

    def notes(self) -> list:
        """What a reader must know to read the numbers: where they are scored, and the terms refinement moved."""
        out = [
            "Every step is scored on the original record's Allan curve: each step's before is the previous step's "
            "after. Curve effects come first; then the components removed in time (removed before the curve "
            "effects were searched), each with every curve effect in the model and its exact Allan variance, "
            "AVAR(y) − AVAR(y − component), part of it. A change of noise level leaves the record's curve model as "
            "it is (the curve of a record whose level steps is the length-weighted mean of its segments' curves: a "
            "model of the same terms), so its before and after there are the same numbers; what found it is on the "
            "windows' levels along the record (evidence['window_levels'], each change point without → with it, every "
            "other one in both) and "
            "held out per segment (evidence['heldout_test']).",
            "Parameters measured in the time domain keep their time-domain values in the final joint refit: a "
            "spectral line's amplitude (its power in the samples' spectrum; the part whose phase carries across "
            "the record in evidence['coherent_amplitude']) and f0 are held in every fit of the curve, and the "
            "components removed in time (drift, regressions, line families, outliers) and change points are as "
            "accepted; the joint refit moves the amplitudes only the curve measures (σ of a Gauss–Markov term "
            "or a resonance, the noise terms).",
        ]
        said = "" if self.counter is None else self.counter.describe(self._rate_unit())
        counter = [said[:1].upper() + said[1:] + "."] if said else []
        return out + counter + [term_move_text(m, self.fit.unit) for m in self.term_moves]

    def report(self) -> str:
        """Markdown: the starting residual, each step with its parameters, evidence and errors, the final model."""
        e0 = self.curve_errors(self.start)
        ho = self.start_heldout_rms_adev_pct
        lines = [
            "# Model refinement",
            "",
            f"Starting model {'+'.join(self.terms)}: χ²/dof = {e0['chi2_dof']:.3g}, "
            f"RMS z = {e0['rms_z']:.3g}, RMS ADEV error = "
            f"{e0['rms_adev_pct']:.3g} %, held-out RMS ADEV error = " + (f"{ho:.3g} %." if ho is not None else "n/a."),
            "",
            f"Held-out error: {self.heldout_note}",
            "",
        ]
        if self.filled:
            lines += [f"Gaps: {filled_words(self.filled)}.", ""]
        if self.counter is not None:
            lines += [f"Quantisation: {self.counter.describe(self._rate_unit())}.", ""]
        if self.declared_filter is not None:
            lines += [declared_sentence(self.declared_filter, "bandwidth" in self.found), ""]
        if not self.steps:
            lines.append(self._nothing_added().capitalize() + ".")
        for i, st in enumerate(self.steps, 1):
            lines += self._step_lines(i, st)
        return "\n".join(lines + self._final_lines() + self._missing_lines())

    def missing_sentences(self) -> list[str]:
        """What the final model still misses, one sentence per entry of ``unexplained`` — or the one sentence
        saying that it passes every calibrated check, at the level they spent (the same words as the report
        page and the console: :mod:`allanite.model.refinement.words`)."""
        out = missing_sentences(self.unexplained, self.level)
        return out if self.unexplained else out + self._misfit_sentences()

    def _misfit_sentences(self) -> list[str]:
        """Beside "passes every calibrated check", where the final curve χ²/dof is ``MISFIT_CHI2_DOF`` or more:
        that number, what the checks test, where the largest residuals are, and a resolved K or R that sets the
        model at its longest τ (it may stand in for a slow periodic or a drift) — :func:`words.misfit_sentences`."""
        e = self.curve_errors(self.fit)
        chi2 = e.get("chi2_dof")
        if chi2 is None or not chi2 >= MISFIT_CHI2_DOF:
            return []
        f, record_s = self.fit, self.result.n_samples / self.result.fs
        z2 = np.asarray(f.z, dtype=np.float64) ** 2
        where = None
        if z2.size and np.isfinite(z2).any():
            big = np.flatnonzero(z2 >= 0.5 * np.nanmax(z2))
            lo, hi = float(f.tau[big[0]]), float(f.tau[big[-1]])
            where = {"tau": (lo, hi), "max_z": float(np.sqrt(np.nanmax(z2))), "clusters": record_s / hi}
        errors = self.final_errors or {}
        return misfit_sentences(chi2, errors.get("p_value"), where, self._stand_in(record_s))

    def _stand_in(self, record_s: float) -> dict | None:
        """The rate random walk or ramp of the final model where its interval excludes 0 and it is the largest
        component at the longest τ fitted, else None."""
        f = self.fit
        shares = {k: float(np.asarray(v)[-1]) for k, v in (f.components or {}).items() if np.size(v) == f.tau.size}
        if not shares:
            return None
        top = max(shares, key=shares.__getitem__)
        c = f.coefficients.get(top)
        if top not in ("K", "R") or c is None or not c.ci[0] > 0:
            return None
        value = f"{c.ieee:.3g} {c.ieee_unit}" if c.ieee is not None else f"{c.value:.3g} {c.unit or ''}".rstrip()
        return {"term": top, "name": TERM_NAMES[top], "value": value, "tau_max": float(f.tau[-1]), "record_s": record_s}

    def _nothing_added(self) -> str:
        """What to say when no effect was added: that the start passes — only when nothing is missing."""
        if not self.unexplained:
            return "nothing added: the starting model passes every calibrated check"
        return "nothing added: no candidate earned its parameters — but the model still misses something"

    def _missing_lines(self) -> list:
        lines = ["", "## What the model still misses", ""]
        if not self.unexplained:
            return lines + self.missing_sentences()
        return lines + [f"- {t}" for t in self.missing_sentences()]

    def _step_lines(self, i: int, st: Step) -> list:
        lines = [
            f"## Step {i}: {st.effect}",
            "",
            f"- parameters at acceptance: {self.params_text(st)}",
            f"- after the final joint refit: {self.params_text(st, final=True)}",
            f"- evidence: { {k: v for k, v in st.evidence.items() if k != 'terms_before_after'} }",
            "- before → after: " + ", ".join(f"{k} {_fmt(st.before.get(k))} → {_fmt(st.after.get(k))}" for k in ERRORS),
            "",
        ]
        tba = st.evidence.get("terms_before_after")
        if tba:
            lines += [f"- noise terms fitted before → after the removal: {_terms_side_by_side(tba)}", ""]
        if st.truth_error:
            lines += [
                "- error against the truth: " + ", ".join(f"{k} {100 * v:+.1f} %" for k, v in st.truth_error.items()),
                "",
            ]
        return lines

    def _final_lines(self) -> list:
        s1 = self.fit
        e1 = self.curve_errors(s1)
        ho = self.final_heldout_rms_adev_pct
        lines = [
            "## Final model",
            "",
            f"χ²/dof = {e1['chi2_dof']:.3g}, RMS z = {e1['rms_z']:.3g}, RMS ADEV error = "
            f"{e1['rms_adev_pct']:.3g} %, held-out RMS ADEV error = " + (f"{ho:.3g} %." if ho is not None else "n/a."),
            "",
        ]
        lines += [f"- {c!r}" for t, c in s1.coefficients.items() if t in self.terms]
        lines += [
            f"- {_effect_name(self.steps, i)}: {self.params_text(st, final=True)}"
            for i, st in enumerate(self.steps)
            if not folded(st)  # a family's own line found again: in the family's row
        ]
        return lines + [""] + [f"{n}" for n in self.notes()[1:]]

    def _steps_table(self) -> Table:
        rows = []
        for i, st in enumerate(self.steps, 1):
            b, a = st.before, st.after
            rows.append(
                [
                    i,
                    st.effect,
                    self.params_text(st),
                    self.params_text(st, final=True),
                    f"{_fmt(b.get('chi2_dof'))} → {_fmt(a.get('chi2_dof'))}",
                    f"{_fmt(b.get('rms_adev_pct'))} → {_fmt(a.get('rms_adev_pct'))}",
                    f"{_fmt(b.get('heldout_rms_adev_pct'))} → {_fmt(a.get('heldout_rms_adev_pct'))}",
                ]
            )
        header = (
            "step",
            "effect",
            "parameters at acceptance [interval]",
            "after the final joint refit",
            "χ²/dof before → after",
            "RMS ADEV error % before → after",
            "held-out % before → after",
        )
        return Table(header, rows, "effects added (each scored on the record's Allan curve)")

    def _final_table(self) -> Table:
        """The final model: each term, then each effect once, with the registry's units."""
        rows = []
        for t, c in self.fit.coefficients.items():
            if t not in self.terms:
                continue
            ieee = "—" if c.ieee is None or c.ieee_ci is None else fmt_ci(c.ieee, *c.ieee_ci)
            rows.append(
                [t, TERM_NAMES.get(t, ""), fmt_ci(c.value, *c.ci), c.unit or "base form", ieee, c.ieee_unit or "—"]
            )
        for i, st in enumerate(self.steps):
            if folded(st):  # a periodic family's own line found again: its power is in the family's rms
                continue
            label = EFFECTS[st.effect].label if st.effect in EFFECTS else ""
            rows.append([_effect_name(self.steps, i), label, self.params_text(st, final=True), "", "—", "—"])
        header = ("term or effect", "", "value [interval]", "unit", *report_header(self.fit.unit))
        return Table(header, rows, "final model")

    def _summary(self) -> Summary:
        s0 = self.start
        e0, e1 = self.curve_errors(s0), self.curve_errors(self.fit)
        facts: list = [
            ("starting model", "+".join(self.terms)),
            ("found", ", ".join(self.found) if self.steps else self._nothing_added()),
            ("χ²/dof", f"{e0['chi2_dof']:.3g} → {e1['chi2_dof']:.3g}"),
            ("RMS z", f"{e0['rms_z']:.3g} → {e1['rms_z']:.3g}"),
            ("RMS ADEV error %", f"{e0['rms_adev_pct']:.3g} → {e1['rms_adev_pct']:.3g}"),
            ("held-out %", f"{_fmt(self.start_heldout_rms_adev_pct)} → {_fmt(self.final_heldout_rms_adev_pct)}"),
            (
                "record",
                f"{self.result.n_samples} samples at {self.result.fs:g} Hz, τ {s0.tau[0]:.4g}–{s0.tau[-1]:.4g} s",
            ),
        ]
        if self.declared_filter is not None:
            facts.append(("declared filter", declared_sentence(self.declared_filter, "bandwidth" in self.found)))
        facts.append(("still missing", " ".join(self.missing_sentences())))
        if self.change_points:
            facts.append(("change points", ", ".join(f"t = {float(c['t']):.4g} s" for c in self.change_points)))
        tables = [self._steps_table()] if self.steps else []
        tables.append(self._final_table())
        for i, st in enumerate(self.steps, 1):
            tba = st.evidence.get("terms_before_after")
            if tba:
                tables.insert(
                    -1, _terms_table(tba, f"step {i} ({st.effect}): the noise terms before and after the removal")
                )
        return Summary(
            title="Refinement",
            what="what the starting noise model lacked, found and fitted by allanite.refine",
            facts=facts,
            tables=tables,
            notes=list(self.fit.notes) + self.notes(),
            figure=self._draw_small,
        )

    def _draw_small(self, ax) -> None:
        """The inline figure: estimates, starting and refined model (≤ MAX_POINTS points each)."""
        i, j = thin(len(self.start.tau)), thin(len(self.fit.tau))
        ax.loglog(self.start.tau[i], np.sqrt(self.start.avar[i]), "k.", ms=2, label="estimate")
        ax.loglog(self.start.tau[i], np.sqrt(self.start.model[i]), "C0-", lw=1, label="start")
        ax.loglog(self.fit.tau[j], np.sqrt(self.fit.model[j]), "C3-", lw=1, label="refined")
        ax.set_xlabel("τ (s)")
        ax.set_ylabel("ADEV")
        ax.legend(fontsize="small", frameon=False)

    def plot(self, fig=None):
        """Residuals before and after, and the ADEV with the starting and the final model."""
        import matplotlib.pyplot as plt

        fig = fig or plt.figure(figsize=(11, 4.2))
        ax1, ax2 = fig.subplots(1, 2)
        tau = self.start.tau
        ax1.loglog(tau, np.sqrt(self.start.avar), "ko", ms=3, label="estimate")
        ax1.loglog(tau, np.sqrt(self.start.model), "C0-", label="starting model")
        ax1.loglog(self.fit.tau, np.sqrt(self.fit.model), "C3-", label="refined model")
        ax1.set_xlabel("τ (s)")
        ax1.set_ylabel("Allan deviation")
        ax1.legend(fontsize="small")
        ax2.semilogx(tau, self.start.z, "C0.-", label="before")
        ax2.semilogx(self.fit.tau, self.fit.z, "C3.-", label="after")
        ax2.axhspan(-2, 2, color="0.9")
        ax2.set_xlabel("τ (s)")
        ax2.set_ylabel("normalised residual z")
        ax2.legend(fontsize="small")
        fig.tight_layout()
        return fig


def _fmt(v) -> str:
    return "n/a" if v is None else f"{v:.3g}"


def _terms_values(tba: dict, when: str) -> dict:
    """Term → "value [lo, hi] unit" (IEEE-952 units where the fit had a unit, else base form)."""
    ieee = tba.get("ieee", {}).get(when, {})
    out = {}
    for t, (v, lo, hi) in tba[when].items():
        if t in ieee:
            v, lo, hi, u = ieee[t]
            out[t] = f"{fmt_ci(v, lo, hi)} {u}"
        else:
            out[t] = fmt_ci(v, lo, hi)
    return out


def _terms_side_by_side(tba: dict) -> str:
    before, after = _terms_values(tba, "before"), _terms_values(tba, "after")
    return "; ".join(f"{t} {before[t]} → {after[t]}" for t in tba["terms"])


def _terms_table(tba: dict, caption: str) -> Table:
    before, after = _terms_values(tba, "before"), _terms_values(tba, "after")
    rows = [[t, TERM_NAMES.get(t, ""), before[t], after[t]] for t in tba["terms"]]
    return Table(("term", "", "before [interval]", "after [interval]"), rows, caption)
