#!/usr/bin/env python3
"""``allanite.refine`` on a twelfth blind suite of simulated sensors, unlike ``tests/sensors.py``, the eleven earlier
blind suites (``benches/refine_blind.py`` … ``refine_blind11.py``), ``benches/refine_sensors.py`` and the
ADIS16405 — what a user brings with default arguments.

**Written and committed before it was first run.** The effects' sizes were fixed beforehand by their Allan
deviation alone (``--sizes``, as ``benches/refine_blind11.py`` sizes them: ≥ 3× for every effect a case asks
refine to find; the effects outside the family are as a sensor makes them), never by refine's answer; the first
run's verdicts are recorded as they came out (the notes below the table) and the cases are not retuned after it.

The cases: a gyro whose bias follows an *accelerometer* channel (g-sensitivity, the vehicle parked on slopes and
shaken); a heater's PWM making a fast 60 s sawtooth in the temperature, reaching the bias through a 20 s lag; an
oscillator's **phase** record (``input="phase"``, unit None) whose frequency follows the room's temperature; a
sigma-delta MEMS whose quantisation noise is shaped to rise toward f_s/2 (clean); a low-cost 10 Hz gyro dominated
by flicker (clean); a 1 kHz gyro of white noise read through a coarse quantiser (clean); a 1 Hz task's glitch comb
(narrow pulses every second: harmonics to Nyquist); a GNSS-disciplined clock's frequency with a diurnal line; a
mechanical line at 0.45·f_s; a gyro on a battery whose bias follows the supply voltage (discharge and load
steps) — and two effects **outside the family**: a motor spinning down (a line whose frequency falls along the
record) and three shocks, each leaving a bias that relaxes back.

Judged as ``benches/refine_blind11.py`` judges (``refine_blind4._judged``: named, parameters within 20 %,
frequencies within 1 %, the chain's error falling in sample and held out, ``unexplained`` empty; a clean case:
nothing added but what it allows, nothing unexplained; an effect outside the family: something left unexplained;
a named channel: no regression on another). Every case with an effect in the family is refined again without its
effect's candidate, which must leave something unexplained.

Usage::

    python benches/refine_blind12.py               # -> benches/results/refine_blind12.{json,md}
    python benches/refine_blind12.py --case clock  # the cases whose name contains "clock", to a temporary folder
    python benches/refine_blind12.py --sizes       # each case's effect size only (no refine)
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
Blind12 = rb2.Blind2
_periodic = rb2._periodic
_weather = rb10._weather  # a random walk through a first-order lag, peak-to-peak 1


# ---------------------------------------------------------------------------------------------------------------
# 1. g-sensitivity: the bias follows an accelerometer channel

#: °/s per g
GSENS_C = 0.05


def _g_sensitive(rng):
    fs, n = 200.0, 1_000_000  # 5000 s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=3e-4, K=1e-5)
    acc = np.ones(n)
    for t0 in np.sort(rng.uniform(0.0, t[-1], 10)):  # parked again on another slope: cos(tilt)
        acc[t >= t0] = math.cos(rng.uniform(0.0, 0.5))
    acc += 0.01 * _weather(n, fs, rng, 100.0)  # the suspension settling
    comp = GSENS_C * (acc - acc.mean())
    return y + comp, fs, {"acc_z": acc + 2e-3 * rng.standard_normal(n)}, {}, comp


# ---------------------------------------------------------------------------------------------------------------
# 2. a heater's PWM: a 60 s sawtooth in the temperature, through a 20 s lag

PWM_C, PWM_LAG = 7e-3, 20.0


def _heater(rng):
    fs, n = 100.0, 1_000_000  # 10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2e-3, B=2e-4, K=5e-6)
    temp = 40.0 + 0.6 * signal.sawtooth(2 * np.pi * t / 60.0, 0.8) + 0.5 * _weather(n, fs, rng, 800.0)
    comp = PWM_C * (sensors.first_order_lag(temp, fs, PWM_LAG) - temp.mean())
    comp -= comp.mean()
    return y + comp, fs, {"temp": temp + 0.01 * rng.standard_normal(n)}, {}, comp


# ---------------------------------------------------------------------------------------------------------------
# 3. an oscillator's phase record, its frequency on the room's temperature

OSC_C = 6e-13  # fractional frequency per °C


def _osc_phase(rng):
    fs, n = 1.0, 200_000  # 2.3 days
    t = np.arange(n + 1) / fs
    freq = rb.noise(n + 1, fs, rng, N=2e-12, B=3e-13, K=1e-16)
    room = 22.0 + 1.5 * np.sin(2 * np.pi * t / 86_400.0 + 0.7) + 1.0 * _weather(n + 1, fs, rng, 3000.0)
    comp = OSC_C * (room - room.mean())
    phase = np.cumsum(freq + comp) / fs + 1e-12 * rng.standard_normal(n + 1)  # s
    return phase, fs, {"room": room}, {"input": "phase"}, comp[1:]


# ---------------------------------------------------------------------------------------------------------------
# 4. sigma-delta MEMS: second-order shaped quantisation noise (clean)


def _sigma_delta(rng):
    fs, n = 1000.0, 1_000_000  # 1000 s
    y = rb.noise(n, fs, rng, N=5e-3, B=5e-4, K=2e-5)
    q = 0.05 * rng.standard_normal(n + 2)  # the modulator's quantisation error, then its (1 − z⁻¹)² shaping
    return y + np.diff(q, 2), fs, {}, {}, None


# ---------------------------------------------------------------------------------------------------------------
# 5. a low-cost 10 Hz gyro dominated by flicker (clean)


def _flicker_10hz(rng):
    fs, n = 10.0, 100_000  # 10⁴ s
    return rb.noise(n, fs, rng, N=2e-3, B=2e-3, K=2e-5), fs, {}, {}, None


# ---------------------------------------------------------------------------------------------------------------
# 6. a 1 kHz gyro, white noise read through a coarse quantiser (clean)


def _coarse(rng):
    fs, n = 1000.0, 1_000_000  # 1000 s
    lsb = 0.02
    y = rb.noise(n, fs, rng, N=1e-3, K=1e-5) + 0.3 * lsb  # σ per sample 1.6 LSB, a bias of 0.3 LSB
    return np.round(y / lsb) * lsb, fs, {}, {}, None


# ---------------------------------------------------------------------------------------------------------------
# 7. a motor spinning down: a line whose frequency falls (outside)


def _spin_down(rng):
    fs, n = 200.0, 1_000_000  # 5000 s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2e-3, B=2e-4, K=5e-6)
    f = 40.0 - 15.0 * t / t[-1]  # 40 → 25 Hz
    comp = 0.1 * np.sin(2 * np.pi * np.cumsum(f) / fs)
    return y + comp, fs, {}, {}, comp


# ---------------------------------------------------------------------------------------------------------------
# 8. a 1 Hz task's glitch comb: narrow pulses every second

COMB_FS, COMB_H, COMB_W = 500.0, 0.03, 10  # Hz, °/s, samples per pulse


def _comb_rms() -> float:
    d = COMB_W / COMB_FS  # duty
    return COMB_H * math.sqrt(d * (1 - d))


def _comb(rng):
    fs, n = COMB_FS, 1_000_000  # 2000 s
    y = rb.noise(n, fs, rng, N=1.5e-4, B=5e-5, K=2e-6)
    k = np.arange(n) % int(fs)
    comp = np.where((k >= 137) & (k < 137 + COMB_W), COMB_H, 0.0)
    comp -= comp.mean()
    return y + comp, fs, {}, {}, comp


# ---------------------------------------------------------------------------------------------------------------
# 9. three shocks, each leaving a bias that relaxes (outside)


def _shocks(rng):
    fs, n = 100.0, 1_000_000  # 10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2e-3, B=2e-4, K=5e-6)
    comp = np.zeros(n)
    for t0, a in ((1800.0, 5.2e-3), (5200.0, -4e-3), (8100.0, 6.5e-3)):
        on = t >= t0
        comp[on] += a * np.exp(-(t[on] - t0) / 250.0)
    return y + comp, fs, {}, {}, comp


# ---------------------------------------------------------------------------------------------------------------
# 10. a GNSS-disciplined clock's frequency with a diurnal line

GDC_A, GDC_F = 4e-13, 1.0 / 86_400.0


def _gnss_clock(rng):
    fs, n = 1.0, 400_000  # 4.6 days
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-12, B=5e-14)  # disciplined: no random walk left at long τ
    comp = GDC_A * np.sin(2 * np.pi * GDC_F * t + 2.1)
    return y + comp, fs, {}, {}, comp


# ---------------------------------------------------------------------------------------------------------------
# 11. a mechanical line at 0.45·f_s

NYQ_FS, NYQ_F, NYQ_A = 2000.0, 900.0, 0.3


def _near_nyquist(rng):
    fs, n = NYQ_FS, 2_000_000  # 1000 s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2e-3, B=3e-4, K=1e-5)
    comp = NYQ_A * np.sin(2 * np.pi * NYQ_F * t + 0.4)
    return y + comp, fs, {}, {}, comp


# ---------------------------------------------------------------------------------------------------------------
# 12. a gyro on a battery: the bias follows the supply voltage

BAT_C = 5e-3  # °/s per V


def _battery(rng):
    fs, n = 400.0, 2_000_000  # 5000 s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=3e-4, K=1e-5)
    v = 12.6 - 1.2 * t / t[-1]  # discharge
    for t0 in np.sort(rng.uniform(0.0, t[-1], 12)):  # loads switched on and off
        v[t >= t0] += rng.choice([-0.25, 0.25])
    v += 0.02 * _weather(n, fs, rng, 50.0)
    comp = BAT_C * (v - v.mean())
    return y + comp, fs, {"vbat": v + 5e-3 * rng.standard_normal(n)}, {}, comp


CASES = [
    Blind12(
        "g-sensitive gyro: the bias follows an accelerometer channel (0.05 °/s per g; parked on 10 slopes), 200 Hz × 10⁶",
        _g_sensitive,
        [Injected("regression", {"coefficient": GSENS_C})],
        channel="acc_z",
        seed=1201,
    ),
    Blind12(
        "a heater's PWM: the temperature a 60 s sawtooth (±0.6 °C), reaching the bias through a 20 s lag (7·10⁻³ °/s per °C), 100 Hz × 10⁶",
        _heater,
        [Injected("regression", {"coefficient": PWM_C, "lag_s": PWM_LAG})],
        channel="temp",
        seed=1202,
    ),
    Blind12(
        "oscillator's phase record (input='phase', s, unit None) at 1 Hz × 2·10⁵, its frequency on the room's temperature (6·10⁻¹³ per °C)",
        _osc_phase,
        [Injected("regression", {"coefficient": OSC_C})],
        channel="room",
        unit=None,
        seed=1203,
    ),
    Blind12(
        "sigma-delta MEMS at 1 kHz × 10⁶, its quantisation noise shaped (1 − z⁻¹)² to rise toward f_s/2 (clean)",
        _sigma_delta,
        # its own noise named is no stand-in (as a clean filtered row allows its bandwidth); the kind did not
        # exist when the suite was written (r18sdm added it), so this allowance came after the first run
        allowed=("shaped_quantisation",),
        seed=1204,
    ),
    Blind12(
        "low-cost gyro at 10 Hz × 10⁵, flicker-dominated (bias instability above the white noise from 0.1 s) (clean)",
        _flicker_10hz,
        seed=1205,
    ),
    Blind12(
        "1 kHz gyro × 10⁶, white noise read through a coarse quantiser (LSB 0.02 °/s, σ 1.6 LSB) (clean)",
        _coarse,
        seed=1206,
    ),
    Blind12(
        "outside the family: a motor spinning down, a 0.1 °/s line falling 40 → 25 Hz along the record, 200 Hz × 10⁶",
        _spin_down,
        outside=True,
        seed=1207,
    ),
    Blind12(
        "a 1 Hz task's glitch comb: 20 ms pulses of 0.03 °/s every second (harmonics to Nyquist), 500 Hz × 10⁶",
        _comb,
        [_periodic([1.0], _comb_rms())],
        seed=1208,
    ),
    Blind12(
        "outside the family: three shocks (t 1800, 5200, 8100 s), each leaving a bias of 4–6.5·10⁻³ °/s that relaxes in 250 s, 100 Hz × 10⁶",
        _shocks,
        outside=True,
        seed=1209,
    ),
    Blind12(
        "GNSS-disciplined clock's frequency (unit None) at 1 Hz × 4·10⁵, white and flicker FM, a diurnal line of 4·10⁻¹³",
        _gnss_clock,
        [Injected("sinusoid", {"f0": GDC_F, "amplitude": GDC_A}, ("f0",))],
        unit=None,
        seed=1210,
    ),
    Blind12(
        "a mechanical line at 0.45·f_s: 0.3 °/s at 900 Hz, 2 kHz × 2·10⁶",
        _near_nyquist,
        [Injected("sinusoid", {"f0": NYQ_F, "amplitude": NYQ_A}, ("f0",))],
        seed=1211,
    ),
    Blind12(
        "gyro on a battery: the bias follows the supply voltage (5·10⁻³ °/s per V; discharge 12.6 → 11.4 V and 12 load steps of ±0.25 V), 400 Hz × 2·10⁶",
        _battery,
        [Injected("regression", {"coefficient": BAT_C})],
        channel="vbat",
        seed=1212,
    ),
]


def _size(y, comp, fs: float, kw: dict) -> float | None:
    """``refine_blind9._size``, on the frequency a phase record stands for."""
    if kw.get("input") == "phase":
        y = np.diff(np.asarray(y, dtype=np.float64)) * fs
    return rb9._size(y, comp, fs, {k: v for k, v in kw.items() if k != "input"})


def run_case(case) -> dict:
    return rb9.run_case(case, _size)


#: What the table shows and why (kept true to the recorded run).
NOTES: list = [
    "**First run** (at 63b9eda, the suite as committed, before any change; the machine otherwise idle; its table and JSON are in commit 7139584): **9 of 12 passed**, without the candidate **4 of 7** flagged. Passed as a user would want: the heater's 60 s PWM sawtooth through a 20 s lag (regression on `temp` with its lag: coefficient −11.0 %, lag 16.9 s, −15.6 %; χ²/dof 76.2 → 1.18, held out 22.4 → 1.9 %); the two clean gyros — flicker-dominated at 10 Hz × 10⁵ and white noise through a coarse quantiser (σ 1.6 LSB) at 1 kHz — nothing added, nothing said; the motor's spin-down, outside the family (said: the Allan curve departs at τ 0.02–1.3 s, ≈ 25 Hz, statistic 3.1·10⁵ against 22.9 — beside stand-ins: a resonance at 28.7 Hz, a one-line 'periodic' at 33.7 Hz whose tracked fundamental wanders by 15 %, and four noise-level change points); the 1 Hz glitch comb (one periodic family, fundamental 1.0000000 Hz, 217 lines to Nyquist, rms +0.01 %; χ²/dof 6457 → 1.00 — not read as outliers though each pulse is ≈ 9 σ per sample); the three shocks, outside the family (said: \"the mean steps by 0.0048 deg/s at t ≈ 1800.72 s; by −0.0042 deg/s at t ≈ 5197.2 s; and by 0.0056 deg/s at t ≈ 8100.8 s\", the steps check 3.72 against 2.48 — each shock's time within 3 s); the GNSS clock's diurnal line in 4.6 days (the few-cycle line test: f0 −0.1 %, amplitude +5.2 %); the 900 Hz line at 0.45·f_s (amplitude +0.01 %); the battery's supply voltage (regression on `vbat`, +4.2 %, through its discharge ramp and load steps).",
    "",
    "Why three failed (from each Refinement's evidence):",
    "",
    "- *g-sensitive gyro (bias on an accelerometer channel)* — named right (regression on `acc_z`, coefficient −2.3 %; likelihood ratio 106.8 against 13.9) and the held-out error fell 5.03 → 2.84 %, but the in-sample chain rose (χ²/dof 1.05 → 1.20, RMS ADEV 2.39 → 2.93 %). The start's five terms had taken the coupling's steps (ten slopes) into the rate random walk: K 1.21·10⁻⁴ with B 0, against the truth's K 10⁻⁵ and B 3·10⁻⁴; after the removal the refit reads B 3.04·10⁻⁴, K 0, R 3·10⁻⁷ — the truth's noise, fitted less well in sample than the start fitted the record with the coupling in it. The record less the true component, refined alone, starts at χ²/dof 1.95: the five terms' own misfit of this noise, not the regression's (the pattern of blind6's held temperature, blind9's dT/dt-only gyro and blind10's humidity). Failed on the in-sample criterion alone.",
    "- *Oscillator's phase record, `input='phase'`* — refused before any work: `ParameterError: unknown input 'phase'; allowed: 'rate', 'increment', 'angle'`. A clock's phase is allanite's `input='angle'` (the integral of the rate, M + 1 points), but a clock user types allantools' and Stable32's word. Refined with `input='angle'` (a diagnostic, not the row) the same call then refused the temperature logged with each phase reading (M + 1 samples against M rates). **Changed since** (dfd81a2, 1f28b9d): with `input='angle'` a channel of M + 1 samples is taken as each interval's mean of its two ends, and `input='phase'` (or 'freq', 'frequency') is refused with allanite's word for it. The row still calls `input='phase'` and is still ✗ (rerun with `--case oscillator`: the error now names `input='angle'`); with `input='angle'` the diagnostic takes the regression on `room`, coefficient 5.47·10⁻¹³ (−8.9 %; likelihood ratio 16.0 against 13.8), and says nothing unexplained.",
    "- *Sigma-delta MEMS, quantisation noise shaped (1 − z⁻¹)²* — clean by the suite, but a `bandwidth` (boxcar, 2.78 taps, 159 Hz; GLS score 4155 against 12.4) was added: the five terms cannot hold doubly differenced white noise (the start's χ²/dof 34.7; quantisation Q is a single difference), and the boxcar's reshaping of the shortest τ stands in for it (χ²/dof → 1.23, nothing said). The family has no shaped-quantisation term; a user would read the step as a filter the sensor does not have.",
    "",
    "Without the candidate (4 of 7 flagged): the accelerometer channel's and the battery's \"the rate still follows channel …\"; the comb's line at 4 Hz and the 900 Hz line said by the PSD check. Not flagged: the heater, whose 60 s sawtooth is taken by the periodic candidate in the regression's place (fundamental 1/60 Hz: a periodic temperature's coupling is a periodic effect — nothing left); the GNSS clock, whose few-cycle line was still taken as a 'sinusoid' by the line search's removal in time with the candidate left out — **changed since** (f248d00: the removals in time take only effects among `candidates`), now nothing is taken and nothing said (the few-cycle line test's finding is not among the checks behind `unexplained`); the oscillator (raised).",
    '**The GNSS clock\'s row without its candidate** (`--case GNSS` rerun at d562e2f: the removals in time hold to `candidates`, and a few-cycle line the line search found but no step could take is said): the default call as recorded (✓); without the sinusoid candidate nothing is taken and `unexplained` says "a line of few cycles at 1.156e-05 Hz (4.6 cycles in the record, amplitude 4.21e-13), found by its test in time (χ² 35.8 against 24.4) — the sinusoid candidate was not among the candidates refine ran" — flagged: **without the candidate 5 of 7**.',
    "**On two other seeds each** (offsets +100, +200; the default call at c50c6c1, judged as the suite judges; not rows of the suite; `/tmp` driver over `CASES` with `dataclasses.replace(case, seed=…)`): the glitch comb passes on both (216 lines, rms +0.04 % and +0.1 %) and so does the 900 Hz line (amplitude +0.03 %, −0.03 %); the heater's PWM passes on 1302 (coefficient −3.2 %, lag −4.8 %) and fails on 1402 on its parameters (+17.1 %, lag +22.5 %); the g-sensitive gyro passes on 1301 (+10.2 %, every chain falling) and fails on 1401 on the held-out error alone (2.93 → 2.98 %); the sigma-delta's shaped noise fails on both — 1304: nothing added, and `unexplained` says the curve departs (the model above it, then below: what a shaped noise the five terms lack looks like — said, which is honest, but a clean case by the judge), 1404: the boxcar stand-in again (2.83 taps, 156 Hz). **The battery fails on both though it passed on the suite's seed**: the coupling named and its coefficient right (−11.8 %, −0.5 %), but the held-out error rises, 1.31 → 4.97 % and 2.27 → 3.47 % (on 1312 the in-sample chain too: χ²/dof 1.50 → 1.52, RMS 1.04 → 1.28 %) — the supply's discharge is a ramp across the record that the held-out halves each see a part of; not examined further this stop.",
    "**The battery's held-out rise on the other seeds, measured** (a diagnostic at 0281c74): the record less its true component, refined with no candidate, starts at a held-out error of 3.82 % (seed 1312) and 5.47 % (1412) — against 1.31 % and 2.27 % with the coupling left in, and the chain's after-values 4.97 % and 3.47 % (the suite's seed: 2.29 % less the truth, the chain 2.22 → 1.79 %). A true removal scores about what the noise alone scores: the five terms predict these records' halves worse than they predict the records with the supply's ramp and steps in them, which the start takes into its slow terms — the pattern of blind10's humidity and blind6's held temperature (benches/results/r13heldout.md), not the regression's estimate (coefficients −11.8 %, −0.5 %).",
    "**The other five rows on two other seeds each** (as above, at abf719b): the two clean gyros (10 Hz flicker, coarse quantiser) say nothing on all four records; the spin-down and the three shocks, outside the family, are said on all four (the shocks: two or three of the three steps named, each within 5 s); the GNSS clock's diurnal line passes on both (f0 +0.98 %, amplitude +3.3 % and −1.1 %). Over the two extra seeds of the eleven rows that do not raise (the oscillator's `input='phase'` fails the same way on any seed): **16 of 22** pass — the failures the sigma-delta (2), the battery (2), the heater and the g-sensitive gyro (1 each), as above.",
    "**The sigma-delta's shaped noise, measured** (2·10⁶ samples of (1 − z⁻¹)² white noise against single-differenced white noise of the same σ, overlapping AVAR): the ratio is 3.34 at τ0 and 2.00 at every m ≥ 2 (2, 3, 4, 8, 16, 64). So the shaped noise is the quantisation term Q with twice the variance, except at the first point of the curve, which is 1.67× that Q. The stand-in `bandwidth` (a boxcar of 2.8 taps) is the family's way to bend a single point at τ0; the seed where nothing was added said that the curve departs there. A term for the first point alone (a sensor's shaped or filtered first lag) is not in the family.",
    "**The heater's row rerun** (`--case heater`, after the suite took `tests/sensors.first_order_lag` in place of its own copy of the same lag): every field as recorded to 10⁻¹¹ relative (the lag's start in equilibrium written another way: the temperature's lagged copy differs by 1.6·10⁻¹³ °C); the row and its JSON replaced.",
    "**The oscillator's row at a6df681** (`--case oscillator`): `input='phase'` is now taken as `'angle'` everywhere an input is taken. The default call: regression on `room`, coefficient −8.9 %; χ²/dof 1.44 → 1.10, RMS ADEV 1.98 → 2.02 %, held out 5.85 → 1.91 %; nothing unexplained — ✓, **10 of 12**. Without its candidate nothing is said (still 5 of 7 flagged): the channel check behind `unexplained` tests at its own share (p = 1.6·10⁻⁴ for each of its two tests), and this coupling's in-phase test gives p = 3.9·10⁻⁴ — the regression candidate takes it at its larger share.",
    "**Rerun whole at 44c3f2f** (the 2026-11-28 late-morning branches merged: r16heldout — the chain's deviance and AIC, keys only —, r16family, r16reson, r16burst; other suites and the false-alarm bench shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict, effects, parameters and words as recorded — 10 of 12 (the motor's resonance now band-pass, r16reson: χ²/dof 2.77·10⁴ → 1.82·10⁴ as there). At 44c3f2f the glitch comb without its candidate was taken as a telegraph; since 9acc633 (regular dwells declined) the row, rerun with `--case`, is flagged again.",
    "**r17nocand: the heater and the oscillator without their candidate** (2026-11-28, `/tmp` driver over `CASES` at cb4d330 — the default call and the call without the regression candidate, as `refined` makes them; load 8–13 on the 2 cores, other helpers' runs beside): *the heater* — the default call as recorded (regression on `temp`, nothing said); without the candidate the periodic family at 1/60 Hz is taken as before and `unexplained` now says it (the new `\"follows\"` check, `model/refinement/_channel_follows.py`: the line the model took is coherent with a channel no regression uses, and the channel carries it): \"the periodic line the model took at 0.01667 Hz follows channel 'temp', which carries it (coherence 0.96 over 27 segments): a regression on 'temp' may be the better reading\" (coherence 0.958 against 0.233 at its α 10⁻³; the channel's line test too) — **flagged**. *The oscillator* — the default call as recorded; without the candidate still nothing said: the channel check runs the regression candidate's own Whittle GLS test against the record's own noise (the pair, the in-phase test and now the first quadratic), and the coupling's in-phase test reads p = 3.6·10⁻⁴ on the final samples — above the check's whole α (3.1·10⁻⁴), so no split of its share can say it; not forced (the share not raised). Without the candidate **6 of 7** flagged (the cells of the table are the recorded run's until the suite is rerun).",
    "Rerun whole on 2026-11-28 at 45caf74 (the r17 merges: the alternative chains unified and memoised, the declared filter, the follows check, the channel check's first quadratic, the level test's runs of blocks, the slow-line test's second reading; r17cost2's cheaper arithmetic, equal to 1e-9, was merged after) with 044680b's why_not_kept fix: every row's verdict as recorded; the heater without its candidate is now flagged (the follows check: the periodic line at 0.01667 Hz follows channel 'temp', coherence 0.96 over 27 segments); the oscillator still not (its coupling's p 3.6e-4 is above the channel check's whole share).",
    "",
    "Rerun whole on 2026-11-28 at da6740f (the r18 merges: r18cost's and r18boot's cheaper arithmetic, the sigma-delta's shaped quantisation (r18sdm), a quantised output's floor (r18bartlett), sharp rippled filter kinds (r18sharp), line families whose fundamental hunts (r18hunt); other suites, CI and the false-alarm bench shared the 2 cores, so the CPU column is not a cost measurement): **11 of 12.** The sigma-delta row now names its own noise, `shaped_quantisation` of order 2 (r18sdm; q +0.36 %), where a boxcar stood in, and says nothing unexplained. The row is clean of injected effects; since this rerun it allows that kind as a clean filtered row allows its bandwidth (2826ff9: the kind did not exist when the suite was written, so the allowance came after the first run and is said here). The other rows as recorded.",
]


def main(argv=None) -> None:
    rb2.suite_main(argv, __doc__, CASES, run_case, _size, NOTES, "refine_blind12", "twelfth")


if __name__ == "__main__":
    main()
