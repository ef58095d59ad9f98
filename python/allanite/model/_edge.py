"""The channel tests' law at the record's edges: the exact null variance of a Whittle score, and the factor by
which the tests' references are widened where it exceeds Whittle's (:mod:`allanite.model._coupling`).

Whittle's likelihood (:mod:`allanite.model._whittle`) takes the DFT bins of the differenced, tapered record to be
independent, each of variance S_k. They are not quite: the record is a stretch of a longer process, and what its
two ends cut off — the differenced white noise's end values, left by a 1 % taper — is one term coherent across the
lowest bins, where a differenced white or flicker noise has almost no power of its own. A regressor whose own
difference sits at the same edge (a temperature warming once, most of its change in the record's first eighth)
lines up with that term in every low bin, and its score ``u = Re Σ_k conj(Z_k)·D_k / S_k`` has a variance several
times the ``½ Σ |Z_k|²/S_k`` the law gives it (docs/channels.md, "The record's edges").

The exact variance under a noise PSD P is computed here in time: ``u = Σ_t v_t·d_t`` with
``v = w · Re(FFT(conj(Z)/S)) / ‖w‖`` (w the taper, d the differenced record), so ``Var u = vᵀ·C·v`` with C the
differenced noise's Toeplitz covariance — ``(1/M)·Σ_j P(2πj/M)·|V_j|²`` over the 2·(n − 1)-point transform of v
zero-padded (the padding keeps the record's ends apart: no wrap-around; only the noise's covariance beyond
n − 1 lags aliases back). P is the fitted noise: the parametric shapes' amounts at half-bin spacing in the
parametric bands, each own band's level above. Per test: the record-length transform of each regressor, one
per direction (a quadrature shares its direction's) and one of twice the length per two directions; O(N log N).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from scipy import fft as sfft
from scipy.linalg import eigh

from . import _whittle as wh

__all__ = ["EdgeSource", "covariances", "score_covariances", "edge_factor"]


@dataclass(frozen=True)
class EdgeSource:
    """The regressors in time, to be transformed again when an exact variance is asked for: ``column(i)`` the
    record-length regressor ``i`` of the band sums (the band sums keep only Σ over each band)."""

    column: Callable[[int], np.ndarray]


def _band_of(bands: wh.Bands, k: np.ndarray) -> np.ndarray:
    """Band index of (1-based, possibly fractional) bin positions ``k`` over the whole spectrum."""
    n_bins = (bands.n_diff - 1) // 2
    starts = wh.band_starts(n_bins)
    return np.clip(np.searchsorted(starts, np.floor(k), side="right") - 1, 0, starts.size - 1)


def psd_grid(bands: wh.Bands, fit: dict) -> np.ndarray:
    """The fitted noise PSD of the differenced record on the 2·n_diff-point rfft grid (n_diff + 1 values, half-bin
    spacing): the parametric shapes' amounts where the bands are parametric, each own band's level above."""
    n_diff = bands.n_diff
    k = np.arange(n_diff + 1) / 2.0  # bin positions of the half-bins, 0 … Nyquist
    s = np.asarray(fit["s"], dtype=np.float64)
    p = s[_band_of(bands, np.maximum(k, 1.0))]
    amounts = fit.get("amounts")
    if bands.par.any() and amounts is not None:
        n_par_bins = int(bands.m[bands.par].sum())
        lo = k <= n_par_bins
        # the shapes' highest corner is set by the top parametric bin, as in the fit (wh._basis)
        kk = np.append(k[lo], float(n_par_bins))
        shapes, _ = wh._basis(kk, n_diff, bands.fs)
        p[lo] = (shapes[:-1, : amounts.size] @ amounts)[: int(lo.sum())]
    return np.maximum(p, 0.0)


def _time_vectors(combos: Sequence[np.ndarray], s_bin: np.ndarray, w: np.ndarray, norm: float) -> list[np.ndarray]:
    """v_i with u_i = Σ_t v_t·d_t for the scores u_i = Re Σ_k conj(combos[i]_k)·D_k / S_k (bins 1 … n_bins). A
    combination that is the previous one's quadrature (× −i) is read off the same transform: its v is −w·Im(H)."""
    out: list[np.ndarray] = []
    h = None
    for i, z in enumerate(combos):
        if h is not None and np.array_equal(z, -1j * combos[i - 1]):
            out.append(-w * h.imag / norm)
            continue
        c = np.zeros(w.size, dtype=np.complex128)
        c[1 : z.size + 1] = np.conj(z) / s_bin
        h = sfft.fft(c)
        out.append(w * h.real / norm)
    return out


def _padded_spectra(vs: list[np.ndarray], big_m: int) -> list[np.ndarray]:
    """rfft(v, big_m) of each v, two at a time through one complex transform (v_a + i·v_b)."""
    out = []
    for i in range(0, len(vs), 2):
        if i + 1 == len(vs):
            out.append(sfft.rfft(vs[i], big_m))
            continue
        f = sfft.fft(vs[i] + 1j * vs[i + 1], big_m)
        half = big_m // 2 + 1
        mirror = np.conj(f[(-np.arange(half)) % big_m])
        out += [(f[:half] + mirror) / 2.0, (f[:half] - mirror) / 2.0j]
    return out


def _bin_grid(bands: wh.Bands) -> tuple[int, np.ndarray, float, np.ndarray]:
    """The DFT grid the scores are read on, as :func:`allanite.model._whittle.spectra` made it: (bins 1 … n_bins of
    the differenced record, its taper w, ‖w‖, each bin's band)."""
    n_bins = (bands.n_diff - 1) // 2
    w = wh._taper(bands.n_diff)
    return n_bins, w, math.sqrt(float(w @ w)), _band_of(bands, np.arange(1, n_bins + 1, dtype=np.float64))


def covariances(
    bands: wh.Bands, fit: dict, combos: Sequence[np.ndarray], noise: dict | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """(exact, Whittle's) null covariance matrices of the scores u_i = Re Σ_k conj(combos[i]_k)·D_k / S_k, for
    per-bin regressor combinations (each a complex DFT over bins 1 … n_bins, normalised as in
    :func:`allanite.model._whittle.spectra`), S the noise of ``fit``, the record's noise that of ``noise`` (a fit
    with ``s`` and ``amounts``; default ``fit``'s); equal where the bins are independent and the two agree."""
    n_diff = bands.n_diff
    _, w, norm, band = _bin_grid(bands)
    s_bin = np.asarray(fit["s"], dtype=np.float64)[band]
    p = psd_grid(bands, fit if noise is None else noise)
    # Whittle's law per bin: Var u = ½·Σ |z|²/S (½·Σ |z|²·P/S² where the record's noise P is another fit's)
    s_eff = s_bin if noise is None else s_bin**2 / np.asarray(noise["s"], dtype=np.float64)[band]
    big_m = 2 * n_diff
    weight = np.full(p.size, 2.0)
    weight[0] = weight[-1] = 1.0
    weight *= p / big_m
    spectra_v = _padded_spectra(_time_vectors(combos, s_bin, w, norm), big_m)
    k = len(combos)
    exact, whittle = np.zeros((k, k)), np.zeros((k, k))
    for i in range(k):
        for j in range(i, k):
            exact[i, j] = exact[j, i] = float(np.sum(weight * (spectra_v[i] * np.conj(spectra_v[j])).real))
            whittle[i, j] = whittle[j, i] = 0.5 * float(np.sum((np.conj(combos[i]) * combos[j]).real / s_eff))
    return exact, whittle


def score_covariances(
    bands: wh.Bands, fit: dict, design: wh.Design, directions: np.ndarray, noise: dict | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`covariances` of the scores along ``directions`` (rows over ``design``'s regressors; ``bands`` must
    carry an :class:`EdgeSource`)."""
    return covariances(bands, fit, _combos(bands, design, directions), noise)


def _combos(bands: wh.Bands, design: wh.Design, directions: np.ndarray) -> list[np.ndarray]:
    """Per-bin DFTs of the combinations ``directions`` (rows: coefficients over ``design``'s regressors)."""
    source = bands.source
    assert isinstance(source, EdgeSource)
    n_bins, w, norm, band = _bin_grid(bands)
    z = {i: wh._dft(np.asarray(source.column(i), dtype=np.float64), w, n_bins) / norm for i in set(design.src)}
    out = []
    for v in np.atleast_2d(directions):
        comb = np.zeros(n_bins, dtype=np.complex128)
        for coef, src, mult in zip(v, design.src, design.mult, strict=True):
            if coef != 0.0:
                comb += coef * np.asarray(mult)[band] * z[src]
        out.append(comb)
    return out


def edge_factor(bands: wh.Bands, fit: dict, design: wh.Design, directions: np.ndarray) -> dict:
    """The factor by which a test's reference is widened for the record's edges, at the null model ``fit``: for the
    scores u along ``directions`` (rows over ``design``'s regressors), uᵀ·W⁻¹·u over uᵀ·E⁻¹·u — W Whittle's
    covariance, E the exact one (:func:`covariances`) —, at least 1 (1 where ``bands`` carries no
    :class:`EdgeSource`). One direction: the variance ratio E/W itself, whatever u. Several (the channel and its
    quadrature): the record's own score decides — a coupling in a direction the edge does not reach keeps its
    statistic, one along the edge's direction is weighed by the variance there. Returns ``{"factor",
    "ratios"}`` (the generalised eigenvalues of E against W: all 1 where Whittle's law holds) and the two
    matrices (``"exact"``, ``"whittle"``)."""
    if getattr(bands, "source", None) is None:
        return {"factor": 1.0, "ratios": []}
    d = np.atleast_2d(np.asarray(directions, dtype=np.float64))
    exact, whittle = covariances(bands, fit, _combos(bands, design, d))
    if not (np.all(np.isfinite(exact)) and np.all(np.linalg.eigvalsh(whittle) > 0)):
        return {"factor": 1.0, "ratios": [], "exact": exact, "whittle": whittle}  # no information along d
    ratios = [float(v) for v in eigh(exact, whittle, eigvals_only=True)]
    weights = 1.0 / np.asarray(fit["s"], dtype=np.float64)
    u = d @ wh.score(bands, design, weights)
    try:
        q_w, q_e = float(u @ np.linalg.solve(whittle, u)), float(u @ np.linalg.solve(exact, u))
        factor = q_w / q_e if q_e > 0 else max(ratios)
    except np.linalg.LinAlgError:  # an exact covariance without an inverse: the largest ratio, conservatively
        factor = max(ratios)
    if d.shape[0] == 1:
        factor = float(exact[0, 0] / whittle[0, 0])
    return {"factor": max(1.0, factor), "ratios": ratios, "exact": exact, "whittle": whittle}
