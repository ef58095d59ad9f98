#!/usr/bin/env python3
"""``allanite.refine`` on a ninth blind suite of simulated sensors, unlike ``tests/sensors.py``, the eight earlier
blind suites (``benches/refine_blind.py`` … ``refine_blind8.py``) and the ADIS16405 — what a user brings with
default arguments.

**Written and committed before it was first run.** The effects' sizes were fixed beforehand by their Allan
deviation alone (``--sizes``, as ``benches/refine_blind5.py`` sizes them: ≥ 3× for every curve effect a case asks
refine to find; the sparse spikes, judged by their rate, and the effects outside the family are as a sensor makes
them), never by refine's answer; the first run's verdicts are recorded as they came out (the notes below the
table) and the cases are not retuned after it.

The cases: a caesium-like clock (fractional frequency at τ₀ 1 s, unit None, flicker FM dominant beyond ~400 s)
whose frequency follows the room's temperature through a 3000 s lag; a gyro that follows only dT/dt (a thermal
gradient across the die: no level term) in a chamber ramping 10–40 °C; a coupling only above 32 °C (a hinge,
outside the family: said, not modelled as linear); white noise whose level follows the temperature (0.63–1.38×,
outside the family); a 12-bit accelerometer's counts as int16 (unit None) on 1 g, its white noise 0.4 count
(strong quantisation, clean); a sample-rate beat at an odd output rate (104 Hz: a 26.3 Hz vibration read by a
sensor that drops a sample every 1/0.65 s); a thermostat's asymmetric sawtooth (85 % rise, 15 % fall) of period
150 s; 80 sparse spikes riding on a strong 4 Hz line (the line 8× the per-sample σ); a truck passing: white noise
3× for only 120 s of 10⁴ s (two change points close together); a 3-axis (n, 3) log with one temperature where
axis 1 follows it through a 600 s lag and axis 2 not at all (each refined on its own axis; axis 2 clean).

Truths are in the unit refine reports (°/s for the gyros unless said; counts and fractional frequency as said). A
family is judged on its fundamental and its rms (the rms over all its harmonics).

Judged as ``benches/refine_blind8.py`` judges (``refine_blind4._judged``: named, parameters within 20 %,
frequencies within 1 %, the chain's error falling in sample and held out, ``unexplained`` empty; a clean case:
nothing added but what it allows, nothing unexplained; an effect outside the family: something left unexplained;
a named channel: no regression on another; change points: each true time within 20 % of a found one).

Usage::

    python benches/refine_blind9.py                  # -> benches/results/refine_blind9.{json,md}
    python benches/refine_blind9.py --case clock     # the cases whose name contains "clock", to a temporary folder
    python benches/refine_blind9.py --sizes          # each case's effect size only (no refine)
"""

from __future__ import annotations

import math

import numpy as np
from scipy import signal

import refine_blind as rb
import refine_blind2 as rb2
import refine_blind4 as rb4
import refine_blind8 as rb8

sensors = rb.sensors
Injected = sensors.Injected
Blind9 = rb2.Blind2
_periodic = rb2._periodic


def _room(t: np.ndarray, rng, lo: float, hi: float, period: float) -> np.ndarray:
    """A room's temperature: a cycle of ``period`` s plus weather (a random walk through a 2 h lag), lo–hi °C."""
    fs = 1.0 / (t[1] - t[0])
    weather = sensors.first_order_lag(np.cumsum(rng.standard_normal(t.size)), fs, 7200.0)
    x = np.sin(2 * np.pi * t / period - 1.0) + 0.3 * weather / max(np.ptp(weather), 1e-300)
    return lo + (hi - lo) * (x - x.min()) / max(np.ptp(x), 1e-300)


#: the clock's coupling (fractional frequency per °C) and the lag from the room to the oscillator (s)
CLOCK_C, CLOCK_LAG = 4e-14, 3000.0


def _clock(rng):
    fs, n = 1.0, 200_000  # 2.3 days of 1 s fractional-frequency readings
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2e-13, B=1.5e-14, K=5e-18)
    room = _room(t, rng, 21.5, 23.5, 86_400.0)
    drive = sensors.first_order_lag(room, fs, CLOCK_LAG)
    comp = CLOCK_C * (drive - drive.mean())
    return y + comp, fs, {"room": room + 0.005 * rng.standard_normal(n)}, {}, comp


#: the gyro's coupling to dT/dt only (°/s per °C/s)
GRAD_R = 0.025


def _gradient(rng):
    fs, n = 200.0, 1_000_000  # 5000 s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=4e-4, K=1e-5)
    temp = rb2._chamber(t, 10.0, 40.0, 350.0, 450.0)
    temp = sensors.first_order_lag(temp, fs, 30.0)  # the chamber's air reaches the housing smoothly
    comp = GRAD_R * np.gradient(temp, 1.0 / fs)
    comp = comp - comp.mean()
    return y + comp, fs, {"temp": temp + 0.01 * rng.standard_normal(n)}, {}, comp


#: the hinge: the rate follows T above HINGE_T (°C) only, at HINGE_C (°/s per °C)
HINGE_T, HINGE_C = 32.0, 6e-4


def _hinge(rng):
    fs, n = 100.0, 1_000_000  # 10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=4e-4, K=1e-5)
    temp = sensors.temperature_profile(t, "cycle", rng, lo=15.0, hi=40.0)
    comp = HINGE_C * np.maximum(temp - HINGE_T, 0.0)
    comp = comp - comp.mean()
    return y + comp, fs, {"temp": temp + 0.01 * rng.standard_normal(n)}, {}, comp


#: the white noise's level per °C about 25 °C (fraction)
LEVEL_PER_C = 0.025


def _level_on_t(rng):
    fs, n = 100.0, 1_000_000  # 10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, B=4e-4, K=1e-5)
    temp = sensors.temperature_profile(t, "cycle", rng, lo=10.0, hi=40.0)
    white = 3e-3 * math.sqrt(fs) * rng.standard_normal(n) * (1.0 + LEVEL_PER_C * (temp - 25.0))
    return y + white, fs, {"temp": temp + 0.01 * rng.standard_normal(n)}, {}, None


def _accel12(rng):
    fs, n = 100.0, 1_000_000  # 10⁴ s; 1 mg per count, 1 g = 1000 counts, white 0.4 count per sample
    y = rb.noise(n, fs, rng, N=0.4 / math.sqrt(fs), B=0.01, K=2e-4) + 1000.0
    return np.round(y).astype(np.int16), fs, {}, {}, None


#: the beat at 104 Hz: the vibration tone (Hz, °/s) and the dropped samples' rate (Hz)
ODR_F1, ODR_AMP, ODR_F2 = 26.3, 0.1, 0.65


def _odr_beat(rng):
    fs, n = 104.0, 1_000_000  # 9615 s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=4e-4, K=1e-5)
    comp = sensors._sample_rate_beat(t, ODR_AMP, ODR_F1, ODR_F2, fs, "drop")
    return y + comp, fs, {}, {}, comp


#: the thermostat's sawtooth: period (s), amplitude (°/s, peak), the rise's share of the period
SAW_P, SAW_A, SAW_RISE = 150.0, 3e-3, 0.85


def _thermostat(rng):
    fs, n = 20.0, 1_000_000  # 5·10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=3e-4, K=2e-6)
    comp = SAW_A * signal.sawtooth(2 * np.pi * t / SAW_P + 0.4, width=SAW_RISE)
    return y + comp, fs, {}, {}, comp


#: the line (°/s, Hz) the spikes ride on; how many spikes, their size (× the per-sample σ)
RIDE_AMP, RIDE_F0, RIDE_SPIKES, RIDE_SIGMAS = 0.08, 4.0, 80, (8.0, 15.0)


def _spikes_on_line(rng):
    fs, n = 100.0, 1_000_000  # 10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=1e-3, B=2e-4, K=2e-6)
    line = RIDE_AMP * np.sin(2 * np.pi * RIDE_F0 * t + 0.9)
    sigma = 1e-3 * math.sqrt(fs)
    hit = rng.choice(np.arange(10, n - 10), RIDE_SPIKES, replace=False)
    spikes = np.zeros(n)
    size = RIDE_SIGMAS[0] + (RIDE_SIGMAS[1] - RIDE_SIGMAS[0]) * rng.random(RIDE_SPIKES)
    spikes[hit] = sigma * size * rng.choice([-1.0, 1.0], RIDE_SPIKES)
    return y + line + spikes, fs, {}, {}, [line, spikes]


#: the truck: when it passes (s), how long (s), the white noise meanwhile (× before)
TRUCK_T, TRUCK_LEN, TRUCK_X = 6000.0, 120.0, 3.0


def _truck(rng):
    fs, n = 50.0, 500_000  # 10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, B=3e-4, K=2e-6)
    white = 3e-3 * math.sqrt(fs) * rng.standard_normal(n)
    white[(t >= TRUCK_T) & (t < TRUCK_T + TRUCK_LEN)] *= TRUCK_X
    return y + white, fs, {}, {}, None


#: the three axes' couplings to the one temperature: axis 0 direct, axis 1 through a lag, axis 2 none
AX_C0, AX_C1, AX_LAG = 1e-4, 2e-4, 600.0


def _axes(axis: int):
    def build(rng):
        fs, n = 100.0, 1_000_000  # 10⁴ s
        t = np.arange(n) / fs
        x = np.column_stack([rb.noise(n, fs, rng, N=3e-3, B=4e-4, K=1e-5) for _ in range(3)])
        temp = sensors.temperature_profile(t, "cycle", rng, lo=20.0, hi=45.0)
        lagged = sensors.first_order_lag(temp, fs, AX_LAG)
        comps = [AX_C0 * (temp - temp.mean()), AX_C1 * (lagged - lagged.mean()), None]
        for j, c in enumerate(comps):
            if c is not None:
                x[:, j] += c
        return x, fs, {"temp": temp + 0.01 * rng.standard_normal(n)}, {"axis": axis}, comps[axis]

    return build


def _size(y, comp, fs: float, kw: dict) -> float | None:
    """``refine_blind4._size`` on the refined axis of multi-axis input."""
    y = np.asarray(y)
    if y.ndim == 2:
        y = y[:, kw.get("axis", 0)]
    return rb4._size(y, comp, fs, kw)


CASES = [
    Blind9(
        "clock: 1 Hz × 2·10⁵ fractional frequency (unit None), flicker FM dominant, the room's temperature reaching it through a 3000 s lag (4·10⁻¹⁴ per °C)",
        _clock,
        [Injected("regression", {"coefficient": CLOCK_C, "lag_s": CLOCK_LAG})],
        channel="room",
        unit=None,
        seed=901,
    ),
    Blind9(
        "gyro on dT/dt only (0.025 °/s per °C/s, no level term), chamber ramping 10–40 °C, 200 Hz × 10⁶",
        _gradient,
        [Injected("regression", {"rate_coefficient": GRAD_R})],
        channel="temp",
        seed=902,
    ),
    Blind9(
        "outside the family: the rate follows T only above 32 °C (6·10⁻⁴ °/s per °C), T cycling 15–40 °C, 100 Hz × 10⁶",
        _hinge,
        outside=True,
        channel="temp",
        seed=903,
    ),
    Blind9(
        "outside the family: white noise level following T (1 + 0.025·(T − 25 °C)), T cycling 10–40 °C, 100 Hz × 10⁶",
        _level_on_t,
        outside=True,
        channel="temp",
        seed=904,
    ),
    Blind9(
        "12-bit accelerometer's counts as int16 (unit None) on 1 g, white 0.4 count per sample, 100 Hz × 10⁶ (clean)",
        _accel12,
        unit=None,
        seed=905,
    ),
    Blind9(
        "odd output rate 104 Hz × 10⁶: a 26.3 Hz vibration of 0.1 °/s, a sample dropped every 1/0.65 s",
        _odr_beat,
        [_periodic([ODR_F1, ODR_F2], ODR_AMP / math.sqrt(2.0))],
        seed=906,
    ),
    Blind9(
        "thermostat sawtooth 3·10⁻³ °/s peak, period 150 s, 85 % rise and 15 % fall, 20 Hz × 10⁶",
        _thermostat,
        [_periodic([1.0 / SAW_P], SAW_A / math.sqrt(3.0))],
        seed=907,
    ),
    Blind9(
        "80 sparse spikes (8–15 σ) riding on a 0.08 °/s line at 4 Hz (8× the per-sample σ), 100 Hz × 10⁶",
        _spikes_on_line,
        [
            Injected("sinusoid", {"amplitude": RIDE_AMP, "f0": RIDE_F0}, ("f0",)),
            Injected("outliers", {"rate": RIDE_SPIKES / 1_000_000}),
        ],
        seed=908,
    ),
    Blind9(
        "a truck passing: white noise 3× for 120 s from t 6000 s, 50 Hz × 5·10⁵",
        _truck,
        [Injected("change_point", {"t": [TRUCK_T, TRUCK_T + TRUCK_LEN]})],
        seed=909,
    ),
    Blind9(
        "three axes (n, 3) with one temperature, 100 Hz × 10⁶: axis 1, through a 600 s lag (2·10⁻⁴ °/s per °C)",
        _axes(1),
        [Injected("regression", {"coefficient": AX_C1, "lag_s": AX_LAG})],
        channel="temp",
        seed=910,
    ),
    Blind9(
        "three axes (n, 3) with one temperature, 100 Hz × 10⁶: axis 2, not coupled (clean)",
        _axes(2),
        seed=910,
    ),
]


def run_case(case, size_of=_size) -> dict:
    """Refine one case with the default call and judge it (``refine_blind4._judged``); ``size_of(y, comp, fs, kw)``
    its effect's size (blind suites 10–12 run their cases through this one)."""
    y, fs, channels, kw, comp = case.build(np.random.default_rng(case.seed))
    size = size_of(y, comp, fs, kw)
    try:
        v = rb.refined(case, y, fs, channels, kw, rb4._judged)
    except Exception as err:  # noqa: BLE001 — recorded as the case's failure, the suite goes on
        return rb8._raised(case, err, size)
    return v | {"size": size, "outside": case.outside}


#: What the table shows and why (kept true to the recorded run).
NOTES: list = [
    "**First run** (at a696626, the suite as committed, before any change; other processes used 63 % of the CPUs; its table and JSON are in commit 2a96a19): **6 of 11 passed**, without the candidate 6 of 7 flagged. Passed as a user would want: the clock's room temperature through its 3000 s lag (regression on `room`, coefficient −11.3 %; the lag not kept and, by the judge, not carried at its test's level; χ²/dof 1.28 → 1.00) — on a record of values ~10⁻¹³ with unit None; the noise level following T, outside the family, said (\"the noise level changes along the record: 1.42× the Allan deviation at τ₀ of t 0–634 s\"), nothing added; the 12-bit accelerometer's int16 counts, white noise 0.4 count (nothing added, nothing said; start χ²/dof 0.36); the beat at 104 Hz as one family (26.464 and 0.65 Hz — the tone read at f1·(1 + f2/fs), as the dropped samples shift it: +0.6 % against the judge's 1 % — 158 lines, rms −0.0 %); the thermostat's asymmetric sawtooth as one family (1/150 Hz +0.0 %, 4 lines, rms −0.7 %); axis 2 of the three, beside the temperature it does not follow (nothing added, nothing said).",
    "",
    "Why five failed at the first run:",
    "",
    "- *Spikes on a strong 4 Hz line* — the sinusoid taken (amplitude and f0 −0.0 %), the spikes not, and a drift (6.6·10⁻⁴ °/s, T 2191 s) that is not in the record; `unexplained` said \"impulsive noise: 44 samples … beyond the Gaussian noise's cut at 5 σ\"; the drift's held-out error read 3.3·10¹⁴⁷ %. Both removals run before the curve effects, on the record with the line in it. The outlier test's robust scale is measured on the first differences, where the line swings 2A·sin(πf/fs) = 0.02 °/s against the differences' σ of 0.014: the cut sat at 0.107 °/s, 44 of the 80 spikes beyond it, and their removal was turned down as immaterial — it moved the Allan curve by 0.06 of the standard errors of a five-term fit whose white term the line had raised 9× (the materiality rule, `scoring.MATERIAL_Z`). The same bent fit (N 9× the truth, no flicker, no random walk) set the drift test's threshold: statistic 22.8 against 15.7; on the record less the line, 362. The 3.3·10¹⁴⁷ is the held-out curve predicted below zero at long τ (the five terms fitted on a part corrected by a spurious drift, plus the correction's negative change) and floored at 10⁻³⁰⁰ — a number, not a decision: the drift was accepted by its own held-out test in time. **Fixed** (below).",
    "- *dT/dt only* — the regression taken with its rate term (rate coefficient 0.02365, −5.4 %) and a level term beside it (1.47·10⁻⁵ °/s per °C, truth 0; ~4·10⁻⁴ °/s over the 30 °C swing), held out 3.22 → 2.11 %, nothing unexplained; failed only on the judge's in-sample criterion: χ²/dof 0.962 → 1.013 and the RMS ADEV error 1.25 → 1.49 % both rose. The five terms absorbed the ramps' ±0.6·10⁻³ °/s square wave (start χ²/dof 0.96: nothing for the curve to see), so its removal cannot lower an in-sample error that was already at 1 (`tests/sensors.judge`'s note on absorption). Without the candidate: \"the rate still follows channel 'temp'\" (37.5 against 20.3). Not changed.",
    "- *The hinge above 32 °C* (outside the family) — the regression on T with its quadratic taken (1.58·10⁻⁴ °/s per °C, quadratic 1.63·10⁻⁵), χ²/dof 7.32 → 1.07, nothing said. Measured: a quadratic in T takes 95 % of the hinge's power over this profile (a straight line 68 %); what it leaves (rms 3.5·10⁻⁴ °/s) is at most 0.94× the rest of the record's Allan deviation, and the shape check (`model/_shape.py`) looks for steps in T, not a kink. As blind8's staircase before r10stair: a check of the residual against the channel's value (its means in bins of T) is what would say it; not built in the time.",
    "- *Truck passing* — both change points found (5999.9 and 6121.5 s, +0.0 %), but outliers taken first (rate 5.9·10⁻⁴: 296 samples), and the held-out error rose 9.39 → 10.47 %. The outlier test's local scale is per block of ~8192 differences (here 61 blocks of 8197; the block's own or its louder neighbour's, `model/_robust_scale.local_scales`); the 6000 loud samples straddle blocks 36 and 37 (40 % and 33 % of them), each block's median is the quiet noise's, and the burst's own Gaussian tail, 3× wider, reads as spikes beyond 0.092 °/s. Removals run before change points, so the burst's level is not yet known when the outliers are flagged. Not fixed: a scale local enough for a 120 s burst at 50 Hz (blocks of ≤ 3000 differences), or outliers retested within the change points' segments, would each move every record's outlier decisions — to be measured on the outlier nulls.",
    "- *Axis 1 through a 600 s lag* — the regression taken with a d(T)/dt term (−0.0486) in place of the lag: coefficient 9.5·10⁻⁵ (−52 %). The rate term's nested test kept it (22.0 against 14.8) and the lag's did not (13.8 against 20.3, at 477 s; its threshold carries the search over the lag's arc length 1.15). At the cycle's frequency (period 3333 s) a 600 s lag is a gain of 0.66 and a phase of −48°: level and rate terms fit that one frequency's in-phase (c·0.44 = 8.8·10⁻⁵) and quadrature parts as well as the lag does, and the rate term is tried first. Blind8's 48 h case met the same order (its lag beaten by the rate term). Not changed: the channel model's order of nested terms decides every channel record; a lag preferred where it fits as well with one number fewer is the change to measure.",
    "",
    "**The fix** (ac6cd3c, its test 2259a13, `tests/test_lines_intime.py`): after the removals in time, where the line search found lone lines, (1) a drift that was taken (the last removal) is tested once more on the samples less the four strongest of them (least squares at their frequencies beside a constant and a ramp), its null from that record's curve, and put back where its statistic is not beyond the threshold there (`_in_time.drift_confirmed_beside_lines`); (2) where no outliers were taken and lines are strong in the first differences (swing 2A·|sin(πf/fs)| ≥ 0.25 of the differences' robust σ), the outlier test runs on the samples less those lines and its materiality is judged on that record's curve and fit (`_in_time.outliers_beside_lines`, `evidence[\"beside_lines_hz\"]`). The lines stay in the samples for the curve's candidates. Only a drift can be put back and only outliers can be added: the ADIS16405's lines swing at most 0.7 % of its differences' σ and none of its records takes a drift, so neither retest reaches them.",
    "",
    "**The table above** is the whole suite rerun after the fix (code of 2259a13, python unchanged since; other processes used 85 % of the CPUs: its CPU seconds are not a cost measurement): **7 of 11**, without the candidate **6 of 7** — the spikes on the line pass: the sinusoid as before, outliers rate 8.1·10⁻⁵ (+1.2 %, cut 0.047 °/s, `beside_lines_hz` [4.0]), no drift, χ²/dof 6.1·10⁴ → 1.02, held out 72.5 → 4.46 %, nothing unexplained; without the candidate (no sinusoid, no outliers: the line is not modelled there) the drift is put back and said instead, \"a warm-up-like drift along the record (T ≈ 1.88e+03 s)\", beside the line and the curve's departure. Every other row's effects, parameters and words as at the first run (compared field by field). The other suites' rows with a lone line or sparse spikes rerun with `--case` on this code and on a696626 (blind's logger and axis 1; blind2's short record, chirp and line switched on; blind3's float32 line and clock; blind4's 24 h and accelerometer warm-up beside a 6.2 Hz line; blind5's Gauss–Markov beside a 0.3 Hz line, short record and 50 spikes; blind6's odd rate and minute-averaged clock; blind7's sway, clock and three axes; blind8's warm-up beside a slow line, wheel and spikes): every row's verdict, effects, parameters and words the same on both; so too `refine_sensors.py`'s square wave and warm-up, consumer IMU families, AM carrier, sample-rate beat and 0.37 Hz square wave. The false-alarm side and the drift's power: `benches/results/lines_intime_null.md`; `refine_false_alarms.py --quick` on the fix: 0 of 16 records with an alarm. The ADIS16405 is not reached (its lines swing ≤ 0.7 % of its differences' σ, no record takes a drift), so `refine_measured.py` was not rerun.",
    "",
    "**r11lagrate** (`--case \"axis 1\"` rerun at 76b976f, the rule's commit; the row above and its JSON replaced, the other rows as before): where the d(ch)/dt term passes its test, the pure lag model is now weighed against it at the same count of numbers — the larger likelihood kept, and within 4 in 2Δℓ the phase's sign decides (r/c < 0, a delay: the lag; docs/channels.md, \"A lag or a d(ch)/dt term\"). Axis 1: the lag fits better by 2Δℓ 9.37 (r/c −509 s, the rate term's 22.0 against 14.8 as before), kept at 554 s (−7.6 %), coefficient 1.93·10⁻⁴ (−3.6 %; was −52 %), χ²/dof 1.19 → 0.91, held out 2.02 → 1.43 % — **passed: 8 of 11**. The other rows that keep a d(ch)/dt term rerun with `--case`, each as recorded (the lead fits better by 46 in 2Δℓ on the dT/dt-only gyro): blind9's dT/dt only; blind8's 48 h (still ✗ on its rate coefficient, +32.6 %: the rate term fits better by 37.7, r/c +2.3·10⁴ s — not this ambiguity); blind2's chamber ramp and blind5's cycling T and dT/dt; `refine_sensors.py`'s dT/dt and 300 s lag rows. A row that kept no d(ch)/dt term cannot move (the choice is made only where that term passed), nor can a null record gain a term (a lag is kept without its own test only in place of a rate term that passed).",
    "**r12burst** (`--case truck` rerun at 0208440; the row above and its JSON replaced, the other rows as before): the outliers test's local scale is now refined where a stretch is louder than its block (`model/_robust_scale.burst_scales`, docs/lines-and-outliers.md): each 8192-sample block is cut into fine blocks of 512, a fine block is loud where its share of differences beyond the median |d| of its block's scale is above the share expected by 5 standard errors (binomial, or the shares' own robust spread over the record where larger: low-passes, quantised wanders), and a loud fine block and its two neighbours are judged at the largest of its own robust σ and theirs; where no fine block is loud the blocks and scales are main's exactly. On the truck the burst is judged at its own scale: clusters beyond 4 σ 31 against 31.7 expected (main 332), no outliers; the two change points are taken on the raw record (6000.1 and 6120.1 s, +0.0 %). The judge (`benches/refine_blind.py`, `_judge_change_points`) now reads the change points' held-out chain at its ends, none → all of them, as refine decides (`_final.change_point_steps` takes all or none): 8.28 → 5.62 % per segment; the link with the first alone reads 9.73 % (the burst left inside a long quiet segment) and had failed the row under the link-by-link reading. **Passed: 9 of 11.** Without the candidate nothing is said of the burst (as before): the noise-level check of `unexplained` does not resolve 120 s in 625 s windows — not changed here. No other row of any suite can move by the judge: every other row with change points is ✓ (each link fell, so the ends fell) or, blind7's pump, ✗ on `unexplained`. Outlier test alone, main (e849a13) against this branch, α 0.25 %: `periodic_outliers_null.py`'s records 0–199, 0 of 200 accepted on both (Clopper–Pearson 0–1.8 %), every record's Bonferroni p-value the same; `periodic_outliers_power.py`'s impulsive records (its generator, seeds 0–29 of spikes and of heavy tails — contaminated normal and Student t) 60 of 60 accepted on both, every flagged count the same (a fine block loud on 1 of the 260 records, null 147, verdict unchanged); every raw record of blind suites 1–9 (118 columns, measured with the binomial-only threshold of 31afa82, whose loud fine blocks include the final form's: where it made none loud the final form is main's exactly) and of `tests/sensors.py` (15): the outlier test's verdict and flagged count the same on all but the truck, a fine block loud on one other (blind5's 2 kHz × 10⁷ behind a 4th-order Butterworth: not accepted either way, clusters at 4 σ 638 → 637); the 36 ADIS16405 channels: the same 17 accepted and 19 not, the gyros' counts unchanged, flagged counts on four accelerometers 111 → 109 (run 1 acc_y), 197 → 195 (run 2 acc_y), 16 → 13 (run 4 acc_x), 145 → 143 (run 4 acc_y). A burst shorter than two fine blocks (1024 samples) is still read as outliers. Rerun with `--case` on this branch, each row as recorded (effects, parameters, errors, words): blind9's 80 spikes on the 4 Hz line, blind2's bursts of spikes, blind5's Student-t, blind8's 150 spikes within 600 s.",
    "**Rerun whole at a593464** (every branch of the 2026-11-27 night merged: r12adis, r12chanres, r12burst, r12lag, r12blind10, r12wline, r12ci, r12lineamp; CI, other suites and the ADIS16405 run shared the 2 cores, so the CPU column is not a cost measurement): **9 of 11**, every row's verdict, effects, parameters and words as in the table (the truck with r12adis's location of change points: +0.0 %, nothing unexplained).",
    "**r13rate** (`--case \"dT/dt only\"` rerun at d013e8c; the row above and its JSON replaced, the other rows as before; load 25–30): the level term is now tested where a d(ch)/dt term alone carries the coupling (docs/channels.md, \"The level term\"). The row keeps the rate term only — 0.02392 (−4.3 %), the level term's test 4.45 against 4.59 (χ²₁ × the coupling's Bartlett factor 1.19 at 5 %; p 0.054, a near miss) —, χ²/dof 0.962 → 0.965 (was → 1.013 with the level term), RMS ADEV 1.25 → 1.31 % (was → 1.49), held out 3.22 → 1.65 % (was → 2.11): the spurious level term (a 4.4·10⁻⁴ °/s swing in T that is not in the record) was most of the in-sample rise. Still ✗ on the in-sample criterion alone: the five terms absorbed the ramps' square wave at the start (χ²/dof 0.962), and what is left of the rise is within the curve's scatter. Why the rest cannot fall (this record, seed 902): the start model takes the ramps into the rate random walk — K 7.9·10⁻⁵ with the effect in the record, 0 with it removed exactly (truth 10⁻⁵; N and B the same) — and fits the curve as well with it as the true model does without it (the start fit's χ²/dof 0.32 against 0.47). On 8 more seeds of this row (90200–90207, refine's default call at d013e8c; every number the same at the rule's first share, 0.1 %) the row passes 7 of 8 (the level term kept on none); the code before, seeds 90201–90207: 6 of 7, the same seed failing (90207: χ²/dof 0.952 → 0.977, was → 0.993) and the level term kept on all — the after-χ²/dof lower on 6 of those 7 seeds by 0.015–0.04. On 20 replicas of the generator (`benches/results/r13rate.md`) a level term is kept on 1 (was 20).",
    "**Rerun whole at 55d58e5** (every branch of the 2026-11-28 night merged: r13heldout, r13gain, r13swing, r13rate, r13cover, r13cost, r13slowline; the other suites, the ADIS16405 run and CI shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict, effects, parameters and words as recorded (the dT/dt-only row as rerun on r13rate: the rate coefficient alone, −4.3 %, still ✗ on the in-sample chain).",
    "Rerun whole at 9eaf694 (the 2026-11-28 morning's branches merged: r14house, r14blind11, r14modline, r14pump, r14cost, r14lagrate, r14fir; r14reson merged and reverted; another suite chain, the ADIS16405 run and CI shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict, effects, parameters and χ²/dof as recorded — 9 of 11.",
    "**The hinge above 32 °C, a kink basis tried** (2026-11-28, not committed to the library): the shape check's search given, beside its 63 steps, a hinge max(T − c, 0) at each of the same cuts, on this row's final residual: the hinge at 32.07 °C scores z²/h = 5.5 alone (the best step 11.2, at 29.9 °C), the greedy pair's 2Δℓ stays 21.3 against a threshold of 33.3 (32.8 with steps only). What the quadratic leaves of the hinge is below this record's noise at the check's share: the row is information-limited, not missing a shape; the kink basis was not kept.",
    "**Rerun whole at 72c4d63** (the 2026-11-28 late-morning branches merged: r16heldout — the chain's deviance and AIC, keys only —, r16family, r16reson, r16burst, and the telegraph's regular-dwell decline; other suites shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict, effects, parameters and words as recorded — 9 of 11.",
    "**r17nocand: the truck without its candidate** (2026-11-28, `/tmp` driver at cb4d330; load 8–13 on the 2 cores, other helpers' runs beside): the default call as recorded (the two change points, nothing said); without the change-point candidate `unexplained` now says \"the noise level changes along the record: the Allan deviation at τ₀ within t 6000–6120 s: 2.95× the rest of the record's (1.8e+02 % off the record's level; held-out error 9.4 %)\" — the level test's statistic is now the largest standardised sum over any run of its 32 blocks (the CUSUM's splits among them): the burst's block reads 13.8 against 4.75 where the one split's CUSUM read 3.12 against 4.22 (p 0.028; the threshold rises 4.22 → 4.75 with the runs) — **flagged**; the stretch's two ends located to 6000.0 and 6120.0 s. The clock's row without its candidate (`room` through 3000 s) still says the channel, 26.1 against 22.7 (was 22.4).",
    "Rerun whole on 2026-11-28 at 45caf74 (the r17 merges: the alternative chains unified and memoised, the declared filter, the follows check, the channel check's first quadratic, the level test's runs of blocks, the slow-line test's second reading; r17cost2's cheaper arithmetic, equal to 1e-9, was merged after) with 044680b's why_not_kept fix: every row's verdict as recorded; the truck without its candidate is now flagged (the level test's runs of blocks: the 120 s stretch, 13.8 against 4.75) — without the candidate 7 of 7 rows flagged.",
    "",
    "Rerun whole on 2026-11-28 at da6740f (the r18 merges: r18cost's and r18boot's cheaper arithmetic, the sigma-delta's shaped quantisation (r18sdm), a quantised output's floor (r18bartlett), sharp rippled filter kinds (r18sharp), line families whose fundamental hunts (r18hunt); other suites, CI and the false-alarm bench shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict and effects as recorded — 9 of 11.",
]


def main(argv=None) -> None:
    rb2.suite_main(argv, __doc__, CASES, run_case, _size, NOTES, "refine_blind9", "ninth")


if __name__ == "__main__":
    main()
