"""A line family removed in time and the sinusoids found again at its own lines: one periodic effect.

The ``"periodic"`` removal runs before the curve effects and takes, by least squares at fixed frequencies, the
part of each line whose phase carries across the record. A line whose frequency wanders (a mains grid moving by
±0.02 %) keeps most of its power after that: the line search runs again on the samples the removals left, and the
``"sinusoid"`` candidate holds what it finds there on the Allan curve, at its power in the spectrum. Those
sinusoids are the same lines — the family's remainder, not other effects — and were listed beside the family, whose
``rms`` then read only the coherent part (a blind suite's 50 Hz mains: 0.047 °/s of 0.102, −54 %, beside three
sinusoids holding the rest, ``benches/results/refine_blind6.md``).

:func:`fold_wandering` makes them one effect: a sinusoid step at one of an accepted family's lines (the family's
line within the sinusoid's width in the spectrum, or two search bins of it) is *folded* into that family — its
step stays in the history, marked ``evidence["folded_into"]``, and its curve column stays in the model (the power
it holds is on the Allan curve); the family's ``rms`` becomes the whole family's, √(coherent² + Σ A_s²/2) over the
sinusoids' power amplitudes A_s, with the coherent part kept in ``evidence["coherent_rms"]`` and the share of the
lines' power that was not coherent, said in words, in ``evidence["wandering"]``. The final model lists the family
once (:class:`.result.Refinement` leaves the folded steps out of it).
"""

from __future__ import annotations

import math

__all__ = ["fold_wandering", "folded"]


def folded(st) -> bool:
    """Whether ``st`` is a sinusoid step :func:`fold_wandering` folded into a family (not listed in the final model)."""
    return "folded_into" in st.evidence


def _at_line(f: float, ln: dict) -> bool:
    """Whether frequency ``f`` (Hz) is the line ``ln`` of the search: within its width or two bins of its f0."""
    lo, hi = ln["width_hz"]
    return lo - ln["bin_hz"] <= f <= hi + ln["bin_hz"] or abs(f - ln["f0"]) <= 2 * ln["bin_hz"]


def fold_wandering(steps: list, lines: list, families: list, truth_error=None) -> None:
    """Fold each sinusoid step (``steps[j]``, from the spectral line ``lines[j]``; None for a curve-only one) that
    sits at a line of an accepted periodic step in ``families`` into that family (module docstring); recompute the
    family's ``truth_error`` with ``truth_error(effect, params)`` when given. In place; nothing changes where no
    sinusoid sits at a family's line."""
    for fam in families:
        freqs = fam.evidence.get("frequencies_hz") or []
        mine = [
            j
            for j, (st, ln) in enumerate(zip(steps, lines, strict=True))
            if st.effect == "sinusoid" and ln is not None and not folded(st) and any(_at_line(f, ln) for f in freqs)
        ]
        if mine:
            _fold(fam, [(j, steps[j], lines[j]) for j in mine], truth_error)


def _fold(fam, members: list, truth_error) -> None:
    """The family step ``fam`` takes the sinusoid steps ``members`` [(index, step, line)]: its rms the whole power."""
    coh = float(fam.params["rms"])
    coh_sd = max(0.0, float(fam.intervals["rms"][1]) - coh) if "rms" in fam.intervals else 0.0
    amps = [float(ln["power_amplitude"]) for _j, _st, ln in members]
    amp_sd = [max(0.0, float(ln["power_amplitude_interval"][1]) - a) for (_j, _st, ln), a in zip(members, amps)]
    power = coh * coh + sum(a * a for a in amps) / 2.0
    rms = math.sqrt(power)
    # delta method on rms² = coh² + Σ A²/2: var = (2·coh·sd_coh)² + Σ (A·sd_A)², sd(rms) = sd(rms²)/(2·rms)
    var2 = (2.0 * coh * coh_sd) ** 2 + sum((a * s) ** 2 for a, s in zip(amps, amp_sd))
    sd = math.sqrt(var2) / (2.0 * rms) if rms > 0 else 0.0
    interval = (max(0.0, rms - sd), rms + sd)
    share = coh * coh / power if power > 0 else 1.0
    where = ", ".join(f"{ln['f0']:.6g}" for _j, _st, ln in members)
    fam.evidence["coherent_rms"] = coh
    fam.evidence["coherent_rms_interval"] = tuple(fam.intervals.get("rms", (coh, coh)))
    fam.evidence["wandering"] = {
        "lines_hz": [float(ln["f0"]) for _j, _st, ln in members],
        "power_amplitudes": amps,
        "coherent_share": share,
        "steps": [j + 1 for j, _st, _ln in members],
        "note": (
            f"{100 * share:.3g} % of the family's line power has a phase that carries across the record (removed "
            f"in time); the rest stays at its lines ({where} Hz), held on the Allan curve by the folded sinusoid "
            "steps: the lines' frequency or phase wanders"
        ),
    }
    fundamentals = fam.params.get("fundamentals")
    for _j, st, _ln in members:
        st.evidence["folded_into"] = {
            "effect": "periodic",
            "fundamentals": fundamentals,
            "note": "this line is one of the periodic family's: the power its coherent fit left (a wandering phase)",
        }
    for p in (fam.params, fam.final_params):
        p["rms"] = rms
    fam.intervals = dict(fam.intervals) | {"rms": interval}
    fam.final_intervals = dict(fam.final_intervals) | {"rms": interval}
    if truth_error is not None:
        fam.truth_error = truth_error(fam.effect, fam.params)
