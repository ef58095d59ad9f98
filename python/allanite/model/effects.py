"""Effects the five-term noise model lacks — one registry entry each.

An effect is what :func:`allanite.refine` may add to a fitted model when the residual asks for it:
its parameters with their units, and how it is found — by its Allan-variance signature on the curve
(``kind="curve"``: an amplitude fitted linearly, one nonlinear parameter searched on a grid), or in
the samples along time (``kind="time"``: change points). Adding an effect is one entry here.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._display import fmt, fmt_ci
from ._shaped import SHAPED_ORDERS, shaped_avar, shaped_q_factor
from ._signatures import (
    BUTTERWORTH_ORDERS,
    CASCADE_SPANS,
    FILTERS,
    NOTCH_Q,
    RESONANCE_Q,
    RESONANCE_SHAPES,
    SINC_ORDERS,
    butterworth_order,
    butterworth_terms,
    drift_avar,
    filter_autocorrelation,
    filter_cutoff,
    filtered_white_avar,
    gm_avar,
    notch_kind,
    notch_zpk,
    resonance_avar,
    sinc_order,
    sinusoid_avar,
    split_notch,
)

__all__ = [
    "Effect",
    "EFFECTS",
    "gm_avar",
    "sinusoid_avar",
    "filtered_white_avar",
    "filter_autocorrelation",
    "filter_cutoff",
    "butterworth_terms",
    "butterworth_order",
    "drift_avar",
    "describe",
    "param_units",
    "channel_units",
    "format_param",
    "format_params",
    "FILTERS",
    "BUTTERWORTH_ORDERS",
    "SINC_ORDERS",
    "sinc_order",
    "CASCADE_SPANS",
    "RESONANCE_Q",
    "RESONANCE_SHAPES",
    "resonance_avar",
    "NOTCH_Q",
    "notch_kind",
    "split_notch",
    "notch_zpk",
    "SHAPED_ORDERS",
    "shaped_avar",
    "shaped_q_factor",
]


@dataclass(frozen=True)
class Effect:
    """One candidate effect.

    Attributes
    ----------
    name : str
        What ``candidates=`` and ``Step.effect`` call it.
    label : str
        Its name in words, for reports.
    kind : {"curve", "time"}
        Found on the Allan curve by its signature, or in the samples along time.
    params : tuple of (name, unit, meaning)
        The parameters a :class:`~allanite.model.refinement.Step` reports, in order; "rate unit" is
        the samples' rate unit. For curve effects the first is the amplitude (fitted linearly), the
        second the nonlinear parameter.
    description : str
        What it is, with its Allan-variance form.
    signature : callable, optional
        ``signature(tau, p, fs)``: Allan variance per unit amplitude squared (curve effects).
    alpha : callable, optional
        ``alpha(tau, p)``: the power-law noise type it resembles at each τ (for the estimates' EDF).
    search : callable, optional
        ``search(tau_min, tau_max)``: the grid of the nonlinear parameter to search.
    domain : str
        Where it is traced: "allan" (the curve's residual), "psd" (Welch periodogram), "time" (the samples
        along time), "channels" (other channels of the log).
    replaces : str, optional
        The term whose noise the effect's column carries ("N" for a bandwidth: the filtered white noise *is* the
        white rate noise, reported as N; "Q" for shaped quantisation, reported as the Q line it shows from m = k
        on); the term's own column is zeroed — beside a Butterworth it stays, as
        white noise added after the filter (its ``floor``; :func:`allanite.model.refinement.curvefit.has_floor`),
        and beside another kind where the samples' spectrum shows a floor (:func:`.refinement._rolloff.floor_choice`).
    """

    name: str
    label: str
    kind: str
    params: tuple[tuple[str, str, str], ...]
    description: str
    signature: Callable[[np.ndarray, float, float], np.ndarray] | None = None
    alpha: Callable[[np.ndarray, float], np.ndarray] | None = None
    search: Callable[[float, float], np.ndarray] | None = None
    domain: str = "allan"
    replaces: str | None = None

    @property
    def param_names(self) -> tuple[str, ...]:
        """Names of the effect's parameters, in order."""
        return tuple(p[0] for p in self.params)


#: The candidates :func:`allanite.refine` may add, by name, in the order they are tried.
EFFECTS: dict[str, Effect] = {
    e.name: e
    for e in (
        Effect(
            "gauss_markov",
            "Gauss–Markov",
            "curve",
            (
                ("sigma", "rate unit", "standard deviation of the Gauss–Markov rate"),
                ("tc", "s", "correlation time T_c"),
            ),
            "first-order Gauss–Markov rate: σ²·(T_c/τ)²·(2τ/T_c − 3 + 4e^{−τ/T_c} − e^{−2τ/T_c}); a bump near "
            "τ ≈ 1.89·T_c, T_c searched in [5·τ_min, τ_max/4] so the bump lies inside the curve (a shorter T_c is "
            "a roll-off of the shortest τ: the bandwidth)",
            signature=lambda tau, tc, fs: gm_avar(tau, tc),
            alpha=lambda tau, tc: np.where(tau < tc, -2, 0),
            search=lambda tmin, tmax: np.geomspace(5.0 * tmin, tmax / 4.0, 40),
        ),
        Effect(
            "sinusoid",
            "sinusoid",
            "curve",
            (
                ("amplitude", "rate unit", "amplitude A of the rate sinusoid"),
                ("f0", "Hz", "frequency f0"),
                ("channel", "", "the channel its amplitude follows, with samples and channels, when kept"),
                ("gain", "per channel unit", "relative change g of A per unit of that channel, when kept"),
            ),
            "rate sinusoid A·sin(2πf0t): A²·sin⁴(πf0τ)/(πf0τ)², nulls at τ = k/f0. With samples it is found as a "
            "line of the Welch PSD (a bin above its neighbours' median beyond the F quantile of the Welch "
            "average against that median, Bonferroni over the bins), f0 refined on the periodogram, A from the "
            "line's power over its width (held in every fit of the curve; the least-squares A at f0 in "
            "evidence['coherent_amplitude']); where channels are given, A·(1 + g·(channel − mean)) when its own "
            "nested test and held-out blocks keep it (refinement._line_gain), the term then held at that modelled "
            "component's exact Allan variance; "
            "on a curve only, f0 ≥ 2/τ_max so that two nulls fall inside it",
            signature=lambda tau, f0, fs: sinusoid_avar(tau, f0, fs),
            alpha=lambda tau, f0: np.zeros(np.asarray(tau).size, dtype=int),
            search=lambda tmin, tmax: np.geomspace(2.0 / tmax, 0.5 / tmin, 120),
            domain="psd",
        ),
        Effect(
            "bandwidth",
            "sensor bandwidth (low-pass)",
            "curve",
            (
                ("cutoff", "Hz", "−3 dB frequency of the low-pass on the rate noise"),
                (
                    "taps",
                    "samples",
                    "FIR length (moving average L, Bartlett 2L − 1; a boxcar's span D·f_s, any real; a sinc^k's "
                    "span per boxcar, 1 for a CIC read at its output rate; a declared FIR's length); 0 for a single "
                    "pole, a Butterworth or a declared IIR",
                ),
                (
                    "floor",
                    "rate unit·√s",
                    "white rate noise added after the filter (the output's quantisation, a readout's noise), as N: "
                    "the N column beside the filtered one, 0 where there is none; beside a Butterworth always, beside "
                    "another kind only where the spectrum above f_s/4 shows one and the fit agrees with it",
                ),
                ("notch_f", "Hz", "centre of a digital notch after the low-pass (``filter`` ``<kind>+notch``)"),
                ("notch_q", "", "the notch's quality factor, f_n over its −3 dB width"),
                (
                    "ripple",
                    "dB",
                    "a sharp kind's signed passband ripple (``filter`` ``elliptic4``, ``elliptic6``, decimated "
                    "``…_dec4``): positive where the gain rises above DC (an even order), negative where it dips",
                ),
                ("passband_edge", "Hz", "a sharp kind's passband edge f_c, where the gain leaves the ripple band"),
            ),
            "the sensor's low-pass on its white rate noise (single pole, the moving-average/Bartlett FIR of a "
            "decimating MEMS part, a boxcar of any span read at the output rate, a CIC decimator's sinc^k of "
            "order 2 to 5, ``sinc2`` … ``sinc5``, or the Butterworth anti-alias "
            "stage of a MEMS or tactical gyro, orders 2 to 6, ``butterworth2`` … ``butterworth6``, or a sharp rippled "
            "elliptic of fixed order and stop band whose signed ripple is searched, ``elliptic4``, ``elliptic6``, "
            "``elliptic4_dec4``, ``elliptic6_dec4``): "
            "N²·(1/2m²)·Σ_l A_m(l)·r(l)/τ0, exact in discrete time, in place of N²/τ — a "
            "roll-off of the shortest τ; the N it reports is the white noise before the filter. Beside a Butterworth "
            "(and beside another kind where the spectrum above f_s/4 shows a floor the fit agrees with) "
            "the N²/τ column stays, non-negative, as white noise added after the filter (``floor``: a digital "
            "part's quantised output adds a step Δ's Δ²/12 per sample, floor = Δ·√(τ0/12); a readout's noise): a "
            "steep filter's stop band is then flat, not a resonance. With samples, a digital notch "
            "(``scipy.signal.iirnotch``) may follow the low-pass — a kind of its own, ``<kind>+notch``, named where "
            "its nested test passes and the Welch spectrum shows it. Accepted first, its parameter is searched "
            "again beside the terms later steps add. With ``refine(..., filter=...)`` the user's own filter (FIR "
            "taps or IIR (b, a), its rate and decimation) is the one kind, exact (aliasing included), its shape "
            "fixed: ``filter`` ``declared``, ``cutoff`` its −3 dB frequency without an interval",
            signature=None,
            alpha=lambda tau, p: np.zeros(np.asarray(tau).size, dtype=int),
            search=None,
            replaces="N",
        ),
        Effect(
            "resonance",
            "resonance (narrowband noise)",
            "curve",
            (
                ("sigma", "rate unit", "standard deviation of the narrowband rate noise"),
                ("f0", "Hz", "centre frequency f_r of its PSD hump"),
                ("q", "", "quality factor f_r / full width at half maximum (searched at 2, 4, 8, 16)"),
                ("shape", "", "``lorentzian`` (the default) or ``bandpass``, the one the fit chose"),
            ),
            "narrowband rate noise — a resonance driven by broadband noise, or a hump of vibration, in one of two "
            "shapes: ``lorentzian``, autocorrelation σ²·e^{−πf_r·l/(Q·f_s)}·cos(2πf_r·l/f_s) (a Lorentzian "
            "pair: a mechanical mode seen as a rate bump, its PSD not zero at DC, a white-like 1/τ tail), or "
            "``bandpass``, white noise through the digital resonator ``scipy.signal.iirpeak`` designs (zeros at "
            "DC and Nyquist: a sense mode read through a demodulator; a 1/τ² tail, no white level to trade with "
            "N). The Lorentzian is taken unless a band-pass column beside it passes the curve test asked again "
            "with the Lorentzian in the model, and the band-pass resonance alone fits the curve better and "
            "lowers the held-out error; a chain that took one is kept only where its final χ² beats "
            "the chain with the Lorentzian shape alone. Allan variance exact in discrete time (Σ_l A_m(l)·R(l)/2m²); "
            "a bump near τ ≈ 0.37/f_r with a dip beyond. A spectral line is the limit "
            "Q → ∞ (found in the PSD instead). f_r is searched at the short-τ end, from 0.05/τ_min to 0.49/τ_min "
            "(5–49 Hz at 100 Hz): a hump near the bandwidth; slower bumps are Gauss–Markov terms",
            signature=None,
            alpha=lambda tau, p: np.zeros(np.asarray(tau).size, dtype=int),
            search=lambda tmin, tmax: np.geomspace(0.05 / tmin, 0.49 / tmin, 24),
            domain="allan",
        ),
        Effect(
            "shaped_quantisation",
            "shaped quantisation (sigma delta modulator)",
            "curve",
            (
                (
                    "q",
                    "rate unit·s",
                    "the quantiser's level before its shaping, σ_e·τ0 (σ_e = Δ/√12 for a step Δ of the rate): the "
                    "IEEE-952 Q of a plain quantiser of that step; the model's Q is the white angle noise the shaped "
                    "noise shows from m = k on, √C(2k − 2, k − 1)·q",
                ),
                ("order", "", "k, the order of the shaping (1 − z⁻¹)^k: 2 or 3"),
            ),
            "the quantisation error of a sigma-delta modulator shaped by (1 − z⁻¹)^k (k = 2, 3), as most MEMS parts "
            "digitise: (q/τ0)·Δ^k w, its autocorrelation the binomial sequence (−1)^l·C(2k, k + l), its Allan "
            "variance exact for sampled data (allanite.model._shaped) in place of the Q column — white angle "
            "noise of Q² = C(2k − 2, k − 1)·q² from m = k on, above that line at the first k − 1 averaging factors "
            "(k = 2: 5/3 of it at τ0), its PSD rising toward f_s/2 as sin^{2k}(πf/f_s). Proposed with samples only, "
            "where the Welch PSD rises toward f_s/2 faster than white angle noise's sin² allows (the sin⁴ and sin⁶ "
            "parts of its best non-negative mix carry ≥ 25 % of 0.42–0.49·f_s; a low-pass falling to f_s/2 gives "
            "none), the order with the lower χ²; tested by the Allan-curve test with the other curve effects and, "
            "like the sensor's roll-off, taken before the rest, and before a bandwidth that fits the curve better "
            "by less than one effective point per octave; its held-out error judged where its column differs from "
            "the Q line. A modulator followed by a decimation filter (a CIC's sinc^k) reads as "
            "that filter's bandwidth: the filter removes the shaped noise above its cutoff",
            signature=lambda tau, k, fs: shaped_avar(tau, k, fs),
            alpha=lambda tau, k: np.full(np.asarray(tau).size, 2, dtype=int),
            search=lambda tmin, tmax: np.array(SHAPED_ORDERS, dtype=np.float64),
            replaces="Q",
        ),
        Effect(
            "drift",
            "warm-up drift",
            "time",
            (("amplitude", "rate unit", "amplitude a of a·e^{−t/T} at t = 0"), ("T", "s", "time constant T")),
            "an exponential warm-up a·e^{−t/T} of the rate, fitted to block means along the record (T from "
            "L/200 to L/2; a constant slope stays the R term); its Allan variance in closed form",
            domain="time",
        ),
        Effect(
            "regression",
            "regression on another channel",
            "time",
            (
                ("channel", "", "name of the other channel (as passed in channels=)"),
                (
                    "coefficient",
                    "rate unit per channel unit",
                    "sensitivity: g-sensitivity, temperature, coupling; beside a quadratic, the slope at the channel's "
                    "mean over the record (evidence['terms']['quadratic']['t_ref']); on a slow channel absent where a "
                    "d(channel)/dt term carries the coupling and the level term's own test drops it",
                ),
                ("quadratic", "rate unit per channel unit²", "on (channel − mean)², slow channels, when kept"),
                ("rate_coefficient", "rate unit per (channel unit/s)", "on d(channel)/dt, slow channels, when kept"),
                ("lag_s", "s", "the rate follows the channel through a first-order lag, slow channels, when kept"),
            ),
            "the rate regressed on another channel of the log, removed before the noise fit. A fast channel "
            "(an accelerometer, a multi-position profile): least squares within 8 blocks in time (coefficient: "
            "the whole-record value), band by band (octaves) where the coupling differs across frequency "
            "(evidence['bands']). A slow channel (≥ 50 % of its variance between the blocks' means: a "
            "temperature): Whittle GLS against the record's own noise, with a quadratic, a d(channel)/dt term or "
            "a lag where their own tests keep them (allanite.model.channels, docs/channels.md)",
            domain="channels",
        ),
        Effect(
            "periodic",
            "family of spectral lines",
            "time",
            (
                (
                    "fundamentals",
                    "Hz",
                    "the family's generators: [f0] for harmonics k·f0, [f1, f2] for lines k·f1 + s·f2 (sidebands "
                    "±s·f2 around the multiples of f1)",
                ),
                ("lines", "", "lines in the family"),
                (
                    "rms",
                    "rate unit",
                    "RMS of the family's lines, √(Σ A_i²/2): the component removed in time with the power that "
                    "sinusoids found again at its own lines hold (a wandering phase; the removed part alone in "
                    "evidence['coherent_rms'])",
                ),
                (
                    "wander_hz",
                    "Hz",
                    "rms of the fundamental's instantaneous frequency about its mean, when its phase is tracked (a "
                    "wandering fundamental: allanite.model.wander; then fundamentals is [its mean])",
                ),
                ("wander_pct", "%", "wander_hz over the mean fundamental, when tracked"),
                ("wander_half_span_hz", "Hz", "half the 1–99 % span of the instantaneous frequency, when tracked"),
            ),
            "every significant line of the Welch PSD (Blackman–Harris, the neighbours' median, Bonferroni over the "
            "bins, at the line share of level) grouped into families on a lattice — harmonics k·f0, sidebands "
            "k·f1 ± s·f2, aliases folded — each family's lattice points tested where it predicts them, the "
            "frequencies refined on the samples (Gauss–Newton on the lines' offsets) and the family removed in time "
            "by least squares at them (allanite.model.periodic); held out, amplitudes and phases are refitted on "
            "the held-in blocks with the frequencies fixed. A family of harmonics whose fundamental wanders (a nested "
            "test at its share of level) is removed with the fundamental's phase tracked, each harmonic at its order "
            "times that phase; so is a lone line whose frequency wanders (a family of one order: lines 1, its tracked "
            "phase taking at least half of what the fixed sinusoid left around it). A line no family takes stays a "
            "sinusoid",
            domain="psd",
        ),
        Effect(
            "outliers",
            "impulsive noise (outliers)",
            "time",
            (
                ("rate", "", "share of the samples flagged"),
                (
                    "threshold",
                    "rate unit",
                    "a sample is flagged when its distance from the slow level exceeds this (noise white at the "
                    "shortest lag), else when the differences into and out of it both do, with opposite signs",
                ),
            ),
            "samples beyond what Gaussian noise predicts: clusters of first differences beyond 4–7 robust σ (per "
            "block; lattice-aware on quantised samples) against more than twice their Gaussian expectation "
            "(Poisson, Bonferroni over the cuts, at the outlier share of level); the flagged samples replaced by a "
            "draw from what Gaussian noise puts there (the slow level plus white noise as wide as the samples "
            "left where the noise is white at the shortest lag, else the line between the neighbours plus the "
            "second difference's noise), tested again on what is left (up to 4 passes: a heavy tail's scale "
            "shrinks as it is cut) and the noise refitted (allanite.model.outliers). Never applied by avar",
            domain="time",
        ),
        Effect(
            "telegraph",
            "random telegraph (burst, popcorn) noise",
            "time",
            (
                ("amplitude", "rate unit", "the upper level less the lower"),
                ("dwell_low", "s", "mean time at the lower level"),
                ("dwell_high", "s", "mean time at the upper level"),
            ),
            "a rate switching between two levels after exponential dwells: Allan variance the Gauss–Markov one "
            "with σ² = A²·p(1 − p), p = dwell_high/(dwell_low + dwell_high), T_c = 1/(1/dwell_low + 1/dwell_high) "
            "(its spectrum a Lorentzian). Found in time by the excess kurtosis of the Allan differences at octave τ "
            "against a Gaussian process of their own autocorrelation (Anscombe–Glynn at n/Σρ⁴ terms, Bonferroni over "
            "the octaves), its levels and switches decoded (a two-state hidden Markov chain on block means over a "
            "slow baseline) and removed — taken only where the levels stand clear of the noise, each is visited at "
            "least 3 times, its dwells are not all alike (a pulse train is periodic) and the samples less it pass "
            "the test (allanite.model.telegraph); else a Gauss–Markov term on the curve stands for it",
            domain="time",
        ),
        Effect(
            "change_point",
            "changes of noise level",
            "time",
            (("t", "s", "time of a step in the noise level, from the start of the record"),),
            "a step in the Allan variance of non-overlapping windows along the record (all τ jointly), located "
            "to the sample by a two-segment likelihood; needs the samples",
            domain="time",
        ),
    )
}


def describe(indent: str = "        ") -> str:
    """The candidates as a numpydoc-style list: name, parameters with units, what each is; every item
    ``indent``-ed alike (in a docstring, the list under its parameter's description)."""
    lines = []
    for e in EFFECTS.values():
        params = ", ".join(f"``{n}`` ({u})" for n, u, _ in e.params)
        lines.append(f"{indent}- ``{e.name!r}`` — {params}: {e.description}.")
    return "\n".join(lines)


def param_units(name: str, rate_unit: str | None = None) -> dict:
    """Each parameter's unit for effect ``name`` (as :data:`EFFECTS` states it), "rate unit" spelled as
    ``rate_unit`` when known; {} for a name the registry does not hold."""
    if name not in EFFECTS:
        return {}
    rate = rate_unit or "rate unit"
    return {p: u.replace("rate unit", rate) for p, u, _ in EFFECTS[name].params}


def channel_units(units: dict, params: dict) -> dict:
    """A step's parameter units with "channel unit" spelled as the unit of the channel ``params["channel"]``
    names, which allanite does not know: "deg/s per unit of temp" (per whatever unit the channel's samples are in)."""
    name = params.get("channel")
    if not isinstance(name, str):
        return units
    return {
        p: u.replace("channel unit²", f"(unit of {name})²").replace("channel unit", f"unit of {name}")
        for p, u in units.items()
    }


def _is_pair(iv: Any) -> bool:
    return (
        isinstance(iv, (tuple, list, np.ndarray))
        and len(iv) == 2
        and all(isinstance(x, (int, float, np.integer, np.floating)) for x in iv)
    )


def _with_interval(v: Any, iv: Any, digits: int) -> str:
    return fmt_ci(v, iv[0], iv[1], digits) if _is_pair(iv) else fmt(v, digits)


def format_param(name: str, value: Any, interval: Any = None, unit: str = "", digits: int = 4) -> str:
    """``name = value [low, high] unit`` for any parameter a step reports: a string (a filter kind, a
    channel's name), an int (taps, a count of lines), a number, or a list of numbers (e.g. fundamentals, with
    ``interval`` one (low, high) per entry); the interval only where there is one."""
    u = f" {unit}" if unit else ""
    if isinstance(value, str):
        return f"{name} = {value}"
    if isinstance(value, (list, tuple, np.ndarray)):
        values = list(value)
        ivs = list(interval) if isinstance(interval, (list, tuple)) and len(interval) == len(values) else []
        ivs = ivs if all(_is_pair(iv) for iv in ivs) else []
        text = ", ".join(_with_interval(v, ivs[i] if ivs else None, digits) for i, v in enumerate(values))
        return f"{name} = {text or 'none'}{u}"
    if value is None or isinstance(value, (bool, np.bool_)):
        return f"{name} = {fmt(value, digits)}"
    return f"{name} = {_with_interval(value, interval, digits)}{u}"


def format_params(name: str, params: dict, intervals: dict, rate_unit: str | None = None, digits: int = 4) -> str:
    """Every parameter of a step of effect ``name``, with its interval where it has one and its unit from the
    registry, ``"; "``-separated."""
    units = channel_units(param_units(name, rate_unit), params)
    return "; ".join(format_param(k, v, (intervals or {}).get(k), units.get(k, ""), digits) for k, v in params.items())
