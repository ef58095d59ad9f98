"""Effects proposed on the Allan curve — one registry entry each: how the effect's columns enter the
bootstrap of the curve test (its family), how its best parameter is found at a step (its proposal), the
parameters and intervals a step reports, and what a second domain says about it.

- ``"gauss_markov"`` — a bump, T_c in [5·τ_min, τ_max/4];
- ``"bandwidth"`` — the sensor's low-pass on its white rate noise (single pole, moving average, Bartlett, boxcar,
  a CIC's sinc^k, pole + boxcar, Butterworth), replacing the N column; the kind with the lowest χ² (ties: the one
  needing fewer other terms; a Butterworth only where the samples' spectrum shows its roll-off);
- ``"resonance"`` — narrowband noise near the shortest τ, at quality factors :data:`RESONANCE_Q`;
- ``"shaped_quantisation"`` — a sigma-delta's quantisation noise shaped by (1 − z⁻¹)^k, k = 2 or 3, replacing the
  Q column; proposed where the samples' spectrum rises toward f_s/2 faster than white angle noise (:mod:`._shaped`);
- ``"sinusoid"`` — with samples, the strongest spectral line of the Welch PSD not yet in the model (its own χ²
  test), its amplitude held at the line's power in the spectrum in every fit of the curve (:func:`line_key`);
  for curve-only input by its nulls at τ = k/f0, its amplitude fitted on the curve.

A proposal is accepted by :func:`choose`: its test passes, its parameter is not at the edge of its range, its
amplitude is positive, χ²/dof falls, and the held-out error falls (the sensor's roll-off first, then spectral
lines, then by statistic over threshold; a resonance waits for a bandwidth that passes; an unmistakable
bandwidth may enter with a Gauss–Markov term or a resonance when alone it would raise the held-out error).

Here the registry itself (:data:`CURVE_CANDIDATES`), the bootstrap's columns (:func:`families`), the searches run
together (:func:`prefetch`) and the final model's parameters (:func:`final_params`); each entry's functions in its
domain's module (:mod:`._bumps`: Gauss–Markov and resonance; :mod:`._bandwidth`; :mod:`._sinusoid`;
:mod:`._shaped`), what they are
given and give in :mod:`._proposal`, :func:`choose` in :mod:`._choose` — their names re-exported here.
"""

from __future__ import annotations

import math

import numpy as np

from ._bandwidth import bandwidth_grids, bw_evidence, bw_family, bw_params, bw_propose, bw_searches
from ._bumps import (
    gm_evidence,
    gm_family,
    gm_propose,
    gm_searches,
    res_evidence,
    res_family,
    res_params,
    res_propose,
    res_searches,
)
from ._choose import PAIR_FACTOR, choose
from ._line_gain import gain_params
from ._proposal import CurveCandidate, Proposal, Round, amplitude_and_profile, column_amplitude
from ._shaped import sq_evidence, sq_family, sq_params, sq_propose
from ._sinusoid import line_key, sin_evidence, sin_family, sin_params, sin_propose, sin_searches
from .curvefit import Curve, base_name, searches

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
    "bandwidth_grids",
]


def prefetch(rnd: Round, candidates) -> None:
    """Run the bounded searches every curve candidate among ``candidates`` will ask for at this step, together
    (:func:`.curvefit.searches`: one batch of fits per round of every search; the same numbers as one search
    after another); the proposals read them from the curve's memory."""
    specs = [s for name, c in CURVE_CANDIDATES.items() if name in candidates for s in c.searches(rnd)]
    if specs:
        searches(rnd.curve, rnd.start, rnd.effects, specs)


#: The curve candidates, in the order their columns enter the bootstrap and their proposals are made.
CURVE_CANDIDATES: dict[str, CurveCandidate] = {
    c.name: c
    for c in (
        CurveCandidate(
            "gauss_markov",
            gm_family,
            gm_propose,
            amplitude_and_profile,
            evidence=gm_evidence,
            amplitude=lambda pr: "sigma",
            searches=gm_searches,
        ),
        CurveCandidate("bandwidth", bw_family, bw_propose, bw_params, evidence=bw_evidence, searches=bw_searches),
        CurveCandidate(
            "resonance",
            res_family,
            res_propose,
            res_params,
            evidence=res_evidence,
            amplitude=lambda pr: "sigma",
            searches=res_searches,
        ),
        CurveCandidate(
            "sinusoid",
            sin_family,
            sin_propose,
            sin_params,
            evidence=sin_evidence,
            amplitude=lambda pr: "amplitude" if pr.line is None else None,
            searches=sin_searches,
        ),
        CurveCandidate(
            "shaped_quantisation",
            sq_family,
            sq_propose,
            sq_params,
            evidence=sq_evidence,
            amplitude=lambda pr: "q",
        ),
    )
}


def families(sub: Curve, candidates, has_samples: bool) -> np.ndarray:
    """Every column the curve candidates could add (on the thinned curve), for the bootstrap of the maximum
    statistic: the look-elsewhere effect over all of them is in the threshold."""
    fam = [col for name, c in CURVE_CANDIDATES.items() if name in candidates for col in c.family(sub, has_samples)]
    return np.column_stack(fam) if fam else np.zeros((sub.tau.size, 0))


def final_params(key: str, p: float, line: dict | None, intervals: dict, j: int, rnd: Round) -> tuple[dict, dict]:
    """Parameters and intervals of effect ``j`` of the final model ``rnd.sol`` (terms ``rnd.start`` plus
    ``rnd.effects``): its amplitude from the final joint fit, its nonlinear parameter as accepted (a roll-off's
    searched again beside the others, :mod:`._rolloff`) with the interval profiled again beside them. A line keeps
    its f0 interval from the samples (``intervals``, at acceptance)."""
    others = rnd.effects[:j] + rnd.effects[j + 1 :]
    column_j = len(rnd.start) + j
    if line is not None:  # held at its time-domain amplitude in every fit: as accepted
        amp, _sd, _int = column_amplitude(rnd.sol, column_j)
        return gain_params(line, {"amplitude": amp, "f0": p}, {k: intervals[k] for k in ("amplitude", "f0")})
    pr = Proposal(key, p, rnd.sol, False, math.nan, math.nan, None, column=column_j)
    return CURVE_CANDIDATES[base_name(key)].params(pr, Round(rnd.curve, rnd.start, others, rnd.sol))
