#!/usr/bin/env python3
"""``allanite.refine`` on a seventh blind suite of simulated sensors, unlike ``tests/sensors.py``, the six earlier
blind suites (``benches/refine_blind.py`` … ``refine_blind6.py``) and the ADIS16405 — what a user brings with
default arguments.

**Written and committed before it was first run.** The effects' sizes were fixed beforehand by their Allan
deviation alone (``--sizes``, as ``benches/refine_blind5.py`` sizes them: ≥ 3× for every curve effect a case asks
refine to find; the gaps, outside the family, are as a logger makes them: size 0.83), never by refine's answer; the first run's verdicts are recorded as they came out (the notes below
the table) and the cases are not retuned after it.

The cases: a tactical gyro whose output is its delta-angle counter (the angle quantised to 3× its white noise's
step per sample, so Q ≥ N up to τ ≈ 2 samples) given as float32 at 2 kHz × 10⁷ (clean: Q is in the start); a
400 Hz MEMS behind a 2nd-order Butterworth at 60 Hz *and* a digital notch at 30 Hz (Q 3; only the roll-off to
name); a 100 Hz record with a family of 100 lines, the harmonics of 0.35 Hz up to 35 Hz with amplitudes falling as
1/k (a band-limited sawtooth); a temperature given in kelvin, quantised to 1/16 K, that reaches the bias through a
600 s lag; a pump switching on three times for 600 s (band noise 20–40 Hz: six change points of the noise's
level); an accelerometer on 1 g (m/s², ``unit=None``) at 10 Hz with a 0.1 Hz sway and a warm-up; a 200 Hz record
whose logger filled three 2 s gaps by repeating the last sample (outside the family: said, not modelled); a clock's
fractional frequency at 1 Hz × 1.5·10⁵ with flicker FM dominant and a line of period 6000 s (a lab's air
conditioning); a FOG with only N and B (rad/s, 10 Hz × 10⁶, clean); a 1 kHz MEMS with Q, N and K only (clean); a
three-axis (n, 3) array refined on axis 2 (a Gauss–Markov term) while axes 0 and 1 carry strong lines; and a gyro
at its turnover temperature: the bias follows (T − 25 °C)² only, no linear term (the quadratic sub-term alone).

Truths are in the unit refine reports (°/s for the gyros unless said; m/s², rad/s and fractional frequency as
said). A family is judged on its fundamental and its rms.

Judged as ``benches/refine_blind6.py`` judges (``refine_blind4._judged``: named, parameters within 20 %,
frequencies within 1 %, the chain's error falling in sample and held out, ``unexplained`` empty; a clean case:
nothing added but what it allows, nothing unexplained; an effect outside the family: something left unexplained;
a named channel: no regression on another; several change points: each true time within 20 % of a found one).

Usage::

    python benches/refine_blind7.py                  # -> benches/results/refine_blind7.{json,md}
    python benches/refine_blind7.py --case kelvin    # the cases whose name contains "kelvin", to a temporary folder
    python benches/refine_blind7.py --sizes          # each case's effect size only (no refine)
"""

from __future__ import annotations

import math

import numpy as np
from scipy import signal

import allanite
import refine_blind as rb
import refine_blind2 as rb2
import refine_blind4 as rb4

sensors = rb.sensors
Injected = sensors.Injected
Blind7 = rb2.Blind2
_periodic = rb2._periodic


def _counter(rng):
    fs, n = 2000.0, 10_000_000  # 5000 s
    rate = rb.noise(n, fs, rng, N=1.7e-3, B=2.8e-4, K=1e-6) + 4.2e-3  # a 0.1 °/√h gyro on the Earth's rate
    q = 3.0 * 1.7e-3 / math.sqrt(fs)  # the counter's step (°): 3× the white noise's angle step per sample
    counts = np.floor(np.cumsum(rate) / fs / q)
    out = np.diff(counts, prepend=0.0) * (q * fs)
    out[0] = out[1]
    return out.astype(np.float32), fs, {}, {}, None


#: the anti-alias Butterworth's cutoff and the notch (Hz, quality factor)
NOTCH_BUTTER, NOTCH_F, NOTCH_Q = 60.0, 30.0, 3.0


def _notch(rng):
    fs, n = 400.0, 1_000_000  # 2500 s
    y = rb.noise(n, fs, rng, N=3e-3, B=5e-4, K=1e-5)
    out = signal.sosfilt(signal.butter(2, NOTCH_BUTTER, fs=fs, output="sos"), y)
    b, a = signal.iirnotch(NOTCH_F, NOTCH_Q, fs=fs)
    return signal.lfilter(b, a, out), fs, {}, {}, {"without": y}


#: the family: fundamental (Hz), number of harmonics, the first harmonic's amplitude (°/s)
FAM_F0, FAM_K, FAM_AMP = 0.35, 100, 1.8e-2


def _family(rng):
    fs, n = 100.0, 1_000_000  # 10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=4e-3, B=6e-4, K=1e-5)
    comp = np.zeros(n)
    for k in range(1, FAM_K + 1):
        comp += FAM_AMP / k * np.sin(2 * np.pi * k * FAM_F0 * t + 0.9 * k)
    return y + comp, fs, {}, {}, comp


def _family_rms() -> float:
    return FAM_AMP * math.sqrt(sum(1.0 / (k * k) for k in range(1, FAM_K + 1)) / 2.0)


#: the kelvin temperature's coupling (°/s per K) and its lag (s)
KELVIN_C, KELVIN_LAG = 3e-4, 600.0


def _kelvin(rng):
    fs, n = 50.0, 1_000_000  # 2·10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=5e-4, K=5e-6)
    temp = sensors.temperature_profile(t, "cycle", rng, lo=288.15, hi=308.15)
    sensor = sensors.first_order_lag(temp, fs, KELVIN_LAG)
    comp = KELVIN_C * (sensor - sensor.mean())
    logged = np.round((temp + 0.01 * rng.standard_normal(n)) * 16.0) / 16.0  # a 1/16 K step
    return y + comp, fs, {"temp_K": logged}, {}, comp


#: the pump: its stretches (s) and its band noise (Hz, °/s rms)
PUMP_ON, PUMP_BAND, PUMP_RMS = ((2000.0, 2600.0), (5000.0, 5600.0), (8000.0, 8600.0)), (20.0, 40.0), 0.15


def _pump(rng):
    fs, n = 200.0, 2_000_000  # 10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2e-3, B=4e-4, K=5e-6)
    band = rb4._band_noise(n, fs, rng, PUMP_BAND[0], PUMP_BAND[1], PUMP_RMS)
    on = np.zeros(n, dtype=bool)
    for a, b in PUMP_ON:
        on |= (t >= a) & (t < b)
    comp = np.where(on, band, 0.0)
    return y + comp, fs, {}, {}, comp


#: the sway (m/s², Hz) and the warm-up (m/s², s)
SWAY_AMP, SWAY_F0, WARM_AMP, WARM_T = 5.6e-4, 0.1, 2e-3, 2500.0


def _sway(rng):
    fs, n = 10.0, 500_000  # 5·10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2e-4, B=3e-5, K=2e-7) + 9.81
    warm = WARM_AMP * np.exp(-t / WARM_T)
    sway = SWAY_AMP * np.sin(2 * np.pi * SWAY_F0 * t + 0.4)
    return y + warm + sway, fs, {}, {}, [warm, sway]


#: the logger's gaps: their starts (s) and length (s), each filled with the last sample before it
GAPS, GAP_S = (1234.0, 2718.0, 4321.0), 2.0


def _gaps(rng):
    fs, n = 200.0, 1_000_000  # 5000 s
    y = rb.noise(n, fs, rng, N=2e-3, B=4e-4, K=5e-6) + 0.3
    held = y.copy()
    for s in GAPS:
        i = int(s * fs)
        held[i : i + int(GAP_S * fs)] = y[i - 1]
    return held, fs, {}, {}, held - y


#: the clock's line: amplitude (fractional frequency) and period (s)
CLOCK_AMP, CLOCK_PERIOD = 1.5e-13, 6000.0


def _clock(rng):
    fs, n = 1.0, 150_000
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-13, B=5e-14, K=1e-18)
    comp = CLOCK_AMP * np.sin(2 * np.pi * t / CLOCK_PERIOD + 0.8)
    return y + comp, fs, {}, {}, comp


def _fog(rng):
    fs, n = 10.0, 1_000_000  # 28 h
    return rb.noise(n, fs, rng, N=2e-7, B=3e-8), fs, {}, {}, None


def _mems_qnk(rng):
    fs, n = 1000.0, 2_000_000  # 2000 s
    return allanite.simulate(n, fs, Q=2e-4, N=3e-3, K=2e-5, seed=rng), fs, {}, {}, None


#: axis 2's Gauss–Markov (rad/s, s); axes 0 and 1 carry lines (rad/s, Hz)
AXIS_GM, AXIS_LINES = (1e-4, 20.0), ((2e-3, 5.5), (1.5e-3, 11.0))


def _axes(rng):
    fs, n = 100.0, 500_000  # 5000 s
    x = np.column_stack([rb.noise(n, fs, rng, N=N, B=B, K=1e-7) for N, B in ((5e-5, 1e-5), (8e-5, 2e-5), (6e-5, 1e-5))])
    t = np.arange(n) / fs
    for j, (a, f) in enumerate(AXIS_LINES):
        x[:, j] += a * np.sin(2 * np.pi * f * t + j)
    comp = allanite.simulate(n, fs, gauss_markov=[AXIS_GM], seed=rng)
    x[:, 2] += comp
    return x, fs, {}, {"axis": 2}, comp


#: the turnover: bias = TURN_Q·(T − TURN_T)² (°/s per °C²), T cycling 15–35 °C
TURN_Q, TURN_T = 4e-5, 25.0


def _turnover(rng):
    fs, n = 20.0, 1_000_000  # 5·10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=4e-4, K=5e-6)
    temp = sensors.temperature_profile(t, "cycle", rng, lo=15.0, hi=35.0)
    comp = TURN_Q * (temp - TURN_T) ** 2
    comp = comp - comp.mean()
    return y + comp, fs, {"temp": temp + 0.01 * rng.standard_normal(n)}, {}, comp


def _size(y, comp, fs: float, kw: dict) -> float | None:
    """``refine_blind4._size`` on the refined axis of multi-axis input."""
    y = np.asarray(y)
    if y.ndim == 2:
        y = y[:, kw.get("axis", 0)]
    return rb4._size(y, comp, fs, kw)


CASES = [
    Blind7(
        "tactical gyro's delta-angle counter (step 3× the white noise's per sample), float32, 2 kHz × 10⁷ (clean: Q)",
        _counter,
        seed=701,
    ),
    Blind7(
        "400 Hz MEMS × 10⁶ behind a 2nd-order Butterworth at 60 Hz and a notch at 30 Hz (Q 3): only the roll-off to name",
        _notch,
        [Injected("bandwidth", {"cutoff": NOTCH_BUTTER, "notch_f": NOTCH_F}, ("notch_f",))],
        filter="butterworth2",
        forbidden=("resonance",),
        seed=702,
    ),
    Blind7(
        "a family of 100 lines: harmonics of 0.35 Hz to 35 Hz, amplitudes 1.8·10⁻²/k °/s, 100 Hz × 10⁶",
        _family,
        [_periodic([FAM_F0], _family_rms())],
        seed=703,
    ),
    Blind7(
        "temperature in kelvin (288–308 K) quantised to 1/16 K, reaching the bias through a 600 s lag (3·10⁻⁴ °/s per K), 50 Hz × 10⁶",
        _kelvin,
        [Injected("regression", {"coefficient": KELVIN_C, "lag_s": KELVIN_LAG})],
        channel="temp_K",
        seed=704,
    ),
    Blind7(
        "a pump on three times for 600 s: band noise 20–40 Hz of 0.15 °/s, 200 Hz × 2·10⁶ (six change points)",
        _pump,
        [Injected("change_point", {"t": [s for ab in PUMP_ON for s in ab]})],
        seed=705,
    ),
    Blind7(
        "accelerometer on 1 g (m/s², unit None), 10 Hz × 5·10⁵: a 0.1 Hz sway of 5.6·10⁻⁴ and a warm-up 2·10⁻³·e^{−t/2500 s}",
        _sway,
        [
            Injected("drift", {"amplitude": WARM_AMP, "T": WARM_T}),
            Injected("sinusoid", {"amplitude": SWAY_AMP, "f0": SWAY_F0}, ("f0",)),
        ],
        unit=None,
        seed=706,
    ),
    Blind7(
        "outside the family: three 2 s gaps the logger filled by repeating the last sample, 200 Hz × 10⁶",
        _gaps,
        outside=True,
        seed=707,
    ),
    Blind7(
        "clock: 1 Hz × 1.5·10⁵ fractional frequency, flicker FM dominant beyond 80 s, a 1.5·10⁻¹³ line of period 6000 s (unit None)",
        _clock,
        [Injected("sinusoid", {"amplitude": CLOCK_AMP, "f0": 1.0 / CLOCK_PERIOD}, ("f0",))],
        unit=None,
        seed=708,
    ),
    Blind7(
        "FOG with only white noise and bias instability (rad/s), 10 Hz × 10⁶ (clean)",
        _fog,
        unit="rad/s",
        seed=709,
    ),
    Blind7(
        "1 kHz MEMS × 2·10⁶ with Q, N and K only (clean)",
        _mems_qnk,
        seed=710,
    ),
    Blind7(
        "three axes as one (n, 3) array (rad/s), 100 Hz × 5·10⁵, refined on axis 2: Gauss–Markov 10⁻⁴ rad/s, T_c 20 s; axes 0, 1 carry lines",
        _axes,
        [Injected("gauss_markov", {"sigma": AXIS_GM[0], "tc": AXIS_GM[1]})],
        unit="rad/s",
        seed=711,
    ),
    Blind7(
        "gyro at its turnover temperature: bias 4·10⁻⁵ °/s per °C² × (T − 25 °C)², no linear term, T 15–35 °C, 20 Hz × 10⁶",
        _turnover,
        [Injected("regression", {"quadratic": TURN_Q})],
        channel="temp",
        seed=712,
    ),
]


def run_case(case) -> dict:
    y, fs, channels, kw, comp = case.build(np.random.default_rng(case.seed))
    size = _size(y, comp, fs, kw)
    return rb.refined(case, y, fs, channels, kw, rb4._judged) | {"size": size, "outside": case.outside}


#: What the table shows and why (kept true to the recorded run).
NOTES: list = [
    "**First run** (at 12960ad, the suite as committed, before any change; other processes used 73 % of the CPUs; its table and JSON are in commit 237eed0): **8 of 12 passed**, without the candidate 8 of 8 flagged. Passed as a user would want: the 100-line family as one periodic effect (0.35 Hz +0.0 %, rms +0.2 %; 32 of its 100 lines taken — the 68 weakest, ≤ 5.5·10⁻⁴ °/s, are below the search's threshold, and the 1/k² power is in the first ones; χ²/dof 912 → 0.71); the kelvin temperature through its 600 s lag (coefficient −4.9 %; the lag's nested test did not keep it and would not at its plain quantile: judged \"not carried\", as `tests/sensors.py` judges); the accelerometer's sway and warm-up (every parameter within 2 %); the clock's 6000 s line under flicker FM (amplitude +4.4 %, f0 −0.1 %); the clean FOG (χ²/dof 0.83) and the clean Q+N+K MEMS (0.96), nothing added or said; axis 2 of the (n, 3) array (σ −2.9 %, T_c −5.5 %; the other axes' lines did not leak in). The logger's gaps, outside the family, were said (\"the record holds one value for 401 samples in a row … in 3 stretches: t 1234–1236, 2718–2720, 4321–4323 s: clipped or stuck — left in the record\") — but beside a Gauss–Markov term (σ 1.5·10⁻³ °/s, T_c 1.0 s) and two change points (t 2717, 4304 s) that are the held stretches read as noise: the judge of an outside case asks only that something be said.",
    "",
    "Why four failed at the first run, and what is still not said:",
    "",
    "- *Delta-angle counter* (clean: Q) — two things. (1) `unexplained` said \"25 % of the samples repeat the one before (5 567 098 exact repeats, 3.06e+06 expected from the quantisation step 0.228): the output rate drops or repeats samples\" — the held check predicts the quantisation's ties from the differences' lattice (n₀ = n₁·(n₁/n₂)^⅓, exact for a smooth density); a counter's rate is the difference of a quantised angle, anti-correlated and on three levels, its −1, +1 pairs raise n₂ and the prediction falls to 0.55× the ties, while the ties at lag 2 are 1.03× those at lag 1. **Fixed** (eaea860): the null is the larger of the prediction and the ties at lag 2 (a repeated sample ties with the one before only; `tests/test_refine_quality.py`); `refine_quality_null.py`: still 0 fired on every null group, its power rows as before. (2) Not fixed: two resonances (380 Hz, q 2, σ 0.020 °/s, statistic 2707 against 12.1; 164 Hz, q 4, 51 against 11.8), χ²/dof 74 → 19, and the curve still departs at τ 0.5–2.5 ms (χ²/dof 69 there). The Q term's 3Q²/τ² holds for a white angle error; a counter whose step is 3× its white noise's angle step per sample has an angle error (the fractional part of a random walk) correlated from sample to sample (≈ 0.07 at lag 1, computed), which 10⁷ samples resolve; refine's family has no such term and the resonances stand in for it. What the user sees: two resonances that are not there, and the departure at τ ≤ 2.5 ms said.",
    "- *Notch behind the anti-alias* — the roll-off named as `single_pole+boxcar` at 40.5 Hz (truth: a 2nd-order Butterworth at 60 Hz, −33 %; statistic 108 104 against 12.2), χ²/dof 5627 → 532, and `unexplained` says the curve departs at τ 2.5–320 ms (χ²/dof 300) and the model lies above it at τ 2.5 ms (χ²/dof 2716). The 30 Hz notch removes a tenth of the band the Allan variance at τ ≈ 1/60 s reads; no kind of the bandwidth effect has a notch, and the nearest shape the kinds give is a lower cutoff. Not fixed (a notch is a filter kind of its own): the model is said not to be right, in the right τ. **Fixed since** (r11notch, below: a notch after the roll-off is a kind of its own).",
    "- *Pump on for three stretches* (six change points) — at the first run three sinusoids at 22.4, 19.9 and 29.4 Hz (PSD ratios 1.67, 1.65, 1.64 against 1.53 at the lines' α 1 % over 17 402 bins), an outliers step (375 samples) and two families (22.38 Hz, 39.3 Hz; 2 lines each), each step *raising* the chain's GLS χ²/dof (35 029 → 40 707), no change point (the search of `refinement/changes.py` takes at most two; none came back), and `unexplained` said the curve departs, the noise level changes (1.34× in t 0–2000 s) and four groups of lines at 20–43 Hz. The lines' mechanism, measured: the Welch average's dof (241, from 121 segments) hold for segments of one power; in 19–31 Hz the segments' powers span 144× (pump on or off) and their effective number (Σ σ_s²)²/Σ σ_s⁴ is 24 of 121, so the F test took the average's own scatter for lines (with the dof scaled by that the threshold at 22.4 Hz is 2.42). **Fixed** (0e921ae): the line search's dof are scaled band by band by K_eff/K from each segment's median level there (`model/_welch_spread.py`; `tests/test_lines_nonstationary.py`: 24–39 false lines per record before, none after, lines beside and inside the band still found; a stationary record's dof unchanged). Rerun: no line, no family; still ✗ — the outliers step stays (a noise on for stretches is, sample by sample, a scale mixture: heavy-tailed against one robust σ), χ²/dof 35 029 → 35 704, and the change points are not found; said: the curve departs at τ 5–45 ms and the noise level changes along the record. **Outliers fixed since** (r9pump, 4cdfac9): the outliers test judges each sample at its local robust scale (per block of 8192 differences, its own or its louder neighbour's: `model/_robust_scale.py`; before, one scale per 31 250 samples put the blocks the pump switches in at a scale between its two levels); the pump row above is rerun with `--case pump` at that commit (other rows as at c7ec6b6): nothing added, no outliers step, `unexplained` still says the curve departs and the noise level changes (1.34× the Allan deviation at τ₀ in t 0–2000 s); still ✗ — the change points are not found. **Change points found since** (r10pump, 34a55b6: the windows' optimal partition instead of binary segmentation of at most two, `refinement/changes.py`); the pump row above is `--case pump` rerun there (other rows as at 6909b06): the six change points at 2000, 2600, 5000, 5600, 8000 and 8600 s (each within 0.01 s), each one's windows' levels and held-out error per segment falling (held out 37.4 → 5.97 % along the six); still ✗ on `unexplained` alone: the curve departs at τ 15–45 ms, the pump's 20–40 Hz band on the record's curve — band noise on 18 % of the time, which no effect of the family models: the resonance that would take its shape (statistic 1.7·10⁶) raised the curve's held-out error 6.69 → 12.8 %, alternate eighths holding 500 s and 1300 s of the pump. The outside rows whose change points moved with it (`--case`, verdicts as recorded, rows not replaced): blind7's gaps 4304 → 4320 s; blind2's chirp 5190 → 5309 s (2543 s kept); blind3's clipped stretch 1184 → 1198 s (its start, 1200 s); blind5's growing noise, replaced on its page.",
    "- *Turnover temperature* (the bias on (T − 25 °C)² only) — at the runs above nothing added: the regression's coupling test is on the channel itself (likelihood ratio 0.19 against 13.7 at α 0.375 %, ν 28; corr(T, (T − mean)²) = 0.05 here), and the quadratic sub-term is tried only once that coupling is accepted (`channels.regress_channel`), so never; `unexplained` says the curve departs at τ 11–61 s (χ²/dof 1.8 there), not that the rate follows the temperature (the channel check is linear too). The user's workaround, measured: (T − mean)² passed as a channel of its own is taken (likelihood ratio 85.6 against 12.6; coefficient 3.88·10⁻⁵, truth 4·10⁻⁵, −2.9 %). Not fixed here: the regression's sub-terms are r9chan's this session; a joint test of the channel and its square (2 dof) at the coupling's share is the general change, its false-alarm side to be measured on the channel nulls. **Fixed at e170c0c** (r9turn; the row above is `--case turnover` rerun there, other processes 69 %): where the coupling's test fails, the quadratic's own nested test runs at its 0.1 % share (docs/channels.md, \"A turnover temperature\") — the regression is taken with quadratic 3.883·10⁻⁵ (−2.9 %), the linear coefficient 6.8·10⁻⁶ beside it, χ²/dof 22.4 → 1.15, nothing unexplained; without the candidate the curve's departure is still said. The other rows were not rerun for this; the channel rows of the suites that could move (a channel the rate does not follow or the coupling fails on: blind 48 h, blind3 two channels and axis 0, blind4 24 h, blind5 72 h, blind6 random-walk temperature and vibrating, blind7 kelvin) rerun with `--case` give the rows as on main.",
    "",
    "**The table above** is the whole suite rerun after both fixes (at c7ec6b6: the held check's lag-2 reference, the line search's per-band dof; other processes 61 %): **8 of 12**, without the candidate 8 of 8 — the counter's row no longer says its samples repeat, the pump's no longer lists lines or families; every other row's effects, parameters and words as at the first run. ADIS16405 (`refine_measured.py --processes 1`, `compare_refine.py`): every row's effects, steps and decisions as before, two line intervals moved in their last digit. `refine_false_alarms.py --quick`: 0 of 16 records with an alarm on main (f6d4d5c) and on this branch. Every other suite rerun whole with both fixes (`refine_blind.py` … `refine_blind6.py`, `refine_sensors.py`, to a temporary folder): every row's verdict, effects and `unexplained` words as their pages record them (passed as recorded: blind 8 of 10, blind2 11 of 11, blind3 12 of 12, blind4 10 of 11, blind5 11 of 12, blind6 9 of 12, sensors 17 of 17); one call without the candidate (blind6's dropped packets, outliers left out) no longer adds a periodic family beside the bandwidth, still flagged.",
    "",
    "**Rerun whole at 6909b06** (r9line, r9blind7, r9chan, r9acc, r9pump and r9turn merged; the table above is this run's, other processes used the second core — CI and helpers): **9 of 12**, without the candidate **8 of 8** — the pump adds nothing (no outliers step since r9pump; still ✗: its six change points are not found, the level change said), the turnover is taken (quadratic −2.9 %, r9turn); the counter (two resonances standing in for its correlated quantisation) and the notch (no filter kind has one) fail as described above; every other row's effects and words as before.",
    "",
    "**r11notch** (`--case notch` rerun at the commit that adds this note, beside four other helpers' runs; the row above and its JSON replaced, the other rows as before): a digital notch after the roll-off is a bandwidth kind of its own since (`<kind>+notch`: `scipy.signal.iirnotch`, its Allan variance exact; gated on the Welch spectrum, screened on the curve beside every kind the step searched, f_n and Q fitted on the spectrum, accepted by its own nested test at a 0.1 % conditional share and where the spectrum's band agrees — docs/refinement.md, \"A notch after the roll-off\"). The row: the roll-off named `butterworth2` at 59.78 Hz (−0.4 %), the notch at 30.02 Hz (+0.06 %), Q 2.92 (truth 3), χ²/dof 5627 → 1.19, held-out 61.1 → 1.87 %, nothing unexplained — **passed** (the judge, `refine_blind._judge_kind`, reads a kind `<low-pass>+notch` as its low-pass and fails a notch where the case's bandwidth truth has none; this case's truth now carries `notch_f`, judged as a frequency within 1 %). The suite: **10 of 12** (the counter and the pump as above).",
    "**Rerun whole at ba83de7** (every branch of the 2026-11-27 evening merged but r11lagrate; none of this suite's rows keeps a d(ch)/dt term): the table above, **11 of 12** — the counter and the notch as their branches recorded, every other row's verdict and effects as before; the repeated-sample gaps' second change point at 4320 s (4304 before). Only the pump fails.",
    "**Rerun whole at a593464** (every branch of the 2026-11-27 night merged: r12adis, r12chanres, r12burst, r12lag, r12blind10, r12wline, r12ci, r12lineamp; CI, other suites and the ADIS16405 run shared the 2 cores, so the CPU column is not a cost measurement): **11 of 12**, every row's verdict, effects, parameters and words as recorded.",
    "**Rerun whole at 55d58e5** (every branch of the 2026-11-28 night merged: r13heldout, r13gain, r13swing, r13rate, r13cover, r13cost, r13slowline; the other suites, the ADIS16405 run and CI shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict, effects, parameters and words as recorded.",
    "",
    '**r14pump** (`--case pump` rerun at 790b78d and again at f75f458 — the base segments must hold half the record — with the same row, other helpers\' runs beside it, load average ≈ 15 on 2 CPUs; the row above and its JSON replaced, the other rows as at 55d58e5): the six change points as before (each within 0.01 s) and now nothing unexplained — the three departures of the record\'s curve (τ 15–45 ms, 5–10 ms, 60–75 ms) are the change points\': the `"allan"` check run again at its share on the four quiet segments\' joined curve, the final terms refitted there, finds none of them, and the three louder segments\' Allan deviation is 7.5× the quiet ones\' at τ 0.01 s (`refinement._segments`, docs/refinement.md, "What a change point changed, and what its louder segments carry"); each change point\'s step says it (`evidence["adev_ratio"]`, `evidence["explains"]`). Without the candidate the departures are still said (4 regions). The suite: **12 of 12**.',
    "Rerun whole at 9eaf694 (the 2026-11-28 morning's branches merged: r14house, r14blind11, r14modline, r14pump, r14cost, r14lagrate, r14fir; r14reson merged and reverted; another suite chain, the ADIS16405 run and CI shared the 2 cores, so the CPU column is not a cost measurement): the pump row as rerun on r14pump (✓), every other row as recorded — 12 of 12.",
    "**Rerun whole at 72c4d63** (the 2026-11-28 late-morning branches merged: r16heldout — the chain's deviance and AIC, keys only —, r16family, r16reson, r16burst; other suites and the false-alarm bench shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict and words as recorded — 12 of 12. The pump's row (band noise 20–40 Hz on for three stretches) now takes two band-pass resonances (27.96 Hz, Q 4; 36.06 Hz, Q 16) before its six change points, where r16reson's band-pass shape fits the band noise's curve (GLS χ²/dof 3.50·10⁴ → 1.29·10⁴, held out 6.69 → 6.64 %); the change points as recorded.",
    "**r17nocand: the pump without its candidate** (2026-11-28, `/tmp` driver at cb4d330, and again at c2f778e with the same words; load 8–13 on the 2 cores, other helpers' runs beside): still flagged — the Allan curve's regions as recorded, and the level check (now the largest standardised sum over any run of blocks) names one of the pump's three runs as a stretch: \"within t 5000–5600 s: 2.27× the rest of the record's (1e+02 % off the record's level; held-out error 6.6 %)\" (recorded: \"1.34× … of t 0…\", a split).",
    "Rerun whole on 2026-11-28 at 45caf74 (the r17 merges: the alternative chains unified and memoised, the declared filter, the follows check, the channel check's first quadratic, the level test's runs of blocks, the slow-line test's second reading; r17cost2's cheaper arithmetic, equal to 1e-9, was merged after) with 044680b's why_not_kept fix: every row's verdict, effects and unexplained domains as recorded, and every without-candidate flag.",
    "",
    "Rerun whole on 2026-11-28 at da6740f (the r18 merges: r18cost's and r18boot's cheaper arithmetic, the sigma-delta's shaped quantisation (r18sdm), a quantised output's floor (r18bartlett), sharp rippled filter kinds (r18sharp), line families whose fundamental hunts (r18hunt); other suites, CI and the false-alarm bench shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict as recorded — 12 of 12; the pump (outside the family, said as before) now also takes a bandwidth among its stand-ins (χ²/dof 1.288·10⁴ → 1.277·10⁴).",
]


def main(argv=None) -> None:
    rb2.suite_main(argv, __doc__, CASES, run_case, _size, NOTES, "refine_blind7", "seventh")


if __name__ == "__main__":
    main()
