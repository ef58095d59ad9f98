"""What :func:`allanite.refine` found: each added effect (:class:`Step`) and the whole refinement
(:class:`Refinement`) with its report, its notebook summary and its figures."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..._display import RichDisplay, Summary, Table, fmt_ci, thin
from ...results import AllanResult
from .. import fitting
from ..effects import EFFECTS
from .scoring import rms_adev_pct

__all__ = ["Step", "Refinement", "describe_region"]


@dataclass
class Step:
    """One effect added by :func:`refine`.

    ``params`` in the input unit's base form (see :data:`allanite.model.effects.EFFECTS` for each
    effect's parameters and units: Gauss–Markov ``sigma`` rate unit, ``tc`` s; sinusoid ``amplitude``
    rate unit, ``f0`` Hz; bandwidth ``cutoff`` Hz, ``taps``, ``filter``; drift ``amplitude`` rate unit,
    ``T`` s; regression ``channel``, ``coefficient`` rate unit per channel unit; change point ``t`` s);
    ``intervals`` the numeric keys → (low, high); ``before``/``after``: ``chi2_dof``, ``rms_z``,
    ``rms_adev_pct`` (on ``Refinement.scored_tau``), ``p_value`` and ``heldout_rms_adev_pct`` (None for
    curve-only input); ``evidence``: where in τ, f or t the residual was and the test that accepted it;
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


@dataclass
class Refinement(RichDisplay):
    """What :func:`refine` found. ``fit`` is the final model (a NoiseFit whose ``coefficients`` also
    hold the added effects' parameters), ``start`` the starting model, ``steps`` the effects added.
    ``heldout_note`` says how (or why not) the held-out error was computed; ``scored_tau`` the τ the RMS ADEV
    errors are scored on (:meth:`rms_adev_pct` gives a fit's). ``unexplained`` lists what the final model still
    misses — empty when every domain's calibrated check passes (at its share of ``level``), else one dict per
    region, largest misfit first: ``"domain"``, ``"tau"`` (lo, hi) s, ``"band_hz"`` (lo, hi) or None,
    ``"chi2_dof"`` over that τ range, ``"what"``, and the test's ``"statistic"``, ``"threshold"``, ``"alpha"``
    (:mod:`allanite.model.refinement.missing`)."""

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

    def rms_adev_pct(self, fit) -> float:
        """RMS ADEV error (%) of a fit (``start`` or ``fit``) on the τ the steps' errors are scored on
        (``scored_tau``: 4 per octave, each estimate within ±10 %, EDF ≥ 50 under the five-term fit)."""
        sel = np.isin(fit.tau, self.scored_tau) if self.scored_tau is not None else slice(None)
        return rms_adev_pct(fit.avar[sel], fit.model[sel])

    @property
    def found(self) -> list:
        """Names of the effects kept, in the order they were added."""
        return [s.effect for s in self.steps]

    def report(self) -> str:
        """Markdown: the starting residual, each step with its parameters, evidence and errors."""
        s0 = self.start
        ho = self.start_heldout_rms_adev_pct
        lines = [
            "# Model refinement",
            "",
            f"Starting model {'+'.join(self.terms)}: χ²/dof = {s0.chi2_dof:.3g}, "
            f"RMS z = {np.sqrt(np.mean(s0.z**2)):.3g}, RMS ADEV error = "
            f"{self.rms_adev_pct(s0):.3g} %, held-out RMS ADEV error = "
            + (f"{ho:.3g} %." if ho is not None else "n/a."),
            "",
            f"Held-out error: {self.heldout_note}",
            "",
        ]
        if not self.steps:
            lines.append(
                "Nothing added: the starting model passes every calibrated check."
                if not self.unexplained
                else "Nothing added: no candidate earned its parameters — but the model still misses something (below)."
            )
        for i, st in enumerate(self.steps, 1):
            ps = ", ".join(_fmt_param(k, v, st.intervals.get(k)) for k, v in st.params.items())
            lines += [
                f"## Step {i}: {st.effect}",
                "",
                f"- parameters: {ps}",
                f"- evidence: {st.evidence}",
                "- before → after: "
                + ", ".join(
                    f"{k} {_fmt(st.before.get(k))} → {_fmt(st.after.get(k))}"
                    for k in ("chi2_dof", "rms_z", "rms_adev_pct", "heldout_rms_adev_pct")
                ),
                "",
            ]
            if st.truth_error:
                lines.append(
                    "- error against the truth: "
                    + ", ".join(f"{k} {100 * v:+.1f} %" for k, v in st.truth_error.items())
                )
                lines.append("")
        lines += ["## What the model still misses", ""]
        lines += [f"- {describe_region(r)}" for r in self.unexplained] or [
            "Nothing: every domain's calibrated check passes against the final model."
        ]
        return "\n".join(lines)

    def _summary(self) -> Summary:
        s0, s1 = self.start, self.fit
        rows = []
        for i, st in enumerate(self.steps, 1):
            units = {name: unit for name, unit, _ in EFFECTS[st.effect].params} if st.effect in EFFECTS else {}
            ps = "; ".join(
                f"{k} = {fmt_ci(v, *st.intervals[k])} {units.get(k, '')}".rstrip() for k, v in st.params.items()
            )
            rows.append(
                [
                    i,
                    st.effect,
                    ps,
                    f"{st.before['chi2_dof']:.3g} → {st.after['chi2_dof']:.3g}",
                    f"{st.before['rms_adev_pct']:.3g} → {st.after['rms_adev_pct']:.3g}",
                ]
            )
        facts: list = [
            ("starting model", "+".join(self.terms)),
            ("found", ", ".join(self.found) if self.steps else "nothing: the starting model fits"),
            ("χ²/dof", f"{s0.chi2_dof:.3g} → {s1.chi2_dof:.3g}"),
            ("RMS z", f"{np.sqrt(np.mean(s0.z**2)):.3g} → {np.sqrt(np.mean(s1.z**2)):.3g}"),
            (
                "record",
                f"{self.result.n_samples} samples at {self.result.fs:g} Hz, τ {s0.tau[0]:.4g}–{s0.tau[-1]:.4g} s",
            ),
        ]
        facts.append(
            (
                "still missing",
                "; ".join(describe_region(r) for r in self.unexplained)
                if self.unexplained
                else "nothing: every calibrated check passes",
            )
        )
        if self.change_points:
            facts.append(("change points", ", ".join(f"t = {float(c['t']):.4g} s" for c in self.change_points)))
        tables = []
        if rows:
            tables.append(
                Table(
                    (
                        "step",
                        "effect",
                        "parameters [interval]",
                        "χ²/dof before → after",
                        "RMS ADEV error % before → after",
                    ),
                    rows,
                    "effects added",
                )
            )
        tables.append(fitting.coefficient_table(s1.coefficients, "final model"))
        return Summary(
            title="Refinement",
            what="what the starting noise model lacked, found and fitted by allanite.refine",
            facts=facts,
            tables=tables,
            notes=list(s1.notes),
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


def _fmt_param(k, v, iv) -> str:
    if isinstance(v, str):
        return f"{k} = {v}"
    if iv is None:
        return f"{k} = {v:.4g}"
    return f"{k} = {v:.4g} [{iv[0]:.4g}, {iv[1]:.4g}]"


def describe_region(reg: dict) -> str:
    """One entry of ``Refinement.unexplained`` in words: "the model still misses τ 0.2–3 s (≈ 0.17–2.5 Hz): …"."""
    lo, hi = reg["tau"]
    text = f"τ {_num(lo)}–{_num(hi)} s" if hi > lo else f"τ {_num(lo)} s"
    band = reg.get("band_hz")
    if band is not None:
        text += f" (≈ {_num(band[0])}–{_num(band[1])} Hz)"
    if reg.get("what"):
        text += f": {reg['what']}"
    if reg.get("chi2_dof") is not None and math.isfinite(reg["chi2_dof"]):
        text += f", χ²/dof {_num(reg['chi2_dof'])} there"
    return text


def _num(v: float) -> str:
    if v == 0 or not math.isfinite(v):
        return f"{v:g}"
    digits = max(0, 1 - int(math.floor(math.log10(abs(v)))))
    return f"{v:.{min(digits, 6)}f}" if abs(v) < 1000 else f"{v:.3g}"
