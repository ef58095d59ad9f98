"""The ``"sinusoid"`` curve candidate: with samples, the strongest spectral line of the Welch PSD not yet in the
model (its own test), held at the line's power in the spectrum in every fit of the curve (:func:`line_key`);
for curve-only input found by its nulls at τ = k/f0, its amplitude fitted on the curve — the entry's bootstrap
family, searches, proposal, parameters and evidence (:data:`.candidates.CURVE_CANDIDATES`)."""

from __future__ import annotations

from ._line_gain import gain_params, modulated_held
from ._proposal import Proposal, Round, amplitude_and_profile, search_grid, with_stat
from .curvefit import Curve, base_name, column, held_key, held_theta, search, solve
from .scoring import MATERIAL_Z, curve_change_z

__all__ = [
    "sin_family",
    "sin_searches",
    "sin_propose",
    "line_key",
    "gain_key",
    "coherent_share",
    "sin_params",
    "sin_evidence",
]


def sin_family(sub: Curve, has_samples: bool) -> list:
    # with samples a sinusoid is found in the PSD (its own test), not on the curve
    return [] if has_samples else [column("sinusoid", p, sub) for p in search_grid("sinusoid", sub.tau[0], sub.tau[-1])]


def sin_searches(rnd: Round) -> list:
    return [("sinusoid", search_grid("sinusoid", rnd.tmin, rnd.tmax), True)] if rnd.y is None else []


def sin_propose(rnd: Round) -> list:
    if rnd.y is None:
        p, s_new, edge = search(
            rnd.curve, rnd.start, rnd.effects, "sinusoid", search_grid("sinusoid", rnd.tmin, rnd.tmax)
        )
        return [with_stat(rnd, "sinusoid", p, s_new, edge)]
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
    return held_key("sinusoid", amp**2, (2.0 * amp * sd) ** 2, coherent_share(ln))


def gain_key(ln: dict, curve: Curve, n: int, channels: dict) -> str:
    """The column key of a line whose gain on a channel was kept (``ln["gain"]``, :mod:`._line_gain`): held at
    the exact Allan variance of the modelled component, the constant line and its gain's part together
    (:func:`._line_gain.modulated_held`), not at the line's power in the spectrum — the curve the model is
    fitted on holds the modulated line, and so does this term."""
    g = ln["gain"]
    sd = ln["amplitude_interval"][1] - ln["amplitude"]  # the coherent amplitude's +1 SD (its lower end is cut at 0)
    x = channels[g["channel"]]
    theta, var, share = modulated_held(n, curve.fs, float(ln["f0"]), g, x, curve.tau, sd)
    return held_key("sinusoid", theta, var, share)


def coherent_share(ln: dict) -> float:
    """The share of a line's power whose phase carries across the whole record: (least-squares amplitude at f0
    / the amplitude of its power in the spectrum)², in [0, 1]. That part is a fixed sinusoid, which adds to the
    Allan estimates only its cross term with the noise (:func:`.calibrated.curve_test`); the rest — a phase
    or amplitude that wanders (ADIS16405 run 3 acc_x's 0.539 Hz line: 2.0·10⁻⁵ of 7.1·10⁻⁴, a share 8·10⁻⁴) —
    is a narrow-band noise, and keeps the noise's covariance."""
    amp = float(ln["power_amplitude"])
    return min(1.0, float(ln["amplitude"]) ** 2 / amp**2) if amp > 0 else 0.0


def sin_params(pr: Proposal, rnd: Round) -> tuple:
    if pr.line is None:
        return amplitude_and_profile(pr, rnd)
    ln = pr.line  # found in the PSD: amplitude (its power) and f0 from the samples, with their intervals
    params = {"amplitude": ln["power_amplitude"], "f0": pr.p}
    return gain_params(ln, params, {"amplitude": ln["power_amplitude_interval"], "f0": ln["f0_interval"]})


def sin_evidence(pr: Proposal, rnd: Round) -> dict:
    if pr.line is None:
        return {}
    ln = pr.line  # the part of the line whose phase carries across the whole record (least squares at f0)
    out = {"coherent_amplitude": ln["amplitude"], "coherent_amplitude_interval": ln["amplitude_interval"]}
    if ln.get("slow"):  # a line of few cycles, found by its test in time (:mod:`allanite.model.slowline`)
        out["slow_line"] = ln["slow"]
    g = ln.get("gain")
    if g:  # its nested option kept: the amplitude follows a channel (._line_gain)
        out["gain_test"] = {k: g[k] for k in ("statistic", "threshold", "alpha", "heldout_ratio", "mean")}
    return out
