#!/usr/bin/env python3
"""``allanite.refine`` on an eleventh blind suite of simulated sensors, unlike ``tests/sensors.py``, the ten earlier
blind suites (``benches/refine_blind.py`` … ``refine_blind10.py``), ``benches/refine_sensors.py`` and the
ADIS16405 — what a user brings with default arguments.

**Written and committed before it was first run.** The effects' sizes were fixed beforehand by their Allan
deviation alone (``--sizes``, as ``benches/refine_blind10.py`` sizes them: ≥ 3× for every curve effect a case asks
refine to find; a change of noise level is judged by its time, the effects outside the family are as a sensor
makes them), never by refine's answer; the first run's verdicts are recorded as they came out (the notes below the
table) and the cases are not retuned after it.

The cases: a navigation-grade ring-laser gyro read as pulse counts (quantisation dominating the short τ) whose
dither residue (427 Hz and its 2nd harmonic) folds to a 27 Hz family at 400 Hz; a 4 kHz fibre-optic gyro with a
1/f corner near 1 Hz (clean); a MEMS gyro decimated 8 kHz → 1 kHz by an equiripple FIR with 1.3 dB of passband
ripple (only its roll-off to name); a temperature logged at 0.1 Hz and linearly interpolated to the gyro's 50 Hz; a
three-axis log whose axes follow the temperature each its own way (+, − with a quadratic, not at all), refined on
the negative axis; a gyro logged beside a magnetometer channel (heading changes, a daily swing) it has nothing to
do with (clean: the channel must not be taken); a clock's phase at 1 Hz turned to frequency (unit None), flicker
FM, linear ageing and a settling after switch-on; an asymmetric burst (popcorn) noise, rare 5 s visits to a high
state; a float32 accelerometer on 1 g (m/s², unit None) at 1 kHz whose white noise doubles at 0.62 T; a 2 kHz MEMS
whose sense-mode resonance (310 Hz, Q 8) shows as a narrowband hump — and two effects **outside the family**: a
spin table's residual line whose amplitude fades 1 → 0.45 along the record, and a 48 h log at 1 Hz with two power
cycles, each a bias step (turn-on repeatability) and a short settling after it.

Truths are in the unit refine reports (°/s for the gyros unless said; rad/s, m/s² and fractional frequency as
said). A family is judged on its fundamental(s) and its rms (over all its lines); a filter on its −3 dB frequency.

Judged as ``benches/refine_blind10.py`` judges (``refine_blind4._judged``: named, parameters within 20 %,
frequencies within 1 %, the chain's error falling in sample and held out, ``unexplained`` empty; a clean case:
nothing added but what it allows, nothing unexplained; an effect outside the family: something left unexplained;
a named channel: no regression on another; a forbidden effect: not added). Every case with an effect in the family
is refined again without its effect's candidate, which must leave something unexplained.

Usage::

    python benches/refine_blind11.py              # -> benches/results/refine_blind11.{json,md}
    python benches/refine_blind11.py --case clock # the cases whose name contains "clock", to a temporary folder
    python benches/refine_blind11.py --sizes      # each case's effect size only (no refine)
"""

from __future__ import annotations

import math

import numpy as np
from scipy import signal

import refine_blind as rb
import refine_blind2 as rb2
import refine_blind9 as rb9
import refine_blind10 as rb10

sensors = rb.sensors
Injected = sensors.Injected
Blind11 = rb2.Blind2
_periodic = rb2._periodic
_weather = rb10._weather  # a random walk through a first-order lag, peak-to-peak 1


# ---------------------------------------------------------------------------------------------------------------
# 1. ring-laser gyro, pulse counts, dither residue folded

#: RLG: output rate (Hz), pulse weight (rad), dither (Hz), residue of the dither and its 2nd harmonic (rad/s)
RLG_FS, RLG_Q, RLG_FD, RLG_A1, RLG_A2 = 400.0, 1.5e-6, 427.0, 4e-3, 2e-3


def _counted_gain(f: float) -> float:
    """A pulse count over one output interval is the rate's boxcar mean: its gain at f Hz."""
    x = math.pi * f / RLG_FS
    return abs(math.sin(x) / x)


def _rlg_rms() -> float:
    a1, a2 = RLG_A1 * _counted_gain(RLG_FD), RLG_A2 * _counted_gain(2 * RLG_FD)
    return math.sqrt((a1 * a1 + a2 * a2) / 2.0)


def _rlg(rng):
    fs, n = RLG_FS, 2_000_000  # 5000 s
    t = np.arange(n + 1) / fs
    rate = rb.noise(n, fs, rng, N=3e-7, B=4e-8, K=1e-9) + 7.3e-5  # the earth's rate on the axis as its bias
    w1, w2 = 2 * np.pi * RLG_FD, 2 * np.pi * 2 * RLG_FD
    # the angle: the noise integrated per interval, the residue integrated exactly
    theta = np.concatenate([[0.0], np.cumsum(rate) / fs])
    theta += RLG_A1 / w1 * (1 - np.cos(w1 * t + 0.3)) + RLG_A2 / w2 * (1 - np.cos(w2 * t + 1.1))
    counts = np.diff(np.floor(theta / RLG_Q))
    y = counts * RLG_Q * fs
    comp = np.diff(RLG_A1 / w1 * (1 - np.cos(w1 * t + 0.3)) + RLG_A2 / w2 * (1 - np.cos(w2 * t + 1.1))) * fs
    return y, fs, {}, {}, comp


# ---------------------------------------------------------------------------------------------------------------
# 2. FOG at 4 kHz, 1/f corner


def _fog_4k(rng):
    fs, n = 4000.0, 4_000_000  # 1000 s
    return rb.noise(n, fs, rng, N=1e-6, B=2.5e-6, K=2e-9), fs, {}, {}, None  # f_c = B²/(2πN²) ≈ 1 Hz


# ---------------------------------------------------------------------------------------------------------------
# 3. equiripple FIR decimator

FIR_FS_IN, FIR_DEC, FIR_PASS, FIR_STOP, FIR_TAPS = 8000.0, 8, 300.0, 450.0, 95


def _fir_taps() -> np.ndarray:
    return signal.remez(FIR_TAPS, [0, FIR_PASS, FIR_STOP, FIR_FS_IN / 2], [1, 0], weight=[1, 30], fs=FIR_FS_IN)


def _fir_cutoff() -> float:
    """The FIR's −3 dB frequency (Hz): the first frequency past the passband where |H| falls below 1/√2."""
    f, h = signal.freqz(_fir_taps(), worN=2**16, fs=FIR_FS_IN)
    g = np.abs(h)
    k = int(np.argmax((f > FIR_PASS) & (g < 1 / math.sqrt(2))))
    return float(np.interp(1 / math.sqrt(2), [g[k], g[k - 1]], [f[k], f[k - 1]]))


def _fir_ripple_db() -> float:
    f, h = signal.freqz(_fir_taps(), worN=2**14, fs=FIR_FS_IN)
    g = 20 * np.log10(np.abs(h[f <= FIR_PASS]))
    return float(np.ptp(g))


def _fir_mems(rng):
    n = 1_000_000  # 1000 s at 1 kHz
    x = rb.noise(n * FIR_DEC, FIR_FS_IN, rng, N=4e-3, B=6e-4, K=2e-5)
    y = signal.lfilter(_fir_taps(), 1.0, x)[::FIR_DEC]
    return y, FIR_FS_IN / FIR_DEC, {}, {}, {"without": x[::FIR_DEC]}


# ---------------------------------------------------------------------------------------------------------------
# 4. temperature at 0.1 Hz, linearly interpolated

#: the bias per °C; the thermometer's sample interval (s) and its resolution (°C)
SLOWT_C, SLOWT_DT, SLOWT_LSB = 4e-4, 10.0, 0.0625


def _slow_thermometer(rng):
    fs, n = 50.0, 1_000_000  # 2·10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=4e-4, K=1e-5)
    temp = 25.0 + 6.0 * np.sin(2 * np.pi * t / 8000.0 + 0.4) + 3.0 * _weather(n, fs, rng, 1500.0)
    comp = SLOWT_C * (temp - temp.mean())
    step = int(SLOWT_DT * fs)
    read = np.round(temp[::step] / SLOWT_LSB) * SLOWT_LSB
    logged = np.interp(t, t[::step], read)
    return y + comp, fs, {"temp": logged}, {}, comp


# ---------------------------------------------------------------------------------------------------------------
# 5. three axes, each its own temperature coupling

#: per axis: level coefficient (°/s per °C) and quadratic (°/s per °C²) about the mean temperature
AX_C, AX_Q = (4e-4, -1.5e-4, 0.0), (0.0, 2e-5, 0.0)


def _axes_temperature(axis: int):
    def build(rng):
        fs, n = 100.0, 1_000_000  # 10⁴ s
        t = np.arange(n) / fs
        x = np.column_stack([rb.noise(n, fs, rng, N=3e-3, B=4e-4, K=1e-5) for _ in range(3)])
        temp = 25.0 + 20.0 * np.sin(2 * np.pi * t / 5000.0 - 1.2) + 1.0 * _weather(n, fs, rng, 400.0)
        d = temp - temp.mean()
        comps = [c * d + q * (d * d - np.mean(d * d)) for c, q in zip(AX_C, AX_Q, strict=True)]
        for j, c in enumerate(comps):
            x[:, j] += c
        return x, fs, {"temp": temp + 0.02 * rng.standard_normal(n)}, {"axis": axis}, comps[axis]

    return build


# ---------------------------------------------------------------------------------------------------------------
# 6. a magnetometer channel that has nothing to do with the bias


def _magnetometer(rng):
    fs, n = 100.0, 1_000_000  # 10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=5e-4, K=3e-5)
    heading = np.zeros(n)
    for t0 in np.sort(rng.uniform(0.0, t[-1], 8)):  # the vehicle parked again at another heading
        heading[t >= t0] = rng.uniform(0.0, 2 * np.pi)
    mag = 22.0 * np.cos(heading) + 0.4 * np.sin(2 * np.pi * t / 86_400.0) + 0.3 * _weather(n, fs, rng, 200.0)
    return y, fs, {"mag_x": mag + 0.05 * rng.standard_normal(n)}, {}, None


# ---------------------------------------------------------------------------------------------------------------
# 7. a clock: phase turned to frequency, flicker FM, ageing and a settling

#: the settling after switch-on (fractional frequency, s) and the linear ageing (per s)
CLK_A, CLK_T, CLK_AGE = 2e-11, 15_000.0, 2e-17


def _clock(rng):
    fs, n = 1.0, 200_000  # 2·10⁵ s, 2.3 days
    t = np.arange(n + 1) / fs
    freq = rb.noise(n + 1, fs, rng, N=3e-12, B=2e-13, K=1e-16)
    freq += CLK_A * np.exp(-t / CLK_T) + CLK_AGE * t
    phase = np.cumsum(freq) / fs + 2e-12 * rng.standard_normal(n + 1)  # white PM of the phase comparator
    y = np.diff(phase) * fs
    comp = CLK_A * np.exp(-t[1:] / CLK_T)
    return y, fs, {}, {}, comp


# ---------------------------------------------------------------------------------------------------------------
# 8. spin table: a residual line fading (outside)


def _fading_line(rng):
    fs, n = 200.0, 1_000_000  # 5000 s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2e-3, B=3e-4, K=5e-6)
    amp = 0.02 * (1.0 - 0.55 * t / t[-1])  # the table's residual wobble dying away as it settles
    comp = amp * np.sin(2 * np.pi * 0.5 * t + 0.8)
    return y + comp, fs, {}, {}, comp


# ---------------------------------------------------------------------------------------------------------------
# 9. 48 h at 1 Hz, two power cycles (outside)

#: each power cycle: time (s), the bias step it leaves (°/s), its settling amplitude (°/s) and time constant (s)
PWR = ((52_000.0, 2.5e-3, 1.5e-3, 300.0), (118_000.0, -3.5e-3, 1.5e-3, 300.0))


def _power_cycles(rng):
    fs, n = 1.0, 172_800  # 48 h
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=1e-3, B=1e-4, K=2e-6)
    comp = np.zeros(n)
    for t0, step, a, tc in PWR:
        on = t >= t0
        comp[on] += step + a * np.exp(-(t[on] - t0) / tc)
    return y + comp, fs, {}, {}, comp


# ---------------------------------------------------------------------------------------------------------------
# 10. asymmetric burst noise

#: the high state's height (°/s), mean dwell low and high (s)
BURST_H, BURST_LOW, BURST_HIGH = 0.02, 200.0, 5.0


def _burst_gm() -> dict:
    p = BURST_HIGH / (BURST_LOW + BURST_HIGH)
    return {"sigma": BURST_H * math.sqrt(p * (1 - p)), "tc": 1.0 / (1 / BURST_LOW + 1 / BURST_HIGH)}


def _telegraph(n: int, fs: float, rng) -> np.ndarray:
    out = np.zeros(n)
    k, high = 0, False
    while k < n:
        dwell = max(1, int(round(rng.exponential(BURST_HIGH if high else BURST_LOW) * fs)))
        if high:
            out[k : k + dwell] = BURST_H
        k, high = k + dwell, not high
    return out


def _bursts(rng):
    fs, n = 100.0, 1_000_000  # 10⁴ s
    y = rb.noise(n, fs, rng, N=2e-3, B=2e-4, K=5e-6)
    comp = _telegraph(n, fs, rng)
    return y + comp, fs, {}, {}, comp - comp.mean()


# ---------------------------------------------------------------------------------------------------------------
# 11. float32 accelerometer, noise doubling at 0.62 T

ACC_T = 620.0


def _accel_doubles(rng):
    fs, n = 1000.0, 1_000_000  # 1000 s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, B=2e-4, K=1e-5)
    white = 4e-4 * math.sqrt(fs) * rng.standard_normal(n)
    white[t >= ACC_T] *= 2.0  # a second motor started
    return (9.80665 + y + white).astype(np.float32), fs, {}, {}, None


# ---------------------------------------------------------------------------------------------------------------
# 12. sense-mode resonance

#: the hump: centre (Hz), quality factor, rms (°/s)
RES_F, RES_Q, RES_SIGMA = 310.0, 8.0, 0.25


def _resonance(rng):
    fs, n = 2000.0, 2_000_000  # 1000 s
    y = rb.noise(n, fs, rng, N=2e-3, B=3e-4, K=1e-5)
    b, a = signal.iirpeak(RES_F, RES_Q, fs=fs)
    hump = signal.lfilter(b, a, rng.standard_normal(n + 20_000))[20_000:]
    comp = RES_SIGMA * hump / hump.std()
    return y + comp, fs, {}, {}, comp


CASES = [
    Blind11(
        "navigation-grade RLG (rad/s) as pulse counts of 1.5 µrad at 400 Hz × 2·10⁶: its 427 Hz dither residue and 2nd harmonic fold to a 27 Hz family",
        _rlg,
        [_periodic([RLG_FD - RLG_FS], _rlg_rms())],
        unit="rad/s",
        seed=1101,
    ),
    Blind11(
        "fibre-optic gyro (rad/s) at 4 kHz × 4·10⁶, white and flicker with a 1/f corner near 1 Hz (clean)",
        _fog_4k,
        unit="rad/s",
        seed=1102,
    ),
    Blind11(
        f"MEMS decimated 8 kHz → 1 kHz by a 95-tap equiripple FIR ({_fir_ripple_db():.1f} dB passband ripple to 300 Hz, −3 dB at {_fir_cutoff():.0f} Hz), 1 kHz × 10⁶: only the roll-off to name",
        _fir_mems,
        [Injected("bandwidth", {"cutoff": _fir_cutoff()})],
        seed=1103,
    ),
    Blind11(
        "temperature read at 0.1 Hz (1/16 °C) and linearly interpolated to the gyro's 50 Hz × 10⁶, 4·10⁻⁴ °/s per °C",
        _slow_thermometer,
        [Injected("regression", {"coefficient": SLOWT_C})],
        channel="temp",
        seed=1104,
    ),
    Blind11(
        "three axes (n, 3) with one temperature, 5–45 °C twice, 100 Hz × 10⁶, each its own coupling (+4·10⁻⁴; −1.5·10⁻⁴ with 2·10⁻⁵ per °C²; none): axis 1",
        _axes_temperature(1),
        [Injected("regression", {"coefficient": AX_C[1], "quadratic": AX_Q[1]})],
        channel="temp",
        seed=1105,
    ),
    Blind11(
        "a magnetometer channel (µT: heading changes, a daily swing) beside a gyro that does not follow it, 100 Hz × 10⁶ (clean: the channel not taken)",
        _magnetometer,
        seed=1106,
    ),
    Blind11(
        "clock: 1 Hz phase × 2·10⁵ turned to frequency (unit None), white PM, flicker FM, ageing 2·10⁻¹⁷/s and a settling 2·10⁻¹¹·e^{−t/15000 s}",
        _clock,
        [Injected("drift", {"amplitude": CLK_A, "T": CLK_T})],
        unit=None,
        seed=1107,
    ),
    Blind11(
        "outside the family: a spin table's residual 0.5 Hz line fading 0.02 → 0.009 °/s along the record, 200 Hz × 10⁶",
        _fading_line,
        outside=True,
        seed=1108,
    ),
    Blind11(
        "outside the family: 48 h at 1 Hz, two power cycles, each a bias step (+2.5, −3.5 ·10⁻³ °/s) and a 300 s settling",
        _power_cycles,
        outside=True,
        seed=1109,
    ),
    Blind11(
        "asymmetric burst noise: a 0.02 °/s high state visited for 5 s every 200 s on average, 100 Hz × 10⁶ (a Gauss–Markov spectrum)",
        _bursts,
        [Injected("gauss_markov", _burst_gm())],
        seed=1110,
    ),
    Blind11(
        "float32 accelerometer on 1 g (m/s², unit None), 1 kHz × 10⁶, its white noise doubling at 620 s (0.62 T)",
        _accel_doubles,
        [Injected("change_point", {"t": ACC_T})],
        unit=None,
        seed=1111,
    ),
    Blind11(
        "2 kHz MEMS × 2·10⁶ whose sense-mode resonance (310 Hz, Q 8) shows as a 0.25 °/s narrowband hump",
        _resonance,
        [Injected("resonance", {"sigma": RES_SIGMA, "f0": RES_F, "q": RES_Q})],
        seed=1112,
    ),
]


run_case = rb9.run_case


#: What the table shows and why (kept true to the recorded run).
NOTES: list = [
    "**First run** (at dc7cdfd, the suite as committed, before any change; other processes used 81 % of the CPUs; its table and JSON are in commit e66d229): **8 of 12 passed**, without the candidate **8 of 8** flagged. Passed as a user would want: the 4 kHz FOG with its 1 Hz 1/f corner (nothing added: the drift's statistic 17.8 against 427, every curve candidate below its threshold); the temperature read at 0.1 Hz, quantised to 1/16 °C and linearly interpolated (regression on `temp`, +0.9 %); the three axes each with its own coupling, refined on the negative one (coefficient +3.0 % — the sign right —, quadratic −0.9 %); the magnetometer channel beside a gyro that does not follow it (not taken: the regression's statistic 0 against 12.2; nothing added, nothing said); the clock's settling in frequency turned from phase (drift amplitude +2.7 %, T +1.7 %, the linear ageing left to R); the spin table's fading line, outside the family (one sinusoid at the mean amplitude 0.0148 °/s, and said: \"the 0.50 Hz line's amplitude changes along the record: 0.0169 deg/s in t 0–2812 s, 0.0114 deg/s in t 2812–5000 s\"); the 48 h log's two power cycles, outside the family (said: \"the mean steps by 0.0027 deg/s at t ≈ 51996 s; by −0.003 deg/s at t ≈ 118020 s\", the steps check's statistic 8.65 against 2.33 — beside a noise-level change point at 51 856 s standing in for the first step, gain χ² 116 at τ 256 s, and the start fit's K 1.06·10⁻⁵ °/s^1.5 against the truth 2·10⁻⁶: the steps taken into K); the float32 accelerometer's noise doubling (change point at 619.99 s, −0.0 %).",
    "",
    "The accelerometer's row passes with a stand-in beside its change point that the judge does not fail: a `resonance` (σ 1.7·10⁻³ m/s², f0 92 Hz, q 2; GLS score 22.0 against 12.4 at α 1.31 %) taken before the change point, on a start χ²/dof of 1.79. The tests' covariance is the stationary model's; a record whose white level doubles at 0.62 T has short-τ Allan estimates whose variance is Σσ⁴/(Σσ²)² = 6.7/2.14² ≈ 1.46× a stationary record's at the same level. A diagnostic twin (the same seed's noise at one level, the length-weighted variance; not a case of the suite) starts at χ²/dof 1.34 and takes nothing — consistent with, not a proof of, the level change inflating the curve's score. The same stand-in is taken without the change-point candidate, where the level check then says \"1.98× the Allan deviation at τ₀ of t 0–620 s\".",
    "",
    "Why four failed at the first run (from each Refinement's evidence: `considered`, the steps' `evidence`, `unexplained`):",
    "",
    "- *Pulse-counted RLG, dither residue folded to 27 Hz* — both folded lines found at their exact counted amplitudes (27.006 Hz, 2.510·10⁻⁴ rad/s; 53.994 Hz, 1.2275·10⁻⁴; the truths 2.510·10⁻⁴ and 1.227·10⁻⁴), but as two `sinusoid` steps, not one `periodic` family: the family candidate's test passed (PSD ratio 2.3·10⁵ against 1.52, α 1 %) with generators [75.67, 27.006] Hz (sidebands k·75.67 ± s·27.0, 182 lines, rms 1.04·10⁻⁵ rad/s against the dither family's 1.98·10⁻⁴) and was turned down on the held-out error (36.358 → 36.373 %). Three more sinusoids followed (102.7, 183.7, 156.7 Hz) and `unexplained` lists the curve at τ 2.5–10 ms (score 2.1·10⁴ against 17.1) and line clusters at 5.1–5.7, 21.3–21.9, 32.1–32.6, 48.4–48.9, 75.3–76.0, 81–87, 102–114, 129–141 and 152–195 Hz (PSD statistics 3.9–18 against ≈ 1.58). Those lines are in the record, not in the row's truth: the bias's count rate is 7.3·10⁻⁵/1.5·10⁻⁶ = 48.67 pulses/s and the noise's angle per sample is 0.01 pulse, so the counter's quantiser is not dithered by the noise and its error is deterministic — lines at i·27 + j·48.67 Hz (mod 400) (a diagnostic on the suite's seed, the counts less the dither residue and the rate noise: rms 2.6·10⁻⁴ rad/s, larger than the dither family's; its strongest lines at 102.65 = 2·27 + 48.67, 183.67 = 5·27 + 48.67, 156.6, 140.4, 167.4, 189.4 Hz, each i·27 ± 48.67 or 400 − (6·27 + 48.67)). A real RLG's own (randomised) dither whitens its quantiser; this case's does not — the truth written before the run is incomplete (a perfect answer would name the quantiser's intermodulation family too), and the case is not changed after it. What refine did wrong by the judge either way: two lines at f and 2f kept as sinusoids because the family was grouped on the wrong generator.",
    '- *Equiripple FIR decimator (−3 dB at 327 Hz)* — the roll-off named (`bandwidth` butterworth3 at 309 Hz, −5.6 %, GLS score 1.06·10⁵ against 12.1; χ²/dof 2576 → 129, held out 11.5 → 4.9 %) but the Allan curve still departs at τ 1–129 ms (score 4104 against 22.4, α 0.19 %). The FIR is flat (1.3 dB ripple) to 300 Hz and falls to its −52 dB stopband by 450 Hz: sharper than any kind in the bandwidth family (single pole, Butterworth 2–6, moving average, Bartlett, boxcar, sinc^k), and butterworth3 stands in; a Gauss–Markov term at the edge of its grid (T_c 5 ms, score 1.9·10⁴) and a 195 Hz resonance (amplitude 0) were turned down. Failed on `unexplained` alone. Arguably the right answer for a filter whose shape the family lacks (the roll-off named, the misfit said) — the judge\'s "nothing unexplained" asks for an FIR kind; the judge is not changed.',
    "- *Asymmetric burst noise* — the Gauss–Markov term found (σ +6.5 %, T_c −0.1 %; score 845 against 12.6; χ²/dof 35.9 → 1.78, held out 13.8 → 5.2 %), then three noise-level change points at 2869, 6444 and 8719 s (each at τ 10.2 s in 625 s windows, gain χ² 137, 106, 118) and `unexplained`: \"the mean steps by −0.0097 deg/s at t ≈ 7373.68 s\" (the steps check, 2.78 against 2.43 at α 0.016 %). The process is stationary; it has only 50 visits to its high state (the longest 22 s), so windows of 625 s differ in how many they hold far more than a Gaussian process of the same spectrum does, and a long visit reads as a step of the mean. Diagnostic twin (a Gaussian Gauss–Markov of the same σ and T_c on the same seed's noise, not a case of the suite): the Gauss–Markov term alone (σ 3.08·10⁻³, T_c 4.91 s), no change point, nothing unexplained — the telegraph's non-Gaussian block statistics, not its spectrum, drive the change points and the step entry. Failed on `unexplained` (the extra change points are not failed by the judge).",
    "- *Sense-mode resonance (310 Hz, Q 8, a digital 2nd-order resonator at 2 kHz)* — named with the right centre and Q (σ 0.2498 at acceptance, 0.2291 after the final refit: −8.4 %; f0 311.3 Hz, +0.4 %; q 8; score 4.4·10⁶ against 11.8), then a second resonance (308.4 Hz, q 16, σ 0.112; score 2.8·10⁴ against 11.6) stands in for the shape, and the final fit's N went to 0 (the start's 1.96·10⁻³ °/√s, the truth 2·10⁻³): the resonance columns took the white noise. Still said: the curve departs at τ 2–7 ms (score 1887 against 23.8), lies above the model at τ 1–1.5 ms (784) and below it at τ 7.5–8.5 ms (198); χ²/dof 6.9·10⁴ → 316. Measured (`allanite.model._signatures.resonance_avar` against the exact Allan variance of the injected process, from `iirpeak`'s impulse response, both at unit variance, 310 Hz, Q 8, 2 kHz): within 4 % at τ ≤ 2 ms, then the kind's is 1.3–7× the process's (τ 3 ms: 0.051 against 0.029; 10 ms 2.1×; 79 ms 6.9×). The kind is a Lorentzian pair, R(l) = Re ρ^|l|, whose PSD is not zero at DC, so its Allan variance ends in a white-like τ⁻¹ tail; a resonator read through a band-pass (`iirpeak`: zeros at DC and Nyquist; a sense mode's rate-like output) has no power at DC and its tail falls as τ⁻². That tail is what took the white noise (final N 0) and what the second resonance and the regions left patch — a kind missing from the family (a band-pass resonance, or R(l) = Re(c·ρ^|l|) with a complex weight), not traced further in the model. Failed on `unexplained` alone.",
    "",
    "On two other seeds each (offsets +100, +200; the default call, judged as the suite judges; not rows of the suite): the FIR decimator fails on both the same way (butterworth3 at 308.5 and 301.8 Hz, −5.8 % and −7.8 %, the curve departing); the resonance on both (seed 1212: five resonances, 279.6–366.9 Hz; seed 1312: two, as here); the burst noise passes on 1 of 2 (seed 1310: Gauss–Markov alone, σ +12.1 %, T_c −0.8 %, nothing said; seed 1210: T_c −22.9 % and two steps of the mean said); the accelerometer passes on both with its change point alone (620.00 and 620.00 s) — the resonance stand-in of the suite seed is that seed's.",
    "",
    "Without the candidate (8 of 8 flagged): the RLG's 27 Hz line said by the PSD check; the FIR's curve departing at τ 1–222 ms; the 0.1 Hz thermometer's \"the rate still follows channel 'temp' (≈ 3.92·10⁻⁴)\"; the axis's \"depends on 'temp' beyond its kept terms\"; the clock's steps of the mean and \"a warm-up-like drift along the record (T ≈ 1.56·10⁴ s)\"; the bursts' curve above the model at τ 0.02–0.16 s; the accelerometer's level check; the resonance's curve at τ 1.5–4.5 ms.",
    "**Rerun whole at 3a5188d** (the first notes committed, no library change; other processes 88 % of the CPUs): every row's fields as at the first run — verdicts, effects, parameters, errors, words, without the candidate — only the CPU column moved: **8 of 12**, without the candidate 8 of 8 (the table above).",
    "Rerun whole at 9eaf694 (the 2026-11-28 morning's branches merged: r14house, r14blind11, r14modline, r14pump, r14cost, r14lagrate, r14fir; r14reson merged and reverted; another suite chain, the ADIS16405 run and CI shared the 2 cores, so the CPU column is not a cost measurement): every row as at the first run — 8 of 12. The FIR row's misfit is its 1.3 dB passband ripple, not its steepness (r14fir); a digital-resonator kind passed the resonance row but moved the ADIS16405 rows and was reverted (r14reson).",
    "**r16family** (no row rerun for this note; `benches/r16family.py` → `benches/results/r16family.md`): the pulse-counted RLG's quantiser lines are not deterministic — least squares at their exact frequencies (i·27 + 48.67 Hz, mod 400) reads 1.1–3.2·10⁻⁶ rad/s over the whole record and ≈ 2·10⁻⁵ over 50 s blocks, against 3.5–9.3·10⁻⁵ in the spectrum, while the dither residue's 27 and 54 Hz read the same three ways (2.51·10⁻⁴, 1.23·10⁻⁴). The count rate's phase, θ/Q, random-walks with the angle noise (0.01 pulse a sample: a line width ≈ 0.25 Hz), which is why each cluster is five peaks 0.065 Hz apart. No family of fixed frequencies removes them, so `unexplained` naming them is right; what refine still does wrong is the grouping: the two-generator lattice [27.006, 75.67] (rows to k = 56) matched 182 of the 197 peaks, its generators refined on them put the 27 Hz row 0.006 Hz off (least-squares amplitude there 8.6·10⁻⁸ of 2.51·10⁻⁴), and the family was turned down — a one-generator family [27] of its two coherent lines is the answer. Also: 27 = 81/3 and 48.67 = 146/3 Hz, so at 400 Hz every line lies on the 1/3 Hz lattice and no two-generator basis for them is unique.",
    "**r16burst** (`--case burst` rerun at 7c84868, the `telegraph` removal; the row above and its JSON replaced, the other rows as before; other helpers' runs shared the 2 cores, load 10–13): the telegraph is now named and removed in time — amplitude 0.019999 °/s (−0.0 %), mean dwells 230.8 s low (+15 %) and 6.38 s high (+28 %; visits shorter than the decoding's blocks are missed, which lengthens both) — and no change point is taken and nothing is said (χ²/dof 35.9 → 0.977, held out 13.8 → 0.32 %). A small Gauss–Markov term is added after it (σ 6.3·10⁻⁴, T_c 0.54 s): the leftovers of the missed short visits. The judge still reads the row's truth as a Gauss–Markov term (σ −79.6 %, T_c −89.0 %), so the row stays ✗ (8 of 12). The judge is left as committed: a truth of `telegraph` (amplitude 0.02, dwell_low 200, dwell_high 5) would fail this seed on the high dwell alone (+28 % against 20 %). Seeds +100 and +200 (1210, 1310): the telegraph alone (amplitude −0.6 %, +0.8 %; dwells +11.6 %/−6.5 %, −6.6 %/+18.3 %), no change point, nothing said, χ²/dof 23.3 → 0.86 and 34.7 → 0.84, held out 12.0 → 0.25 % and 11.3 → 0.36 %. Before, seed 1210 said two steps of the mean and seed 1310 passed with the Gauss–Markov term alone. Without the candidate (no `gauss_markov`), the telegraph is taken on all three and nothing is said.",
    "**Rerun whole at 72c4d63** (the 2026-11-28 late-morning branches merged: r16heldout — the chain's deviance and AIC, keys only —, r16family, r16reson, r16burst, and the telegraph's regular-dwell decline; other suites shared the 2 cores, so the CPU column is not a cost measurement): **9 of 12** — the sense-mode row passes (one band-pass resonance: σ +0.04 %, f0 −0.003 %, Q 8; nothing unexplained), every other row's verdict, effects and words as recorded. The burst row is named a telegraph (amplitude −0.0 %, dwells +15 % and +28 %) beside a small Gauss–Markov term, with no change point and nothing said, but its truth is the Gauss–Markov term it was written with (✗ as committed); without the Gauss–Markov candidate the telegraph explains it and nothing is said (without the candidate 7 of 8; the telegraph is the process's own name).",
    "**r17nocand: the burst row without its candidate** (2026-11-28, `/tmp` driver at cb4d330; load 8–13 on the 2 cores, other helpers' runs beside): the default call as recorded (the telegraph and a small Gauss–Markov term, nothing said); without the Gauss–Markov candidate the telegraph takes it and nothing is said, as recorded — left so: the process is a telegraph (a 0.02 °/s high state visited for 5 s every 200 s), so the telegraph explaining it is the right reading and nothing is missing; no check was made to flag it.",
    "Rerun whole on 2026-11-28 at 45caf74 (the r17 merges: the alternative chains unified and memoised, the declared filter, the follows check, the channel check's first quadratic, the level test's runs of blocks, the slow-line test's second reading; r17cost2's cheaper arithmetic, equal to 1e-9, was merged after) with 044680b's why_not_kept fix: every row's verdict, effects and unexplained domains as recorded, and every without-candidate flag.",
    "",
    "Rerun whole on 2026-11-28 at da6740f (the r18 merges: r18cost's and r18boot's cheaper arithmetic, the sigma-delta's shaped quantisation (r18sdm), a quantised output's floor (r18bartlett), sharp rippled filter kinds (r18sharp), line families whose fundamental hunts (r18hunt); other suites, CI and the false-alarm bench shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict as recorded — 9 of 12. The FIR decimator (1.3 dB ripple) is now read as a sharp kind (r18sharp: elliptic4 at −1.13 dB ripple, cutoff −5.6 % → −1.0 %, χ²/dof 128.6 → 53.6, held out 4.91 → 3.76 %) and still fails on `unexplained` alone (it passes with its taps declared); the RLG's diffusing lines now end in a one-line 'periodic' at 0.6 Hz in place of a fifth sinusoid (r18hunt), still ✗.",
]


def main(argv=None) -> None:
    rb2.suite_main(argv, __doc__, CASES, run_case, rb9._size, NOTES, "refine_blind11", "eleventh")


if __name__ == "__main__":
    main()
