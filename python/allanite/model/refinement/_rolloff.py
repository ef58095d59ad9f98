"""The sensor's roll-off: which filter kind is named, and its parameter re-searched beside the terms that came
after it.

Kinds compete on χ² (:func:`better_kind`); the Butterworths above the 2nd order only where the 2nd order was
searched, one order after another while each beats the one before (:func:`higher_butterworths`). A 2nd-order
Butterworth bends the shortest τ broadly enough to stand in for a hump beside a milder filter (ADIS16405 run 1
acc_x beside its 10 Hz hump: a Butterworth at 23 Hz where
the spectrum's 40–48 Hz band holds half the power of its 2–10 Hz band, as a boxcar of 1.2 samples predicts and
the Butterworth predicts a twentieth; run 1 gyro_z's 20 Hz resonance: a Butterworth at 36 Hz); so it is named
only where the samples' spectrum shows its roll-off (:func:`spectrum_agrees`), and never on a curve alone —
every order so (a steeper one stands in for a hump no less); the spectrum may show a white floor after the
filter there, up to :data:`SPECTRUM_FLOOR` (a steep filter's output quantised). Beside a Butterworth that floor is
in the model (the N column kept: :func:`.curvefit.has_floor`, the bandwidth's ``floor``), and an order less plus
white angle noise stands in for the order plus the floor on the Allan curve; where the two are within one
effective χ² point the spectrum above f_s/4 chooses (:func:`white_psd_misfit`: a floor is flat, white angle
noise rises to f_s/2). Beside a single pole, a boxcar or another kind the floor is in the model only where the
spectrum shows one and the Allan curve's fit agrees with it (:func:`floor_choice`): offered everywhere, it moved
the ADIS16405's boxcars and resonances where the spectrum has none.

A CIC decimator's sinc^k (orders 2–5; the boxcar is order 1) is named where it fits better than the boxcar, or
ties with a boxcar of more than two samples at a span of one output sample; of the orders that tie, the one whose
span lies nearest one sample (:func:`sinc_choice`). That choice is made before the terms later steps add, and a
sinc^k's lag-2 correlation is also what a resonance beside a one-lag roll-off makes: where one is named the curve
steps run again without the sinc^k kinds, and the sinc^k's chain is kept unless the other ends better by more
than one effective point (:func:`sinc_chain_kept`).

The roll-off is accepted first (:func:`.candidates.choose`: the white noise every other column is judged
against), so its parameter is searched without the terms later steps add; a Gauss–Markov term's short-τ slope
or a resonance beside it then leaves the cutoff biased, and the final joint fit refits amplitudes only
(a 2nd-order Butterworth at 100 Hz with a Gauss–Markov term: 101.3 Hz at acceptance, a 1.8 % misfit at the
shortest τ that ``unexplained`` flags). Once the loop is done its parameter is searched again on its kind's grid
with every other effect in the model, and moved where the value at acceptance lies outside the new value's
profile interval. Not beside a resonance: near the bandwidth the two trade (ADIS16405 run 3 acc_z's single pole
beside three resonances near 10 Hz would move 19.9 → 14.3 Hz, run 1 gyro_z's beside two at 20 Hz 23.9 → 28.4 Hz,
where the same sensor's other runs agree at acceptance); there the accepted value stays.
"""

from __future__ import annotations

import contextvars
import math
from contextlib import AbstractContextManager

import numpy as np
from scipy.optimize import nnls

from ..._scoped import scoped
from .. import tracing
from .._counter import sample_lattice
from .._sharp import sharp_of
from .._sinc import SINC_ORDERS, sinc_order
from ..effects import BUTTERWORTH_ORDERS, butterworth_order, filter_autocorrelation, filter_cutoff, split_notch
from .curvefit import FLOOR_TAG, PROFILE_RHO, Curve, Solution, base_name, bw_kind, column, search, searches, solve

__all__ = [
    "better_kind",
    "filter_params",
    "psd_white",
    "white_psd_misfit",
    "needs_spectrum",
    "needs_samples",
    "spectrum_agrees",
    "research_rolloff",
    "higher_butterworths",
    "SPECTRUM_FACTOR",
    "SPECTRUM_FLOOR",
    "STEEPER",
    "SINCS",
    "sinc_grids",
    "sinc_choice",
    "sinc_named",
    "without_sincs",
    "sinc_chain_kept",
    "CIC_SPAN",
    "floor_choice",
    "FLOOR_MIN",
    "FLOOR_AGREE",
]

#: The Butterworths above the 2nd order: searched only where the 2nd order was (:func:`higher_butterworths`).
STEEPER = tuple(f"butterworth{n}" for n in BUTTERWORTH_ORDERS[1:])
#: The sinc^k (CIC) kinds, order 2 up: the boxcar is order 1 (:func:`sinc_choice`).
SINCS = tuple(f"sinc{k}" for k in SINC_ORDERS)


def sinc_grids(boxcar: np.ndarray) -> dict:
    """Each sinc^k kind's grid of spans (output samples per boxcar): the boxcar's grid at the same −3 dB
    frequencies (a span D·x_k/x_1, :func:`allanite.model.filter_cutoff`), none below 1.02/k (white there)."""
    grids = {}
    for kind in SINCS:
        k, ref = sinc_order(kind), filter_cutoff("boxcar", 1.0, 1.0)
        spans = np.asarray(boxcar, dtype=np.float64) * filter_cutoff(kind, 1.0, 1.0) / ref
        grids[kind] = np.geomspace(max(1.02 / k, float(spans[0])), float(spans[-1]), spans.size)
    return grids


#: How near one output sample (a factor either way) a sinc^k's span must lie to be read as a CIC at its own output
#: rate where the boxcar fits as well: the discrete CIC's ρ lies below the spline's by O(1/R²) — spans 0.97–1.0 at
#: decimations 4–64 (``benches/refine_cic.py``).
CIC_SPAN = 1.1


def sinc_choice(found: list, tie: float) -> list:
    """``found`` (key, p, sol, edge) with the sinc^k kinds left out but one: among the orders whose χ² lies within
    ``tie`` of the best sinc^k's, the one whose span lies nearest one output sample — a CIC read at its own
    output rate, whose boxcars are as long as its decimation. Kept where it lowers χ² by more than ``tie`` below
    the boxcar's (order 1), or where the two tie, the boxcar is more than two samples long and the sinc^k's span
    within a factor :data:`CIC_SPAN` of one sample (the boxcar then left out, as the same process): a boxcar of
    2.1 samples and a sinc⁴ of one have the same autocorrelation at the output's lags (0.52, 0.05 against 0.49,
    0.05) but −3 dB points 8 % apart before the sampling aliases them, and a span of one is what a CIC has.
    Neighbouring orders trade span for order on the Allan curve (a sinc³ CIC 3200 → 200 Hz: sinc² at 1.24
    samples, sinc³ at 1.00, sinc⁴ at 0.87, χ² 83–85, the boxcar's 156, one effective point 14). Where the
    roll-off is one lag long (a boxcar of 1–2 samples, an MA(1) process: the ADIS16405's) every order is the
    boxcar's process and none is kept. Inside :func:`without_sincs` no sinc^k is kept."""
    if not _SINCS.get():
        return [f for f in found if not sinc_order(bw_kind(f[0]))]
    sincs = [f for f in found if sinc_order(bw_kind(f[0])) and not f[3]]
    rest = [f for f in found if not sinc_order(bw_kind(f[0]))]
    box = next((f for f in rest if bw_kind(f[0]) == "boxcar" and not f[3]), None)
    if not sincs or box is None:
        return rest
    best = min(f[2].chi2 for f in sincs)
    pick = min((f for f in sincs if f[2].chi2 < best + tie), key=lambda f: abs(math.log(f[1])))
    beats = pick[2].chi2 < box[2].chi2 - tie
    cic = box[1] > 2.0 and pick[2].chi2 < box[2].chi2 + tie and abs(math.log(pick[1])) <= math.log(CIC_SPAN)
    if beats:
        return rest + [pick]
    return [f for f in rest if f is not box] + [pick] if cic else rest  # the CIC reading in the boxcar's place


#: Whether :func:`sinc_choice` may keep a sinc^k kind (False inside :func:`without_sincs`).
_SINCS: contextvars.ContextVar[bool] = contextvars.ContextVar("allanite_sincs", default=True)


def without_sincs() -> AbstractContextManager[None]:
    """Within it the bandwidth step names no sinc^k kind (:func:`sinc_choice` drops them): the chain the kinds
    without them would have taken, which :func:`sinc_chain_kept` weighs against the one with them."""
    return scoped(_SINCS, False)


def sinc_named(effects: list) -> bool:
    """Whether the curve effects [(key, p)] hold a bandwidth of a sinc^k kind."""
    return any(base_name(k) == "bandwidth" and sinc_order(bw_kind(k)) for k, _p in effects)


def sinc_chain_kept(with_sinc, without, tie: float) -> bool:
    """Whether the chain that named a sinc^k is kept over the one the kinds without it took (each a
    :class:`.curvefit.Solution` of its final model, fitted on the same curve): unless the other's final χ² lies
    more than ``tie`` (one effective point) below its own. The kind is chosen where it is accepted, before the
    terms later steps add, and a sinc^k's lag-2 correlation is also what a resonance or a line beside a one-lag
    roll-off makes: ADIS16405 run 6 acc_z read a sinc³ of 0.99 samples over a boxcar of 1.19 by one point at
    that step, and its 10 Hz resonance (GLS score 210 → 3.4) and 0.46 Hz line were then no longer taken —
    χ²/dof 2.22 at the end where the boxcar's chain ends at 1.09. Judged on the whole chain the sinc^k stays
    where it is the better reading with everything else in (run 1 acc_z: 2.36 against 2.52), and where the two
    chains tie, as a CIC read at its output rate ties with a boxcar of two samples (:func:`sinc_choice`)."""
    return not without.chi2 < with_sinc.chi2 - tie


#: How far (a factor either way) the filter's predicted high-band/low-band power ratio may lie from the one
#: measured in the Welch PSD (:func:`allanite.model.tracing.rolloff_psd`) for a kind of ``needs_spectrum``.
SPECTRUM_FACTOR = 2.0
#: The white floor a roll-off may sit on in that band, as a fraction of the passband's power: white noise added
#: after the filter — the quantisation of a digital part's output (a step Δ adds (Δ/σ)²/12 of the white noise's
#: σ² per sample: up to a step of √2·σ), or a readout's noise after its anti-alias stage. Far below the half a
#: boxcar of 1.2 samples leaves there (ADIS16405), which a Butterworth must not stand in for.
SPECTRUM_FLOOR = 1.0 / 6.0


def needs_spectrum(kind: str) -> bool:
    """Whether a bandwidth kind is named only where the samples' spectrum shows its roll-off."""
    return butterworth_order(kind) > 0 or sharp_of(kind) is not None  # every Butterworth order, a sharp kind


def needs_samples(kind: str) -> bool:
    """Whether a bandwidth kind is proposed only with samples: the Butterworths (named where the spectrum shows
    their roll-off) and the sinc^k, steep shapes the Allan curve alone does not pin (the IMAR gyro y curve, whose
    main reading is a boxcar of 1.09 samples beside a misfit at τ 5–80 ms, read as a sinc⁵ of 1.24 samples)."""
    return needs_spectrum(kind) or sinc_order(kind) > 0


def spectrum_agrees(y: np.ndarray | None, fs: float, kind: str, p: float) -> bool:
    """Whether the roll-off filter ``kind`` at ``p`` predicts the Welch PSD's power at 0.40–0.48·f_s over its
    power at 0.02–0.10·f_s within a factor :data:`SPECTRUM_FACTOR` of the samples' (``y``; False without), or
    below it where the samples' is a white floor after the filter (at most :data:`SPECTRUM_FLOOR`: a steep
    filter's stop band is the quantisation's, 1/12 of the passband for a step of one σ)."""
    if y is None:
        return False
    psd = tracing.rolloff_psd(y, fs, filter_autocorrelation(kind, p, fs))
    meas, pred = psd["measured"], psd["predicted"]
    if not (meas > 0 and pred > 0):
        return False
    return abs(math.log(pred / meas)) <= math.log(SPECTRUM_FACTOR) or pred < meas <= SPECTRUM_FLOOR


def white_psd_misfit(y: np.ndarray, fs: float, kind: str, p: float, sol: Solution) -> float:
    """RMS of log(measured/predicted) of the Welch PSD's power in 12 parts of 0.25–0.49·f_s, predicted as the
    filtered white noise of the solution ``sol`` (the bandwidth ``kind`` at ``p`` in its last column: 2N²·|H(f)|²,
    one-sided per Hz) plus the non-negative mix of a white floor (flat) and white angle noise (∝ sin²(πf/f_s))
    that fits the parts best. Where a steep filter has fallen, a floor is flat and white angle noise rises to
    f_s/2: on the Allan curve a Butterworth of one order less plus Q stands in for the order plus a floor (4th
    order at 400 Hz of 2 kHz with a floor: the 3rd at 404.5 Hz plus Q within 0.08 % at every τ), and the curve
    splits the two white kinds loosely — the spectrum tells the orders apart."""
    return _white_parts(y, fs, kind, p, float(sol.theta[-1]))[0]


def psd_white(y: np.ndarray, fs: float, kind: str, p: float, n2: float) -> dict:
    """What the spectrum above f_s/4 says of the white noise after the filter ``kind`` at ``p`` (filtered white
    noise N² = ``n2``): ``floor`` (white rate noise, as N: rate unit·√s) and ``q`` (white angle noise, as Q),
    the non-negative mix of :func:`white_psd_misfit`, and its ``misfit`` — the step's evidence beside the floor
    the Allan curve gave, which splits the two loosely."""
    misfit, mix = _white_parts(y, fs, kind, p, n2)
    return {
        "floor": math.sqrt(mix[0] / 2.0),
        "q": math.sqrt(mix[1] / (8.0 * fs)),
        "misfit": misfit if math.isfinite(misfit) else None,
    }


def _white_parts(y: np.ndarray, fs: float, kind: str, p: float, n2: float) -> tuple[float, np.ndarray]:
    """(:func:`white_psd_misfit`, the mix (2N_floor², 8Q²f_s) of its best prediction)."""
    nper = int(min(4096, 2 ** int(math.log2(max(y.size // 8, 256)))))
    f, meas = tracing._rolloff_welch(np.asarray(y, dtype=np.float64), float(fs), nper)
    band = (f >= 0.25 * fs) & (f <= 0.49 * fs)
    r = filter_autocorrelation(kind, p, fs)
    lags = np.arange(1, r.size)
    h2 = r[0] + 2.0 * np.cos(2.0 * np.pi * np.outer(f[band] / fs, lags)) @ r[1:]
    # the band in 12 parts, each part's mean power: the Welch estimate's scatter averaged out, the shape kept
    parts = np.array_split(np.arange(int(band.sum())), 12)
    m = np.array([meas[band][ix].mean() for ix in parts])
    filt = np.array([2.0 * n2 * max(float(h2[ix].mean()), 0.0) for ix in parts])
    white = np.array([[1.0, float(np.mean(np.sin(np.pi * f[band][ix] / fs) ** 2))] for ix in parts])
    if not np.all(m > 0):
        return math.inf, np.zeros(2)
    mix, _res = nnls(white / m[:, None], 1.0 - filt / m)  # relative least squares, non-negative
    pred = filt + white @ mix
    if not np.all(pred > 0):
        return math.inf, mix
    return float(np.sqrt(np.mean(np.log(m / pred) ** 2))), mix


#: How much better (a factor on :func:`white_psd_misfit`) the steeper order's white parts must predict the
#: spectrum's upper half band to be taken where the Allan curve cannot tell the two apart (within ``tie``).
PSD_MISFIT_FACTOR = 0.5


def higher_butterworths(
    curve: Curve, start: tuple, effects: list, grid: np.ndarray, second, tie: float, y: np.ndarray | None = None
) -> tuple[list, set]:
    """The Butterworths of order 3 and up as (key, p, sol, edge), searched on the 2nd order's ``grid`` one order
    after another while each lowers χ² by more than ``tie`` below the order before (``second``: the 2nd order's
    (key, p, sol, edge)) — or, within ``tie`` of it, predicts the spectrum of ``y`` above f_s/4 better by
    :data:`PSD_MISFIT_FACTOR` (:func:`white_psd_misfit`: a floor after the filter, not white angle noise beside
    an order less). A steeper roll-off is tried only where the 2nd order was, and only as far as the curve asks
    for it: a record whose 2nd order no 3rd beats costs one search more. An order the spectrum took a steeper one
    over is left out of the list and its key returned in ``superseded`` (the 2nd order's too), so that the choice
    between kinds on χ² does not take it back."""
    prev, out, superseded = second, [], set()
    for kind in STEEPER:
        key = f"bandwidth:{kind}"
        p, sol, edge = search(curve, start, effects, key, grid)
        out.append((key, p, sol, edge))
        if sol.chi2 < prev[2].chi2 - tie:
            prev = out[-1]
        elif _spectrum_prefers(y, curve.fs, out[-1], prev, tie):
            superseded.add(prev[0])
            prev = out[-1]
        else:
            break
    return [o for o in out if o[0] not in superseded], superseded


def _spectrum_prefers(y, fs: float, new: tuple, prev: tuple, tie: float) -> bool:
    """Whether the steeper order ``new`` = (key, p, sol, edge), within ``tie`` of ``prev`` on χ², predicts the
    spectrum's upper half band better by :data:`PSD_MISFIT_FACTOR` (False without samples)."""
    if y is None or new[3] or not new[2].chi2 < prev[2].chi2 + tie:
        return False
    mis = [white_psd_misfit(y, fs, bw_kind(k), p, s) for k, p, s, _e in (new, prev)]
    return mis[0] < PSD_MISFIT_FACTOR * mis[1]


#: The least white floor, as a fraction of N times the root of the share of white noise's Allan variance the filter
#: passes at the curve's shortest τ (:func:`_passed`), that the spectrum above f_s/4 must show beside a kind other
#: than a Butterworth (:func:`psd_white` at the kind found without one) for a floor to be tried there: a floor
#: whose Allan variance is 1/400 of the filtered noise's at the shortest τ — below that the floor moves nothing.
FLOOR_MIN = 0.05
#: How far (a factor either way) the floor the Allan curve's fit gives may lie from the spectrum's at that fit
#: (:func:`psd_white`) for the floor to be kept beside a kind other than a Butterworth.
FLOOR_AGREE = 1.5


def floor_choice(curve: Curve, start: tuple, effects: list, best: tuple, specs: list, y, tie: float) -> tuple:
    """The bandwidth (key, p, sol, edge) with a white floor after the filter where the samples show one, else
    ``best`` as found without one. Two readings of the floor the spectrum above f_s/4 shows beside ``best``
    (:func:`psd_white`):

    - the output's quantisation, where the samples lie on a lattice whose Δ/√(12·f_s) is that floor within
      :data:`FLOOR_AGREE` (:func:`_lattice_floor`): tried where it is at least :data:`FLOOR_MIN` of N times the root
      of what the filter passes at the shortest τ (:func:`_passed`), every kind of ``specs`` ((key, grid,
      continuous), the Butterworths left out) searched again with the floor (:data:`.curvefit.FLOOR_TAG`), and the
      kinds whose fitted floor agrees with the spectrum's (:func:`_floor_agrees`) compete as without it
      (:func:`sinc_choice`, :func:`better_kind`); beside a Butterworth (which keeps its floor always:
      :func:`.curvefit.has_floor`) the pick only where it beats it (a 16-tap average quantised at 1.2 times its
      output's SD was read as the one kind that had its floor). r18bartlett: before, the best kind with a floor was
      taken or refused alone, and a quantised Bartlett read as a sinc⁵ of 2.4 samples whose fit put its floor into
      white angle noise;
    - any other floor, beside a kind other than a Butterworth: tried where it is at least :data:`FLOOR_MIN` of N,
      the best kind with it kept only where its floor agrees — on the Allan curve a floor trades with the cutoff
      and white angle noise, so a floor the fit leaves at 0, or puts where the spectrum has none, is not one
      (ADIS16405 run 4 gyro_x: the spectrum's 0.07·N beside a boxcar of 1.25 samples, the fit's 0 and a span of
      1.58 with white angle noise; run 1 gyro_z's single pole beside its 20 Hz resonances)."""
    key, p, sol, _edge = best
    kind = bw_kind(key)
    # a sharp kind keeps its floor always, as a Butterworth does; a Butterworth goes on to the lattice reading
    if y is None or "N" not in start or sharp_of(kind) is not None or key.endswith(FLOOR_TAG):
        return best
    n2 = float(sol.theta[-1])
    if not n2 > 0:
        return best
    spec = psd_white(y, curve.fs, kind, p, n2)["floor"]
    if not _lattice_floor(y, curve.fs, spec):
        # a floor the samples' lattice does not explain: tried beside a kind other than a Butterworth where it is at
        # least FLOOR_MIN of N, the best kind with it kept only where its floor agrees
        if butterworth_order(kind) or spec < FLOOR_MIN * math.sqrt(n2):
            return best
        found = _with_floor(curve, start, effects, specs)
        pick = None
        for f in sinc_choice(found, tie):
            if better_kind(f, pick, tie):
                pick = f
        if pick is None or pick[3] or not _floor_agrees(y, curve.fs, list(start).index("N"), pick):
            return best
        return pick
    # the output's quantisation: weighed against what the filter passes at the shortest τ, and the kinds whose
    # fitted floor agrees with the spectrum's compete (a Bartlett of 7 taps, quantised, read as a sinc⁵ of 2.4
    # samples whose fit put its floor into white angle noise, where the Bartlett's floor agrees)
    if spec < FLOOR_MIN * math.sqrt(n2 * _passed(curve, key, p)):
        return best
    n_col = list(start).index("N")
    found = _with_floor(curve, start, effects, specs)
    agreed = [f for f in found if not f[3] and _floor_agrees(y, curve.fs, n_col, f)]
    pick = None
    for f in sinc_choice(agreed, tie):
        if better_kind(f, pick, tie):
            pick = f
    if butterworth_order(kind):  # a Butterworth has its floor already: another kind with one must beat it
        return pick if pick is not None and better_kind(pick, best, tie) else best
    return best if pick is None else pick


def _with_floor(curve: Curve, start: tuple, effects: list, specs: list) -> list:
    """Every kind of ``specs`` but the Butterworths searched with the floor (:data:`.curvefit.FLOOR_TAG`)."""
    tagged = [(k + FLOOR_TAG, g, c) for k, g, c in specs if not butterworth_order(bw_kind(k))]
    return [(spec[0], *res) for spec, res in zip(tagged, searches(curve, start, effects, tagged))]


def _lattice_floor(y: np.ndarray, fs: float, spec: float) -> bool:
    """Whether every sample of ``y`` lies on a lattice (step Δ) whose quantisation floor, Δ/√(12·f_s) (rate
    unit·√s, as N), lies within :data:`FLOOR_AGREE` of the spectrum's floor ``spec``: the floor is the output's
    quantisation (ADIS16405 run 4 gyro_x's spectrum shows 19× its 0.05 °/s step's: not it)."""
    if not spec > 0 or y.size < 1000 or sample_lattice(y[:1000]) is None:
        return False
    got = sample_lattice(y)
    if got is None:
        return False
    return abs(math.log(spec / (got[0] / math.sqrt(12.0 * fs)))) <= math.log(FLOOR_AGREE)


def _passed(curve: Curve, key: str, p: float) -> float:
    """The share of white noise's Allan variance the filter of ``key`` at ``p`` passes at the curve's shortest τ
    (at most 1): a floor after the filter is weighed against what the filter leaves there, not against N — a
    moving average of 14 taps passes 1/196 of it at one sample, where a step of half the output's SD adds a
    third to the curve with a floor of 0.04·N."""
    return float(min(1.0, column(key, p, curve)[0] * curve.tau[0]))


def _floor_agrees(y: np.ndarray, fs: float, n_col: int, found: tuple) -> bool:
    """Whether the floor of the fit ``found`` = (key, p, sol, edge) (its N column, ``n_col``) lies within
    :data:`FLOOR_AGREE` of the one the spectrum above f_s/4 shows beside its filter (:func:`psd_white`), and
    below the filtered white noise N: a "filter" whose white part is mostly after it is none (ADIS16405 run 1
    gyro_z before its resonance: a 3-tap average carrying N = 0 beside a floor of 0.040, the spectrum's 0.029)."""
    key, p, sol, _edge = found
    fit, n2 = math.sqrt(max(float(sol.theta[n_col]), 0.0)), max(float(sol.theta[-1]), 0.0)
    spec = psd_white(y, fs, bw_kind(key), p, n2)["floor"]
    agree = fit > 0.0 and spec > 0.0 and abs(math.log(fit / spec)) <= math.log(FLOOR_AGREE)
    return agree and fit < math.sqrt(n2)


def better_kind(new, best, tie) -> bool:
    """Whether the bandwidth kind ``new`` = (key, p, sol, edge) beats ``best``: a kind whose best parameter sits
    at the edge of its range is not identified (any kind that is comes first); then the lowest χ², and within
    one effective point of it the one that needs fewer other terms (a 2-tap average plus white angle noise and
    a boxcar of 1.2 samples are the same MA(1) process: the single filter is the physical reading; a cascade
    counts one parameter more, its boxcar span)."""
    if best is None or (best[3] and not new[3]):
        return True
    if best[3] != new[3]:
        return False

    def n_par(key, sol):  # a cascade's boxcar span, a sharp kind's ripple: one parameter more
        return np.count_nonzero(sol.theta > 0) + ("+" in key) + (sharp_of(bw_kind(key)) is not None)

    s_new, s_best = new[2], best[2]
    return s_new.chi2 < s_best.chi2 - tie or (
        s_new.chi2 < s_best.chi2 + tie and (n_par(new[0], s_new), s_new.chi2) < (n_par(best[0], s_best), s_best.chi2)
    )


def research_rolloff(
    curve: Curve, start: tuple, effects: list, sol: Solution, grids: dict, y: np.ndarray | None = None
) -> tuple[list, Solution]:
    """(effects, solution) with the bandwidth's parameter re-searched beside the others on its kind's grid
    (``grids``: :func:`.candidates.bandwidth_grids`) — a Butterworth's order chosen again too, among the orders
    whose roll-off the samples ``y`` show (:func:`_butterworth_beside`); the same when there is none, when its
    best value sits at the edge of its grid, when the value at acceptance lies inside the new value's profile
    interval, or beside a resonance."""
    j = next((i for i, (k, _p) in enumerate(effects) if base_name(k) == "bandwidth"), None)
    if j is None or len(effects) < 2 or any(base_name(k) == "resonance" for k, _p in effects):
        return effects, sol  # beside a resonance near the bandwidth the cutoff trades with it: left as accepted
    key = effects[j][0]
    kind = bw_kind(key)
    grid = grids.get(kind)
    if grid is None:
        return effects, sol
    others = effects[:j] + effects[j + 1 :]
    if needs_spectrum(kind):
        found = _butterworth_beside(curve, start, others, grids, y, kind)
        if found is None:
            return effects, sol
        key, p = found
    else:
        p, _s, edge = search(curve, start, others, key, grid, continuous=kind not in ("moving_average", "bartlett"))
        if edge:
            return effects, sol
    new = effects[:j] + [(key, p)] + effects[j + 1 :]
    s_new = solve(curve, start, new)  # in the model's own column order
    # moved only where the value at acceptance lies outside the new one's profile interval (effective χ², as
    # :func:`.curvefit.profile_interval` counts it, more than 1 above): a flat profile keeps the accepted value
    scale = curve.n_eff * (1 - PROFILE_RHO) / (1 + PROFILE_RHO) / curve.tau.size
    return (new, s_new) if (sol.chi2 - s_new.chi2) * scale > 1.0 else (effects, sol)


def _butterworth_beside(curve: Curve, start: tuple, others: list, grids: dict, y, kind: str) -> tuple | None:
    """(key, f_c) of the Butterworth order that fits best beside ``others`` — the accepted ``kind`` and every other
    order whose roll-off the spectrum of ``y`` shows, a higher order only where it lowers χ² by more than one
    effective point — or None where the best one's cutoff sits at the edge of its grid. At acceptance the order
    is chosen without the terms later steps add: a Gauss–Markov term's short-τ slope beside a 2nd-order filter at
    100 Hz of 400 Hz read as a 3rd order, its final χ²/dof 20.4 where the 2nd order's is 2.34 (blind suite 1)."""
    tie = curve.tau.size / curve.n_eff
    best = None
    for k in ("butterworth2",) + STEEPER:
        if k not in grids:
            continue
        p, s_k, edge = search(curve, start, others, f"bandwidth:{k}", grids[k])
        if k != kind and (edge or not spectrum_agrees(y, curve.fs, k, p)):
            continue
        new = (f"bandwidth:{k}", p, s_k, edge)
        if best is None or s_k.chi2 < best[2].chi2 - tie or _spectrum_prefers(y, curve.fs, new, best, tie):
            best = new
    if best is None or best[3]:
        return None
    return best[0], best[1]


def filter_params(kind: str, p: float, fs: float, profile) -> tuple[dict, dict]:
    """A bandwidth's reported parameters and intervals: ``cutoff`` (−3 dB, Hz), ``taps``, ``filter`` (and a
    cascade's ``pole_cutoff``) of the kind ``kind`` at its searched parameter ``p``; ``profile()`` gives the
    parameter's profile interval (called only where the kind's intervals come from it); a kind with a notch after
    it (:func:`allanite.model.effects.notch_kind`) its low-pass's, and ``notch_f`` (Hz) and ``notch_q`` beside them
    (no intervals: fitted on the spectrum, :mod:`._notch`)."""
    base, f_n, q = split_notch(kind)
    if f_n is not None:
        params, intervals = filter_params(base, p, fs, profile)
        return params | {"filter": f"{params['filter']}+notch", "notch_f": f_n, "notch_q": q}, intervals
    cut = filter_cutoff(kind, p, fs)
    if sharp_of(kind) is not None:  # searched on its passband edge; its −3 dB cutoff and interval reported beside it
        e_lo, e_hi = (min(c, fs / 2.0) for c in profile())
        design, ripple = kind.split(":")
        params = {"cutoff": cut, "taps": 0, "filter": design, "ripple": float(ripple), "passband_edge": float(p)}
        return params, {
            "cutoff": (filter_cutoff(kind, e_lo, fs), filter_cutoff(kind, e_hi, fs)),
            "passband_edge": (e_lo, e_hi),
        }
    if kind == "single_pole" or needs_spectrum(kind):  # a Butterworth's f_c ends at f_s/2 (no filter beyond)
        c_int = profile() if kind == "single_pole" else tuple(min(c, fs / 2.0) for c in profile())
        return {"cutoff": cut, "taps": 0, "filter": kind}, {"cutoff": c_int}
    if kind.startswith("single_pole+boxcar:"):
        p_lo, p_hi = profile()
        span = float(kind.split(":", 1)[1])
        return {"cutoff": cut, "taps": span, "filter": "single_pole+boxcar", "pole_cutoff": float(p)}, {
            "cutoff": (filter_cutoff(kind, p_lo, fs), filter_cutoff(kind, p_hi, fs)),
            "pole_cutoff": (p_lo, p_hi),
        }
    if kind == "boxcar" or sinc_order(kind):
        s_lo, s_hi = profile()
        return {"cutoff": cut, "taps": float(p), "filter": kind}, {
            "cutoff": (filter_cutoff(kind, s_hi, fs), filter_cutoff(kind, s_lo, fs)),
            "taps": (s_lo, s_hi),
        }
    taps = int(p) if kind == "moving_average" else 2 * int(p) - 1
    c_int = (filter_cutoff(kind, p + 1, fs), filter_cutoff(kind, max(1.0, p - 1), fs))
    return {"cutoff": cut, "taps": taps, "filter": kind}, {"cutoff": c_int}
