"""Effects proposed on the Allan curve — one registry entry each: how the effect's columns enter the
bootstrap of the curve test (its family), how its best parameter is found at a step (its proposal), the
parameters and intervals a step reports, and what a second domain says about it.

- ``"gauss_markov"`` — a bump, T_c in [5·τ_min, τ_max/4];
- ``"bandwidth"`` — the sensor's low-pass on its white rate noise (single pole, moving average, Bartlett, boxcar,
  a CIC's sinc^k, pole + boxcar, Butterworth), replacing the N column; the kind with the lowest χ² (ties: the one
  needing fewer other terms; a Butterworth only where the samples' spectrum shows its roll-off);
- ``"resonance"`` — narrowband noise near the shortest τ, at quality factors :data:`RESONANCE_Q`;
- ``"sinusoid"`` — with samples, the strongest spectral line of the Welch PSD not yet in the model (its own χ²
  test), its amplitude held at the line's power in the spectrum in every fit of the curve (:func:`line_key`);
  for curve-only input by its nulls at τ = k/f0, its amplitude fitted on the curve.

A proposal is accepted by :func:`choose`: its test passes, its parameter is not at the edge of its range, its
amplitude is positive, χ²/dof falls, and the held-out error falls (the sensor's roll-off first, then spectral
lines, then by statistic over threshold; a resonance waits for a bandwidth that passes; an unmistakable
bandwidth may enter with a Gauss–Markov term or a resonance when alone it would raise the held-out error).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from .. import tracing
from ..effects import CASCADE_SPANS, EFFECTS, RESONANCE_Q, filter_autocorrelation
from ._rolloff import (
    STEEPER,
    better_kind,
    filter_params,
    floor_choice,
    higher_butterworths,
    needs_samples,
    needs_spectrum,
    psd_white,
    sinc_choice,
    sinc_grids,
    spectrum_agrees,
)
from .curvefit import (
    Curve,
    Solution,
    base_name,
    bw_kind,
    column,
    has_floor,
    held_key,
    held_theta,
    profile_interval,
    search,
    searches,
    solve,
)
from .scoring import MATERIAL_Z, Split, curve_change_z

__all__ = [
    "Proposal",
    "Round",
    "CurveCandidate",
    "CURVE_CANDIDATES",
    "PAIR_FACTOR",
    "families",
    "prefetch",
    "choose",
    "final_params",
    "line_key",
]

#: A bandwidth that raises the held-out error alone may enter with a Gauss–Markov term if its statistic is
#: at least this multiple of the threshold.
PAIR_FACTOR = 100.0


@dataclass
class Round:
    """What one step of the loop offers every curve candidate: the curve, the current model (terms ``start``
    plus ``effects``, solution ``sol``), the thinned curve with the curve test and its threshold, the held-out
    split, the samples (None for curve-only input) and the spectral lines found in them. (A round that only
    reads an effect's parameters off a solution needs the first four.)"""

    curve: Curve
    start: tuple
    effects: list
    sol: Solution
    sub: Curve | None = None
    test: tracing.ScoreTest | None = None
    thr: float = math.nan
    split: Split | None = None
    y: np.ndarray | None = None
    lines: list = field(default_factory=list)

    @property
    def tmin(self) -> float:
        """Shortest τ of the curve (s)."""
        return float(self.curve.tau[0])

    @property
    def tmax(self) -> float:
        """Longest τ of the curve (s)."""
        return float(self.curve.tau[-1])


@dataclass
class Proposal:
    """One candidate's best column at a step: ``key`` (effect, with its kind), nonlinear parameter ``p``,
    the solution with it, whether ``p`` sits at the edge of its range, the statistic and its threshold,
    the held-out split to judge it on, the spectral line it came from (if any), and its entry in
    ``Refinement.considered``."""

    key: str
    p: float
    sol: Solution
    edge: bool
    stat: float
    thr: float
    split: Split | None
    line: dict | None = None
    pair_note: str | None = None
    record: dict = field(default_factory=dict)
    #: its column in ``sol`` (the last while it is proposed; its place in the final model afterwards)
    column: int = -1

    @property
    def effect(self) -> str:
        """The effect's name (``key`` without its kind)."""
        return base_name(self.key)


@dataclass(frozen=True)
class CurveCandidate:
    """A curve effect's entry: ``family(sub, has_samples)`` its columns on the thinned curve for the
    bootstrap of the maximum statistic; ``propose(round)`` its proposals at a step; ``params(pr, round)``
    the step's parameters and intervals; ``evidence(pr, round)`` what another domain says (or {});
    ``amplitude`` the parameter that is the column's amplitude, updated from the final joint fit (None:
    none, or it came from the samples); ``searches(round)`` the bounded searches ``propose`` will ask for,
    ``(key, grid, continuous)`` each, run beforehand with every other candidate's (:func:`prefetch`)."""

    name: str
    family: Callable[[Curve, bool], list]
    propose: Callable[[Round], list]
    params: Callable[[Proposal, Round], tuple]
    evidence: Callable[[Proposal, Round], dict] = lambda pr, rnd: {}
    amplitude: Callable[[Proposal], str | None] = lambda pr: None
    searches: Callable[[Round], list] = lambda rnd: []


def prefetch(rnd: Round, candidates) -> None:
    """Run the bounded searches every curve candidate among ``candidates`` will ask for at this step, together
    (:func:`.curvefit.searches`: one batch of fits per round of every search; the same numbers as one search
    after another); the proposals read them from the curve's memory."""
    specs = [s for name, c in CURVE_CANDIDATES.items() if name in candidates for s in c.searches(rnd)]
    if specs:
        searches(rnd.curve, rnd.start, rnd.effects, specs)


def _amplitude(sol: Solution, i: int) -> tuple[float, float, tuple[float, float]]:
    """Amplitude of column ``i`` (√θ), its SD, and the ±1 SD interval clipped at 0."""
    amp = math.sqrt(max(sol.theta[i], 0.0))
    var_i = sol.cov[i, i]
    sd = math.sqrt(max(var_i, 0.0)) / (2 * amp) if amp > 0 and np.isfinite(var_i) else float("nan")
    return amp, sd, (max(0.0, amp - sd), amp + sd)


def _with_stat(rnd: Round, key: str, p: float, sol: Solution, edge: bool, bump: np.ndarray | None = None):
    """A proposal judged by the curve test (its column on the thinned τ, less ``bump`` if given)."""
    assert rnd.sub is not None and rnd.test is not None
    col = column(key, p, rnd.sub) if bump is None else column(key, p, rnd.sub) - bump
    return Proposal(key, p, sol, edge, rnd.test.statistic(rnd.sub.avar, col), rnd.thr, rnd.split)


# ---- Gauss–Markov


def _grid(effect: str, tmin, tmax):
    """The registry's search grid of a curve effect's nonlinear parameter over the τ range [tmin, tmax]."""
    grid = EFFECTS[effect].search
    assert grid is not None
    return grid(tmin, tmax)


def _gm_family(sub: Curve, has_samples: bool) -> list:
    return [column("gauss_markov", p, sub) for p in _grid("gauss_markov", sub.tau[0], sub.tau[-1])]


def _gm_searches(rnd: Round) -> list:
    return [("gauss_markov", _grid("gauss_markov", rnd.tmin, rnd.tmax), True)]


def _gm_propose(rnd: Round) -> list:
    p, s_new, edge = search(
        rnd.curve, rnd.start, rnd.effects, "gauss_markov", _grid("gauss_markov", rnd.tmin, rnd.tmax)
    )
    return [_with_stat(rnd, "gauss_markov", p, s_new, edge)]


def _gm_evidence(pr: Proposal, rnd: Round) -> dict:
    # a second domain: the correlation time the residual's autocorrelation in time gives
    return {} if rnd.y is None else {"autocorrelation": tracing.gm_autocorrelation(rnd.y, rnd.curve.fs, pr.p)}


def _amplitude_and_profile(pr: Proposal, rnd: Round) -> tuple:
    """(amplitude, nonlinear parameter) with the amplitude's ±1 SD and the parameter's profile interval."""
    names = EFFECTS[pr.effect].param_names
    amp, _sd, amp_int = _amplitude(pr.sol, pr.column)
    p_int = profile_interval(rnd.curve, rnd.start, rnd.effects, pr.key, pr.p, pr.sol)
    return {names[0]: amp, names[1]: pr.p}, {names[0]: amp_int, names[1]: p_int}


# ---- bandwidth


def bandwidth_grids(curve: Curve) -> dict:
    """Search grids per filter kind: single-pole and Butterworth cutoffs (every order's the same) whose roll-off
    falls inside the curve, FIR lengths."""
    # the roll-off must reach into the curve: a time constant (or FIR span) of at least a third of the
    # shortest τ — a faster filter leaves no mark on it
    fs = curve.fs
    f_lo = 1.0 / (2 * math.pi * 10 * curve.tau[0])
    f_hi = min(0.45 * fs, 3.0 / (2 * math.pi * curve.tau[0]))
    grids = {}
    if f_lo < f_hi:
        grids["single_pole"] = np.geomspace(f_lo, f_hi, 24)
        grids.update({kind: grids["single_pole"] for kind in ("butterworth2",) + STEEPER})
    l_min = max(2, int(math.ceil(curve.tau[0] * fs / 3)))
    l_max = int(max(2, min(64, 0.1 * curve.tau[-1] * fs)))
    if l_max > l_min:
        grids["moving_average"] = np.arange(l_min, l_max + 1, dtype=np.float64)
        grids["bartlett"] = np.arange(max(2, l_min // 2), max(3, l_max // 2) + 1, dtype=np.float64)
        grids["boxcar"] = np.geomspace(max(1.02, curve.tau[0] * fs / 3), l_max, 32)
        grids.update(sinc_grids(grids["boxcar"]))  # sinc² … sinc⁵ (CIC): the boxcar's cutoffs
    if "single_pole" in grids and curve.tau[0] * fs <= 1.0:
        # a single pole after the part's own short averaging (only where the curve starts at one sample)
        for span in CASCADE_SPANS:
            grids[f"single_pole+boxcar:{span:g}"] = grids["single_pole"]
    return grids


def _bw_family(sub: Curve, has_samples: bool) -> list:
    return [
        column(f"bandwidth:{kind}", p, sub) - 1.0 / sub.tau
        for kind, grid in bandwidth_grids(sub).items()
        if has_samples or not needs_samples(kind)  # a Butterworth, a sinc^k: proposed only with samples
        for p in grid
    ]


def _bw_searches(rnd: Round) -> list:
    if any(base_name(k) == "bandwidth" for k, _p in rnd.effects) or "N" not in rnd.start:
        return []
    return [  # the Butterworths above the 2nd order only where it was searched (:func:`_bw_propose`)
        (f"bandwidth:{kind}", grid, kind not in ("moving_average", "bartlett"))
        for kind, grid in bandwidth_grids(rnd.curve).items()
        if kind not in STEEPER and (rnd.y is not None or not needs_samples(kind))
    ]


def _bw_propose(rnd: Round) -> list:
    best = None
    tie = rnd.curve.tau.size / rnd.curve.n_eff
    found, grids = [], {}
    for key, grid, cont in _bw_searches(rnd):
        found.append((key, *search(rnd.curve, rnd.start, rnd.effects, key, grid, continuous=cont)))
        grids[key] = grid
    two = "bandwidth:butterworth2"
    if two in grids and rnd.y is not None:  # steeper Butterworths, named only with a spectrum as the 2nd order
        steeper, superseded = higher_butterworths(
            rnd.curve, rnd.start, rnd.effects, grids[two], found[list(grids).index(two)], tie, rnd.y
        )
        found = [f for f in found if f[0] not in superseded] + steeper
    found = sinc_choice(found, tie)  # one sinc^k order at most, where it beats the boxcar and the orders below
    for key, p, s_new, edge in found:
        kind = bw_kind(key)  # a Butterworth only where the spectrum shows its roll-off (:mod:`._rolloff`)
        if needs_spectrum(kind) and not spectrum_agrees(rnd.y, rnd.curve.fs, kind, p):
            continue
        if better_kind((key, p, s_new, edge), best, tie):
            best = (key, p, s_new, edge)
    if best is None:
        return []
    key, p, s_new, edge = floor_choice(rnd.curve, rnd.start, rnd.effects, best, _bw_searches(rnd), rnd.y, tie)
    assert rnd.sub is not None
    return [_with_stat(rnd, key, p, s_new, edge, bump=1.0 / rnd.sub.tau)]


def _bw_params(pr: Proposal, rnd: Round) -> tuple:
    params, intervals = filter_params(
        bw_kind(pr.key),
        pr.p,
        rnd.curve.fs,
        lambda: profile_interval(rnd.curve, rnd.start, rnd.effects, pr.key, pr.p, pr.sol),
    )
    if "N" in rnd.start and has_floor(pr.key):  # the N column kept (has_floor): white noise after the filter
        floor, sd, floor_int = _amplitude(pr.sol, list(rnd.start).index("N"))
        params["floor"] = floor
        if math.isfinite(sd):  # none where the floor is 0 (a bound, not an estimate)
            intervals["floor"] = floor_int
    return params, intervals


def _bw_evidence(pr: Proposal, rnd: Round) -> dict:
    ev: dict = {"N": math.sqrt(max(pr.sol.theta[-1], 0.0))}
    if rnd.y is not None:  # a second domain: the roll-off the filter predicts in the spectrum, and the data's
        r = filter_autocorrelation(bw_kind(pr.key), pr.p, rnd.curve.fs)
        ev["psd"] = tracing.rolloff_psd(rnd.y, rnd.curve.fs, r)
        if has_floor(pr.key):  # the white noise after it, as the spectrum above f_s/4 splits it (floor, Q)
            ev["psd_white"] = psd_white(rnd.y, rnd.curve.fs, bw_kind(pr.key), pr.p, ev["N"] ** 2)
    return ev


# ---- resonance


def _res_family(sub: Curve, has_samples: bool) -> list:
    grid = _grid("resonance", sub.tau[0], sub.tau[-1])
    return [column(f"resonance:{q:g}", p, sub) for q in RESONANCE_Q for p in grid]


def _res_searches(rnd: Round) -> list:
    return [(f"resonance:{q:g}", _grid("resonance", rnd.tmin, rnd.tmax), True) for q in RESONANCE_Q]


def _res_propose(rnd: Round) -> list:
    best_r = None
    for key, grid, _cont in _res_searches(rnd):
        p, s_new, edge = search(rnd.curve, rnd.start, rnd.effects, key, grid)
        if best_r is None or s_new.chi2 < best_r[2].chi2:
            best_r = (key, p, s_new, edge)
    assert best_r is not None
    key, p, s_new, edge = best_r
    return [_with_stat(rnd, key, p, s_new, edge)]


def _res_params(pr: Proposal, rnd: Round) -> tuple:
    amp, _sd, amp_int = _amplitude(pr.sol, pr.column)
    p_int = profile_interval(rnd.curve, rnd.start, rnd.effects, pr.key, pr.p, pr.sol)
    return {"sigma": amp, "f0": pr.p, "q": float(pr.key.split(":", 1)[1])}, {"sigma": amp_int, "f0": p_int}


# ---- sinusoid


def _sin_family(sub: Curve, has_samples: bool) -> list:
    # with samples a sinusoid is found in the PSD (its own test), not on the curve
    return [] if has_samples else [column("sinusoid", p, sub) for p in _grid("sinusoid", sub.tau[0], sub.tau[-1])]


def _sin_searches(rnd: Round) -> list:
    return [("sinusoid", _grid("sinusoid", rnd.tmin, rnd.tmax), True)] if rnd.y is None else []


def _sin_propose(rnd: Round) -> list:
    if rnd.y is None:
        p, s_new, edge = search(rnd.curve, rnd.start, rnd.effects, "sinusoid", _grid("sinusoid", rnd.tmin, rnd.tmax))
        return [_with_stat(rnd, "sinusoid", p, s_new, edge)]
    done_f = [p for k, p in rnd.effects if base_name(k) == "sinusoid"]
    # a line's power is taken over its width: a line inside a taken one's width is part of it
    taken = [d["width_hz"] for d in rnd.lines if any(abs(d["f0"] - f) <= 2 * d["bin_hz"] for f in done_f)]
    for ln in rnd.lines:
        if all(abs(ln["f0"] - f) > 2 * ln["bin_hz"] for f in done_f) and not any(
            lo <= ln["f0"] <= hi for lo, hi in taken
        ):
            key = line_key(ln)
            held = held_theta(key)
            assert held is not None
            # a line is a term of the curve's model only where it matters to the curve: its Allan variance at
            # its time-domain amplitude reaches MATERIAL_Z of the estimates' standard errors somewhere (as a
            # removal judged in time alone); a weaker one stays a line of the spectrum (``unexplained`` says it)
            z, _tau = curve_change_z(rnd.curve, rnd.sol, held[0] * column(key, ln["f0"], rnd.curve))
            if not z >= MATERIAL_Z:
                continue
            s_new = solve(rnd.curve, rnd.start, rnd.effects + [(key, ln["f0"])])
            return [Proposal(key, ln["f0"], s_new, False, ln["psd_ratio"], ln["threshold"], rnd.split, line=ln)]
    return []


def line_key(ln: dict) -> str:
    """The column key of a spectral line found in the samples: held at its power in the spectrum (amplitude A,
    A²/2 the line's power over its main lobe, whether or not its phase carries across the record — all of it
    is on the Allan curve), with that estimate's variance. The curve does not refit it: there its column
    aliases with a bandwidth's or a resonance's (ADIS16405 run 1 z: a line of 0.0045 °/s at 18.8 Hz beside a
    20.4 Hz resonance drifted to 0.063 in a free joint refit)."""
    amp = ln["power_amplitude"]
    sd = ln["power_amplitude_interval"][1] - amp
    return held_key("sinusoid", amp**2, (2.0 * amp * sd) ** 2)


def _sin_params(pr: Proposal, rnd: Round) -> tuple:
    if pr.line is None:
        return _amplitude_and_profile(pr, rnd)
    ln = pr.line  # found in the PSD: amplitude (its power) and f0 from the samples, with their intervals
    return {"amplitude": ln["power_amplitude"], "f0": pr.p}, {
        "amplitude": ln["power_amplitude_interval"],
        "f0": ln["f0_interval"],
    }


def _sin_evidence(pr: Proposal, rnd: Round) -> dict:
    if pr.line is None:
        return {}
    ln = pr.line  # the part of the line whose phase carries across the whole record (least squares at f0)
    return {"coherent_amplitude": ln["amplitude"], "coherent_amplitude_interval": ln["amplitude_interval"]}


#: The curve candidates, in the order their columns enter the bootstrap and their proposals are made.
CURVE_CANDIDATES: dict[str, CurveCandidate] = {
    c.name: c
    for c in (
        CurveCandidate(
            "gauss_markov",
            _gm_family,
            _gm_propose,
            _amplitude_and_profile,
            evidence=_gm_evidence,
            amplitude=lambda pr: "sigma",
            searches=_gm_searches,
        ),
        CurveCandidate("bandwidth", _bw_family, _bw_propose, _bw_params, evidence=_bw_evidence, searches=_bw_searches),
        CurveCandidate(
            "resonance", _res_family, _res_propose, _res_params, amplitude=lambda pr: "sigma", searches=_res_searches
        ),
        CurveCandidate(
            "sinusoid",
            _sin_family,
            _sin_propose,
            _sin_params,
            evidence=_sin_evidence,
            amplitude=lambda pr: "amplitude" if pr.line is None else None,
            searches=_sin_searches,
        ),
    )
}


def families(sub: Curve, candidates, has_samples: bool) -> np.ndarray:
    """Every column the curve candidates could add (on the thinned curve), for the bootstrap of the maximum
    statistic: the look-elsewhere effect over all of them is in the threshold."""
    fam = [col for name, c in CURVE_CANDIDATES.items() if name in candidates for col in c.family(sub, has_samples)]
    return np.column_stack(fam) if fam else np.zeros((sub.tau.size, 0))


# ---- which proposal a step accepts


def _admissible(props: list, sol: Solution) -> list:
    """Proposals whose test passes, whose parameter is identified and amplitude positive, and that lower
    χ²/dof (a spectral line, held at its amplitude from the samples, needs its own test, material to the curve,
    and the held-out error's fall, as a removal in time: a term the curve fitted before it — a Gauss–Markov
    term that took the line's bump, its T_c biased — can make the true line raise χ²/dof, and the weights
    change with the model's noise mix). Spectral lines and the sensor's roll-off first, the one that explains
    more of the curve (the lower χ²) before the other: the roll-off is a property of the white noise every other
    column is judged against, and weak lines held before it can leave it no held-out gain (ADIS16405 run 3
    acc_x: four lines after the 0.54 Hz site line, then the roll-off 5.16 → 8.42 % held out, turned down; final
    χ²/dof 252), while a strong line's harmonics can pass for a roll-off (a 0.73 Hz square wave's: a boxcar of
    25 samples). Then by the statistic over its threshold (a line is also the most specific evidence: a
    sinusoid raises a bump on the curve that a Gauss–Markov term would otherwise take)."""
    ok = []
    for pr in props:
        why = _inadmissible(pr, sol)
        if why is None:
            ok.append(pr)
        elif pr.stat > pr.thr:  # a test that passed: say why it was not taken
            pr.record["rejected"] = why
    first = [pr for pr in ok if pr.line is not None or pr.effect == "bandwidth"]
    first.sort(key=lambda pr: pr.sol.chi2)
    rest = [pr for pr in ok if not (pr.line is not None or pr.effect == "bandwidth")]
    rest.sort(key=lambda pr: -pr.stat / pr.thr)
    return first + rest


def _inadmissible(pr: Proposal, sol: Solution) -> str | None:
    """Why proposal ``pr`` cannot be accepted against the model ``sol`` (None: it can)."""
    if not pr.stat > pr.thr:
        return "test not passed"
    if pr.edge:
        return f"its parameter ({pr.p:.4g}) sits at the edge of its search range: not identified"
    if not pr.sol.theta[-1] > 0:
        return "amplitude 0"
    if pr.line is None and not pr.sol.chi2_dof < sol.chi2_dof:  # a held line has tests of its own
        return f"χ²/dof does not fall ({sol.chi2_dof:.4g} → {pr.sol.chi2_dof:.4g})"
    return None


def _first_heldout_winner(cands: list, rnd: Round):
    """The first proposal that lowers the held-out error: (proposal, held-out before, after), or None.

    A roll-off is judged beside the lines held so far and, where that fails, without them (:func:`_unheld_gain`)."""
    for pr in cands:
        ho_b = ho_a = None
        if pr.split is not None:
            ho_b = pr.split.error(rnd.start, rnd.effects)
            ho_a = pr.split.error(rnd.start, rnd.effects + [(pr.key, pr.p)])
            if not ho_a < ho_b and not (pr.effect == "bandwidth" and _unheld_gain(pr, rnd, ho_b, ho_a)):
                pr.record["rejected"] = f"held-out error {ho_b:.3g} → {ho_a:.3g} %"
                continue
        return (pr, ho_b, ho_a)
    return None


def _unheld_gain(pr: Proposal, rnd: Round, ho_b: float, ho_a: float) -> bool:
    """Whether the roll-off ``pr`` lowers the held-out error of the model without the lines held so far. A held
    line's column is measured in the samples, not fitted, and a line whose phase wanders is a sinusoid's column
    only up to its coherence time: beside it, the roll-off's gain at the shortest τ can be lost in the long-τ
    scatter of the two parts (ADIS16405 run 3 acc_x: beside the 0.54 Hz site line 6.2 → 7.25 %, without it
    25.2 → 12.8 %). The roll-off's evidence should not hang on which came first; both comparisons go into its
    ``pair_note``."""
    assert pr.split is not None
    free = [(k, p) for k, p in rnd.effects if held_theta(k) is None]
    if len(free) == len(rnd.effects):
        return False
    ho_b2 = pr.split.error(rnd.start, free)
    ho_a2 = pr.split.error(rnd.start, free + [(pr.key, pr.p)])
    if not ho_a2 < ho_b2:
        return False
    pr.pair_note = (
        f"held out beside the lines held so far {ho_b:.3g} → {ho_a:.3g} %, without them {ho_b2:.3g} → {ho_a2:.3g} %"
    )
    return True


def _partners(rnd: Round, with_bw: list, candidates) -> list:
    """The terms a roll-off may enter beside (:func:`_paired_bandwidth`): the Gauss–Markov term and the resonance
    of each quality factor at their best parameters with the bandwidth in the model, where identified."""
    out = []
    if "gauss_markov" in candidates:
        p, s, edge = search(rnd.curve, rnd.start, with_bw, "gauss_markov", _grid("gauss_markov", rnd.tmin, rnd.tmax))
        out.append(("gauss_markov", p, s, edge))
    if "resonance" in candidates:
        for q in RESONANCE_Q:
            key = f"resonance:{q:g}"
            p, s, edge = search(rnd.curve, rnd.start, with_bw, key, _grid("resonance", rnd.tmin, rnd.tmax))
            out.append((key, p, s, edge))
    return [(key, p) for key, p, s, edge in out if not edge and s.theta[-1] > 0]


def _paired_bandwidth(ok: list, rnd: Round, candidates):
    """An unmistakable roll-off (statistic ≥ :data:`PAIR_FACTOR` × threshold) that alone raised the held-out
    error, accepted when it lowers it together with a Gauss–Markov term or a resonance (the next step's): a
    bandwidth alone can raise the held-out error where a bump sits further up the curve (the five terms bend to
    the bump once the short τ are right) or where a resonance sits beside the roll-off (the ADIS16405
    accelerometers' 10 Hz hump: run 6 acc_x, the roll-off alone 8.95 → 9.72 %, with a resonance → 8.62 %).
    (proposal, held-out before, after alone), or None."""
    bw = next((pr for pr in ok if pr.effect == "bandwidth"), None)
    if bw is None or bw.split is None or not bw.stat >= PAIR_FACTOR * bw.thr:
        return None
    with_bw = rnd.effects + [(bw.key, bw.p)]
    partners = _partners(rnd, with_bw, candidates)
    if not partners:
        return None
    ho_b = bw.split.error(rnd.start, rnd.effects)
    ho_alone = bw.split.error(rnd.start, with_bw)
    ho_pair, (key, _p) = min((bw.split.error(rnd.start, with_bw + [pt]), pt) for pt in partners)
    if not ho_pair < ho_b:
        return None
    name = "Gauss–Markov term" if base_name(key) == "gauss_markov" else f"resonance (Q = {key.split(':', 1)[1]})"
    bw.pair_note = (
        f"accepted with the {name} of the next step: alone it moved the held-out error "
        f"{ho_b:.3g} → {ho_alone:.3g} %, with it → {ho_pair:.3g} %"
    )
    return (bw, ho_b, ho_alone)


def choose(props: list, rnd: Round, candidates):
    """The proposal a step accepts, with the held-out error before and after it, or None (the loop stops).

    A resonance near the shortest τ can stand in for the sensor's roll-off: while a bandwidth passes its test
    and is not in the model, the resonance waits until the bandwidth (alone or paired) was tried."""
    ok = _admissible(props, rnd.sol)
    deferred = []
    if any(pr.effect == "bandwidth" for pr in ok):
        deferred = [pr for pr in ok if pr.effect == "resonance"]
        ok = [pr for pr in ok if pr.effect != "resonance"]
    chosen = _first_heldout_winner(ok, rnd)
    if chosen is None:
        chosen = _paired_bandwidth(ok, rnd, candidates)
    if chosen is None and deferred:
        chosen = _first_heldout_winner(deferred, rnd)
    return chosen


def final_params(key: str, p: float, line: dict | None, intervals: dict, j: int, rnd: Round) -> tuple[dict, dict]:
    """Parameters and intervals of effect ``j`` of the final model ``rnd.sol`` (terms ``rnd.start`` plus
    ``rnd.effects``): its amplitude from the final joint fit, its nonlinear parameter as accepted (a roll-off's
    searched again beside the others, :mod:`._rolloff`) with the interval profiled again beside them. A line keeps
    its f0 interval from the samples (``intervals``, at acceptance)."""
    others = rnd.effects[:j] + rnd.effects[j + 1 :]
    column_j = len(rnd.start) + j
    if line is not None:  # held at its time-domain amplitude in every fit: as accepted
        amp, _sd, _int = _amplitude(rnd.sol, column_j)
        return {"amplitude": amp, "f0": p}, {"amplitude": intervals["amplitude"], "f0": intervals["f0"]}
    pr = Proposal(key, p, rnd.sol, False, math.nan, math.nan, None, column=column_j)
    return CURVE_CANDIDATES[base_name(key)].params(pr, Round(rnd.curve, rnd.start, others, rnd.sol))
