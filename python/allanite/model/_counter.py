"""A delta-angle counter's quantisation, exactly: the Q term's column where the angle, not the rate, is quantised.

A counter (a ring-laser or fibre-optic gyro's pulse count, a MEMS part that outputs delta angles or delta
velocities) outputs y'_k = (Θ_k − Θ_{k−1})/τ₀ with Θ_k = θ_k + e_k the true angle θ_k quantised at step q. The
Q term's 3Q²/τ² (Q = q/√12) holds for a white angle error e; a counter's e is the fractional part of a random
walk, correlated from sample to sample wherever the angle's increment per sample, σ_θ (white rate noise N:
σ_θ² = N²τ₀), is not large beside q. With θ's fractional part (mod q) uniform, e is independent of the
increments (E[y_j e_k] = 0) and, from the sawtooth's Fourier series,

    R_e(m) = E[e_k e_{k+m}] = Σ_{n≥1} (q²/(2π²n²)) · cos(2πn·b·m·τ₀/q) · exp(−2π²n²·m·σ_θ²/q²),  R_e(0) = q²/12,

b the mean rate. The output's Allan variance is the rate noise's plus the exact Allan variance of the
differenced sequence (e_k − e_{k−1})/τ₀; its mean over m samples telescopes to (e_{k+m} − e_k)/τ, so

    σ²_e(τ) = (3R_e(0) − 4R_e(m) + R_e(2m))/τ²,   τ = mτ₀,

which is 3Q²/τ² times :func:`counter_factor`, 1 where R_e(m) = 0 (σ_θ ≫ q: the plain Q term). No free parameter
beyond q (the samples' lattice), σ_θ and b (both read off the samples, :func:`detect_counter`).

Where it lives: in refine's Q term, not as an effect. The right answer for a counter's record is the Q term with
its exact form — nothing added (the record is clean) — so where the samples are a counter's (:func:`detect_counter`),
refine runs inside :func:`counter_quantisation` and every Q column it builds (the start, every step's fits, the
tests' columns, the held-out parts) is 3/τ² × :func:`counter_factor`; Q's coefficient is still fitted (≈ q/√12 on
a counter) and ``Refinement.counter`` says the step, in the angle unit, and in words. Read as a counter's: every
sample on a lattice (q = the lattice's step / f_s), the counts' Allan variance at τ₀ solved for σ_θ/q, and the
counts' autocovariance at lag 1 less lag 2 agreeing with the counter's, (3R_e(1) − R_e(0) − 3R_e(2) + R_e(3))/q²
(≈ −1/12; white rate noise and slow components add alike at both lags). A rate quantised at the output (the
ADIS16405's 14-bit samples, a dead band) has a white error — the contrast near 0 — and is left as it is; so is any
record whose factor differs from 1 by less than :data:`MIN_EFFECT` at every τ (σ_θ ≳ 0.7q: there 3Q²/τ² is exact).

Assumed: the rate noise's increments are white over the few samples R_e lasts (B, K and a filter change them
only over many more); b is each block's mean rate (:func:`block_phases`: a bias drifting along the record is a
mix of phases), so a rate that changes by a good part of a step per sample within a block (a turning platform) is
not modelled — there the contrast usually disagrees and the plain Q term stays.
"""

from __future__ import annotations

import contextvars
import math
import threading
from contextlib import AbstractContextManager
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from .._scoped import scoped
from ..errors import ParameterError
from ..units import parse_unit

__all__ = [
    "Counter",
    "angle_error_autocorrelation",
    "counter_factor",
    "counter_avar",
    "detect_counter",
    "counter_quantisation",
    "active_counter",
    "angle_unit",
    "block_phases",
    "Phase",
    "MIN_EFFECT",
    "CONTRAST_AGREE",
    "sample_lattice",
]

#: The counter's column is used only where it differs from 3Q²/τ² by at least this share at some τ (else the
#: plain term is exact to that share and the record is left as it is).
MIN_EFFECT = 1e-4
#: The counts' autocovariance at lag 1 less lag 2 must agree with the counter's prediction within this share
#: (plus five of its standard errors): an extra white angle noise, or a rate quantised at the output, does not.
CONTRAST_AGREE = 0.1
#: Fourier terms of R_e at most (the tail beyond is ≤ 3/(π²·n) of R_e(0), 7·10⁻⁵ here: only for σ_θ ≪ q).
N_TERMS = 4096
#: Lattice: a sample is on it within this share of a step (plus float32's relative spacing of its magnitude).
LATTICE_TOL = 1e-3
#: Samples per block whose mean rate gives one phase of the mix (:func:`block_phases`).
PHASE_BLOCK = 1024
#: Bins the blocks' phases are gathered in.
PHASE_BINS = 256
#: Shortest record read as a counter's (its autocovariances need samples).
MIN_SAMPLES = 1000


#: A mean rate: b·τ₀/q (the mean counts per sample; only its fractional part matters), or a mix of them —
#: (phases, weights): a rate that drifts along the record, each block's mean weighted by its share.
Phase = float | tuple[np.ndarray, np.ndarray]


def _mix(phase: Phase) -> tuple[np.ndarray, np.ndarray]:
    if isinstance(phase, tuple):
        return np.asarray(phase[0], dtype=np.float64), np.asarray(phase[1], dtype=np.float64)
    return np.array([float(phase)]), np.array([1.0])


def angle_error_autocorrelation(m, ratio: float, phase: Phase) -> np.ndarray:
    """R_e(m)/q² for lags ``m`` (samples, ≥ 0): the quantisation error's autocovariance over q², with ``ratio``
    σ_θ/q and ``phase`` b·τ₀/q (:data:`Phase`; a mix averages the cosines). R_e(0)/q² = 1/12.

    Examples
    --------
    >>> r = angle_error_autocorrelation(np.array([0, 1, 2]), 1 / 3, 0.0)
    >>> [round(float(v) * 12, 4) for v in r]
    [1.0, 0.0678, 0.0076]
    """
    m = np.atleast_1d(np.asarray(m, dtype=np.float64))
    out = np.zeros(m.shape)
    s2 = 2.0 * math.pi**2 * ratio**2
    phases, weights = _mix(phase)
    for i, mi in enumerate(m.ravel()):
        if mi == 0:
            out.flat[i] = 1.0 / 12.0
            continue
        # terms while exp(−s2·n²·m) ≥ e^{−40}
        n_max = N_TERMS if s2 * mi <= 0 else min(N_TERMS, int(math.sqrt(40.0 / (s2 * mi))) + 1)
        if n_max < 1:
            continue
        n = np.arange(1, n_max + 1, dtype=np.float64)
        cosines = _mixed_cosines(phases, weights, float(mi), n_max)
        terms = cosines * np.exp(-s2 * n * n * mi) / (2.0 * math.pi**2 * n * n)
        out.flat[i] = float(terms.sum())
    return out


def _mixed_cosines(phases: np.ndarray, weights: np.ndarray, mi: float, n_max: int) -> np.ndarray:
    """Σ_p w_p·cos(2π·m·β_p·n) for n = 1 … ``n_max``: independent of the ratio σ_θ/q, so the root search over the
    ratio (:func:`_ratios`: 161 grid points and Brent's steps, each at lags 1 and 2, with up to 256 phases ×
    :data:`N_TERMS` cosines) computes them once per lag; the last few kept (:data:`_COSINES`), longer ones sliced —
    the same cosines, their weighted sum per n to rounding."""
    key = (phases.tobytes(), weights.tobytes(), mi)
    with _COSINES_LOCK:
        got = _COSINES.get(key)
    if got is None or got.size < n_max:
        n = np.arange(1, n_max + 1, dtype=np.float64)
        got = weights @ np.cos(2.0 * math.pi * mi * np.outer(phases, n))
        got.flags.writeable = False
        with _COSINES_LOCK:  # refine calls run in threads (Dask workers, the report's)
            while len(_COSINES) >= 8:
                _COSINES.pop(next(iter(_COSINES)))
            _COSINES[key] = got
    return got[:n_max]


#: :func:`_mixed_cosines`' last few, by the phases, weights and lag (≤ 8 × N_TERMS numbers), and their lock.
_COSINES: dict = {}
_COSINES_LOCK = threading.Lock()


def counter_factor(m, ratio: float, phase: Phase) -> np.ndarray:
    """The counter's Allan variance over the plain Q term's at τ = mτ₀: (3R_e(0) − 4R_e(m) + R_e(2m))/(3R_e(0)).

    Examples
    --------
    >>> [round(float(g), 4) for g in counter_factor(np.array([1, 2, 8]), 1 / 3, 0.0)]
    [0.9121, 0.9899, 1.0]
    """
    m = np.atleast_1d(np.asarray(m, dtype=np.float64))
    r1, r2 = angle_error_autocorrelation(m, ratio, phase), angle_error_autocorrelation(2.0 * m, ratio, phase)
    return 1.0 - 4.0 * (4.0 * r1 - r2)


def counter_avar(tau, fs: float, step: float, ratio: float, phase: Phase) -> np.ndarray:
    """The Allan variance the counter's quantisation adds at ``tau`` (s, multiples of 1/``fs``): ``step`` q in
    the angle unit, ``ratio`` σ_θ/q, ``phase`` b/(q·fs); (3R_e(0) − 4R_e(m) + R_e(2m))/τ²."""
    tau = np.asarray(tau, dtype=np.float64)
    return step**2 / (4.0 * tau**2) * counter_factor(np.rint(tau * fs), ratio, phase)


@dataclass(frozen=True)
class Counter:
    """A record read as a delta-angle counter's: its angle ``step`` q (rate unit·s: the angle unit), the rate
    lattice's ``rate_step`` (q·f_s), ``ratio`` σ_θ/q and the mean rate's ``phases`` b/(q·f_s) with their ``weights``
    (per block of :data:`PHASE_BLOCK` samples, :func:`block_phases`) read off the counts, ``fs``, and the
    counts' autocovariance at lag 1 less lag 2, measured and predicted (``contrast``, in steps²)."""

    step: float
    rate_step: float
    ratio: float
    phases: tuple[float, ...]
    weights: tuple[float, ...]
    fs: float
    contrast: tuple[float, float]

    def factor(self, m) -> np.ndarray:
        """:func:`counter_factor` at averaging factors ``m``."""
        return counter_factor(m, self.ratio, self.phase)

    @property
    def phase(self) -> Phase:
        """The mean rate's :data:`Phase` mix."""
        return (np.asarray(self.phases), np.asarray(self.weights))

    @property
    def key(self) -> tuple:
        """What a remembered column depends on."""
        return (self.ratio, self.phases, self.weights, self.fs)

    def describe(self, unit: str | None = None) -> str:
        """The counter in words, for a refinement's notes."""
        u = f" {angle_unit(unit)}"
        return (
            f"the samples are a delta-angle counter's (on a lattice of {self.rate_step:.4g}, anti-correlated as a "
            f"quantised angle's differences: autocovariance at lag 1 less lag 2 {self.contrast[0]:.3g} steps², "
            f"{self.contrast[1]:.3g} predicted): the angle is quantised at step q = {self.step:.4g}{u}, its noise "
            f"per sample {self.ratio:.3g} q; the Q term's column is the counter's exact Allan variance (its angle "
            f"error correlated from sample to sample), not 3Q²/τ² — Q = q/√12 on a counter"
        )


def angle_unit(unit: str | None) -> str:
    """The unit a counter's step is in, from the samples' ``unit``: "deg" for "deg/s", an angle unit as given
    (``input="angle"``: the rate is its differences per second), else "(unit)·s".

    Examples
    --------
    >>> angle_unit("deg/s"), angle_unit("rad"), angle_unit("m/s^2"), angle_unit(None)
    ('deg', 'rad', '(m/s^2)·s', '(rate unit)·s')
    """
    if not unit:
        return "(rate unit)·s"
    if unit.endswith("/s"):
        return unit[:-2]
    try:
        parse_unit(unit, "angle")
    except ParameterError:
        return f"({unit})·s"
    return unit


def _lattice(y: np.ndarray) -> tuple[float, np.ndarray] | None:
    """(step, counts from the first sample) where every sample is on a lattice through the first, else None. The
    step is the smallest difference above 10⁻⁶ of the median non-zero one: a rate made by differencing a quantised
    angle given in floating point (``input="angle"``) has rounding differences of ~10⁻¹⁵ beside its steps."""
    d = np.abs(np.diff(y))
    nonzero = d[d > 0]
    if nonzero.size == 0:
        return None
    floor = 1e-6 * float(np.median(nonzero))
    step = float(np.min(nonzero, where=nonzero > floor, initial=np.inf))
    if not np.isfinite(step) or step <= 0:
        return None
    k = (y - y[0]) / step
    counts = np.rint(k)
    tol = LATTICE_TOL + 2.4e-7 * (np.abs(y) + abs(float(y[0]))) / step  # float32's spacing of the magnitude
    if not np.all(np.abs(k - counts) <= tol):
        return None
    return step, counts


def sample_lattice(y: np.ndarray) -> tuple[float, np.ndarray] | None:
    """(step, counts from the first sample) where every sample of ``y`` lies on a lattice, else None (the lattice
    :func:`detect_counter` reads; :mod:`allanite.model._quantiser` reads a rate quantised at the output on it)."""
    return _lattice(y)


def _allan_tau0(ratio: float, phase: Phase) -> float:
    """The counts' Allan variance at τ₀ (steps²) a counter of ``ratio`` and ``phase`` gives: σ_θ²/q² plus
    3R_e(0) − 4R_e(1) + R_e(2) over q²."""
    r = angle_error_autocorrelation(np.array([0.0, 1.0, 2.0]), ratio, phase)
    return ratio**2 + 3.0 * r[0] - 4.0 * r[1] + r[2]


def block_phases(counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The mean rate's phases (fractional counts per sample) along the record: each block of :data:`PHASE_BLOCK`
    samples' mean, gathered in :data:`PHASE_BINS` bins of [0, 1) (each bin's mean phase, weighted by its share of
    the blocks). A static record's is one phase; a bias drifting with temperature spreads it. The block mean's
    own noise (σ_θ/q/√32 at most) is left in: it blurs the cosine of R_e(1) by < 1 % where R_e matters."""
    nb = counts.size // PHASE_BLOCK
    if nb < 1:
        return np.array([float(np.mean(counts)) % 1.0]), np.array([1.0])
    beta = counts[: nb * PHASE_BLOCK].reshape(nb, PHASE_BLOCK).mean(axis=1) % 1.0
    idx = np.minimum((beta * PHASE_BINS).astype(np.int64), PHASE_BINS - 1)
    n = np.bincount(idx, minlength=PHASE_BINS)
    keep = n > 0
    means = np.bincount(idx, weights=beta, minlength=PHASE_BINS)[keep] / n[keep]
    return means, n[keep] / nb


def _ratios(a1: float, phase: Phase) -> list[float]:
    """Every ratio σ_θ/q at which a counter of ``phase`` gives the counts' Allan variance ``a1`` at τ₀ (one where
    the mean rate is a whole number of steps per sample; with a fractional one, a nearly noiseless counter's
    pattern can give the same: the contrast picks)."""
    grid = np.concatenate(([0.0], np.geomspace(1e-3, math.sqrt(a1) + 1.0, 160)))
    f = np.array([_allan_tau0(float(r), phase) - a1 for r in grid])
    out = []
    for i in np.flatnonzero(np.sign(f[:-1]) * np.sign(f[1:]) <= 0):
        lo, hi = float(grid[i]), float(grid[i + 1])
        out.append(lo if f[i] == 0 else float(brentq(lambda r: _allan_tau0(r, phase) - a1, lo, hi, xtol=1e-7)))
    return out


def _contrast(ratio: float, phase: Phase) -> float:
    """The counts' autocovariance at lag 1 less lag 2 a counter gives (steps²): (3R_e(1) − R_e(0) − 3R_e(2) +
    R_e(3))/q² (white rate noise and slow components add alike at both lags)."""
    r = angle_error_autocorrelation(np.arange(4.0), ratio, phase)
    return float(3.0 * r[1] - r[0] - 3.0 * r[2] + r[3])


def detect_counter(y, fs: float) -> Counter | None:
    """The record read as a delta-angle counter's, or None.

    Read so where (1) every sample lies on a lattice (step Δ, the smallest non-zero difference: q = Δ/f_s);
    (2) the counts' Allan variance at τ₀ gives a ratio σ_θ/q (solved for exactly: every root of :func:`_ratios`,
    the one whose contrast (3) agrees best; with a fractional mean rate a nearly noiseless counter's pattern can
    give the same Allan variance) at which the counter's column differs from 3Q²/τ² by at least
    :data:`MIN_EFFECT`; and (3) the counts' autocovariance at
    lag 1 less lag 2 agrees with the counter's, (3R_e(1) − R_e(0) − 3R_e(2) + R_e(3))/q², within
    :data:`CONTRAST_AGREE` plus five standard errors (a rate quantised at the output has white counts: near 0;
    white rate noise and slow components add alike at both lags). A strong line near the Nyquist frequency
    changes the contrast too: the record is then left with the plain Q term."""
    y = np.asarray(y, dtype=np.float64)
    if y.ndim != 1 or y.size < MIN_SAMPLES or not np.all(np.isfinite(y[:MIN_SAMPLES])):
        return None
    if _lattice(y[:MIN_SAMPLES]) is None:  # a continuous record: out at once
        return None
    got = _lattice(y)
    if got is None:
        return None
    step, counts = got
    a1 = 0.5 * float(np.mean(np.diff(counts) ** 2))
    phase = block_phases(y / step)
    c = counts - counts.mean()
    measured = float(np.mean(c[1:] * c[:-1]) - np.mean(c[2:] * c[:-2]))
    fits = [(abs(measured - _contrast(r, phase)), r) for r in _ratios(a1, phase)]
    if not fits:
        return None
    miss, ratio = min(fits)
    if np.max(np.abs(1.0 - counter_factor(np.arange(1, 9), ratio, phase))) < MIN_EFFECT:
        return None
    predicted = _contrast(ratio, phase)
    if miss > CONTRAST_AGREE * abs(predicted) + 5.0 * a1 * math.sqrt(2.0 / y.size):
        return None
    phases, weights = (tuple(float(v) for v in a) for a in phase)
    return Counter(step / fs, step, float(ratio), phases, weights, float(fs), (measured, predicted))


#: The counter refine's Q columns take (None: 3Q²/τ²), set by :func:`counter_quantisation`.
_ACTIVE: contextvars.ContextVar[Counter | None] = contextvars.ContextVar("allanite_counter", default=None)


def counter_quantisation(counter: Counter | None) -> AbstractContextManager[None]:
    """Within it every Q column refine builds is ``counter``'s exact one (nothing changes for None)."""
    return scoped(_ACTIVE, counter)


def active_counter() -> Counter | None:
    """The counter set by :func:`counter_quantisation`, or None."""
    return _ACTIVE.get()
