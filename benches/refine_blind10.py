#!/usr/bin/env python3
"""``allanite.refine`` on a tenth blind suite of simulated sensors, unlike ``tests/sensors.py``, the nine earlier
blind suites (``benches/refine_blind.py`` … ``refine_blind9.py``) and the ADIS16405 — what a user brings with
default arguments.

**Written and committed before it was first run.** The effects' sizes were fixed beforehand by their Allan
deviation alone (``--sizes``, as ``benches/refine_blind5.py`` sizes them: ≥ 3× for every curve effect a case asks
refine to find; the sparse spikes, judged by their rate, and the effect outside the family are as a sensor makes
them), never by refine's answer; the first run's verdicts are recorded as they came out (the notes below the
table) and the cases are not retuned after it.

The cases: a gyro logged with three channels (temperature, supply voltage, relative humidity; the humidity
partly anti-correlated with the temperature) whose bias follows the humidity only; a warm-up that is the
temperature's own warm-up (the bias linear in a temperature that rises as 1 − e^{−t/900 s}: a drift and a
regression describe it alike — the channel, the cause, is asked for and a drift is forbidden); a tiltmeter (µrad,
unit None) at 0.5 Hz × 2·10⁵ (4.6 days, fs < 1 Hz) with a daily line and an 11 h settling drift; 2·10⁴ samples
only (50 s) at 400 Hz with 30 spikes; int32 counts at 2 kHz behind an integrate-and-dump (sinc¹, 16 kHz → 2 kHz)
decimator with a 37 Hz hum and its 3rd harmonic; float32 samples on a 20 °/s bias at 400 Hz × 4·10⁶ whose
bias is slow and quadratic in the temperature; a gyro whose temperature sensor is noisy (white, σ 10 % of the
swing); two line families at once (a 1.7 Hz square wave and a 13.7 Hz hum with its 2nd harmonic); a three-axis
(n, 3) log whose axes share one 23 Hz vibration family at amplitudes 1 : 0.25 : 0.6 (refined on the weakest
axis); a thermostat's sawtooth whose period lengthens 120 → 132 s along the record (outside the family: a
family of constant fundamental does not hold it) — and two clean cases: a tiny record (4096 samples at 50 Hz),
and white noise drawn uniform (light tails: no outlier may be taken) beside flicker at 1 kHz.

Truths are in the unit refine reports (°/s for the gyros unless said; counts and µrad as said). A family is
judged on its fundamental(s) and its rms (over all its lines).

Judged as ``benches/refine_blind9.py`` judges (``refine_blind4._judged``: named, parameters within 20 %,
frequencies within 1 %, the chain's error falling in sample and held out, ``unexplained`` empty; a clean case:
nothing added but what it allows, nothing unexplained; an effect outside the family: something left unexplained;
a named channel: no regression on another; a forbidden effect: not added).

Usage::

    python benches/refine_blind10.py                  # -> benches/results/refine_blind10.{json,md}
    python benches/refine_blind10.py --case humidity  # the cases whose name contains "humidity", to a temporary folder
    python benches/refine_blind10.py --sizes          # each case's effect size only (no refine)
"""

from __future__ import annotations

import math

import numpy as np
from scipy import signal

import refine_blind as rb
import refine_blind2 as rb2
import refine_blind9 as rb9

sensors = rb.sensors
Injected = sensors.Injected
Blind10 = rb2.Blind2
_periodic = rb2._periodic


def _weather(n: int, fs: float, rng, lag_s: float) -> np.ndarray:
    """A random walk through a first-order lag of ``lag_s``, scaled to a peak-to-peak of 1."""
    w = sensors.first_order_lag(np.cumsum(rng.standard_normal(n)), fs, lag_s)
    return (w - w.mean()) / max(np.ptp(w), 1e-300)


#: the bias per % relative humidity (°/s per %RH)
HUM_C = 3e-4


def _humidity(rng):
    fs, n = 20.0, 1_000_000  # 5·10⁴ s, 13.9 h
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=4e-4, K=1e-5)
    cycle = np.sin(2 * np.pi * t / 20_000.0)
    temp = 24.0 + 3.0 * cycle + 2.0 * _weather(n, fs, rng, 3000.0)
    hum = 45.0 - 8.0 * cycle + 15.0 * _weather(n, fs, rng, 2000.0)  # partly anti-correlated with T
    volt = 12.0 + 0.3 * _weather(n, fs, rng, 500.0) + 0.05 * (np.mod(t, 7000.0) < 1500.0)
    comp = HUM_C * (hum - hum.mean())
    channels = {
        "temp": temp + 0.01 * rng.standard_normal(n),
        "supply_v": volt + 0.002 * rng.standard_normal(n),
        "humidity": hum + 0.1 * rng.standard_normal(n),
    }
    return y + comp, fs, channels, {}, comp


#: the bias per °C, and the temperature's warm-up (°C rise, time constant s)
WT_C, WT_RISE, WT_T = 1.2e-3, 15.0, 900.0


def _warm_by_temp(rng):
    fs, n = 100.0, 1_000_000  # 10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=4e-4, K=1e-5)
    temp = 22.0 + WT_RISE * (1.0 - np.exp(-t / WT_T)) + 0.4 * _weather(n, fs, rng, 600.0)
    comp = WT_C * (temp - temp.mean())
    return y + comp, fs, {"temp": temp + 0.01 * rng.standard_normal(n)}, {}, comp


#: the tiltmeter: daily line (µrad), settling drift (µrad, s)
TILT_LINE, TILT_DRIFT, TILT_T = 0.6, 2.0, 40_000.0


def _tiltmeter(rng):
    fs, n = 0.5, 200_000  # 4·10⁵ s, 4.6 days
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=0.05, B=0.01, K=2e-5)
    line = TILT_LINE * np.sin(2 * np.pi * t / 86_400.0 + 0.7)
    drift = TILT_DRIFT * np.exp(-t / TILT_T)
    return y + line + drift, fs, {}, {}, [line, drift]


#: a 50 s record at 400 Hz: how many spikes, their size (× the per-sample σ)
SHORT_SPIKES, SHORT_SIGMAS = 30, (10.0, 20.0)


def _short_spikes(rng):
    fs, n = 400.0, 20_000
    y = rb.noise(n, fs, rng, N=2e-3, B=3e-4, K=1e-5)
    sigma = 2e-3 * math.sqrt(fs)
    hit = rng.choice(np.arange(5, n - 5), SHORT_SPIKES, replace=False)
    size = SHORT_SIGMAS[0] + (SHORT_SIGMAS[1] - SHORT_SIGMAS[0]) * rng.random(SHORT_SPIKES)
    spikes = np.zeros(n)
    spikes[hit] = sigma * size * rng.choice([-1.0, 1.0], SHORT_SPIKES)
    return y + spikes, fs, {}, {}, spikes


#: the hum (counts at 16 kHz before the decimator): fundamental (Hz), its and its 3rd harmonic's amplitudes
HUM_F0, HUM_A1, HUM_A3, DEC, FS_IN = 37.0, 6.0, 2.5, 8, 16_000.0


def _dump_gain(f: float) -> float:
    """The integrate-and-dump's (a D-sample boxcar at FS_IN) gain at f Hz."""
    x = math.pi * f / FS_IN
    return abs(math.sin(DEC * x) / (DEC * math.sin(x)))


def _hum_rms() -> float:
    a1, a3 = HUM_A1 * _dump_gain(HUM_F0), HUM_A3 * _dump_gain(3 * HUM_F0)
    return math.sqrt((a1 * a1 + a3 * a3) / 2.0)


def _counts_sinc(rng):
    n = 1_000_000  # 500 s at 2 kHz
    fs = FS_IN / DEC
    t = np.arange(n * DEC) / FS_IN
    x = rb.noise(n * DEC, FS_IN, rng, N=3.0 * math.sqrt(DEC) / math.sqrt(FS_IN), B=0.3, K=0.02)
    hum = HUM_A1 * np.sin(2 * np.pi * HUM_F0 * t + 0.2) + HUM_A3 * np.sin(2 * np.pi * 3 * HUM_F0 * t + 1.3)
    y = (x + hum).reshape(n, DEC).mean(axis=1)
    comp = hum.reshape(n, DEC).mean(axis=1)
    return np.round(y + 2_000_000.0).astype(np.int32), fs, {}, {}, comp


#: the float32 gyro's bias (°/s) and its slow coupling: level and quadratic about the mean temperature
F32_BIAS, F32_C, F32_Q = 20.0, 5e-5, 1.5e-5


def _float32_quadratic(rng):
    fs, n = 400.0, 4_000_000  # 10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2e-3, B=2e-4, K=5e-6)
    temp = 10.0 + 30.0 * (0.5 - 0.5 * np.cos(2 * np.pi * t / 10_000.0)) + 0.5 * _weather(n, fs, rng, 300.0)
    d = temp - temp.mean()
    comp = F32_C * d + F32_Q * (d * d - np.mean(d * d))
    return (y + comp + F32_BIAS).astype(np.float32), fs, {"temp": temp + 0.01 * rng.standard_normal(n)}, {}, comp


#: the gyro beside a noisy thermometer: coupling (°/s per °C), the swing (°C) and the channel's white σ (°C)
NOISY_C, NOISY_SWING, NOISY_SIGMA = 2e-4, 20.0, 2.0


def _noisy_thermometer(rng):
    fs, n = 100.0, 1_000_000  # 10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=4e-4, K=1e-5)
    temp = sensors.temperature_profile(t, "cycle", rng, lo=15.0, hi=15.0 + NOISY_SWING)
    comp = NOISY_C * (temp - temp.mean())
    return y + comp, fs, {"temp": temp + NOISY_SIGMA * rng.standard_normal(n)}, {}, comp


#: two families: a square wave (Hz, °/s) and a hum with its 2nd harmonic (Hz, °/s, °/s)
SQ_F, SQ_A, TWO_F, TWO_A1, TWO_A2 = 1.7, 0.02, 13.7, 0.07, 0.042


def _two_families(rng):
    fs, n = 200.0, 1_000_000  # 5000 s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2e-3, B=3e-4, K=5e-6)
    square = SQ_A * signal.square(2 * np.pi * SQ_F * t + 0.4)
    hum = TWO_A1 * np.sin(2 * np.pi * TWO_F * t + 0.9) + TWO_A2 * np.sin(2 * np.pi * 2 * TWO_F * t + 2.1)
    return y + square + hum, fs, {}, {}, [square, hum]


#: the shared vibration: fundamental (Hz), harmonics' relative amplitudes, each axis's fundamental (°/s)
VIB_F, VIB_REL, VIB_AX = 23.0, (1.0, 0.5, 0.3), (0.28, 0.07, 0.168)


def _vib_rms(axis: int) -> float:
    return VIB_AX[axis] * math.sqrt(sum(r * r for r in VIB_REL) / 2.0)


def _shared_family(axis: int):
    def build(rng):
        fs, n = 250.0, 1_000_000  # 4000 s
        t = np.arange(n) / fs
        x = np.column_stack([rb.noise(n, fs, rng, N=2e-3, B=3e-4, K=5e-6) for _ in range(3)])
        shape = sum(r * np.sin(2 * np.pi * (k + 1) * VIB_F * t + 0.7 * k) for k, r in enumerate(VIB_REL))
        comps = [a * shape for a in VIB_AX]
        for j, c in enumerate(comps):
            x[:, j] += c
        return x, fs, {}, {"axis": axis}, comps[axis]

    return build


#: the thermostat whose period lengthens: first and last period (s), amplitude (°/s, peak)
DRIFT_P0, DRIFT_P1, DRIFT_SAW_A = 120.0, 132.0, 3e-3


def _saw_lengthening(rng):
    fs, n = 20.0, 1_000_000  # 5·10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=3e-4, K=2e-6)
    f = 1.0 / (DRIFT_P0 + (DRIFT_P1 - DRIFT_P0) * t / t[-1])
    phase = 2 * np.pi * np.cumsum(f) / fs
    comp = DRIFT_SAW_A * signal.sawtooth(phase + 0.3)
    return y + comp, fs, {}, {}, comp


def _tiny(rng):
    fs, n = 50.0, 4096  # 82 s
    return rb.noise(n, fs, rng, N=3e-3, B=4e-4, K=1e-5), fs, {}, {}, None


def _uniform_white(rng):
    fs, n = 1000.0, 1_000_000  # 1000 s
    sigma = 2e-3 * math.sqrt(fs)
    white = sigma * math.sqrt(3.0) * (2.0 * rng.random(n) - 1.0)  # uniform, variance σ²
    return white + rb.noise(n, fs, rng, B=2e-4, K=1e-5), fs, {}, {}, None


CASES = [
    Blind10(
        "three channels (temperature, supply voltage, humidity), the bias on humidity only (3·10⁻⁴ °/s per %RH), 20 Hz × 10⁶",
        _humidity,
        [Injected("regression", {"coefficient": HUM_C})],
        channel="humidity",
        seed=1001,
    ),
    Blind10(
        "a warm-up that is the temperature's own (T rising 15 °C as 1 − e^{−t/900 s}, 1.2·10⁻³ °/s per °C), 100 Hz × 10⁶: the channel asked, a drift forbidden",
        _warm_by_temp,
        [Injected("regression", {"coefficient": WT_C})],
        channel="temp",
        forbidden=("drift",),
        seed=1002,
    ),
    Blind10(
        "tiltmeter (µrad, unit None) at 0.5 Hz × 2·10⁵ (4.6 days): a daily line of 0.6 µrad and a settling drift 2 µrad·e^{−t/40000 s}",
        _tiltmeter,
        [
            Injected("sinusoid", {"amplitude": TILT_LINE, "f0": 1.0 / 86_400.0}, ("f0",)),
            Injected("drift", {"amplitude": TILT_DRIFT, "T": TILT_T}),
        ],
        unit=None,
        seed=1003,
    ),
    Blind10(
        "2·10⁴ samples only (50 s at 400 Hz) with 30 spikes of 10–20 σ",
        _short_spikes,
        [Injected("outliers", {"rate": SHORT_SPIKES / 20_000})],
        seed=1004,
    ),
    Blind10(
        "int32 counts (unit None) at 2 kHz × 10⁶ behind an integrate-and-dump decimator (16 kHz → 2 kHz): a 37 Hz hum of 6 counts and its 3rd harmonic",
        _counts_sinc,
        [_periodic([HUM_F0], _hum_rms())],
        allowed=("bandwidth",),
        unit=None,
        seed=1005,
    ),
    Blind10(
        "float32 on a 20 °/s bias, 400 Hz × 4·10⁶: the bias slow and quadratic in T (5·10⁻⁵ °/s per °C, 1.5·10⁻⁵ per °C²), T 10–40 °C once",
        _float32_quadratic,
        [Injected("regression", {"coefficient": F32_C, "quadratic": F32_Q})],
        channel="temp",
        seed=1006,
    ),
    Blind10(
        "a noisy thermometer (white σ 2 °C on a 20 °C swing), the bias following T (2·10⁻⁴ °/s per °C), 100 Hz × 10⁶",
        _noisy_thermometer,
        [Injected("regression", {"coefficient": NOISY_C})],
        channel="temp",
        seed=1007,
    ),
    Blind10(
        "two line families at once: a 1.7 Hz square wave of 0.02 °/s and a 13.7 Hz hum (0.07 °/s) with its 2nd harmonic (0.042 °/s), 200 Hz × 10⁶",
        _two_families,
        [_periodic([SQ_F, TWO_F], math.sqrt(SQ_A**2 + (TWO_A1**2 + TWO_A2**2) / 2.0))],
        seed=1008,
    ),
    Blind10(
        "three axes (n, 3) sharing one 23 Hz vibration family (harmonics 1–3) at 1 : 0.25 : 0.6, 250 Hz × 10⁶: axis 1, the weakest (0.07 °/s)",
        _shared_family(1),
        [_periodic([VIB_F], _vib_rms(1))],
        seed=1009,
    ),
    Blind10(
        "outside the family: a thermostat's sawtooth (3·10⁻³ °/s peak) whose period lengthens 120 → 132 s along the record, 20 Hz × 10⁶",
        _saw_lengthening,
        outside=True,
        seed=1010,
    ),
    Blind10("a tiny record: 4096 samples at 50 Hz, N, B and K only (clean)", _tiny, seed=1011),
    Blind10(
        "uniform white noise (light tails: no outlier) beside flicker and rate random walk, 1 kHz × 10⁶ (clean)",
        _uniform_white,
        seed=1012,
    ),
]


run_case = rb9.run_case


#: What the table shows and why (kept true to the recorded run).
NOTES: list = [
    "**First run** (at aa22876, the suite as committed, before any change; other processes used 85 % of the CPUs; its table and JSON are in commit 8fbdb2c): **8 of 12 passed**, without the candidate 8 of 9 flagged. Passed as a user would want: the warm-up that is the temperature's own, given the temperature (regression on `temp`, +5.3 %, no drift; without the regression candidate the drift is said *and* \"the rate still follows channel 'temp'\"); 30 spikes in 2·10⁴ samples (rate +0.0 %); the int32 counts behind the integrate-and-dump decimator (one family, 37 Hz and its 3rd harmonic, rms +0.0 %; nothing said of the decimator, whose output noise is white); the noisy thermometer (σ 2 °C on a 20 °C swing; −8.5 %, the errors-in-variables attenuation var(T)/(var(T) + var(noise)) would be −7 % for an ordinary regression on the raw channel); the three axes sharing one family, refined on the weakest (23 Hz, 3 lines, rms −0.0 %); the sawtooth lengthening its period, outside the family, said (the family's lines change along the record; six sinusoids and two Gauss–Markov terms stand in, χ²/dof 167 → 113); the tiny record and the uniform white noise (nothing added, nothing said).",
    "",
    "Why four failed at the first run:",
    "",
    "- *Humidity among three channels* — the regression taken on the temperature (−7.8·10⁻⁴ °/s per °C: it shares the humidity's cycle, anti-correlated), the humidity then 2.6 against 18.4. The channels were regressed in the order of `channels=` (temp, supply_v, humidity), each on what the ones taken before it left; alone, the humidity reads 45 and the temperature 36 (thresholds ≈ 17). **Fixed** (f448120, below): the strongest first.",
    "- *The 0.5 Hz tiltmeter* — nothing added (start χ²/dof 0.41), the curve's departure at τ 6–20 s said. The five terms took both effects: the start fit's K 1.8·10⁻⁴ (the truth 2·10⁻⁵) and a rate ramp R 3.3·10⁻⁵ (the truth 0). The drift test's block means carry the daily line: statistic 314 against 902 (a threshold from that inflated fit); on the record less the line 3035, less both 41. The retest beside slow lines (blind8's fix) runs only where the line search found a lone line, and the search reaches down to 18/T (`model/lines.py`): the daily line is at 4.6/T (4.6 cycles in the record) — below it, and no `sinusoid` candidate is offered. Not fixed: a slow line of a few cycles needs its own test in time beside the drift's (a least-squares sinusoid of free frequency below 18/T against the five-term null), which would move every long record's drift decisions — to be measured on the drift nulls.",
    "- *float32, slow quadratic coupling* — regression on T with its quadratic (quadratic +0.9 %), the level coefficient **+28.8 %** (6.44·10⁻⁵ against 5·10⁻⁵; its 68 % interval 5.56–7.32·10⁻⁵); χ²/dof 2.24 → 1.18, held out 3.70 → 2.39 %; failed on the coefficient alone. Not float32's (its step at 20 °/s, 1.9·10⁻⁶ °/s, against a per-sample σ of 0.04) and not one record's chance: `regress_channel` on seeds 500 and 501 of the same case reads +18 % and +58 % (intervals 5.24–6.58 and 6.83–9.01·10⁻⁵: the truth outside both), the quadratic +6 % and +6.5 %. Not the quadratic's either: the same record without it reads the level term alone at +24.6 % (6.23·10⁻⁵, interval 5.18–7.28·10⁻⁵). A level term on a temperature that swings once, monotone (half a cosine over the record), against flicker and rate random walk: measured on 90 seeds of the same profile and noise at a tenth of the rate (`benches/channel_swing_interval.py` → `benches/results/channel_swing_interval.md`), the level coefficient is not biased (mean error +7 ± 15 %, median +24 %, spread 1.4× the coefficient; the coupling accepted on none at that size, the interval as the fit reports it) but its 68.3 % interval covers the truth on **42 of 90** (47 %; 95 % Clopper–Pearson 36–57 %): at that size the interval is too narrow for a once-swing. The full-size case's three seeds (+18, +29, +58 %, two intervals of three missing the truth; +28.8 % is 1.6 half-widths) fit the same under-coverage; not measured at full size on more seeds in the time. The channel's estimator is `model/channels.py`'s (another helper's, r12lag, this session): not changed here. Without the candidate nothing is said (**none**): the linear channel check cannot see a coupling whose linear part is 1/4.5 of its quadratic; the shape check's steps are r12chanres's this session.",
    "- *Two families at once* — both named (13.7 Hz, 2 lines; 1.7 Hz, 30 lines; the judge's rms −0.5 %), but a `sinusoid` at 1.69993 Hz (amplitude 0.0050, −4.2·10⁻⁵ off the family's 1.7 Hz) beside them, χ²/dof 3.2·10⁴ → 17.2, and `unexplained` says the 1.70 Hz family's line changes along the record (0.0246 → 0.0161 °/s, its phase turned 34°) and lines at 51–66 and 73–96 Hz. The square wave is sampled without an anti-alias filter at 117.6 samples per period: its harmonics fold back (the sampled wave repeats every 10 s, 17 periods), and the family of 30 lines holds 0.0132 °/s of the square's 0.02 rms. The sinusoid's frequency is off by 7·10⁻⁵ Hz, 0.35 cycles over the record: removed beside the family's own 1.7 Hz line, it beats with it, which is the \"change along the record\" said. Why the family holds too little (refine with `periodic` alone: the 1.7 Hz family's least-squares amplitudes 0.0153, 0.0011, 0.0004 at its 1st, 3rd, 5th harmonics against the square's 0.0255, 0.0085, 0.0051): the 13.7 Hz family, removed first, is removed by its waveform folded on the period in 4096 phase bins (held out 0.233 against its two lines' 0.265; 64 bins 0.266) — and at 200 Hz the two fundamentals share the sampled lattice (the order 759 of 13.7 Hz folds onto 1.7 Hz: 759·13.7 = 52·200 − 1.7), so a template that fine holds harmonics up to order 2048 and with them the square wave's lines. Measured on the square wave alone: its 4096-bin fold on 13.7 Hz's period holds it whole (rms 0.0200 of 0.0200, its 1.7 Hz fundamental 100 %), the 64-bin fold 0.06 % of the fundamental — at 200 Hz both waves repeat every 2000 samples, the 13.7 Hz phase of sample k, 137k/2000 mod 1, takes 2000 distinct values, and 4096 bins separate them all: a template that fine is any sequence periodic in 10 s. How the 1.7 Hz family was then still found at 0.0153 (the removal's template refitted on held-in parts, or its lines' reading) was not traced. Not fixed in the time: a template's bins limited to the orders its family's lines reach (or folded on the samples less the other families' lines) is the change to measure on the family nulls.",
    "",
    "**The fix** (f448120, `model/refinement/_channel_order.py`; docs/channels.md, \"Several channels: the strongest first\"; its tests `tests/test_channel_order.py`): each round tests every channel not yet taken on the current samples and offers the one furthest beyond its threshold (a likelihood ratio over its threshold, a t statistic's square over its threshold's square); the others are tested again on what that removal left. Whether any regression is taken cannot change: the first round tests every channel on the samples as they are, each at its Bonferroni share, as the given order did until one passed. Measured (`benches/channel_order_null.py` → `benches/results/channel_order_null.md`): 102 records with three channels none of which couples (a temperature and a humidity sharing a cycle, a supply voltage), a regression taken on **0 of 102** in the given order and **0 of 102** strongest first (95 % Clopper–Pearson 0–3.6 % each), the same decisions record by record.",
    "",
    "**The humidity's row** (`--case \"three channels\"` rerun on f448120, the row and its JSON replaced, the other rows as recorded: each has one channel or none, where the order is one round, as before): the humidity taken (+12.1 %, 3.36·10⁻⁴ — the same fit as with the humidity given first), the temperature after it 1.9 against 18.5, χ²/dof 1.14 → 1.11, RMS ADEV error 2.86 → 2.58 % — but the held-out error rose, 1.91 → 2.65 % (the temperature's removal had raised it to 3.84 %), so the row still fails, on that criterion alone. The five terms had absorbed the humidity's wander (start χ²/dof 1.14, held out 1.91 %: little for the curve to see), as blind9's dT/dt-only gyro; not examined further. **Still 8 of 12.** The other suites' rows with two or more channels rerun with `--case` on f448120: blind3's temperature and supply voltage, blind5's 72 h, blind8's board and case and blind2's 2 kHz MEMS with an irrelevant supply voltage — every field as recorded (the channel, coefficients, errors, χ²/dof, held-out errors and words). The ADIS16405 is not reached (`refine_measured.py` gives no channels).",
    "**Rerun whole at a593464** (every branch of the 2026-11-27 night merged: r12adis, r12chanres, r12burst, r12lag, r12blind10, r12wline, r12ci, r12lineamp; CI, other suites and the ADIS16405 run shared the 2 cores, so the CPU column is not a cost measurement): **8 of 12**, every row's verdict, effects, parameters and words as recorded (the humidity row as rerun after the channel-order fix; the lengthening sawtooth, outside the family, still read as six sinusoids and two Gauss–Markov terms and said — r12wline's lone-line tracking does not take it).",
    "",
    "**The humidity's held-out rise measured on replicas** (r13heldout, `benches/r13heldout.py` → `benches/results/r13heldout.md`, the row's generator on 20 other seeds): the chain's held-out error falls after the regression on 18 of 20 (rises on 2, 95 % Clopper–Pearson 1–32 %; after − before median −2.25 points, SD 2.14), and the two rises are the replicas with the lowest starts (1.34 → 3.12, 1.95 → 2.14 %). The suite seed's start, 1.91 %, is below 19 of the 20 replicas' (1.34–10.4 %, median 4.76 %): the start's number is the lucky draw, its after (2.65 %) is a typical one. Not the regression's estimate: the true component removed in its place scores 1.91 → 2.49 %. Not the split: scoring only τ where the corrected parts agree as well changes nothing (the same 51 τ). Per τ, the rise comes from τ 106–499 s, where the humidity is 19–74 % of the held-out part's curve: there the raw parts agree within 1–4 %, the corrected ones (the noise alone) differ by 6–10 %, about one standard error of estimates at EDF ≈ 50. The row stays ✗ by the judge's 'held out falling', a single draw of that score; the judge is not changed. The step's own held-out comparison (`evidence[\"heldout_test\"]`) read 1.91 → 5.31 %, scored on the held-out part's corrected curve; it is now the chain's 1.91 → 2.65 % (`scoring.Split.error`; every decision and chain number as recorded).",
    "**The tiltmeter's row** (`--case tiltmeter` rerun on r13slowline, the row and its JSON replaced, the other rows as recorded; load ≈ 19 on 2 cores): the daily line of 4.6 cycles is found by the new test in time of a line of few cycles (`model/slowline.py`: the block means' generalised least-squares χ² of a sinusoid beside a constant, a ramp and settling drifts, under their fitted white, random-walk and flicker noise, scanned over 3/T … 18/T against its own null draws, at its share 0.008 of `level`) — χ² 116 against 24.4 (α 0.04 %; 79 % of its whitened signal separable from the drifts) — and removed in time (a `sinusoid` step, 0.5984 µrad, f0 −0.1 %, phase 0.704 against 0.7; its held-out test in time passes); the drift test beside it then takes the settling drift (1.879 µrad, T 34 900 s: −6.0 %, −12.8 %). χ²/dof 352 → 1.49, held-out RMS ADEV error 12.9 → 1.1 %, nothing unexplained: **passed, 9 of 12.** Held on the Allan curve instead, the line had raised the held-out error (3.33 → 3.46 %): its signature peaks near τ = 0.37/f0 ≈ 32 000 s, beyond the held-out halves' τ.",
    "**Rerun whole at 55d58e5** (every branch of the 2026-11-28 night merged: r13heldout, r13gain, r13swing, r13rate, r13cover, r13cost, r13slowline; the other suites, the ADIS16405 run and CI shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict, effects, parameters and words as recorded (the tiltmeter as rerun on r13slowline: the daily line and the drift named, ✓; the float32 row as rerun on r13swing, +24.6 %): **9 of 12**.",
    "Rerun whole at 9eaf694 (the 2026-11-28 morning's branches merged: r14house, r14blind11, r14modline, r14pump, r14cost, r14lagrate, r14fir; r14reson merged and reverted; another suite chain, the ADIS16405 run and CI shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict, effects, parameters and χ²/dof as recorded — 9 of 12.",
    '**The tiltmeter\'s row without its candidate** (`--case tiltmeter` rerun after the line search\'s removals were held to `candidates`: a few-cycle line is a `"sinusoid"` removal made by the `"periodic"` one, and it was taken with `"sinusoid"` left out): the default call as recorded (✓); refined without the sinusoid candidate it now takes nothing (was: the daily line as a sinusoid anyway, and two change points) and says the Allan curve departs at τ 6–20 s (statistic 94.0 against 16.3) — flagged, as before. Found by `benches/refine_blind12.py`\'s GNSS clock, whose row without the candidate named its diurnal line.',
    "**The tiltmeter's row without its candidate, again** (`--case tiltmeter` rerun at d562e2f): besides the curve's departure, `unexplained` now names the daily line the few-cycle test found (\"a line of few cycles at 1.156e-05 Hz (4.6 cycles in the record …) — the sinusoid candidate was not among the candidates refine ran\"); the default call as recorded.",
    "**r16family** (`--case \"two line families\"` rerun at 3fe30c3; the row above and its JSON replaced, the other rows as recorded; load ≈ 1.5–10 on 2 cores): a family's folded waveform is now taken on the samples less the least-squares lines of the families still to be removed (`refinement/removals._waveform`, docs/lines-and-outliers.md). The 13.7 Hz hum, removed first, no longer holds the 1.7 Hz square wave: the hum's rms 0.05935 → 0.05774 (truth 0.0577), the square's family 0.01318 → 0.01994 (truth 0.02), the 1.70 Hz sinusoid beside it and the 51–96 Hz lines gone, nothing unexplained; χ²/dof 3.19·10⁴ → 1.13 (was → 17.2), held out 47.8 → 2.96 % (was → 3.52 %): **passed, 10 of 12.** Every other row of every suite with a periodic or sinusoid truth or finding rerun with `--case` on the same commit (50 rows): verdicts, effects and words as recorded; only the rows with two families moved, in the 8th digit (blind8's pulse train) or as `refine_sensors.py`'s consumer IMU (its 0.19 Hz family removed by its lines, rms error −0.15 → −0.07 %, χ²/dof 0.903 → 0.849).",
    "**Rerun whole at 44c3f2f** (the 2026-11-28 late-morning branches merged: r16heldout — the chain's deviance and AIC, keys only —, r16family, r16reson, r16burst; other suites and the false-alarm bench shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict, effects, parameters and words as recorded (the two families as rerun on r16family: ✓) — 10 of 12.",
    "**r17nocand: the float32 quadratic coupling without its candidate** (2026-11-28, `/tmp` driver at cb4d330; load 8–13 on the 2 cores, other helpers' runs beside): the default call as recorded (regression on T with its quadratic, nothing said); without the regression candidate nothing is taken and `unexplained` now says \"the rate still follows channel 'temp' through its square (≈ 1.51e-05 deg/s per channel unit²)\": the channel check tries the regression candidate's first quadratic where the pair fails (at 0.2/1.8 of the check's share; the pair and the in-phase test at 0.8/1.8 each), 43.0 against 38.6 — the pair read 1.9 against 21.7 — **flagged**. The humidity, warm-up and thermometer rows' channel entries without the candidate are far above their thresholds (45.2/24.6 and more) and do not move by the split.",
    "Rerun whole on 2026-11-28 at 45caf74 (the r17 merges: the alternative chains unified and memoised, the declared filter, the follows check, the channel check's first quadratic, the level test's runs of blocks, the slow-line test's second reading; r17cost2's cheaper arithmetic, equal to 1e-9, was merged after) with 044680b's why_not_kept fix: every row's verdict as recorded; the float32 quadratic coupling without its candidate is now flagged (the channel check's first quadratic: 'the rate still follows channel temp through its square').",
    "",
    "Rerun whole on 2026-11-28 at da6740f (the r18 merges: r18cost's and r18boot's cheaper arithmetic, the sigma-delta's shaped quantisation (r18sdm), a quantised output's floor (r18bartlett), sharp rippled filter kinds (r18sharp), line families whose fundamental hunts (r18hunt); other suites, CI and the false-alarm bench shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict and effects as recorded — 10 of 12.",
]


def main(argv=None) -> None:
    rb2.suite_main(argv, __doc__, CASES, run_case, rb9._size, NOTES, "refine_blind10", "tenth")


if __name__ == "__main__":
    main()
