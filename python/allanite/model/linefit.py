"""Least squares at a lattice of frequencies: the numerics behind :mod:`allanite.model.lines`.

A family of spectral lines sits on a lattice: line i at the normalised frequency ν_i = C_i · g (cycles per
sample), g the family's generators (one: harmonics k·f0; two: sidebands k·f1 + s·f2) and C_i a row of
integers. Everything here is O(N) in the samples per distinct second coefficient s, whatever the number of
lines:

- :func:`dtft` — Σ_n y_n e^{−i2πν_i n} at every line at once. The samples, heterodyned by e^{−i2πsν2 n}, are
  *folded* at ν1: spread onto M phase bins of u_n = frac(ν1 n) by linear interpolation (two ``bincount``),
  one FFT of the bins, and the interpolation kernel's transform sinc²(k/M) divided out. Exact up to aliases
  of weight ≈ (k/M)² (M ≥ 256·max k); agrees with the direct sum to ~1e-10 on 10⁶ samples.
- :func:`solve` — the amplitudes (a_i, b_i) of a_i cos ω_i n + b_i sin ω_i n by least squares over any set of
  sample indices (the held-in blocks of a held-out test too): the Gram matrix in closed form (Dirichlet sums
  over the index runs), so a line's negative-frequency image and its neighbours are accounted for exactly.
- :func:`evaluate` — the fitted component at any sample indices: per s, the waveform Σ_k c_k e^{i2πku} on
  M phase points (one inverse FFT, the kernel pre-compensated) interpolated at frac(ν1 n).
- :func:`refine_generators` — the generators by Gauss–Newton on the lines' own frequency offsets: each
  line's offset maximises the power of its DTFTs over Q contiguous pieces re-phased (a zoom around the
  line), and the generators are their weighted least-squares combination (weights: the inverse Cramér–Rao
  variances, A²N³/(12·S₁f_s) per line — Kay's bound var(ω̂) = 24σ²/(A²N³) for a real sinusoid in white
  noise σ² = S₁f_s/2 locally).

The two passes over the samples — the folding's gridding and the waveform's interpolation — run in the Rust
core where it has them (``allanite._core.phase_bins``, ``add_waveform``: one pass each instead of NumPy's
eight, the same operations in the same order, so the same numbers; ``tests/test_refine_irls.py`` holds the
two paths equal); NumPy's path stays the reference. A two-generator family's phasors e^{i2π|s|ν2 n} are then
made sample by sample in those passes from two short tables (``lattice_bins``, ``add_lattice_waveform``:
:class:`_Lattice`) instead of being formed as 16 bytes a sample per family and part.
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import NamedTuple

import numpy as np

from .. import _core
from ._recent import Recent

__all__ = ["runs", "dirichlet", "dtft", "solve", "evaluate", "refine_generators", "frequency_sd"]

#: Phasors e^{i2πνn} are products e^{i2πν·B·⌊n/B⌋}·e^{i2πν·(n mod B)} of two exact short tables, B = _BLOCK
#: (error ≈ 1e-15, one complex product per sample).
_BLOCK = 1024
#: The Rust core's gridding and waveform passes, or None where the core lacks them (then NumPy's, below).
_BINS = getattr(_core, "phase_bins", None)
_WAVE = getattr(_core, "add_waveform", None)
#: The core's passes with the second generator's phasors made per sample (:class:`_Lattice`), or None where it lacks
#: them (then :func:`_phasor`'s arrays, to ``_BINS`` and ``_WAVE`` or NumPy's).
_LBINS = getattr(_core, "lattice_bins", None)
_LWAVE = getattr(_core, "add_lattice_waveform", None)


def runs(idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Starts and lengths of the runs of consecutive integers in sorted ``idx``."""
    idx = np.asarray(idx, dtype=np.int64)
    if idx.size == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    brk = np.flatnonzero(np.diff(idx) != 1) + 1
    starts = np.concatenate([[0], brk])
    ends = np.concatenate([brk, [idx.size]])
    return idx[starts], ends - starts


def dirichlet(omega: np.ndarray, starts: np.ndarray, lengths: np.ndarray, centre: float | None = None) -> np.ndarray:
    """S(ω) = Σ_runs Σ_{n = a}^{a + m − 1} e^{iωn} = Σ_runs e^{iωc}·D(ω), c = a + (m − 1)/2 and
    D(ω) = sin(mω/2)/sin(ω/2); with ``centre``, Σ (n − centre)·e^{iωn} = Σ_runs e^{iωc}·((c − centre)·D − i·D′)."""
    omega = np.asarray(omega, dtype=np.float64)
    # ω is 2π-periodic: wrap to (−π, π] so that sin(ω/2) vanishes only at ω ≡ 0
    w = omega - 2 * np.pi * np.round(omega / (2 * np.pi))
    out = np.zeros(w.shape, dtype=np.complex128)
    half = np.sin(w / 2)
    small = np.abs(half) < 1e-6
    safe = np.where(small, 1.0, half)
    for a, m in zip(starts, lengths):
        c = a + (m - 1) / 2.0
        d = np.where(small, m - m * (m * m - 1.0) * w * w / 24.0, np.sin(m * w / 2) / safe)
        phase = np.exp(1j * _wrap(w * c))
        if centre is None:
            out += phase * d
            continue
        dp = np.where(
            small,
            -m * (m * m - 1.0) * w / 12.0,
            (0.5 * m * np.cos(m * w / 2) * half - 0.5 * np.sin(m * w / 2) * np.cos(w / 2)) / safe**2,
        )
        out += phase * ((c - centre) * d - 1j * dp)
    return out


def _wrap(x: np.ndarray) -> np.ndarray:
    """x modulo 2π in (−π, π] (keeps phases of large n accurate)."""
    return x - 2 * np.pi * np.round(x / (2 * np.pi))


def _phasor(nu: float, idx: np.ndarray) -> np.ndarray:
    """e^{i2πν n} at the indices (read-only): per sample, the product of its block's phasor and its offset's within
    the block (:func:`_tables`) — one complex product per sample. The last few are remembered
    (:data:`_PHASORS`): a family's sidebands are fitted on one half of a record and evaluated on the other,
    family after family, at the same spacing ν. (Where the Rust core has the lattice passes, :func:`_groups` hands
    them the tables instead: no phasor is formed.)"""
    got = _PHASORS.get(idx, (nu,))
    if got is not None:
        return got
    if idx.size == 0:
        out = np.ones(0, dtype=np.complex128)
    else:
        blocks, offsets, k0 = _tables(nu, idx)
        lo, hi = int(idx.min()), int(idx.max())
        if hi - lo + 1 == idx.size and idx[0] == lo:  # one run: the outer product, sliced
            out = np.multiply.outer(blocks, offsets).ravel()[lo - k0 * _BLOCK : hi - k0 * _BLOCK + 1]
        else:
            out = blocks[idx // _BLOCK - k0] * offsets[idx % _BLOCK]
    out.flags.writeable = False
    return _PHASORS.put(idx, (nu,), out)


def _tables(nu: float, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
    """(e^{i2πν·B·k} for the blocks k = k0 … ⌊max idx/B⌋, e^{i2πν·j} for j = 0 … B − 1, k0 = ⌊min idx/B⌋),
    B = :data:`_BLOCK`, each from ``np.exp``: e^{i2πνn} is the product of n's block's and its offset's (idx not
    empty)."""
    lo, hi = int(idx.min()), int(idx.max())
    k0 = lo // _BLOCK
    blocks = np.exp(2j * np.pi * _frac(np.arange(k0, hi // _BLOCK + 1, dtype=np.int64) * _BLOCK * nu))
    offsets = np.exp(2j * np.pi * _frac(np.arange(_BLOCK) * nu))
    return blocks, offsets, k0


class _Lattice(NamedTuple):
    """The phasors e^{i2πaνn} at ``idx`` as the Rust core's lattice passes take them (``allanite._core.lattice_bins``,
    ``add_lattice_waveform``): :func:`_tables`' two tables (complex as interleaved float64), k0 and the power a,
    conjugated when ``conj`` — made there sample by sample, each product as NumPy's on x86-64 (a fused multiply-add:
    the numbers of :func:`_phasor` and :func:`_groups`' powers bit for bit there, ``tests/test_refine_irls.py``), with
    no array of n phasors formed (16 bytes a sample, and its fresh memory, per family and part)."""

    idx: np.ndarray
    blocks: np.ndarray
    offsets: np.ndarray
    k0: int
    power: int
    conj: bool = False

    def args(self) -> tuple:
        return self.idx, self.blocks, self.offsets, self.k0, self.power, self.conj


def _conj(ph):
    """The conjugate phasors: of an array, or a :class:`_Lattice` flagged to conjugate."""
    return ph._replace(conj=not ph.conj) if isinstance(ph, _Lattice) else np.conj(ph)


def _unit_phase(idx: np.ndarray, nu: float) -> np.ndarray:
    """frac(ν·n) at the indices, in [0, 1): the same numbers as ``np.mod(idx * nu, 1.0)``, faster where ν·n ≥ 0.
    Read-only, the last few remembered by the indices' content and ν (:data:`_PHASES`)."""
    got = _PHASES.get(idx, (float(nu),))
    if got is not None:
        return got
    x = idx * nu
    if nu >= 0 and (idx.size == 0 or idx.min() >= 0):
        # x ≥ 0: its fractional part is x − ⌊x⌋ exactly; np.modf's is the same numbers in one pass (4× faster than
        # floor and subtract), where ν > 0 (ν = −0.0 would give −0.0 for 0)
        out = np.modf(x)[0] if nu > 0 else _frac(x)
    else:
        out = np.mod(x, 1.0)
    out.flags.writeable = False
    return _PHASES.put(idx, (float(nu),), out)


def _frac(x: np.ndarray) -> np.ndarray:
    """x − ⌊x⌋ (= x mod 1, exactly, for x ≥ 0; one pass fewer than ``np.mod``)."""
    return x - np.floor(x)


#: Phasors remembered by :func:`_phasor`: the last four, of records up to 4·10⁶ samples (16 bytes per sample each).
_PHASORS = Recent(4, 4_000_000)
#: Unit phases remembered by :func:`_unit_phase` (8 bytes per sample each): a family's fit, its evaluation and its
#: refits on the held-out parts take the same indices' phases at the same fundamental (33 calls, 16 distinct, in one
#: refine of the line-family sensor of ``tests/sensors.py``; the last two kept find the 16 repeats as four did, at
#: half the memory).
_PHASES = Recent(2, 4_000_000)


def _grid(kmax: int) -> int:
    """Phase bins for harmonics up to ``kmax``: a power of two ≥ 256·kmax (≥ 4096), so that the aliases of
    the linear interpolation weigh ≤ (k/M)² ≤ 1.5e-5."""
    return int(2 ** max(12, math.ceil(math.log2(256 * max(1, kmax)))))


def _oriented(gens: np.ndarray, coefs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two generators put so that the second has the fewer distinct coefficients (one fold per distinct value:
    a carrier with 60 sidebands is one fold at the spacing, not 60 at the carrier); the lines keep their order."""
    if gens.size == 2 and np.unique(coefs[:, 0]).size < np.unique(coefs[:, 1]).size:
        return gens[::-1].copy(), coefs[:, ::-1].copy()
    return gens, coefs


def _groups(coefs: np.ndarray, nu2: float, idx: np.ndarray, lattice: bool = False):
    """(s, rows, e^{i2π|s|ν2 n} or None for s = 0) for each distinct second coefficient s (0 for one-generator
    lattices; a negative s's phasor is the conjugate, taken by the caller where it needs it); the phasors as
    powers of one :func:`_phasor`, by increasing |s| (one complex product each) — or, with ``lattice`` (the core's
    lattice passes at hand, idx not empty), as a :class:`_Lattice` of power |s| each: the same numbers, made there."""
    s_all = coefs[:, 1] if coefs.shape[1] > 1 else np.zeros(coefs.shape[0], dtype=np.int64)
    present = set(np.unique(s_all).tolist())
    if 0 in present:
        yield 0, np.flatnonzero(s_all == 0), None
    top = max((abs(v) for v in present), default=0)
    if top and lattice and idx.size:
        blocks, offsets, k0 = _tables(nu2, idx)
        tables = (np.ascontiguousarray(idx, dtype=np.int64), blocks.view(np.float64), offsets.view(np.float64), k0)
        for a in range(1, top + 1):
            for s in (a, -a):
                if s in present:
                    yield s, np.flatnonzero(s_all == s), _Lattice(*tables, a)
        return
    base = _phasor(nu2, idx) if top else np.ones(0)
    cur = base
    for a in range(1, top + 1):
        cur = base if a == 1 else cur * base
        for s in (a, -a):
            if s in present:
                yield s, np.flatnonzero(s_all == s), cur


def _fold(z: np.ndarray, u: np.ndarray, m_bins: int, seg: np.ndarray | None, n_seg: int) -> np.ndarray:
    """Σ z_n e^{−i2πk u_n} for k = 0 … M − 1 (per segment: shape (n_seg, M)), by linear gridding + FFT."""
    parts = [z.real, z.imag] if np.iscomplexobj(z) else [z]
    return _binned_fft(_bins_of(parts, u, m_bins, seg, n_seg, {}), m_bins, n_seg)


def _bins_of(parts: list, u: np.ndarray, m_bins: int, seg: np.ndarray | None, n_seg: int, grids: dict, ph=None) -> list:
    """Each real part spread onto the phase bins of ``u`` (:func:`_binned` on :func:`_gridding`; in the Rust
    core where it has it, else the grid remembered in ``grids`` per grid size). With the phasors ``ph``, the
    parts are y·Re ph and y·(−Im ph) of the one series ``parts[0]`` (the core forms them sample by sample; a
    :class:`_Lattice` only where the core has its lattice passes)."""
    if _BINS is not None:
        f64 = np.float64
        parts = [np.ascontiguousarray(part, dtype=f64) for part in parts]
        seg_c = None if seg is None else np.ascontiguousarray(seg, dtype=np.int64)
        if isinstance(ph, _Lattice):
            assert _LBINS is not None  # a lattice is made only where the core has its passes
            return _LBINS(parts[0], np.ascontiguousarray(u, dtype=f64), m_bins, seg_c, n_seg, *ph.args())
        ph_f = None if ph is None else np.ascontiguousarray(ph, dtype=np.complex128).view(f64)
        return _BINS(parts, np.ascontiguousarray(u, dtype=f64), m_bins, seg_c, n_seg, ph_f)
    if ph is not None:
        parts = [parts[0] * ph.real, parts[0] * -ph.imag]
    if m_bins not in grids:
        grids[m_bins] = _gridding(u, m_bins, seg)
    return [_binned(part, grids[m_bins], m_bins * n_seg) for part in parts]


def _gridding(u: np.ndarray, m_bins: int, seg: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each sample's two phase bins (j, j + 1 mod M; each segment its own M bins) and the weight w of the second."""
    x = u * m_bins
    j = x.astype(np.int64)
    w = x - j
    j1 = j + 1
    j1[j1 >= m_bins] = 0
    if seg is not None:  # each segment its own M bins
        off = seg * m_bins
        j += off
        j1 += off
    return j, j1, w


def _binned(part: np.ndarray, grid, size: int) -> np.ndarray:
    """One real part spread onto the phase bins ``grid`` (linear interpolation: two ``bincount``)."""
    j, j1, w = grid
    hi = part * w
    return np.bincount(j, part - hi, minlength=size) + np.bincount(j1, hi, minlength=size)


def _binned_fft(out: list, m_bins: int, n_seg: int) -> np.ndarray:
    """The FFT of the bins (real, or real and imaginary parts), the kernel's transform divided out."""
    g = out[0] + 1j * out[1] if len(out) == 2 else out[0]
    return np.fft.fft(g.reshape(n_seg, m_bins), axis=1) / _kernel_transform(m_bins)


@lru_cache(maxsize=8)
def _kernel_transform(m_bins: int) -> np.ndarray:
    """sinc²(k/M) at the FFT's bins k (signed): the linear interpolation kernel's transform (read-only)."""
    k = np.arange(m_bins)
    ks = np.where(k > m_bins // 2, k - m_bins, k)
    out = np.sinc(ks / m_bins) ** 2
    out.flags.writeable = False
    return out


def dtft(y: np.ndarray, idx: np.ndarray, gens, coefs: np.ndarray, n_seg: int = 1) -> np.ndarray:
    """D_i = Σ_{n ∈ idx} y_n e^{−i2πν_i n}, ν_i = coefs_i · gens; with ``n_seg`` > 1, per contiguous piece of
    ``idx`` (shape (n_seg, lines)), else shape (lines,)."""
    gens, coefs = _oriented(
        np.atleast_1d(np.asarray(gens, dtype=np.float64)), np.atleast_2d(np.asarray(coefs, dtype=np.int64))
    )
    idx = np.asarray(idx, dtype=np.int64)
    y = np.asarray(y, dtype=np.float64)
    out = np.zeros((n_seg, coefs.shape[0]), dtype=np.complex128)
    seg = None if n_seg == 1 else np.minimum(np.arange(idx.size) * n_seg // max(1, idx.size), n_seg - 1)
    u = _unit_phase(idx, float(gens[0]))
    nu2 = float(gens[1]) if gens.size > 1 else 0.0
    grids: dict = {}  # the phase bins per grid size, for every second coefficient
    bins: dict = {}  # (|s|, grid size): the bins of y·cos θ and y·sin θ, shared by s and −s
    for s, rows, ph in _groups(coefs, nu2, idx, lattice=_BINS is not None and _LBINS is not None):
        k = coefs[rows, 0]
        m_bins = _grid(int(np.max(np.abs(k))))
        if s == 0:
            g = _binned_fft(_bins_of([y], u, m_bins, seg, n_seg, grids), m_bins, n_seg)
        else:
            # y·conj(e^{iθ}) part by part (a real times a complex scales each part: the complex product's
            # numbers); −s's phasor is s's conjugate: its imaginary part's bins are s's negated, exactly
            key = (abs(s), m_bins)
            if key not in bins:  # s's phasor (conjugated for a negative s: only where s itself is absent)
                bins[key] = (*_bins_of([y], u, m_bins, seg, n_seg, grids, ph if s > 0 else _conj(ph)), s)
            re, im, s_done = bins[key]
            g = _binned_fft([re, im if s == s_done else -im], m_bins, n_seg)
        out[:, rows] = g[:, np.mod(k, m_bins)]
    return out if n_seg > 1 else out[0]


def _omegas(gens, coefs) -> np.ndarray:
    return 2 * np.pi * (np.atleast_2d(coefs) @ np.atleast_1d(np.asarray(gens, dtype=np.float64)))


def solve(y: np.ndarray, idx: np.ndarray, gens, coefs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Least-squares (a_i, b_i) of c₀ + c₁·n + Σ_i a_i cos ω_i n + b_i sin ω_i n on the samples ``y`` at indices
    ``idx`` (a straight line is fitted with the lines — the record's mean and slope are not lines — exactly:
    its cross terms with the lines are Dirichlet sums too)."""
    idx = np.asarray(idx, dtype=np.int64)
    y = np.asarray(y, dtype=np.float64)
    centre = float(idx.mean())
    t = idx - centre
    yc = y - y.mean()
    d = dtft(yc, idx, gens, coefs)
    om = _omegas(gens, coefs)
    starts, lengths = runs(idx)
    s_minus = dirichlet(om[:, None] - om[None, :], starts, lengths)
    s_plus = dirichlet(om[:, None] + om[None, :], starts, lengths)
    s_one = dirichlet(om, starts, lengths)
    s_t = dirichlet(om, starts, lengths, centre)
    cc = 0.5 * (s_minus + s_plus).real
    ss = 0.5 * (s_minus - s_plus).real
    cs = 0.5 * (s_plus - s_minus).imag
    scale = max(1.0, float(np.max(np.abs(t))))  # the slope column in units of the half-span: conditioning
    nuis = np.array([[float(idx.size), float(t.sum()) / scale], [float(t.sum()) / scale, float(t @ t) / scale**2]])
    cross = np.vstack(
        [np.concatenate([s_one.real, s_one.imag]), np.concatenate([s_t.real, s_t.imag]) / scale]
    )  # (2, 2L): Σ 1·cos, Σ 1·sin; Σ t·cos, Σ t·sin
    gram = np.block([[nuis, cross], [cross.T, np.block([[cc, cs], [cs.T, ss]])]])
    rhs = np.concatenate([[float(yc.sum()), float(t @ yc) / scale], d.real, -d.imag])
    try:
        sol = np.linalg.solve(gram, rhs)
    except np.linalg.LinAlgError:
        sol = np.linalg.lstsq(gram, rhs, rcond=1e-12)[0]
    n_lines = om.size
    return sol[2 : 2 + n_lines], sol[2 + n_lines :]


def evaluate(idx: np.ndarray, gens, coefs: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Σ_i a_i cos ω_i n + b_i sin ω_i n at the sample indices ``idx``."""
    gens, coefs = _oriented(
        np.atleast_1d(np.asarray(gens, dtype=np.float64)), np.atleast_2d(np.asarray(coefs, dtype=np.int64))
    )
    idx = np.asarray(idx, dtype=np.int64)
    out = np.zeros(idx.size)
    u = _unit_phase(idx, float(gens[0]))
    nu2 = float(gens[1]) if gens.size > 1 else 0.0
    grids: dict = {}
    for s, rows, ph in _groups(coefs, nu2, idx, lattice=_WAVE is not None and _LWAVE is not None):
        ph = _conj(ph) if s < 0 else ph
        k = coefs[rows, 0]
        m_bins = _grid(int(np.max(np.abs(k))))
        spec = np.zeros(m_bins, dtype=np.complex128)
        # a cos θ + b sin θ = Re[(a − ib)e^{iθ}]; the linear interpolation's sinc² is divided out beforehand
        np.add.at(spec, np.mod(k, m_bins), (a[rows] - 1j * b[rows]) / np.sinc(k / m_bins) ** 2)
        wave = np.fft.ifft(spec) * m_bins
        wave = np.append(wave, wave[0])
        if isinstance(ph, _Lattice):  # the same sums and phasors in the Rust core, one pass
            assert _LWAVE is not None  # a lattice is made only where the core has its passes
            _LWAVE(out, np.ascontiguousarray(u, dtype=np.float64), wave.view(np.float64), *ph.args())
            continue
        if _WAVE is not None:  # the same sums in the Rust core, one pass
            _WAVE(out, u, wave.view(np.float64), None if ph is None else np.ascontiguousarray(ph).view(np.float64))
            continue
        if m_bins not in grids:  # each sample's phase bin and weights, once per grid size
            x = u * m_bins
            j = x.astype(np.int64)
            f = x - j
            grids[m_bins] = (j, j + 1, 1.0 - f, f)
        j, j1, g, f = grids[m_bins]
        if ph is None:  # the real part alone: a complex times a real scales both parts, each as a real product
            wr = wave.real
            out += wr[j] * g + wr[j1] * f
            continue
        val = wave[j] * g + wave[j1] * f
        out += (val * ph).real
    return out


def frequency_sd(amplitude: np.ndarray, s1: np.ndarray, fs: float, n: int) -> np.ndarray:
    """Cramér–Rao standard deviation of a line's frequency (Hz): (f_s/2π)·√(12·S₁f_s/(A²N³)) for a real
    sinusoid of amplitude A in locally white noise of one-sided PSD S₁ over N samples."""
    amp = np.maximum(np.asarray(amplitude, dtype=np.float64), 1e-300)
    return fs / (2 * np.pi) * np.sqrt(12.0 * np.asarray(s1) * fs / (amp**2 * float(n) ** 3))


def _zoom_offsets(d_seg: np.ndarray, centres: np.ndarray, span: float, points: int = 65) -> np.ndarray:
    """Per line, the offset δ (rad/sample) in (−span, span) maximising |Σ_q D_q e^{−iδ n̄_q}|² (a parabola
    through the best grid point and its neighbours)."""
    grid = np.linspace(-span, span, points)
    ph = np.exp(-1j * np.outer(grid, centres))  # (points, Q)
    power = np.abs(ph @ d_seg) ** 2  # (points, lines)
    j = np.clip(np.argmax(power, axis=0), 1, points - 2)
    cols = np.arange(power.shape[1])
    p0, p1, p2 = power[j - 1, cols], power[j, cols], power[j + 1, cols]
    den = p0 - 2 * p1 + p2
    frac = np.where(den < 0, 0.5 * (p0 - p2) / np.where(den < 0, den, -1.0), 0.0)
    return grid[j] + np.clip(frac, -1.0, 1.0) * (grid[1] - grid[0])


def refine_generators(
    y: np.ndarray,
    gens,
    coefs: np.ndarray,
    var_nu: np.ndarray,
    n_iter: int = 3,
    n_seg: int = 32,
) -> tuple[np.ndarray, np.ndarray]:
    """Generators refined by Gauss–Newton on the lines' frequency offsets; returns (gens, covariance).

    ``var_nu``: each line's frequency variance (cycles/sample)², the weights of the least-squares step
    (:func:`frequency_sd` / f_s, squared). A line whose offset lies beyond 4 of the offsets' robust σ (the
    median |z| scaled; at least 1) from the fitted lattice is left out of that step (a weak line's zoom may
    pick a noise peak; the weights from the PSD's amplitudes are themselves rough)."""
    gens = np.atleast_1d(np.asarray(gens, dtype=np.float64)).copy()
    coefs = np.atleast_2d(np.asarray(coefs, dtype=np.int64))
    n = y.size
    idx = np.arange(n, dtype=np.int64)
    centres = (np.arange(n_seg) + 0.5) * n / n_seg
    c = coefs[:, : gens.size].astype(np.float64)
    w = 1.0 / np.maximum(np.asarray(var_nu, dtype=np.float64), 1e-300)
    yd = y - y.mean()
    cov = np.full((gens.size, gens.size), np.nan)
    for _ in range(n_iter):
        d_seg = dtft(yd, idx, gens, coefs, n_seg=n_seg)
        # the zoom spans ± half a piece's resolution: the pieces' phases then advance by < π between pieces
        delta = _zoom_offsets(d_seg, centres, 0.9 * np.pi * n_seg / n) / (2 * np.pi)
        use = np.ones(coefs.shape[0], dtype=bool)
        for _k in range(3):
            cw = c[use] * w[use, None]
            info = c[use].T @ cw
            if np.linalg.matrix_rank(info) < gens.size:
                return gens, cov
            step = np.linalg.solve(info, cw.T @ delta[use])
            z = (delta - c @ step) * np.sqrt(w)
            scale = max(1.0, 1.4826 * float(np.median(np.abs(z[use]))))
            keep = np.abs(z) <= 4.0 * scale
            if np.array_equal(keep, use) or keep.sum() < gens.size + 1:
                break
            use = keep
        gens = gens + step
        cov = np.linalg.inv(info)
        if np.all(np.abs(step) <= 0.01 * np.sqrt(np.diag(cov))):
            break
    return gens, cov
