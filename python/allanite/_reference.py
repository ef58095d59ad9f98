"""Pure-NumPy twins of the estimators, written straight from the definitions.

Used by the tests (as the plain per-window recomputation every fast result is checked against) and
by the benchmarks (as the baseline a NumPy user would write). Not tuned, not public API.

Definitions (NIST SP 1065; paper 000): rate y_1..y_M at τ0 = 1/fs; angle x_0 = 0,
x_k = τ0·Σ_{i≤k}(y_i − ȳ); overlapping σ²(mτ0) = Σ_{k=0}^{N−2m−1} (x_{k+2m} − 2x_{k+m} + x_k)² /
(2 m² τ0² (N − 2m)), N = M + 1; classic: K = ⌊M/m⌋ cluster means, σ² = ½⟨(ȳ_{i+1} − ȳ_i)²⟩.
"""

from __future__ import annotations

import numpy as np


def angle_from_rate(y, fs, dtype=np.float64) -> np.ndarray:
    """x_0 = 0, x_k = τ0·Σ_{i≤k} (y_i − ȳ): the mean is removed before integrating."""
    y = np.asarray(y, dtype=dtype)
    x = np.empty(y.size + 1, dtype=dtype)
    x[0] = 0
    np.cumsum((y - y.mean()) / dtype(fs), out=x[1:])
    return x


def oavar_from_angle(x, fs, m) -> float:
    """Overlapping Allan variance from angle points at one m (the textbook double-difference sum)."""
    x = np.asarray(x)
    n = x.size
    tau0 = 1.0 / fs
    d = x[2 * m :] - 2 * x[m : n - m] + x[: n - 2 * m]
    return float(np.sum(d * d) / (2.0 * m * m * tau0 * tau0 * (n - 2 * m)))


def avar_from_angle(x, fs, m) -> float:
    """Classic (non-overlapping) Allan variance from angle points at one m."""
    x = np.asarray(x)
    tau0 = 1.0 / fs
    k = (x.size - 1) // m
    xs = x[: k * m + 1 : m]
    d = xs[2:] - 2 * xs[1:-1] + xs[:-2]
    return float(np.sum(d * d) / (2.0 * m * m * tau0 * tau0 * (k - 1)))


def avar_reference(y, fs, ms, estimator="oavar", dtype=np.float64) -> np.ndarray:
    """Static Allan variance of rate samples at each m (``dtype=np.longdouble`` for extra digits)."""
    x = angle_from_rate(y, fs, dtype=dtype)
    f = oavar_from_angle if estimator == "oavar" else avar_from_angle
    return np.array([f(x, dtype(fs), int(m)) for m in ms])


def davar_reference(y, fs, window, hop, ms, estimator="oavar", dtype=np.float64) -> np.ndarray:
    """Plain per-window recomputation: column j = static Allan variance of y[j·hop : j·hop + window]."""
    y = np.asarray(y, dtype=np.float64)
    n_win = (y.size - window) // hop + 1
    out = np.empty((len(ms), n_win))
    for j in range(n_win):
        s = j * hop
        out[:, j] = avar_reference(y[s : s + window], fs, ms, estimator, dtype=dtype)
    return out


def davar_prefix(y, fs, window, hop, ms) -> np.ndarray:
    """The vectorised NumPy DAVAR a user would write: one global cumulative angle, then per m the
    squared second differences and their window sums by differences of a cumulative sum.

    Fast, but both cumulative sums drift and cancel: it is the benchmark baseline, not a reference.
    """
    x = angle_from_rate(y, fs)
    n = x.size
    tau0 = 1.0 / fs
    starts = np.arange(0, y.size - window + 1, hop)
    out = np.empty((len(ms), starts.size))
    for i, m in enumerate(ms):
        m = int(m)
        d = x[2 * m :] - 2 * x[m : n - m] + x[: n - 2 * m]
        c = np.concatenate(([0.0], np.cumsum(d * d)))
        terms = window + 1 - 2 * m
        out[i] = (c[starts + terms] - c[starts]) / (2.0 * m * m * tau0 * tau0 * terms)
    return out


def angle_term_sums(blocks, starts, off_w, off_r, q_exp, plan, classic) -> np.ndarray:
    """NumPy twin of the Dask static kernel (``allanite.estimators.allan.angle_term_sums``, which
    ``allanite.dask.avar`` used as NumPy code before the Rust kernel): Σ (X[i+2m] − 2X[i+m] + X[i])² in
    quanta² per plan item (m, i0, i1) and axis, X the exact angle of the rate ``blocks`` ((samples,
    axes); consecutive ones form runs) in quanta 2^q_exp — int64 cumulative sum of the whole quanta
    from ``off_w``, float cumulative sum of the remainders from 0 plus ``off_r``. About ten NumPy passes
    per factor."""
    runs = []  # (first sample, X whole, X remainder) over runs of consecutive blocks
    j = 0
    while j < len(blocks):
        j1 = j
        while j1 + 1 < len(blocks) and starts[j1 + 1] == starts[j1] + len(blocks[j1]):
            j1 += 1
        y = np.concatenate(blocks[j : j1 + 1]) if j1 > j else blocks[j]
        rest = np.ldexp(np.asarray(y, dtype=np.float64), -q_exp)
        whole = np.rint(rest)
        rest -= whole
        xw = np.empty((y.shape[0] + 1, y.shape[1]), dtype=np.int64)
        xr = np.empty((y.shape[0] + 1, y.shape[1]), dtype=np.float64)
        xw[0], xr[0] = off_w[j], off_r[j]
        np.cumsum(whole.astype(np.int64), axis=0, out=xw[1:])
        del whole
        np.cumsum(rest, axis=0, out=xr[1:])
        del y, rest
        xw[1:] += np.asarray(off_w[j], dtype=np.int64)
        xr[1:] += np.asarray(off_r[j], dtype=np.float64)
        runs.append((int(starts[j]), xw, xr))
        j = j1 + 1

    def angle(lo: int, hi: int, step: int):
        for s, xw, xr in runs:
            if s <= lo and hi - s <= xw.shape[0]:
                return xw[lo - s : hi - s : step], xr[lo - s : hi - s : step]
        raise ValueError(f"angle points {lo}:{hi} are not in the blocks given")

    out = np.zeros((len(plan), runs[0][1].shape[1]))
    for p, (m, i0, i1) in enumerate(plan):
        step = m if classic else 1
        if classic:
            i0 = -(-i0 // m) * m  # classic terms start at multiples of m
        if i0 >= i1:
            continue
        a_w, a_r = angle(i0, i1, step)
        b_w, b_r = angle(i0 + m, i1 + m, step)
        c_w, c_r = angle(i0 + 2 * m, i1 + 2 * m, step)
        dw = c_w - 2 * b_w + a_w  # exact (int64)
        d = dw.astype(np.float64) + ((c_r - b_r) - (b_r - a_r))
        out[p] = np.einsum("ij,ij->j", d, d)
    return out


def nbs14_1000() -> np.ndarray:
    """The NBS14 / NIST SP 1065 1000-point test data (docs/FORMULAS.md §2.4): n₀ = 1234567890,
    n_{i+1} = 16807·n_i mod 2147483647, y_i = n_i / 2147483647, the seed being the first sample."""
    n = 1234567890
    out = np.empty(1000)
    for i in range(1000):
        out[i] = n / 2147483647.0
        n = (16807 * n) % 2147483647
    return out


# --------------------------------------------------------------------------------------------------
# Theo1, TheoBR, TheoH and the dynamic TheoH of paper 001 (DHVAR, DHVAR-A)
#
# Conventions (checked against the reference values in tests/test_theo_reference.py):
#   * x_0 … x_{N−1}: N phase/angle points at spacing τ0 (a rate record of M samples gives N = M + 1).
#   * Record length T = (N − 1)·τ0 (= M·τ0, paper 001's "T = N_x·τ0" with N_x rate samples).
#   * Theo1(m): even m, 10 ≤ m ≤ N − 1, belongs to τ = 0.75·m·τ0; Stable32's "Thêo1 #" = (N − m)·m/2.
#   * kf = (n+1)⁻¹ Σ_{i=0}^{n} AVAR(9+3i) / Theo1(12+4i), AVAR the *overlapping* Allan variance of the
#     same N phase points. n = ⌊0.1·N/3 − 3⌋ (Howe's TheoBR, "textbook"; NBS14: kf = 1.0856664) or
#     n = ⌊N/6 − 3⌋ (what Stable32 uses for its Thêo1 "Alpha = auto/BR" run and for the Thêo1 column
#     of its ThêoH table: PHASE.DAT kf = 0.6027870, Sr87 kf = 1.3491114 vs 1.3170812 textbook).
#   * TheoH: AVAR for m = 1 … k_m with k_m = ⌊0.1·(N − 1)⌋, i.e. k = k_m·τ0 the largest τ ≤ 10 % of T;
#     TheoBR for even m with 0.75·m·τ0 > k (10 ≤ m ≤ N − 1), reaching 0.75·(N − 1)·τ0.
# --------------------------------------------------------------------------------------------------

from fractions import Fraction  # noqa: E402
from typing import NamedTuple  # noqa: E402

#: Nominal Theo1 bias AVAR/Theo1 per noise type α (Howe & Peppler 2003; Stable32 uses these to name
#: the noise type of a run from kf: geometric means of neighbours are the class boundaries).
THEO1_NOMINAL_BIAS = {2: 0.4, 1: 0.6, 0: 1.0, -1: 1.71, -2: 2.24}


def theo1_terms(n_points, m) -> int:
    """Number of squared terms in Theo1(m) of N phase points, (N − m)·m/2 (Stable32's "Thêo1 #")."""
    return (int(n_points) - int(m)) * (int(m) // 2)


def theo1_from_angle(x, tau0, m, dtype=np.float64) -> float:
    """Theo1 variance at averaging factor m (τ = 0.75·m·τ0), the direct double sum of Howe & Peppler:

        Theo1(m) = 1 / (0.75·(N − m)·(m·τ0)²) · Σ_{i=0}^{N−m−1} Σ_{δ=0}^{m/2−1}
                   [(x_i − x_{i−δ+m/2}) + (x_{i+m} − x_{i+δ+m/2})]² / (m/2 − δ)

    x: N phase points; m even, 10 ≤ m ≤ N − 1. Vectorised over i for each δ; ``dtype=np.longdouble``
    for extra digits. Invariant to adding a constant or a linear ramp to x.
    """
    m = int(m)
    x = np.asarray(x, dtype=dtype)
    n = x.size
    if m % 2 or m < 10 or m > n - 1:
        raise ValueError(f"Theo1 needs an even m with 10 ≤ m ≤ N − 1 = {n - 1}, got m = {m}")
    h = m // 2
    i = np.arange(n - m)
    total = dtype(0)
    for d in range(h):
        t = (x[i] - x[i - d + h]) + (x[i + m] - x[i + d + h])
        total += np.sum(t * t) / dtype(h - d)
    return total / (dtype(0.75) * dtype(n - m) * (dtype(m) * dtype(tau0)) ** 2)


def theo1_reference(x, tau0, ms, dtype=np.float64) -> np.ndarray:
    """Theo1 variance at each (even) m of ``ms``; the τ of entry j is 0.75·ms[j]·τ0."""
    return np.array([theo1_from_angle(x, tau0, int(m), dtype=dtype) for m in ms])


def _oavar_tau0(x, tau0, m, dtype=np.float64):
    """Overlapping Allan variance of N phase points at m (same sum as oavar_from_angle, τ0 given)."""
    x = np.asarray(x, dtype=dtype)
    n = x.size
    if n - 2 * m < 1:
        raise ValueError(f"overlapping AVAR needs N − 2m ≥ 1, got N = {n}, m = {m}")
    d = x[2 * m :] - 2 * x[m : n - m] + x[: n - 2 * m]
    return np.sum(d * d) / (dtype(2) * dtype(m) ** 2 * dtype(tau0) ** 2 * dtype(n - 2 * m))


def _avar_tau0(x, tau0, m, dtype=np.float64):
    """Classic (stride m) Allan variance of N phase points at m: K = ⌊(N−1)/m⌋ cluster means."""
    x = np.asarray(x, dtype=dtype)
    k = (x.size - 1) // m
    if k < 2:
        raise ValueError(f"classic AVAR needs ⌊(N−1)/m⌋ ≥ 2, got N = {x.size}, m = {m}")
    xs = x[: k * m + 1 : m]
    d = xs[2:] - 2 * xs[1:-1] + xs[:-2]
    return np.sum(d * d) / (dtype(2) * dtype(m) ** 2 * dtype(tau0) ** 2 * dtype(k - 1))


def theobr_n(n_points, rule="textbook") -> int:
    """Last index n of the kf average for N phase points.

    ``"textbook"``: n = ⌊0.1·N/3 − 3⌋ (Howe, Tasset & Taylor; docs/FORMULAS.md §6.2), the AVAR m = 9 … 9+3n
    covering τ up to ≈ 10 % of T. ``"stable32"``: n = ⌊N/6 − 3⌋, AVAR m up to ≈ N/2 (found by
    reproducing Stable32's Thêo1/ThêoH tables; the same rule is noted in allantoolkit's docs for
    Stable32's Run/Plot functions). Computed in exact integer arithmetic.
    """
    n_points = int(n_points)
    if rule == "textbook":
        return (n_points - 90) // 30  # ⌊N/30 − 3⌋
    if rule == "stable32":
        return (n_points - 18) // 6  # ⌊N/6 − 3⌋
    raise ValueError(f"unknown kf rule {rule!r}; allowed: 'textbook', 'stable32'")


def theobr_kf(x, tau0, rule="textbook", dtype=np.float64) -> float:
    """TheoBR bias factor kf = (n+1)⁻¹ Σ_{i=0}^{n} OAVAR(m = 9+3i) / Theo1(m = 12+4i).

    Each ratio compares the overlapping Allan variance at τ = (9+3i)·τ0 with Theo1 at the same τ,
    0.75·(12+4i)·τ0. n from :func:`theobr_n` (needs n ≥ 0, i.e. N ≥ 90 textbook, N ≥ 18 Stable32).
    """
    x = np.asarray(x, dtype=dtype)
    n = theobr_n(x.size, rule)
    if n < 0:
        raise ValueError(f"TheoBR needs n = {n} ≥ 0 (N = {x.size} phase points too few for rule {rule!r})")
    ratios = [
        _oavar_tau0(x, tau0, 9 + 3 * i, dtype) / theo1_from_angle(x, tau0, 12 + 4 * i, dtype) for i in range(n + 1)
    ]
    return np.sum(np.array(ratios, dtype=dtype)) / dtype(n + 1)


def theobr_reference(x, tau0, ms, rule="textbook", dtype=np.float64) -> np.ndarray:
    """TheoBR variance kf·Theo1(m) at each (even) m of ``ms`` (τ = 0.75·m·τ0); kf from :func:`theobr_kf`."""
    kf = theobr_kf(x, tau0, rule, dtype)
    return kf * theo1_reference(x, tau0, ms, dtype)


class TheoH(NamedTuple):
    """A TheoH result: averaging factor, τ, variance and which estimator gave each entry."""

    m: np.ndarray  # averaging factor (AVAR: τ = m·τ0; TheoBR: τ = 0.75·m·τ0)
    tau: np.ndarray
    var: np.ndarray
    source: np.ndarray  # "oavar" | "avar" (short τ) or "theobr" (long τ)
    kf: float


def theoh_switch(n_points, fraction=Fraction(1, 10)) -> int:
    """k_m = ⌊fraction·(N − 1)⌋: k = k_m·τ0 is the largest AVAR τ ≤ fraction·T, T = (N − 1)·τ0."""
    f = Fraction(fraction)
    return int((int(n_points) - 1) * f.numerator // f.denominator)


def theoh_grid(n_points, fraction=Fraction(1, 10)):
    """Default TheoH grid for N phase points: AVAR at m = 1 … k_m, TheoBR at every even m with
    0.75·m > k_m (10 ≤ m ≤ N − 1). Returns (avar_ms, theo_ms)."""
    k_m = theoh_switch(n_points, fraction)
    avar_ms = np.arange(1, k_m + 1)
    theo_ms = np.array([m for m in range(10, int(n_points), 2) if 3 * m > 4 * k_m], dtype=np.int64)
    return avar_ms, theo_ms


def theoh_reference(
    x, tau0, avar_ms=None, theo_ms=None, short="oavar", rule="textbook", fraction=Fraction(1, 10), dtype=np.float64
) -> TheoH:
    """TheoH (Howe 2006; paper 001): Allan variance for τ ≤ k, TheoBR beyond.

    k = k_m·τ0 with k_m = ⌊0.1·(N − 1)⌋ (largest τ ≤ 10 % of T = (N − 1)·τ0). Short τ: every m of
    ``avar_ms`` with m ≤ k_m, estimator ``short`` ("oavar" for TheoH/DHVAR, "avar" — classic Allan —
    for paper 001's DHVAR-A). Long τ: every even m of ``theo_ms`` with 10 ≤ m ≤ N − 1 and
    0.75·m·τ0 > k, value kf·Theo1(m) at τ = 0.75·m·τ0 (kf always from the overlapping AVAR, rule
    ``rule``). Entries outside those ranges are dropped. Defaults: :func:`theoh_grid`. Sorted by τ.
    """
    x = np.asarray(x, dtype=dtype)
    n = x.size
    k_m = theoh_switch(n, fraction)
    d_avar, d_theo = theoh_grid(n, fraction)
    avar_ms = d_avar if avar_ms is None else np.asarray(avar_ms, dtype=np.int64)
    theo_ms = d_theo if theo_ms is None else np.asarray(theo_ms, dtype=np.int64)
    avar_ms = [int(m) for m in avar_ms if 1 <= m <= k_m]
    theo_ms = [int(m) for m in theo_ms if m % 2 == 0 and 10 <= m <= n - 1 and 3 * m > 4 * k_m]
    if short not in ("oavar", "avar"):
        raise ValueError(f"unknown short-τ estimator {short!r}; allowed: 'oavar', 'avar'")
    f = _oavar_tau0 if short == "oavar" else _avar_tau0
    kf = theobr_kf(x, tau0, rule, dtype) if theo_ms else np.nan
    ms = avar_ms + theo_ms
    tau = [m * tau0 for m in avar_ms] + [0.75 * m * tau0 for m in theo_ms]
    var = [f(x, tau0, m, dtype) for m in avar_ms] + [kf * theo1_from_angle(x, tau0, m, dtype) for m in theo_ms]
    source = [short] * len(avar_ms) + ["theobr"] * len(theo_ms)
    order = np.argsort(np.array(tau, dtype=np.float64), kind="stable")
    return TheoH(
        np.array(ms, dtype=np.int64)[order],
        np.array(tau, dtype=np.float64)[order],
        np.array(var, dtype=dtype)[order],
        np.array(source)[order],
        kf,
    )


class DHVAR(NamedTuple):
    """Dynamic TheoH: one column of variances per window (rows follow m/tau/source)."""

    m: np.ndarray
    tau: np.ndarray
    source: np.ndarray
    var: np.ndarray  # shape (len(tau), windows)
    kf: np.ndarray  # kf of each window


def dhvar_reference(
    y, fs, window, hop, avar_ms=None, theo_ms=None, estimator="theoh", rule="textbook", dtype=np.float64
) -> DHVAR:
    """Dynamic TheoH of paper 001 (Zhu, Wang, Chen, Xue, J. BUAA 2017): DAVAR with TheoH per window.

    Window j holds the rate samples y[j·hop : j·hop + window] (paper 001: a rectangular window of
    L = 401 samples, slid with overlap, output at its centre); their angle (angle_from_rate) has
    N = window + 1 points and T = window·τ0. In each window, independently:
      * ``estimator="theoh"`` (DHVAR): overlapping Allan variance for τ = m·τ0 ≤ k, k the largest
        τ ≤ 10 % of T (paper: "k为τ≤10%T条件下的最大值");
      * ``estimator="theoh_a"`` (DHVAR-A): the classic (non-overlapping) Allan variance there instead
        (paper: "DHVAR-A为经典Allan方差与TheoBR方差混合");
      * beyond k: TheoBR = kf·Theo1 at τ = 0.75·m·τ0 for even m, 0.75·m·τ0 > k, up to m = N − 1
        (τ up to 0.75·T); kf re-estimated from the window's own data (overlapping AVAR both ways).
    The paper fixes no τ grid (its DAVAR mentions τ_max = L/3; TheoH reaches 0.75·T): pass
    ``avar_ms``/``theo_ms`` or get :func:`theoh_grid` of N = window + 1. Plain per-window recomputation.
    """
    y = np.asarray(y, dtype=np.float64)
    short = {"theoh": "oavar", "theoh_a": "avar"}.get(estimator)
    if short is None:
        raise ValueError(f"unknown estimator {estimator!r}; allowed: 'theoh', 'theoh_a'")
    n_win = (y.size - window) // hop + 1
    cols, kfs, first = [], [], None
    for j in range(n_win):
        s = j * hop
        x = angle_from_rate(y[s : s + window], fs, dtype=dtype)
        r = theoh_reference(x, 1.0 / fs, avar_ms, theo_ms, short=short, rule=rule, dtype=dtype)
        first = first or r
        cols.append(r.var)
        kfs.append(r.kf)
    var = np.array(cols, dtype=dtype).T if cols else np.empty((0, 0))
    assert first is not None, "at least one window"
    return DHVAR(first.m, first.tau, first.source, var, np.array(kfs))


def theo1_edf(alpha, m, n_points) -> float:
    """EDF of Theo1 (Howe & Peppler 2003; NIST SP 1065 §5.2.x, Riley's "CI2" note), r = 0.75·m:

      α =  2 (WPM):  [0.86 (N+1)(N − 4r/3) / (N − r)] · [r / (r + 1.14)]
      α =  1 (FPM):  [(4.798 N² − 6.374 N r + 12.387 r) / (√(r + 36.6) (N − r))] · [r / (r + 0.3)]
      α =  0 (WFM):  [(4.1 N + 0.8)/r − (3.1 N + 6.5)/N] · [r^1.5 / (r^1.5 + 5.2)]
      α = −1 (FFM):  [(2 N² − 1.3 N r − 3.5 r) / (N r)] · [r³ / (r³ + 2.3)]
      α = −2 (RWFM): [(4.4 N − 2) / (2.9 r)] · [((4.4 N − 1)² − 8.6 r (4.4 N − 1) + 11.4 r²) / (4.4 N − 3)²]

    N = number of phase points (reproduces Stable32's Thêo1 and ThêoH bounds on Sr87 with χ²
    intervals; N − 1 does not). The same ν serves TheoBR (kf is treated as exact).
    """
    r = 0.75 * float(m)
    n = float(n_points)
    if alpha == 2:
        return 0.86 * (n + 1) * (n - 4 * r / 3) / (n - r) * (r / (r + 1.14))
    if alpha == 1:
        return (4.798 * n * n - 6.374 * n * r + 12.387 * r) / (np.sqrt(r + 36.6) * (n - r)) * (r / (r + 0.3))
    if alpha == 0:
        return ((4.1 * n + 0.8) / r - (3.1 * n + 6.5) / n) * (r**1.5 / (r**1.5 + 5.2))
    if alpha == -1:
        return (2 * n * n - 1.3 * n * r - 3.5 * r) / (n * r) * (r**3 / (r**3 + 2.3))
    if alpha == -2:
        a = 4.4 * n
        return (a - 2) / (2.9 * r) * (((a - 1) ** 2 - 8.6 * r * (a - 1) + 11.4 * r * r) / (a - 3) ** 2)
    raise ValueError(f"Theo1 EDF is defined for α in 2 … −2, got {alpha!r}")


def theo1_noise_type(kf) -> int:
    """Stable32's run-wide noise type from kf: the nominal bias (THEO1_NOMINAL_BIAS) nearest in log."""
    alphas = sorted(THEO1_NOMINAL_BIAS, reverse=True)  # 2, 1, 0, −1, −2: bias increasing
    for a, b in zip(alphas[:-1], alphas[1:]):
        if kf < np.sqrt(THEO1_NOMINAL_BIAS[a] * THEO1_NOMINAL_BIAS[b]):
            return a
    return alphas[-1]
