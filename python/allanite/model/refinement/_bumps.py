"""The curve candidates that raise a bump on the Allan curve: ``"gauss_markov"`` (T_c in [5·τ_min, τ_max/4]) and
``"resonance"`` (narrowband noise near the shortest τ, at quality factors
:data:`allanite.model.effects.RESONANCE_Q`) — each entry's bootstrap family, searches, proposal, parameters and
evidence (:data:`.candidates.CURVE_CANDIDATES`)."""

from __future__ import annotations

from .. import tracing
from ..effects import RESONANCE_Q
from ._proposal import Proposal, Round, column_amplitude, search_grid, with_stat
from .curvefit import Curve, column, profile_interval, search

__all__ = [
    "gm_family",
    "gm_searches",
    "gm_propose",
    "gm_evidence",
    "res_family",
    "res_searches",
    "res_propose",
    "res_params",
]


def gm_family(sub: Curve, has_samples: bool) -> list:
    return [column("gauss_markov", p, sub) for p in search_grid("gauss_markov", sub.tau[0], sub.tau[-1])]


def gm_searches(rnd: Round) -> list:
    return [("gauss_markov", search_grid("gauss_markov", rnd.tmin, rnd.tmax), True)]


def gm_propose(rnd: Round) -> list:
    p, s_new, edge = search(
        rnd.curve, rnd.start, rnd.effects, "gauss_markov", search_grid("gauss_markov", rnd.tmin, rnd.tmax)
    )
    return [with_stat(rnd, "gauss_markov", p, s_new, edge)]


def gm_evidence(pr: Proposal, rnd: Round) -> dict:
    # a second domain: the correlation time the residual's autocorrelation in time gives
    return {} if rnd.y is None else {"autocorrelation": tracing.gm_autocorrelation(rnd.y, rnd.curve.fs, pr.p)}


def res_family(sub: Curve, has_samples: bool) -> list:
    grid = search_grid("resonance", sub.tau[0], sub.tau[-1])
    return [column(f"resonance:{q:g}", p, sub) for q in RESONANCE_Q for p in grid]


def res_searches(rnd: Round) -> list:
    return [(f"resonance:{q:g}", search_grid("resonance", rnd.tmin, rnd.tmax), True) for q in RESONANCE_Q]


def res_propose(rnd: Round) -> list:
    best_r = None
    for key, grid, _cont in res_searches(rnd):
        p, s_new, edge = search(rnd.curve, rnd.start, rnd.effects, key, grid)
        if best_r is None or s_new.chi2 < best_r[2].chi2:
            best_r = (key, p, s_new, edge)
    assert best_r is not None
    key, p, s_new, edge = best_r
    return [with_stat(rnd, key, p, s_new, edge)]


def res_params(pr: Proposal, rnd: Round) -> tuple:
    amp, _sd, amp_int = column_amplitude(pr.sol, pr.column)
    p_int = profile_interval(rnd.curve, rnd.start, rnd.effects, pr.key, pr.p, pr.sol)
    return {"sigma": amp, "f0": pr.p, "q": float(pr.key.split(":", 1)[1])}, {"sigma": amp_int, "f0": p_int}
