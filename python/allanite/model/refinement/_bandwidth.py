"""The ``"bandwidth"`` curve candidate: the sensor's low-pass on its white rate noise (single pole, moving average,
Bartlett, boxcar, a CIC's sinc^k, pole + boxcar, Butterworth, a sharp rippled elliptic: :mod:`._sharp`), replacing the N
column — its search grids per filter kind, bootstrap family, searches, proposal (the kind with the lowest χ²,
:mod:`._rolloff` deciding the Butterworths, the sinc^k order and the white floor, :mod:`._notch` a notch after the
kind), parameters and evidence in the spectrum (:data:`.candidates.CURVE_CANDIDATES`). Where the user declared the
filter (``refine(..., filter=...)``, :mod:`allanite.model._declared`) it is the one kind: its exact column, its shape
fixed, no search — the test asks only whether the curve needs it; its floor after it kept as beside a Butterworth."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from .. import tracing
from .._declared import DeclaredFilter, active_declared
from .._sharp import sharp_of
from ..effects import CASCADE_SPANS, filter_autocorrelation, split_notch
from ._notch import notch_choice
from ._proposal import Proposal, Round, column_amplitude, with_stat
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
from ._sharp import ripple_interval, sharp_kinds, sharp_searched
from .curvefit import Curve, base_name, bw_kind, column, has_floor, profile_interval, search, solve

__all__ = ["bandwidth_grids", "bw_family", "bw_searches", "bw_propose", "bw_params", "bw_evidence"]


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


def bw_family(sub: Curve, has_samples: bool) -> list:
    decl = active_declared()
    if decl is not None:  # the declared filter alone: the test's family is its one column
        return [column(f"bandwidth:{decl.kind}", decl.cutoff, sub) - 1.0 / sub.tau]
    return [
        column(f"bandwidth:{kind}", p, sub) - 1.0 / sub.tau
        for kind, grid in bandwidth_grids(sub).items()
        if has_samples or not needs_samples(kind)  # a Butterworth, a sinc^k: proposed only with samples
        for p in grid
    ]


def bw_searches(rnd: Round) -> list:
    if active_declared() is not None:  # nothing to search: the declared filter's shape is known
        return []
    if any(base_name(k) == "bandwidth" for k, _p in rnd.effects) or "N" not in rnd.start:
        return []
    return [  # the Butterworths above the 2nd order only where it was searched (:func:`bw_propose`)
        (f"bandwidth:{kind}", grid, kind not in ("moving_average", "bartlett"))
        for kind, grid in bandwidth_grids(rnd.curve).items()
        if kind not in STEEPER and (rnd.y is not None or not needs_samples(kind))
    ]


def bw_propose(rnd: Round) -> list:
    decl = active_declared()
    if decl is not None:
        return _declared_propose(rnd, decl)
    best = None
    tie = rnd.curve.tau.size / rnd.curve.n_eff
    found, grids = [], {}
    for key, grid, cont in bw_searches(rnd):
        found.append((key, *search(rnd.curve, rnd.start, rnd.effects, key, grid, continuous=cont)))
        grids[key] = (grid, cont)
    two = "bandwidth:butterworth2"
    if two in grids and rnd.y is not None:  # steeper Butterworths, named only with a spectrum as the 2nd order
        steeper, superseded = higher_butterworths(
            rnd.curve, rnd.start, rnd.effects, grids[two][0], found[list(grids).index(two)], tie, rnd.y
        )
        found = [f for f in found if f[0] not in superseded] + steeper
        grids.update({f[0]: grids[two] for f in steeper})
        butterworths = [f for f in found if needs_spectrum(bw_kind(f[0]))]
        if sharp_searched(butterworths, {f[0] for f in steeper} | superseded, rnd.y, rnd.curve.fs):
            sharp, near = sharp_kinds(rnd.curve, rnd.start, rnd.effects, grids[two][0], steeper)
            found += sharp
            grids.update({f[0]: (near, True) for f in sharp})
    found = sinc_choice(found, tie)  # one sinc^k order at most, where it beats the boxcar and the orders below
    for key, p, s_new, edge in found:
        kind = bw_kind(key)  # a Butterworth only where the spectrum shows its roll-off (:mod:`._rolloff`)
        if needs_spectrum(kind) and not spectrum_agrees(rnd.y, rnd.curve.fs, kind, p):
            continue
        if better_kind((key, p, s_new, edge), best, tie):
            best = (key, p, s_new, edge)
    if best is None:
        return []
    f_best = best
    best = _remembered(rnd, "floor_choice", (_found(f_best), tie), lambda: _floor(rnd, f_best, tie))
    # a sharp kind is a notch's base only where it was chosen: as every base, it would widen the notch's family
    found = [f for f in found if sharp_of(bw_kind(f[0])) is None or f[0] == best[0]]
    parts = (tuple(_found(f) for f in found), _found(best), _grids(grids), rnd.level)
    key, p, s_new, edge = _remembered(  # a notch after it (:mod:`._notch`)
        rnd, "notch_choice", parts, lambda: notch_choice(rnd, found, best, grids, rnd.level)
    )
    assert rnd.sub is not None
    return [with_stat(rnd, key, p, s_new, edge, bump=1.0 / rnd.sub.tau)]


def _remembered(rnd: Round, name: str, parts: tuple, compute) -> tuple:
    """``compute()``, a choice of :func:`bw_propose` — (key, p, solution, edge) made from the curve, the model (terms
    and effects), the samples and ``parts`` alone — remembered by the curve under them: a chain run again without
    an option (:meth:`.loop._Run.curve_chains`) asks again from the first chain's states. Each caller its own
    :class:`.curvefit.Solution`, as :func:`.curvefit.searches` hands them out."""
    y = rnd.y
    samples = None if y is None else (id(y), y.size, y[:: max(1, y.size // 64)].tobytes())
    key = ("bandwidth:" + name, tuple(rnd.start), tuple((k, float(p)) for k, p in rnd.effects), samples, parts)
    got = rnd.curve.cached(key)
    if got is None:
        got = rnd.curve.remember(key, compute())
    k, p, sol, edge = got
    return k, p, replace(sol), edge


def _floor(rnd: Round, best: tuple, tie: float) -> tuple:
    return floor_choice(rnd.curve, rnd.start, rnd.effects, best, bw_searches(rnd), rnd.y, tie)


def _found(f: tuple) -> tuple:
    """A searched kind (key, p, solution, edge) as a key: its parameter, edge and fit's coefficients and χ²."""
    return f[0], float(f[1]), bool(f[3]), f[2].theta.tobytes(), float(f[2].chi2)


def _grids(grids: dict) -> tuple:
    return tuple((k, np.asarray(g, dtype=np.float64).tobytes(), bool(c)) for k, (g, c) in grids.items())


def _declared_propose(rnd: Round, decl: DeclaredFilter) -> list:
    """The declared filter's proposal: its column in place of N's (the floor kept, :func:`.curvefit.has_floor`),
    fitted at its fixed shape (its parameter the −3 dB frequency, reported, not searched); none where the model
    has a bandwidth already or no N term to filter."""
    if any(base_name(k) == "bandwidth" for k, _p in rnd.effects) or "N" not in rnd.start:
        return []
    key, p = f"bandwidth:{decl.kind}", decl.cutoff
    sol = solve(rnd.curve, rnd.start, rnd.effects + [(key, p)])
    assert rnd.sub is not None
    return [with_stat(rnd, key, p, sol, False, bump=1.0 / rnd.sub.tau)]


def bw_params(pr: Proposal, rnd: Round) -> tuple:
    decl = active_declared()
    if decl is not None and bw_kind(pr.key) == decl.kind:  # known, not fitted: no interval
        params: dict = {"cutoff": decl.cutoff, "taps": int(decl.b.size) if decl.is_fir else 0, "filter": "declared"}
        return _with_floor(params, {}, pr, rnd)
    kind = bw_kind(pr.key)
    params, intervals = filter_params(
        kind, pr.p, rnd.curve.fs, lambda: profile_interval(rnd.curve, rnd.start, rnd.effects, pr.key, pr.p, pr.sol)
    )
    if "ripple" in params:  # a sharp kind: its ripple's own profile, the edge searched again at each ripple
        grid = bandwidth_grids(rnd.curve).get("butterworth2", np.asarray([pr.p]))
        intervals["ripple"] = ripple_interval(rnd.curve, rnd.start, rnd.effects, split_notch(kind)[0], pr.p, grid)
    return _with_floor(params, intervals, pr, rnd)


def _with_floor(params: dict, intervals: dict, pr: Proposal, rnd: Round) -> tuple:
    """``params`` and ``intervals`` with the white floor after the filter where its N column is kept."""
    if "N" in rnd.start and has_floor(pr.key):  # the N column kept (has_floor): white noise after the filter
        floor, sd, floor_int = column_amplitude(pr.sol, list(rnd.start).index("N"))
        params["floor"] = floor
        if math.isfinite(sd):  # none where the floor is 0 (a bound, not an estimate)
            intervals["floor"] = floor_int
    return params, intervals


def bw_evidence(pr: Proposal, rnd: Round) -> dict:
    ev: dict = {"N": math.sqrt(max(pr.sol.theta[-1], 0.0))}
    decl = active_declared()
    if decl is not None and bw_kind(pr.key) == decl.kind:
        ev["declared_filter"] = decl.describe() | {"words": "the declared filter, " + decl.words()}
    if rnd.y is not None:  # a second domain: the roll-off the filter predicts in the spectrum, and the data's
        r = filter_autocorrelation(bw_kind(pr.key), pr.p, rnd.curve.fs)
        ev["psd"] = tracing.rolloff_psd(rnd.y, rnd.curve.fs, r)
        if has_floor(pr.key):  # the white noise after it, as the spectrum above f_s/4 splits it (floor, Q)
            ev["psd_white"] = psd_white(rnd.y, rnd.curve.fs, bw_kind(pr.key), pr.p, ev["N"] ** 2)
    return ev
