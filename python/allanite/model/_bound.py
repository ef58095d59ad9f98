"""The Cramér–Rao bound on the noise coefficients of a record (Whittle approximation): what no fit can beat."""

from __future__ import annotations

import math

import numpy as np

from .._validate import check_count, check_nonnegative, check_positive
from ..errors import ParameterError


def information_bound(n: int, fs: float, *, Q: float = 0.0, N: float = 0.0, B: float = 0.0, K: float = 0.0) -> dict:
    """How precisely a record of ``n`` rate samples at ``fs`` Hz can determine each noise coefficient at all.

    The Cramér–Rao bound, in the Whittle (periodogram) approximation of the Gaussian likelihood, on the
    relative standard deviation of each nonzero coefficient — Q, N, B, K in the input unit's base form,
    as :func:`fit` and :func:`~allanite.simulate` use them — that any unbiased estimator, from the Allan
    variance or otherwise, can reach. Use it to plan a logging campaign (how long until K is known to
    10 %?) and to judge a fit's intervals: ``fit``'s standard errors should not be far above it.

    The spectra are those of the sampled processes :func:`~allanite.simulate` makes (one-sided, rate
    samples, f_k = k·fs/n, k = 1 … n/2): Q: 8Q²sin²(πfτ0)/τ0; N: 2N²; B: B²/(πf); K:
    K²τ0²/(2sin²(πfτ0)). The Fisher information is I_pq = Σ_k ∂_pS·∂_qS/S² for θ = coefficient²,
    and the bound on a coefficient's relative SD is √(I⁻¹)_pp/(2θ_p). For a roughly normal estimate
    the median |relative error| is ≈ 0.674 times that. The rate ramp R is a deterministic trend, not a
    spectral term, and has no bound here.

    Returns a dict term → relative standard deviation (only the nonzero terms).

    Examples
    --------
    >>> import allanite
    >>> b = allanite.information_bound(1_000_000, 100.0, N=2e-3)   # white noise alone: 1/√(2n)
    >>> round(b["N"] * (2 * 1_000_000) ** 0.5, 6)
    1.0
    >>> b = allanite.information_bound(1_000_000, 100.0, Q=3.5e-4, N=2e-3, B=1e-3, K=6e-5)
    >>> round(100 * 0.674 * b["K"], 1)   # median |error| of K no unbiased estimator beats: 16 %
    16.4
    """
    n = int(check_count(n, "n", 4))
    tau0 = 1.0 / check_positive(fs, "fs")
    given = {"Q": Q, "N": N, "B": B, "K": K}
    terms = []
    theta = []
    for name, v in given.items():
        v = check_nonnegative(v, name)
        if v > 0:
            terms.append(name)
            theta.append(v * v)
    if not terms:
        raise ParameterError("information_bound needs at least one nonzero coefficient among Q, N, B, K")
    theta_arr = np.array(theta)
    info = np.zeros((len(terms), len(terms)))
    n_freq = n // 2
    chunk = 1 << 20
    for start in range(1, n_freq + 1, chunk):
        k = np.arange(start, min(n_freq, start + chunk - 1) + 1, dtype=np.float64)
        f = k * (fs / n)
        s2 = np.sin(np.pi * f * tau0) ** 2
        cols = {"Q": 8.0 * s2 / tau0, "N": np.full_like(f, 2.0), "B": 1.0 / (np.pi * f), "K": tau0 * tau0 / (2.0 * s2)}
        d = np.array([cols[t] for t in terms])
        spec = theta_arr @ d
        dw = d / spec
        info += dw @ dw.T
    cov = np.linalg.inv(info)
    return {t: float(math.sqrt(cov[i, i]) / (2.0 * theta_arr[i])) for i, t in enumerate(terms)}
