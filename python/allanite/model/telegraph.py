"""Random telegraph (burst, popcorn) noise: a rate that switches between two levels, found and removed in time.

A telegraph of amplitude A that stays a mean ``dwell_low`` at its lower level and ``dwell_high`` at its upper one
(exponential dwells) has the autocorrelation A²·p(1 − p)·e^{−|t|/T_c}, p = dwell_high/(dwell_low + dwell_high) the
share of time at the upper level and T_c = 1/(1/dwell_low + 1/dwell_high): the spectrum is a Lorentzian, the
same as a first-order Gauss–Markov process of σ² = A²·p(1 − p) and that T_c, so its Allan variance is the
Gauss–Markov one (:func:`telegraph_avar`). The Allan curve cannot tell the two apart; the samples can. A
telegraph whose levels stand clear of the rest of the noise makes the Allan differences at τ of the order of its
dwells heavy-tailed (mostly the noise's, a few ±A at its switches), where a Gaussian process of any spectrum
keeps them Gaussian.

:func:`telegraph_test` — the excess kurtosis of the non-overlapping Allan differences at each octave m, in
standard units under a Gaussian process of the differences' own autocorrelation ρ: a stationary Gaussian
series of n terms has var(g₂) ≈ (24/n)·Σ_k ρ_k⁴, so its kurtosis is that of n_eff = n / Σ_k ρ_k⁴ independent
terms, and the Anscombe–Glynn transformation of the kurtosis of n_eff Gaussian terms (D'Agostino's test) makes
it standard normal; one-sided (a telegraph's tail is heavy), Bonferroni over the octaves; the octave of the largest
z must also show an excess kurtosis of at least :data:`MIN_EXCESS` (real sensors' slight non-Gaussianity is no
telegraph). Octaves whose
differences are fewer than :data:`MIN_DIFFS` or finer than 4 steps of a quantised record's lattice are not
tested.

:func:`telegraph_fit` — the two levels and the state of each block of L = m* samples (m* the octave whose
kurtosis stands highest): block means less a slow baseline (their running median over a stretch of the
record, then the running mean of what the levels leave), a two-Gaussian mixture for the levels, and the
Viterbi path of a two-state hidden Markov chain with the dwells of the decoded runs (twice); each switch
then placed to the sample (the split of the two blocks around it that the two levels fit best). The
component removed is A·(s − mean s): the record's mean stays.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.ndimage import median_filter, uniform_filter1d
from scipy.stats import chi2, norm

from ._signatures import gm_avar

__all__ = [
    "MIN_DIFFS",
    "MIN_EXCESS",
    "SEPARATION",
    "telegraph_avar",
    "telegraph_gm",
    "simulate_telegraph",
    "kurtosis_z",
    "telegraph_test",
    "telegraph_fit",
    "dwell_cv",
]

#: Fewest Allan differences an octave's kurtosis is read from (the Anscombe–Glynn form needs n_eff ≫ 20).
MIN_DIFFS = 2000
#: Least excess kurtosis of the Allan differences, at the octave of the largest z, that a telegraph is looked for
#: at: real sensors' noise is slightly non-Gaussian (the ADIS16405 gyros' differences at τ₀: g₂ 0.03–0.04, z 5.7
#: and 8.0 over 10⁶ samples, beyond the test's 4.24), and so much is no switching that matters. The telegraphs
#: measured read far more at their octave: refine_blind11's burst 6.6, refine_telegraph's ten seeds 6.0–8.9,
#: tests/test_telegraph's short record 1.6.
MIN_EXCESS = 0.25
#: The levels must stand this many block-noise σ apart for the states to be read from the samples.
SEPARATION = 4.0


def telegraph_gm(amplitude: float, dwell_low: float, dwell_high: float) -> dict:
    """The Gauss–Markov process of the same spectrum: ``{"sigma": A·√(p(1 − p)), "tc": 1/(1/d_low + 1/d_high)}``."""
    p = dwell_high / (dwell_low + dwell_high)
    return {"sigma": abs(amplitude) * math.sqrt(p * (1 - p)), "tc": 1.0 / (1.0 / dwell_low + 1.0 / dwell_high)}


def telegraph_avar(tau, amplitude: float, dwell_low: float, dwell_high: float) -> np.ndarray:
    """Allan variance of a telegraph of ``amplitude`` (rate unit) and mean dwells ``dwell_low``, ``dwell_high``
    (s): σ²·gm_avar(τ, T_c) with σ² = A²·p(1 − p), T_c = 1/(1/dwell_low + 1/dwell_high) (continuous time)."""
    gm = telegraph_gm(amplitude, dwell_low, dwell_high)
    return gm["sigma"] ** 2 * gm_avar(tau, gm["tc"])


def simulate_telegraph(n: int, fs: float, amplitude: float, dwell_low: float, dwell_high: float, rng) -> np.ndarray:
    """``n`` samples at ``fs`` of a telegraph between 0 and ``amplitude``, exponential dwells of the given means
    (s), its start drawn from the stationary law; each sample the level at its instant."""
    t_end = n / fs
    high = bool(rng.random() < dwell_high / (dwell_low + dwell_high))
    t, edges, states = 0.0, [], []
    while t < t_end:
        edges.append(t)
        states.append(high)
        t += rng.exponential(dwell_high if high else dwell_low)
        high = not high
    idx = np.searchsorted(np.asarray(edges), np.arange(n) / fs, side="right") - 1
    return amplitude * np.asarray(states, dtype=np.float64)[idx]


def kurtosis_z(d: np.ndarray) -> tuple[float, float, float]:
    """(z, n_eff, g₂): the excess kurtosis g₂ of series ``d`` and it in standard-normal units under a Gaussian
    series of its own autocorrelation (n_eff = n/Σρ⁴, lags to 64; Anscombe–Glynn at n_eff)."""
    d = d - d.mean()
    n = d.size
    m2 = float(d @ d) / n
    if not m2 > 0:
        return 0.0, 0.0, 0.0
    d2 = d * d
    b2 = float(np.mean(d2 * d2)) / m2**2  # (d²)², not d**4: numpy's pow took 13× as long
    # lags 1–64 as products (64 dot products cost less than an FFT of 2n points: ≈ 0.2 s a refine at 10⁶ samples)
    acf = np.array([float(d[:-k] @ d[k:]) for k in range(1, min(65, n))]) / (n * m2)
    ne = n / (1.0 + 2.0 * float(np.sum(acf**4)))
    mean = 3.0 * (ne - 1) / (ne + 1)
    var = 24.0 * ne * (ne - 2) * (ne - 3) / ((ne + 1) ** 2 * (ne + 3) * (ne + 5))
    x = (b2 - mean) / math.sqrt(var)
    sb1 = (
        6.0
        * (ne * ne - 5 * ne + 2)
        / ((ne + 7) * (ne + 9))
        * math.sqrt(6.0 * (ne + 3) * (ne + 5) / (ne * (ne - 2) * (ne - 3)))
    )
    a = 6.0 + 8.0 / sb1 * (2.0 / sb1 + math.sqrt(1.0 + 4.0 / sb1**2))
    denom = 1.0 + x * math.sqrt(2.0 / (a - 4.0))
    term2 = math.copysign(abs((1.0 - 2.0 / a) / denom) ** (1.0 / 3.0), denom) if denom != 0 else -math.inf
    return float((1.0 - 2.0 / (9.0 * a) - term2) / math.sqrt(2.0 / (9.0 * a))), float(ne), b2 - 3.0


def _lattice(y: np.ndarray) -> float:
    """A quantised record's step (the smallest non-zero |first difference| where ≥ 1 % of them are 0), else 0."""
    dy = np.abs(np.diff(y[: min(y.size, 200_000)]))
    if np.mean(dy == 0) < 0.01:
        return 0.0
    nz = dy[dy > 0]
    return float(nz.min()) if nz.size else 0.0


def telegraph_test(y: np.ndarray, fs: float, alpha: float) -> dict:
    """The kurtosis of the Allan differences at each octave m (:func:`kurtosis_z`), one-sided, Bonferroni over the
    octaves tested: ``{"accepted", "z", "threshold", "m", "tau", "octaves": [{m, tau, z, n_eff}], "alpha"}``."""
    q = _lattice(y)
    octaves = []
    m = 1
    while y.size // m - 1 >= MIN_DIFFS:
        b = y[: (y.size // m) * m].reshape(-1, m).mean(axis=1)
        d = np.diff(b)
        if not (q > 0 and float(np.std(d)) < 4.0 * q / m):
            z, ne, g2 = kurtosis_z(d)
            octaves.append({"m": m, "tau": m / fs, "z": z, "n_eff": ne, "excess": g2})
        m *= 2
    thr = float(norm.isf(alpha / max(1, len(octaves))))
    best = max(octaves, key=lambda o: o["z"]) if octaves else {"m": 0, "tau": 0.0, "z": -math.inf, "excess": 0.0}
    out = {"z": best["z"], "threshold": thr, "m": best["m"], "tau": best["tau"], "excess": best["excess"]}
    accepted = best["z"] > thr and best["excess"] >= MIN_EXCESS
    return out | {"octaves": octaves, "accepted": bool(accepted), "alpha": alpha}


def _mixture(r: np.ndarray, sigma0: float) -> tuple[float, float, float] | None:
    """The two levels (μ0 the commoner) and their shared σ by EM, started from the median and the samples beyond
    4·``sigma0`` on the side that has more of them; None where fewer than 3 lie beyond."""
    mu0 = float(np.median(r))
    up, down = r > mu0 + 4 * sigma0, r < mu0 - 4 * sigma0
    far = up if up.sum() >= down.sum() else down
    if far.sum() < 3:
        return None
    mu1, s, w = float(np.median(r[far])), sigma0, float(far.mean())
    for _ in range(30):
        l0 = (1 - w) * np.exp(-0.5 * ((r - mu0) / s) ** 2)
        l1 = w * np.exp(-0.5 * ((r - mu1) / s) ** 2)
        g = l1 / np.maximum(l0 + l1, 1e-300)
        w = float(np.clip(g.mean(), 1e-6, 1 - 1e-6))
        mu0 = float(np.sum((1 - g) * r) / max(np.sum(1 - g), 1e-12))
        mu1 = float(np.sum(g * r) / max(np.sum(g), 1e-12))
        s = max(float(np.sqrt(np.sum((1 - g) * (r - mu0) ** 2 + g * (r - mu1) ** 2) / r.size)), 1e-300)
    if w > 0.5:  # μ0 the level held longer
        mu0, mu1 = mu1, mu0
    return mu0, mu1, s


def _viterbi(r: np.ndarray, mu: tuple, s: float, stay: tuple) -> np.ndarray:
    """The likeliest path of a two-state chain (levels ``mu``, noise σ ``s``, per-block staying probabilities
    ``stay``) through ``r``: 0/1 per block."""
    e0 = -0.5 * ((r - mu[0]) / s) ** 2
    e1 = -0.5 * ((r - mu[1]) / s) ** 2
    ls0, lx0 = math.log(stay[0]), math.log1p(-stay[0])
    ls1, lx1 = math.log(stay[1]), math.log1p(-stay[1])
    n = r.size
    back = np.zeros((n, 2), dtype=bool)  # True: came from the other state
    v0, v1 = float(e0[0]), float(e1[0])
    for i, (a, b) in enumerate(zip(e0.tolist(), e1.tolist())):
        if i == 0:
            continue
        s00, s10 = v0 + ls0, v1 + lx1
        s11, s01 = v1 + ls1, v0 + lx0
        back[i, 0], back[i, 1] = s10 > s00, s01 > s11
        v0, v1 = max(s00, s10) + a, max(s11, s01) + b
    path = np.zeros(n, dtype=np.int8)
    k = int(v1 > v0)
    for i in range(n - 1, -1, -1):
        path[i] = k
        if back[i, k]:
            k = 1 - k
    return path


def _runs(s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(starts, lengths, states) of the runs of ``s``."""
    edge = np.flatnonzero(np.diff(s)) + 1
    starts = np.concatenate([[0], edge])
    lengths = np.diff(np.concatenate([starts, [s.size]]))
    return starts, lengths, s[starts]


def _cv(lengths: np.ndarray) -> float:
    """The coefficient of variation (sample s.d. over mean) of run ``lengths``; NaN for fewer than two."""
    d = np.asarray(lengths, dtype=np.float64)
    return float(np.std(d, ddof=1) / np.mean(d)) if d.size >= 2 else math.nan


def dwell_cv(states: np.ndarray) -> tuple[float, float]:
    """The coefficient of variation of the complete runs in each state of the 0/1 sequence ``states`` — (state 0's,
    state 1's); NaN where a state has fewer than two complete runs. A telegraph's dwells are exponential (CV ≈ 1); a
    pulse train's are all alike (CV ≈ 0). :func:`telegraph_fit` gives its own as ``"dwell_cv"`` (low, high)."""
    _starts, lengths, st = _runs(np.asarray(states))
    ln, st = lengths[1:-1], st[1:-1]  # the first and last runs are cut by the record's ends
    return _cv(ln[st == 0]), _cv(ln[st == 1])


def _diff_sigma(x: np.ndarray) -> float:
    """σ of white noise behind ``x`` from its first differences: 1.4826·median|Δx|/√2."""
    return 1.4826 * float(np.median(np.abs(np.diff(x)))) / math.sqrt(2.0)


def _decode(b: np.ndarray, wb: int) -> tuple | None:
    """Block means ``b`` → (states, baseline, levels (μ0, μ1), block noise σ), the baseline a running median over
    ``wb`` blocks, then twice: the Viterbi path at the dwells of the runs decoded so far, the baseline the running
    mean of what the levels leave, the levels the decoded states' means. None where no second level shows."""
    base = median_filter(b, size=wb, mode="nearest")
    r = b - base
    sigma0 = _diff_sigma(r)
    mix = _mixture(r, max(sigma0, 1e-300))
    if mix is None:
        return None
    mu0, mu1, s = mix
    path = (np.abs(r - mu1) < np.abs(r - mu0)).astype(np.int8)
    for _ in range(2):
        _st, lengths, states = _runs(path)
        stay = tuple(
            1.0 - 1.0 / max(float(np.mean(lengths[states == k])) if np.any(states == k) else 2.0, 1.5) for k in (0, 1)
        )
        path = _viterbi(r, (mu0, mu1), s, stay)
        if path.min() == path.max():
            return None
        base = uniform_filter1d(b - (mu1 - mu0) * path, size=wb, mode="nearest")
        r = b - base
        mu0, mu1 = float(np.mean(r[path == 0])), float(np.mean(r[path == 1]))
        s = max(float(np.std(r - np.where(path == 1, mu1, mu0))), 1e-300)
    left = r - np.where(path == 1, mu1, mu0)
    sigma_b = _diff_sigma(left)
    return path, base, (mu0, mu1), max(sigma_b, 1e-300)


def _to_samples(y: np.ndarray, path: np.ndarray, base: np.ndarray, mu: tuple, block: int) -> np.ndarray:
    """The blocks' states at sample resolution: each switch placed at the split of the two blocks around it that
    the two levels (over the baseline) fit best."""
    n = y.size
    s = np.empty(n, dtype=np.int8)
    s[: path.size * block] = np.repeat(path, block)
    s[path.size * block :] = path[-1]
    if block == 1:
        return s
    for i in np.flatnonzero(np.diff(path)) + 1:
        lo = (i - 1) * block
        w = y[lo : lo + 2 * block] - np.repeat(base[i - 1 : i + 1], block)
        a, c = mu[path[i - 1]], mu[path[i]]
        g = (c - a) * (2.0 * w - a - c)
        tail = np.cumsum(g[::-1])[::-1]  # tail[k]: the gain of the later level from sample k on
        k = int(np.argmax(tail))
        s[lo : lo + k], s[lo + k : lo + 2 * block] = path[i - 1], path[i]
    return s


def _dwell(lengths: np.ndarray, fs: float, confidence: float) -> tuple[float, tuple[float, float], int]:
    """Mean dwell (s) of complete runs, its interval (the sum of n exponential dwells: 2n·d̄/θ ~ χ²₂ₙ), and n."""
    k = lengths.size
    if k == 0:
        return math.nan, (math.nan, math.nan), 0
    d = float(np.mean(lengths)) / fs
    a = 1.0 - confidence
    return d, (2 * k * d / float(chi2.isf(a / 2, 2 * k)), 2 * k * d / float(chi2.ppf(a / 2, 2 * k))), k


def telegraph_fit(y: np.ndarray, fs: float, m: int, confidence: float = 0.683) -> dict | None:
    """The two-level switching of ``y`` (:func:`_fit_at`) read at blocks of L = m samples, then at the finest L = m/2^k
    at which the levels would still stand 2·:data:`SEPARATION` σ apart (the blocks' noise σ taken to fall as 1/√L,
    white): a visit shorter than a block is not seen, so the finer the blocks the fewer missed; the coarse reading
    kept where the fine one's levels stand less than :data:`SEPARATION` apart. ``{"amplitude", "dwell_low",
    "dwell_high", "intervals", "visits", "dwell_cv", "separation", "block", "states", "baseline", "component"}``
    (amplitude the upper level less the lower, rate unit; dwells in s and their coefficients of variation (low, high),
    from the complete runs; ``separation`` |A| over the blocks' noise σ), or None where no second level shows."""
    n = y.size
    coarse = _fit_at(y, fs, max(1, m, n // 200_000), m, confidence)
    if coarse is None:
        return None
    k = int(math.floor(2.0 * math.log2(max(coarse["separation"] / (2.0 * SEPARATION), 1.0))))
    block = max(1, coarse["block"] >> k, n // 200_000)
    if block == coarse["block"]:
        return coarse
    fine = _fit_at(y, fs, block, m, confidence)
    return fine if fine is not None and fine["separation"] >= SEPARATION else coarse


def _fit_at(y: np.ndarray, fs: float, block: int, m: int, confidence: float) -> dict | None:
    """The two-level switching of ``y`` read at blocks of ``block`` samples (:func:`_decode`, its baseline over
    max(64·m, n/32) samples), switches placed to the sample."""
    n = y.size
    nb = n // block
    b = y[: nb * block].reshape(nb, block).mean(axis=1)
    wb = max(33, int(max(64 * m, n / 32) / block)) | 1
    dec = _decode(b, wb)
    if dec is None:
        return None
    path, base, mu, sigma_b = dec
    s = _to_samples(y, path, base, mu, block)
    base_s = np.concatenate([np.repeat(base, block), np.full(n - nb * block, base[-1])])
    resid = y - base_s
    starts, lengths, states = _runs(s)
    amp = float(np.mean(resid[s == 1]) - np.mean(resid[s == 0]))
    inner = slice(1, max(1, starts.size - 1))  # the first and last runs are cut by the record's ends
    st, ln = states[inner], lengths[inner]
    rare = 1 if np.mean(s) < 0.5 else 0
    visits = [float(np.mean(resid[a : a + k])) for a, k, q in zip(starts[inner], ln, st) if q == rare]
    sign = 1.0 if rare == 1 else -1.0
    a_vis = sign * (np.asarray(visits) - float(np.mean(resid[s != rare])))
    se = float(np.std(a_vis, ddof=1) / math.sqrt(a_vis.size)) if a_vis.size > 1 else math.inf
    zc = float(norm.isf((1.0 - confidence) / 2.0))
    up = 1 if amp > 0 else 0  # the state at the upper level
    d_hi, iv_hi, k_hi = _dwell(ln[st == up], fs, confidence)
    d_lo, iv_lo, k_lo = _dwell(ln[st != up], fs, confidence)
    return {
        "amplitude": abs(amp),
        "dwell_low": d_lo,
        "dwell_high": d_hi,
        "intervals": {"amplitude": (abs(amp) - zc * se, abs(amp) + zc * se), "dwell_low": iv_lo, "dwell_high": iv_hi},
        "visits": {"low": k_lo, "high": k_hi},
        "dwell_cv": (_cv(ln[st != up]), _cv(ln[st == up])),
        "separation": abs(amp) / sigma_b,
        "block": block,
        "states": s,
        "baseline": base_s,
        "component": amp * (s - float(np.mean(s))),
    }
