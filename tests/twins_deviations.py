"""Pure-NumPy twins of the deviation kernels in ``allanite._core``, written straight from the
definitions (NIST SP 1065 = W. J. Riley, *Handbook of Frequency Stability Analysis*, 2008, §5.2; ITU-T
G.810 for MTIE and TIE rms). Slow loops on purpose: each twin is the textbook sum on the phase record,
so that the fast rate-domain kernels are checked against something that shares none of their tricks.

Conventions: ``y`` rate (fractional frequency) samples y_0..y_{M−1} at τ0 = 1; phase x_0 = 0,
x_k = Σ_{i<k} y_i (N = M + 1 points); τ = m. All functions return *variances* (MTIE and TIE rms: the
deviation-like quantity itself). 0-based indices below; SP 1065 writes them 1-based.
"""

from __future__ import annotations

import numpy as np


def phase(y) -> np.ndarray:
    """x_0 = 0, x_k = Σ_{i<k} y_i (no mean removed: every estimator here ignores a constant rate)."""
    y = np.asarray(y, dtype=float)
    return np.concatenate([[0.0], np.cumsum(y)])


def mvar(y, m: int) -> float:
    """SP 1065 eq. (14): Mod σ²(τ) = 1/(2m²τ²(N−3m+1)) Σ_{j=0}^{N−3m} [Σ_{i=j}^{j+m−1}
    (x_{i+2m} − 2x_{i+m} + x_i)]²."""
    x = phase(y)
    n = x.size
    total = 0.0
    for j in range(n - 3 * m + 1):
        inner = 0.0
        for i in range(j, j + m):
            inner += x[i + 2 * m] - 2 * x[i + m] + x[i]
        total += inner * inner
    return total / (2.0 * m**4 * (n - 3 * m + 1))


def tvar(y, m: int, tau0: float = 1.0) -> float:
    """SP 1065 eq. (15): TVAR = (τ²/3)·MVAR, τ = m·τ0."""
    return (m * tau0) ** 2 / 3.0 * mvar(y, m)


def ohvar(y, m: int) -> float:
    """SP 1065 eq. (20): Hσ²(τ) = 1/(6τ²(N−3m)) Σ_{i=0}^{N−3m−1} (x_{i+3m} − 3x_{i+2m} + 3x_{i+m} − x_i)²."""
    x = phase(y)
    n = x.size
    s = 0.0
    for i in range(n - 3 * m):
        d = x[i + 3 * m] - 3 * x[i + 2 * m] + 3 * x[i + m] - x[i]
        s += d * d
    return s / (6.0 * m * m * (n - 3 * m))


def hvar(y, m: int) -> float:
    """SP 1065 eq. (17): K = ⌊M/m⌋ non-overlapping averages ȳ_j, Hσ²(τ) = 1/(6(K−2)) Σ_{j=0}^{K−3}
    (ȳ_{j+2} − 2ȳ_{j+1} + ȳ_j)²."""
    y = np.asarray(y, dtype=float)
    k = y.size // m
    ybar = [np.mean(y[j * m : (j + 1) * m]) for j in range(k)]
    s = 0.0
    for j in range(k - 2):
        d = ybar[j + 2] - 2 * ybar[j + 1] + ybar[j]
        s += d * d
    return s / (6.0 * (k - 2))


def totvar(y, m: int) -> float:
    """SP 1065 eq. (25): Tot var(τ) = 1/(2τ²(N−2)) Σ_{i=1}^{N−2} (x*_{i−m} − 2x*_i + x*_{i+m})², x* the
    phase extended by reflection, x*_{−j} = 2x_0 − x_j, x*_{N−1+j} = 2x_{N−1} − x_{N−1−j}."""
    x = phase(y)
    n = x.size

    def xs(i):
        if i < 0:
            return 2 * x[0] - x[-i]
        if i > n - 1:
            return 2 * x[n - 1] - x[2 * (n - 1) - i]
        return x[i]

    s = 0.0
    for i in range(1, n - 1):
        d = xs(i - m) - 2 * xs(i) + xs(i + m)
        s += d * d
    return s / (2.0 * m * m * (n - 2))


def _detrend_reflect(seq: np.ndarray) -> np.ndarray:
    """Half-average slope removal and uninverted even reflection of a 3m-point subsequence (SP 1065
    §5.2.12 steps 1–2): slope = (mean of last ⌊3m/2⌋ − mean of first ⌊3m/2⌋) / ⌈3m/2⌉."""
    n3 = seq.size
    h1, h2 = n3 // 2, (n3 + 1) // 2
    slope = (np.mean(seq[h2:]) - np.mean(seq[:h1])) / h2
    x0 = seq - slope * np.arange(n3)
    return np.concatenate([x0[::-1], x0, x0[::-1]])


def mtotvar(y, m: int) -> float:
    """SP 1065 eq. (27): Mod Totvar(τ) = 1/(2τ²(N−3m+1)) Σ_{n=0}^{N−3m} { 1/(6m) Σ_{i=0}^{6m−1} z_i² },
    z_i = (1/m) Σ_{j=i}^{i+m−1} (x#_{j+2m} − 2x#_{j+m} + x#_j), x# the 3m-point phase subsequence from
    x_n, detrended and reflected to 9m points."""
    x = phase(y)
    n = x.size
    total = 0.0
    for start in range(n - 3 * m + 1):
        xs = _detrend_reflect(x[start : start + 3 * m])
        inner = 0.0
        for i in range(6 * m):
            z = sum(xs[j + 2 * m] - 2 * xs[j + m] + xs[j] for j in range(i, i + m)) / m
            inner += z * z
        total += inner / (6.0 * m)
    return total / (2.0 * m * m * (n - 3 * m + 1))


def ttotvar(y, m: int, tau0: float = 1.0) -> float:
    """SP 1065 eq. (28) (τ²/3, the handbook's τ³ is a misprint): Ttot var = (τ²/3)·Mod Totvar."""
    return (m * tau0) ** 2 / 3.0 * mtotvar(y, m)


def htotvar(y, m: int) -> float:
    """SP 1065 eq. (30): Htotvar(τ) = 1/(6(M−3m+1)) Σ_{n=0}^{M−3m} { 1/(6m) Σ_{i=0}^{6m−1} H_i² },
    H_i = ȳ#_{i+2m} − 2ȳ#_{i+m} + ȳ#_i (m-sample averages of y#, the 3m-sample frequency subsequence
    from y_n, detrended and reflected to 9m samples); m = 1 is OHVAR (Riley; Stable32)."""
    y = np.asarray(y, dtype=float)
    if m == 1:
        return ohvar(y, 1)
    total = 0.0
    count = y.size - 3 * m + 1
    for start in range(count):
        ys = _detrend_reflect(y[start : start + 3 * m])
        inner = 0.0
        for i in range(6 * m):
            a = [np.mean(ys[i + k * m : i + (k + 1) * m]) for k in range(3)]
            h = a[2] - 2 * a[1] + a[0]
            inner += h * h
        total += inner / (6.0 * m)
    return total / (6.0 * count)


def mtie(x, m: int) -> float:
    """ITU-T G.810 / SP 1065 §5.2.15: max over windows of m+1 consecutive phase points of (max − min)."""
    x = np.asarray(x, dtype=float)
    best = 0.0
    for k in range(x.size - m):
        w = x[k : k + m + 1]
        best = max(best, float(w.max() - w.min()))
    return best


def tierms(x, m: int) -> float:
    """ITU-T G.810: TIErms(τ) = sqrt(1/(N−m) Σ_{i=0}^{N−m−1} (x_{i+m} − x_i)²)."""
    x = np.asarray(x, dtype=float)
    d = [x[i + m] - x[i] for i in range(x.size - m)]
    return float(np.sqrt(np.mean(np.square(d))))


# ---- gap-aware twins: the same sums over only the terms whose rate samples are all present --------


def _span_ok(y, start, span) -> bool:
    return not np.any(np.isnan(y[start : start + span]))


def gap_terms(y, m: int, estimator: str):
    """(Σ term², number of complete terms) for 'oavar' | 'avar' | 'mvar' | 'ohvar' | 'hvar' on a rate record with NaN
    gaps. A term is complete when every rate sample it spans is present: OAVAR term k spans y[k, k+2m),
    MVAR term j spans y[j, j+3m−1), OHVAR term k spans y[k, k+3m). Phase differences are summed from
    the rate samples inside the span (the phase across a gap is unknown)."""
    y = np.asarray(y, dtype=float)
    mu = np.nanmean(y) if np.any(~np.isnan(y)) else 0.0
    mm = y.size
    # classic AVAR / HVAR: the OAVAR / OHVAR terms that start at a cluster boundary (k a multiple of m)
    classic = estimator in ("avar", "hvar")
    estimator = {"avar": "oavar", "hvar": "ohvar"}.get(estimator, estimator)
    span = {"oavar": 2 * m, "mvar": 3 * m - 1, "ohvar": 3 * m}[estimator]
    s, n = 0.0, 0
    for k in range(0, mm - span + 1, m if classic else 1):
        if not _span_ok(y, k, span):
            continue
        seg = y[k : k + span] - mu
        xs = np.concatenate([[0.0], np.cumsum(seg)])  # local phase, x_k relative
        if estimator == "oavar":
            t = xs[2 * m] - 2 * xs[m] + xs[0]
        elif estimator == "ohvar":
            t = xs[3 * m] - 3 * xs[2 * m] + 3 * xs[m] - xs[0]
        else:
            t = sum(xs[i + 2 * m] - 2 * xs[i + m] + xs[i] for i in range(m))
        s += t * t
        n += 1
    return s, n


def gap_var(y, m: int, estimator: str):
    """(variance, complete-term count); NaN and 0 when no term is complete."""
    s, n = gap_terms(y, m, estimator)
    norm = {"oavar": 2.0 * m * m, "avar": 2.0 * m * m, "mvar": 2.0 * m**4, "ohvar": 6.0 * m * m, "hvar": 6.0 * m * m}[
        estimator
    ]
    return (s / (norm * n) if n else float("nan")), n


def gap_total(y, m: int, estimator: str):
    """(variance, complete-term count) of 'totvar' | 'mtotvar' | 'htotvar' on a rate record with NaN gaps.

    TOTVAR: the term at phase point p (1 ≤ p ≤ N − 2) is Σ y*[p, p+m) − Σ y*[p−m, p) over the evenly
    reflected rate y* (y*_{−1−j} = y_j, y*_{M+j} = y_{M−1−j}: the rate of SP 1065's reflected phase); it is
    complete when every *original* sample it reads (reflected ones mapped back) is present.
    MTOTVAR: the 3m-point phase subsequence from x_n, i.e. the rate samples y[n, n + 3m − 1); HTOTVAR: the
    3m rate samples y[n, n + 3m) (m = 1: the OHVAR terms). Complete subsequences only, each detrended and
    reflected as in the gapless twins."""
    y = np.asarray(y, dtype=float)
    mm = y.size
    if estimator == "htotvar" and m == 1:
        return gap_var(y, 1, "ohvar")
    mu = np.nanmean(y)
    s, n = 0.0, 0
    if estimator == "totvar":
        for p in range(1, mm):
            q = np.arange(p - m, p + m)
            orig = np.where(q < 0, -q - 1, np.where(q < mm, q, 2 * mm - 1 - q))
            v = y[orig] - mu
            if np.any(np.isnan(v)):
                continue
            t = v[m:].sum() - v[:m].sum()
            s += t * t
            n += 1
        return (s / (2.0 * m * m * n) if n else float("nan")), n
    span = 3 * m - 1 if estimator == "mtotvar" else 3 * m
    for start in range(mm - span + 1):
        seg = y[start : start + span]
        if np.any(np.isnan(seg)):
            continue
        if estimator == "mtotvar":
            xs = _detrend_reflect(np.concatenate([[0.0], np.cumsum(seg - mu)]))
            z = [sum(xs[j + 2 * m] - 2 * xs[j + m] + xs[j] for j in range(i, i + m)) / m for i in range(6 * m)]
        else:
            ys = _detrend_reflect(seg)
            z = [np.mean(ys[i + 2 * m : i + 3 * m]) - 2 * np.mean(ys[i + m : i + 2 * m]) + np.mean(ys[i : i + m])
                 for i in range(6 * m)]  # fmt: skip
        s += float(np.sum(np.square(z))) / (6.0 * m)
        n += 1
    if not n:
        return float("nan"), 0
    return (s / (2.0 * m * m * n) if estimator == "mtotvar" else s / (6.0 * n)), n


def dynamic_ohvar(y, window: int, hop: int, m: int) -> np.ndarray:
    """OHVAR of every window y[j·hop, j·hop + window)."""
    y = np.asarray(y, dtype=float)
    n_win = (y.size - window) // hop + 1
    return np.array([ohvar(y[j * hop : j * hop + window], m) for j in range(n_win)])
