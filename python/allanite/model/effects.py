"""Effects the five-term noise model lacks — one registry entry each.

An effect is what :func:`allanite.refine` may add to a fitted model when the residual asks for it:
its parameters with their units, and how it is found — by its Allan-variance signature on the curve
(``kind="curve"``: an amplitude fitted linearly, one nonlinear parameter searched on a grid), or in
the samples along time (``kind="time"``: change points). Adding an effect is one entry here.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._display import fmt, fmt_ci
from ..errors import ParameterError
from ._sinc import SINC_ORDERS, sinc_autocorrelation, sinc_cutoff, sinc_order

__all__ = [
    "Effect",
    "EFFECTS",
    "gm_avar",
    "sinusoid_avar",
    "filtered_white_avar",
    "filter_autocorrelation",
    "filter_cutoff",
    "butterworth_terms",
    "butterworth_order",
    "drift_avar",
    "describe",
    "param_units",
    "channel_units",
    "format_param",
    "format_params",
    "FILTERS",
    "BUTTERWORTH_ORDERS",
    "SINC_ORDERS",
    "sinc_order",
    "CASCADE_SPANS",
    "RESONANCE_Q",
    "resonance_avar",
]

#: Low-pass filters a "bandwidth" effect can be: a single pole (first-order IIR, impulse-invariant:
#: a = e^{−2πf_c/f_s}), a moving average of L taps (the boxcar decimation filter of MEMS parts), a Bartlett
#: (triangular, two cascaded moving averages: 2L − 1 taps), and a boxcar of any span D (a moving average a
#: part computes at its internal rate and the host reads at the output rate, so D·f_s need not be whole:
#: the samples' autocorrelation is the triangle (1 − l/(D·f_s))₊; −3 dB at 0.443/D), and Butterworths of order
#: 2 to 6 ("butterworth2" … "butterworth6": the digital filter ``scipy.signal.butter(n, f_c, fs=f_s)``: bilinear,
#: prewarped, −3 dB at f_c exactly — the 2nd- to 6th-order anti-alias low-passes of MEMS, tactical and
#: navigation gyros; one parameter, f_c; the order is in the kind's name, as every other kind's shape is), and
#: sinc^k of order 2 to 5 ("sinc2" … "sinc5": a CIC decimator read at its output rate, k boxcars of span D,
#: the samples' autocorrelation the B-spline M_2k(l/D); :mod:`allanite.model._sinc`).
FILTERS: tuple[str, ...] = (
    ("single_pole", "moving_average", "bartlett", "boxcar")
    + tuple(f"sinc{k}" for k in SINC_ORDERS)
    + ("single_pole+boxcar",)
    + tuple(f"butterworth{n}" for n in (2, 3, 4, 5, 6))
)
#: Orders of the Butterworth kinds of :data:`FILTERS` ("butterworth2" … "butterworth6").
BUTTERWORTH_ORDERS = (2, 3, 4, 5, 6)
#: Spans (samples) of the boxcar a single pole may follow ("single_pole+boxcar:<span>": a filter added after
#: a part's own averaging, e.g. an anti-alias stage or a user's low-pass on the logged rate).
CASCADE_SPANS = (1.2, 1.5, 2.0)


def gm_avar(tau: np.ndarray | float, tc: float) -> np.ndarray:
    """Allan variance of a first-order Gauss–Markov rate of unit variance and correlation time ``tc``:
    (T_c/τ)²·(2τ/T_c − 3 + 4e^{−τ/T_c} − e^{−2τ/T_c}) (IEEE Std 952 App. C)."""
    tau = np.asarray(tau, dtype=np.float64)
    x = tau / tc
    big = (2 * x - 3 + 4 * np.exp(-x) - np.exp(-2 * x)) / np.maximum(x, 1e-300) ** 2
    small = (2.0 / 3.0) * x - 0.5 * x * x + (7.0 / 30.0) * x**3  # series: no cancellation for x ≪ 1
    return np.where(x < 1e-2, small, big)


def sinusoid_avar(tau: np.ndarray | float, f0: float, fs: float | None = None) -> np.ndarray:
    """Allan variance of a unit-amplitude rate sinusoid of frequency ``f0``: sin⁴(πf0τ)/(πf0τ)² in continuous
    time; with ``fs``, exact for samples at that rate (averages of m = τ·f_s samples, ν = f0/f_s):
    sin⁴(πνm)/(m·sin πν)², the same to O(ν²) for f0 ≪ f_s and right up to f_s/2, where the continuous form
    is off by (πν/sin πν)² (1.23× at f_s/4) — a line above a quarter of the rate is then seen at the
    shortest τ of a curve that starts at m = 2 (nulls at even m for a line at f_s/2)."""
    tau = np.asarray(tau, dtype=np.float64)
    if fs is None:
        u = np.pi * f0 * tau
        return np.sin(u) ** 4 / u**2
    nu = f0 / fs
    m = np.maximum(1.0, np.round(tau * fs))
    return np.sin(np.pi * nu * m) ** 4 / (m * np.sin(np.pi * nu)) ** 2


def butterworth_order(kind: str) -> int:
    """The order of a Butterworth kind of :data:`FILTERS` ("butterworth4" → 4); 0 for any other kind."""
    tail = kind[len("butterworth") :] if kind.startswith("butterworth") else ""
    return int(tail) if tail.isdigit() and int(tail) in BUTTERWORTH_ORDERS else 0


def butterworth_terms(order: int, fc: float, fs: float) -> tuple[float, np.ndarray, np.ndarray, float]:
    """The autocorrelation of unit-DC-gain Butterworth filtered unit white noise in closed form:
    (r(0), C, p, d) with r(l) = Σ_j C_j·p_j^l + d·[l = 1] for l ≥ 1 (``p`` the filter's nonzero poles, distinct;
    ``C`` complex conjugates where the poles are; ``d`` the lag-1 term of a pole at z = 0, which an odd order
    has at f_c = f_s/4, else 0).

    The filter is ``scipy.signal.butter(order, fc, fs=fs)``, H(z) = k·Π(z − z_i)/Π(z − p_i). For l ≥ 1,
    r(l) = Σ_n h(n)h(n + l) is the sum of the residues of H(z)·H(1/z)·z^{l−1} inside the unit circle, at the
    poles: r(l) = Σ_j D_j·p_j^{l−1}, D_j = A_j·H(1/p_j), A_j = k·Π_i(p_j − z_i)/Π_{i≠j}(p_j − p_i); so
    C_j = D_j/p_j, and a pole at 0 (|p| < 1e-8) gives d = D_j. r(0) = H(1)² − 2Σ_{l≥1} r(l). All divided by
    H(1)² (= 1 up to rounding) so that Σ_l r(|l|) = 1."""
    if order not in BUTTERWORTH_ORDERS:
        raise ParameterError(f"Butterworth order {order!r}: must be one of {BUTTERWORTH_ORDERS}")
    if not 0.0 < fc < fs / 2.0:
        raise ParameterError(f"Butterworth cutoff {fc!r} Hz: must lie in (0, fs/2 = {fs / 2.0!r})")
    return _butterworth_terms(int(order), float(fc), float(fs))


@functools.lru_cache(maxsize=1024)
def _butterworth_terms(order: int, fc: float, fs: float) -> tuple[float, np.ndarray, np.ndarray, float]:
    """:func:`butterworth_terms`, remembered (a bandwidth search asks for the same cutoffs on every curve it fits:
    the record's, the held-out parts', a removal's; SciPy's filter design costs ~2 ms a call). Read-only arrays."""
    from scipy import signal  # here, not at import: `import allanite` stays free of scipy.signal

    zeros, poles, k = signal.butter(order, fc, fs=fs, output="zpk")
    b, a = signal.zpk2tf(zeros, poles, k)
    dc2 = float((b.sum() / a.sum()) ** 2)
    # H at z = 1/p_j: b and a as polynomials in z⁻¹, evaluated at z⁻¹ = p_j
    h_inv = np.polyval(b[::-1], poles) / np.polyval(a[::-1], poles)
    others = poles[:, None] - poles[None, :]  # [j, i]: p_j − p_i
    np.fill_diagonal(others, 1.0)
    d = k * np.prod(poles[:, None] - zeros[None, :], axis=1) / np.prod(others, axis=1) * h_inv / dc2
    at_zero = np.abs(poles) < 1e-8
    lag1 = float(d[at_zero].sum().real)
    poles, d = poles[~at_zero], d[~at_zero]
    c = d / poles
    r0 = 1.0 - 2.0 * (lag1 + float((d / (1.0 - poles)).sum().real))
    c.flags.writeable = poles.flags.writeable = False
    return r0, c, poles, lag1


def _geometric_avar(rho: np.ndarray, m: np.ndarray) -> np.ndarray:
    """σ²(m) of samples with autocorrelation ρ^|l| (complex ρ, |ρ| < 1: the real part taken by the caller), per
    ρ (rows) and m (columns): (Var S_m − Cov(S_m, next S_m))/m², closed geometric sums (see
    :func:`resonance_avar`)."""
    rho = np.asarray(rho, dtype=np.complex128)[:, None]
    rm = np.exp(m[None, :] * np.log(rho))
    one = 1.0 - rho
    var = m * (1.0 + rho) / one - 2.0 * rho * (1.0 - rm) / one**2
    cov = rho * (1.0 - rm) ** 2 / one**2
    return (var - cov) / (m * m)


def filter_autocorrelation(kind: str, p: float, fs: float) -> np.ndarray:
    """Normalised autocorrelation r(l), l = 0, 1, …, of unit-DC-gain filtered white noise: Σ_l r(|l|) = 1.

    ``kind`` one of :data:`FILTERS`; ``p`` the cutoff (Hz) for ``"single_pole"`` and the Butterworths, the
    length L (taps of one moving average) for the FIRs, the span D·f_s (samples, ≥ 1, any real) for
    ``"boxcar"``, each boxcar's span in output samples (≥ 1/k, any real) for a sinc^k (``"sinc2"`` …)."""
    if kind == "single_pole":
        a = math.exp(-2.0 * math.pi * p / fs)
        n = int(min(200_000, math.ceil(40.0 / max(1.0 - a, 1e-9)))) + 1
        return (1.0 - a) / (1.0 + a) * a ** np.arange(n, dtype=np.float64)
    order = butterworth_order(kind)
    if order and p >= fs / 2.0:  # its limit there: H → 1, no filter
        return np.ones(1)
    if order:  # to where the poles' terms fall below 1e-17 of r(0)
        r0, c, poles, lag1 = butterworth_terms(order, p, fs)
        decay = max(float(np.max(np.abs(poles))), 1e-300)
        n = int(min(200_000, math.ceil(math.log(1e-17) / math.log(decay)) if decay < 1.0 else 200_000)) + 2
        lags = np.arange(1, n, dtype=np.float64)
        tail = (c[None, :] * np.exp(lags[:, None] * np.log(poles.astype(np.complex128))[None, :])).sum(axis=1).real
        tail[0] += lag1
        return np.concatenate([[r0], tail])
    if sinc_order(kind):
        return sinc_autocorrelation(sinc_order(kind), p)
    if kind == "boxcar":
        span = max(1.0, float(p))
        tri = 1.0 - np.arange(int(math.ceil(span)), dtype=np.float64) / span
        return tri / (tri[0] + 2.0 * tri[1:].sum())
    if kind.startswith("single_pole+boxcar:"):
        # the cascade's autocorrelation: the two (two-sided, unit-sum) autocorrelations convolved
        r_pole = filter_autocorrelation("single_pole", p, fs)
        r_box = filter_autocorrelation("boxcar", float(kind.split(":", 1)[1]), fs)
        both = np.convolve(np.concatenate([r_pole[:0:-1], r_pole]), np.concatenate([r_box[:0:-1], r_box]))
        return both[both.size // 2 :]
    taps = max(1, int(round(p)))
    h = np.full(taps, 1.0 / taps)
    if kind == "bartlett":
        h = np.convolve(h, h)
    r = np.correlate(h, h, mode="full")[h.size - 1 :]
    return r


def filter_cutoff(kind: str, p: float, fs: float) -> float:
    """−3 dB frequency (Hz) of a filter of :data:`FILTERS` (``p`` as in :func:`filter_autocorrelation`); for a
    boxcar the continuous filter's, 0.4430/D (sinc² = ½), and a sinc^k's, before the output sampling aliases it."""
    if sinc_order(kind):
        return sinc_cutoff(sinc_order(kind), p, fs)
    if kind == "single_pole" or butterworth_order(kind):  # a Butterworth's prewarped cutoff: −3 dB at f_c exactly
        return float(p)
    if kind == "boxcar":
        return float(0.44295 * fs / max(1.0, float(p)))
    # any other kind (the FIRs, a cascade): where the sampled filter's power falls to half
    r = filter_autocorrelation(kind, p, fs)
    f = np.linspace(0.0, fs / 2.0, 4097)
    lags = np.arange(1, r.size)
    power = r[0] + 2.0 * np.cos(2.0 * np.pi * np.outer(f / fs, lags)) @ r[1:]
    below = np.flatnonzero(power <= 0.5 * power[0])
    if not below.size:
        return float(fs / 2.0)
    j = int(below[0])
    if j == 0:
        return 0.0
    # linear between the two grid frequencies around the half-power point
    p0, p1, half = power[j - 1], power[j], 0.5 * power[0]
    return float(f[j - 1] + (f[j] - f[j - 1]) * (p0 - half) / (p0 - p1))


def filtered_white_avar(tau: np.ndarray | float, kind: str, p: float, fs: float) -> np.ndarray:
    """Allan variance of low-pass filtered white rate noise per unit N² — exact in discrete time.

    σ²(m) = (1/2m²)·Σ_l A_m(l)·R(l) with A_m(l) = 2·tri_m(l) − tri_m(l − m) − tri_m(l + m) (tri_m(l) =
    max(0, m − |l|): the autocorrelation of the Allan kernel of m ones then m minus ones) and R the
    autocorrelation of the filtered samples; N² = σ²_w·τ0 of the white input. Unity DC gain, so the curve
    tends to N²/τ for τ well above 1/f_c (the filter only reshapes the shortest τ). For a Butterworth
    R(l) = Σ_j C_j·p_j^|l| beyond lag 0 (:func:`butterworth_terms`), so the sum is closed: (r(0) − Σ C_j)/m plus
    Σ_j C_j times the geometric sums of :func:`resonance_avar` at ρ = p_j; at f_c ≥ f_s/2 its limit (the poles
    meet the n-fold zero at z = −1: no filter), N²/τ."""
    tau = np.atleast_1d(np.asarray(tau, dtype=np.float64))
    m = np.maximum(1.0, np.round(tau * fs))
    order = butterworth_order(kind)
    if order and p >= fs / 2.0:  # its limit there: H → 1, white noise
        return fs / m
    if order:  # geometric autocorrelation: closed sums, white part r(0) − Σ C_j at lag 0
        r0, c, poles, lag1 = butterworth_terms(order, p, fs)
        s2 = (r0 - c.sum().real) / m + (c[:, None] * _geometric_avar(poles, m)).sum(axis=0).real
        return (s2 + (2.0 * m - 3.0) * lag1 / (m * m)) * fs  # a lag-1 term d: A_m(±1) = 2m − 3
    r = filter_autocorrelation(kind, p, fs)
    lag = np.arange(r.size, dtype=np.float64)
    # A_m(l) at the lags l ≥ 0 (tri_m(l + m) = 0 there): 2m − 3l wherever m reaches the last lag, the triangles
    # only on the rows of shorter m — the same whole numbers, so the same sum
    a = np.subtract.outer(2.0 * m, 3.0 * lag)
    short = np.flatnonzero(m < lag[-1])
    if short.size:
        ms = m[short, None]
        a[short] = 2.0 * np.maximum(0.0, ms - lag) - np.maximum(0.0, ms - np.abs(lag - ms))
    w = np.full(r.size, 2.0)
    w[0] = 1.0
    s = a @ (w * r)
    return s / (2.0 * m * m) * fs  # σ_w² = N²·f_s


#: Quality factors a "resonance" is searched at (Q = f_r / full width at half maximum of its PSD): a hump,
#: not a roll-off (Q ≥ 2; a broad low-Q bump near the bandwidth is what the bandwidth kinds describe).
RESONANCE_Q = (2.0, 4.0, 8.0, 16.0)


def resonance_avar(tau: np.ndarray | float, f_r: float, q: float, fs: float) -> np.ndarray:
    """Allan variance of unit-variance narrowband rate noise at ``f_r`` (Hz) with quality factor ``q`` —
    exact in discrete time for samples at ``fs``.

    The noise's autocorrelation is R(l) = Re ρ^|l|, ρ = e^{−πf_r/(q·f_s)}·e^{i2πf_r/f_s} (a Lorentzian pair of
    PSD peaks at ±f_r, full width f_r/q: a resonance driven by broadband noise, or a hump of vibration).
    With S_m the sum of m samples, σ²(m) = (Var S_m − Cov(S_m, next S_m))/m², both linear in R, so closed
    geometric sums in ρ: Var = m(1 + ρ)/(1 − ρ) − 2ρ(1 − ρ^m)/(1 − ρ)², Cov = ρ(1 − ρ^m)²/(1 − ρ)², real
    part taken."""
    tau = np.atleast_1d(np.asarray(tau, dtype=np.float64))
    m = np.maximum(1.0, np.round(tau * fs))
    rho = complex(
        math.exp(-math.pi * f_r / (q * fs)) * math.cos(2 * math.pi * f_r / fs),
        math.exp(-math.pi * f_r / (q * fs)) * math.sin(2 * math.pi * f_r / fs),
    )
    rm = np.exp(m * np.log(rho))
    one = 1.0 - rho
    var = m * (1.0 + rho) / one - 2.0 * rho * (1.0 - rm) / one**2
    cov = rho * (1.0 - rm) ** 2 / one**2
    return np.maximum(((var - cov) / (m * m)).real, 0.0)


def drift_avar(tau: np.ndarray | float, t_const: float, fs: float, n: int) -> np.ndarray:
    """Overlapping Allan variance of a unit warm-up drift e^{−t/T} sampled at ``fs`` over ``n`` samples —
    exact: block means at stride j are e^{−jτ0/T}·g, g = (1 − q^m)/(m(1 − q)), q = e^{−τ0/T}, so the M = n − 2m + 1
    squared differences sum to g²(1 − q^m)²·(1 − q^{2M})/(1 − q²)."""
    tau = np.atleast_1d(np.asarray(tau, dtype=np.float64))
    m = np.maximum(1.0, np.round(tau * fs))
    q = math.exp(-1.0 / (fs * t_const))
    big_m = np.maximum(1.0, n - 2.0 * m + 1.0)
    g = -np.expm1(m * math.log(q)) / (m * (1.0 - q))
    geo = -np.expm1(2.0 * big_m * math.log(q)) / (1.0 - q * q)
    return g * g * np.expm1(m * math.log(q)) ** 2 * geo / (2.0 * big_m)


@dataclass(frozen=True)
class Effect:
    """One candidate effect.

    Attributes
    ----------
    name : str
        What ``candidates=`` and ``Step.effect`` call it.
    label : str
        Its name in words, for reports.
    kind : {"curve", "time"}
        Found on the Allan curve by its signature, or in the samples along time.
    params : tuple of (name, unit, meaning)
        The parameters a :class:`~allanite.model.refinement.Step` reports, in order; "rate unit" is
        the samples' rate unit. For curve effects the first is the amplitude (fitted linearly), the
        second the nonlinear parameter.
    description : str
        What it is, with its Allan-variance form.
    signature : callable, optional
        ``signature(tau, p, fs)``: Allan variance per unit amplitude squared (curve effects).
    alpha : callable, optional
        ``alpha(tau, p)``: the power-law noise type it resembles at each τ (for the estimates' EDF).
    search : callable, optional
        ``search(tau_min, tau_max)``: the grid of the nonlinear parameter to search.
    domain : str
        Where it is traced: "allan" (the curve's residual), "psd" (Welch periodogram), "time" (the samples
        along time), "channels" (other channels of the log).
    replaces : str, optional
        The term whose noise the effect's column carries ("N" for a bandwidth: the filtered white noise *is* the
        white rate noise, reported as N); the term's own column is zeroed — beside a Butterworth it stays, as
        white noise added after the filter (its ``floor``; :func:`allanite.model.refinement.curvefit.has_floor`),
        and beside another kind where the samples' spectrum shows a floor (:func:`.refinement._rolloff.floor_choice`).
    """

    name: str
    label: str
    kind: str
    params: tuple[tuple[str, str, str], ...]
    description: str
    signature: Callable[[np.ndarray, float, float], np.ndarray] | None = None
    alpha: Callable[[np.ndarray, float], np.ndarray] | None = None
    search: Callable[[float, float], np.ndarray] | None = None
    domain: str = "allan"
    replaces: str | None = None

    @property
    def param_names(self) -> tuple[str, ...]:
        """Names of the effect's parameters, in order."""
        return tuple(p[0] for p in self.params)


#: The candidates :func:`allanite.refine` may add, by name, in the order they are tried.
EFFECTS: dict[str, Effect] = {
    e.name: e
    for e in (
        Effect(
            "gauss_markov",
            "Gauss–Markov",
            "curve",
            (
                ("sigma", "rate unit", "standard deviation of the Gauss–Markov rate"),
                ("tc", "s", "correlation time T_c"),
            ),
            "first-order Gauss–Markov rate: σ²·(T_c/τ)²·(2τ/T_c − 3 + 4e^{−τ/T_c} − e^{−2τ/T_c}); a bump near "
            "τ ≈ 1.89·T_c, T_c searched in [5·τ_min, τ_max/4] so the bump lies inside the curve (a shorter T_c is "
            "a roll-off of the shortest τ: the bandwidth)",
            signature=lambda tau, tc, fs: gm_avar(tau, tc),
            alpha=lambda tau, tc: np.where(tau < tc, -2, 0),
            search=lambda tmin, tmax: np.geomspace(5.0 * tmin, tmax / 4.0, 40),
        ),
        Effect(
            "sinusoid",
            "sinusoid",
            "curve",
            (("amplitude", "rate unit", "amplitude A of the rate sinusoid"), ("f0", "Hz", "frequency f0")),
            "rate sinusoid A·sin(2πf0t): A²·sin⁴(πf0τ)/(πf0τ)², nulls at τ = k/f0. With samples it is found as a "
            "line of the Welch PSD (a bin above its neighbours' median beyond the F quantile of the Welch "
            "average against that median, Bonferroni over the bins), f0 refined on the periodogram, A from the "
            "line's power over its width (held in every fit of the curve; the least-squares A at f0 in "
            "evidence['coherent_amplitude']); "
            "on a curve only, f0 ≥ 2/τ_max so that two nulls fall inside it",
            signature=lambda tau, f0, fs: sinusoid_avar(tau, f0, fs),
            alpha=lambda tau, f0: np.zeros(np.asarray(tau).size, dtype=int),
            search=lambda tmin, tmax: np.geomspace(2.0 / tmax, 0.5 / tmin, 120),
            domain="psd",
        ),
        Effect(
            "bandwidth",
            "sensor bandwidth (low-pass)",
            "curve",
            (
                ("cutoff", "Hz", "−3 dB frequency of the low-pass on the rate noise"),
                (
                    "taps",
                    "samples",
                    "FIR length (moving average L, Bartlett 2L − 1; a boxcar's span D·f_s, any real; a sinc^k's "
                    "span per boxcar, 1 for a CIC read at its output rate); 0 for a single pole or a Butterworth",
                ),
                (
                    "floor",
                    "rate unit·√s",
                    "white rate noise added after the filter (the output's quantisation, a readout's noise), as N: "
                    "the N column beside the filtered one, 0 where there is none; beside a Butterworth always, beside "
                    "another kind only where the spectrum above f_s/4 shows one and the fit agrees with it",
                ),
            ),
            "the sensor's low-pass on its white rate noise (single pole, the moving-average/Bartlett FIR of a "
            "decimating MEMS part, a boxcar of any span read at the output rate, a CIC decimator's sinc^k of "
            "order 2 to 5, ``sinc2`` … ``sinc5``, or the Butterworth anti-alias "
            "stage of a MEMS or tactical gyro, orders 2 to 6, ``butterworth2`` … ``butterworth6``): "
            "N²·(1/2m²)·Σ_l A_m(l)·r(l)/τ0, exact in discrete time, in place of N²/τ — a "
            "roll-off of the shortest τ; the N it reports is the white noise before the filter. Beside a Butterworth "
            "(and beside another kind where the spectrum above f_s/4 shows a floor the fit agrees with) "
            "the N²/τ column stays, non-negative, as white noise added after the filter (``floor``: a digital "
            "part's quantised output adds a step Δ's Δ²/12 per sample, floor = Δ·√(τ0/12); a readout's noise): a "
            "steep filter's stop band is then flat, not a resonance. Accepted first, its parameter is searched "
            "again beside the terms later steps add",
            signature=None,
            alpha=lambda tau, p: np.zeros(np.asarray(tau).size, dtype=int),
            search=None,
            replaces="N",
        ),
        Effect(
            "resonance",
            "resonance (narrowband noise)",
            "curve",
            (
                ("sigma", "rate unit", "standard deviation of the narrowband rate noise"),
                ("f0", "Hz", "centre frequency f_r of its PSD hump"),
                ("q", "", "quality factor f_r / full width at half maximum (searched at 2, 4, 8, 16)"),
            ),
            "narrowband rate noise — a resonance driven by broadband noise, or a hump of vibration: "
            "autocorrelation σ²·e^{−πf_r·l/(Q·f_s)}·cos(2πf_r·l/f_s), Allan variance exact in discrete time "
            "(Σ_l A_m(l)·R(l)/2m²); a bump near τ ≈ 0.37/f_r with a dip beyond. A spectral line is the limit "
            "Q → ∞ (found in the PSD instead). f_r is searched at the short-τ end, from 0.05/τ_min to 0.49/τ_min "
            "(5–49 Hz at 100 Hz): a hump near the bandwidth; slower bumps are Gauss–Markov terms",
            signature=None,
            alpha=lambda tau, p: np.zeros(np.asarray(tau).size, dtype=int),
            search=lambda tmin, tmax: np.geomspace(0.05 / tmin, 0.49 / tmin, 24),
            domain="allan",
        ),
        Effect(
            "drift",
            "warm-up drift",
            "time",
            (("amplitude", "rate unit", "amplitude a of a·e^{−t/T} at t = 0"), ("T", "s", "time constant T")),
            "an exponential warm-up a·e^{−t/T} of the rate, fitted to block means along the record (T from "
            "L/200 to L/2; a constant slope stays the R term); its Allan variance in closed form",
            domain="time",
        ),
        Effect(
            "regression",
            "regression on another channel",
            "time",
            (
                ("channel", "", "name of the other channel (as passed in channels=)"),
                ("coefficient", "rate unit per channel unit", "sensitivity: g-sensitivity, temperature, coupling"),
                ("quadratic", "rate unit per channel unit²", "on (channel − mean)², slow channels, when kept"),
                ("rate_coefficient", "rate unit per (channel unit/s)", "on d(channel)/dt, slow channels, when kept"),
                ("lag_s", "s", "the rate follows the channel through a first-order lag, slow channels, when kept"),
            ),
            "the rate regressed on another channel of the log, removed before the noise fit. A fast channel "
            "(an accelerometer, a multi-position profile): least squares within 8 blocks in time (coefficient: "
            "the whole-record value), band by band (octaves) where the coupling differs across frequency "
            "(evidence['bands']). A slow channel (≥ 50 % of its variance between the blocks' means: a "
            "temperature): Whittle GLS against the record's own noise, with a quadratic, a d(channel)/dt term or "
            "a lag where their own tests keep them (allanite.model.channels, docs/channels.md)",
            domain="channels",
        ),
        Effect(
            "periodic",
            "family of spectral lines",
            "time",
            (
                (
                    "fundamentals",
                    "Hz",
                    "the family's generators: [f0] for harmonics k·f0, [f1, f2] for lines k·f1 + s·f2 (sidebands "
                    "±s·f2 around the multiples of f1)",
                ),
                ("lines", "", "lines in the family"),
                (
                    "rms",
                    "rate unit",
                    "RMS of the family's lines, √(Σ A_i²/2): the component removed in time with the power that "
                    "sinusoids found again at its own lines hold (a wandering phase; the removed part alone in "
                    "evidence['coherent_rms'])",
                ),
            ),
            "every significant line of the Welch PSD (Blackman–Harris, the neighbours' median, Bonferroni over the "
            "bins, at the line share of level) grouped into families on a lattice — harmonics k·f0, sidebands "
            "k·f1 ± s·f2, aliases folded — each family's lattice points tested where it predicts them, the "
            "frequencies refined on the samples (Gauss–Newton on the lines' offsets) and the family removed in time "
            "by least squares at them (allanite.model.periodic); held out, amplitudes and phases are refitted on "
            "the held-in blocks with the frequencies fixed. A line no family takes stays a sinusoid",
            domain="psd",
        ),
        Effect(
            "outliers",
            "impulsive noise (outliers)",
            "time",
            (
                ("rate", "", "share of the samples flagged"),
                (
                    "threshold",
                    "rate unit",
                    "a sample is flagged when its distance from the slow level exceeds this (noise white at the "
                    "shortest lag), else when the differences into and out of it both do, with opposite signs",
                ),
            ),
            "samples beyond what Gaussian noise predicts: clusters of first differences beyond 4–7 robust σ (per "
            "block; lattice-aware on quantised samples) against more than twice their Gaussian expectation "
            "(Poisson, Bonferroni over the cuts, at the outlier share of level); the flagged samples replaced by a "
            "draw from what Gaussian noise puts there (the slow level plus white noise as wide as the samples "
            "left where the noise is white at the shortest lag, else the line between the neighbours plus the "
            "second difference's noise), tested again on what is left (up to 4 passes: a heavy tail's scale "
            "shrinks as it is cut) and the noise refitted (allanite.model.outliers). Never applied by avar",
            domain="time",
        ),
        Effect(
            "change_point",
            "changes of noise level",
            "time",
            (("t", "s", "time of a step in the noise level, from the start of the record"),),
            "a step in the Allan variance of non-overlapping windows along the record (all τ jointly), located "
            "to the sample by a two-segment likelihood; needs the samples",
            domain="time",
        ),
    )
}


def describe(indent: str = "        ") -> str:
    """The candidates as a numpydoc-style list: name, parameters with units, what each is; every item
    ``indent``-ed alike (in a docstring, the list under its parameter's description)."""
    lines = []
    for e in EFFECTS.values():
        params = ", ".join(f"``{n}`` ({u})" for n, u, _ in e.params)
        lines.append(f"{indent}- ``{e.name!r}`` — {params}: {e.description}.")
    return "\n".join(lines)


def param_units(name: str, rate_unit: str | None = None) -> dict:
    """Each parameter's unit for effect ``name`` (as :data:`EFFECTS` states it), "rate unit" spelled as
    ``rate_unit`` when known; {} for a name the registry does not hold."""
    if name not in EFFECTS:
        return {}
    rate = rate_unit or "rate unit"
    return {p: u.replace("rate unit", rate) for p, u, _ in EFFECTS[name].params}


def channel_units(units: dict, params: dict) -> dict:
    """A step's parameter units with "channel unit" spelled as the unit of the channel ``params["channel"]``
    names, which allanite does not know: "deg/s per unit of temp" (per whatever unit the channel's samples are in)."""
    name = params.get("channel")
    if not isinstance(name, str):
        return units
    return {
        p: u.replace("channel unit²", f"(unit of {name})²").replace("channel unit", f"unit of {name}")
        for p, u in units.items()
    }


def _is_pair(iv: Any) -> bool:
    return (
        isinstance(iv, (tuple, list, np.ndarray))
        and len(iv) == 2
        and all(isinstance(x, (int, float, np.integer, np.floating)) for x in iv)
    )


def _with_interval(v: Any, iv: Any, digits: int) -> str:
    return fmt_ci(v, iv[0], iv[1], digits) if _is_pair(iv) else fmt(v, digits)


def format_param(name: str, value: Any, interval: Any = None, unit: str = "", digits: int = 4) -> str:
    """``name = value [low, high] unit`` for any parameter a step reports: a string (a filter kind, a
    channel's name), an int (taps, a count of lines), a number, or a list of numbers (e.g. fundamentals, with
    ``interval`` one (low, high) per entry); the interval only where there is one."""
    u = f" {unit}" if unit else ""
    if isinstance(value, str):
        return f"{name} = {value}"
    if isinstance(value, (list, tuple, np.ndarray)):
        values = list(value)
        ivs = list(interval) if isinstance(interval, (list, tuple)) and len(interval) == len(values) else []
        ivs = ivs if all(_is_pair(iv) for iv in ivs) else []
        text = ", ".join(_with_interval(v, ivs[i] if ivs else None, digits) for i, v in enumerate(values))
        return f"{name} = {text or 'none'}{u}"
    if value is None or isinstance(value, (bool, np.bool_)):
        return f"{name} = {fmt(value, digits)}"
    return f"{name} = {_with_interval(value, interval, digits)}{u}"


def format_params(name: str, params: dict, intervals: dict, rate_unit: str | None = None, digits: int = 4) -> str:
    """Every parameter of a step of effect ``name``, with its interval where it has one and its unit from the
    registry, ``"; "``-separated."""
    units = channel_units(param_units(name, rate_unit), params)
    return "; ".join(format_param(k, v, (intervals or {}).get(k), units.get(k, ""), digits) for k, v in params.items())
