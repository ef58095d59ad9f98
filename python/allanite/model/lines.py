"""Every significant narrow line of a record's spectrum, and the families they form.

:func:`find_lines` — the lines of the Welch PSD (Blackman–Harris window, 50 % overlap): a bin stands out
when its power over the median of its neighbours exceeds the F quantile of a Welch average against that
median, Bonferroni-corrected over every bin searched. The neighbours are ±(5 … 4 + w) bins, w = k/2 clipped
to 4 … 32 (the window's main lobe, ±4 bins, is left out so that a line does not raise its own reference;
beyond it the window leaks ≤ −92 dB, so a line 10⁹ above the floor makes no false neighbours; a symmetric
window's median of a monotone 1/f or 1/f² slope is its value at the centre). Two passes: segments of
2^⌊log₂ N/8⌋ (≤ 2¹⁵) samples from its bin 36 up, and three segments of N/2 below, so that lines down to 18/T
(T the record) are searched, and the lowest bins of the short segments (steep floors, crowded neighbourhoods)
are searched at the long segments' finer resolution. Degrees of freedom: the Welch average's
2K/(1 + 2Σ(1 − m/K)ρ_m²) (Percival & Walden 1993, eq. 292b; ρ_m the window's overlap correlation), the
median's that times its neighbours' effective number (2w/(1 + 2Σρ_j²), ρ_j the correlation of bins j
apart) times 2/π (a sample median's efficiency); both times K_eff/K in a band where the segments' powers differ
(a noise on for part of the record: :mod:`._welch_spread`). Lines close together raise each other's reference, so the
search repeats with the lines found left out of every median (in mirror pairs, keeping it centred).

:func:`group_lines` — lines into families on a lattice: harmonics k·f0 (one generator) or sidebands
k·f1 + s·f2 (two), with aliases folded into [0, f_s/2]. Greedy: every seed (a strong line over h = 1 … 6,
differences of strong lines, a strong line as carrier with a difference as spacing) is grown by matching
lines within their tolerance and refitting the generators by weighted least squares; the family kept is the
one that explains most lines beyond what chance would match (lines × lattice points × window), needing at
least one line more than it has generators; two generators in a small ratio (p/q, q ≤ 4) are one (g1/q).
Harmonics reach order 4096 (folded: a waveform with a jump, sampled without an anti-alias filter, has lines at
every multiple of f_s/P, P its period in samples, and any fundamental whose orders reach far enough explains
them all); of the one-generator families that score alike, the one taking most lines at their own frequency
(below f_s/2, unfolded) is the fundamental, the higher of equals (a subharmonic takes the same lines).
A two-generator basis is reduced to the larger generator and the other modulo it (the sidebands' offset).
A line no family takes stays a ``"sinusoid"``.
"""

from __future__ import annotations

import hashlib
import math
from contextlib import contextmanager
from functools import lru_cache

import numpy as np
from scipy import signal
from scipy.stats import chi2 as chi2_dist
from scipy.stats import f as f_dist

from ._chunked import CHUNK, welch_detrended, window_overlap
from ._medians import median_by_sort, nanmedian_rows
from ._welch_spread import SegmentLevels

__all__ = ["find_lines", "line_spectrum", "remembering_spectra", "group_lines", "LOBE", "MAX_SEGMENT", "fold_frequency"]

#: Main-lobe half width of the Blackman–Harris window, bins (to its first null; −92 dB beyond).
LOBE = 4
#: Longest segment of the band-wide pass (samples).
MAX_SEGMENT = 2**15
#: Neighbours per side: w = k/2 clipped to this range (bins).
NEIGHBOURS = (4, 32)
WINDOW = "blackmanharris"
#: The band-wide pass starts at this bin; below it the long-segment pass searches (when the record allows).
SWITCH = 36
#: Seeds: the strongest lines tried as fundamentals (over h = 1 … SUBHARMONICS) and pairwise spacings.
SEEDS = 12
SUBHARMONICS = 6
#: The strongest lines tried as carriers of a sideband lattice (with a spacing of two of them).
CARRIERS = 6
#: Largest |s| of a sideband lattice (a sample-rate beat's sawtooth phase modulation spreads over the band).
MAX_SIDEBAND = 256
#: Largest harmonic order of a one-generator lattice: a waveform with a jump, sampled without an anti-alias
#: filter, has harmonics of every order folded into the band (a 2.3 Hz sawtooth at 400 Hz: lines to order ≈ 2000
#: stand above a moving average's noise nulls).
MAX_HARMONIC = 4096


def fold_frequency(nu: np.ndarray) -> np.ndarray:
    """A normalised frequency (cycles per sample) folded into [0, ½] (its alias as sampled)."""
    nu = np.asarray(nu, dtype=np.float64)
    return np.abs(nu - np.round(nu))


def _edof(win: np.ndarray, n: int, nper: int) -> tuple[float, float, int]:
    """Welch's equivalent degrees of freedom, the bins' correlation factor 1 + 2Σρ_j², and the segments (for the
    long pass's three segments, whose window is half the record, summed over chunks: :mod:`._chunked`)."""
    step = nper // 2
    k = (n - nper) // step + 1
    if 16 * nper > CHUNK and k <= 3:
        _ww, rho, corr = window_overlap(win, nper, 2 * LOBE - 1)
        rho = rho[: max(0, min(k, nper // step) - 1)]
    else:
        h = win / math.sqrt(float(win @ win))
        rho = [float(h[: nper - m * step] @ h[m * step :]) for m in range(1, min(k, nper // step))]
        # white noise's periodogram bins j apart correlate by |Σ h_t² e^{−i2πjt/n}|² (Σ h² = 1)
        corr = np.abs(np.fft.rfft(h * h)[1 : 2 * LOBE]) ** 2
    dof = 2.0 * k / (1.0 + 2.0 * sum((1 - (m + 1) / k) * r * r for m, r in enumerate(rho)))
    return dof, 1.0 + 2.0 * float(np.sum(corr)), k


@lru_cache(maxsize=16)
def _window_edof(nper: int, n: int) -> tuple:
    """The window (read-only) and :func:`_edof` of ``nper`` of ``n`` samples, kept for the process up to 2²⁰-sample
    segments (refine searches three records of one length: each pass's window and sums were made three times)."""
    win = signal.get_window(WINDOW, nper)
    win.flags.writeable = False
    return win, _edof(win, n, nper)


def _welch(x: np.ndarray, fs: float, win: np.ndarray, nper: int, mean: float = 0.0):
    """One-sided Welch PSD (unit²/Hz) of 50 %-overlapping segments, each with its least-squares line removed
    (as ``scipy.signal.welch(detrend="linear")``, without a least-squares solve per segment) of ``x − mean``; a few
    segments at a time, or one, so that the memory beyond ``x`` stays a chunk's or a segment's (:mod:`._chunked`);
    and per bin the factor on its dof where the segments' powers differ (:mod:`._welch_spread`)."""
    k = (x.size - nper) // (nper // 2) + 1
    levels = SegmentLevels()
    p = welch_detrended(x, win, nper, mean, each=levels if k >= 4 else None)  # the long pass's 3: none
    p *= 1.0 / (fs * float(win @ win)) / k
    p[1:-1] *= 2.0  # one-sided (the Nyquist bin of an even nper once)
    return np.arange(p.size) * fs / nper, p, levels.factor(p.size)


def _one_pass(x: np.ndarray, fs: float, nper: int, k_lo: int, k_hi: int, mean: float = 0.0) -> dict:
    """Welch PSD of one segment length up to the bins its search reaches, the bins k_lo ≤ k < k_hi it searches
    (grouped by their neighbourhood w) and, unmasked, the noise level under each (:func:`_noise`)."""
    win, (dof, kappa, k_seg) = (_window_edof if nper <= 2**20 else _window_edof.__wrapped__)(nper, x.size)
    f, p, spread = _welch(x, fs, win, nper, mean)
    ks_all = np.arange(p.size)
    width = np.clip(ks_all // 2, *NEIGHBOURS)
    k_hi = min(k_hi, p.size - 1 - LOBE - NEIGHBOURS[0])
    groups = []
    for w in range(NEIGHBOURS[0], NEIGHBOURS[1] + 1):
        ks = ks_all[(width == w) & (ks_all >= max(k_lo, LOBE + w + 1)) & (ks_all < k_hi)]
        ks = ks[ks + LOBE + w < p.size - 1]
        if ks.size:
            groups.append((w, ks))
    # the bins a searched bin's neighbourhood can reach (±(LOBE + 2w) with its mirror, the line's width) and one
    # unsearched bin beyond: the long pass searches its lowest few thousand bins of n/4, and its whole PSD, noise
    # and dof arrays, remembered through a refine, were the record's size again; every bin beyond has NaN noise, as
    # the kept last one does, so a frequency beyond reads as unsearched as before
    top = min(p.size, k_hi + LOBE + 2 * NEIGHBOURS[1] + 2)
    f, p = f[:top].copy(), p[:top].copy()
    ps = {"f": f, "p": p, "dof": dof, "kappa": kappa, "df": fs / nper, "segments": k_seg, "groups": groups}
    ps["dof_bin"] = dof * spread[:top]  # the Welch dof per bin: fewer where the segments' powers differ
    ps["noise"], ps["dof_med"] = _noise(ps, np.zeros(p.size, dtype=bool))
    return ps


def _noise(ps: dict, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The noise level under each searched bin — the median of its neighbours ±(LOBE + 1 … LOBE + w) over the
    median's bias — leaving out masked bins (other lines' main lobes) in mirror pairs (a bin and its mirror
    across k go together, so that the median of a sloped spectrum stays its centre value); where fewer than w/2
    pairs are left, pairs out to ±(LOBE + 2w) join. Degrees of freedom of the median: the Welch average's times
    the bins used over their correlation factor times 2/π."""
    p, dof = ps["p"], ps["dof_bin"]
    noise = np.full(p.size, np.nan)
    dof_med = np.full(p.size, np.nan)
    bias = chi2_dist.median(dof) / dof
    for w, ks in ps["groups"]:
        near = np.arange(LOBE + 1, LOBE + w + 1)
        if not mask.any():
            both = np.concatenate([-near[::-1], near])
            noise[ks] = median_by_sort(p[ks[:, None] + both[None, :]], axis=1) / bias[ks]
            dof_med[ks] = dof[ks] * (2.0 * w / ps["kappa"]) * (2.0 / math.pi)
            continue
        med = np.full(ks.size, np.nan)
        used = np.zeros(ks.size)
        for reach in (near, np.arange(LOBE + 1, LOBE + 2 * w + 1)):
            todo = np.flatnonzero(~np.isfinite(med))
            if todo.size == 0:
                break
            lo, hi = ks[todo, None] - reach[None, :], ks[todo, None] + reach[None, :]
            inside = (lo >= 1) & (hi <= p.size - 2)
            lo_c, hi_c = np.clip(lo, 0, p.size - 1), np.clip(hi, 0, p.size - 1)
            keep = inside & ~mask[lo_c] & ~mask[hi_c]
            count = keep.sum(axis=1)
            enough = count >= max(2, w // 2)
            vals = np.where(np.concatenate([keep, keep], axis=1), np.concatenate([p[lo_c], p[hi_c]], axis=1), np.nan)
            sel = todo[enough]
            if sel.size:
                med[sel] = nanmedian_rows(vals[enough])
                used[sel] = 2 * count[enough]
        # a bin whose neighbourhood is all lines keeps its unmasked reference
        lost = ~np.isfinite(med)
        if lost.any():
            both = np.concatenate([-near[::-1], near])
            med[lost] = median_by_sort(p[ks[lost, None] + both[None, :]], axis=1)
            used[lost] = 2 * w
        noise[ks] = med / bias[ks]
        dof_med[ks] = dof[ks] * (used / ps["kappa"]) * (2.0 / math.pi)
    return noise, dof_med


#: :func:`line_spectrum`'s results by the samples' digest, while :func:`remembering_spectra` is on (refine searches
#: the same samples for lines up to three times: the periodic removal, the sinusoid candidate, the final check of
#: what is still missing); None when off.
_SPECTRA: list[dict] = []


@contextmanager
def remembering_spectra():
    """Within it, :func:`line_spectrum` remembers its results (forgotten on leaving: a 10⁸-sample record's
    spectra are large)."""
    _SPECTRA.append({})
    try:
        yield
    finally:
        _SPECTRA.pop()


def line_spectrum(y: np.ndarray, fs: float) -> list[dict]:
    """The passes :func:`find_lines` searches: per pass the Welch PSD (``f``, ``p``), the noise level under
    each searched bin (``noise``, NaN elsewhere), the degrees of freedom (``dof``; per bin ``dof_bin``,
    ``dof_med``) and ``df``.

    Within :func:`remembering_spectra`, the passes of samples searched before (the same values, by a digest of
    their bytes) are read from memory: each call gets its own dicts (their arrays shared and read-only), the
    same numbers as computed afresh."""
    x = np.ascontiguousarray(y, dtype=np.float64)
    if not _SPECTRA:
        return _line_spectrum(x, fs)
    memo = _SPECTRA[-1]
    key = (hashlib.blake2b(x.data, digest_size=20).digest(), x.size, float(fs))
    if key not in memo:
        passes = _line_spectrum(x, fs)
        for ps in passes:
            for v in ps.values():
                if isinstance(v, np.ndarray):
                    v.flags.writeable = False
        memo[key] = passes
    return [dict(ps) for ps in memo[key]]


def _line_spectrum(x: np.ndarray, fs: float) -> list[dict]:
    """:func:`line_spectrum` computed."""
    mean = float(x.mean())  # subtracted per segment (each taken as a copy): no de-meaned copy of the record
    n = x.size
    if n < 2048:
        return []
    nper = int(min(MAX_SEGMENT, 2 ** int(math.log2(max(n // 8, 256)))))
    first = LOBE + NEIGHBOURS[0] + 1
    long = 2 * (n // 4)  # three half-overlapping segments (any length: the FFT needs no power of two)
    if long < 2 * nper:
        return [_one_pass(x, fs, nper, first, nper // 2, mean)]
    # the long segments take the lowest SWITCH bins of the band-wide pass, where a steep 1/f² floor and a
    # line's neighbours crowd its short neighbourhoods
    return [
        _one_pass(x, fs, long, first, int(math.ceil(SWITCH * long / nper)), mean),
        _one_pass(x, fs, nper, SWITCH, nper // 2, mean),
    ]


def _peaks(ps: dict, alpha_bin: float) -> tuple[list[int], np.ndarray, np.ndarray]:
    """Bins beyond the F threshold, strongest first, one per main lobe; and the ratio and threshold arrays."""
    ok = np.isfinite(ps["noise"])
    ratio = np.full(ps["p"].size, -np.inf)
    ratio[ok] = ps["p"][ok] / ps["noise"][ok]
    thr = np.full(ps["p"].size, np.inf)
    # the bins' dof pairs take a few values (one per neighbourhood width and count of bins used, per band where the
    # segments differ): the F quantile of each pair once, the same numbers as per bin (≈ 7 ms a pass per 10⁴ bins)
    pairs, at = np.unique(np.stack([ps["dof_bin"][ok], ps["dof_med"][ok]], axis=1), axis=0, return_inverse=True)
    thr[ok] = f_dist.isf(alpha_bin, pairs[:, 0], pairs[:, 1])[at.ravel()]
    hits = np.flatnonzero(ratio > thr)
    peaks: list[int] = []
    for k in hits[np.argsort(-ratio[hits])]:
        if all(abs(int(k) - q) > LOBE for q in peaks):
            peaks.append(int(k))
    return peaks, ratio, thr


def find_lines(y: np.ndarray, fs: float, alpha: float, rounds: int = 4) -> dict:
    """Significant narrow lines of ``y`` (rate samples at ``fs``): false-alarm probability ``alpha`` per record.

    Lines close together raise each other's reference (a median of neighbours that are partly lines), so the
    search is repeated (up to ``rounds`` times) with the main lobes of the lines found left out of every median;
    with no line in the first round nothing changes (the null is the first round's).

    Returns ``lines`` (strongest first; each ``f`` Hz, ``amplitude`` and ``amplitude_sd`` (from the PSD: the
    line's power over its width ``width_hz`` — the main lobe, or more where its phase wanders —, A²/2, whether or
    not its phase carries across the record), ``psd_ratio`` (bin over
    the noise level), ``threshold``, ``noise`` (one-sided PSD under it, unit²/Hz), ``bin_hz``, ``pass``),
    ``bins`` (the number searched: the Bonferroni factor), ``p_value`` (the smallest bin's in the first round,
    times ``bins``: the record's Bonferroni p-value) and ``passes`` (:func:`line_spectrum`)."""
    passes = line_spectrum(y, fs)
    n_bins = int(sum(np.count_nonzero(np.isfinite(ps["noise"])) for ps in passes))
    out: list[dict] = []
    if n_bins == 0:
        return {"lines": out, "bins": 0, "passes": passes, "p_value": 1.0}
    p_min = 1.0
    for ps in passes:
        ok = np.isfinite(ps["noise"])
        if ok.any():
            r = ps["p"][ok] / ps["noise"][ok]
            p_min = min(p_min, float(np.min(f_dist.sf(r, ps["dof_bin"][ok], ps["dof_med"][ok]))))
    masks = [np.zeros(ps["p"].size, dtype=bool) for ps in passes]
    found: list[list[int]] = [[] for _ in passes]
    for _ in range(rounds):
        changed = False
        for j, ps in enumerate(passes):
            if masks[j].any():
                ps["noise"], ps["dof_med"] = _noise(ps, masks[j])
            peaks, ratio, thr = _peaks(ps, alpha / n_bins)
            new = np.zeros_like(masks[j])
            for k in peaks:
                new[max(0, k - LOBE) : k + LOBE + 1] = True
            if sorted(peaks) != sorted(found[j]) or not np.array_equal(new, masks[j]):
                changed = True
            found[j], masks[j] = peaks, new
            ps["ratio"], ps["thr"] = ratio, thr
        if not changed:
            break
    for j, ps in enumerate(passes):
        for k in found[j]:
            out.append(_describe(ps, k, float(ps["ratio"][k]), float(ps["thr"][k]), j))
    out.sort(key=lambda d: -d["psd_ratio"])
    return {"lines": out, "bins": n_bins, "passes": passes, "p_value": min(1.0, p_min * n_bins)}


def _describe(ps: dict, k: int, ratio: float, thr: float, j: int) -> dict:
    """A peak's frequency (log-parabola through the bin and its neighbours), amplitude from the power above
    the noise over the line's width (A²/2 = Σ (p − noise)·df; the main lobe, wider where the bins beside it
    stand out: ``width_hz``), and the test."""
    p, df = ps["p"], ps["df"]
    lp = np.log(np.maximum(p[k - 1 : k + 2], 1e-300))
    den = lp[0] - 2 * lp[1] + lp[2]
    delta = 0.5 * (lp[0] - lp[2]) / den if den < 0 else 0.0
    delta = float(np.clip(delta, -0.5, 0.5))
    noise = float(ps["noise"][k])
    # the line's width: its main lobe, widened while the next bin stands 2 SD above the noise (a line whose
    # phase wanders spreads over more bins than the window's lobe), at most to the neighbourhood its noise level
    # came from
    lo, hi, reach = k - LOBE, k + LOBE, LOBE + int(np.clip(k // 2, *NEIGHBOURS))
    above = noise * (1.0 + 2.0 * math.sqrt(2.0 / ps["dof_bin"][k]))
    while lo - 1 >= max(1, k - reach) and p[lo - 1] > above:
        lo -= 1
    while hi + 1 <= min(p.size - 2, k + reach) and p[hi + 1] > above:
        hi += 1
    lobe = p[lo : hi + 1]
    power = float(np.sum(np.maximum(lobe - noise, 0.0)) * df)
    # its SD: each Welch bin scatters by p·√(2/dof) (a line whose phase wanders scatters like the noise; the
    # bins of one lobe correlate: κ), the noise level under it by noise·√(2/dof_med)
    var_p = ps["kappa"] * float(np.sum(lobe**2)) * 2.0 / ps["dof_bin"][k] + (lobe.size * noise) ** 2 * 2.0 / float(
        ps["dof_med"][k]
    )
    amp = math.sqrt(2.0 * power)
    return {
        "f": (k + delta) * df,
        "amplitude": amp,
        "width_hz": (lo * df, hi * df),
        # A²/2 = power: σ_A = σ_power/A (a line at the noise level: the SD of √(2·power) at power's SD)
        "amplitude_sd": math.sqrt(var_p) * df / amp if amp > 0 else math.sqrt(2.0 * math.sqrt(var_p) * df),
        "psd_ratio": ratio,
        "threshold": thr,
        "noise": noise,
        "bin_hz": df,
        "pass": j,
    }


# ----------------------------------------------------------------------------------------------
# families


@lru_cache(maxsize=64)
def _rows(n_gens: int, k_max: int, s_max: int) -> np.ndarray:
    """Integer rows of a lattice — k ≥ 1 for one generator; (k, s) with k ≥ 0, |s| ≤ s_max and s > 0 when
    k = 0 for two (a row and its negative are one real line)."""
    if n_gens == 1:
        return np.arange(1, k_max + 1)[:, None]
    k, s = np.meshgrid(np.arange(0, k_max + 1), np.arange(-s_max, s_max + 1), indexing="ij")
    coefs = np.column_stack([k.ravel(), s.ravel()])
    return coefs[(coefs[:, 0] > 0) | (coefs[:, 1] > 0)]


def _lattice(gens: np.ndarray, k_max: int, s_max: int) -> tuple[np.ndarray, np.ndarray]:
    """The lattice's rows (:func:`_rows`) and their frequencies folded into [0, ½]."""
    coefs = _rows(gens.size, k_max, s_max)
    return coefs, fold_frequency(coefs @ gens)


def _match(nu, tol, gens, gen_sd, k_max, s_max):
    """For each line the lattice row nearest to it within its tolerance plus twice the row's uncertainty
    (|k|·σ_g1 + |s|·σ_g2), or −1 (of rows folding onto one frequency, the first); a lattice point takes only its
    nearest line. Returns (rows, match, slack):
    slack the rows' uncertainty, for the chance count."""
    coefs, pos = _lattice(gens, k_max, s_max)
    slack = 2.0 * (np.abs(coefs) @ gen_sd)
    order = np.argsort(pos, kind="stable")
    # rows that fold onto one frequency (orders k and P − k of a waveform P samples long): the lowest row only,
    # so that a line is not credited to a far order and the lattice does not grow past its lines
    first = np.concatenate([[True], np.diff(pos[order]) > 1e-12]) if order.size else np.zeros(0, dtype=bool)
    order = order[first]
    ps = pos[order]
    j = np.searchsorted(ps, nu)
    lo, hi = np.clip(j - 1, 0, ps.size - 1), np.clip(j, 0, ps.size - 1)
    pick = np.where(np.abs(ps[lo] - nu) <= np.abs(ps[hi] - nu), lo, hi)
    row = order[pick]
    dist = np.abs(pos[row] - nu)
    row = np.where(dist <= tol + slack[row], row, -1)
    # a lattice point keeps its nearest line only
    m = np.flatnonzero(row >= 0)
    if m.size:
        srt = m[np.lexsort((dist[m], row[m]))]
        dup = np.concatenate([[False], row[srt][1:] == row[srt][:-1]])
        row[srt[dup]] = -1
    return coefs, row, slack


def _grow(nu, tol, w, gens, gen_sd, k_max, s_max, iters: int = 16):
    """Match lines to the lattice of ``gens`` and refit the generators on the matched lines (weighted least
    squares in the unfolded frequency). The lattice starts at its lowest rows (k ≤ 4 for harmonics; k ≤ 1,
    |s| ≤ 2 for sidebands) and grows only as far as lines are matched (to twice the extents in use, or two
    more): a lattice wider than its lines is dense enough, aliased, to put some far row next to any line,
    which then pulls the generators off. Returns (gens, coefs of matched lines, matched index, generator SDs,
    chance count)."""
    gens = np.asarray(gens, dtype=np.float64)
    gen_sd = np.asarray(gen_sd, dtype=np.float64)
    k_now, s_now = (min(k_max, 4), 0) if gens.size == 1 else (1, min(s_max, 2))
    m = np.zeros(0, dtype=np.int64)
    coefs = np.zeros((0, gens.size), dtype=np.int64)
    row = np.full(nu.size, -1)
    slack = np.zeros(0)
    last = None
    for _ in range(iters):
        coefs, row, slack = _match(nu, tol, gens, gen_sd, k_now, s_now)
        m = np.flatnonzero(row >= 0)
        if m.size < gens.size + 1:
            break
        c = coefs[row[m]].astype(np.float64)
        raw = c @ gens
        alias = np.round(raw)
        sign = np.where(raw - alias >= 0, 1.0, -1.0)
        target = alias + sign * nu[m]  # the unfolded frequency the row stands for
        cw = c * w[m, None]
        info = c.T @ cw
        if gens.size == 2 and np.linalg.det(info) <= 1e-9 * info[0, 0] * info[1, 1]:
            break  # the matched rows do not pin both generators
        gens = np.linalg.solve(info, cw.T @ target)
        gen_sd = np.sqrt(np.maximum(np.diag(np.linalg.inv(info)), 0.0))
        top = np.max(np.abs(c), axis=0).astype(int)
        k_next = min(k_max, max(2 * top[0], top[0] + 2))
        s_next = min(s_max, max(2 * top[1], top[1] + 2)) if gens.size == 2 else 0
        state = (k_next, s_next, m.size)
        if state == last:
            break
        last = state
        k_now, s_now = k_next, s_next
    if m.size == 0:
        return gens, coefs[:0], m, gen_sd, 0.0
    used = coefs[row[m]]
    # chance: lines that random frequencies would put within the matching window of the lattice points
    # inside the used extents
    ext = np.all(np.abs(coefs) <= np.max(np.abs(used), axis=0), axis=1)
    chance = nu.size * min(1.0, float(np.sum(4.0 * (np.mean(tol) + slack[ext]))))
    return gens, used, m, gen_sd, chance


def _seeds(nu: np.ndarray, tol: np.ndarray, strength: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """(generators, their SDs) to grow families from: the strongest lines over h and their spacings as
    fundamentals; the few strongest as carriers with a spacing as offset (both orders). Near-duplicates
    (within a tolerance) are tried once."""
    top = np.argsort(-strength)[:SEEDS]
    seeds = [(np.array([nu[i] / h]), np.array([tol[i] / h])) for i in top for h in range(1, SUBHARMONICS + 1)]
    diffs: list[tuple[float, float]] = []
    for i, a in enumerate(top):
        for b in top[i + 1 :]:
            diffs.append((float(abs(nu[a] - nu[b])), math.hypot(tol[a], tol[b])))
    seeds += [(np.array([d]), np.array([sd])) for d, sd in diffs]
    few = top[:CARRIERS]
    for a in few:
        for i, b in enumerate(few):
            for c in few[i + 1 :]:
                gap, gap_sd = float(abs(nu[b] - nu[c])), math.hypot(tol[b], tol[c])
                seeds.append((np.array([nu[a], gap]), np.array([tol[a], gap_sd])))
                seeds.append((np.array([gap, nu[a]]), np.array([gap_sd, tol[a]])))
    out: list[tuple[np.ndarray, np.ndarray]] = []
    seen: set = set()
    res = float(np.min(tol))
    for g, sd in seeds:
        key = tuple(np.round(g / res).astype(np.int64).tolist())
        if key not in seen:
            seen.add(key)
            out.append((g, sd))
    return out


def _directions(coefs: np.ndarray) -> int:
    """How many lines through the origin of the integer lattice the rows ``coefs`` lie on (each row's primitive
    direction, sign-free) — independent of the basis the generators are written in. Rows on one or two directions
    are the harmonics of one or two fundamentals (a 13.7 Hz hum's (1, 0), (2, 0) beside a 1.7 Hz square wave's
    (0, 1), (0, 3), …): only a third direction — a mixed row i·f1 + j·f2 beyond both generators' harmonics — is an
    intermodulation or sideband family."""
    c = np.asarray(coefs, dtype=np.int64)
    g = np.gcd(c[:, 0], c[:, 1])
    u = c // np.maximum(g, 1)[:, None]
    flip = (u[:, 0] < 0) | ((u[:, 0] == 0) & (u[:, 1] < 0))
    u = np.where(flip[:, None], -u, u)
    return int(np.unique(u, axis=0).shape[0])


def _commensurate(gens: np.ndarray, tol: float, q_max: int = 4) -> bool:
    """Whether g2 = (p/q)·g1 within ``tol`` for some q ≤ q_max: then the lattice is one generator's, g1/q."""
    for q in range(1, q_max + 1):
        p = round(gens[1] * q / gens[0])
        if p > 0 and abs(gens[1] - p * gens[0] / q) <= tol:
            return True
    return False


def _reduce(gens: np.ndarray, coefs: np.ndarray, gen_sd: np.ndarray, strength: np.ndarray):
    """One basis for a two-generator lattice: the larger generator first, the second reduced modulo it to
    (0, g1/2] — (1.37, 1.18) and (1.37, 0.19) Hz span the same lines; the second is the one a user names (the
    offset of the sidebands) — and, when the strongest line is a first multiple (k = 1), the first generator
    moved onto it by multiples of the second (a tone's sidebands: the tone is the carrier, not a sideband).
    Rows follow, signs made k ≥ 0 (s > 0 when k = 0)."""
    if gens.size != 2:
        return gens, coefs, gen_sd
    if gens[1] > gens[0]:
        gens, coefs, gen_sd = gens[::-1].copy(), coefs[:, ::-1].copy(), gen_sd[::-1].copy()
    q = int(np.round(gens[1] / gens[0]))
    g2 = gens[1] - q * gens[0]
    coefs = np.column_stack([coefs[:, 0] + q * coefs[:, 1], coefs[:, 1]])
    if g2 < 0:
        g2, coefs = -g2, np.column_stack([coefs[:, 0], -coefs[:, 1]])
    flip = (coefs[:, 0] < 0) | ((coefs[:, 0] == 0) & (coefs[:, 1] < 0))
    coefs = np.where(flip[:, None], -coefs, coefs)
    sd2 = math.hypot(gen_sd[1], q * gen_sd[0])
    g1 = gens[0]
    top = int(np.argmax(strength))
    if coefs[top, 0] == 1 and coefs[top, 1] != 0:
        shift = int(coefs[top, 1])
        g1 = g1 + shift * g2
        coefs = np.column_stack([coefs[:, 0], coefs[:, 1] - coefs[:, 0] * shift])
    return np.array([g1, g2]), coefs, np.array([gen_sd[0], sd2])


def _direct(nu: np.ndarray, tol: np.ndarray, gen: float, gen_sd: float) -> int:
    """How many of the lines ``nu`` sit at their own frequency on the harmonics of ``gen`` (a multiple k·g below
    f_s/2 within the line's tolerance plus 2k·σ_g) — whatever folded row the lattice matched them to (orders k
    and P − k of a waveform P samples long fold onto the same frequency)."""
    k = np.maximum(np.round(nu / gen), 1.0)
    return int(np.count_nonzero((k * gen < 0.5) & (np.abs(nu - k * gen) <= tol + 2.0 * k * gen_sd)))


def _lowest_fundamental(best: tuple, ones: list, nu: np.ndarray, tol: np.ndarray) -> tuple:
    """The fundamental that explains the lines: among the one-generator families whose score is as good as the
    best's within the chance count's own scatter (2√chance), the one that takes most lines at their own
    frequency (k·g below f_s/2, not folded); of those, the highest generator. A waveform with a jump sampled
    without an anti-alias filter puts a line at every multiple of f_s/P (P its period in samples), so any
    lattice whose orders reach far enough explains them all folded (a 2.3 Hz sawtooth at 400 Hz: 3.45 Hz and
    6.9 Hz as well as 2.3 Hz) — only the true fundamental puts its strongest lines at their own frequency. A
    subharmonic (g/2) takes the same lines directly at even orders only, and loses to g: missing harmonics are
    allowed, but no lower fundamental than the lines need."""
    near = [c for c in ones if c[0] >= best[0] - 2.0 * math.sqrt(max(c[5], 1.0))]
    if not near:
        return best
    pick = max(near, key=lambda c: (_direct(nu[c[3]], tol[c[3]], float(c[1][0]), float(c[4][0])), float(c[1][0])))
    return pick[:5]


def group_lines(lines: list[dict], fs: float) -> list[dict]:
    """Families of ``lines`` (:func:`find_lines`' dicts): each ``gens`` (normalised generators), ``coefs``
    (integer rows, one per member), ``members`` (indices into ``lines``), ``gen_sd``; lines no family takes
    are not listed.

    The family explaining most lines beyond chance first; a family needs one line more than it has
    generators and must beat chance by more than its generators (see the module's docstring)."""
    nu = np.array([d["f"] / fs for d in lines])
    tol = np.array([0.5 * d["bin_hz"] / fs for d in lines])
    strength = np.array([d["psd_ratio"] for d in lines])
    w = 1.0 / tol**2
    left = np.arange(nu.size)
    fams: list[dict] = []
    while left.size >= 2:
        best: dict = {1: None, 2: None}
        ones: list = []
        sub_nu, sub_tol, sub_w = nu[left], tol[left], w[left]
        for g, g_sd in _seeds(sub_nu, sub_tol, strength[left]):
            if np.any(g <= 2.0 * np.mean(sub_tol)):
                continue
            k_max = MAX_HARMONIC if g.size == 1 else 64  # the lattice grows only as far as lines match it
            gens, coefs, m, gen_sd, chance = _grow(sub_nu, sub_tol, sub_w, g, g_sd, k_max, MAX_SIDEBAND)
            if m.size < gens.size + 1:
                continue
            score = m.size - chance
            if score < gens.size + 0.5:
                continue
            if gens.size == 2 and _directions(coefs) < 3:
                continue  # two harmonic families side by side, not sidebands: the one-generator families say them
            if gens.size == 1:
                ones.append((score, gens, coefs, m, gen_sd, chance))
            if best[gens.size] is None or score > best[gens.size][0]:
                best[gens.size] = (score, gens, coefs, m, gen_sd)
        one, two = best[1], best[2]
        if one is not None:
            one = _lowest_fundamental(one, ones, sub_nu, sub_tol)
        if two is not None and _commensurate(two[1], 2.0 * float(np.mean(sub_tol))):
            two = None  # (2f0, 425f0) is the harmonics of f0 in another basis: the one-generator family says it
        pick = two if two is not None and (one is None or two[0] > one[0]) else one
        if pick is None:
            break
        _, gens, coefs, m, gen_sd = pick
        gens, coefs, gen_sd = _reduce(gens, coefs, gen_sd, strength[left[m]])
        fams.append({"gens": gens, "coefs": coefs, "members": left[m].tolist(), "gen_sd": gen_sd})
        left = np.delete(left, m)
    return fams
