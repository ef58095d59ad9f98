"""A filter the user declares — the FIR taps or IIR (b, a) a sensor's data sheet or driver gives — as an exact
kind of the bandwidth effect (``refine(..., filter=...)``).

The rate noise's white part runs through the declared filter at the rate the filter runs at, ``rate`` Hz, and
every ``decimation``-th output is kept (``rate = decimation · f_s``; 1 where it runs at the output rate). White
input of variance σ² then gives output samples whose autocorrelation at output lag l is σ²·r_h(l·D), with
r_h(k) = Σ_n h_n·h_{n+k} the autocorrelation of the filter's impulse response h at its own rate — exact, aliasing
included (an FIR: its taps; an IIR: its impulse response to where its energy left is below 10⁻¹⁷ of the total).
Normalised to a unit two-sided sum (the curve tends to N²/τ, as every kind of
:data:`allanite.model.effects.FILTERS`), its Allan variance follows exactly
(:func:`allanite.model.effects.filtered_white_avar`). The filter is known, so its shape has no free
parameter: the bandwidth effect's test then asks only whether the curve needs it; its −3 dB frequency (where
the power response falls to half its value at DC) is reported, not fitted.

Quantisation: a rate quantised after the filter (the output register) adds white noise after it — the bandwidth's
``floor``, kept beside a declared filter as beside a Butterworth; angle quantisation stays the Q term; a
quantiser before the filter is white noise through it, part of N.

Accepted forms (:func:`declared_filter`): a 1-D array of FIR taps running at the output rate; a tuple ``(b, a)``
of two 1-D arrays, an IIR at the output rate; a dict ``{"taps": …}`` or ``{"b": …, "a": …}`` with optional
``"rate"`` (Hz it runs at) and ``"decimation"`` (an int; one of them gives the other from f_s). Each bad value is
a :class:`~allanite.errors.ParameterError` naming it and what is allowed.
"""

from __future__ import annotations

import contextvars
import hashlib
import math
from contextlib import AbstractContextManager
from dataclasses import dataclass, field

import numpy as np

from .._scoped import scoped
from ..errors import ParameterError

__all__ = [
    "DeclaredFilter",
    "declared_filter",
    "declaring",
    "active_declared",
    "declared_of",
    "impulse_response",
    "DECLARED",
    "MAX_RESPONSE",
]

#: The prefix of a declared filter's kind ("declared:<token>"; the token names it in :func:`declared_of`).
DECLARED = "declared"
#: Longest impulse response (samples at the filter's rate) an IIR may have: poles nearer the unit circle than
#: that (|p| ≳ 1 − 10⁻⁵) are refused — their low-pass lies far below any τ of a record.
MAX_RESPONSE = 4_000_000
#: The energy an IIR's impulse response may leave beyond its last sample (share of the total).
TAIL = 1e-17
#: Keys a dict form may hold.
_KEYS = ("taps", "b", "a", "rate", "decimation")
#: The declared filters by token, newest last (a few at most: one per refine call under way).
_BY_TOKEN: dict[str, DeclaredFilter] = {}
_KEPT = 64
_ACTIVE: contextvars.ContextVar[DeclaredFilter | None] = contextvars.ContextVar("declared_filter", default=None)


@dataclass(frozen=True, eq=False)
class DeclaredFilter:
    """A declared filter: numerator ``b`` and denominator ``a`` (``a = [1]`` for an FIR) at ``rate`` Hz, every
    ``decimation``-th output kept; ``token`` names it in its bandwidth kind (:attr:`kind`)."""

    b: np.ndarray = field(repr=False)
    a: np.ndarray = field(repr=False)
    rate: float
    decimation: int
    token: str
    r: np.ndarray = field(repr=False)  # the output's normalised autocorrelation, lags ≥ 0 (read-only)
    cutoff: float  # −3 dB frequency, Hz: where |H|² falls to half its value at DC

    @property
    def kind(self) -> str:
        """The bandwidth kind of this filter ("declared:<token>")."""
        return f"{DECLARED}:{self.token}"

    @property
    def is_fir(self) -> bool:
        return self.a.size == 1

    def describe(self) -> dict:
        """What was declared, as JSON-ready numbers and words (``Refinement.declared_filter``)."""
        out: dict = {"type": "FIR" if self.is_fir else "IIR", "rate_hz": self.rate, "decimation": self.decimation}
        if self.is_fir:
            out["taps"] = int(self.b.size)
        else:
            out["order"] = int(max(self.b.size, self.a.size) - 1)
        out["cutoff_hz"] = self.cutoff
        return out

    def words(self) -> str:
        """One phrase: "a 95-tap FIR at 8000 Hz, decimated by 8 (−3 dB at 327 Hz)"."""
        what = f"a {self.b.size}-tap FIR" if self.is_fir else f"an IIR of order {max(self.b.size, self.a.size) - 1}"
        dec = f", decimated by {self.decimation}" if self.decimation > 1 else ""
        return f"{what} at {self.rate:.6g} Hz{dec} (−3 dB at {self.cutoff:.4g} Hz)"


def declared_of(kind: str) -> DeclaredFilter | None:
    """The declared filter a bandwidth kind names ("declared:<token>"), None for any other kind."""
    head, sep, token = kind.partition(":")
    if head != DECLARED or not sep:
        return None
    got = _BY_TOKEN.get(token)
    if got is None:
        raise ParameterError(f"bandwidth kind {kind!r}: no declared filter of that token (declare it first)")
    return got


def declaring(decl: DeclaredFilter | None) -> AbstractContextManager[None]:
    """Within it :func:`active_declared` is ``decl`` (None: no filter declared, every kind searched)."""
    return scoped(_ACTIVE, decl)


def active_declared() -> DeclaredFilter | None:
    """The filter the refinement under way was given (:func:`declaring`), or None."""
    return _ACTIVE.get()


def declared_filter(spec, fs: float) -> DeclaredFilter | None:
    """The :class:`DeclaredFilter` of ``spec`` for output samples at ``fs`` Hz (None for None); forms in the module
    docstring. Raises :class:`~allanite.errors.ParameterError` for an empty, non-finite or wrongly shaped filter, an
    unstable IIR, a rate and decimation that disagree with ``fs``, or a filter that passes no power at DC."""
    if spec is None:
        return None
    rate, dec = None, None
    if isinstance(spec, dict):
        bad = [k for k in spec if k not in _KEYS]
        if bad or ("taps" in spec) == ("b" in spec or "a" in spec):
            raise ParameterError(
                f"filter dict keys {sorted(spec)!r}: give 'taps' (an FIR) or 'b' and 'a' (an IIR), optionally "
                f"'rate' (Hz) and 'decimation'; allowed keys {_KEYS}"
            )
        b, a = (spec["taps"], [1.0]) if "taps" in spec else (spec.get("b"), spec.get("a"))
        rate, dec = spec.get("rate"), spec.get("decimation")
    elif isinstance(spec, (tuple, list)) and len(spec) == 2 and all(np.ndim(e) == 1 for e in spec):
        b, a = spec
    else:
        b, a = spec, [1.0]
    b, a = _coefficients(b, "b (taps)"), _coefficients(a, "a")
    rate, dec = _rate(rate, dec, fs)
    _check_stable(a)
    token = hashlib.sha1(b.tobytes() + b"|" + a.tobytes() + repr((rate, dec)).encode()).hexdigest()[:16]
    got = _BY_TOKEN.get(token)
    if got is not None:
        return got
    r = _output_autocorrelation(b, a, dec)
    decl = DeclaredFilter(b, a, rate, dec, token, r, _cutoff(b, a, rate))
    while len(_BY_TOKEN) >= _KEPT:
        del _BY_TOKEN[next(iter(_BY_TOKEN))]
    _BY_TOKEN[token] = decl
    return decl


def _coefficients(x, name: str) -> np.ndarray:
    try:
        arr = np.array(x, dtype=np.float64)
    except (TypeError, ValueError):
        raise ParameterError(f"filter {name}: must be a 1-D array of real numbers, got {type(x).__name__}") from None
    if arr.ndim != 1:
        raise ParameterError(f"filter {name}: must be 1-D, got shape {arr.shape}")
    if arr.size == 0:
        raise ParameterError(f"filter {name}: empty; give at least one coefficient")
    if not np.isfinite(arr).all():
        raise ParameterError(f"filter {name}: every coefficient must be finite, got {arr[~np.isfinite(arr)][0]!r}")
    if not np.any(arr != 0.0):
        raise ParameterError(f"filter {name}: all zero; a filter needs a non-zero coefficient")
    arr.flags.writeable = False
    return arr


def _rate(rate, dec, fs: float) -> tuple[float, int]:
    """(rate Hz, decimation) from what was given and the output rate ``fs``; they must agree: rate = D·f_s."""
    if dec is not None and not (isinstance(dec, (int, np.integer)) and not isinstance(dec, bool) and dec >= 1):
        raise ParameterError(f"filter decimation {dec!r}: must be a whole number ≥ 1")
    if rate is not None and not (isinstance(rate, (int, float, np.number)) and math.isfinite(rate) and rate > 0):
        raise ParameterError(f"filter rate {rate!r}: must be a positive number of Hz")
    if rate is None:
        dec = 1 if dec is None else int(dec)
        return float(dec * fs), dec
    ratio = float(rate) / float(fs)
    if dec is None:
        dec = int(round(ratio))
    if dec < 1 or abs(ratio - dec) > 1e-6 * ratio:
        raise ParameterError(
            f"filter rate {rate!r} Hz with decimation {dec!r}: the rate must be the decimation times the output "
            f"rate f_s = {fs!r} Hz"
        )
    return float(rate), int(dec)


def _check_stable(a: np.ndarray) -> None:
    if a[0] == 0.0:
        raise ParameterError("filter a: its first coefficient a[0] must be non-zero")
    if a.size > 1:
        poles = np.roots(a)
        big = float(np.max(np.abs(poles))) if poles.size else 0.0
        if not big < 1.0:
            raise ParameterError(
                f"filter a: an unstable IIR (a pole at |p| = {big:.6g}); every root of a must lie inside the unit "
                "circle"
            )
        if big > 0 and math.log(TAIL) / math.log(big) > MAX_RESPONSE:
            raise ParameterError(
                f"filter a: a pole at |p| = {big:.9g} — its impulse response lasts beyond {MAX_RESPONSE} samples; "
                "poles must lie further inside the unit circle"
            )


def impulse_response(b: np.ndarray, a: np.ndarray) -> np.ndarray:
    """h of the filter (b, a) at its own rate: the taps of an FIR; an IIR's to where the energy left is below
    :data:`TAIL` of the total (its slowest pole's decay bounds the length)."""
    if a.size == 1:
        return b / a[0]
    from scipy import signal

    big = float(np.max(np.abs(np.roots(a))))
    n = b.size + (int(math.ceil(math.log(TAIL) / math.log(big))) + 8 if big > 0 else a.size)
    impulse = np.zeros(min(n, MAX_RESPONSE + b.size + 8))
    impulse[0] = 1.0
    return signal.lfilter(b, a, impulse)


def _output_autocorrelation(b: np.ndarray, a: np.ndarray, dec: int) -> np.ndarray:
    """r(l), l = 0, 1, … output lags, of white noise through (b, a) then decimated by ``dec``: r_h(l·D), with a
    unit two-sided sum; :class:`ParameterError` where it has none (no power at DC: not a low-pass)."""
    from scipy.signal import fftconvolve

    h = impulse_response(b, a)
    full = fftconvolve(h, h[::-1])[h.size - 1 :]  # r_h(k), k ≥ 0
    r = full[::dec].copy()
    scale = max(abs(float(r[0])), 1e-300)
    total = float(r[0] + 2.0 * r[1:].sum())
    if not total > 1e-9 * scale:
        raise ParameterError(
            f"filter: its output's white-noise power at DC is {total / scale:.3g} of its variance — not a low-pass; "
            "a declared bandwidth filter must pass DC"
        )
    keep = np.flatnonzero(np.abs(r) > 1e-18 * scale)
    r = r[: int(keep[-1]) + 1] / total
    r.flags.writeable = False
    return r


def _cutoff(b: np.ndarray, a: np.ndarray, rate: float) -> float:
    """−3 dB frequency (Hz) of (b, a) at ``rate``: the first frequency where |H|² falls to half |H(0)|² (a fine
    grid, then linear between its two points); ``rate``/2 where it never does."""
    from scipy import signal

    f, h = signal.freqz(b, a, worN=1 << 15, fs=rate)
    power = np.abs(h) ** 2
    half = 0.5 * power[0]
    below = np.flatnonzero(power <= half)
    if not below.size:
        return float(rate / 2.0)
    j = int(below[0])
    if j == 0:
        return 0.0
    p0, p1 = power[j - 1], power[j]
    return float(f[j - 1] + (f[j] - f[j - 1]) * (p0 - half) / (p0 - p1))
