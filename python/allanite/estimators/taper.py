"""Tapered windows for the overlapping Allan variance (paper 002; docs/FORMULAS.md §10).

``"hann"``: inside each window, the M = W − 2m + 1 squared second differences at lag m are weighted
by the Hann taper w_i = ½ − ½·cos(2π(i + 1)/(M + 1)) and normalised by Σw = (M + 1)/2 — unbiased for
stationary noise at every τ. Computed by the Rust core in O(1) per output and τ
(``rust/core/src/taper.rs``). Its EDF is the rectangular window's (Greenhall) scaled by the effective
share of the weighted sum (:func:`hann_edf_factor`; (Σw)²/(M·Σw²) = 2(M + 1)/(3M) for 2m ≪ M).

``"hann_signal"``: paper 002's eq. (1) literally — the window's samples (mean removed) multiplied by a
W-point Hann taper, rescaled by 1/√mean(w²) so that white noise keeps its power, then the overlapping
Allan variance. Biased beyond m = 1 (docs/tapers.md tabulates the bias); NumPy, O(W) per τ per
window. No EDF model.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from .. import _core
from .._validate import resolve_workers
from ..errors import ParameterError
from ._registry import Computed, Taper, register_taper
from .allan import n_terms
from .grid import resolve_taus

__all__ = ["MIN_TERMS", "hann_weights", "hann_edf_factor", "signal_taper", "hann_signal_values"]

#: Fewest squared differences per window a taper accepts (M = W − 2m + 1 ≥ 3).
MIN_TERMS = 3

#: Samples per chunk of windows processed at once by the NumPy ``hann_signal`` path.
_CHUNK = 2_000_000


def hann_weights(terms: int) -> np.ndarray:
    """w_i = sin²(π(i + 1)/(M + 1)) = ½ − ½·cos(2π(i + 1)/(M + 1)), i = 0 … M − 1."""
    return np.sin(np.pi * np.arange(1, terms + 1) / (terms + 1)) ** 2


#: Above this many terms the share is computed on a geometry scaled down to it (same m/M).
_SHARE_MAX_TERMS = 1 << 18


@functools.lru_cache(maxsize=4096)
def _share(m: int, window: int) -> float:
    mt = window + 1 - 2 * m
    if mt > _SHARE_MAX_TERMS:
        # the share depends on the shape (m/M), not the scale: evaluate it on a smaller window
        f = _SHARE_MAX_TERMS / mt
        m_s = max(1, round(m * f))
        return _share(m_s, _SHARE_MAX_TERMS - 1 + 2 * m_s)
    w = hann_weights(mt)
    lag = np.arange(min(2 * m, mt))
    r = np.where(lag <= m, 2 * m - 3 * lag, lag - 2 * m).astype(np.float64)  # cov. of d_k, d_{k+L}
    cov = r * r  # Cov(d_k², d_{k+L}²) = 2·r², Gaussian d
    nfft = 1 << int(math.ceil(math.log2(2 * mt)))
    spec = np.fft.rfft(w, nfft)
    auto_w = np.fft.irfft(spec * np.conj(spec), nfft)[: lag.size]
    auto_1 = (mt - lag).astype(np.float64)
    w_cov_w = cov[0] * auto_w[0] + 2.0 * np.sum(cov[1:] * auto_w[1:])
    one_cov_one = cov[0] * auto_1[0] + 2.0 * np.sum(cov[1:] * auto_1[1:])
    return float((w.sum() ** 2 / w_cov_w) / (mt * mt / one_cov_one))


def hann_edf_factor(m, window: int) -> np.ndarray:
    """The share of the rectangular window's degrees of freedom a Hann-weighted estimate keeps:
    ν_H/ν_rect = [(Σw)²/wᵀCw] / [M²/1ᵀC1], C the covariance of the squared second differences
    of white frequency noise (correlated over 2m lags). For 2m ≪ M it is (Σw)²/(M·Σw²) = 2(M + 1)/(3M)
    ≈ 2/3; at m ≈ W/5 … W/3 it rises to ≈ 0.72 (Monte Carlo: tests/test_taper.py)."""
    ms = np.asarray(m, dtype=np.int64)
    out = np.array([_share(int(v), int(window)) for v in ms.ravel()], dtype=np.float64)
    return out.reshape(ms.shape)


def _tapered_ms(taus, n: int, fs: float) -> np.ndarray:
    """Averaging factors for a tapered window of ``n`` samples: a named grid keeps the m that leave
    at least MIN_TERMS terms; explicit τ are checked (a ParameterError names the value)."""
    ms = resolve_taus(taus, n, fs)
    if isinstance(taus, str):
        ms = ms[n + 1 - 2 * ms >= MIN_TERMS]
        if ms.size == 0:
            raise ParameterError(f"a window of {n} samples leaves fewer than {MIN_TERMS} terms at every τ of the grid")
        return ms
    bad = np.flatnonzero(n + 1 - 2 * ms < MIN_TERMS)
    if bad.size:
        m = int(ms[bad[0]])
        raise ParameterError(
            f"a tapered window needs at least {MIN_TERMS} terms, but a window of {n} samples holds "
            f"M = window + 1 − 2m = {n + 1 - 2 * m} at τ = {m / fs:g} s (m = {m}): use m ≤ {(n + 1 - MIN_TERMS) // 2} "
            f"or a longer window"
        )
    return ms


def _hann_static(cols, fs, taus, workers) -> Computed:
    n = cols[0].size
    ms = _tapered_ms(taus, n, fs)
    values = _core.davar_hann(cols, n, 1, [int(m) for m in ms], "fast", resolve_workers(workers))[:, :, 0]
    return Computed(tau=ms / fs, values=values, n=n_terms("oavar", n, ms), m=ms)


def _hann_dynamic(cols, fs, window, hop, taus, method, workers) -> Computed:
    ms = _tapered_ms(taus, window, fs)
    values = _core.davar_hann(cols, window, hop, [int(m) for m in ms], method, resolve_workers(workers))
    return Computed(tau=ms / fs, values=values, n=n_terms("oavar", window, ms), m=ms)


def signal_taper(window: int) -> np.ndarray:
    """The W-point Hann taper of ``hann_signal`` (no zero ends), scaled so that mean(w²) = 1."""
    w = hann_weights(window)
    return w / np.sqrt(np.mean(w * w))


def hann_signal_values(y: np.ndarray, window: int, hop: int, ms: np.ndarray) -> np.ndarray:
    """Paper 002 eq. (1) for one rate column: (len(ms), windows). Each window's mean is removed (a bias
    would otherwise become a Hann-shaped signal), the samples are multiplied by :func:`signal_taper`,
    and the overlapping Allan variance of the result is taken at every m."""
    n = y.size
    n_win = (n - window) // hop + 1
    taper = signal_taper(window)
    out = np.empty((ms.size, n_win))
    per = max(1, _CHUNK // window)
    views = np.lib.stride_tricks.sliding_window_view(y, window)[::hop]
    for j0 in range(0, n_win, per):
        blk = np.asarray(views[j0 : j0 + per], dtype=np.float64)
        blk = (blk - blk.mean(axis=1, keepdims=True)) * taper
        x = np.zeros((blk.shape[0], window + 1))
        np.cumsum(blk, axis=1, out=x[:, 1:])
        for t, m in enumerate(ms):
            m = int(m)
            d = x[:, 2 * m :] - 2.0 * x[:, m:-m] + x[:, : -2 * m]
            out[t, j0 : j0 + blk.shape[0]] = np.mean(d * d, axis=1) / (2.0 * m * m)
    return out


def _signal_static(cols, fs, taus, workers) -> Computed:
    n = cols[0].size
    return _signal_dynamic(cols, fs, n, 1, taus, "fast", workers)


def _signal_dynamic(cols, fs, window, hop, taus, method, workers) -> Computed:
    ms = _tapered_ms(taus, window, fs)
    values = np.stack([hann_signal_values(c, window, hop, ms) for c in cols])
    return Computed(tau=ms / fs, values=values, n=n_terms("oavar", window, ms), m=ms)


register_taper(
    Taper(
        "hann",
        "Hann-weighted squared differences (unbiased; paper 002)",
        estimators=("oavar",),
        static=_hann_static,
        dynamic=_hann_dynamic,
        edf_factor=hann_edf_factor,
        methods=("fast", "naive"),
    )
)
register_taper(
    Taper(
        "hann_signal",
        "Hann-tapered samples, then OAVAR (paper 002 eq. 1; biased)",
        estimators=("oavar",),
        static=_signal_static,
        dynamic=_signal_dynamic,
        edf_factor=None,
        methods=("fast", "naive"),
    )
)
