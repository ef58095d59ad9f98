#!/usr/bin/env python3
"""``allanite.refine`` on an eighth blind suite of simulated sensors, unlike ``tests/sensors.py``, the seven earlier
blind suites (``benches/refine_blind.py`` … ``refine_blind7.py``) and the ADIS16405 — what a user brings with
default arguments.

**Written and committed before it was first run.** The effects' sizes were fixed beforehand by their Allan
deviation alone (``--sizes``, as ``benches/refine_blind5.py`` sizes them: ≥ 3× for every curve effect a case asks
refine to find; the sparse spikes, judged by their rate, and the bias staircase outside the family are as a
sensor makes them), never by refine's answer; the first run's verdicts are recorded as they came out (the notes
below the table) and the cases are not retuned after it.

The cases: a 50 Hz automotive gyro with a wheel's family (1.2 Hz and harmonics 2–4) whose fundamental wanders
±0.25 % with the vehicle's speed (still one family?); a 2 kHz tactical gyro given as float32 whose spikes all fall
in one 10-minute stretch; 48 h at 5 Hz under a daily temperature cycle, the rate on T and on dT/dt; a 250 Hz MEMS
whose bias steps at two temperature thresholds (20 and 30 °C; outside the family: a staircase in T, said, not
modelled); Student-t(3) white noise behind a 2nd-order Butterworth at 50 Hz (the roll-off to name; its tails
may be flagged); two temperatures logged, a board's and its case's (the case's the board's through a 400 s lag,
correlated 0.8), the rate on the board's only; a clean 800 Hz record behind a 4th-order Butterworth at
240 Hz quantised to twice its per-sample σ (only the roll-off may be added); a clean 24-bit ADC's counts given as
int32 (unit None); a warm-up beside a slow line (period 500 s, the warm-up's 900 s); a 20 % duty pulse train at
0.25 Hz (not a square wave: every harmonic but the 5th, 10th …); the white noise falling to 0.55× at 0.15 T (a
fan stopping near the record's start).

Truths are in the unit refine reports (°/s for the gyros unless said; counts as said). A family is judged on its
fundamental and its rms (the rms over all its harmonics).

Judged as ``benches/refine_blind7.py`` judges (``refine_blind4._judged``: named, parameters within 20 %,
frequencies within 1 %, the chain's error falling in sample and held out, ``unexplained`` empty; a clean case:
nothing added but what it allows, nothing unexplained; an effect outside the family: something left unexplained;
a named channel: no regression on another; change points: each true time within 20 % of a found one).

Usage::

    python benches/refine_blind8.py                  # -> benches/results/refine_blind8.{json,md}
    python benches/refine_blind8.py --case wheel     # the cases whose name contains "wheel", to a temporary folder
    python benches/refine_blind8.py --sizes          # each case's effect size only (no refine)
"""

from __future__ import annotations

import math

import numpy as np
from scipy import signal

import refine_blind as rb
import refine_blind2 as rb2
import refine_blind4 as rb4

sensors = rb.sensors
Injected = sensors.Injected
Blind8 = rb2.Blind2
_periodic = rb2._periodic

#: the wheel's fundamental (Hz), its wander (fraction, ±) and period (s), the harmonics' amplitudes (°/s)
WHEEL_F0, WHEEL_WANDER, WHEEL_PERIOD, WHEEL_AMPS = 1.2, 0.0025, 13_000.0, (3.4e-2, 2.1e-2, 1.3e-2, 8e-3)


def _wheel(rng):
    fs, n = 50.0, 1_000_000  # 2·10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=4e-3, B=5e-4, K=1e-5)
    f = WHEEL_F0 * (1.0 + WHEEL_WANDER * np.sin(2 * np.pi * t / WHEEL_PERIOD + 0.3))
    phase = 2 * np.pi * np.cumsum(f) / fs
    comp = sum(a * np.sin(k * phase + 0.7 * k) for k, a in enumerate(WHEEL_AMPS, start=1))
    return y + comp, fs, {}, {}, comp


def _wheel_rms() -> float:
    return math.sqrt(sum(a * a for a in WHEEL_AMPS) / 2.0)


#: the spikes: how many, the stretch they fall in (s), their size (× the white noise's per-sample σ)
SPIKES, SPIKE_STRETCH, SPIKE_SIGMAS = 150, (900.0, 1500.0), (8.0, 16.0)


def _spikes(rng):
    fs, n = 2000.0, 4_000_000  # 2000 s
    y = rb.noise(n, fs, rng, N=1.5e-3, B=2e-4, K=1e-6) + 4.2e-3
    sigma = 1.5e-3 * math.sqrt(fs)
    lo, hi = (int(s * fs) for s in SPIKE_STRETCH)
    hit = rng.choice(np.arange(lo, hi), SPIKES, replace=False)
    comp = np.zeros(n)
    size = SPIKE_SIGMAS[0] + (SPIKE_SIGMAS[1] - SPIKE_SIGMAS[0]) * rng.random(SPIKES)
    comp[hit] = sigma * size * rng.choice([-1.0, 1.0], SPIKES)
    return (y + comp).astype(np.float32), fs, {}, {}, comp


#: the rate's coupling to the temperature (°/s per °C) and to its rate of change (°/s per °C/s)
DAY_C, DAY_R = 1.3e-4, 2.0


def _daily(rng):
    fs, n = 5.0, 864_000  # 48 h
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2e-3, B=2e-4, K=2e-6)
    weather = sensors.first_order_lag(np.cumsum(rng.standard_normal(n)), fs, 3600.0)
    weather = 1.5 * weather / max(np.ptp(weather), 1e-300)
    temp = 23.0 + 5.0 * np.sin(2 * np.pi * t / 86_400.0 - 2.0) + weather
    comp = DAY_C * (temp - temp.mean()) + DAY_R * np.gradient(temp, 1.0 / fs)
    return y + comp, fs, {"temp": temp + 0.01 * rng.standard_normal(n)}, {}, comp


#: the bias's steps (°/s) at the temperature thresholds (°C)
STAIRS = ((20.0, 1.4e-3), (30.0, 1.8e-3))


def _thresholds(rng):
    fs, n = 250.0, 1_000_000  # 4000 s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=4e-4, K=1e-5)
    temp = sensors.temperature_profile(t, "cycle", rng, lo=10.0, hi=40.0)
    comp = sum(step * (temp > thr) for thr, step in STAIRS)
    comp = comp - comp.mean()
    return y + comp, fs, {"temp": temp + 0.01 * rng.standard_normal(n)}, {}, comp


#: Student-t white noise (dof, scale in °/s per sample) behind a 2nd-order Butterworth (Hz)
STUDENT_DOF, STUDENT_SCALE, STUDENT_CUT = 3, 0.03, 50.0


def _student_lp(rng):
    fs, n = 500.0, 1_000_000  # 2000 s
    y = STUDENT_SCALE * rng.standard_t(STUDENT_DOF, n) + rb.noise(n, fs, rng, B=3e-4, K=5e-6)
    out = signal.sosfilt(signal.butter(2, STUDENT_CUT, fs=fs, output="sos"), y)
    return out, fs, {}, {}, {"without": y}


#: the board's coupling (°/s per °C) and the case's lag behind the board (s)
BOARD_C, CASE_LAG = 1e-4, 400.0


def _board_case(rng):
    fs, n = 100.0, 1_000_000  # 10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=4e-4, K=1e-5)
    board = sensors.temperature_profile(t, "cycle", rng, lo=25.0, hi=45.0)
    case = sensors.first_order_lag(board, fs, CASE_LAG) - 4.0
    comp = BOARD_C * (board - board.mean())
    chans = {"board": board + 0.02 * rng.standard_normal(n), "case": case + 0.02 * rng.standard_normal(n)}
    return y + comp, fs, chans, {}, comp


#: the clean record's 4th-order Butterworth (Hz) and its quantisation (× the filtered per-sample σ)
QF_CUT, QF_STEP = 240.0, 2.0


def _quant_filter(rng):
    fs, n = 800.0, 2_000_000  # 2500 s
    y = rb.noise(n, fs, rng, N=3e-3, B=3e-4, K=1e-5)
    out = signal.sosfilt(signal.butter(4, QF_CUT, fs=fs, output="sos"), y)
    q = QF_STEP * float(np.std(np.diff(out))) / math.sqrt(2.0)
    return np.round(out / q) * q, fs, {}, {}, None


def _adc_counts(rng):
    fs, n = 1000.0, 2_000_000  # 2000 s, counts of a 24-bit ADC: 40 counts per sample white, an offset
    y = rb.noise(n, fs, rng, N=40.0 / math.sqrt(fs), B=0.4, K=4e-3) + 12_345.0
    return np.round(y).astype(np.int32), fs, {}, {}, None


#: the warm-up (°/s, s) and the slow line (°/s, Hz)
SLOW_WARM, SLOW_T, SLOW_AMP, SLOW_F0 = 0.02, 900.0, 2e-3, 1.0 / 500.0


def _warm_slow(rng):
    fs, n = 100.0, 1_000_000  # 10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=3e-4, K=5e-6)
    warm = SLOW_WARM * np.exp(-t / SLOW_T)
    line = SLOW_AMP * np.sin(2 * np.pi * SLOW_F0 * t + 1.1)
    return y + warm + line, fs, {}, {}, [warm, line]


#: the pulse train: frequency (Hz), duty, height (°/s)
PULSE_F0, PULSE_DUTY, PULSE_H = 0.25, 0.2, 0.032


def _pulses(rng):
    fs, n = 200.0, 1_000_000  # 5000 s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=4e-4, K=1e-5)
    comp = PULSE_H * (np.mod(PULSE_F0 * t + 0.13, 1.0) < PULSE_DUTY)
    comp = comp - PULSE_H * PULSE_DUTY
    return y + comp, fs, {}, {}, comp


#: the fan stopping: when (s) and the white noise after it (× before)
FAN_T, FAN_AFTER = 1500.0, 0.55


def _fan_stops(rng):
    fs, n = 50.0, 500_000  # 10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, B=3e-4, K=2e-6)
    white = 3e-3 * math.sqrt(fs) * rng.standard_normal(n)
    white[t >= FAN_T] *= FAN_AFTER
    return y + white, fs, {}, {}, None


CASES = [
    Blind8(
        "automotive gyro, 50 Hz × 10⁶: a wheel's family, 1.2 Hz and harmonics 2–4 (34, 21, 13, 8 ·10⁻³ °/s), the fundamental wandering ±0.25 %",
        _wheel,
        [_periodic([WHEEL_F0], _wheel_rms())],
        seed=801,
    ),
    Blind8(
        "tactical gyro as float32, 2 kHz × 4·10⁶: 150 spikes (8–16 σ) all within t 900–1500 s",
        _spikes,
        [Injected("outliers", {"rate": SPIKES / 4_000_000})],
        seed=802,
    ),
    Blind8(
        "48 h at 5 Hz, daily temperature cycle ±5 °C plus weather: rate on T (1.3·10⁻⁴ °/s per °C) and dT/dt (2 °/s per °C/s)",
        _daily,
        [Injected("regression", {"coefficient": DAY_C, "rate_coefficient": DAY_R})],
        channel="temp",
        seed=803,
    ),
    Blind8(
        "outside the family: bias steps +1.4·10⁻³ and +1.8·10⁻³ °/s where T crosses 20 and 30 °C, T cycling 10–40 °C, 250 Hz × 10⁶",
        _thresholds,
        outside=True,
        channel="temp",
        seed=804,
    ),
    Blind8(
        "Student-t(3) white noise behind a 2nd-order Butterworth at 50 Hz, 500 Hz × 10⁶: the roll-off to name",
        _student_lp,
        [Injected("bandwidth", {"cutoff": STUDENT_CUT})],
        filter="butterworth2",
        seed=805,
    ),
    Blind8(
        "board and case temperatures (the case's through a 400 s lag), the rate on the board's only (10⁻⁴ °/s per °C), 100 Hz × 10⁶",
        _board_case,
        [Injected("regression", {"coefficient": BOARD_C})],
        channel="board",
        seed=806,
    ),
    Blind8(
        "800 Hz × 2·10⁶ behind a 4th-order Butterworth at 240 Hz, quantised to 2σ per sample (clean: only the roll-off)",
        _quant_filter,
        allowed=("bandwidth",),
        seed=807,
    ),
    Blind8(
        "24-bit ADC counts as int32 (unit None), 1 kHz × 2·10⁶, white, flicker and random walk (clean)",
        _adc_counts,
        unit=None,
        seed=808,
    ),
    Blind8(
        "warm-up 0.02·e^{−t/900 s} beside a slow line 2·10⁻³ °/s of period 500 s, 100 Hz × 10⁶",
        _warm_slow,
        [
            Injected("drift", {"amplitude": SLOW_WARM, "T": SLOW_T}),
            Injected("sinusoid", {"amplitude": SLOW_AMP, "f0": SLOW_F0}, ("f0",)),
        ],
        seed=809,
    ),
    Blind8(
        "pulse train 0.032 °/s at 0.25 Hz, 20 % duty (no 5th, 10th … harmonics), 200 Hz × 10⁶",
        _pulses,
        [_periodic([PULSE_F0], PULSE_H * math.sqrt(PULSE_DUTY * (1 - PULSE_DUTY)))],
        seed=810,
    ),
    Blind8(
        "a fan stopping at 0.15 T: white noise 0.55× after t 1500 s, 50 Hz × 5·10⁵",
        _fan_stops,
        [Injected("change_point", {"t": [FAN_T]})],
        seed=811,
    ),
]


def _raised(case, err: Exception, size) -> dict:
    """The row of a case whose call raised: failed, the error in its ``unexplained`` cell (a user's call that
    raises on a record refine should take is a failure of its own)."""
    said = [{"tau": (0.0, 0.0), "band_hz": None, "chi2_dof": None, "what": f"raised {type(err).__name__}: {err}"}]
    v = {"name": case.name, "injected": [{"effect": i.effect, "truth": i.truth} for i in case.injected]}
    v |= {"param_errors": {}, "unexplained": said, "steps": [], "found": [], "start_chi2_dof": float("nan")}
    return v | {"passed": False, "cpu_seconds": 0.0, "size": size, "outside": case.outside, "error": repr(err)}


def run_case(case) -> dict:
    y, fs, channels, kw, comp = case.build(np.random.default_rng(case.seed))
    size = rb4._size(y, comp, fs, kw)
    try:
        v = rb.refined(case, y, fs, channels, kw, rb4._judged)
    except Exception as err:  # noqa: BLE001 — recorded as the case's failure, the suite goes on
        return _raised(case, err, size)
    return v | {"size": size, "outside": case.outside}


#: What the table shows and why (kept true to the recorded run).
NOTES: list = [
    "**First run** (at 1b4b423, the suite as committed, before any change; other processes used 77 % of the CPUs; its table and JSON are in commit 7d44383): **7 of 11 passed**, without the candidate 8 of 8 flagged. Passed as a user would want: the spikes in one 10-minute stretch of a float32 tactical gyro (rate +1.3 %; beside them a Gauss–Markov term σ 1.2·10⁻³ °/s, T_c 33 ms was added, which the judge does not fail — not examined); the filtered Student-t(3) noise (the roll-off named butterworth2 at 50.06 Hz, +0.1 %; its tails flagged as outliers, rate 0.16 %); the board's temperature taken and the case's, correlated 0.8 with it, not (+3.3 %); the clean 800 Hz record behind its 4th-order filter, quantised to 2σ (only the roll-off added, named butterworth3 at 241 Hz: allowed); the clean int32 counts (nothing added, nothing said); the 20 % duty pulse train as one family of 24 lines (0.25 Hz +0.0 %, rms +0.2 %; a second family at 14.66 Hz, 2 lines, rms 1.9·10⁻⁴ °/s, beside it — not examined); the fan stopping at 0.15 T (change point at 1500 s, +0.0 %).",
    "",
    "Why four failed at the first run:",
    "",
    "- *Wheel family wandering ±0.25 %* — named as a family (1.2028 Hz, +0.2 %; rms −0.3 %) but with four sinusoids at its harmonics beside it and a second 'fundamental' of 3.8 mHz tiling the smeared lines; χ²/dof 19 900 → 281 and `unexplained` says lines left at 1.196, 2.396, 3.59–3.60 and 4.79–4.80 Hz, the curve's departure at τ 0.06–0.24 s and that the family's 1.2 Hz line changes along the record (0.012 → 0.022 °/s). A fundamental wandering ±0.25 % with a 13 000 s period swings the fundamental's phase by f₀·0.0025·P = 39 rad (the 4th harmonic's by 156): a phase-modulated family, not lines of constant phase — outside the family as blind6's wandering mains is. Not fixed: no line effect has a wandering phase; what remains is said, in the right band.",
    "- *48 h, T and dT/dt* — the regression taken on T and dT/dt (coefficient −10.0 %, rate coefficient 2.65 against 2.0, **+32.6 %**; the lag's nested test beaten by the rate term, as collinear). The rate coefficient's 68 % interval is 2.31–2.99 (σ ≈ 0.34, 13 % of the estimate), the truth 1.9σ below it: two daily cycles under flicker and rate random walk carry little of dT/dt's information, and the judge's 20 % is 1.2σ of that interval. No bias shown on one record; not examined on more seeds in the time. The channel's regression is `model/channels.py`'s (another helper's this session): not changed here.",
    "- *Bias staircase at 20 and 30 °C* (outside the family) — the regression on T taken (1.59·10⁻⁴ °/s per °C), χ²/dof 1.51 → 1.07, and nothing said. Measured: a straight line in T takes 92 % of the staircase's power (least squares, 1.36·10⁻⁴ °/s per °C); what it leaves (rms 4.0·10⁻⁴ °/s, a quadratic takes nothing more) is 0.74× the rest of the record's Allan deviation at its largest — below what the curve's checks can see — and uncorrelated with T by construction, so the channel check, linear, cannot see it either. Only a check of the residual against the channel's *value* (its means in bins of T against their noise) would; not built in the time (the channels' modules are another helper's this session).",
    "- *Warm-up beside a 500 s line* — the sinusoid taken (amplitude +4.8 %, f0 +0.4 %) and no drift, nothing unexplained. The drift test (500 block means of 20 s) had the line in its block means: statistic 748 against 961, its threshold from the five-term fit whose slow terms the line had raised (K 35 °/h^1.5 in the plain fit, 14 once the line is a term). On the record less the line the same test takes 0.0205·e^{−t/906 s}. **Fixed** (0d8a478, its test a971d14): where the drift is not taken and the line search found lone lines whose period spans more than two block means, the drift test runs once more on the samples less those lines (least squares beside a constant and a ramp), its null from that record's curve; the lines stay for the `sinusoid` candidate (`_in_time.drift_beside_slow_lines`, `tests/test_drift_beside_lines.py`). Its false-alarm side, `benches/results/drift_beside_lines_null.md` (records with one slow line of period 200–3000 s and no warm-up): 40 whole refines, a line found on 17 and the retest run there, no drift taken by either test; the retest's decision alone on 200 more records (the drift test on each record less its line), **0 drifts of 200** (95 % CP 0–1.8 %; the test's share 0.375 %).",
    "",
    "**The table above** is the whole suite rerun after the fix (code of a971d14; other processes used 95 % of the CPUs — two helpers and the ADIS16405 run beside it: its CPU seconds are not a cost measurement): **8 of 11**, without the candidate **8 of 8** — the warm-up beside the slow line is taken (the sinusoid as before; drift amplitude +1.4 %, T +2.7 %; χ²/dof 7.51 → 3.58, RMS ADEV error 9.68 → 0.41 %, held out 5.84 → 2.02 %: the drift's own step raised the held-out curve error 1.85 → 2.02 % and was accepted by its held-out test in time, ratio 0.42); every other row's effects, parameters and words as at the first run. Left as it is: that row's final GLS χ²/dof 3.6 with nothing said (a strong slow line's; blind6's notes give the mechanism for strong lines). The other suites' rows that reach the retest (a lone line slower than 250/L Hz found, no drift taken: blind2's short record, blind3's clock, blind4's 24 h and 0.01 Hz line, blind6's minute-averaged clock and duty-cycled heater, blind7's clock) rerun with `--case`: each row as main gives it (blind3's clock and blind4's 24 h differ from their pages' tables, by the same numbers on main at b49e971: the pages predate later merges). ADIS16405 (`refine_measured.py --processes 1`, `compare_refine.py` against `benches/results/refine.json`): 0 fields not equal. `refine_false_alarms.py --quick` on the fix: 0 of 16 records with an alarm.",
    "",
    '**The staircase\'s row** (r10stair) is `--case "bias steps"` rerun with `unexplained`\'s new shape check (`allanite.model._shape`; docs/channels.md, "A coupling no term models"), merged into the table and JSON: the regression and its numbers as before, and now said — "the rate depends on \'temp\' beyond its kept terms: steps near 20.4 and 29.8 (largest ≈ 0.00147 deg/s)" (truth: steps of 1.4·10⁻³ and 1.8·10⁻³ at 20 and 30 °C; 2Δℓ 37.6 against 34.7 on the least-squares residual) — **passed**: the suite **9 of 11** with that row. The other rows with a channel (the 48 h daily cycle, the board and case) rerun with `--case temperature`: as in the table.',
    "",
    "**The wheel's row** (r11wander) is `--case wheel` rerun with a family's wandering fundamental tracked (`allanite.model.wander`; docs/refinement.md, \"A family whose fundamental wanders\"), merged into the table and JSON: the family's nested test (what the steady fit left within ±0.0113 Hz of 1.2 Hz against the floor 0.27–0.54 Hz away: ratio 795 against 1.16 at α 0.001) and the held-out variance ratio (steady 1.011, tracked 0.466) take the tracked form — one family, fundamentals [1.200115] (+0.0 %), 4 lines, rms 0.03024 (−0.0 %), its wander rms 0.00215 Hz (0.18 %; truth 0.0025·1.2/√2 = 0.00212 Hz) and half span 0.00301 Hz (truth 0.003); no sinusoid, no second 'fundamental', χ²/dof 1.99·10⁴ → 0.838, RMS ADEV error 41.5 → 3.78 %, held out 43.2 → 4.08 %, nothing unexplained: **passed**, the suite **10 of 11**. Tracked from the 1st harmonic in a band of ±0.0113 Hz (the line's spread), the phase is then low-passed to its own band (±0.001 Hz) and tracked again against itself: read in the line's whole band, the track carried that band's noise into the 2nd harmonic at (2·A₂/A₁)² = 1.5× the floor, and the line search after the removal found it as lines left at 2.40–2.41 Hz (✗ at the first try). The other rows with a family (the pulse train) rerun with `--case`: as in the table.",
    "",
    '**r11lagrate** (`--case "48 h at 5 Hz"` rerun; the row as recorded, not replaced): the lag and the d(ch)/dt term are now weighed against each other by their likelihoods, with the phase\'s sign deciding a tie (docs/channels.md, "A lag or a d(ch)/dt term"). Here the rate term fits better by 37.7 in 2Δℓ with r/c +2.3·10⁴ s — a lead, which no lag makes — so it stays, at +32.6 %: not the lag-or-rate ambiguity but the rate coefficient\'s estimate on two daily cycles (as above).',
    "**r12lag** (`--case \"48 h at 5 Hz\"` rerun after the change; the row as recorded): the same (no lag used). On 120 seeded replicas (0.5 Hz × 86 400, the same noise and profile; on this row's own record the replica reads 2.653 for 2.652) the rate coefficient is kept on 86 and reads +3.1 % (−5.8 … +12.7 %) on the first 40 seeds and +6.4 % (+2.6 … +10.4 %) on 80 more, sd 13–16 %, its 68 % interval covering 56 of 86 (65 %): scatter with honest intervals (a few per cent high where its test keeps it) — the row's +32.6 % a 2σ draw, the judge's 20 % 1.3σ of one record (`benches/results/channel_lag_bias.md`).",
    "**Rerun whole at a593464** (every branch of the 2026-11-27 night merged: r12adis, r12chanres, r12burst, r12lag, r12blind10, r12wline, r12ci, r12lineamp; CI, other suites and the ADIS16405 run shared the 2 cores, so the CPU column is not a cost measurement): **10 of 11**, every row's verdict, effects, parameters and words as recorded. The 48 h row's rate coefficient still reads +32.6 %: r12lag measured it a 2σ draw (`benches/results/channel_lag_bias.md`: on 40 and 80 seeded replicas median +3.1 % and +6.4 %, sd 13–16 %).",
    '**r13rate** (`--case "48 h at 5 Hz"` rerun at d013e8c, load 25–30): the level term\'s own test (docs/channels.md, "The level term") keeps it here — at 2 % of the level it would not have (10.79 against 10.83, p 0.0010), at the whole level it does —, so the row is as recorded (coefficient −10.0 %, rate coefficient +32.6 %, every other field the same). On 20 replicas of this row\'s generator (`benches/results/r13rate.md`) the level term is kept on 18 of the 19 accepted (the 19th: p 0.077), the rate coefficient\'s median +1.6 %; with the level term taken out of the truth, a level term is named on 1 of 15.',
    "**Rerun whole at 55d58e5** (every branch of the 2026-11-28 night merged: r13heldout, r13gain, r13swing, r13rate, r13cover, r13cost, r13slowline; the other suites, the ADIS16405 run and CI shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict, effects, parameters and words as recorded.",
    "Rerun whole at 9eaf694 (the 2026-11-28 morning's branches merged: r14house, r14blind11, r14modline, r14pump, r14cost, r14lagrate, r14fir; r14reson merged and reverted; another suite chain, the ADIS16405 run and CI shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict, effects, parameters and χ²/dof as recorded — 10 of 11.",
    "**r16family** (`--case \"pulse train\"` rerun at eb50192, the row and its JSON replaced): the 0.25 Hz pulse train's fold is now taken on the samples less the 14.66 Hz family's two lines — every field as recorded to 7 digits (χ²/dof 0.75837209 → 0.75837213, rms error +0.2394 %); passed as before.",
    "**Rerun whole at 44c3f2f** (the 2026-11-28 late-morning branches merged: r16heldout — the chain's deviance and AIC, keys only —, r16family, r16reson, r16burst; other suites and the false-alarm bench shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict, effects, parameters and words as recorded — 10 of 11. At 44c3f2f the pulse train without its candidate was taken as a telegraph and nothing was said; since 9acc633 regular dwells are declined as periodic (`_telegraph.REGULAR_CV`) and the row, rerun with `--case`, is flagged again (its lines said by the PSD check).",
    "**r17nocand: the board and case temperatures without their candidate** (2026-11-28, `/tmp` driver at cb4d330; load 8–13 on the 2 cores, other helpers' runs beside): still flagged, \"the rate still follows channel 'board'\", 22.97 against 22.57 (was 22.30: the in-phase test at 0.8/1.8 of the channel check's share, was half).",
    "Rerun whole on 2026-11-28 at 45caf74 (the r17 merges: the alternative chains unified and memoised, the declared filter, the follows check, the channel check's first quadratic, the level test's runs of blocks, the slow-line test's second reading; r17cost2's cheaper arithmetic, equal to 1e-9, was merged after) with 044680b's why_not_kept fix: every row's verdict, effects and unexplained domains as recorded, and every without-candidate flag.",
    "",
    "Rerun whole on 2026-11-28 at da6740f (the r18 merges: r18cost's and r18boot's cheaper arithmetic, the sigma-delta's shaped quantisation (r18sdm), a quantised output's floor (r18bartlett), sharp rippled filter kinds (r18sharp), line families whose fundamental hunts (r18hunt); other suites, CI and the false-alarm bench shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict as recorded — 10 of 11; the wheel's family is now gathered as one hunting family (r18hunt; f0 1.2001147 Hz as before, wander 0.002154 → 0.002139 Hz, χ²/dof 0.838 → 0.826).",
]


def main(argv=None) -> None:
    rb2.suite_main(argv, __doc__, CASES, run_case, rb4._size, NOTES, "refine_blind8", "eighth")


if __name__ == "__main__":
    main()
