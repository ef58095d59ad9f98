"""A rate quantised at the output, exactly: the white floor after a filter is not white where the quantum is
coarse beside the filtered rate's sample-to-sample change.

A MEMS part filters its rate (a moving average, a Bartlett, a CIC) and then rounds each output sample to its LSB
Δ: y_n = Q(x_n) = x_n + e_n. Where x moves by much more than Δ from one sample to the next the error e is white of
variance Δ²/12, the bandwidth's ``floor``; but a filter makes x smooth, and a coarse Δ then rounds neighbouring
samples alike: e is correlated over the lags where x moves by less than a step (Bartlett of 7 taps, Δ of 1.2 times
the output's SD: ρ_e(1) = 0.05, enough for a 2·10⁵-sample record to tell at τ = 2 samples). With the quantiser's
offset uniform against the lattice (the bias and its slow wander over a step), e is independent of x and, from the
sawtooth's Fourier series and x's Gaussian increments,

    R_e(l) = Σ_{k≥1} (Δ²/(2π²k²)) · exp(−4π²k²·D_x(l)/Δ²),   R_e(0) = Δ²/12,

D_x(l) = ½E[(x_{n+l} − x_n)²] the unquantised rate's structure function. It is read off the samples: the
output's own D_y(l) = D_x(l) + R_e(0) − R_e(l) solved for D_x at each lag (a fixed point: R_e is small where D_x
is not). The floor's Allan variance is then (4S(m) − S(2m))/(2m²), S(m) = Σ_{|l|<m} (m − |l|)·R_e(l) — over the
white floor's R_e(0)/m, :meth:`OutputQuantiser.factor`: 1 where x moves by more than a step per sample. No free
parameter beyond Δ (the samples' lattice) and D_y (the samples' increments).

Where it lives: in refine's floor, the N column a bandwidth keeps beside its filter (``has_floor``): inside
:func:`output_quantisation` that column is 1/τ × the factor. Read as an output quantiser's only where the samples
lie on a lattice and the factor differs from 1 by at least :data:`MIN_EFFECT` at some τ (the ADIS16405's 14-bit
samples against its noise: far below). A delta-angle counter (:mod:`allanite.model._counter`) is read first.
"""

from __future__ import annotations

import contextvars
import math
from contextlib import AbstractContextManager
from dataclasses import dataclass

import numpy as np

from .._scoped import scoped
from ._counter import sample_lattice

__all__ = [
    "OutputQuantiser",
    "error_autocorrelation",
    "detect_output_quantiser",
    "output_quantisation",
    "active_quantiser",
    "MIN_EFFECT",
    "MAX_LAG",
    "RHO_TAIL",
]

#: The floor's column is changed only where the factor differs from 1 by at least this share at some τ.
MIN_EFFECT = 1e-3
#: Lags of the error's autocorrelation at most (a filter this long at a step this coarse: its tail left out).
MAX_LAG = 4096
#: The error's correlation is cut at the first lag where it falls below this (beyond, the samples' structure
#: function's own scatter: a record of 10⁵ samples reads D_y to ≈ 10⁻² of itself).
RHO_TAIL = 1e-4
#: Fourier terms of R_e summed (the k-th falls as exp(−4π²k²·D/Δ²)/k²; the tail beyond is added in closed form).
N_TERMS = 256
#: Shortest record read (its increments need samples).
MIN_SAMPLES = 1000


def error_autocorrelation(d: np.ndarray) -> np.ndarray:
    """R_e/Δ² at structure functions ``d`` = D_x/Δ² (≥ 0): Σ_k exp(−4π²k²d)/(2π²k²); 1/12 at d = 0.

    Examples
    --------
    >>> [round(float(v) * 12, 4) for v in error_autocorrelation(np.array([0.0, 0.01, 0.1]))]
    [1.0, 0.443, 0.0117]
    """
    d = np.maximum(np.asarray(d, dtype=np.float64), 0.0)
    k = np.arange(1, N_TERMS + 1, dtype=np.float64)
    head = (np.exp(-4.0 * math.pi**2 * np.multiply.outer(d, k * k)) / (2.0 * math.pi**2 * k * k)).sum(axis=-1)
    # the terms beyond, Σ_{k>K} 1/k² ≈ 1/(K + ½), at the first one's decay (1/12 at d = 0 to O(1/K³))
    tail = np.exp(-4.0 * math.pi**2 * (N_TERMS + 1) ** 2 * d) / (2.0 * math.pi**2 * (N_TERMS + 0.5))
    return head + tail


@dataclass(frozen=True)
class OutputQuantiser:
    """A record read as a rate quantised at the output: its ``step`` Δ (rate unit), ``fs`` and the error's
    autocorrelation ``rho`` R_e(l)/R_e(0), l = 0, 1, … (:func:`detect_output_quantiser`)."""

    step: float
    fs: float
    rho: tuple[float, ...]

    def factor(self, m) -> np.ndarray:
        """The floor's Allan variance over the white floor's at averaging factors ``m`` (samples)."""
        m = np.maximum(np.atleast_1d(np.asarray(m, dtype=np.float64)), 1.0)
        r = np.asarray(self.rho, dtype=np.float64)
        lags = np.arange(1, r.size, dtype=np.float64)
        c0 = np.concatenate(([0.0], np.cumsum(r[1:])))
        c1 = np.concatenate(([0.0], np.cumsum(lags * r[1:])))

        def s(mm):  # S(m)/R_e(0) = m + 2·Σ_{l=1}^{m−1} (m − l)·ρ(l)
            j = np.minimum(mm - 1.0, r.size - 1).astype(np.int64)
            return mm + 2.0 * (mm * c0[j] - c1[j])

        return (4.0 * s(m) - s(2.0 * m)) / (2.0 * m)

    @property
    def key(self) -> tuple:
        """What a remembered column depends on."""
        return (self.step, self.fs, self.rho)

    def describe(self, unit: str | None = None) -> str:
        """The quantiser in words, for a refinement's notes."""
        u = f" {unit}" if unit else ""
        return (
            f"the samples are quantised at the output (a lattice of {self.step:.4g}{u}), coarse beside the filtered "
            f"rate's change from sample to sample: the error is correlated (ρ at lag 1 {self.rho[1]:.3g}); the "
            "floor after the filter is its exact Allan variance, not white"
        )


def _structure(y: np.ndarray, lags: int) -> np.ndarray:
    """D_y(l) = ½·mean((y_{n+l} − y_n)²) for l = 0 … ``lags`` (FFT autocovariance, de-meaned)."""
    z = y - y.mean()
    n = z.size
    size = 1 << int(math.ceil(math.log2(n + lags + 1)))
    f = np.fft.rfft(z, size)
    acov = np.fft.irfft(f * np.conj(f), size)[: lags + 1]
    lag = np.arange(lags + 1)
    sq = np.cumsum(z * z)
    total = sq[-1]
    # Σ_{n<N−l} (z_n² + z_{n+l}²) − 2·Σ z_n z_{n+l}, over N − l pairs
    head = sq[n - 1 - lag]  # Σ_{n ≤ N−1−l} z_n²
    tail = total - np.concatenate(([0.0], sq[:lags]))  # Σ_{n ≥ l} z_n²
    return 0.5 * (head + tail - 2.0 * acov) / (n - lag)


#: R_e/Δ² tabulated on D_x/Δ² in [0, 1] (:func:`_rho` interpolates it: within 10⁻⁷ of R_e(0)).
_GRID = np.concatenate(([0.0], np.geomspace(1e-6, 1.0, 4000)))
_TABLE = error_autocorrelation(_GRID)


def _rho(d_y: np.ndarray) -> np.ndarray:
    """R_e(l)/R_e(0) from the output's structure function ``d_y`` (in Δ²; lag 0 first): D_y = D_x + 1/12 − R_e(D_x)
    solved for D_x at each lag by bisection (the right side rises with D_x, and R_e lies in [0, 1/12]: D_x in
    [D_y − 1/12, D_y]); lags where D_y ≥ 1 have R_e < e⁻³⁰ and are 0. As a covariance: less R_e at the last lag
    (the samples' far apart, independent: its value there is the error's mean over the quantiser's offsets
    squared, a constant of the record, not noise)."""
    r = np.zeros(d_y.size)
    near = np.flatnonzero(d_y[1:] < 1.0) + 1
    lo, hi = np.maximum(d_y[near] - 1.0 / 12.0, 0.0), np.maximum(d_y[near], 0.0)
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        above = mid + 1.0 / 12.0 - np.interp(mid, _GRID, _TABLE) > d_y[near]
        hi, lo = np.where(above, mid, hi), np.where(above, lo, mid)
    r[near] = np.interp(0.5 * (lo + hi), _GRID, _TABLE)
    r[0] = 1.0 / 12.0
    far = float(r[-1]) if r.size > 1 else 0.0
    return (r - far) / (r[0] - far)


def detect_output_quantiser(y, fs: float) -> OutputQuantiser | None:
    """The record read as a rate quantised at the output, or None: every sample on a lattice of step Δ
    (:func:`allanite.model._counter.sample_lattice`), the error's autocorrelation from the samples' structure
    function (:func:`_rho`, up to the lag where it falls below :data:`RHO_TAIL` or :data:`MAX_LAG`), and the
    floor's factor differing from 1 by at least :data:`MIN_EFFECT` at some τ. Out at once where the samples move
    by more than a step from one to the next (D_y(1) > Δ²; a filter's D_x rises with the lag)."""
    y = np.asarray(y, dtype=np.float64)
    if y.ndim != 1 or y.size < MIN_SAMPLES or not np.all(np.isfinite(y[:MIN_SAMPLES])):
        return None
    if sample_lattice(y[:MIN_SAMPLES]) is None:
        return None
    got = sample_lattice(y)
    if got is None:
        return None
    step = got[0]
    if 0.5 * float(np.mean(np.diff(y) ** 2)) / step**2 > 1.0:  # D_y(1) ≥ Δ²: R_e(1) < e⁻³⁰ (the ADIS16405's)
        return None
    lags = int(min(MAX_LAG, y.size // 8))
    rho = _rho(_structure(y, lags) / step**2)
    small = np.flatnonzero(np.abs(rho[1:]) < RHO_TAIL)
    rho = rho[: int(small[0]) + 1] if small.size else rho
    q = OutputQuantiser(float(step), float(fs), tuple(float(v) for v in rho))
    m = np.unique(np.rint(np.geomspace(1, max(2, 4 * rho.size), 64)))
    if np.max(np.abs(q.factor(m) - 1.0)) < MIN_EFFECT:
        return None
    return q


#: The quantiser refine's floor columns take (None: white), set by :func:`output_quantisation`.
_ACTIVE: contextvars.ContextVar[OutputQuantiser | None] = contextvars.ContextVar("allanite_quantiser", default=None)


def output_quantisation(q: OutputQuantiser | None) -> AbstractContextManager[None]:
    """Within it every floor column refine builds (the N column a bandwidth keeps) is ``q``'s exact one."""
    return scoped(_ACTIVE, q)


def active_quantiser() -> OutputQuantiser | None:
    """The quantiser set by :func:`output_quantisation`, or None."""
    return _ACTIVE.get()
