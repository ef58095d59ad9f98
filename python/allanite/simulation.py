"""Simulated gyro rate records with known IEEE-952 noise terms.

Every term is generated so that its Allan variance is the closed form of docs/FORMULAS.md §4.4, §5 (with the
discrete-time effects named where they matter):

==========  ====================================  ===========================================
term        generated as                          Allan variance
==========  ====================================  ===========================================
Q           white angle noise, std Q, differenced  3Q²/τ² (exact for m ≥ 1: white phase)
N           white rate noise, std N/√τ0             N²/τ
B           flicker rate noise, Kasdin–Walter        (2 ln2/π)·B² plateau (+ the usual roll-off
            fractional integration (α = 1) of        at τ near τ0 and near the record length)
            white noise of variance B²
K           random walk of rate: cumsum of white    K²τ/3 for m ≫ 1; the sampled walk gives
            rate steps of std K·√τ0                  K²τ0/2 = 1.5 × K²τ/3 at m = 1 (exact:
                                                     K²τ0(2m² + 1)/(6m))
R           deterministic ramp R·t                  R²τ²/2
GM(σ, Tc)   exact AR(1), φ = e^(−τ0/Tc)            discrete AR(1) closed form
sinusoid    A·sin(2π f0 t + φ)                     A²·[sin²(πf0τ)/(πf0τ)]²
==========  ====================================  ===========================================

Coefficients may change along the record: pass a number, a callable of t (s) returning an array, or
a piecewise list ``[(t_start, value), …]`` (value from t_start on). White, flicker, random-walk and
Gauss–Markov terms scale their driving noise sample by sample; the ramp integrates R(t).
"""

from __future__ import annotations

import functools
import math
import numbers
from typing import Any

import numpy as np

from ._validate import check_count, check_fs
from .errors import ParameterError

__all__ = ["simulate", "kasdin_walter", "power_law_filter"]


def kasdin_walter(n: int, alpha: float, rng: np.random.Generator, variance: float = 1.0) -> np.ndarray:
    """Power-law noise with one-sided PSD ≈ 2·variance·τ0 / (2π f τ0)^alpha (Kasdin & Walter 1992):
    :func:`power_law_filter` applied to n white samples of the given variance drawn from ``rng``."""
    return power_law_filter(rng.normal(scale=np.sqrt(variance), size=n), alpha)


def power_law_filter(w: np.ndarray, alpha: float) -> np.ndarray:
    """Kasdin & Walter's (1992) fractional integration of the white samples ``w``: the filter
    h_0 = 1, h_k = h_{k−1}·(k − 1 + alpha/2)/k, applied by FFT convolution over 2n points so that no
    low-frequency content is lost to circular wrap-around. alpha = 1: flicker, 2: random walk,
    −2: first difference; the output PSD is the input's times |2 sin(π f τ0)|^(−alpha)."""
    n = w.size
    response = _cached_response(n, float(alpha)) if n <= _CACHED_MAX_N else _response(n, float(alpha))
    return np.fft.irfft(response * np.fft.rfft(w, 2 * n), 2 * n)[:n]


#: longest record whose filter transform is kept for the next call (16 MB at most per entry)
_CACHED_MAX_N = 2**20


def power_law_coefficients(n: int, alpha: float) -> np.ndarray:
    """The first n Kasdin & Walter (1992) filter coefficients: h_0 = 1, h_k = h_{k−1}·(k − 1 + alpha/2)/k."""
    h = np.empty(n)
    h[0] = 1.0
    k = np.arange(1, n)
    h[1:] = np.cumprod((k - 1 + alpha / 2.0) / k)
    return h


def _response(n: int, alpha: float) -> np.ndarray:
    """The transform (length-2n rfft) of the first n Kasdin & Walter filter coefficients."""
    out = np.fft.rfft(power_law_coefficients(n, alpha), 2 * n)
    out.flags.writeable = False
    return out


#: repeated draws of one size and exponent (allantools' Noise, Monte Carlo loops) reuse the transform
_cached_response = functools.lru_cache(maxsize=4)(_response)


def _profile(value, t: np.ndarray, name: str) -> Any:
    """A coefficient as a scalar or a per-sample array, validated."""
    if callable(value):
        out = value(t)
        try:
            arr = np.asarray(out, dtype=np.float64)
            if arr.shape != t.shape:
                arr = np.broadcast_to(arr, t.shape).astype(np.float64)
        except (TypeError, ValueError):
            raise ParameterError(
                f"{name}: the callable must return a number or an array of {t.size} numbers (one per sample "
                f"time t), got {type(out).__name__}{f' of shape {out.shape}' if hasattr(out, 'shape') else ''}"
            ) from None
    elif isinstance(value, (list, tuple)) and value and isinstance(value[0], (list, tuple)):
        try:
            pairs = sorted(((float(start), float(v)) for start, v in value), key=lambda p: p[0])
        except (TypeError, ValueError):
            raise ParameterError(
                f"{name} as a piecewise profile must be a list of (t_start, value) pairs of numbers, got {value!r}"
            ) from None
        if not all(math.isfinite(start) for start, _ in pairs):
            raise ParameterError(f"{name}: piecewise start times must be finite seconds, got {value!r}")
        arr = np.zeros_like(t)
        for start, v in pairs:
            arr[t >= start] = v
    elif isinstance(value, (numbers.Real, np.floating, np.integer)) and not isinstance(value, bool):
        arr = float(value)  # type: ignore[assignment]  # a constant coefficient stays a scalar
    else:
        raise ParameterError(
            f"{name} must be a number, a callable of t or a list of (t_start, value) pairs, got {value!r}"
        )
    a = np.asarray(arr)
    if not np.all(np.isfinite(a)) or np.any(a < 0):
        raise ParameterError(f"{name} must be finite and ≥ 0 everywhere, got {value!r}")
    return arr


def _is_zero(p) -> bool:
    return bool(np.all(np.asarray(p) == 0))


def simulate(
    n: int, fs: float, *, Q=0.0, N=0.0, B=0.0, K=0.0, R=0.0, gauss_markov=(), sinusoid=(), seed=None
) -> np.ndarray:
    """Rate samples with the five IEEE-952 terms, Gauss–Markov processes and sinusoids.

    Parameters
    ----------
    n : int
        Number of rate samples.
    fs : float
        Sampling rate, Hz.
    Q, N, B, K, R : float, callable or list of (t_start, value)
        Quantization (angle unit, e.g. °), angle random walk (unit/√s, e.g. °/√s), bias instability
        (rate unit, °/s), rate random walk (unit/s^1.5) and rate ramp (unit/s²), in the caller's
        unit's base form; 0 leaves a term out.
    gauss_markov : sequence of (sigma, tc)
        First-order Gauss–Markov processes: stationary std sigma (rate unit, may vary like the
        terms above) and correlation time tc (s).
    sinusoid : sequence of (amplitude, f0) or (amplitude, f0, phase)
        Sinusoids in the rate, f0 in Hz (> 0), phase in radians (default 0).
    seed : int or numpy Generator, optional
        For reproducible records.

    Returns
    -------
    numpy.ndarray
        n rate samples (the caller's rate unit).

    Examples
    --------
    >>> import numpy as np, allanite
    >>> y = allanite.simulate(200_000, 100.0, N=0.01, seed=1)     # ARW 0.01 °/√s
    >>> r = allanite.avar(y, 100.0, taus=[1.0, 10.0])
    >>> np.round(r.adev * np.sqrt(r.tau), 3)                       # adev·√τ = N
    array([0.01, 0.01])
    """
    n = check_count(n, "n", 2)
    fs = check_fs(fs)
    tau0 = 1.0 / fs
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    t = np.arange(n) * tau0
    y = np.zeros(n)
    q = _profile(Q, t, "Q")
    if not _is_zero(q):
        # white angle noise of std Q on n + 1 angle points, differenced to rate
        qq = np.append(q, q[-1]) if np.ndim(q) else q
        theta = rng.normal(size=n + 1) * qq
        y += np.diff(theta) / tau0
    nn = _profile(N, t, "N")
    if not _is_zero(nn):
        y += rng.normal(size=n) * (nn / np.sqrt(tau0))
    b = _profile(B, t, "B")
    if not _is_zero(b):
        y += kasdin_walter(n, 1.0, rng) * b
    k = _profile(K, t, "K")
    if not _is_zero(k):
        y += np.cumsum(rng.normal(size=n) * (k * np.sqrt(tau0)))
    r = _profile(R, t, "R")
    if not _is_zero(r):
        y += np.cumsum(np.broadcast_to(r, t.shape)) * tau0 if np.ndim(r) else r * t
    for item in gauss_markov:
        y += _gauss_markov(item, t, tau0, rng)
    for item in sinusoid:
        y += _sinusoid(item, t)
    return y


def _gauss_markov(item, t: np.ndarray, tau0: float, rng: np.random.Generator) -> np.ndarray:
    """One first-order Gauss–Markov process, the (sigma, tc) entry ``item``, at the sample times ``t``."""
    try:
        sigma, tc = item
    except (TypeError, ValueError):
        raise ParameterError(f"gauss_markov entries must be (sigma, tc) pairs, got {item!r}") from None
    sig = _profile(sigma, t, "gauss_markov sigma")
    value = _float_or_nan(tc)
    if not np.isfinite(value) or value <= 0:
        shown = tc if math.isnan(value) else value  # a number as a float (as before), else as given
        raise ParameterError(f"gauss_markov correlation time must be a positive number of seconds, got {shown!r}")
    phi = np.exp(-tau0 / value)
    drive = rng.normal(size=t.size) * np.sqrt(1.0 - phi * phi)
    unit = ar1(drive, phi, rng.normal())
    return unit * sig


def _sinusoid(item, t: np.ndarray) -> np.ndarray:
    """One sinusoid, the (amplitude, f0) or (amplitude, f0, phase) entry ``item``, at the sample times ``t``."""
    if not isinstance(item, (list, tuple)) or len(item) not in (2, 3):
        raise ParameterError(f"sinusoid entries must be (amplitude, f0) or (amplitude, f0, phase), got {item!r}")
    amp = _profile(item[0], t, "sinusoid amplitude")
    f0 = _float_or_nan(item[1])
    if not np.isfinite(f0) or f0 <= 0:
        raise ParameterError(f"sinusoid frequency must be a positive number of Hz, got {item[1]!r}")
    phase = _float_or_nan(item[2]) if len(item) == 3 else 0.0
    if not np.isfinite(phase):
        raise ParameterError(f"sinusoid phase must be a finite number of radians, got {item[2]!r}")
    return amp * np.sin(2 * np.pi * f0 * t + phase)


def _float_or_nan(value) -> float:
    """``value`` as a float, NaN where it is not a number (the caller's check then names it)."""
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan


def ar1(drive: np.ndarray, phi: float, x0: float, block: int = 1024) -> np.ndarray:
    """x_i = φ·x_{i−1} + drive_i, in blocks: x_i = φ^(i+1)·x0 + φ^i·Σ_{j≤i} φ^(−j)·drive_j, where
    φ^(−j) stays O(1) inside a block (block ≪ correlation length in samples is not required: for
    φ^(−block) to overflow, Tc would have to be below ~block/700 samples; those use the plain loop)."""
    if phi**block < 1e-200:
        out = np.empty_like(drive)
        acc = x0
        for i, d in enumerate(drive):
            acc = phi * acc + d
            out[i] = acc
        return out
    out = np.empty_like(drive)
    j = np.arange(block)
    grow, shrink = phi ** (j + 1), phi**j
    inv = phi ** (-j.astype(float))
    for s in range(0, drive.size, block):
        d = drive[s : s + block]
        k = d.size
        out[s : s + k] = grow[:k] * x0 + shrink[:k] * np.cumsum(d * inv[:k])
        x0 = out[s + k - 1]
    return out
