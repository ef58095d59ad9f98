"""The sharp rippled kinds of the bandwidth step (:mod:`allanite.model._sharp`): an elliptic of fixed order and
stop band whose cutoff is searched as a Butterworth's and whose signed passband ripple is searched on
:data:`allanite.model._sharp.SHARP_RIPPLES`, then between the best ripple's neighbours (Brent's bounded search on
log |r|, each point a cutoff search), per design.

Searched only where the Butterworths' chain climbed past the 3rd order, or where the samples' spectrum shows the
roll-off of one of its orders (:func:`sharp_searched`) — a record whose spectrum shows no Butterworth's roll-off, or
that has none, costs nothing more. A sharp kind then competes with the others on χ² (:func:`._rolloff.better_kind`,
which counts its ripple as a parameter more: within one effective point a Butterworth keeps the name), is named only
where the samples' spectrum shows its roll-off (:func:`._rolloff.spectrum_agrees`, as a Butterworth) and keeps the white
floor after it (:func:`.curvefit.has_floor`). Its cutoff is not searched again beside later terms
(:func:`._rolloff.research_rolloff` leaves a kind without a grid as accepted). Not in the step's bootstrap family
(:func:`._bandwidth.bw_family`): it is searched only after the family's steepest columns were taken, as the shape those
columns' roll-off has.
"""

from __future__ import annotations

import math

import numpy as np

from .._sharp import RIPPLE_RANGE, SHARP_DESIGNS, SHARP_RIPPLES, sharp_kind
from ._brent import bounded
from ._rolloff import spectrum_agrees
from .curvefit import PROFILE_RHO, Curve, bw_kind, profile_crossings, searches

__all__ = ["sharp_searched", "sharp_kinds", "near_grid", "ripple_interval", "RIPPLE_XTOL", "NEAR", "NEAR_NYQUIST"]

#: Brent's tolerance on log |ripple| (a ripple named within ~3 %; the curve's χ² is flat at that scale).
RIPPLE_XTOL = 0.03


def sharp_searched(butterworths: list, searched: set[str], y: np.ndarray | None, fs: float) -> bool:
    """Whether the sharp kinds are searched: the Butterworths' chain searched the 4th order (the 3rd beat the
    2nd: the curve asks for a roll-off steeper than a 2nd order's) — ``searched`` the keys of every order it
    searched —, or the samples' spectrum ``y`` shows the roll-off of one of the orders found, ``butterworths``
    (key, f_c, solution, edge) — a rippled filter's curve need not climb the chain (an elliptic of order 7 and
    0.9 dB read as a 3rd order). Not where no order's roll-off is in the spectrum: a boxcar of 1.2 samples leaves
    half the passband's power at 0.40–0.48·f_s (ADIS16405 run 3 acc_x: closed on both chains). On 5 ADIS16405
    channels it opened on 8 of 15 calls (a Butterworth order at some cutoff agreeing with their spectrum), every
    field of their results unchanged (``benches/results/r18sharp.md``)."""
    if "bandwidth:butterworth4" in searched:
        return True
    return any(not f[3] and spectrum_agrees(y, fs, bw_kind(f[0]), f[1]) for f in butterworths)


def sharp_kinds(curve: Curve, start: tuple, effects: list, grid: np.ndarray, butterworths: list) -> tuple:
    """(the best sharp kind of each design as (key, f_c, solution, edge), the cutoff grid they were searched on):
    every design at every ripple of :data:`SHARP_RIPPLES` searched on the points of the Butterworths' cutoff
    ``grid`` near the best Butterworth's cutoff (:func:`near_grid`; ``butterworths`` the chain's (key, f_c, solution,
    edge)), in one batch, then its best ripple refined between its neighbours of the same sign (Brent on log |r|,
    the designs in lockstep). The decimated designs only where that cutoff lies above :data:`NEAR_NYQUIST`·f_s:
    below it their folded stop band is 40 dB down and they are the undecimated designs' shapes."""
    fb = min((f for f in butterworths if not f[3]), key=lambda f: f[2].chi2, default=butterworths[0])[1]
    near = near_grid(grid, fb)
    designs = [d for d in SHARP_DESIGNS if SHARP_DESIGNS[d][2] == 1 or fb > NEAR_NYQUIST * curve.fs]
    specs = [(f"bandwidth:{sharp_kind(d, r)}", near, True) for d in designs for r in SHARP_RIPPLES]
    found = [(spec[0], *res) for spec, res in zip(specs, searches(curve, start, effects, specs))]
    per = len(SHARP_RIPPLES)
    gens, best = [], []
    for j, design in enumerate(designs):
        rows = found[j * per : (j + 1) * per]
        i = min(range(per), key=lambda k: (rows[k][3], rows[k][2].chi2))  # an edge cutoff last
        best.append(rows[i])
        gens.append((design, _ripple_brent(i)))
    _advance(curve, start, effects, near, gens, best)
    return [_at_range_edge(f) for f in best], near


def _at_range_edge(found: tuple) -> tuple:
    """``found`` (key, f_c, solution, edge) marked at the edge where its ripple ends within two of Brent's steps of
    an end of :data:`allanite.model._sharp.RIPPLE_RANGE`: a ripple the search runs into the end of is not identified
    (:func:`._rolloff.better_kind` ranks it last, as a cutoff at its grid's end) — near 3 dB a dip in the passband
    is what a notch after a Butterworth makes (a 2nd order at 40 Hz of 200 with a 12 Hz notch of Q 2: `elliptic6`
    at −2.94 dB beat the Butterworth by χ² 18118 → 3349 before the notch was tried), near 0.05 dB a Butterworth."""
    ripple = abs(float(found[0].rpartition(":")[2]))
    lo, hi = RIPPLE_RANGE
    slack = math.exp(2.0 * RIPPLE_XTOL)
    return found if lo * slack < ripple < hi / slack else (*found[:3], True)


#: Where a sharp kind's passband edge is searched, as a factor on the best Butterworth's cutoff: a sharp filter's
#: edge lies below its −3 dB point (an elliptic of order 4 and 1 dB at 30 Hz of 200: edge 30.2 Hz where the best
#: Butterworth-6 reads 31.9, 0.95), and the Butterworth's cutoff trades with the ripple's lift. Not every design
#: falls inside: a Chebyshev I of order 3 decimated by 4, its edge near the output's Nyquist, fits an edge of
#: 93 Hz where its Butterworth-2 reads 68.8 (1.35) — there the search ends at the grid's last point.
NEAR = (0.6, 1.3)
#: The cutoff (a share of f_s) above which the decimated designs are searched too.
NEAR_NYQUIST = 0.25


def near_grid(grid: np.ndarray, fb: float) -> np.ndarray:
    """The points of ``grid`` within :data:`NEAR` of ``fb``; the three nearest (in log) where fewer lie there."""
    grid = np.asarray(grid, dtype=np.float64)
    keep = grid[(grid >= NEAR[0] * fb) & (grid <= NEAR[1] * fb)]
    if keep.size >= 3:
        return keep
    return np.sort(grid[np.argsort(np.abs(np.log(grid / fb)))[:3]])


def _ripple_brent(i: int):
    """Brent's bounded search on log |r| between the neighbours of ripple ``i`` of :data:`SHARP_RIPPLES` on its side
    of 0 (to the ends of :data:`allanite.model._sharp.RIPPLE_RANGE`), its sign kept; yields signed ripples."""
    r = SHARP_RIPPLES[i]
    side = sorted(abs(x) for x in SHARP_RIPPLES if x * r > 0)
    k = side.index(abs(r))
    lo = side[k - 1] if k > 0 else RIPPLE_RANGE[0]
    hi = side[k + 1] if k + 1 < len(side) else RIPPLE_RANGE[1]
    sign = math.copysign(1.0, r)
    gen = bounded(math.log(lo), math.log(hi), xatol=RIPPLE_XTOL, maxfun=12)
    try:
        x = next(gen)
        while True:
            value = yield sign * math.exp(x)
            x = gen.send(value)
    except StopIteration:
        return


def _advance(curve: Curve, start: tuple, effects: list, grid: np.ndarray, gens: list, best: list) -> None:
    """Runs the ripple searches ``gens`` [(design, generator)] in lockstep, each round's cutoff searches in one
    batch, keeping in ``best`` (per design) the lowest χ² seen off the grid's edge."""
    live = []
    for j, (design, gen) in enumerate(gens):
        live.append((j, design, gen, next(gen)))
    while live:
        specs = [(f"bandwidth:{sharp_kind(d, r)}", grid, True) for _j, d, _g, r in live]
        got = searches(curve, start, effects, specs)
        nxt = []
        for (j, design, gen, _r), spec, (p, sol, edge) in zip(live, specs, got):
            if not edge and (best[j][3] or sol.chi2 < best[j][2].chi2):
                best[j] = (spec[0], p, sol, edge)
            try:
                nxt.append((j, design, gen, gen.send(sol.chi2)))
            except StopIteration:
                continue
        live = nxt


def ripple_interval(curve: Curve, start: tuple, effects: list, kind: str, p: float, grid: np.ndarray) -> tuple:
    """The signed ripple's profile interval (dB) of the sharp ``kind`` at passband edge ``p`` beside ``effects``:
    where the effective χ² (scaled as :func:`.curvefit.profile_interval` scales it), the edge searched again at each
    ripple on the points of ``grid`` near ``p`` (:func:`near_grid`), rises by at most 1 over its minimum; 15 ripples
    within a factor 2 either way of the named one (its sign kept, inside :data:`allanite.model._sharp.RIPPLE_RANGE`),
    searched in one batch, the crossings interpolated in log |r|."""
    design, _sep, tail = kind.partition(":")
    r0 = float(tail)
    lo_r, hi_r = RIPPLE_RANGE
    local = np.unique(np.clip(abs(r0) * np.exp(np.linspace(-0.7, 0.7, 15)), lo_r, hi_r))
    near = near_grid(grid, p)
    specs = [(f"bandwidth:{sharp_kind(design, math.copysign(r, r0))}", near, True) for r in local]
    chi2 = np.array([res[1].chi2 for res in searches(curve, start, effects, specs)])
    scale = curve.n_eff * (1 - PROFILE_RHO) / (1 + PROFILE_RHO) / curve.tau.size
    lo, hi = profile_crossings(local, (chi2 - chi2.min()) * scale - 1.0)
    lo, hi = min(lo, abs(r0)), max(hi, abs(r0))
    return (lo, hi) if r0 > 0 else (-hi, -lo)
