"""Impulsive noise: samples beyond what Gaussian noise predicts, found on the differenced record.

:func:`outlier_test` — the test behind the ``"outliers"`` effect of :func:`allanite.refine`. The first
differences d_t = y_t − y_{t−1} of any Gaussian record are Gaussian, whatever its spectrum (white, flicker,
random walk, a ramp, a low-pass: a linear filter of Gaussian noise stays Gaussian; slow terms barely reach
the differences, so they hide nothing). Their scale is estimated robustly in blocks of the record (so a noise
level that changes along the record does not read as a heavy tail): the median absolute difference, or — for
quantised samples (every difference a multiple of a step L) — the σ of the Gaussian whose differences,
quantised, put the observed share of |d| ≤ jL (j where that share is nearest ½). With y quantised as y + u
(u uniform on a step, independent of d), P(|d_q| ≤ jL) = P(|d + U| < (j + ½)L), U uniform on (−L/2, L/2):
exact for the lattice however coarse (a Gaussian σ alone would miss a record whose differences are mostly 0
or ±1 step). The offsets are uniform when the samples wander over a step or more; a record whose samples'
standard deviation in a block is below :data:`COARSE` step (a quiet sensor toggling between two or three
codes) is not tested — no Gaussian model of the lattice describes it.

At each cut c of :data:`CUTS` (in those σ) the exceedances |d_t| > c·σ are counted as clusters (consecutive
exceedances are one: a spike makes two, a low-pass makes runs) and set against the Gaussian expectation
λ = Σ_blocks n_b·P(|d| > c·σ_b) (on a lattice, the lattice's own probability). Clusters are at most as many
as exceedances, so under the null they are at most Poisson(λ) (declustered extremes). A tail is called heavy
only beyond :data:`TAIL_FACTOR` (2) times the Gaussian count — real sensors' noise is slightly non-Gaussian
(the ADIS16405 gyros' differences hold 1.1–1.5× the Gaussian count at 3–4 σ over 10⁶ samples and none beyond
5.2 σ: no spikes, yet an exact Gaussian null rejects on two of them) — so
P(Poisson(2λ) ≥ count) ≤ ``alpha``/len(CUTS) accepts (Bonferroni over the cuts).

The samples then flagged are those farther from their local median (5 samples) than c* white-noise σ — the
σ the robust scale of the second difference y_t − (y_{t−1} + y_{t+1})/2 implies in its block — c* the lowest
significant cut whose Gaussian expectation is at most a tenth of the count (the excess is the bulk of what is
flagged). A step of the mean moves the local median with it and is not flagged. :func:`replace_outliers`
replaces each flagged sample by its local median (the median of the 5 samples around it): how
:func:`allanite.refine` refits the noise after removing them.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.ndimage import median_filter
from scipy.optimize import brentq
from scipy.special import ndtr
from scipy.stats import poisson

__all__ = ["outlier_test", "replace_outliers", "lattice_step", "robust_sigma", "CUTS", "MEDIAN_SPAN"]

#: Cuts (in robust σ of the differences) at which exceedances are counted.
CUTS = (4.0, 5.0, 6.0, 7.0)
#: A heavy tail is a count beyond this multiple of the Gaussian expectation: the null is "at most
#: TAIL_FACTOR × λ", so that a sensor whose noise is only slightly non-Gaussian is not flagged (the
#: ADIS16405 gyros' differences hold 1.1–1.5× the Gaussian count at 3–4 σ, none beyond 5.2 σ: no spikes).
TAIL_FACTOR = 2.0
#: Samples of the local median a flagged sample is replaced by (odd).
MEDIAN_SPAN = 5
#: Samples per block of the robust scale (at most MAX_BLOCKS blocks, at least one).
BLOCK = 8192
MAX_BLOCKS = 64
#: Least spread of the samples (standard deviation per block, in quantisation steps) for the lattice model to
#: hold: the offsets y mod L are uniform only when the samples wander over a step or more. Measured on white
#: noise quantised with steps of 0.7 … 2 σ and offsets 0, ¼, ½ step (2·10⁶ samples): the count beyond 4 σ is
#: within 0.8–1.3× the model up to a step of 1.4 σ (std ≥ 0.7 step), 2.25× at 2 σ.
COARSE = 0.7
#: The flagged samples' cut: the lowest significant cut whose Gaussian expectation is ≤ this share of the count.
EXCESS_SHARE = 0.1


def lattice_step(x: np.ndarray) -> float:
    """The quantisation step L of ``x`` if every nonzero |x| is a whole multiple of the smallest (to 1e-6),
    else 0 (continuous)."""
    a = np.abs(np.asarray(x, dtype=np.float64))
    nz = a[a > 0]
    if nz.size == 0:
        return 0.0
    step = float(nz.min())
    q = nz / step
    if np.all(np.abs(q - np.round(q)) <= 1e-6 * np.maximum(1.0, q)):
        return step
    return 0.0


def _inner(a: float, sigma: float, step: float) -> float:
    """P(|d + U| < a), d ~ N(0, σ²), U uniform on (−L/2, L/2): (1/L)∫ [Φ((a−u)/σ) − Φ((−a−u)/σ)] du, closed
    form with ∫Φ(x/σ)dx = xΦ(x/σ) + σφ(x/σ)."""

    def psi(x: float) -> float:
        z = x / sigma
        return x * 0.5 * math.erfc(-z / math.sqrt(2.0)) + sigma * math.exp(-0.5 * z * z) / math.sqrt(2.0 * math.pi)

    h = step / 2.0
    return float((psi(a + h) - psi(a - h) - psi(-a + h) + psi(-a - h)) / step)


def robust_sigma(d: np.ndarray, step: float) -> float:
    """σ of the Gaussian behind differences ``d`` (robust): 1.4826·median|d − median d| when continuous; on a
    lattice of ``step`` L, the σ at which P(|d + U| < (j + ½)L) matches the share of |d| ≤ jL, j where that
    share is nearest ½. NaN when the differences carry no scale (all equal)."""
    d = np.asarray(d, dtype=np.float64)
    if step <= 0:
        mad = float(np.median(np.abs(d - np.median(d))))
        return 1.4826 * mad if mad > 0 else float("nan")
    j_all = np.round(np.abs(d) / step).astype(np.int64)
    counts = np.bincount(j_all)
    share = np.cumsum(counts) / d.size
    j = int(np.argmin(np.abs(share - 0.5)))
    target = float(share[j])
    if target >= 1.0:
        return float("nan")
    a = (j + 0.5) * step
    lo, hi = 1e-6 * step, 1e6 * step
    f_lo, f_hi = _inner(a, lo, step) - target, _inner(a, hi, step) - target
    if f_lo * f_hi > 0:
        return float("nan")
    return float(brentq(lambda s: _inner(a, s, step) - target, lo, hi, xtol=1e-9 * step))


def _tail(c: float, sigma: float, step: float) -> tuple[float, float]:
    """(cut in the data's unit, P(|d| beyond it)) at c·σ: continuous 2Φ̄(c); on a lattice the next multiple
    of L above c·σ, k·L, with P(|d_q| ≥ kL) = 2·(1 − P(d + U < (k − ½)L))."""
    if step <= 0:
        return c * sigma, float(2.0 * ndtr(-c))
    k = math.floor(c * sigma / step) + 1
    return (k - 0.5) * step, 1.0 - _inner((k - 0.5) * step, sigma, step)


def _blocks(n: int) -> list[slice]:
    nb = int(min(MAX_BLOCKS, max(1, n // BLOCK)))
    edges = np.linspace(0, n, nb + 1).astype(np.int64)
    return [slice(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:])]


def _clusters(mask: np.ndarray) -> int:
    """Runs of consecutive True."""
    if mask.size == 0:
        return 0
    return int(np.count_nonzero(mask[1:] & ~mask[:-1]) + int(mask[0]))


def outlier_test(y: np.ndarray, fs: float, alpha: float) -> dict:
    """Test a record for samples beyond its Gaussian noise; flag them when the test accepts.

    Returns ``accepted`` (bool), ``cuts`` (per cut c: ``count`` of exceedance clusters, ``expected`` λ,
    ``p_value`` of the count under Poisson(TAIL_FACTOR·λ), ``p_gaussian`` under Poisson(λ)),
    ``alpha_per_cut``, ``step`` (the quantisation step, 0 if continuous), ``sigma_d`` (the differences'
    robust σ, median over blocks, rate unit) and, when accepted, ``cut`` (c*), ``flags`` (bool per sample),
    ``rate`` (flagged share of the samples) and ``threshold`` (rate unit: c* white-noise σ, median over
    blocks). ``fs`` only labels the record (the test is on samples)."""
    y = np.asarray(y, dtype=np.float64)
    n = y.size
    out: dict = {"accepted": False, "cuts": [], "alpha_per_cut": alpha / len(CUTS), "fs": float(fs)}
    if n < 64:
        out["note"] = "too few samples"
        return out
    d = np.diff(y)
    step = lattice_step(d)
    out["step"] = step
    blocks = _blocks(d.size)
    sig = np.array([robust_sigma(d[b], step) for b in blocks])
    out["sigma_d"] = float(np.nanmedian(sig)) if np.isfinite(sig).any() else float("nan")
    if not np.isfinite(sig).all():
        out["note"] = "a block of the differenced record has no spread (constant samples)"
        return out
    if step > 0:
        spread = min(float(np.std(y[b])) for b in blocks)
        if not spread >= COARSE * step:
            # the quantisation offsets are uniform only when the samples wander over a step or more
            out["note"] = (
                f"quantisation too coarse for the test: the samples' standard deviation in a block is "
                f"{spread / step:.2g} step (< {COARSE:g})"
            )
            return out
    ad = np.abs(d)
    for c in CUTS:
        count, lam = 0, 0.0
        for b, s in zip(blocks, sig):
            cut, p = _tail(c, s, step)
            count += _clusters(ad[b] > cut)
            lam += (b.stop - b.start) * p
        pv = float(poisson.sf(count - 1, TAIL_FACTOR * lam)) if count > 0 else 1.0
        pg = float(poisson.sf(count - 1, lam)) if count > 0 else 1.0
        out["cuts"].append({"c": c, "count": count, "expected": lam, "p_value": pv, "p_gaussian": pg})
    sig_cuts = [r for r in out["cuts"] if r["p_value"] <= out["alpha_per_cut"]]
    if not sig_cuts:
        return out
    clean = [r for r in sig_cuts if r["expected"] <= EXCESS_SHARE * r["count"]]
    chosen = (clean or sig_cuts[-1:])[0]
    flags, thr = _flag(y, chosen["c"], step)
    if not flags.any():
        out["note"] = "the differences' tail exceeds the Gaussian's, but no sample stands off its local median"
        return out
    out.update(accepted=True, cut=chosen["c"], flags=flags, rate=float(flags.mean()), threshold=thr)
    return out


def _flag(y: np.ndarray, c: float, step: float) -> tuple[np.ndarray, float]:
    """Samples farther from their local median than c·σ_e/√1.5 (per block): σ_e the robust σ of the second
    difference e_t = y_t − (y_{t−1} + y_{t+1})/2 — a linear, hence Gaussian, statistic: a sample's own noise
    around its neighbours, √1.5·σ for white noise of σ, so the cut is c white-noise σ. (The residual from the
    median has a point mass at 0 — a sample that is its window's median — and no usable σ of its own.)"""
    med = median_filter(y, size=MEDIAN_SPAN, mode="nearest")
    r = y - med
    e = np.zeros(y.size)
    e[1:-1] = y[1:-1] - 0.5 * (y[:-2] + y[2:])
    flags = np.zeros(y.size, dtype=bool)
    thrs = []
    for b in _blocks(y.size):
        s = robust_sigma(e[b], 0.5 * step)
        if not np.isfinite(s):
            continue
        cut = c * s / math.sqrt(1.5)
        flags[b] = np.abs(r[b]) > cut
        thrs.append(cut)
    return flags, float(np.median(thrs)) if thrs else float("nan")


def replace_outliers(y: np.ndarray, flags: np.ndarray) -> np.ndarray:
    """``y`` with each flagged sample replaced by the median of the :data:`MEDIAN_SPAN` samples around it."""
    y = np.asarray(y, dtype=np.float64)
    out = y.copy()
    if np.any(flags):
        med = median_filter(y, size=MEDIAN_SPAN, mode="nearest")
        out[flags] = med[flags]
    return out
