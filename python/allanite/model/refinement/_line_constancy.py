"""A removed line's amplitude along the record: is it the same in every block?

The test behind the ``"line"`` check of :mod:`.missing` (:mod:`._line_check`): the
least-squares phasor of a fixed-frequency line in ``B`` blocks along the record (each ≥ ``MIN_PERIODS``
periods), compared with their mean by an F test whose noise variance comes from phasors at off-line
frequencies of the same blocks (the residual's local PSD at f0). The complex phasor, not |A|, is tested, so
that a line on noise (a Rice-distributed |A|) and a line of zero amplitude are treated alike.

Each block's fit is weighted by a Hann taper: with the block's own (rectangular) edges, power far from f0 —
the in-block trend of a random walk or flicker, a filter's pass band beside a line in its stop band — leaked
into the phasors through sidelobes falling only as 1/Δf², the same component in the line's and in the off-line
phasors and, from a trend, with one phase (measured: the phasor's |E z²|/E|z|² 0.45 on rate random walk, 0.05
tapered); the untapered test rejected 1.35 % of 4000 constant-line records on white + flicker at α 1 %
(tapered 0.90 %). A constant line is still fitted exactly (it lies in the fitted span whatever the weights). The
tapered off-line phasors of neighbouring frequencies are correlated; each is scaled by its own white-noise
variance and the F test's denominator degrees of freedom are the Satterthwaite count of their correlations.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import stats

from .._recent import Small

__all__ = ["line_constancy", "block_phasors", "MAX_BLOCKS", "MIN_PERIODS", "OFF_BINS"]

#: Blocks along the record at most.
MAX_BLOCKS = 16
#: Periods of the line each block holds at least.
MIN_PERIODS = 20
#: Off-line frequencies f0 ± k/T_block (k = 2 … OFF_BINS + 1) per side whose phasors give the noise variance.
OFF_BINS = 4


def _taper(n: int) -> np.ndarray:
    """The square root of a length-``n`` Hann window (sin(π(j + ½)/n)): the weights' root the rows are scaled by."""
    return np.sin(np.pi * (np.arange(n) + 0.5) / n)


def _phasors(y: np.ndarray, t: np.ndarray, freqs: np.ndarray) -> np.ndarray:
    """Hann-weighted least-squares complex amplitudes (a·cos + b·sin → a − ib, with a constant) of ``y`` at each
    of ``freqs``, at the times ``t`` themselves (the reference the block-local fits of :func:`line_constancy` are
    checked against)."""
    return _local_phasors(y, _basis(t, freqs))


def _basis(t: np.ndarray, freqs: np.ndarray) -> tuple:
    """The phasors' linear map at block-local times ``t``: ``g`` (one complex row per frequency, to be applied to
    the tapered samples; the Hann-weighted least squares of cos, sin and a constant) and the taper's root ``r``;
    with ``cov``, the phasors' covariance for unit white noise (gᵢ·diag(r²)·gⱼᴴ)."""
    r = _taper(t.size)
    w = 2.0 * np.pi * freqs[:, None] * t[None, :]
    c, s = np.cos(w) * r, np.sin(w) * r
    rn = r / np.linalg.norm(r)
    c -= np.outer(c @ rn, rn)  # the weighted constant projected out: columns orthogonal to it
    s -= np.outer(s @ rn, rn)
    cc, ss, cs = np.sum(c * c, 1), np.sum(s * s, 1), np.sum(c * s, 1)
    scale = 1.0 / (cc * ss - cs**2)[:, None]
    # ((ss·c − cs·s) − i(cc·s − cs·c))/det part by part: NumPy divides a complex by a real det as by det + 0i, its
    # real and imaginary parts each times 1/det — the same numbers, without the complex temporaries
    g = np.empty(c.shape, dtype=np.complex128)
    g.real = (ss[:, None] * c - cs[:, None] * s) * scale
    g.imag = -((cc[:, None] * s - cs[:, None] * c) * scale)
    gr = np.empty_like(g)
    gr.real, gr.imag = g.real * r, g.imag * r
    return g, r, gr @ gr.conj().T


#: The bases last made (:func:`_basis_of`), by block length, rate and frequencies: the final line check and the
#: phasors of the components removed at a line ask for the same blocks' basis at the same frequencies.
_BASES = Small(2)
#: Largest basis kept (bytes of its phasor map; a longer block's is made each time).
KEPT_BASIS = 2**25


def _basis_of(size: int, fs: float, freqs: np.ndarray) -> tuple:
    """:func:`_basis` at block-local times of ``size`` samples at ``fs``, the last few remembered (read-only)."""
    key = Small.key(np.asarray(freqs, dtype=np.float64), int(size), float(fs))
    got = _BASES.get(key)
    if got is None:
        got = _basis(np.arange(size) / fs, freqs)
        for a in got:
            a.flags.writeable = False
        if got[0].nbytes <= KEPT_BASIS:
            _BASES.put(key, got)
    return got


def _local_phasors(y: np.ndarray, basis: tuple) -> np.ndarray:
    """:func:`_phasors` of ``y`` on a :func:`_basis` in block-local time; a block starting at t₀ has its
    phasors times e^{−2πi·f·t₀} (a cos + b sin of f(t₀ + τ) is the same line; the fit's span does not change)."""
    g, r, _cov = basis
    return g @ (r * y)


def _noise_terms(cov: np.ndarray) -> tuple[np.ndarray, float]:
    """Per frequency, the phasor's variance under unit white noise, and the Satterthwaite degrees of freedom of
    the sum of the off-line phasors' |z|² each over its variance (2 per phasor when they are uncorrelated)."""
    d = np.real(np.diag(cov))
    rho2 = np.abs(cov[1:, 1:]) ** 2 / np.outer(d[1:], d[1:])
    return d, float(2 * (d.size - 1) ** 2 / np.sum(rho2))


def _block_terms(y: np.ndarray, fs: float, f0: float, edges: np.ndarray) -> tuple:
    """Per block: the line's phasor, its variance under unit white noise, the off-line level (the mean of the
    off-line phasors' |z|² each over its unit-noise variance) and that level's degrees of freedom."""
    k = np.arange(2, OFF_BINS + 2, dtype=float)
    blocks = edges.size - 1
    ph, unit, level, dof = np.empty(blocks, complex), np.empty(blocks), np.empty(blocks), np.empty(blocks)
    bases: dict[int, tuple] = {}  # the blocks have at most two lengths: one basis each
    for b in range(blocks):
        yb = np.asarray(y[edges[b] : edges[b + 1]], dtype=float)
        if yb.size not in bases:
            df = fs / yb.size
            off = np.concatenate([f0 - k * df, f0 + k * df])
            off = off[(off > 0) & (off < fs / 2)]
            freqs = np.concatenate([[f0], off])
            basis = _basis_of(yb.size, fs, freqs)
            bases[yb.size] = (freqs, basis, *_noise_terms(basis[2]))
        freqs, basis, d, nu = bases[yb.size]
        z = _local_phasors(yb, basis) * np.exp(-2j * np.pi * freqs * (edges[b] / fs))
        ph[b], unit[b], dof[b] = z[0], d[0], nu
        level[b] = float(np.mean(np.abs(z[1:]) ** 2 / d[1:]))
    return ph, unit, level, dof


def block_phasors(y: np.ndarray, fs: float, f0: float, blocks: int) -> np.ndarray:
    """The line's complex amplitude at ``f0`` in each of ``blocks`` blocks of ``y``, as :func:`line_constancy`
    fits it (its blocks, its taper, record time): phasors are linear in the samples, so those of a removed
    component added to the final samples' give the record's own."""
    edges = np.linspace(0, y.size, blocks + 1).astype(int)
    return _block_terms(y, fs, f0, edges)[0]


def line_constancy(y: np.ndarray, fs: float, f0: float, alpha: float, phasors: bool = False) -> dict | None:
    """Test that the line at ``f0`` Hz has the same complex amplitude in every block of ``y`` (rate ``fs``).

    Returns None where fewer than 4 blocks of ``MIN_PERIODS`` periods fit, else a dict: ``statistic`` (the F
    ratio), ``threshold`` (its 1 − ``alpha`` quantile, F(2(B − 1), d₂) with d₂ the off-line phasors' Satterthwaite
    degrees of freedom, ≈ 9.4 per block where all 2·OFF_BINS are inside (0, fs/2)), ``rejected``, ``blocks``,
    ``edges_s`` (block edges, s), ``amplitude`` (|A| per block) and ``amplitude_mean`` (|mean phasor|); with
    ``phasors`` also ``"phasors"``, the complex amplitude per block, and ``"phasor_var"``, each one's noise
    variance E|c − A|² — the pooled level ``"noise_level"`` (``"noise_dof"`` its degrees of freedom) times the
    block's variance under unit white noise, ``"phasor_unit"``.

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
    ph, unit, level, dof = _block_terms(y, fs, f0, edges)
    s2 = float(np.sum(level * dof) / np.sum(dof))  # the local noise level at f0 (per unit white variance), pooled
    var = level * unit  # each block's own estimate of its phasor's noise variance E|c − A|²
    mean = complex(np.sum(ph / unit) / np.sum(1 / unit))
    num = float(np.sum(np.abs(ph - mean) ** 2 / unit) / s2) / (blocks - 1)  # each |c − A|²/(s²·u) is χ²₂/2
    d2 = float(np.sum(dof))
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
        out["phasor_unit"], out["noise_level"], out["noise_dof"] = unit.tolist(), s2, d2
    return out
