"""The ``"shaped_quantisation"`` curve candidate: a sigma-delta modulator's quantisation noise, shaped by
(1 − z⁻¹)^k (k = 2, 3; :mod:`allanite.model._shaped`), in place of the Q column — its bootstrap family, proposal,
parameters and evidence (:data:`.candidates.CURVE_CANDIDATES`).

Where it belongs: a curve effect beside the bandwidth, not a kind of it. A bandwidth filters the white rate noise
N and lowers the shortest τ below the five terms; the shaped noise is the quantisation term Q itself, raised at
the first k − 1 averaging factors above Q's line (k = 2: 5/3 of it at τ0) and on that line beyond. So its column
replaces Q's, the model's Q is the line it shows (√C(2k − 2, k − 1)·q), and its test is the Allan-curve score test
of every curve effect (its columns, less the Q they replace, among the bootstrap's family: the look-elsewhere
effect over all of them is in the threshold, so it spends no share of ``level`` of its own).

It is proposed only with samples, and only where their spectrum rises toward f_s/2 faster than white angle noise
does (:func:`spectrum_rises`): the Welch PSD over 0.15–0.49·f_s as the best non-negative mix of 1, s, s², s³
(s = sin²(πf/f_s): white rate noise, white angle noise, shaped noise of order 2 and 3) gives the s² and s³ parts
at least :data:`SHAPED_SHARE` of the power in 0.42–0.49·f_s. The five terms take none (flicker and a random walk
fall, white noise is flat, white angle noise is s), nor does a low-pass whose spectrum falls to f_s/2 (a
Butterworth, a single pole, a CIC: a modulator behind its decimation filter reads as the filter's bandwidth). A
guard, not a test: a moving average's sidelobe rising from its zero (3 taps: from f_s/3) passes it — a rounded
3-tap average reads share 1.0 — and there the Allan-curve test decides (one-sided: the shaping raises τ0 above the
Q line, an average lowers it; its score 0 on those records). Where it fits the curve better than the bandwidth, or
within one effective point per octave of it, it is taken first (:func:`._choose.choose`).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import nnls

from .. import tracing
from ..effects import SHAPED_ORDERS, shaped_q_factor
from ._proposal import Proposal, Round, column_amplitude, with_stat
from .curvefit import Curve, base_name, column, solve, term_columns

__all__ = [
    "SHAPED_SHARE",
    "spectrum_shaped_share",
    "spectrum_rises",
    "sq_family",
    "sq_propose",
    "sq_params",
    "sq_evidence",
]

KEY = "shaped_quantisation"
#: The share of the Welch PSD in :data:`TOP_BAND` that the shaped parts (∝ sin⁴ and sin⁶ of πf/f_s) must carry in
#: the spectrum's best non-negative mix of white rate noise (flat), white angle noise (∝ sin²) and those parts over
#: :data:`FIT_BAND` (:func:`spectrum_shaped_share`) for the shaped kind to be proposed: 0 for every noise the five
#: terms hold and a low-pass whose spectrum falls to f_s/2, up to 1 where shaped noise is all there is (and on a
#: moving average's rising sidelobe: the curve test decides there).
SHAPED_SHARE = 0.25
#: The band the spectrum's mix is fitted over and the band its shaped share is read in, as fractions of f_s.
FIT_BAND, TOP_BAND = (0.15, 0.49), (0.42, 0.49)
#: Parts the fitted band is cut into (each part's mean power: the Welch estimate's scatter averaged out).
PARTS = 16


def spectrum_shaped_share(y: np.ndarray | None, fs: float) -> dict:
    """The samples' Welch PSD over :data:`FIT_BAND` (in :data:`PARTS` parts, each its mean power) as the best
    non-negative mix (relative least squares) of 1, s, s², s³ (s = sin²(πf/f_s): white rate noise, white angle
    noise, shaped noise of order 2 and 3): ``share``, what the s² and s³ parts carry of the mix's power in
    :data:`TOP_BAND`, and the ``mix`` (per Hz, one-sided); share NaN without samples."""
    if y is None:
        return {"share": math.nan, "mix": None}
    nper = int(min(4096, 2 ** int(math.log2(max(y.size // 8, 256)))))
    f, p = tracing._rolloff_welch(np.asarray(y, dtype=np.float64), float(fs), nper)
    band = (f >= FIT_BAND[0] * fs) & (f <= FIT_BAND[1] * fs)
    if band.sum() < 2 * PARTS:
        return {"share": math.nan, "mix": None}
    s = np.sin(np.pi * f / fs) ** 2
    parts = np.array_split(np.flatnonzero(band), PARTS)
    m = np.array([p[ix].mean() for ix in parts])
    x = np.array([[float(np.mean(s[ix] ** j)) for j in range(4)] for ix in parts])
    if not np.all(m > 0):
        return {"share": math.nan, "mix": None}
    mix, _res = nnls(x / m[:, None], np.ones(m.size))
    top = (f >= TOP_BAND[0] * fs) & (f <= TOP_BAND[1] * fs)
    powers = np.array([float(np.mean(s[top] ** j)) for j in range(4)]) * mix
    total = float(powers.sum())
    return {"share": float(powers[2:].sum() / total) if total > 0 else math.nan, "mix": [float(v) for v in mix]}


def spectrum_rises(y: np.ndarray | None, fs: float) -> bool:
    """Whether the samples' spectrum rises toward f_s/2 faster than white angle noise's: the shaped parts carry at
    least :data:`SHAPED_SHARE` of its top band (:func:`spectrum_shaped_share`)."""
    return spectrum_shaped_share(y, fs)["share"] >= SHAPED_SHARE


def _q_line(sub: Curve, order: float, start=("Q",)) -> np.ndarray:
    """The Q column's share the shaped column of ``order`` takes over (C(2k − 2, k − 1) × Q's column), 0 where the
    model has no Q term."""
    if "Q" not in start:
        return np.zeros(sub.tau.size)
    return shaped_q_factor(order) * term_columns(sub, ("Q",))[:, 0]


def sq_family(sub: Curve, has_samples: bool) -> list:
    """Its columns less the Q line they replace (nonzero at the first k − 1 averaging factors): with samples only."""
    if not has_samples:
        return []
    return [column(KEY, float(k), sub) - _q_line(sub, k) for k in SHAPED_ORDERS]


def sq_propose(rnd: Round) -> list:
    """The order with the lower χ², where the samples' spectrum rises (:func:`spectrum_rises`) and the model has
    no shaped term yet."""
    if rnd.y is None or any(base_name(k) == KEY for k, _p in rnd.effects):
        return []
    if not spectrum_rises(rnd.y, rnd.curve.fs):
        return []
    best = None
    for k in SHAPED_ORDERS:
        sol = solve(rnd.curve, rnd.start, rnd.effects + [(KEY, float(k))])
        if best is None or sol.chi2 < best[1].chi2:
            best = (float(k), sol)
    assert best is not None and rnd.sub is not None
    order, sol = best
    return [with_stat(rnd, KEY, order, sol, False, bump=_q_line(rnd.sub, order, rnd.start))]


def sq_params(pr: Proposal, rnd: Round) -> tuple:
    """``q`` (rate unit·s) with its ±1 SD, ``order`` (an int, no interval)."""
    amp, _sd, amp_int = column_amplitude(pr.sol, pr.column)
    return {"q": amp, "order": int(round(pr.p))}, {"q": amp_int}


def sq_evidence(pr: Proposal, rnd: Round) -> dict:
    """The spectrum's rise (:func:`spectrum_rise`, with what each order alone and white angle noise give) and the
    Q the model shows from m = k on."""
    k = int(round(pr.p))
    q2 = max(float(pr.sol.theta[pr.column]), 0.0)
    ev: dict = {"Q_equivalent": math.sqrt(q2 * shaped_q_factor(k))}
    if rnd.y is not None:
        ev["psd_shaped"] = spectrum_shaped_share(rnd.y, rnd.curve.fs) | {
            "threshold": SHAPED_SHARE,
            "bands_fs": (FIT_BAND, TOP_BAND),
        }
    return ev
