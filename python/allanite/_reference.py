"""Pure-NumPy twins of the estimators, written straight from the definitions.

Used by the tests (as the plain per-window recomputation every fast result is checked against) and
by the benchmarks (as the baseline a NumPy user would write). Not tuned, not public API.

Definitions (NIST SP 1065; paper 000): rate y_1..y_M at τ0 = 1/fs; angle x_0 = 0,
x_k = τ0·Σ_{i≤k}(y_i − ȳ); overlapping σ²(mτ0) = Σ_{k=0}^{N−2m−1} (x_{k+2m} − 2x_{k+m} + x_k)² /
(2 m² τ0² (N − 2m)), N = M + 1; classic: K = ⌊M/m⌋ cluster means, σ² = ½⟨(ȳ_{i+1} − ȳ_i)²⟩.
"""

from __future__ import annotations

import numpy as np


def angle_from_rate(y, fs, dtype=np.float64) -> np.ndarray:
    """x_0 = 0, x_k = τ0·Σ_{i≤k} (y_i − ȳ): the mean is removed before integrating."""
    y = np.asarray(y, dtype=dtype)
    x = np.empty(y.size + 1, dtype=dtype)
    x[0] = 0
    np.cumsum((y - y.mean()) / dtype(fs), out=x[1:])
    return x


def oavar_from_angle(x, fs, m) -> float:
    """Overlapping Allan variance from angle points at one m (the textbook double-difference sum)."""
    x = np.asarray(x)
    n = x.size
    tau0 = 1.0 / fs
    d = x[2 * m:] - 2 * x[m:n - m] + x[:n - 2 * m]
    return float(np.sum(d * d) / (2.0 * m * m * tau0 * tau0 * (n - 2 * m)))


def avar_from_angle(x, fs, m) -> float:
    """Classic (non-overlapping) Allan variance from angle points at one m."""
    x = np.asarray(x)
    tau0 = 1.0 / fs
    k = (x.size - 1) // m
    xs = x[: k * m + 1: m]
    d = xs[2:] - 2 * xs[1:-1] + xs[:-2]
    return float(np.sum(d * d) / (2.0 * m * m * tau0 * tau0 * (k - 1)))


def avar_reference(y, fs, ms, estimator="oavar", dtype=np.float64) -> np.ndarray:
    """Static Allan variance of rate samples at each m (``dtype=np.longdouble`` for extra digits)."""
    x = angle_from_rate(y, fs, dtype=dtype)
    f = oavar_from_angle if estimator == "oavar" else avar_from_angle
    return np.array([f(x, dtype(fs), int(m)) for m in ms])


def davar_reference(y, fs, window, hop, ms, estimator="oavar", dtype=np.float64) -> np.ndarray:
    """Plain per-window recomputation: column j = static Allan variance of y[j·hop : j·hop + window]."""
    y = np.asarray(y, dtype=np.float64)
    n_win = (y.size - window) // hop + 1
    out = np.empty((len(ms), n_win))
    for j in range(n_win):
        s = j * hop
        out[:, j] = avar_reference(y[s:s + window], fs, ms, estimator, dtype=dtype)
    return out


def davar_prefix(y, fs, window, hop, ms) -> np.ndarray:
    """The vectorised NumPy DAVAR a user would write: one global cumulative angle, then per m the
    squared second differences and their window sums by differences of a cumulative sum.

    Fast, but both cumulative sums drift and cancel: it is the benchmark baseline, not a reference.
    """
    x = angle_from_rate(y, fs)
    n = x.size
    tau0 = 1.0 / fs
    starts = np.arange(0, y.size - window + 1, hop)
    out = np.empty((len(ms), starts.size))
    for i, m in enumerate(ms):
        m = int(m)
        d = x[2 * m:] - 2 * x[m:n - m] + x[:n - 2 * m]
        c = np.concatenate(([0.0], np.cumsum(d * d)))
        terms = window + 1 - 2 * m
        out[i] = (c[starts + terms] - c[starts]) / (2.0 * m * m * tau0 * tau0 * terms)
    return out


def nbs14_1000() -> np.ndarray:
    """The NBS14 / NIST SP 1065 1000-point test data (FORMULAS.md §4): n₀ = 1234567890,
    n_{i+1} = 16807·n_i mod 2147483647, y_i = n_i / 2147483647, the seed being the first sample."""
    n = 1234567890
    out = np.empty(1000)
    for i in range(1000):
        out[i] = n / 2147483647.0
        n = (16807 * n) % 2147483647
    return out
