"""The curve candidates that raise a bump on the Allan curve: ``"gauss_markov"`` (T_c in [5·τ_min, τ_max/4]) and
``"resonance"`` (narrowband noise near the shortest τ, at quality factors
:data:`allanite.model.effects.RESONANCE_Q`, in the Lorentzian shape or, where the fit prefers it by the
candidate's own test, the band-pass one: :func:`res_propose`) — each entry's bootstrap family, searches,
proposal, parameters and evidence (:data:`.candidates.CURVE_CANDIDATES`)."""

from __future__ import annotations

import contextvars
from contextlib import AbstractContextManager

import numpy as np

from ..._scoped import scoped
from .. import tracing
from ..effects import RESONANCE_Q
from ._proposal import Proposal, Round, column_amplitude, search_grid, with_stat
from .calibrated import N_BOOT, curve_test
from .curvefit import Curve, column, profile_interval, res_kind, search, searches
from .levels import alpha

__all__ = [
    "gm_family",
    "gm_searches",
    "gm_propose",
    "gm_evidence",
    "res_family",
    "res_searches",
    "res_propose",
    "res_params",
    "res_evidence",
    "without_bandpass",
    "bandpass_named",
    "bandpass_chain_kept",
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
    """The best Lorentzian resonance over :data:`RESONANCE_Q` and its search grid — or the best band-pass one in
    its place where the fit prefers that shape by the candidate's own test (:func:`_shape_test`)."""
    best_r = None
    for key, grid, _cont in res_searches(rnd):
        p, s_new, edge = search(rnd.curve, rnd.start, rnd.effects, key, grid)
        if best_r is None or s_new.chi2 < best_r[2].chi2:
            best_r = (key, p, s_new, edge)
    assert best_r is not None
    key, p, s_new, edge = best_r
    pr = with_stat(rnd, key, p, s_new, edge)
    bp, shape = _shape_test(rnd, pr)
    if bp is not None:
        pr = bp
    pr.notes["shape_test"] = shape
    return [pr]


def _shape_test(rnd: Round, lor: Proposal) -> tuple[Proposal | None, dict]:
    """The band-pass shape in place of the Lorentzian proposal ``lor`` — offered only over a Lorentzian that
    passes the step's test. A nested comparison, M + L ⊂ M + L + B: the curve test of one more column beside
    the model with the Lorentzian (the next step's test: its covariance is the model's with L), asked of the
    band-pass family (:data:`RESONANCE_Q` × the search grid) at the candidate's share of level, its threshold
    the family's own bootstrap maximum; where (1) a band-pass column passes and (2) the best band-pass resonance,
    searched over every Q as the Lorentzian is, fits the curve better alone than the Lorentzian (lower χ²) and
    (3) lowers the held-out error, as the step will ask of it (a swap that then failed that check would lose a
    resonance the Lorentzian could have explained: ADIS16405 run 1 gyro_z's third, χ²/dof 2.44 → 13.7), it is
    proposed in the Lorentzian's place. The nested test alone
    is not calibrated beside a fitted Lorentzian (its f_r estimated, its Q on a grid: on 24 simulated
    Lorentzian records, 400 Hz × 2·10⁵, it passed 14 times); with (2) alone none of the 24 swapped, while a
    band-pass hump the Lorentzian cannot follow (a 1/τ² tail: no white level at DC, which the Lorentzian's
    1/τ tail takes from N) swaps. (None, the comparison) where the Lorentzian stays."""
    if not _BANDPASS.get():
        return None, {"shape": "lorentzian", "tested": False, "chain": "the Lorentzian shape alone"}
    if rnd.sub is None or rnd.thin is None or not lor.stat > rnd.thr:
        return None, {"shape": "lorentzian", "tested": False}
    with_l = rnd.effects + [(lor.key, lor.p)]
    test = curve_test(rnd.curve, rnd.thin, lor.sol, rnd.start, with_l, rnd.exact)
    grid = search_grid("resonance", rnd.tmin, rnd.tmax)
    keys = [(f"resonance:bp:{q:g}", f) for q in RESONANCE_Q for f in grid]
    fam = np.column_stack([column(k, f, rnd.sub) for k, f in keys])
    thr = test.threshold(fam, alpha("curve", rnd.level), N_BOOT, seed=len(with_l))
    stat, (key, f) = max(zip((test.statistic(rnd.sub.avar, fam[:, i]) for i in range(len(keys))), keys))
    note = {"shape": "lorentzian", "tested": True, "statistic": float(stat), "threshold": float(thr)}
    note |= {"bandpass_q": res_kind(key)[0], "bandpass_f0": float(f)}
    if not stat > thr:
        return None, note
    specs = [(f"resonance:bp:{q:g}", grid, True) for q in RESONANCE_Q]
    found = searches(rnd.curve, rnd.start, rnd.effects, specs)
    (p, s_new, edge), key = min(zip(found, (k for k, _g, _c in specs)), key=_chi2)
    note |= {"bandpass_q": res_kind(key)[0], "bandpass_f0": float(p)}
    note |= {"chi2": {"lorentzian": float(lor.sol.chi2), "bandpass": float(s_new.chi2)}}
    if not s_new.chi2 < lor.sol.chi2:
        return None, note
    if rnd.split is not None:  # and passes the step's held-out check itself (where the Lorentzian may too)
        ho = {"before": rnd.split.error(rnd.start, rnd.effects)}
        ho["bandpass"] = rnd.split.error(rnd.start, rnd.effects + [(key, p)])
        note |= {"heldout_pct": ho}
        if not ho["bandpass"] < ho["before"]:
            return None, note
    return with_stat(rnd, key, p, s_new, edge), note | {"shape": "bandpass"}


def _chi2(found: tuple) -> float:
    return float(found[0][1].chi2)


def res_params(pr: Proposal, rnd: Round) -> tuple:
    amp, _sd, amp_int = column_amplitude(pr.sol, pr.column)
    p_int = profile_interval(rnd.curve, rnd.start, rnd.effects, pr.key, pr.p, pr.sol)
    q, shape = res_kind(pr.key)
    return {"sigma": amp, "f0": pr.p, "q": q, "shape": shape}, {"sigma": amp_int, "f0": p_int}


def res_evidence(pr: Proposal, rnd: Round) -> dict:
    # the shape's nested comparison at acceptance (:func:`_shape_test`)
    return {"shape_test": pr.notes["shape_test"]} if "shape_test" in pr.notes else {}


#: Whether the band-pass shape is offered (off in the chain :func:`bandpass_chain_kept` weighs against).
_BANDPASS: contextvars.ContextVar[bool] = contextvars.ContextVar("allanite_bandpass", default=True)


def without_bandpass() -> AbstractContextManager[None]:
    """Within it a resonance keeps the Lorentzian shape (:func:`_shape_test` offers no band-pass): the chain the
    default shape alone would have taken, which :func:`bandpass_chain_kept` weighs against the one with it."""
    return scoped(_BANDPASS, False)


def bandpass_named(effects: list) -> bool:
    """Whether the curve effects [(key, p)] hold a resonance of the band-pass shape."""
    return any(k.startswith("resonance:") and res_kind(k)[1] == "bandpass" for k, _p in effects)


def bandpass_chain_kept(with_bp, lorentzian, tie: float) -> bool:
    """Whether the chain that took a band-pass resonance is kept over the one the Lorentzian shape alone took
    (each a :class:`.curvefit.Solution` of its final model on the same curve): only where its final χ² lies more
    than ``tie`` (one effective point) below the other's. A shape is chosen at its step, before the terms later
    steps add; judged on the whole chain the Lorentzian, the default, stays wherever the swap did not pay at the
    end (avar-curves IMAR gyro X: a band-pass hump at its step, then a Gauss–Markov term and one line where the
    Lorentzian's chain took two lines, χ²/dof 2.29 against 1.12; NavChip accel X 5.76 against 1.61)."""
    return with_bp.chi2 < lorentzian.chi2 - tie
