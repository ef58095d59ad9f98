"""A removed line's amplitude along the record: is it the same in every block?

The test behind the ``"line"`` check of :mod:`.missing` (:mod:`._line_check`): the
least-squares phasor of a fixed-frequency line in ``B`` blocks along the record (each ≥ ``MIN_PERIODS``
periods), compared with their mean by an F test whose noise variance comes from phasors at off-line
frequencies of the same blocks (the residual's local PSD at f0). The complex phasor, not |A|, is tested, so
that a line on noise (a Rice-distributed |A|) and a line of zero amplitude are treated alike.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import stats

__all__ = ["line_constancy", "MAX_BLOCKS", "MIN_PERIODS", "OFF_BINS"]

#: Blocks along the record at most.
MAX_BLOCKS = 16
#: Periods of the line each block holds at least.
MIN_PERIODS = 20
#: Off-line frequencies f0 ± k/T_block (k = 2 … OFF_BINS + 1) per side whose phasors give the noise variance.
OFF_BINS = 4


def _phasors(y: np.ndarray, t: np.ndarray, freqs: np.ndarray) -> np.ndarray:
    """Least-squares complex amplitudes (a·cos + b·sin → a − ib) of ``y`` at each of ``freqs``, mean removed, at
    the times ``t`` themselves (the reference the block-local fits of :func:`line_constancy` are checked against)."""
    return _local_phasors(y, _basis(t, freqs))


def _basis(t: np.ndarray, freqs: np.ndarray) -> tuple:
    """The mean-removed cosines and sines of :func:`_phasors` at block-local times ``t``, with their Gram terms."""
    w = 2.0 * np.pi * freqs[:, None] * t[None, :]
    c, s = np.cos(w), np.sin(w)
    c -= c.mean(axis=1, keepdims=True)
    s -= s.mean(axis=1, keepdims=True)
    cc, ss, cs = np.sum(c * c, 1), np.sum(s * s, 1), np.sum(c * s, 1)
    return c, s, cc, ss, cs, cc * ss - cs**2


def _local_phasors(y: np.ndarray, basis: tuple) -> np.ndarray:
    """:func:`_phasors` of ``y`` on a :func:`_basis` in block-local time; a block starting at t₀ has its
    phasors times e^{−2πi·f·t₀} (a cos + b sin of f(t₀ + τ) is the same line; the fit's span does not change)."""
    c, s, cc, ss, cs, det = basis
    yc = y - y.mean()
    yc_c, yc_s = c @ yc, s @ yc
    a = (ss * yc_c - cs * yc_s) / det
    b = (cc * yc_s - cs * yc_c) / det
    return a - 1j * b


def line_constancy(y: np.ndarray, fs: float, f0: float, alpha: float, phasors: bool = False) -> dict | None:
    """Test that the line at ``f0`` Hz has the same complex amplitude in every block of ``y`` (rate ``fs``).

    Returns None where fewer than 4 blocks of ``MIN_PERIODS`` periods fit, else a dict: ``statistic`` (the F
    ratio), ``threshold`` (its 1 − ``alpha`` quantile, F(2(B − 1), 4·OFF_BINS·B)), ``rejected``, ``blocks``,
    ``edges_s`` (block edges, s), ``amplitude`` (|A| per block) and ``amplitude_mean`` (|mean phasor|); with
    ``phasors`` also ``"phasors"``, the complex amplitude per block, and ``"phasor_var"``, each one's noise
    variance E|c − A|².

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(1)
    >>> t = np.arange(200_000) / 200.0
    >>> y = rng.normal(size=t.size) + 0.5 * np.sin(2 * np.pi * 4.3 * t) * (t > 500)
    >>> bool(line_constancy(y, 200.0, 4.3, 0.01)["rejected"])
    True
    """
    n = y.size
    per_block = MIN_PERIODS * fs / f0
    blocks = int(min(MAX_BLOCKS, n // max(per_block, 1.0)))
    if blocks < 4:
        return None
    edges = np.linspace(0, n, blocks + 1).astype(int)
    k = np.arange(2, OFF_BINS + 2, dtype=float)
    ph, noise = np.empty(blocks, complex), np.empty(blocks)
    bases: dict[int, tuple] = {}  # the blocks have at most two lengths: one basis each
    for b in range(blocks):
        yb = np.asarray(y[edges[b] : edges[b + 1]], dtype=float)
        if yb.size not in bases:
            df = fs / yb.size
            off = np.concatenate([f0 - k * df, f0 + k * df])
            off = off[(off > 0) & (off < fs / 2)]
            freqs = np.concatenate([[f0], off])
            bases[yb.size] = (freqs, _basis(np.arange(yb.size) / fs, freqs))
        freqs, basis = bases[yb.size]
        z = _local_phasors(yb, basis) * np.exp(-2j * np.pi * freqs * (edges[b] / fs))
        ph[b] = z[0]
        noise[b] = float(np.mean(np.abs(z[1:]) ** 2)) * yb.size  # |A|² var × block length: per-sample scale
    lengths = np.diff(edges).astype(float)
    var = noise / lengths  # each block's phasor variance (E|c − A|²)
    pooled = float(np.mean(noise))  # the per-sample scale v·L, pooled over the blocks
    mean = complex(np.sum(ph / var) / np.sum(1 / var))
    num = float(np.sum(np.abs(ph - mean) ** 2 * lengths) / pooled) / (blocks - 1)  # each |c − A|²/v is χ²₂/2
    d2 = 4 * OFF_BINS * blocks
    thr = float(stats.f.ppf(1 - alpha, 2 * (blocks - 1), d2))
    out = {
        "statistic": num,
        "threshold": thr,
        "rejected": bool(num > thr),
        "blocks": blocks,
        "edges_s": (edges / fs).tolist(),
        "amplitude": np.abs(ph).tolist(),
        "amplitude_mean": abs(mean),
        "p_value": float(stats.f.sf(num, 2 * (blocks - 1), d2)),
        "alpha": alpha,
        "f0": f0,
        "periods_per_block": float(math.floor(n / blocks * f0 / fs)),
    }
    if phasors:
        out["phasors"], out["phasor_var"] = ph.tolist(), var.tolist()
    return out
