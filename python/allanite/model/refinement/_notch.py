"""A digital notch after the sensor's roll-off: the bandwidth's kind changed to the roll-off followed by
``scipy.signal.iirnotch(f_n, Q, fs)`` (:func:`allanite.model.effects.notch_kind`), where the Allan curve and the
samples' spectrum both show one.

A notch removes power, so it cannot be a column added with a non-negative amplitude beside the roll-off's: it is a
change of the filter's shape, the kind the bandwidth step names. It is tried once the step has its kind
(:func:`notch_choice`, with samples only). A 2-D grid of f_n × Q (:func:`notch_grid`: Q of :data:`NOTCH_Q`; f_n
geometric at :data:`PER_OCTAVE` points an octave in each kind's passband, up to :data:`TOP` of its cutoff, each
notch's −3 dB width f_n/Q and f_n itself at least :data:`MIN_BINS` bins of the Welch spectrum) is first gated on the
spectrum: only the pairs whose band holds at most :data:`DIP` of what the step's kind predicts there, relative to
the flanks (:func:`_dips`, :func:`_band_ratio`), go on — on a record without a notch, none. Those are screened on
the curve beside every kind the step searched, in one batch of fits at each kind's parameter: a notch below the
cutoff bends the curve the way a lower cutoff does, so the kind named without it may be the wrong one (a
2nd-order Butterworth at 60 Hz behind a 30 Hz notch reads as a single pole after a 2-sample boxcar at 40 Hz).
After each of the :data:`KINDS` kinds that fit best, f_n and Q are fitted on the spectrum beside the kind
(:func:`_spectrum_notch`: the spectrum resolves the notch the curve blurs, where f_n, Q and the cutoff trade) in
turn with the kind's parameter searched on the curve beside the notch, then Q once more on the curve
(:func:`_curve_q`) and the parameter again.

It is accepted only by its own nested test, at its own share of ``level`` (``"bandwidth:notch"`` in
:data:`.levels.CONDITIONAL_SHARES`: run only once a roll-off is accepted, so a record without one spends nothing on
it, and on a filtered record it is the rate of naming a notch that is not there): the drop in χ² from the kind
without a notch, counted in the curve's effective independent points (as :func:`.curvefit.profile_interval` counts
them), above χ²₃'s quantile at that α shared over the grid's pairs (Bonferroni) — and only where the Welch spectrum
in the notch's −3 dB band shows it (:func:`notch_in_spectrum`: the band's power within :data:`SPECTRUM_FACTOR` of
the cascade's prediction and nearer to it than to the kind's alone, each levelled on the flanks beside the band).
A kind that is named only where the spectrum shows its roll-off (a Butterworth) is checked so with the notch in.
Its parameter is then not searched again once the loop is done (:func:`._rolloff.research_rolloff`: no grid for a
kind with a notch): the accepted value stays.
"""

from __future__ import annotations

import math

import numpy as np

from .. import tracing
from ..effects import NOTCH_Q, filter_autocorrelation, filter_cutoff, notch_kind, split_notch
from . import _brent
from ._rolloff import needs_spectrum, spectrum_agrees
from .curvefit import FLOOR_TAG, PROFILE_RHO, Curve, bw_kind, chi2s_of, search
from .levels import alpha

__all__ = ["notch_choice", "notch_grid", "notch_in_spectrum", "notch_threshold", "PER_OCTAVE", "MIN_BINS", "TOP"]

#: Points an octave of the notch's frequency grid (a notch of Q 8 is 0.18 octave wide at −3 dB; f_n and Q are then
#: fitted on the spectrum, :func:`_spectrum_notch`).
PER_OCTAVE = 3
#: The most a pair's −3 dB band may hold, in the Welch spectrum, of the power the step's kind predicts there
#: (each levelled on the flanks) for the pair to be screened on the curve: a notch's band holds ≈ 0.21 of it, white
#: noise's its own scatter about 1 — a cheap gate (:func:`_dips`), the acceptance is :func:`notch_in_spectrum`.
DIP = 0.6
#: The fewest Welch bins a notch's −3 dB width f_n/Q, and its distance from 0, may span.
MIN_BINS = 4
#: The highest notch frequency searched, as a fraction of the roll-off's −3 dB cutoff (inside its passband).
TOP = 0.8
#: The quality factors a notch's fit may reach (a factor 2 beyond :data:`NOTCH_Q`'s ends), its width f_n/Q below
#: 0.45·f_s.
Q_RANGE = (NOTCH_Q[0] / 2.0, NOTCH_Q[-1] * 2.0)
#: How many of the step's kinds (lowest χ² first) a notch is tried after.
KINDS = 3
#: How far (a factor either way) the spectrum's power in the notch's −3 dB band may lie from the cascade's
#: prediction (relative to the flanks beside the band, :func:`_band_ratio`); a notch's band holds 1 − π/4 ≈ 0.21 of
#: the power the kind alone predicts there, a factor 4.7: the two are told apart at its square root.
SPECTRUM_FACTOR = 1.5


def _nper(n: int) -> int:
    """The Welch segment length the roll-off's spectrum checks use (:func:`.tracing.rolloff_psd`)."""
    return int(min(4096, 2 ** int(math.log2(max(n // 8, 256)))))


def notch_grid(fc: float, fs: float, tmax: float, n: int) -> list[tuple[float, float]]:
    """The (f_n, Q) pairs a notch is screened at after a roll-off of −3 dB cutoff ``fc`` (Hz) on a curve reaching
    τ ``tmax`` of ``n`` samples at ``fs``: f_n geometric at :data:`PER_OCTAVE` an octave from the larger of
    :data:`MIN_BINS` Welch bins and 4/τ_max up to :data:`TOP`·f_c (below f_s/2 and :data:`MIN_BINS` bins from the
    cutoff), each Q of :data:`NOTCH_Q` where the width f_n/Q spans :data:`MIN_BINS` bins. Empty where none fits."""
    bin_hz = fs / _nper(n)
    f_lo = max(MIN_BINS * bin_hz, 4.0 / tmax)
    f_hi = min(TOP * fc, fc - MIN_BINS * bin_hz, 0.45 * fs)
    if not f_hi > f_lo:
        return []
    fs_grid = np.geomspace(f_lo, f_hi, max(2, int(math.ceil(PER_OCTAVE * math.log2(f_hi / f_lo))) + 1))
    return [(float(f), q) for q in NOTCH_Q for f in fs_grid if f / q >= MIN_BINS * bin_hz]


def notch_threshold(level: float, n_pairs: int) -> float:
    """The nested test's threshold on the effective χ² drop: χ²₃'s upper α/n_pairs quantile, α the notch's share
    of ``level`` (f_n, Q and the roll-off's parameter moved; Bonferroni over the grid's pairs)."""
    from scipy.stats import chi2

    return float(chi2.isf(alpha("bandwidth:notch", level) / max(1, n_pairs), 3))


def _notch_h2(f_n: float, q: float, fs: float, e1: np.ndarray) -> np.ndarray:
    """|H|² of ``scipy.signal.iirnotch(f_n, q, fs=fs)`` at z⁻¹ = ``e1`` — its coefficients in closed form
    (g = 1/(1 + tan(π·f_n/(q·f_s))), b = g·(1, −2cos ω₀, 1), a = (1, −2g·cos ω₀, 2g − 1)), without the design call."""
    w0 = 2.0 * math.pi * f_n / fs
    g = 1.0 / (1.0 + math.tan(math.pi * f_n / (q * fs)))
    c = math.cos(w0)
    num = g * (1.0 - 2.0 * c * e1 + e1 * e1)
    den = 1.0 - 2.0 * g * c * e1 + (2.0 * g - 1.0) * e1 * e1
    return np.abs(num) ** 2 / np.abs(den) ** 2


def _h2(kind: str, p: float, fs: float, f: np.ndarray) -> np.ndarray:
    """|H(f)|² of the filter ``kind`` (with its notch, if any) at the frequencies ``f``."""
    base, f_n, q = split_notch(kind)
    r = filter_autocorrelation(base, p, fs)
    h2 = r[0] + 2.0 * np.cos(2.0 * np.pi * np.outer(f / fs, np.arange(1, r.size))) @ r[1:]
    if f_n is not None and q is not None:
        h2 = h2 * _notch_h2(f_n, q, fs, np.exp(-2j * np.pi * f / fs))
    return np.maximum(h2, 0.0)


def _band_ratio(f: np.ndarray, meas: np.ndarray, pred: np.ndarray, f_n: float, q: float, dip: bool = False) -> float:
    """The power ``meas`` holds in the −3 dB band f_n ± f_n/2Q over what ``pred`` predicts there, relative to the
    same ratio on the flanks — each flank (up to a band's width beside it, the lower one from f_n/4) levelled on its
    own and the two joined log-linearly in log f at f_n, so that a slope the prediction lacks (rate random walk,
    bias instability or a Gauss–Markov term below a white passband) is not read as a dip; with ``dip``, over the
    lower of the two flanks instead — a dip must lie below both sides (a slope, or a hump beside the band, such as
    the ADIS16405 gyros' 20 Hz resonances, lies above one side only). NaN where a part holds no bin or no power."""
    half = f_n / (2.0 * q)
    i0, i1, i2, i3 = np.searchsorted(f, [max(f_n - 3.0 * half, f_n / 4.0), f_n - half, f_n + half, f_n + 3.0 * half])
    cm, cp = np.concatenate([[0.0], np.cumsum(meas)]), np.concatenate([[0.0], np.cumsum(pred)])
    parts = [(i0, i1), (i1, i2), (i2, i3)]
    if any(j <= i or cp[j] - cp[i] <= 0 or cm[j] - cm[i] <= 0 for i, j in parts):
        return math.nan
    lo, band, hi = ((cm[j] - cm[i]) / (cp[j] - cp[i]) for i, j in parts)
    if dip:
        return band / min(lo, hi)
    f_lo, f_hi = math.sqrt(f[i0] * f[i1 - 1]), math.sqrt(f[i2] * f[i3 - 1])
    w = (math.log(f_n) - math.log(f_lo)) / (math.log(f_hi) - math.log(f_lo)) if f_hi > f_lo else 0.5
    return band / math.exp((1.0 - w) * math.log(lo) + w * math.log(hi))


def notch_in_spectrum(y: np.ndarray, fs: float, kind: str, p: float) -> bool:
    """Whether the Welch PSD of ``y`` shows the notch of ``kind`` (:func:`notch_kind`) at ``p``: the power in the
    notch's −3 dB band over the kind's prediction without it, relative to the flanks (:func:`_band_ratio`), within
    :data:`SPECTRUM_FACTOR` of what the notch predicts there, and nearer to it than to 1 (no notch)."""
    base, f_n, q = split_notch(kind)
    if f_n is None or q is None:
        return False
    f, meas = tracing._rolloff_welch(np.asarray(y, dtype=np.float64), float(fs), _nper(y.size))
    sel = (f > 0) & (f <= min(f_n * (1.0 + 1.5 / q) * 1.01, 0.5 * fs))
    f, meas = f[sel], meas[sel]
    alone = _h2(base, p, fs, f)
    measured = _band_ratio(f, meas, alone, f_n, q)
    predicted = _band_ratio(f, _h2(kind, p, fs, f), alone, f_n, q)
    if not (measured > 0 and predicted > 0):
        return False
    off = abs(math.log(measured / predicted))
    return off <= math.log(SPECTRUM_FACTOR) and off < abs(math.log(measured))


def _with_notch(key: str, f_n: float, q: float) -> str:
    """The bandwidth key ``key`` with a notch at ``f_n``, ``q`` after its filter (its floor tag kept)."""
    tag = FLOOR_TAG if key.endswith(FLOOR_TAG) else ""
    return f"bandwidth:{notch_kind(bw_kind(key), f_n, q)}{tag}"


def _spectrum_notch(y: np.ndarray, fs: float, base: str, p: float, notch: tuple) -> tuple:
    """The notch (f_n, Q) near ``notch`` that fits the Welch PSD of ``y`` best beside the filter ``base`` at ``p``:
    least squares of log(measured / (level·|H_base|²·|H_notch|²)) over the bins within two −3 dB widths of f_n
    (below 0.45·f_s), the level free (Nelder–Mead on log f_n, log Q; f_n within a factor 1.5 of ``notch``'s, Q in
    :data:`Q_RANGE`) — the spectrum resolves a notch the Allan
    curve blurs, where f_n, Q and the roll-off's parameter trade."""
    from scipy import optimize

    f, meas = tracing._rolloff_welch(np.asarray(y, dtype=np.float64), float(fs), _nper(y.size))
    f0, q0 = notch
    sel = (np.abs(f - f0) <= 2.0 * f0 / q0) & (f > 0) & (f < 0.45 * fs) & (meas > 0)
    if sel.sum() < 8:
        return notch
    fr, logm = f[sel], np.log(meas[sel]) - np.log(np.maximum(_h2(base, p, fs, f[sel]), 1e-300))

    e1 = np.exp(-2j * np.pi * fr / fs)

    def cost(x):
        fn, q = math.exp(x[0]), math.exp(x[1])
        near = abs(math.log(fn / f0)) <= math.log(1.5)  # within the bins fitted: no wandering off to another dip
        if not (near and fn < 0.45 * fs and Q_RANGE[0] <= q <= Q_RANGE[1] and fn / q < 0.45 * fs):
            return math.inf
        d = logm - np.log(np.maximum(_notch_h2(fn, q, fs, e1), 1e-30))
        return float(np.sum((d - d.mean()) ** 2))

    res = optimize.minimize(
        cost, [math.log(f0), math.log(q0)], method="Nelder-Mead", options={"xatol": 1e-5, "fatol": 1e-9}
    )
    return (math.exp(res.x[0]), math.exp(res.x[1])) if math.isfinite(res.fun) else notch


def _dips(y: np.ndarray, fs: float, kind: str, p: float, pairs: list) -> list:
    """The (f_n, Q) of ``pairs`` whose −3 dB band holds at most :data:`DIP` of the power the filter ``kind`` at
    ``p`` predicts there in the Welch PSD of ``y``, relative to each flank (:func:`_band_ratio` with ``dip``)."""
    if not pairs:
        return []
    f, meas = tracing._rolloff_welch(np.asarray(y, dtype=np.float64), float(fs), _nper(y.size))
    top = min(f.size, int(np.searchsorted(f, 2.5 * max(fn for fn, _q in pairs))) + 1)
    f, meas = f[:top], meas[:top]
    pred = _h2(kind, p, fs, f)
    return [(fn, q) for fn, q in pairs if _band_ratio(f, meas, pred, fn, q, dip=True) <= DIP]


def _screen(rnd, bases: list, best: tuple) -> list:
    """(base, pairs, χ² per pair) of each base (key, p, sol, edge): the (f_n, Q) pairs of its grid where the
    spectrum dips beside the step's kind ``best`` (:func:`_dips`), fitted at the base's own parameter, all in one
    batch of fits (a few reweighting passes: the ranking settles early)."""
    fs, n = rnd.curve.fs, rnd.y.size
    kind, p = bw_kind(best[0]), best[1]
    grids = [notch_grid(filter_cutoff(bw_kind(b[0]), b[1], fs), fs, rnd.tmax, n) for b in bases]
    dipping = set(_dips(rnd.y, fs, kind, p, sorted({pair for g in grids for pair in g})))  # one pass, one prediction
    pairs = [[pair for pair in g if pair in dipping] for g in grids]
    models = [rnd.effects + [(_with_notch(b[0], f, q), b[1])] for b, pp in zip(bases, pairs) for f, q in pp]
    chi2 = chi2s_of(rnd.curve, rnd.start, models, 6) if models else np.zeros(0)
    parts = np.split(chi2, np.cumsum([len(pp) for pp in pairs])[:-1]) if models else [np.zeros(0)] * len(bases)
    return [(b, pp, c, g) for b, pp, c, g in zip(bases, pairs, parts, grids) if pp]


def _notch_after(rnd, base: tuple, screened: tuple, grid: np.ndarray, cont: bool) -> tuple | None:
    """(key, p, sol, edge) of the best notch after the kind of ``base`` = (key, p, sol, edge), from its screened
    (pairs, their χ², the whole grid of pairs), its parameter searched on ``grid``; None where the best f_n sits at
    the edge of the whole grid (not identified)."""
    curve, start, effects, key = rnd.curve, rnd.start, rnd.effects, base[0]
    pairs, chi2, whole = screened
    f_n, q = pairs[int(np.argmin(chi2))]
    if f_n in (min(f for f, _q in whole), max(f for f, _q in whole)):
        return None  # at the edge of its range: not identified
    # the notch from the spectrum beside the kind at its parameter — none where the spectrum does not show it there
    # (the check an accepted notch passes, :func:`notch_in_spectrum`, made before the curve's searches) —, the
    # parameter searched on the curve beside the notch, in turn until the parameter settles (three rounds at most)
    notch, p = (f_n, q), base[1]
    if not notch_in_spectrum(
        rnd.y, curve.fs, notch_kind(bw_kind(key), *_spectrum_notch(rnd.y, curve.fs, bw_kind(key), p, notch)), p
    ):
        return None
    for _round in range(3):
        notch = _spectrum_notch(rnd.y, curve.fs, bw_kind(key), p, notch)
        p_new, sol, edge = search(curve, start, effects, _with_notch(key, *notch), grid, continuous=cont)
        settled = abs(math.log(p_new / p)) < 1e-3
        p = p_new
        if settled:
            break
    # Q once more on the curve (the Welch estimate's window widens a notch a little), and the parameter beside it
    notch = (notch[0], _curve_q(curve, start, effects, key, p, notch))
    p, sol, edge = search(curve, start, effects, _with_notch(key, *notch), grid, continuous=cont)
    return _with_notch(key, *notch), p, sol, edge


def _curve_q(curve: Curve, start: tuple, effects: list, key: str, p: float, notch: tuple) -> float:
    """The notch's Q within a factor 1.25 of ``notch``'s of least χ² on the curve, f_n and the kind's parameter
    ``p`` held (Brent on log Q)."""
    lo = max(notch[1] / 1.25, Q_RANGE[0], notch[0] / (0.45 * curve.fs))
    hi = max(min(notch[1] * 1.25, Q_RANGE[1]), lo)
    gen = _brent.bounded(math.log(lo), math.log(hi), xatol=1e-4)
    x = next(gen)
    try:
        while True:
            x = gen.send(
                float(chi2s_of(curve, start, [effects + [(_with_notch(key, notch[0], math.exp(x)), p)]], 40)[0])
            )
    except StopIteration as stop:
        return math.exp(stop.value)


def notch_choice(rnd, found: list, best: tuple, grids: dict, level: float) -> tuple:
    """``best`` = (key, p, sol, edge), the kind the bandwidth step chose, or a kind of ``found`` followed by a
    notch where its nested test passes and the spectrum shows it (module docstring); ``grids`` each searched
    key's (grid, continuous). Only with samples (``rnd.y``)."""
    if rnd.y is None or best[3]:
        return best
    bases = [f for f in found if not f[3] and f[0].removesuffix(FLOOR_TAG) in grids]
    if best[0] not in [f[0] for f in bases]:
        bases.append(best)
    screened = _screen(rnd, bases, best)
    fs = rnd.curve.fs
    n_pairs = sum(len(notch_grid(filter_cutoff(bw_kind(b[0]), b[1], fs), fs, rnd.tmax, rnd.y.size)) for b in bases)
    tried = []
    for base, *got_screen in sorted(screened, key=lambda s: float(np.min(s[2])))[:KINDS]:
        got = _notch_after(rnd, base, tuple(got_screen), *grids[base[0].removesuffix(FLOOR_TAG)])
        if got is None or got[3]:
            continue
        kind = bw_kind(got[0])
        if needs_spectrum(split_notch(kind)[0]) and not spectrum_agrees(rnd.y, rnd.curve.fs, kind, got[1]):
            continue
        if notch_in_spectrum(rnd.y, rnd.curve.fs, kind, got[1]):
            tried.append(got)
    if not tried:
        return best
    pick = min(tried, key=lambda g: g[2].chi2)
    scale = rnd.curve.n_eff * (1 - PROFILE_RHO) / (1 + PROFILE_RHO) / rnd.curve.tau.size
    if (best[2].chi2 - pick[2].chi2) * scale <= notch_threshold(level, n_pairs):
        return best
    return pick
