#!/usr/bin/env python3
"""``allanite.refine`` on a sixth blind suite of simulated sensors, unlike ``tests/sensors.py``, the five earlier
blind suites (``benches/refine_blind.py`` … ``refine_blind5.py``) and the ADIS16405 — what a user brings with
default arguments.

**Written and committed before it was first run.** The effects' sizes were fixed beforehand by their Allan
deviation alone (``--sizes``, as ``benches/refine_blind5.py`` sizes them: ≥ 3× for every curve effect a case asks
refine to find; impulsive noise by its count), never by refine's answer; the first run's verdicts are recorded as
they came out (the notes below the table) and the cases are not retuned after it.

The cases: a gyro behind a dead band (its output quantised to three levels, −q, 0, +q, with q its white noise's σ:
a nonlinearity, nothing to add); an accelerometer on 1 g (m/s², ``unit=None``) whose logger drops packets — runs
of 4 samples written as 0.0 (impulsive noise 7000 σ deep, in runs, not single samples); a clock's fractional
frequency averaged over minutes (fs 1/60 Hz, 10⁵ samples = 69 days) with a daily line; 50 Hz mains and its odd
harmonics on a 3 kHz record whose grid frequency wanders by ±0.02 %; a vibrating-structure gyro whose 2 Hz line's
amplitude follows the temperature (given as a channel the bias does not follow); an accelerometer with bias
instability and a slow linear tilt (a ramp: rate ramp R, in the family — nothing to add); a 7.3 Hz record (an odd
rate) with a line at 0.4·fs; a heater duty-cycled 30 % of every 600 s reaching the bias through a 40 s thermal
lag (no channel); a rate-random-walk gyro beside a temperature that is itself a random walk and does not couple
(a spurious regression's classic); a short record (3·10⁴ samples at 10 Hz) with a temperature that couples; a
clock at 1 Hz with a frequency step (outside the family); and a white-dominated 200 Hz MEMS (flicker corner far
below 0.01 Hz) whose temperature is logged at 1 Hz and held on the 200 Hz stamps.

Truths are in the unit refine reports (°/s for the gyros; m/s² and fractional frequency under ``unit=None``). A
line whose amplitude varies is judged on its rms amplitude (√2 × the component's rms); a family on its rms.

Judged as ``benches/refine_blind5.py`` judges (``refine_blind4._judged``: named, parameters within 20 %,
frequencies within 1 %, the chain's error falling in sample and held out, ``unexplained`` empty; a clean case:
nothing added but what it allows, nothing unexplained; an effect outside the family: something left unexplained;
a named channel: no regression on another; ``forbidden``: effects that must not be added).

Usage::

    python benches/refine_blind6.py                 # -> benches/results/refine_blind6.{json,md}
    python benches/refine_blind6.py --case clock    # the cases whose name contains "clock", to a temporary folder
    python benches/refine_blind6.py --sizes         # each case's effect size only (no refine)
"""

from __future__ import annotations

import math

import numpy as np

import refine_blind as rb
import refine_blind2 as rb2
import refine_blind4 as rb4

sensors = rb.sensors
Injected = sensors.Injected
Blind6 = rb2.Blind2
_periodic = rb2._periodic


def _dead_band(rng):
    fs, n = 100.0, 1_000_000  # 10⁴ s
    y = rb.noise(n, fs, rng, N=2e-3, B=5e-4, K=1e-5)
    q = 2e-3 * math.sqrt(fs)  # the white noise's σ per sample: 0.02 °/s
    return q * np.clip(np.round(y / q), -1.0, 1.0), fs, {}, {}, None


#: dropped packets: runs of DROP_RUN samples written as 0.0
DROPS, DROP_RUN = 60, 4


def _dropouts(rng):
    fs, n = 200.0, 1_000_000  # 5000 s
    y = rb.noise(n, fs, rng, N=1e-4, B=2e-5, K=5e-7) + 9.81
    starts = np.sort(rng.choice(np.arange(100, n // 10 - 100), DROPS, replace=False)) * 10
    comp = np.zeros(n)
    for s in starts:
        comp[s : s + DROP_RUN] = -y[s : s + DROP_RUN]
    return y + comp, fs, {}, {}, comp


#: the clock's daily line: amplitude (fractional frequency) and frequency (Hz)
DAY_AMP, DAY_F0 = 1e-14, 1.0 / 86_400.0


def _clock_minutes(rng):
    fs, n = 1.0 / 60.0, 100_000  # minute averages, 69 days
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2.3e-13, B=1.5e-15, K=2e-19)
    comp = DAY_AMP * np.sin(2 * np.pi * DAY_F0 * t + 1.1)
    return y + comp, fs, {}, {}, comp


#: mains on a 3 kHz record: fundamental (Hz), amplitudes of harmonics 1, 3, 5 (°/s), wander (fraction, peak)
MAINS_F, MAINS_AMPS, MAINS_WANDER = 50.0, (0.12, 0.072, 0.036), 2e-4


def _mains_wander(rng):
    fs, n = 3000.0, 3_000_000  # 1000 s
    y = rb.noise(n, fs, rng, N=2e-3, B=5e-4, K=1e-5)
    walk = sensors.first_order_lag(np.cumsum(rng.standard_normal(n)), fs, 20.0)
    walk = (walk - walk.mean()) / np.max(np.abs(walk - walk.mean()))
    phase = 2 * np.pi * np.cumsum(MAINS_F * (1.0 + MAINS_WANDER * walk)) / fs
    comp = sum(a * np.sin(k * phase + 0.3 * k) for k, a in zip((1, 3, 5), MAINS_AMPS, strict=True))
    return y + comp, fs, {}, {}, comp


def _mains_rms() -> float:
    return math.sqrt(sum(a * a for a in MAINS_AMPS) / 2.0)


#: the vibrating-structure gyro's line: amplitude (°/s) at the mean temperature, its change per °C, f0 (Hz)
VSG_AMP, VSG_PER_C, VSG_F0 = 0.04, 0.02, 2.0


def _vsg(rng):
    fs, n = 100.0, 1_000_000  # 10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=5e-4, K=1e-5)
    temp = sensors.temperature_profile(t, "cycle", rng, lo=15.0, hi=35.0)
    amp = VSG_AMP * (1.0 + VSG_PER_C * (temp - temp.mean()))
    comp = amp * np.sin(2 * np.pi * VSG_F0 * t + 0.7)
    return y + comp, fs, {"temp": temp + 0.01 * rng.standard_normal(n)}, {}, comp


def _vsg_truth(_params: dict, _steps: list) -> dict:
    y, fs, _ch, _kw, comp = _vsg(np.random.default_rng(605))
    return {"amplitude": float(math.sqrt(2.0 * np.mean(comp * comp)))}


def _tilt_ramp(rng):
    fs, n = 50.0, 1_000_000  # 2·10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2e-4, B=4e-5, K=2e-7)
    tilt = 9.81 * np.sin(3e-4 * t / t[-1])  # a 0.3 mrad tilt building linearly over the record
    return y + 9.81 + tilt, fs, {}, {}, None


#: a line at 0.4·fs of a 7.3 Hz record: amplitude (°/s), frequency (Hz)
ODD_AMP, ODD_F0 = 0.042, 2.9


def _odd_rate(rng):
    fs, n = 7.3, 300_000  # 41 096 s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=4e-3, B=6e-4, K=5e-6)
    comp = ODD_AMP * np.sin(2 * np.pi * ODD_F0 * t + 2.2)
    return y + comp, fs, {}, {}, comp


#: a heater on 30 % of every 600 s, reaching the bias through a 40 s lag (°/s when on, in steady state)
HEAT_PERIOD, HEAT_DUTY, HEAT_LAG, HEAT_STEP = 600.0, 0.3, 40.0, 6e-3


def _heater(rng):
    fs, n = 20.0, 1_000_000  # 5·10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=5e-4, K=5e-6)
    on = (np.mod(t + 123.0, HEAT_PERIOD) < HEAT_DUTY * HEAT_PERIOD).astype(float)
    warm = sensors.first_order_lag(np.concatenate([on[-int(3 * HEAT_PERIOD * fs) :], on]), fs, HEAT_LAG)
    comp = HEAT_STEP * warm[-n:]
    comp = comp - comp.mean()
    return y + comp, fs, {}, {}, comp


def _heater_rms() -> float:
    _y, _fs, _ch, _kw, comp = _heater(np.random.default_rng(608))
    return float(np.sqrt(np.mean(comp * comp)))


def _walks(rng):
    fs, n = 10.0, 1_000_000  # 10⁵ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2e-3, B=2e-4, K=3e-5)
    temp = sensors.temperature_profile(t, "walk", rng, lo=18.0, hi=26.0)
    return y, fs, {"temp": temp + 0.01 * rng.standard_normal(n)}, {}, None


#: the short record's coupling (°/s per °C)
SHORT_C = 7.5e-3


def _short_temperature(rng):
    fs, n = 10.0, 30_000  # 3000 s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=4e-3, B=1e-3, K=2e-5)
    temp = sensors.temperature_profile(t, "swing", rng, lo=24.0, hi=31.0)
    comp = SHORT_C * (temp - temp.mean())
    return y + comp, fs, {"temp": temp + 0.02 * rng.standard_normal(n)}, {}, comp


def _clock_step(rng):
    fs, n = 1.0, 100_000
    y = rb.noise(n, fs, rng, N=1e-12, B=1e-14, K=1e-17)
    comp = np.zeros(n)
    comp[int(0.4 * n) :] = 1e-13  # the frequency steps (a synthesiser retuned, a cable moved)
    return y + comp, fs, {}, {}, comp


#: the white-dominated MEMS's coupling (°/s per °C)
HELD_C = 1.5e-4


def _held_temperature(rng):
    fs, n = 200.0, 2_000_000  # 10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=5e-5, K=2e-7)  # flicker's corner with the white noise ≈ 10⁻³ Hz
    temp = sensors.temperature_profile(t, "cycle", rng, lo=20.0, hi=30.0)
    comp = HELD_C * (temp - temp.mean())
    read = temp[:: int(fs)] + 0.01 * rng.standard_normal(n // int(fs))  # read at 1 Hz …
    held = np.repeat(read, int(fs))[:n]  # … and held on the 200 Hz stamps
    return y + comp, fs, {"temp": held}, {}, comp


CASES = [
    Blind6(
        "gyro behind a dead band: output quantised to 3 levels (−q, 0, +q; q = σ of its white noise), 100 Hz × 10⁶ (clean)",
        _dead_band,
        seed=601,
    ),
    Blind6(
        "accelerometer on 1 g (m/s², unit None), 60 dropped packets: runs of 4 samples written as 0.0, 200 Hz × 10⁶",
        _dropouts,
        [Injected("outliers", {"rate": DROPS * DROP_RUN / 1_000_000})],
        unit=None,
        seed=602,
    ),
    Blind6(
        "clock: minute averages of fractional frequency (fs 1/60 Hz) × 10⁵ (69 days), a 10⁻¹⁴ daily line (unit None)",
        _clock_minutes,
        [Injected("sinusoid", {"amplitude": DAY_AMP, "f0": DAY_F0}, ("f0",))],
        unit=None,
        seed=603,
    ),
    Blind6(
        "50 Hz mains and harmonics 3, 5, the grid wandering ±0.02 % (±0.01 Hz), 3 kHz × 3·10⁶",
        _mains_wander,
        [_periodic([MAINS_F], _mains_rms())],
        seed=604,
    ),
    Blind6(
        "vibrating-structure gyro: a 2 Hz line whose amplitude follows the temperature (±20 %), temperature given, bias not on it, 100 Hz × 10⁶",
        _vsg,
        [Injected("sinusoid", {"f0": VSG_F0}, ("f0",), truth_at=_vsg_truth)],
        forbidden=("regression",),
        seed=605,
    ),
    Blind6(
        "accelerometer (m/s², unit None) on 1 g, bias instability, a 0.3 mrad tilt building linearly, 50 Hz × 10⁶ (clean: a ramp is R)",
        _tilt_ramp,
        unit=None,
        forbidden=("drift",),
        seed=606,
    ),
    Blind6(
        "odd rate: 7.3 Hz × 3·10⁵, a 0.042 °/s line at 2.9 Hz (0.4·fs)",
        _odd_rate,
        [Injected("sinusoid", {"amplitude": ODD_AMP, "f0": ODD_F0}, ("f0",))],
        seed=607,
    ),
    Blind6(
        "heater duty-cycled 30 % of every 600 s through a 40 s thermal lag (no channel), 20 Hz × 10⁶",
        _heater,
        [_periodic([1.0 / HEAT_PERIOD], None)],
        seed=608,
    ),
    Blind6(
        "rate-random-walk gyro beside a random-walk temperature that does not couple, 10 Hz × 10⁶ (clean)",
        _walks,
        channel="temp",
        forbidden=("regression",),
        seed=609,
    ),
    Blind6(
        "short record: 3·10⁴ samples at 10 Hz, a housing warming 24 → 31 °C, 7.5·10⁻³ °/s per °C",
        _short_temperature,
        [Injected("regression", {"coefficient": SHORT_C})],
        channel="temp",
        seed=610,
    ),
    Blind6(
        "outside the family: a clock (1 Hz × 10⁵, unit None) whose frequency steps by 10⁻¹³ at 0.4 T",
        _clock_step,
        outside=True,
        unit=None,
        seed=611,
    ),
    Blind6(
        "white-dominated 200 Hz MEMS × 2·10⁶ (flicker corner ≈ 10⁻³ Hz), temperature read at 1 Hz and held, 1.5·10⁻⁴ °/s per °C",
        _held_temperature,
        [Injected("regression", {"coefficient": HELD_C})],
        channel="temp",
        seed=612,
    ),
]

# the heater's rms is the component's own (the family's lines and their decay through the lag)
CASES[7].injected[0].truth["rms"] = _heater_rms()


def run_case(case) -> dict:
    y, fs, channels, kw, comp = case.build(np.random.default_rng(case.seed))
    size = rb4._size(y, comp, fs, kw)
    return rb.refined(case, y, fs, channels, kw, rb4._judged) | {"size": size, "outside": case.outside}


#: What the table shows and why (kept true to the recorded run).
NOTES: list = [
    "**First run** (at cc49baa, the suite as committed, before any change; other processes used 72 % of the CPUs; its table and JSON are in commit 6592dd5): **7 of 12 passed**, without the candidate 7 of 8 flagged. Passed as a user would want: the dead band's three levels (nothing added, nothing said; start χ²/dof 0.51); the minute-averaged clock's daily line at 10⁻¹⁴ (amplitude −0.6 %, f0 +0.0 %; fs 1/60 Hz, values ~10⁻¹³); the linear tilt on 1 g (nothing added: a ramp is R; no drift in its place); the 7.3 Hz record's line at 0.4·fs (amplitude and f0 +0.0 %) — but with a Gauss–Markov term (σ 8.4·10⁻⁴ °/s, T_c 1.1 s) added beside it that is not in the truth (the judge asks for the injected effects, not for nothing else; see below); the duty-cycled heater as one family (1/600 Hz, 5 lines, rms +0.2 %); the random-walk temperature beside a rate-random-walk gyro not taken (the spurious regression's classic); the short coupled record (coefficient +5.4 %).",
    "",
    "**The table above** is the whole suite rerun after the fix below (at 1c7cb65; its \"+dirty\" is these notes, not yet committed when it ran; other processes 82 %): **8 of 12**, without the candidate 7 of 8 — the dropped packets pass, nothing unexplained; every other row's effects, parameters and words as at the first run. Rerun with the fix (`--case`): `refine_sensors.py`'s sparse spikes, heavy tails, and temperature and spikes; blind5's spikes and Student-t tails; blind2's bursts; blind3's 6 s clipped at full scale (still said, clipped or stuck): each row as its page records it. `refine_false_alarms.py --quick`: 0 of 16 records with an alarm on main (80c1a7b) and on this branch.",
    "",
    "Why five failed at the first run, and what is still not said:",
    "",
    '- *Dropped packets* — the outliers step found all 240 zeroed samples (rate +0.0 %) and replaced them, then `unexplained` said "the record is clipped at 0: 240 samples at its smallest value (240 in 60 runs) … — left in the record": the clipped check looked at the samples as given, replaced or not. **Fixed** (1c7cb65): the clipped and held checks leave out the samples the outliers step replaced (a rail keeps those no step replaced; `tests/test_refine_replaced_samples.py`). Rerun: ✓, nothing unexplained.',
    "- *Mains with grid wander* — the family at 49.998 Hz (3 lines) is removed in time first (least squares at fixed frequencies: the part of each line whose phase carries across the record, rms 0.047 °/s), then the line search runs again on what it left and three sinusoids at 50, 150 and 250 Hz hold the rest on the curve at their power (0.106, 0.063, 0.035 °/s; the chain lists the curve steps first). The powers add up (0.047² + 0.091² = 0.102²): not a double count of power but the same lines listed twice, the family's rms the coherent 21 % of it (−54 % at the first run). Since r8fam the sinusoids at a family's own lines fold into it (`refinement/_family_fold.py`): their steps stay in the history marked `folded_into`, their columns in the curve's model (χ²/dof 52 800 → 12.5 as before), the final model lists the family once and its rms is the whole family's, 0.1019 for 0.1019 (−0.3 %). Still ✗: `unexplained` says the 50 Hz line's amplitude changes along the record (0.158 °/s in t 0–125 s, 0.089 after) — true of a fixed-frequency fit: a grid wandering ±0.01 Hz through a 20 s lag moves the tone's phase by radians over the record (a line 10 bins wide at 1000 s); refine has no tone whose phase follows a wandering frequency, and the family's `evidence[\"wandering\"]` says that 21 % of its power is coherent.",
    "- *Vibrating-structure gyro* — the 2 Hz line exact (f0 +0.0 %, amplitude +0.3 % on its rms), no regression on the temperature (the bias does not follow it), and `unexplained` says \"the 2.00 Hz line's amplitude changes along the record: 0.0328 °/s in t 0–625 s, 0.0408 after\" — true, its amplitude follows the temperature ±20 %. The case's truth asked for a constant line; refine's family has no line whose amplitude follows a channel. Not retuned; the entry is what a user needs to read.",
    "- *Clock frequency step* (outside the family) — at the first run nothing added and nothing said: the mean check's statistic 4.99·10⁻¹⁴ against its threshold 5.25·10⁻¹⁴ at its α (1.6·10⁻⁴) — 0.95×; the step located at sample 40 040 (truth 40 000), d 1.02·10⁻¹³ (truth 10⁻¹³). Its null, refitted on the record less the located step (K 0, B 6.6·10⁻¹⁵), raised flicker and random walk to their upper ends *at once* (B 1.25·10⁻¹⁴, K 1.2·10⁻¹⁶ against the true 10⁻¹⁷): each end is allowed with the other terms refitted, together a corner the curve does not allow. **Fixed** (r8step): the threshold is the largest over the profile's models — each slow term at its upper end, the others refitted there (B-end: B 1.25·10⁻¹⁴, K 0, threshold 2.89·10⁻¹⁴; K-end: K 1.2·10⁻¹⁶, B 0, threshold 4.62·10⁻¹⁴) — so 1.08× its threshold. Rerun alone (`--case \"clock (1 Hz\"`): ✓, \"the mean steps by 1e-13 at t ≈ 40040 s (it raises the Allan deviation by 135 % at τ 1.111e+04 s; held-out error 5.9 %)\" — 9 of 12 with the table's other rows. Still a narrow pass: the statistic under the true noise is 2.0× its threshold there, and a GLS (Whittle) likelihood ratio for a step at the known time gives z 10.5 under the true noise, 9.0 under the K-end model, 7.5 under the corner: the check's statistic (unweighted block means) loses most of that to the random walk the curve cannot rule out; on five other seeds of this record the profile says the step on 2 (ratios 0.68–1.29; the corner 0.63–1.21). The change-point candidate does not take it by design: it tests steps of the noise *level* (the windows' Allan variances), which a step of the mean leaves alone.",
    "- *1 Hz-held temperature on a white-dominated MEMS* — the regression named (coefficient −5.8 %; likelihood ratio 23.1 against 17.8 at α 0.375 %), GLS χ²/dof 1.01 → 0.96, but the RMS ADEV error 1.48 → 1.98 % and held out 3.97 → 4.29 % (the step's own held-out test 3.97 → 5.29 %): before the removal the five terms had absorbed the temperature into K 1.8·10⁻⁵ and R 4.9·10⁻⁷ (truth K 2·10⁻⁷, R 0); after it B 8.3·10⁻⁵ (truth 5·10⁻⁵), K and R 0 — nearer the truth, scored worse by the RMS error (as `tests/sensors.py`'s judge says of issue 29's 25-hour log). Without the candidate nothing is said: `unexplained`'s channel check at its share (α 6.25·10⁻⁴, pair and in-phase tests at half each) does not reach a coupling the regression's own test takes at 1.3× its threshold. Not changed.",
    "",
    "**A cause measured and not fixed — strong lines' covariance.** The 7.3 Hz row's Gauss–Markov term is a stand-in: on white noise alone plus the same 0.042 °/s line at 2.9 Hz (3.9× the white noise's σ per sample) refine takes the exact sinusoid and is left at GLS χ²/dof 5.9 with the Allan curve said to depart (the same line at 1.0 Hz: χ²/dof 17.6, then a roll-off at 1.47 Hz added). The sinusoid's Allan variance is exact there (estimate/model 1.0000 at m = 1 … 12); the misfit is the covariance the tests whiten with (`calibrated.curve_test`): the five terms' covariance scaled by model/terms, so where the line dominates the estimates are given the scatter of a noise 14× the white one and its correlation, while a tone adds no scatter of its own — only a cross term with the noise, 2·L_m·ε with one ε for every τ (on this record cross/L_m = 5.85·10⁻⁴ at m = 1 … 12; 40 seeds: the estimates' relative SD 0.11 % at m = 1 with the line, 0.31 % without). Tried (not committed): the noise's covariance left unscaled by the line plus that cross term's, σ²·v·vᵀ with v = L_m·√8/(A·√N) (σ² the noise's variance per sample, N the samples) — white + line: χ²/dof 5.9 → 1.24, nothing added, nothing unexplained; but ADIS16405 run 3 acc_x's default call then skipped its Gauss–Markov and 0.443 Hz line for the periodic family and ended with the fit's χ²/dof 3.4 (1.4 on main) and held out 5.03 % (4.17 %), failing `test_refine_line_amplitude.py`. Left for a session that can rerun the measured table with it.",
    "**Rerun at 44eba23** (every branch of the 2026-11-27 afternoon merged: the sinc^k kind chain, the family fold, the mean check's per-term nulls, the coupling test's bootstrap where its dof is small, the cost round, the module splits): the table above, **9 of 12**, without the candidate **8 of 8** — the clock's frequency step is now said (the mean check's null raises one slow term at a time, `refinement/_noisefit.upper_models`), the mains family's rms is the whole family's (−0.3 %: the sinusoids found again at its own lines fold into it), and the 1 Hz-held temperature refined without its candidate now says the rate still follows 'temp' (the coupling test's bootstrap). Still ✗: the mains (its lines' phase wanders: said as the 50 Hz line's amplitude changing), the vibrating gyro (its line's amplitude follows the temperature: said), the 1 Hz-held temperature (named, coefficient −5.8 %, but its held-out error rises 3.97 → 4.29 %).",
    "**The 1 Hz-held temperature's held-out rise measured** (r9chan): it is the scoring's, not the regression's. The channel is now read back at its readings' instants (held for 1 s, `evidence[\"channel_form\"]`); the row, rerun alone (`--case white-dominated`, replaced above): coefficient 1.413·10⁻⁴ (−5.8 %; its 68 % interval 1.22–1.60·10⁻⁴ holds the truth), RMS ADEV 1.48 → 1.99 % (1.98 before: a ½ s hold on a 3333 s cycle moves the coefficient by 0.07 %), held out 3.97 → 4.29 % as before. The true coupling removed in its place scores no better: the regression's coefficient replaced by the true 1.5·10⁻⁴, RMS 1.48 → 1.92 %, held out 3.97 → 4.29 %; with the true component also in the held-out refit (no estimate at all), 3.97 → 4.38 %. The record less the true component, refined alone, scores 2.09 % in sample and 3.61 % held out on its own curve: the five terms fit this noise (N 3·10⁻³, flicker 5·10⁻⁵, K 2·10⁻⁷; fitted B 8.3·10⁻⁵, K and R 0) only to ≈ 2 %, while with the temperature left in, K 1.8·10⁻⁵ and R 4.9·10⁻⁷ bend the model toward this record's long-τ estimates. A true removal scored worse: the RMS ADEV error rewards a model that absorbs the coupling where the five terms' own misfit of the noise exceeds the coupling's footprint. Not changed (the scoring is refine's, not the regression's); the row stays ✗ by the judge's held-out criterion.",
    "",
    "**The mains row** (r11wander) is `--case mains` rerun with a family's wandering fundamental tracked (`allanite.model.wander`; docs/refinement.md, \"A family whose fundamental wanders\"), merged into the table and JSON: the family's nested test (ratio 2400 against 1.30 at α 0.001, tracked from the 3rd harmonic) and the held-out variance ratio (steady 0.979, tracked 0.535) take the tracked form — fundamentals [49.99980] (+0.0 %), 3 lines, rms 0.1022 (−0.0 %; the coherent fit's 0.040 before the fold), its wander rms 0.00365 Hz (truth, this record's grid: 0.00385 Hz) and half span 0.00895 Hz (0.0090), no sinusoid at its lines, χ²/dof 5.28·10⁴ → 1.13, RMS ADEV error 46.7 → 2.08 %, held out 47.6 → 4.30 %, nothing unexplained: **passed**, the suite **10 of 12**. The heater's duty cycle (a family of 5 lines) rerun with `--case`: as in the table.",
    "**Rerun whole at ba83de7** (every branch of the 2026-11-27 evening merged but r11lagrate; none of this suite's rows keeps a d(ch)/dt term): the table above, **10 of 12** with r11wander's mains row — every row's verdict, effects and words as on this page; the dropped packets' outlier threshold 0.01002 → 0.009995.",
    "**Rerun whole at a593464** (every branch of the 2026-11-27 night merged: r12adis, r12chanres, r12burst, r12lag, r12blind10, r12wline, r12ci, r12lineamp; CI, other suites and the ADIS16405 run shared the 2 cores, so the CPU column is not a cost measurement): **11 of 12** (the vibrating gyro's line with its gain on 'temp', r12lineamp), every row's verdict, effects, parameters and words as recorded.",
    "",
    "**The 1 Hz-held temperature's held-out rise on replicas** (r13heldout, `benches/r13heldout.py` → `benches/results/r13heldout.md`, the row's generator on 20 other seeds): the chain's held-out error rises after the regression on 4 of 20 (95 % Clopper–Pearson 6–44 %; after − before median −0.68 points, SD 0.99), the true component removed in its place on 4 of 20 too. The suite seed's start (3.97 %) is the replicas' median and its rise (+0.32 points) a third of the change's SD: the held-out score is scored on τ ≤ 167 s (EDF ≥ 50 on parts of 5000 s), where the temperature is at most 34 % of the curve and the parts' own scatter (on this seed 10–16 % at 30–140 s) decides the RMS. The row stays ✗ by the judge's 'held out falling' on this seed; the judge is not changed. The step's own held-out comparison (`evidence[\"heldout_test\"]`) read 3.97 → 5.29 %, scored on the held-out part's corrected curve; it is now the chain's 3.97 → 4.29 % (`scoring.Split.error`; every decision and chain number as recorded).",
    "**Rerun whole at 55d58e5** (every branch of the 2026-11-28 night merged: r13heldout, r13gain, r13swing, r13rate, r13cover, r13cost, r13slowline; the other suites, the ADIS16405 run and CI shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict, effects, parameters and words as recorded.",
    "Rerun whole at 9eaf694 (the 2026-11-28 morning's branches merged: r14house, r14blind11, r14modline, r14pump, r14cost, r14lagrate, r14fir; r14reson merged and reverted; another suite chain, the ADIS16405 run and CI shared the 2 cores, so the CPU column is not a cost measurement): every row as recorded but the vibrating gyro's (r14modline: χ²/dof final 1.50 → 1.38, the same effects, ✓) — 11 of 12.",
    "**Rerun whole at 44c3f2f** (the 2026-11-28 late-morning branches merged: r16heldout — the chain's deviance and AIC, keys only —, r16family, r16reson, r16burst; other suites and the false-alarm bench shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict, effects, parameters and words as recorded — 11 of 12. Without its candidate the dropped-packet row takes a telegraph (the runs of zeros switch between two levels) and is still flagged (rerun at 9acc633).",
    "**r17nocand: the white-dominated MEMS without its candidate** (2026-11-28, `/tmp` driver at cb4d330; load 8–13 on the 2 cores, other helpers' runs beside): still flagged, \"the rate still follows channel 'temp' (≈ 0.000141 deg/s per channel unit)\", 22.99 against 22.96 — the in-phase test now at 0.8/1.8 of the channel check's share (was half; the first quadratic's test takes the rest), so its threshold rose from 22.65: the narrowest margin of the suites' channel entries.",
    "Rerun whole on 2026-11-28 at 45caf74 (the r17 merges: the alternative chains unified and memoised, the declared filter, the follows check, the channel check's first quadratic, the level test's runs of blocks, the slow-line test's second reading; r17cost2's cheaper arithmetic, equal to 1e-9, was merged after) with 044680b's why_not_kept fix: every row's verdict, effects and unexplained domains as recorded, and every without-candidate flag.",
    "",
    "Rerun whole on 2026-11-28 at da6740f (the r18 merges: r18cost's and r18boot's cheaper arithmetic, the sigma-delta's shaped quantisation (r18sdm), a quantised output's floor (r18bartlett), sharp rippled filter kinds (r18sharp), line families whose fundamental hunts (r18hunt); other suites, CI and the false-alarm bench shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict and effects as recorded — 11 of 12.",
]


def main(argv=None) -> None:
    rb2.suite_main(argv, __doc__, CASES, run_case, rb4._size, NOTES, "refine_blind6", "sixth")


if __name__ == "__main__":
    main()
