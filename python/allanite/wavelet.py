"""Wavelet split of a rate record into trend, low- and high-frequency parts (paper 002).

Paper 002 decomposes a gyro's dynamic error with a db5 wavelet over 5 levels into a trend, mid/low- and
high-frequency noise, and analyses the low part with a rectangular and the high part with a Hann
window (:func:`allanite.combine`). The paper does not say which details go where; the default here is
trend = A5, low = D5 … D3, high = D2 … D1, and :attr:`Split.bands` states each band's frequency range.

Removing A5 high-passes the data near fs/2^(L+1) (fs/64 for L = 5): the low band's long-τ terms (bias
instability, random walk, ramp) shrink by construction. On a rate table the trend is a periodic
signal at the table frequency; ``trend="periodic"`` removes a fitted periodic trend instead and keeps
the slow noise in the low band.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ._validate import as_rate_columns, check_choice, check_count
from .errors import MissingDependencyError, ParameterError

__all__ = ["Split", "wavelet_split", "TRENDS", "level_bands", "periodic_trend"]

#: ``trend=`` of :func:`wavelet_split`.
TRENDS = ("a5", "periodic", "none")

#: Harmonics of the table frequency in the periodic trend (scale-factor error at f0; an asymmetric scale
#: factor, ∝ ω|ω|, puts power at 3·f0 and 5·f0; a quadratic one at 2·f0).
HARMONICS = 5

#: A periodic trend identified from the periodogram has at least this many cycles in the record.
MIN_CYCLES = 20


def _pywt():
    try:
        import pywt
    except ImportError:  # pragma: no cover - PyWavelets is a dependency
        raise MissingDependencyError("the wavelet split needs PyWavelets: pip install PyWavelets") from None
    return pywt


@dataclass(frozen=True)
class Split:
    """A record split into ``trend + low + high`` (arrays of the input's shape).

    Attributes
    ----------
    trend, low, high : ndarray, (samples,) or (samples, axes)
        The parts; ``trend + low + high`` equals the input to rounding (``high`` is formed as the
        remainder, so the sum closes to ~1 ulp).
    bands : dict
        For each part, ``{"levels": ("d5", "d4", "d3"), "hz": (f_low, f_high)}`` — the wavelet levels
        it holds and the frequency range they cover for ``fs`` (a detail Dj spans fs/2^(j+1) … fs/2^j,
        the approximation AL spans 0 … fs/2^(L+1)); the trend of ``trend="periodic"`` lists
        ``("periodic",)`` and the table frequency.
    wavelet : str
    level : int
    fs : float
    trend_kind : str
        ``"a5"`` (the approximation at ``level``), ``"periodic"`` or ``"none"``.
    trend_freq : float or None
        The table frequency of a periodic trend, Hz (given or identified from the PSD peak).
    """

    trend: np.ndarray
    low: np.ndarray
    high: np.ndarray
    bands: dict[str, dict] = field(repr=False)
    wavelet: str = "db5"
    level: int = 5
    fs: float = 1.0
    trend_kind: str = "a5"
    trend_freq: float | None = None

    def __repr__(self) -> str:
        parts = ", ".join(
            f"{k}: {'+'.join(v['levels']) or '—'} {v['hz'][0]:.3g}–{v['hz'][1]:.3g} Hz" for k, v in self.bands.items()
        )
        return f"Split({self.wavelet}, level {self.level}, {parts})"


def level_bands(fs: float, level: int) -> dict[str, tuple[float, float]]:
    """Frequency range (Hz) of every level name: ``"a{L}"`` → (0, fs/2^(L+1)), ``"d{j}"`` →
    (fs/2^(j+1), fs/2^j)."""
    out = {f"a{level}": (0.0, fs / 2 ** (level + 1))}
    for j in range(level, 0, -1):
        out[f"d{j}"] = (fs / 2 ** (j + 1), fs / 2**j)
    return out


def _default_bands(level: int, trend: str) -> dict[str, tuple[str, ...]]:
    low = tuple(f"d{j}" for j in range(level, 2, -1))
    high = tuple(f"d{j}" for j in range(min(2, level), 0, -1))
    if trend == "a5":
        return {"trend": (f"a{level}",), "low": low, "high": high}
    return {"trend": (), "low": (f"a{level}",) + low, "high": high}


def _check_bands(bands, level: int, trend: str) -> dict[str, tuple[str, ...]]:
    names = [f"a{level}"] + [f"d{j}" for j in range(level, 0, -1)]
    if not isinstance(bands, dict) or set(bands) - {"trend", "low", "high"}:
        raise ParameterError(
            f"bands must be a dict with keys among 'trend', 'low', 'high' mapping to level names {names}, got {bands!r}"
        )
    out = {k: tuple(str(v).lower() for v in bands.get(k, ())) for k in ("trend", "low", "high")}
    if trend != "a5" and out["trend"]:
        raise ParameterError(
            f"with trend={trend!r} the trend is not a wavelet band; put {out['trend']} in 'low' or 'high'"
        )
    seen = [v for k in ("trend", "low", "high") for v in out[k]]
    unknown = [v for v in seen if v not in names]
    dup = sorted({v for v in seen if seen.count(v) > 1})
    missing = [v for v in names if v not in seen]
    if unknown or dup or missing:
        raise ParameterError(
            f"bands must partition the levels {names} (each exactly once) for level={level}: "
            + "; ".join(
                s
                for s in (
                    f"unknown {unknown}" if unknown else "",
                    f"repeated {dup}" if dup else "",
                    f"missing {missing}" if missing else "",
                )
                if s
            )
        )
    return out


def periodic_trend(y: np.ndarray, fs: float, freq: float | None = None, harmonics: int = HARMONICS):
    """Least-squares fit of c + Σ_h (a_h cos 2πh·f0·t + b_h sin 2πh·f0·t) to each column of ``y``
    (samples, axes); returns (fitted trend, f0). Without ``freq``, f0 is the periodogram's peak (mean
    removed; the bin most prominent over the median of its ±25 neighbours, at least ``MIN_CYCLES`` cycles
    in the record) of the first
    column, refined to the frequency within ±1 bin that maximises
    the fitted power; a fundamental of which that line is a harmonic is taken when its harmonics
    explain > 5 % more power)."""
    n = y.shape[0]
    t = np.arange(n) / fs

    def design(f):
        cols = [np.ones(n)]
        for h in range(1, harmonics + 1):
            cols += [np.cos(2 * np.pi * h * f * t), np.sin(2 * np.pi * h * f * t)]
        return np.stack(cols, axis=1)

    if freq is None:
        z = y[:, 0] - y[:, 0].mean()
        spec = np.abs(np.fft.rfft(z)) ** 2
        # the most prominent line, not the largest bin: slow noise (random walk, flicker) holds the
        # largest power at the lowest frequencies; judge each bin against its neighbourhood's median
        half = 25
        pad = np.pad(spec, half, mode="edge")
        background = np.median(np.lib.stride_tricks.sliding_window_view(pad, 2 * half + 1), axis=1)
        # and at least MIN_CYCLES cycles in the record: the lowest bins of a random walk are not a table
        if spec.size <= MIN_CYCLES + 1:
            raise ParameterError(
                f"{n} samples are too few to identify a periodic trend ({MIN_CYCLES} cycles needed): give trend_freq"
            )
        k = int(np.argmax(spec[MIN_CYCLES:] / np.maximum(background[MIN_CYCLES:], 1e-300))) + MIN_CYCLES
        df = fs / n

        def fitted_power(f):
            # ‖projection of z on the columns‖² = bᵀG⁻¹b by the normal equations: the columns (mean,
            # cos, sin of distinct harmonics) are near-orthogonal, so G is well conditioned
            a = design(f)
            b = a.T @ z
            return float(b @ np.linalg.solve(a.T @ a, b))

        def best_near(f_c):
            # a grid over ±1 bin, then a bounded scalar search around its best point: a phase drift of
            # 2π·Δf·T over the record must stay ≪ 1 rad, so Δf ≪ 1/T (a fraction of a bin)
            grid = np.linspace(max(f_c - df, df / 4), f_c + df, 21)
            power = [fitted_power(f) for f in grid]
            i = int(np.argmax(power))
            step = grid[1] - grid[0]
            from scipy.optimize import minimize_scalar  # at its first use, not at import allanite

            res = minimize_scalar(
                lambda f: -fitted_power(f),
                bounds=(grid[i] - step, grid[i] + step),
                method="bounded",
                options={"xatol": 1e-6 * df},
            )
            if -res.fun > power[i]:
                return float(res.x), float(-res.fun)
            return float(grid[i]), float(power[i])

        # the most prominent line may be a harmonic (an asymmetric scale factor puts much power at 3·f0):
        # try the fundamentals it could be a harmonic of; a lower one must explain clearly more power
        freq, best = best_near(k * df)
        for h in range(2, harmonics + 1):
            if k * df / h < 2 * df:
                break
            f_h, p_h = best_near(k * df / h)
            if p_h > 1.05 * best:
                freq, best = f_h, p_h
    elif not (np.isfinite(freq) and 0 < freq < fs / 2):
        raise ParameterError(f"trend_freq = {freq!r} Hz must lie between 0 and fs/2 = {fs / 2:g} Hz")
    a = design(freq)
    coef = np.linalg.lstsq(a, y, rcond=None)[0]
    return a @ coef, float(freq)


def _check_wavelet(pywt, wavelet) -> None:
    """A ParameterError unless ``wavelet`` names a discrete PyWavelets wavelet."""
    discrete = pywt.wavelist(kind="discrete")
    if not isinstance(wavelet, str) or wavelet not in discrete:
        raise ParameterError(
            f"unknown wavelet {wavelet!r}; allowed: a discrete PyWavelets wavelet such as 'db1' … 'db38', "
            f"'sym2' … 'sym20', 'coif1' … 'coif17' (pywt.wavelist(kind='discrete'))"
        )


def _parts(pywt, w, y, rest, level, groups, trend, trend_part):
    """(trend, low, high) of the record ``y``: ``rest`` (``y`` less a periodic trend) decomposed to ``level``,
    each part rebuilt from its levels in ``groups``; ``high`` is the remainder, so the three sum to ``y``."""
    n = y.shape[0]
    coeffs = pywt.wavedec(rest, w, mode="symmetric", level=level, axis=0)
    names = [f"a{level}"] + [f"d{j}" for j in range(level, 0, -1)]

    def reconstruct(keep: tuple[str, ...]) -> np.ndarray:
        if not keep:
            return np.zeros_like(y)
        parts = [c if name in keep else np.zeros_like(c) for name, c in zip(names, coeffs)]
        return pywt.waverec(parts, w, mode="symmetric", axis=0)[:n]

    if trend == "a5":
        trend_part = reconstruct(groups["trend"])
    low = reconstruct(groups["low"])
    return trend_part, low, y - trend_part - low


def _part_bands(groups, trend, freq, fs, level) -> dict[str, dict]:
    """Each part's levels and the frequency range they cover (:attr:`Split.bands`)."""
    ranges = level_bands(fs, level)
    out_bands: dict[str, dict] = {}
    for key in ("trend", "low", "high"):
        lv = groups[key]
        if key == "trend" and trend == "periodic":
            out_bands[key] = {"levels": ("periodic",), "hz": (float(freq or 0.0), float(HARMONICS * (freq or 0.0)))}
        elif lv:
            out_bands[key] = {"levels": lv, "hz": (min(ranges[v][0] for v in lv), max(ranges[v][1] for v in lv))}
        else:
            out_bands[key] = {"levels": (), "hz": (0.0, 0.0)}
    return out_bands


def wavelet_split(
    x,
    fs,
    *,
    wavelet: str = "db5",
    level: int = 5,
    bands=None,
    trend: str = "a5",
    trend_freq: float | None = None,
) -> Split:
    """Split a rate record into trend, low- and high-frequency parts by a discrete wavelet transform.

    Parameters
    ----------
    x : array_like, shape (samples,) or (samples, axes)
        Rate samples (paper 002: the dynamic error, gyro output − table rate).
    fs : float
        Sampling rate, Hz.
    wavelet : str
        A discrete PyWavelets wavelet (default ``"db5"``, paper 002).
    level : int
        Decomposition depth (default 5). At most ``pywt.dwt_max_level(samples, wavelet)``.
    bands : dict, optional
        Which levels form each part, e.g. ``{"trend": ("a5",), "low": ("d5", "d4", "d3"),
        "high": ("d2", "d1")}`` (the default for ``trend="a5"``); must use every level exactly once.
    trend : {"a5", "periodic", "none"}
        ``"a5"``: the approximation at ``level`` is the trend (removing it high-passes the record near
        fs/2^(level+1), so slow noise — bias instability, random walk — shrinks). ``"periodic"``: a
        least-squares periodic trend (mean + ``HARMONICS`` harmonics of the table frequency) is the
        trend and the approximation joins ``low``. ``"none"``: no trend; the approximation joins ``low``.
    trend_freq : float, optional
        Table frequency for ``trend="periodic"``, Hz; identified from the periodogram peak if omitted.

    Returns
    -------
    Split
        ``trend``, ``low``, ``high`` (shape of ``x``), ``bands`` with each part's levels and frequency
        range. Edge mode ``"symmetric"`` (PyWavelets' and MATLAB's default).

    Examples
    --------
    >>> import numpy as np, allanite
    >>> y = np.random.default_rng(0).normal(size=4096)
    >>> s = allanite.wavelet_split(y, fs=100.0)
    >>> s.bands["high"]["hz"]
    (12.5, 50.0)
    >>> bool(np.max(np.abs(s.trend + s.low + s.high - y)) < 1e-12)
    True
    """
    pywt = _pywt()
    check_choice(trend, "trend", TRENDS)
    _check_wavelet(pywt, wavelet)
    level = check_count(level, "level", 1)
    cols, fs, is_multi = as_rate_columns(x, fs, "rate")
    y = np.stack(cols, axis=1)
    n = y.shape[0]
    w = pywt.Wavelet(wavelet)
    deepest = pywt.dwt_max_level(n, w.dec_len)
    if level > deepest:
        raise ParameterError(
            f"level = {level} is too deep for {n} samples with {wavelet!r} (filter length {w.dec_len}): "
            f"the deepest useful level is {deepest}"
        )
    groups = _default_bands(level, trend) if bands is None else _check_bands(bands, level, trend)
    freq = None
    if trend == "periodic":
        trend_part, freq = periodic_trend(y, fs, trend_freq)
        rest = y - trend_part
    else:
        trend_part = np.zeros_like(y)
        rest = y
    trend_part, low, high = _parts(pywt, w, y, rest, level, groups, trend, trend_part)
    out_bands = _part_bands(groups, trend, freq, fs, level)

    def shape(a: np.ndarray) -> np.ndarray:
        return a if is_multi else a[:, 0]

    return Split(
        trend=shape(trend_part),
        low=shape(low),
        high=shape(high),
        bands=out_bands,
        wavelet=wavelet,
        level=level,
        fs=fs,
        trend_kind=trend,
        trend_freq=freq,
    )
