#!/usr/bin/env python3
"""``allanite.refine`` on a thirteenth blind suite of simulated sensors, unlike ``tests/sensors.py``, the twelve
earlier blind suites (``benches/refine_blind.py`` … ``refine_blind12.py``), ``benches/refine_sensors.py`` and the
ADIS16405 — what a user brings with default arguments.

**Written and committed before it was first run.** The effects' sizes were fixed beforehand by their Allan
deviation alone (``--sizes``, as ``benches/refine_blind12.py`` sizes them: ≥ 3× for every effect a case asks
refine to find; the effects outside the family are as a sensor makes them), never by refine's answer; the first
run's verdicts are recorded as they came out (the notes below the table) and the cases are not retuned after it.

The cases: a navigation-grade fibre-optic gyro at 2 kHz × 10⁷ (rad/s) whose square-wave bias-modulation residue
(487.3 Hz) folds its odd harmonics back below Nyquist; a 400 Hz MEMS behind its 42 Hz digital low-pass whose
rate carries 1.5 % of the neighbouring axis's vibration (that axis given as a channel); a fibre-optic gyro whose
bias follows the magnetic field along its coil (the Faraday effect; a magnetometer channel, the vehicle turned
to eight headings) beside a humidity channel it does not follow; a car standing with its engine idling (a
12.5 Hz half-order family, the firing order's 25 Hz strongest, the idle speed hunting ±0.15 %) whose cabin
temperature the gyro follows; a star tracker's attitude error at 0.5 Hz × 10⁵ (arcsec, unit None) with the
orbit's thermal line and its second harmonic; int16 counts of a ±250 °/s gyro with 25 single-bit errors on its
bus; a MEMS whose power mode switches twice (three white-noise levels); three clean records — int16 counts of a
±2000 °/s gyro (σ 1.2 LSB) in a short 10⁵-sample log, an 8 kHz MEMS of white noise and flicker, a float32 gyro
on a rate table at a constant 75 °/s beside temperature, humidity and supply-voltage channels it does not
follow — and two effects **outside the family**: a clock's phase record (``input="phase"``) with ageing and a
frequency step, and a logger that dropped 0.2 % of its samples and repeated the one before in their place.

Judged as ``benches/refine_blind12.py`` judges (``refine_blind4._judged``: named, parameters within 20 %,
frequencies within 1 %, the chain's error falling in sample and held out, ``unexplained`` empty; a clean case:
nothing added, nothing unexplained; an effect outside the family: something left unexplained; a named channel:
no regression on another). Every case with an effect in the family is refined again without its effect's
candidate, which must leave something unexplained.

Usage::

    python benches/refine_blind13.py               # -> benches/results/refine_blind13.{json,md}
    python benches/refine_blind13.py --case clock  # the cases whose name contains "clock", to a temporary folder
    python benches/refine_blind13.py --sizes       # each case's effect size only (no refine)
"""

from __future__ import annotations

import math

import numpy as np
from scipy import signal

import refine_blind as rb
import refine_blind2 as rb2
import refine_blind4 as rb4
import refine_blind9 as rb9
import refine_blind10 as rb10
import refine_blind12 as rb12

sensors = rb.sensors
Injected = sensors.Injected
Blind13 = rb2.Blind2
_periodic = rb2._periodic
_weather = rb10._weather  # a random walk through a first-order lag, peak-to-peak 1
_band_noise = rb4._band_noise  # white noise through a 4th-order Butterworth band-pass, scaled to an rms


def _lines(t: np.ndarray, f0: float, parts) -> np.ndarray:
    """Σ a_k·sin(2π·k·f0·t + φ_k) over ``parts`` = ((k, a_k, φ_k), …)."""
    return sum(a * np.sin(2 * np.pi * k * f0 * t + ph) for k, a, ph in parts)


def _rms(parts) -> float:
    return math.sqrt(sum(a * a for _k, a, _ph in parts) / 2.0)


# ---------------------------------------------------------------------------------------------------------------
# 1. a fibre-optic gyro at 2 kHz × 10⁷ with its bias-modulation residue: a square wave's odd harmonics, folded

FOG_F = 487.3  # Hz: 3·f0 folds to 538.1, 5·f0 to 436.5, 7·f0 to 588.9 Hz
FOG_A = 3.3e-5  # rad/s: the square wave's amplitude
FOG_PARTS = tuple((k, 4 * FOG_A / (math.pi * k), 0.3 * k) for k in (1, 3, 5, 7))


def _fog_residue(rng):
    fs, n = 2000.0, 10_000_000  # 5000 s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-7, B=2e-8, K=1e-10)
    comp = _lines(t, FOG_F, FOG_PARTS)
    return y + comp, fs, {}, {}, comp


# ---------------------------------------------------------------------------------------------------------------
# 2. a MEMS behind its 42 Hz digital low-pass, 1.5 % of the neighbouring axis's vibration in its rate

DLPF_HZ, XAXIS_C, XAXIS_VIB = 42.0, 0.015, 1.4  # Hz; cross-axis share; the y axis's vibration (°/s rms)


def _cross_axis(rng):
    fs, n = 400.0, 1_000_000  # 2500 s
    sos = signal.butter(2, DLPF_HZ, fs=fs, output="sos")
    vib = _band_noise(n, fs, rng, 8.0, 20.0, XAXIS_VIB)  # a pump beside the mount shakes the y axis
    raw_x = rb.noise(n, fs, rng, N=1e-3, B=1e-4, K=5e-6)
    raw_y = rb.noise(n, fs, rng, N=1e-3, B=1e-4, K=5e-6) + vib
    comp = XAXIS_C * signal.sosfilt(sos, vib)
    y = signal.sosfilt(sos, raw_x) + comp
    gyro_y = signal.sosfilt(sos, raw_y)
    return y, fs, {"gyro_y": gyro_y}, {}, [{"without": raw_x + XAXIS_C * vib}, comp]


# ---------------------------------------------------------------------------------------------------------------
# 3. a fibre-optic gyro's Faraday sensitivity: the bias follows the magnetic field along its coil

MAG_C = 5e-8  # rad/s per µT


def _faraday(rng):
    fs, n = 100.0, 1_000_000  # 10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=1.5e-6, B=1e-7, K=1e-9)
    heading = np.full(n, rng.uniform(0, 2 * np.pi))
    for t0 in np.sort(rng.uniform(0.0, t[-1], 8)):  # the vehicle turned to another heading
        heading[t >= t0] = rng.uniform(0, 2 * np.pi)
    field = 20.0 * np.cos(heading) + 0.5 * _weather(n, fs, rng, 600.0)  # µT along the coil's axis
    comp = MAG_C * (field - field.mean())
    hum = 45.0 + 12.0 * _weather(n, fs, rng, 1500.0)  # %RH, not coupled
    chans = {"mag_x": field + 0.1 * rng.standard_normal(n), "humidity": hum + 0.3 * rng.standard_normal(n)}
    return y + comp, fs, chans, {}, comp


# ---------------------------------------------------------------------------------------------------------------
# 4. a car standing with its engine idling: a 12.5 Hz half-order family, the idle speed hunting; the cabin's
#    temperature in the bias

IDLE_F = 12.5  # Hz: 750 rpm
IDLE_PARTS = ((1, 0.024, 0.2), (2, 0.08, 1.1), (4, 0.032, 2.3), (6, 0.016, 0.7))  # (harmonic, °/s, phase)
CABIN_C = 2.5e-3  # °/s per °C


def _idle(rng):
    fs, n = 200.0, 1_000_000  # 5000 s
    y = rb.noise(n, fs, rng, N=2e-3, B=5e-4, K=2e-5)
    f = IDLE_F * (1.0 + 3e-3 * _weather(n, fs, rng, 40.0))  # hunting ±0.15 %
    phase = 2 * np.pi * np.cumsum(f) / fs
    lines = sum(a * np.sin(k * phase + ph) for k, a, ph in IDLE_PARTS)
    cabin = 22.0 + 3.0 * _weather(n, fs, rng, 300.0)  # the climate control holding ±1.5 °C
    comp = CABIN_C * (cabin - cabin.mean())
    return y + lines + comp, fs, {"cabin": cabin + 0.05 * rng.standard_normal(n)}, {}, [lines, comp]


# ---------------------------------------------------------------------------------------------------------------
# 5. a star tracker's attitude error at 0.5 Hz × 10⁵: the orbit's thermal line and its second harmonic

ORBIT_F = 1.0 / 5640.0  # Hz: a 94-minute orbit
ORBIT_PARTS = ((1, 1.0, 0.4), (2, 0.4, 2.0))  # arcsec


def _star_tracker(rng):
    fs, n = 0.5, 100_000  # 2·10⁵ s, 35 orbits
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=7.0, B=0.05)  # arcsec·√s (5 arcsec per sample), arcsec
    comp = _lines(t, ORBIT_F, ORBIT_PARTS)
    return y + comp, fs, {}, {}, comp


# ---------------------------------------------------------------------------------------------------------------
# 6. int16 counts of a ±250 °/s gyro with single-bit errors on its bus

BITS_N, BITS_FS = 25, 500.0


def _bit_errors(rng):
    fs, n = BITS_FS, 1_000_000  # 2000 s
    lsb = 250.0 / 32768.0
    y = rb.noise(n, fs, rng, N=3 * lsb / math.sqrt(fs), B=2 * lsb, K=0.02 * lsb)  # σ 3 counts per sample
    counts = np.round(y / lsb + 120.0).astype(np.int16)
    clean = counts.copy()
    at = rng.choice(n, BITS_N, replace=False)
    bits = rng.integers(9, 14, BITS_N)  # 512 … 8192 counts
    counts[at] = counts[at] ^ (np.int16(1) << bits).astype(np.int16)
    comp = counts.astype(np.float64) - clean.astype(np.float64)
    return counts, fs, {}, {}, comp


# ---------------------------------------------------------------------------------------------------------------
# 7. a MEMS whose power mode switches twice: three white-noise levels

MODE_T = (375.0, 875.0)  # s
MODE_GAIN = (1.0, 2.0, 0.6)


def _mode_switch(rng):
    fs, n = 800.0, 1_000_000  # 1250 s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, B=2e-4, K=5e-6)
    white = 2e-3 * math.sqrt(fs) * rng.standard_normal(n)
    gain = np.where(t < MODE_T[0], MODE_GAIN[0], np.where(t < MODE_T[1], MODE_GAIN[1], MODE_GAIN[2]))
    return y + gain * white, fs, {}, {}, None  # a level, not a component: its size is the levels' ratio


# ---------------------------------------------------------------------------------------------------------------
# 8. int16 counts of a ±2000 °/s gyro, a short log (clean)


def _int16_coarse(rng):
    fs, n = 100.0, 100_000  # 1000 s
    lsb = 2000.0 / 32768.0
    y = rb.noise(n, fs, rng, N=1.2 * lsb / math.sqrt(fs), K=2e-4)  # σ 1.2 counts per sample
    return np.round(y / lsb + 0.35).astype(np.int16), fs, {}, {}, None


# ---------------------------------------------------------------------------------------------------------------
# 9. an 8 kHz MEMS of white noise and flicker (clean)


def _mems_8k(rng):
    fs, n = 8000.0, 4_000_000  # 500 s
    return rb.noise(n, fs, rng, N=2e-3, B=1e-4), fs, {}, {}, None


# ---------------------------------------------------------------------------------------------------------------
# 10. float32 on a rate table at 75 °/s, three channels it does not follow (clean)


def _rate_table(rng):
    fs, n = 50.0, 1_000_000  # 2·10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=3e-4, K=1e-5) + 75.0
    temp = 24.0 + 2.0 * np.sin(2 * np.pi * t / 7200.0) + 1.5 * _weather(n, fs, rng, 900.0)
    hum = 50.0 - 4.0 * (temp - 24.0) + 3.0 * _weather(n, fs, rng, 2000.0)
    supply = 28.0 + 0.3 * _weather(n, fs, rng, 30.0)
    for t0 in np.sort(rng.uniform(0.0, t[-1], 6)):
        supply[t >= t0] += rng.choice([-0.2, 0.2])
    chans = {
        "temp": temp + 0.02 * rng.standard_normal(n),
        "humidity": hum + 0.3 * rng.standard_normal(n),
        "supply": supply + 0.01 * rng.standard_normal(n),
    }
    return y.astype(np.float32), fs, chans, {}, None


# ---------------------------------------------------------------------------------------------------------------
# 11. a clock's phase record with ageing and a frequency step (outside)


def _clock_step(rng):
    fs, n = 1.0, 200_000  # 2.3 days
    t = np.arange(n) / fs
    freq = rb.noise(n, fs, rng, N=3e-12, B=5e-14) + 5e-18 * (t - t.mean())  # white and flicker FM, ageing
    comp = np.where(t >= 120_000.0, 1e-12, 0.0)
    comp -= comp.mean()
    phase = np.concatenate([[0.0], np.cumsum(freq + comp) / fs]) + 2e-12 * rng.standard_normal(n + 1)  # s
    return phase, fs, {}, {"input": "phase"}, comp


# ---------------------------------------------------------------------------------------------------------------
# 12. a logger that dropped 0.2 % of its samples and repeated the one before in their place (outside)


def _dropped(rng):
    fs, n = 400.0, 1_000_000  # 2500 s
    y = rb.noise(n, fs, rng, N=3e-3, B=3e-4, K=1e-5)
    at = np.sort(rng.choice(np.arange(1, n), 2000, replace=False))
    held = y.copy()
    held[at] = held[at - 1]  # single drops: the one before is always a real sample (no two adjacent, almost surely)
    return held, fs, {}, {}, held - y


CASES = [
    Blind13(
        "fibre-optic gyro (rad/s) at 2 kHz × 10⁷: its bias-modulation residue, a 3.3·10⁻⁵ rad/s square wave at 487.3 Hz whose odd harmonics fold to 538.1, 436.5 and 588.9 Hz",
        _fog_residue,
        [_periodic([FOG_F], _rms(FOG_PARTS))],
        unit="rad/s",
        seed=1301,
    ),
    Blind13(
        "400 Hz MEMS behind its 42 Hz digital low-pass (2nd-order Butterworth), 1.5 % of the neighbouring axis's 8–20 Hz vibration (1.4 °/s) in its rate, that axis given as channel `gyro_y`",
        _cross_axis,
        [Injected("bandwidth", {"cutoff": DLPF_HZ}), Injected("regression", {"coefficient": XAXIS_C})],
        channel="gyro_y",
        seed=1302,
    ),
    Blind13(
        "fibre-optic gyro (rad/s) at 100 Hz × 10⁶, its bias on the magnetic field along its coil (Faraday, 5·10⁻⁸ rad/s per µT; eight headings), beside a humidity channel it does not follow",
        _faraday,
        [Injected("regression", {"coefficient": MAG_C})],
        channel="mag_x",
        unit="rad/s",
        seed=1303,
    ),
    Blind13(
        "car standing, engine idling: a 12.5 Hz half-order family (harmonics 1, 2, 4, 6; 0.08 °/s at 25 Hz), the idle speed hunting ±0.15 %, and the bias on the cabin's temperature (2.5·10⁻³ °/s per °C), 200 Hz × 10⁶",
        _idle,
        [_periodic([IDLE_F], _rms(IDLE_PARTS)), Injected("regression", {"coefficient": CABIN_C})],
        channel="cabin",
        seed=1304,
    ),
    Blind13(
        "star tracker's attitude error (arcsec, unit None) at 0.5 Hz × 10⁵: the orbit's thermal line (1 arcsec, period 5640 s) and its 2nd harmonic (0.4 arcsec)",
        _star_tracker,
        [_periodic([ORBIT_F], _rms(ORBIT_PARTS))],
        unit=None,
        seed=1305,
    ),
    Blind13(
        "int16 counts (unit None) of a ±250 °/s gyro, 500 Hz × 10⁶, σ 3 counts: 25 single-bit errors on its bus (bits 9–13: +512 … +8192 counts)",
        _bit_errors,
        [Injected("outliers", {"rate": BITS_N / 1_000_000})],
        unit=None,
        seed=1306,
    ),
    Blind13(
        "a MEMS whose power mode switches twice: white noise 2× from t 375 s, 0.6× from t 875 s, 800 Hz × 10⁶",
        _mode_switch,
        [Injected("change_point", {"t": list(MODE_T)})],
        seed=1307,
    ),
    Blind13(
        "int16 counts (unit None) of a ±2000 °/s gyro (LSB 0.061 °/s), a short log of 100 Hz × 10⁵, σ 1.2 counts (clean)",
        _int16_coarse,
        unit=None,
        seed=1308,
    ),
    Blind13(
        "8 kHz MEMS × 4·10⁶ (500 s), white noise and flicker only (clean)",
        _mems_8k,
        seed=1309,
    ),
    Blind13(
        "float32 gyro on a rate table at a constant 75 °/s, 50 Hz × 10⁶, beside temperature, humidity and a 28 V supply it does not follow (clean: no channel taken)",
        _rate_table,
        seed=1310,
    ),
    Blind13(
        "outside the family: a clock's phase record (input='phase', s, unit None) at 1 Hz × 2·10⁵, white and flicker FM, ageing 5·10⁻¹⁸/s, the frequency stepping by 10⁻¹² at t 120 000 s",
        _clock_step,
        outside=True,
        unit=None,
        seed=1311,
    ),
    Blind13(
        "outside the family: a logger that dropped 2000 single samples (0.2 %) and repeated the one before in their place, 400 Hz × 10⁶",
        _dropped,
        outside=True,
        seed=1312,
    ),
]


def _size(y, comp, fs: float, kw: dict) -> float | None:
    """``refine_blind12._size``; of several effects where one is a filter (``{"without": …}``), the smallest of
    each: the filter's as ``refine_blind4._size`` reads it, the others against the record less all of them."""
    if not (isinstance(comp, list) and any(isinstance(c, dict) for c in comp)):
        return rb12._size(y, comp, fs, kw)
    arrays = [c for c in comp if not isinstance(c, dict)]
    rest = np.asarray(y, dtype=np.float64) - sum(arrays)
    sizes = [rb4._size(y, c, fs, kw) for c in comp if isinstance(c, dict)]
    sizes += [rb2.effect_size(rest + c, c, fs) for c in arrays]
    return min(sizes)


def run_case(case) -> dict:
    return rb9.run_case(case, _size)


#: What the table shows and why (kept true to the recorded run).
NOTES: list = [
    "**First run** (at 314b4c6, the suite as committed, before any change; other helpers' runs shared the 2 cores — load 10–15 —, so the CPU column is not a cost measurement; the whole suite took ≈ 7 min of wall time there, its default calls 80 CPU s; the table above and its JSON are this run's, in commit af206ea): **9 of 12 passed**, without the candidate **7 of 7** flagged. Passed as a user would want: the 2 kHz × 10⁷ FOG's square-wave modulation residue as one family at 487.3 Hz with its three folded odd harmonics (4 lines, rms −0.03 %; χ²/dof 4.3·10⁵ → 1.21); the DLPF'd MEMS — `butterworth2` at 41.9 Hz (−0.2 %) and the regression on `gyro_y` (+0.1 %), χ²/dof 1.2·10⁴ → 1.71, held out 46.0 → 2.98 %; the star tracker's orbit line and its 2nd harmonic as one family in 10⁵ samples at 0.5 Hz (f0 +0.03 %, rms −0.4 %); the two power-mode switches (change points at 375.0 and 875.0 s); the three clean records — int16 counts at ±2000 °/s (σ 1.2 LSB, 10⁵ samples), the 8 kHz MEMS, the float32 gyro on a 75 °/s rate table beside three channels it does not follow — nothing added, nothing said; the clock's frequency step, outside the family, said by the mean check (\"the mean steps by 1.5e-12 at t ≈ 119990 s\": the true 10⁻¹² at 120 000 s, its size read +51 % beside the ageing; statistic 7.35·10⁻¹³ against 6.68·10⁻¹³, 1.10× its threshold — near); the dropped samples, outside the family, said by the held check (\"0.2 % of the samples repeat the one before (1995 exact repeats), every ≈ 0.851 s: the output rate drops or repeats samples\"; their Allan deviation is 0.07× the noise's, so only that check in time can see them).",
    "",
    "Why three failed (from each Refinement's evidence):",
    "",
    "- *Faraday FOG (bias on the magnetometer channel)* — named right (regression on `mag_x`, coefficient +15.6 %, likelihood ratio 83.4 against 13.2; the humidity not taken, 3.3 against 16.4), χ²/dof 1.01 → 0.97, nothing unexplained; failed on the held-out error alone, 2.12 → 2.28 % (the step accepted by its own held-out test across frequency, variance ratio 0.985, and its `heldout_note` says the rise). The start's five terms had taken the eight heading steps into rate random walk (K 0.272 °/h^1.5 with B 0.0168 °/h; the truth K 0.0124, B 0.0206); after the removal B 0.0237, K 0. The record less its true component, refined with no candidate, scores a held-out error of 2.80 %: a true removal scores what the noise alone scores, and the absorbed start predicts the halves better — the pattern of blind12's g-sensitive gyro and battery. The chain's deviance falls −4146 → −4178 (AIC by the same 32). Also: the coefficient's 68 % interval, 5.41–6.15·10⁻⁸, does not cover the truth 5·10⁻⁸ (2.1 of its σ; +5.7 % and +0.6 % on the other seeds below).",
    "- *Idling car (12.5 Hz half-order family, idle hunting ±0.15 %; cabin temperature)* — the engine's lines named as a `periodic` of two 'fundamentals', 24.974 and 12.472 Hz (16 lines, rms −1.8 %), only 1.77 % of its power coherent across the record (`evidence[\"wandering\"]`: the hunting wanders the lines' phase), the wander not tracked (no `wander_hz`), three sinusoids (25.00, 12.51, 50.01 Hz) folded into it; χ²/dof 5.5·10⁴ → 15; `unexplained` lists the lines at 25, 50 and 75 Hz (tested as sinusoids and not kept), the 12.48 Hz line, the curve's departure at τ 0.01–0.05 s and the lines' amplitude changing along the record. The cabin's regression passed its test (likelihood ratio 24.1 against 15.2, coefficient 2.85·10⁻³, +14 %) and was turned down on its held-out test (error 18.1 → 16.4 %, but variance ratio 1.34) — regressions run before the line families, so with the engine's lines (0.09 °/s rms) still in the samples; `unexplained` then says \"the rate still follows channel 'cabin' (≈ 0.00285 deg/s per channel unit)\". Failed on the regression missing and on `unexplained` (the family itself passes the parameter check: 12.472 Hz −0.22 %, rms −1.8 %). A user would read: an engine family found but its lines not all removed, and a cabin coupling said but not taken.",
    "- *int16 bit errors* — all 25 flagged (rate +0.0 %, cut 5 σ, each flagged time one of the 25), held out 7.50 → 2.57 %, N 0.766 → 0.137 counts·√s (truth 0.134), nothing unexplained; failed on the in-sample criterion alone: χ²/dof 0.636 → 1.15, RMS ADEV 1.77 → 2.03 %. The five terms had taken the spikes as white noise (N 5.7×) and fit that curve well; the clean counts (the record less the bit errors) refined alone start at χ²/dof 1.12, RMS 2.09 %, held out 1.73 % — the chain ends at the noise's own in-sample level. The chain's deviance falls −484 → −600. A white contamination the start absorbs cannot lower the judge's in-sample errors (the absorption noted in `tests/sensors.judge`): refine did what a user wants here.",
    "",
    "Without the candidate (7 of 7 flagged): the FOG's lines said (487.3, 538.1, 436.5 Hz — beside a `resonance` standing in); the DLPF'd MEMS — the curve departs at τ 7.5–460 ms and \"the rate still follows channel 'gyro_y' (≈ 0.015)\"; the Faraday FOG — \"the rate still follows channel 'mag_x' (≈ 5.78e-08)\"; the idling car — three resonances stand in, its lines said; the star tracker's two lines said; the bit errors — four change points stand in and the impulsive noise is said (\"25 samples … beyond the Gaussian noise's cut at 5 σ\"); the mode switches — the level check (2.43× within t 375–875 s).",
    "**On two other seeds each** (`--seed-offset 100` and `200` at 314b4c6, to /tmp; the default call, judged as the suite judges; not rows of the suite; load 15–30 from other helpers): **10 of 12** and **9 of 12** — with the suite's seed **28 of 36**; without the candidate 7 of 7 flagged on each. The same three rows fail and nothing else: the Faraday FOG on all three (+100: coefficient +5.7 %, χ²/dof 0.759 → 1.03, held out 3.24 → 4.08 %, the record less its truth 3.45 %; +200: +0.6 %, held out 3.52 → 2.62 % but in sample χ²/dof 0.554 → 0.743, RMS 0.785 → 1.28 %); the idling car on all three (+100: the regression taken, +13.3 %, a `periodic` at 12.4997 Hz with its wander tracked, 0.078 %, but of one line — rms −73.5 % —, 25 and 50 Hz as sinusoids, 75 Hz said; +200: no family, three sinusoids at 25.01, 12.50 and 50.01 Hz, the regression taken, −13.3 %, the lines said); the bit errors on two (+100 passes, RMS 1.96 → 1.62 %; +200: χ²/dof 0.501 → 0.715, RMS 1.19 → 1.22 %, held out 3.28 → 1.80 %). The clock's step said on all three (1.5, 1.1, 1.5·10⁻¹²; its start χ²/dof 0.08, 0.17, 0.17 — far below 1 on a phase record: not examined), the repeats on all three, the three clean rows silent on all nine records.",
    "",
    "Rerun whole on 2026-11-28 at da6740f (the r18 merges: r18cost's and r18boot's cheaper arithmetic, the sigma-delta's shaped quantisation (r18sdm), a quantised output's floor (r18bartlett), sharp rippled filter kinds (r18sharp), line families whose fundamental hunts (r18hunt); other suites, CI and the false-alarm bench shared the 2 cores, so the CPU column is not a cost measurement): 9 of 12, without the candidate 7 of 7, the verdicts as at the first run. **The idling car** now has its engine as one 'periodic' whose fundamental hunts (r18hunt: 12.502 Hz, 4 lines — orders 1, 2, 4, 6 —, rms +0.01 %, the wander tracked; χ²/dof 5.5·10⁴ → 1.37), where two 'fundamentals' and three sinusoids stood in, and `unexplained` no longer lists lines; on seeds +100 and +200 the row passes (r18hunt's runs with `--seed-offset`). On this seed it still fails, on the cabin's regression alone: turned down on its held-out variance ratio (1.34), and `unexplained` says the rate still follows 'cabin'. **The first run's reading of that decline was wrong**: the record less its true lines turns the regression down with the same ratio 1.3432, so the engine's lines were not what spoiled it (the regression's held-out test across frequency in the channel's own low bands is); not changed this stop.",
]


def main(argv=None) -> None:
    rb2.suite_main(argv, __doc__, CASES, run_case, _size, NOTES, "refine_blind13", "thirteenth")


if __name__ == "__main__":
    main()
