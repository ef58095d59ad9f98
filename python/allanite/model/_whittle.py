"""Whittle (frequency-domain) generalised least squares of a rate on regressors, against the record's own noise.

Shared by :mod:`allanite.model.channels`. The record and the regressors are differenced — every IEEE-952 term
then has a bounded spectrum (a random walk of rate becomes white, flicker's 1/f becomes ∝ f, a ramp becomes a
constant, which only the dropped bin 0 sees), so the periodogram has no leakage from f → 0 —, tapered at the
ends (a Tukey taper over :data:`TAPER` of the record at each end: the differenced white noise's two end values
would otherwise leak a flat floor, the same at every bin, into the lowest bins, where the random walk's level
is read; what the taper leaves of it is coherent across those bins, and the channel tests widen their references
for it: :mod:`allanite.model._edge`) and transformed (rfft; bin 0 and the Nyquist bin are left out). Bins are
pooled into bands about 1/:data:`BAND_DIV` of their frequency wide (single bins at the bottom); per band the sums
of |D|², Z̄·D and Z̄·Zᵀ are the sufficient statistics of the Whittle likelihood when the noise PSD is constant
across the band:

    ℓ(c, S) = −Σ_b [ m_b·ln S_b + R_b(c)/S_b ],   R_b(c) = Σ_{k∈b} |D_k − Z_k·c|²   (m_b bins in band b).

The noise PSD S of the differenced record: a band of ≥ :data:`OWN_BINS` bins has its own level (profiled out:
S_b = R_b/m_b, a free level per band — a filter's roll-off, a line, anything); below, where bands are a few bins
wide, the differenced IEEE-952 terms — Q: s⁴, N: s², B: s, K: 1 (s = 2·sin(πf/f_s); exact for the simulator's
Kasdin–Walter flicker) — and first-order Gauss–Markov terms (s²·(1 − φ)²/|1 − φe^{−iω}|², corners two per
octave from :data:`GM_FLOOR_BINS` bins up), non-negative amounts fitted by Whittle's likelihood (iteratively
reweighted NNLS). Each of these spectra is non-decreasing in f, so a channel's swing at the lowest frequencies
cannot be taken into the noise: it stands above the level the higher bins set. The GM corners start at
:data:`GM_FLOOR_BINS` bins so that the lowest bins' level is set by many bins (K, B), not by themselves.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from scipy import fft as sfft
from scipy.optimize import nnls as scipy_nnls
from scipy.signal.windows import tukey

from .. import _core
from . import _rfft
from ._nnls import raw_solver
from ._recent import Small

__all__ = [
    "Bands",
    "spectra",
    "fit_noise",
    "joint_fit",
    "nested_fit",
    "Design",
    "cross",
    "score",
    "band_info",
    "loglik",
    "noise_dof",
    "residual_power",
    "usable_length",
    "BAND_DIV",
    "OWN_BINS",
]

#: Taper: this fraction of the differenced record at each end (Tukey).
TAPER = 0.01
#: Bands are ≈ f/BAND_DIV wide (single bins below BAND_DIV).
BAND_DIV = 16
#: Bands of at least this many bins carry their own noise level; narrower ones take the parametric model's.
OWN_BINS = 32
#: Lowest Gauss–Markov corner of the parametric model, in bins.
GM_FLOOR_BINS = 32
#: Iterations of the alternating fit (noise ↔ coefficients) and of the noise model's reweighting.
MAX_ITER = 60


def band_starts(n_bins: int) -> np.ndarray:
    """First bin (1-based frequency index) of each band over bins 1 … n_bins."""
    starts = [1]
    while True:
        e = starts[-1] + max(1, starts[-1] // BAND_DIV)
        if e > n_bins:
            return np.asarray(starts, dtype=np.int64)
        starts.append(e)


@dataclass
class Bands:
    """Band sums of one record and its regressors (see the module docstring); ``m`` bins per band, ``f`` the
    bands' mean frequency (Hz), ``q`` Σ|D|², ``g`` Σ Z̄·D (nb, p), ``G`` Σ Z̄·Zᵀ (nb, p, p), ``basis`` the
    parametric noise shapes averaged over the bins of the parametric bands (n_par, k), ``names`` their names."""

    m: np.ndarray
    f: np.ndarray
    q: np.ndarray
    g: np.ndarray
    G: np.ndarray
    par: np.ndarray
    basis: np.ndarray
    names: tuple
    fs: float
    n_diff: int
    source: object | None = None
    #: a null draw's bands (:func:`allanite.model._coupling._null_bands`): their noise fits in the Rust core
    #: (:data:`COMPILED`, the same loop, the numbers to rounding); the record's own fits stay SciPy's, bit for bit
    compiled: bool = False

    @property
    def own(self) -> np.ndarray:
        return ~self.par


def _taper(n: int) -> np.ndarray:
    return tukey(n, min(1.0, 2.0 * TAPER)) if n > 8 else np.ones(n)


def _dft(x: np.ndarray, w: np.ndarray, n_bins: int) -> np.ndarray:
    d = np.diff(x)
    d = np.multiply(d, w, out=d) if d.dtype == np.float64 else d * w  # tapered in place: one copy, not two
    return _rfft.rfft(d)[1 : n_bins + 1]  # remembered: refine transforms the same samples again


def _basis(k: np.ndarray, n_diff: int, fs: float) -> tuple[np.ndarray, tuple]:
    """Parametric noise shapes of the differenced record at bins ``k``: Q, N, B, K, then GM corners."""
    omega = 2.0 * np.pi * k / n_diff
    s = 2.0 * np.sin(omega / 2.0)
    cols, names = [s**4, s**2, s, np.ones_like(s)], ["Q", "N", "B", "K"]
    top = float(k.max()) if k.size else 1.0
    corner = float(GM_FLOOR_BINS)
    while corner < top and corner < 0.45 * n_diff:
        phi = math.exp(-2.0 * math.pi * corner / n_diff)
        cols.append(s**2 * (1.0 - phi) ** 2 / (1.0 + phi**2 - 2.0 * phi * np.cos(omega)))
        names.append(f"GM@{corner * fs / n_diff:.4g}Hz")
        corner *= math.sqrt(2.0)
    return np.column_stack(cols), tuple(names)


def usable_length(n: int) -> int:
    """The longest prefix (samples) whose differences have a fast FFT length (5-smooth): pocketfft on 999 999
    points takes 4× as long as on 1 000 000. What is dropped at the end is up to 2.3 % of ``n`` above 10⁶ samples
    (3 456 000, 40 Hz × 24 h, keeps 3 375 001), 2.8 % above 10⁵, 6.3 % above 10³ (995 329 of 10⁶ kept)."""
    m = n - 1
    while m > 1 and sfft.next_fast_len(m, real=True) != m:
        m -= 1
    return m + 1


def spectra(y: np.ndarray, regressors: Iterable[np.ndarray], fs: float, parity: int | None = None) -> Bands:
    """Band sums of the differenced, tapered record ``y`` and ``regressors`` (each the record's length; an
    iterator is taken one regressor at a time, each let go once transformed); with ``parity`` 0 or 1 over the
    even or the odd bins only (a held-out split across frequency)."""
    n_diff = y.size - 1
    n_bins = (n_diff - 1) // 2  # strictly between 0 and the Nyquist frequency
    w = _taper(n_diff)
    norm = math.sqrt(float(w @ w))
    starts = band_starts(n_bins)
    k_all = np.arange(1, n_bins + 1, dtype=np.int64)
    band_of = np.searchsorted(starts, k_all, side="right") - 1
    sel = slice(None) if parity is None else (k_all % 2 == parity)
    k_all, band_of = k_all[sel], band_of[sel]
    idx = np.flatnonzero(np.diff(band_of, prepend=-1))
    m = np.diff(np.append(idx, k_all.size))
    f = np.add.reduceat(k_all.astype(np.float64), idx) / m * fs / n_diff
    # the band's width in bins of the whole spectrum decides its noise model (a split keeps the full record's)
    par = np.diff(np.append(starts, n_bins + 1))[band_of[idx]] < OWN_BINS
    # the parametric bands are the lowest ones: a last band cut short by the Nyquist bin is narrow too, yet above
    # bands that carry their own level (n = 3999: it indexed past the parametric bins' shapes)
    par = np.logical_and.accumulate(par)
    n_par_bins = int(m[par].sum())
    k_par = k_all[:n_par_bins].astype(np.float64)
    del k_all, band_of  # the bins' numbers and bands (half the record's length each): not held beside the transforms
    d = _dft(y, w, n_bins)[sel] / norm
    zs = [_dft(np.asarray(r, dtype=np.float64), w, n_bins)[sel] / norm for r in regressors]
    p = len(zs)
    q = np.add.reduceat(d.real**2 + d.imag**2, idx)
    g = np.zeros((idx.size, p), dtype=np.complex128)
    big = np.zeros((idx.size, p, p), dtype=np.complex128)
    for i, zi in enumerate(zs):
        zc = np.conj(zi)
        g[:, i] = np.add.reduceat(zc * d, idx)
        for j in range(i, p):
            big[:, i, j] = np.add.reduceat(zc * zs[j], idx)
            big[:, j, i] = np.conj(big[:, i, j])
    shapes, names = _basis(k_par, n_diff, fs)
    basis = np.add.reduceat(shapes, idx[par], axis=0) / m[par][:, None] if n_par_bins else np.zeros((0, 4))
    return Bands(m, f, q, g, big, par, basis, names, float(fs), n_diff)


#: The noise fit's loop in the Rust core (``allanite._core.whittle_noise``), or None where the core lacks it.
COMPILED = getattr(_core, "whittle_noise", None)
#: Relative change of the noise level in every band below which the noise fit's reweighting stops.
NOISE_RTOL = 1e-6

#: Noise fits by their inputs, within a refine: every cold-started :func:`joint_fit` (its coefficients 0) refits,
#: at its first step, the noise of the record's own power — the null model's, bit for bit —, and the coupling's
#: bootstrap does so three times in each of its draws: 60 % of a short record's noise fits were repeats.
_FITS = Small(512)


def fit_noise(
    power: np.ndarray, m: np.ndarray, basis: np.ndarray, start: np.ndarray | None = None, compiled: bool = False
):
    """Whittle fit of non-negative amounts of ``basis`` to band-mean powers ``power`` (m bins each): iteratively
    reweighted NNLS (weights m/S², the score equations of Σ m(ln S + P/S)). Returns (amounts, S), read-only
    (within a refine the same inputs' fit is found again, not repeated). ``compiled``: the loop in the Rust core
    where it has it (:data:`COMPILED`; its own Lawson–Hanson NNLS: the numbers to rounding, not SciPy's bits)."""
    key = Small.key(power, m, basis, start, compiled)
    hit = _FITS.get(key)
    if hit is not None:
        return hit
    coef, s_cur = _fit_noise(power, m, basis, start, compiled)
    coef.setflags(write=False)
    s_cur.setflags(write=False)
    return _FITS.put(key, (coef, s_cur))


def _lawson_hanson(a: np.ndarray, b: np.ndarray, maxiter: int) -> np.ndarray:
    """``scipy.optimize.nnls(a, b, maxiter=maxiter)[0]``: the same routine and numbers, without the wrapper's checks
    (:func:`allanite.model._nnls.raw_solver`: a quarter of a noise fit's time, and a short record's refine makes
    ≈ 2·10⁴ of these calls); the public function, with its error, where ``a`` or ``b`` is not finite."""
    if not math.isfinite(float(a.sum()) + float(b.sum())):
        return scipy_nnls(a, b, maxiter=maxiter)[0]
    return raw_solver()(a, b, maxiter)


def _fit_noise(power: np.ndarray, m: np.ndarray, basis: np.ndarray, start: np.ndarray | None, compiled: bool = False):
    scale = np.maximum(basis.max(axis=0), 1e-300)
    a_s = basis / scale
    if start is None:
        # a first pass weighted by a smoothed power (single bins are exponential: too ragged to weigh by)
        k = min(7, power.size)
        smooth = np.convolve(power, np.ones(k) / k, mode="same") + 1e-300
        s_cur = smooth
    else:
        s_cur = np.maximum(a_s @ (start * scale), 1e-300)
    coef = np.zeros(basis.shape[1])
    root_m, maxiter = np.sqrt(m), 50 * basis.shape[1]
    if compiled and COMPILED is not None:
        coef, s_cur = COMPILED(np.ascontiguousarray(a_s), power, root_m, s_cur, MAX_ITER, NOISE_RTOL)
        return coef / scale, s_cur
    for _ in range(MAX_ITER):
        sw = root_m / s_cur
        coef_new = _lawson_hanson(a_s * sw[:, None], power * sw, maxiter)
        s_new = a_s @ coef_new
        s_new = np.maximum(s_new, 1e-12 * max(float(s_new.max()), 1e-300))
        done = np.max(np.abs(s_new / s_cur - 1.0)) < NOISE_RTOL
        coef, s_cur = coef_new, s_new
        if done:
            break
    return coef / scale, s_cur


@dataclass
class Design:
    """Regressors in band space: each a source column of :class:`Bands` (``src``) times a complex multiplier
    per band (``mult``, (nb,) — 1 for a plain regressor; a filter's response for a lagged one)."""

    src: list
    mult: list

    def __len__(self) -> int:
        return len(self.src)

    def plus(self, src: int, mult: np.ndarray) -> Design:
        return Design(self.src + [src], self.mult + [mult])

    def gram(self, bands: Bands, weight: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(Σ_b Re(μ̄_i μ_j G_b[i,j])·w_b, Σ_b Re(μ̄_i g_b[i])·w_b): normal equations with band weights w."""
        return cross(bands, self, self, weight), score(bands, self, weight)


def cross(bands: Bands, a: Design, b: Design, weight: np.ndarray) -> np.ndarray:
    """Σ_b Re(μ̄_i·ν_j·G_b[src_i, src_j])·w_b for the regressors i of ``a`` and j of ``b``."""
    out = np.zeros((len(a), len(b)))
    for i in range(len(a)):
        mi = np.conj(a.mult[i]) * weight
        for j in range(len(b)):
            out[i, j] = float(np.sum((mi * b.mult[j] * bands.G[:, a.src[i], b.src[j]]).real))
    return out


def score(bands: Bands, a: Design, weight: np.ndarray) -> np.ndarray:
    """Σ_b Re(μ̄_i·g_b[src_i])·w_b for the regressors of ``a``."""
    return np.array([float(np.sum((np.conj(m) * bands.g[:, k]).real * weight)) for k, m in zip(a.src, a.mult)])


def band_info(bands: Bands, design: Design, v: np.ndarray) -> np.ndarray:
    """Per band, the Fisher information ×S_b along the combination ``v`` of the regressors: 2·Re Σ v_i v_j
    μ̄_i μ_j G_b[src_i, src_j] (non-negative; its sum over bands weighted by 1/S_b is vᵀ·I·v)."""
    d = np.zeros(bands.m.size)
    for i in range(len(design)):
        for j in range(len(design)):
            d += (
                2.0
                * v[i]
                * v[j]
                * (np.conj(design.mult[i]) * design.mult[j] * bands.G[:, design.src[i], design.src[j]]).real
            )
    return np.maximum(d, 0.0)


def residual_power(bands: Bands, design: Design, c: np.ndarray) -> np.ndarray:
    """R_b(c) = Σ_{k∈b} |D_k − Z_k·c|² per band."""
    r = bands.q.copy()
    for i in range(len(design.src)):
        mi = np.conj(design.mult[i])
        r -= 2.0 * c[i] * (mi * bands.g[:, design.src[i]]).real
        for j in range(len(design.src)):
            r += c[i] * c[j] * (mi * design.mult[j] * bands.G[:, design.src[i], design.src[j]]).real
    return np.maximum(r, 1e-300)


def noise_psd(bands: Bands, resid: np.ndarray, start=None):
    """The noise level S_b of every band given residual powers: parametric below (fitted to ``resid``); above,
    each band's own level *before* any coupling is removed (q_b/m_b: fixed, see the module docstring)."""
    s = bands.q / bands.m
    amounts = None
    if bands.par.any():
        par_power = resid[bands.par] / bands.m[bands.par]
        amounts, s_par = fit_noise(par_power, bands.m[bands.par], bands.basis, start, bands.compiled)
        s = s.copy()
        s[bands.par] = s_par
    return s, amounts


def loglik(bands: Bands, resid: np.ndarray, s: np.ndarray) -> float:
    """Whittle log-likelihood Σ −(m ln S + R/S) (constant terms dropped)."""
    return float(-np.sum(bands.m * np.log(s) + resid / s))


def joint_fit(bands: Bands, design: Design, fixed_s: np.ndarray | None = None, start: dict | None = None) -> dict:
    """Coefficients and noise jointly (alternating: GLS of the coefficients with the noise fixed, the noise
    refitted on the residual — the noise never sees the channel's share). With ``fixed_s`` the noise stays put.

    The alternation is not monotone: the noise refit (IRLS-NNLS, warm-started) is not a maximiser of the Whittle
    likelihood given the residual, and on a 1 kHz × 10⁶ record it lowered ℓ by more than the GLS step had gained.
    The best (coefficients, noise) pair visited — after each GLS step and after each noise refit — is returned:
    each is a point of the model. ``start``, a fit of
    the first regressors of ``design`` (a nested smaller model), is the alternation's start (its coefficients, the
    new ones at 0, its noise): its first GLS step is taken at the smaller model's noise, so the result's ℓ is at
    least the smaller model's — a nested likelihood ratio ≥ 0 (:func:`nested_fit`).

    Returns ``c``, ``cov`` ((2·Σ Re Z̄Zᵀ/S)⁻¹, the inverse Fisher information), ``s``, ``loglik``, ``amounts``
    (the parametric noise shapes' amounts, or None)."""
    p = len(design.src)
    c = np.zeros(p)
    amounts = None
    best: dict | None = None
    if start is not None:
        c[: start["c"].size] = start["c"]
        amounts = start["amounts"]
        best = {k: start[k] for k in ("s", "loglik", "amounts", "resid")} | {"c": c.copy()}
    prev = -math.inf
    for it in range(MAX_ITER):
        resid = residual_power(bands, design, c)
        if start is not None and it == 0:
            s, ll = start["s"], start["loglik"]  # the first GLS step at the smaller model's noise: ℓ can only rise
        else:
            s, amounts = (fixed_s, amounts) if fixed_s is not None else noise_psd(bands, resid, amounts)
            ll = loglik(bands, resid, s)
        if best is None or ll > best["loglik"]:
            best = {"c": c.copy(), "s": s, "loglik": ll, "amounts": amounts, "resid": resid}
        if p == 0 or abs(ll - prev) <= 1e-10 * max(1.0, abs(ll)):
            break
        prev = ll
        info, score = design.gram(bands, 1.0 / s)
        c = np.linalg.solve(info, score)
        resid = residual_power(bands, design, c)  # the GLS half-step, (new c, this noise): ℓ rose
        ll = loglik(bands, resid, s)
        if ll > best["loglik"]:
            best = {"c": c.copy(), "s": s, "loglik": ll, "amounts": amounts, "resid": resid}
        if fixed_s is not None:
            break
    assert best is not None
    s = best["s"]
    cov = np.linalg.inv(2.0 * design.gram(bands, 1.0 / s)[0]) if p else np.zeros((0, 0))
    return best | {"cov": cov}


def nested_fit(bands: Bands, design: Design, small: dict) -> dict:
    """:func:`joint_fit` of ``design`` whose first regressors are the model ``small`` was fitted with: from a cold
    start as always, and where that ends below ``small``'s likelihood (the alternation is not monotone) from
    ``small`` itself — the better of the two, never below ``small``."""
    big = joint_fit(bands, design)
    if big["loglik"] < small["loglik"]:
        warm = joint_fit(bands, design, start=small)
        big = warm if warm["loglik"] > big["loglik"] else big
    return big


def noise_dof(bands: Bands, fit: dict, direction: np.ndarray) -> float:
    """Effective degrees of freedom of the information Σ_b d_b/S_b along ``direction`` (d_b ≥ 0 per band): the
    noise levels it is weighed by are estimates — the parametric bands' from the Whittle fit of the shapes
    (covariance (Σ m·AᵀA/S²)⁻¹ over the shapes in use), the own bands' each from its m_b bins (relative
    variance 1/m_b). ν = 2/Var(δI/I) (Satterthwaite: a χ²_ν/ν has relative variance 2/ν)."""
    s = fit["s"]
    info = float(np.sum(direction / s))
    if not info > 0:
        return math.inf
    u_own = np.where(bands.own, direction / s / info, 0.0)
    var = float(np.sum(u_own**2 / bands.m))
    if bands.par.any() and fit["amounts"] is not None:
        # every shape, not only those the NNLS kept: which ones are in use is itself decided by the data
        # (with the kept ones only, 0.6 % of 2000 null records crossed a 0.375 % threshold; with all, 0.25 %)
        a = bands.basis
        sp = s[bands.par]
        if a.shape[1]:
            fisher = (a * (bands.m[bands.par] / sp**2)[:, None]).T @ a
            u = (direction[bands.par] / sp**2) @ a / info
            var += float(u @ np.linalg.pinv(fisher) @ u)
    return 2.0 / var if var > 0 else math.inf
