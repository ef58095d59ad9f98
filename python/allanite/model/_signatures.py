"""The Allan-variance signatures of the effects :mod:`allanite.model.effects` registers — the filter kinds of
a bandwidth effect, a Gauss–Markov, a sinusoid, a resonance and a warm-up drift, each exact for sampled data.

Split from :mod:`allanite.model.effects` (the registry and its formatting stay there, and re-export every name
here), so that a new kind lands beside the others without the registry growing past its size.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ..errors import ParameterError
from ._declared import declared_of
from ._sharp import SHARP_DESIGNS, sharp_cutoff, sharp_of, sharp_zpk
from ._sinc import SINC_ORDERS, sinc_autocorrelation, sinc_cutoff, sinc_order

__all__ = [
    "gm_avar",
    "sinusoid_avar",
    "filtered_white_avar",
    "filter_autocorrelation",
    "filter_cutoff",
    "butterworth_terms",
    "butterworth_order",
    "drift_avar",
    "FILTERS",
    "BUTTERWORTH_ORDERS",
    "SINC_ORDERS",
    "sinc_order",
    "SHARP_DESIGNS",
    "sharp_of",
    "CASCADE_SPANS",
    "RESONANCE_Q",
    "RESONANCE_SHAPES",
    "resonance_avar",
    "rational_terms",
    "NOTCH_Q",
    "notch_kind",
    "split_notch",
    "notch_zpk",
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
#: the samples' autocorrelation the B-spline M_2k(l/D); :mod:`allanite.model._sinc`). Any of them may be followed
#: by a digital notch (:func:`notch_kind`: ``"<kind>+notch:<f_n>:<Q>"``, not listed here — its f_n and Q are in the
#: kind's name, searched by :mod:`allanite.model.refinement._notch`), and the sharp rippled kinds
#: (``"elliptic4:<r>"``, ``"elliptic6:<r>"``: an elliptic of fixed order and stop band whose signed passband ripple
#: r dB is in the kind's name, :mod:`allanite.model._sharp`; not listed here either — searched by
#: :mod:`allanite.model.refinement._sharp`).
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
#: Quality factors a notch after the roll-off is searched at (:func:`notch_kind`; Q = f_n / its −3 dB width).
NOTCH_Q = (1.0, 2.0, 4.0, 8.0)
#: The tail of a filter kind that cascades a notch after the kind before it (:func:`notch_kind`).
_NOTCH = "+notch:"


def notch_kind(base: str, f_n: float, q: float) -> str:
    """The kind of :data:`FILTERS` ``base`` followed by a digital notch at ``f_n`` (Hz) of quality factor ``q``:
    ``scipy.signal.iirnotch(f_n, q, fs=f_s)`` — H(z) = g·(1 − 2cos ω₀·z⁻¹ + z⁻²)/(1 − 2g·cos ω₀·z⁻¹ + (2g − 1)·z⁻²),
    zeros on the unit circle at ±ω₀ = ±2πf_n/f_s, unit gain at DC (so the curve still tends to N²/τ), −3 dB width
    f_n/q: the user or vibration notch of a MEMS part's digital chain (InvenSense/TDK, Bosch), after its
    anti-alias low-pass. Its parameter ``p`` stays the base kind's (:func:`filter_autocorrelation`)."""
    return f"{base}{_NOTCH}{float(f_n)!r}:{float(q)!r}"


def split_notch(kind: str) -> tuple[str, float | None, float | None]:
    """(base kind, f_n, q) of a kind of :func:`notch_kind`; (``kind``, None, None) for a kind without a notch."""
    base, sep, tail = kind.rpartition(_NOTCH)
    if not sep:
        return kind, None, None
    f_n, q = tail.split(":")
    return base, float(f_n), float(q)


@functools.lru_cache(maxsize=4096)
def notch_zpk(f_n: float, q: float, fs: float) -> tuple[np.ndarray, np.ndarray, float]:
    """Zeros, poles and gain of ``scipy.signal.iirnotch(f_n, q, fs=fs)`` (remembered; read-only arrays)."""
    from scipy import signal

    if not (0.0 < f_n < fs / 2.0 and q > 0.0 and f_n / q < fs / 2.0):
        raise ParameterError(
            f"notch at {f_n!r} Hz, Q {q!r}: f_n must lie in (0, fs/2 = {fs / 2.0!r}), Q above 0 and the width f_n/Q "
            "below fs/2 (a wider notch's poles leave the unit circle)"
        )
    zeros, poles, k = signal.tf2zpk(*signal.iirnotch(f_n, q, fs=fs))
    zeros.flags.writeable = poles.flags.writeable = False
    return zeros, poles, float(k)


@functools.lru_cache(maxsize=4096)
def _cascade_terms(order: int, fc: float, f_n: float, q: float, fs: float) -> tuple:
    """:func:`rational_terms` of a Butterworth (order, f_c; none at f_c ≥ f_s/2) followed by a notch."""
    zn, pn, kn = notch_zpk(f_n, q, fs)
    if fc >= fs / 2.0:
        return rational_terms(zn, pn, kn)
    zb, pb, kb = _butterworth_zpk(order, fc, fs)
    return rational_terms(np.concatenate([zb, zn]), np.concatenate([pb, pn]), kb * kn)


@functools.lru_cache(maxsize=4096)
def _sharp_terms(kind: str, fc: float, fs: float) -> tuple:
    """:func:`rational_terms` of a sharp kind (:func:`allanite.model._sharp.sharp_zpk`), remembered; of a decimated
    one (every D-th output of the filter at D·f_s), the output's: r_out(l) = r_h(l·D) = Σ_j C_j·(p_j^D)^l for l ≥ 1
    (a pole at z = 0 adds only at the filter's own lag 1, no output lag), renormalised to a unit two-sided sum —
    the same closed form with poles p_j^D, the stop band's aliasing included."""
    r0, c, poles, _lag1 = rational_terms(*sharp_zpk(kind, fc, fs))
    dec = SHARP_DESIGNS[kind.partition(":")[0]][2]
    if dec == 1:
        return r0, c, poles, _lag1
    folded = poles**dec
    total = r0 + 2.0 * float((c * folded / (1.0 - folded)).sum().real)
    c, folded = c / total, folded.copy()
    c.flags.writeable = folded.flags.writeable = False
    return r0 / total, c, folded, 0.0


@functools.lru_cache(maxsize=1024)
def _notch_autocorrelation(f_n: float, q: float, fs: float) -> np.ndarray:
    """r(l) of a notch alone (:func:`notch_zpk`), remembered (read-only)."""
    r = _terms_autocorrelation(rational_terms(*notch_zpk(f_n, q, fs)))
    r.flags.writeable = False
    return r


def _terms_autocorrelation(terms: tuple) -> np.ndarray:
    """r(l), l = 0, 1, …, of (r(0), C, p, d) (:func:`rational_terms`), to where the poles' terms fall below 1e-17."""
    r0, c, poles, lag1 = terms
    decay = max(float(np.max(np.abs(poles))), 1e-300) if poles.size else 1e-300
    n = int(min(200_000, math.ceil(math.log(1e-17) / math.log(decay)) if decay < 1.0 else 200_000)) + 2
    lags = np.arange(1, n, dtype=np.float64)
    tail = (c[None, :] * np.exp(lags[:, None] * np.log(poles.astype(np.complex128))[None, :])).sum(axis=1).real
    tail[0] += lag1
    return np.concatenate([[r0], tail])


def _notch_terms(kind: str, p: float, fs: float) -> tuple | None:
    """The closed-form terms of a Butterworth followed by a notch (:func:`notch_kind`), or of a sharp kind
    (:mod:`allanite.model._sharp`, at f_c below f_s/2); None for another kind."""
    if sharp_of(kind) is not None and p < fs / 2.0:
        return _sharp_terms(kind, float(p), float(fs))
    base, f_n, q = split_notch(kind)
    order = butterworth_order(base)
    if f_n is None or q is None or not order:
        return None
    return _cascade_terms(order, float(p), float(f_n), float(q), float(fs))


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
    return rational_terms(*_butterworth_zpk(order, fc, fs))


@functools.lru_cache(maxsize=1024)
def _butterworth_zpk(order: int, fc: float, fs: float) -> tuple[np.ndarray, np.ndarray, float]:
    """``scipy.signal.butter(order, fc, fs=fs, output="zpk")``, remembered."""
    from scipy import signal  # here, not at import: `import allanite` stays free of scipy.signal

    zeros, poles, k = signal.butter(order, fc, fs=fs, output="zpk")
    return zeros, poles, float(k)


def rational_terms(zeros: np.ndarray, poles: np.ndarray, k: float) -> tuple[float, np.ndarray, np.ndarray, float]:
    """The autocorrelation of filtered unit white noise, normalised to unit DC gain, of any stable rational filter
    H(z) = k·Π(z − z_i)/Π(z − p_i) with as many zeros as poles and the poles distinct: (r(0), C, p, d) as
    :func:`butterworth_terms` gives them (the residues of H(z)·H(1/z)·z^{l−1} inside the unit circle)."""
    zeros, poles = np.asarray(zeros, dtype=np.complex128), np.asarray(poles, dtype=np.complex128)
    b, a = np.poly(zeros).real * k, np.poly(poles).real
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

    ``kind`` one of :data:`FILTERS`, or one followed by a notch (:func:`notch_kind`: a Butterworth's and the
    notch's poles together in closed form, :func:`rational_terms`; any other kind's autocorrelation convolved with
    the notch's); ``p`` the cutoff (Hz) for ``"single_pole"`` and the Butterworths, the
    length L (taps of one moving average) for the FIRs, the span D·f_s (samples, ≥ 1, any real) for
    ``"boxcar"``, each boxcar's span in output samples (≥ 1/k, any real) for a sinc^k (``"sinc2"`` …); a declared
    filter's kind (``"declared:<token>"``, :mod:`allanite.model._declared`) its own exact autocorrelation, ``p``
    not read (its shape is known); a sharp kind (``"elliptic6:<ripple dB>"``, :mod:`allanite.model._sharp`) ``p``
    its passband edge (Hz), its poles' closed form."""
    decl = declared_of(kind)
    if decl is not None:
        return decl.r
    terms = _notch_terms(kind, p, fs)
    if terms is not None:  # a Butterworth and a notch, or a sharp kind: one rational filter, its closed form
        return _terms_autocorrelation(terms)
    base, f_n, q = split_notch(kind)
    if f_n is not None:  # any other kind and a notch: the two (two-sided, unit-sum) autocorrelations convolved
        assert q is not None
        return _convolved(filter_autocorrelation(base, p, fs), _notch_autocorrelation(f_n, q, fs))
    if kind == "single_pole":
        a = math.exp(-2.0 * math.pi * p / fs)
        n = int(min(200_000, math.ceil(40.0 / max(1.0 - a, 1e-9)))) + 1
        return (1.0 - a) / (1.0 + a) * a ** np.arange(n, dtype=np.float64)
    order = butterworth_order(kind)
    if (order or sharp_of(kind) is not None) and p >= fs / 2.0:  # its limit there: H → 1, no filter
        return np.ones(1)
    if order:  # to where the poles' terms fall below 1e-17 of r(0)
        return _terms_autocorrelation(butterworth_terms(order, p, fs))
    if sinc_order(kind):
        return sinc_autocorrelation(sinc_order(kind), p)
    if kind == "boxcar":
        span = max(1.0, float(p))
        tri = 1.0 - np.arange(int(math.ceil(span)), dtype=np.float64) / span
        return tri / (tri[0] + 2.0 * tri[1:].sum())
    if kind.startswith("single_pole+boxcar:"):
        # the cascade's autocorrelation: the two (two-sided, unit-sum) autocorrelations convolved
        r_pole = filter_autocorrelation("single_pole", p, fs)
        return _convolved(r_pole, filter_autocorrelation("boxcar", float(kind.split(":", 1)[1]), fs))
    taps = max(1, int(round(p)))
    h = np.full(taps, 1.0 / taps)
    if kind == "bartlett":
        h = np.convolve(h, h)
    r = np.correlate(h, h, mode="full")[h.size - 1 :]
    return r


def _convolved(r1: np.ndarray, r2: np.ndarray) -> np.ndarray:
    """The autocorrelation (lags ≥ 0) of two filters in cascade from each one's (lags ≥ 0, unit two-sided sum)."""
    from scipy.signal import fftconvolve

    both = fftconvolve(np.concatenate([r1[:0:-1], r1]), np.concatenate([r2[:0:-1], r2]))
    return both[both.size // 2 :]


def filter_cutoff(kind: str, p: float, fs: float) -> float:
    """−3 dB frequency (Hz) of a filter of :data:`FILTERS` (``p`` as in :func:`filter_autocorrelation`); for a
    boxcar the continuous filter's, 0.4430/D (sinc² = ½), and a sinc^k's, before the output sampling aliases it;
    for a kind with a notch (:func:`notch_kind`) its low-pass's (the notch's own −3 dB points are f_n ∓ f_n/2q);
    for a declared filter its own (:class:`allanite.model._declared.DeclaredFilter`: at the rate it runs at)."""
    decl = declared_of(kind)
    if decl is not None:
        return decl.cutoff
    kind = split_notch(kind)[0]
    if sharp_of(kind) is not None:
        return sharp_cutoff(kind, float(p), float(fs))
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
    meet the n-fold zero at z = −1: no filter), N²/τ. A Butterworth followed by a notch (:func:`notch_kind`) is one
    rational filter: the same closed sums over its and the notch's poles, as a sharp kind's over its own
    (:mod:`allanite.model._sharp`: an elliptic of fixed order and stop band, its ripple in its name); another kind
    with a notch, and a declared
    filter (``"declared:<token>"``, :mod:`allanite.model._declared`: the output's autocorrelation r_h(l·D), aliasing
    included), sum their (long) autocorrelation by prefix sums (:func:`_prefix_avar`)."""
    tau = np.atleast_1d(np.asarray(tau, dtype=np.float64))
    m = np.maximum(1.0, np.round(tau * fs))
    order = butterworth_order(kind)
    if (order or sharp_of(kind) is not None) and p >= fs / 2.0:  # its limit there: H → 1, white noise
        return fs / m
    terms = butterworth_terms(order, p, fs) if order else _notch_terms(kind, p, fs)
    if terms is not None:  # geometric autocorrelation: closed sums, white part r(0) − Σ C_j at lag 0
        r0, c, poles, lag1 = terms
        s2 = (r0 - c.sum().real) / m + (c[:, None] * _geometric_avar(poles, m)).sum(axis=0).real
        return (s2 + (2.0 * m - 3.0) * lag1 / (m * m)) * fs  # a lag-1 term d: A_m(±1) = 2m − 3
    r = filter_autocorrelation(kind, p, fs)
    if split_notch(kind)[1] is not None or declared_of(kind) is not None:
        # a notch's, or a declared IIR's, long autocorrelation: the sums by prefix sums, O(lags + τ)
        return _prefix_avar(r, m) * fs
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


def _prefix_avar(r: np.ndarray, m: np.ndarray) -> np.ndarray:
    """(1/2m²)·Σ_l A_m(l)·w_l·r(l) (w = 1 at lag 0, else 2) by prefix sums: A_m(l) = 2m − 3l for l ≤ m and
    −(2m − l) for m < l < 2m (0 beyond), so the sum is 2m·S0(m+1) − 3·S1(m+1) − 2m·(S0(2m) − S0(m+1)) +
    (S1(2m) − S1(m+1)) with S0(L) = Σ_{l<L} w_l·r(l), S1(L) = Σ_{l<L} l·w_l·r(l) — the same sum as the matrix
    product of :func:`filtered_white_avar`, in time linear in the lags and the τ."""
    wr = 2.0 * r
    wr[0] = r[0]
    s0 = np.concatenate([[0.0], np.cumsum(wr)])
    s1 = np.concatenate([[0.0], np.cumsum(np.arange(r.size) * wr)])
    top = r.size
    mid = np.minimum(m.astype(np.int64) + 1, top)
    end = np.minimum(2 * m.astype(np.int64), top)
    end = np.maximum(end, mid)
    s = 2.0 * m * s0[mid] - 3.0 * s1[mid] - 2.0 * m * (s0[end] - s0[mid]) + (s1[end] - s1[mid])
    return s / (2.0 * m * m)


#: Quality factors a "resonance" is searched at (Q = f_r / full width at half maximum of its PSD): a hump,
#: not a roll-off (Q ≥ 2; a broad low-Q bump near the bandwidth is what the bandwidth kinds describe).
RESONANCE_Q = (2.0, 4.0, 8.0, 16.0)


#: The shapes a "resonance" takes (:func:`resonance_avar`): the Lorentzian pair, the default, and the band-pass
#: digital resonator, offered only where the fit prefers it by the candidate's own test (``refinement._bumps``).
RESONANCE_SHAPES = ("lorentzian", "bandpass")


def resonance_avar(tau: np.ndarray | float, f_r: float, q: float, fs: float, shape: str = "lorentzian") -> np.ndarray:
    """Allan variance of unit-variance narrowband rate noise at ``f_r`` (Hz) with quality factor ``q`` —
    exact in discrete time for samples at ``fs``, in one of two shapes (:data:`RESONANCE_SHAPES`).

    ``"lorentzian"``: the autocorrelation is R(l) = Re ρ^|l|, ρ = e^{−πf_r/(q·f_s)}·e^{i2πf_r/f_s} (a Lorentzian
    pair of PSD peaks at ±f_r, full width f_r/q: a mechanical mode seen as a narrowband rate bump, vibration).
    Its PSD is not zero at DC, so its Allan variance keeps a white-like 1/τ tail. With S_m the sum of m samples,
    σ²(m) = (Var S_m − Cov(S_m, next S_m))/m², both linear in R, so closed geometric sums in ρ:
    Var = m(1 + ρ)/(1 − ρ) − 2ρ(1 − ρ^m)/(1 − ρ)², Cov = ρ(1 − ρ^m)²/(1 − ρ)², real part taken.

    ``"bandpass"``: white noise through the digital 2nd-order resonator
    H(z) = g(1 − z⁻²)/(1 − 2g·cos ω₀·z⁻¹ + (2g − 1)z⁻²), ω₀ = 2πf_r/f_s, g = 1/(1 + tan(ω₀/2q))
    (``scipy.signal.iirpeak``: PSD peak at f_r, half power at f_r ± f_r/2q, zeros at DC and Nyquist: a sense
    mode read through a demodulator). Its PSD is zero at DC, so its Allan variance falls as 1/τ² at τ ≫ 1/f_r
    and its column holds no white noise to trade with N. With R(l) = Σ_k c_k p_k^l (l ≥ 1) over the poles p_k,
    the same two sums are closed geometric sums in p_k (:func:`_two_pole_avar`)."""
    tau = np.atleast_1d(np.asarray(tau, dtype=np.float64))
    m = np.maximum(1.0, np.round(tau * fs))
    if shape == "bandpass":
        return _bandpass_avar(m, f_r, q, fs)
    if shape != "lorentzian":
        raise ParameterError(f"resonance shape {shape!r}: must be one of {RESONANCE_SHAPES}")
    rho = complex(
        math.exp(-math.pi * f_r / (q * fs)) * math.cos(2 * math.pi * f_r / fs),
        math.exp(-math.pi * f_r / (q * fs)) * math.sin(2 * math.pi * f_r / fs),
    )
    rm = np.exp(m * np.log(rho))
    one = 1.0 - rho
    var = m * (1.0 + rho) / one - 2.0 * rho * (1.0 - rm) / one**2
    cov = rho * (1.0 - rm) ** 2 / one**2
    return np.maximum(((var - cov) / (m * m)).real, 0.0)


def _bandpass_avar(m: np.ndarray, f_r: float, q: float, fs: float) -> np.ndarray:
    """σ²(m) per unit variance of the ``iirpeak`` resonator's output (:func:`resonance_avar`'s band-pass shape)."""
    w0, half = _resonator_angles(f_r, q, fs)
    g = 1.0 / (1.0 + math.tan(half))
    poles = np.roots([1.0, -2.0 * g * math.cos(w0), 2.0 * g - 1.0]).astype(np.complex128)
    # a pole at 0 (g = 1/2; both at 0 when ω₀ is π/2 too): moved off it, apart, c_k·p_k^l keeps its limit
    poles = np.where(np.abs(poles) < 1e-7, np.array([1e-7, -1e-7]), poles)
    if poles[0] == poles[1]:  # a double pole (f_r/q at its one value for f_r): nudged, the sums stay finite
        poles = poles * np.array([1.0 + 1e-9, 1.0 - 1e-9])
    big = np.abs(poles) > 1.0 - 1e-12  # on the unit circle (half width at π/2 with ω₀ at π): just inside it
    poles[big] *= (1.0 - 1e-12) / np.abs(poles[big])
    # the all-pole part's autocorrelation R_x(l) = Σ_k d_k p_k^l for l ≥ −1 (residues of its PSD); the zeros
    # (1 − z⁻²) make R(l) = 2R_x(l) − R_x(l − 2) − R_x(l + 2): c_k = −d_k(p_k − 1/p_k)² for l ≥ 1
    d = poles / ((poles - poles[::-1]) * (1.0 - poles * poles[0]) * (1.0 - poles * poles[1]))
    r0 = float(np.sum(2.0 * d * (1.0 - poles * poles)).real)
    return _two_pole_avar(m, r0, -d * (poles - 1.0 / poles) ** 2, poles)


def _resonator_angles(f_r: float, q: float, fs: float) -> tuple[float, float]:
    """The resonator's centre ω₀ (rad/sample) and half its −3 dB width (rad), kept where the design is defined:
    a centre beyond f_s/2 (an interval's profile scans past the best f_r) folds as a sampled resonance
    aliases, kept just inside (0, π) where the zeros at DC and Nyquist would meet the peak; the half width
    π·(f_r/q)/f_s (the physical width, whatever the fold) stays below π/2, where tan and the poles stay finite."""
    f = math.fmod(abs(f_r), fs)
    f = fs - f if f > fs / 2.0 else f
    w0 = min(max(2.0 * math.pi * f / fs, 1e-6), math.pi * (1.0 - 1e-6))
    half = min(math.pi * abs(f_r) / (q * fs), 0.5 * math.pi * (1.0 - 1e-6))
    return w0, half


def _two_pole_avar(m: np.ndarray, r0: float, c: np.ndarray, poles: np.ndarray) -> np.ndarray:
    """σ²(m) of a process with R(0) = ``r0`` and R(l) = Σ_k c_k p_k^l for l ≥ 1, per unit variance: Var S_m =
    m·R(0) + 2Σ_{l<m}(m − l)R(l), Cov(S_m, next S_m) = Σ_{|l|<m}(m − |l|)R(m + l), each a geometric sum."""
    s = m * r0
    for ck, pk in zip(c, poles):
        pm = np.exp(m * np.log(pk))
        one = 1.0 - pk
        g1 = m * pk / one - pk * (1.0 - pm) / one**2
        g2 = pk * (1.0 - pm) ** 2 / one**2
        s = s + ck * (2.0 * g1 - g2)
    return np.maximum(s.real / (m * m * r0), 0.0)


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
