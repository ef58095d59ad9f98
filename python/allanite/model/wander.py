"""A line family whose fundamental wanders: its phase tracked, each harmonic removed at k times that phase.

A family of harmonics k·f0 removed by least squares at fixed frequencies (:mod:`allanite.model.periodic`) takes the
part of each line whose phase carries across the record. A wheel's, a rotor's, a pump's or the mains' fundamental
wanders: the lines smear over k·Δf and a fixed-frequency fit leaves most of their power in the samples (a wheel's
1.2 Hz wandering ±0.25 % over a 13 000 s period moves its phase by 39 rad). :func:`track_family` follows it:

1. the reference line: of the family's orders k, the one whose power over the noise floor around it, times k, is
   largest (the fundamental's phase is the reference's over k, but a wandering line's spread, and with it the band
   of noise its phase is read in, grows as k: the phase error's variance goes as 1/(k·power));
2. the bandwidth B from the reference line's spread in the record's spectrum (zero-padded to 2N): the half-width
   around k·f0 holding :data:`SPREAD_SHARE` of the line's power above the floor (the floor the median of a ring
   0.225–0.45·f0 away), times 2, at least :data:`MIN_CYCLES`/T;
3. complex demodulation at k·f0: the band ±B of the zero-padded spectrum (cosine tapered to 1.5·B) shifted to 0
   and transformed back (the record's own end stays an edge, not a wrap), its phase unwrapped and divided by k —
   the fundamental's phase θ(t) beside 2π·f0·t; then once more against that track (:func:`_retracked`: near the
   ends the low pass sees one side only, which biases a phase running away from a fixed carrier); interpolated
   linearly at every sample;
4. each order k removed as a_k·cos(k·θ) + b_k·sin(k·θ): amplitudes constant per harmonic (least squares on every
   sample), the tracked phase shared — held out, the amplitudes are refitted on the held-in blocks with θ fixed
   (as a steady family's are with its frequencies fixed).

The tracked form is taken only by a nested test against the steady family: what the steady fit leaves within ±B of
the reference line (its periodogram's bins, unpadded) against the floor in the ring around it (F with 2·bins dof
each), at its own share of ``level`` (:data:`allanite.model._shares.WANDER_SHARE`, a test run only once a family
is accepted — nothing from the per-record budget under the null), and the tracked form's held-out variance ratio
must be below the steady one's. A family of more than :data:`MAX_ORDERS` lines (a square wave's, a sawtooth's) or
whose reference line is too weak to track (its band's power under :data:`MIN_SNR` times the noise there) is not
tracked; nor is a line whose envelope, read in its phase band, changes as a narrowband noise's does (its SD beyond
the noise's over its mean above :data:`MAX_ENVELOPE_CHANGE`; a Rayleigh envelope's is 0.52): the model's amplitudes are
constant per harmonic, and a narrowband noise — amplitude and phase both wandering — is power on the curve, not a
line to follow.

A lone line is tracked as a family of one order (its fundamental the line, k = 1); the removal then also asks that
the tracked form take at least :data:`MIN_EXPLAINED` of the excess the steady fit left around it
(:func:`explained_share`): a line whose amplitude changes at a steady frequency leaves power within ±B too, in its
envelope, which a tracked phase of constant amplitude cannot take; and that a fixed sinusoid at the tracked mean
frequency still fail :func:`wander_test` (a strong steady line searched a hair off leaves an excess too).

Reported: the fundamental's mean (the tracked phase's mean slope) and its wander — the instantaneous frequency's
rms about the mean and half its 1–99 % span, Hz and relative — away from the record's ends (1/B each).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.stats import f as f_dist

__all__ = [
    "WanderingFamily",
    "track_family",
    "wander_test",
    "explained_share",
    "MAX_ENVELOPE_CHANGE",
    "MIN_EXPLAINED",
    "MAX_ORDERS",
    "MIN_CYCLES",
    "MIN_SNR",
    "SPREAD_SHARE",
]

#: Most lines of a family the tracker takes (a waveform with a jump has hundreds: those are folded, not tracked).
MAX_ORDERS = 16
#: Narrowest tracking band, cycles per record (a steady line's leakage from a fixed-frequency fit is within it).
MIN_CYCLES = 16.0
#: Share of the reference line's power above the floor that its spread holds.
SPREAD_SHARE = 0.95
#: Least power of the reference line in its band over the noise there (phase noise ≲ 1/√MIN_SNR rad per sample).
MIN_SNR = 10.0
#: Largest change of the reference line's envelope (its SD beyond the noise's, over its mean): a wandering
#: fundamental keeps its amplitude (≈ 0.02 simulated); a narrowband noise's Rayleigh envelope changes by 0.52
#: (simulated 0.41–0.57): left to the sinusoid term, which describes its power on the Allan curve. The ADIS16405
#: accelerometers' 0.47–0.56 Hz site family reads 0.08–0.12 and is tracked on six channels
#: (benches/results/wander_measured.md).
MAX_ENVELOPE_CHANGE = 0.25
#: Least share of the excess a steady fit left within ±B of the reference line that the tracked form must take, for a
#: lone line (:func:`explained_share`): a line whose frequency wanders leaves that excess in its phase (the tracked
#: form takes 1.00 of it on a seeded line wandering ±0.3 %); a line whose *amplitude* changes at a steady frequency
#: leaves it in its envelope, which a tracked phase with constant amplitude cannot take (``refine_blind6.py``'s
#: vibrating-structure gyro, a 2 Hz line following the temperature ±20 %: F 247 against 1.64, envelope change 0.12,
#: share 0.002 — "wandering" 0.0004 %, removed as such, left its sinusoid at −87 % of the amplitude).
MIN_EXPLAINED = 0.5
#: Samples per chunk of the least-squares passes (the design is never held whole).
CHUNK = 1 << 18


@dataclass
class WanderingFamily:
    """A family of harmonics ``orders`` of a fundamental whose phase (cycles) is f0·n/f_s plus ``cycles`` at the
    decimated sample indices ``knots`` (the carrier exact at every sample, the slow part interpolated); amplitudes
    ``a``, ``b`` of cos, sin (2π·k·phase) per order; ``mean_hz``, ``wander_rms_hz``, ``wander_half_span_hz`` and
    ``bandwidth_hz`` as in the module docstring; ``reference`` the order tracked; ``n`` samples at ``fs`` Hz."""

    fs: float
    n: int
    orders: np.ndarray
    knots: np.ndarray
    cycles: np.ndarray
    a: np.ndarray
    b: np.ndarray
    mean_hz: float
    wander_rms_hz: float
    wander_half_span_hz: float
    bandwidth_hz: float
    reference: int
    f0: float

    def _cycles_at(self, idx: np.ndarray) -> np.ndarray:
        x = idx.astype(np.float64)
        return self.f0 * x / self.fs + np.interp(x, self.knots, self.cycles)

    def component(self, idx: np.ndarray | None = None) -> np.ndarray:
        """The tracked lines at sample indices ``idx`` (all n samples by default)."""
        idx = np.arange(self.n) if idx is None else np.asarray(idx, dtype=np.int64)
        return _evaluate(self, idx, self.a, self.b)

    def refit(self, samples: np.ndarray, idx: np.ndarray):
        """Amplitudes refitted on ``samples`` at indices ``idx``, the tracked phase fixed; the component as a
        function of sample indices."""
        idx = np.asarray(idx, dtype=np.int64)
        a, b = _solve(self, np.asarray(samples, dtype=np.float64), idx)
        return lambda i: _evaluate(self, np.asarray(i, dtype=np.int64), a, b)

    @property
    def rms(self) -> float:
        """RMS of the tracked lines, √(Σ A_k²/2)."""
        return float(math.sqrt(np.sum(self.a**2 + self.b**2) / 2.0))


def _design(fam: WanderingFamily, idx: np.ndarray) -> np.ndarray:
    c = fam._cycles_at(idx)
    x = 2.0 * np.pi * np.mod(np.outer(c, fam.orders), 1.0)
    return np.hstack([np.cos(x), np.sin(x), np.ones((idx.size, 1))])


def _solve(fam: WanderingFamily, samples: np.ndarray, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Least squares of ``samples`` on the tracked harmonics and a constant, a chunk at a time."""
    k = fam.orders.size
    xtx, xty = np.zeros((2 * k + 1, 2 * k + 1)), np.zeros(2 * k + 1)
    for s in range(0, idx.size, CHUNK):
        d = _design(fam, idx[s : s + CHUNK])
        xtx += d.T @ d
        xty += d.T @ samples[s : s + CHUNK]
    coef = np.linalg.lstsq(xtx, xty, rcond=None)[0]
    return coef[:k], coef[k : 2 * k]


def _evaluate(fam: WanderingFamily, idx: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    out = np.empty(idx.size)
    w = np.concatenate([a, b, [0.0]])
    for s in range(0, idx.size, CHUNK):
        out[s : s + CHUNK] = _design(fam, idx[s : s + CHUNK]) @ w
    return out


def _ring(spec_f: np.ndarray, centre: float, inner: float, outer: float) -> np.ndarray:
    d = np.abs(spec_f - centre)
    return (d >= inner) & (d <= outer)


def _floor(power: np.ndarray, freqs: np.ndarray, centre: float, f0: float) -> float:
    """Mean periodogram level in the ring 0.225–0.45·f0 from ``centre`` (its median over ln 2: exponential bins)."""
    ring = _ring(freqs, centre, 0.225 * f0, 0.45 * f0)
    return float(np.median(power[ring]) / math.log(2.0)) if ring.any() else float("nan")


def _reference(pad_power: np.ndarray, pad_f: np.ndarray, orders: np.ndarray, f0: float, fs: float) -> tuple | None:
    """The order to track (largest k·excess/floor) and its excess power's spread (half-width, Hz)."""
    best = None
    for k in orders:
        fc = float(k * f0)
        if fc + 0.45 * f0 >= fs / 2.0:
            continue
        floor = _floor(pad_power, pad_f, fc, f0)
        near = np.abs(pad_f - fc) < 0.225 * f0
        excess = pad_power[near] - floor
        score = k * float(excess.sum()) / floor
        if best is None or score > best[0]:
            best = (score, int(k), near, excess, floor)
    if best is None:
        return None
    _s, k, near, excess, floor = best
    d = np.abs(pad_f[near] - k * f0)
    order = np.argsort(d)
    cum = np.cumsum(excess[order])
    total = cum[-1]
    if not total > 0:
        return None
    half = float(d[order][min(int(np.searchsorted(cum, SPREAD_SHARE * total)), d.size - 1)])
    return k, half, floor


def _demodulate(pad_spec: np.ndarray, n: int, fs: float, fc: float, band: float, floor: float) -> tuple:
    """The band ±band around fc of the record's spectrum (zero-padded to 2n; cosine taper to 1.5·band) at baseband:
    its samples, their sample indices in the record (those within it), and the band's power over the noise's
    (``floor`` per bin) less 1."""
    df = fs / (2 * n)
    width = 1.5 * band
    lo, hi = max(int(math.floor((fc - width) / df)), 0), min(int(math.ceil((fc + width) / df)), pad_spec.size - 1)
    j = np.arange(lo, hi + 1)
    off = j * df - fc
    taper = np.where(np.abs(off) <= band, 1.0, 0.5 * (1 + np.cos(np.pi * (np.abs(off) - band) / (width - band))))
    taper[np.abs(off) > width] = 0.0
    m = 1 << max(6, int(math.ceil(math.log2(4 * j.size))))
    base = np.zeros(m, dtype=np.complex128)
    # bin j at offset (j − j_c)·df: put it at index (j − j_c) mod m; the carrier's remainder fc − j_c·df is taken out
    j_c = int(round(fc / df))
    base[(j - j_c) % m] = pad_spec[j] * taper
    w2 = float(np.sum(taper**2))
    snr = float(np.sum(np.abs(base) ** 2)) / (floor * w2) - 1.0 if floor > 0 and w2 > 0 else 0.0
    z = np.fft.ifft(base)
    step = 2 * n / m
    knots = np.arange(m) * step
    inside = knots <= n - 1
    t = knots[inside] / fs
    z = z[inside] * np.exp(-2j * np.pi * (fc - j_c * df) * t)
    return z, knots[inside], snr


def _phase_band(knots: np.ndarray, dev: np.ndarray, fs: float, band: float, n: int) -> float:
    """The fundamental's phase bandwidth: the highest frequency where the first track's periodogram (less its line,
    Hann-windowed) stands 10× above its own floor (the median of its upper half-band over ln 2: the track's noise,
    white within ±band), × 1.5; within [MIN_CYCLES/T, band]. The carrier's band must hold the line's whole spread
    (k·Δf); the phase itself moves far slower (a wheel's over 13 000 s), and its noise goes as the band it is read
    in."""
    t = knots / fs
    d = dev - np.polyval(np.polyfit(t, dev, 1), t)
    p = np.abs(np.fft.rfft(d * np.hanning(d.size))) ** 2  # Hann: a phase swinging radians leaks no far floor
    f = np.fft.rfftfreq(d.size, t[1] - t[0])
    low = MIN_CYCLES * fs / n
    upper = (f > band / 2) & (f <= band)
    if upper.sum() < 8:
        return band
    floor = float(np.median(p[upper]) / math.log(2.0))
    above = f[(f <= band) & (p > 10.0 * floor)]
    return float(min(max(1.5 * above.max() if above.size else low, low), band))


def _smoothed(knots: np.ndarray, dev: np.ndarray, fs: float, band: float) -> np.ndarray:
    """The track low-passed to ±band (cosine taper to 1.5·band), less its straight line, extended by half its length
    at each end by point reflection about the end value (slope carries on: no jump, no kink at the ends)."""
    t = knots / fs
    line = np.polyval(np.polyfit(t, dev, 1), t)
    d = dev - line
    h = d.size // 2
    ext = np.concatenate([2 * d[0] - d[h:0:-1], d, 2 * d[-1] - d[-2 : -h - 2 : -1]])
    spec = np.fft.rfft(ext)
    f = np.fft.rfftfreq(ext.size, t[1] - t[0])
    taper = np.where(f <= band, 1.0, 0.5 * (1 + np.cos(np.pi * np.minimum(f - band, 0.5 * band) / (0.5 * band))))
    return np.fft.irfft(spec * taper, ext.size)[h : h + d.size] + line


def _retracked(y: np.ndarray, fs: float, f0: float, k0: int, knots: np.ndarray, dev: np.ndarray, band: float):
    """The phase tracked once more against the first track: the record times e^{−i2π·k0·phase}, low-passed to ±band
    (zero-padded, tapered as in :func:`_demodulate`), its phase added to the first's. Near the record's ends the low
    pass averages over one side only, which biases a phase that runs away from the carrier (a wheel's 1.2 Hz
    wandering 0.003 Hz, at B = 0.006 Hz: ≈ 1.6 rad at the ends); against the first track what is left is small.
    Returns the knots, the phase (cycles beyond f0·n/f_s), the envelope and the noise's variance in it (the same
    band read 0.3·f0 either side, between the harmonics: the noise there, through the same filter)."""
    n = y.size
    w = np.empty(n, dtype=np.complex128)
    mean = float(y.mean())
    for s in range(0, n, CHUNK):
        x = np.arange(s, min(s + CHUNK, n), dtype=np.float64)
        c = np.mod(k0 * (f0 * x / fs + np.interp(x, knots, dev)), 1.0)
        w[s : s + CHUNK] = (y[s : s + CHUNK] - mean) * np.exp(-2j * np.pi * c)
    spec = np.fft.fft(w, 2 * n)
    del w
    df = fs / (2 * n)
    q = int(math.ceil(1.5 * band / df))
    j = np.arange(-q, q + 1)
    off = np.abs(j * df)
    taper = np.where(off <= band, 1.0, 0.5 * (1 + np.cos(np.pi * (off - band) / (0.5 * band))))
    taper[off > 1.5 * band] = 0.0
    m = 1 << max(14, int(math.ceil(math.log2(4 * j.size))))
    base = np.zeros(m, dtype=np.complex128)
    base[j % m] = spec[j % (2 * n)] * taper
    z = np.fft.ifft(base)
    k2 = np.arange(m) * (2 * n / m)
    inside = k2 <= n - 1
    k2 = k2[inside]
    z = z[inside]
    noise = 0.0
    for side in (-1, 1):
        base[:] = 0.0
        base[j % m] = spec[(j + side * int(round(0.3 * f0 / df))) % (2 * n)] * taper
        noise += 0.5 * float(np.mean(np.abs(np.fft.ifft(base)[inside]) ** 2))
    return k2, np.interp(k2, knots, dev) + np.unwrap(np.angle(z)) / (2.0 * np.pi * k0), np.abs(z), noise


def wander_test(resid: np.ndarray, fs: float, fc: float, band: float, f0: float, alpha: float) -> dict:
    """What a steady fit left (``resid``) within ±band of fc against the ring 0.225–0.45·f0 around it: the ratio of
    their periodogram means, F(2·in, 2·ring) at ``alpha``."""
    n = resid.size
    spec = np.fft.rfft(resid - resid.mean())
    freqs = np.fft.rfftfreq(n, 1.0 / fs)
    power = np.abs(spec) ** 2
    inner = np.abs(freqs - fc) <= band
    ring = _ring(freqs, fc, 0.225 * f0, 0.45 * f0)
    n_in, n_ring = int(inner.sum()), int(ring.sum())
    if n_in == 0 or n_ring < 8:
        return {"ratio": float("nan"), "threshold": float("inf"), "alpha": alpha, "accepted": False}
    ratio = float(power[inner].mean() / power[ring].mean())
    thr = float(f_dist.isf(alpha, 2 * n_in, 2 * n_ring))
    return {"ratio": ratio, "threshold": thr, "alpha": alpha, "bins": n_in, "accepted": bool(ratio > thr)}


def explained_share(y: np.ndarray, tracked: np.ndarray, fs: float, test: dict, f0: float) -> float:
    """The share of the excess over the floor that the steady fit left within ±B of the reference line
    (``test``: :func:`track_family`'s evidence) which the tracked component ``tracked`` takes: 1 − (ratio after
    the tracked removal − 1)/(the steady ratio − 1), the ratios :func:`wander_test`'s."""
    k, band = test["order"], test["bandwidth_hz"]
    after = wander_test(np.asarray(y, dtype=np.float64) - tracked, fs, k * f0, band, f0, test["alpha"])["ratio"]
    excess = test["ratio"] - 1.0
    return float(1.0 - (after - 1.0) / excess) if excess > 0 else 0.0


def _harmonic_orders(gens: np.ndarray, coefs: np.ndarray, fs: float) -> tuple[float, np.ndarray] | None:
    """The fundamental and its orders, for a family of harmonics — or of sidebands so close (|s|·f2 < f1/4 on
    every line) that they tile a smeared harmonic; None otherwise, or for orders that fold."""
    if gens.size == 2:
        if not np.all(np.abs(coefs[:, 1]) * abs(gens[1]) < abs(gens[0]) / 4.0):
            return None
    elif gens.size != 1:
        return None
    f0 = float(abs(gens[0]))
    orders = np.unique(np.abs(coefs[:, 0]))
    orders = orders[orders > 0]
    if f0 <= 0 or orders.size == 0 or orders.size > MAX_ORDERS or orders.max() * f0 >= fs / 2.0:
        return None
    return f0, orders


def _envelope_change(knots: np.ndarray, env: np.ndarray, noise: float, fs: float, band: float, n: int) -> float:
    """The reference line's envelope in its phase band, away from the ends: its SD beyond the noise's (half the
    noise's variance goes into the envelope of a line well above it) over its mean."""
    t = knots / fs
    keep = (t >= 1.0 / band) & (t <= n / fs - 1.0 / band)
    e = env[keep] if keep.sum() >= 8 else env
    mean = float(e.mean())
    return float(math.sqrt(max(float(e.var()) - noise / 2.0, 0.0)) / mean) if mean > 0 else math.inf


def _stats(knots: np.ndarray, cycles: np.ndarray, fs: float, band: float, n: int) -> tuple[float, float, float]:
    """Mean frequency (least-squares slope of the phase) and the wander's rms and 1–99 % half span away from the
    ends (1/band each)."""
    t = knots / fs
    slope = float(np.polyfit(t, cycles, 1)[0])
    inst = np.gradient(cycles, t)
    edge = 1.0 / band
    keep = (t >= edge) & (t <= n / fs - edge)
    if keep.sum() < 8:
        keep = np.ones_like(t, dtype=bool)
    dev = inst[keep] - slope
    lo, hi = np.percentile(dev, [1.0, 99.0])
    return slope, float(np.sqrt(np.mean(dev**2))), float((hi - lo) / 2.0)


def track_family(y: np.ndarray, fs: float, gens, coefs, steady: np.ndarray, alpha: float):
    """The family (``gens`` Hz, ``coefs``; ``steady`` its fixed-frequency component) with its fundamental's phase
    tracked, and the nested test's evidence — or (None, evidence or None) where it is not taken (module
    docstring)."""
    y = np.asarray(y, dtype=np.float64)
    n = y.size
    ho = _harmonic_orders(np.asarray(gens, dtype=np.float64), np.asarray(coefs), fs)
    if ho is None:
        return None, None
    f0, orders = ho
    pad = np.fft.rfft(y - y.mean(), 2 * n)
    pad_f = np.fft.rfftfreq(2 * n, 1.0 / fs)
    ref = _reference(np.abs(pad) ** 2, pad_f, orders, f0, fs)
    if ref is None:
        return None, None
    k0, half, floor = ref
    band = max(2.0 * half, MIN_CYCLES * fs / n)
    band = min(band, 0.2 * f0)
    test = wander_test(y - steady, fs, k0 * f0, band, f0, alpha) | {"order": k0, "bandwidth_hz": band}
    if not test["accepted"]:
        return None, test
    z, knots, snr = _demodulate(pad, n, fs, k0 * f0, band, floor)
    test["snr"] = snr
    if not snr > MIN_SNR:
        return None, test | {"accepted": False, "why": "the reference line is too weak to track"}
    dev = np.unwrap(np.angle(z)) / (2.0 * np.pi * k0)
    slow = _phase_band(knots, dev, fs, band, n)
    knots, dev, env, noise = _retracked(y, fs, f0, k0, knots, _smoothed(knots, dev, fs, slow), slow)
    test["phase_bandwidth_hz"] = slow
    test["envelope_change"] = change = _envelope_change(knots, env, noise, fs, slow, n)
    if not change < MAX_ENVELOPE_CHANGE:
        why = "its amplitude changes along the record as much as its phase: narrowband noise, not a wandering line"
        return None, test | {"accepted": False, "why": why}
    mean, rms, half_span = _stats(knots, f0 * knots / fs + dev, fs, slow, n)
    fam = WanderingFamily(
        fs, n, orders.astype(np.float64), knots, dev, np.zeros(orders.size), np.zeros(orders.size),
        mean, rms, half_span, band, k0, f0,
    )  # fmt: skip
    fam.a, fam.b = _solve(fam, y, np.arange(n))
    return fam, test
