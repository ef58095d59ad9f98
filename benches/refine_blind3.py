#!/usr/bin/env python3
"""``allanite.refine`` on a third blind suite of simulated sensors, unlike ``tests/sensors.py``, the first two
blind suites (``benches/refine_blind.py``, ``benches/refine_blind2.py``) and the ADIS16405 — what a user brings
with default arguments.

**Written and committed before it was first run.** The effects' sizes were fixed beforehand by their Allan
deviation alone (``--sizes``: the largest ratio over τ ≤ T/4 of the injected component's Allan deviation to that of
the rest of the record, ≥ 3× for every curve effect), never by refine's answer; the first run's verdicts are
recorded as they came out (the notes below the table) and the cases are not retuned after it.

The cases: a temperature channel quantised to 1/16 °C and logged at 1 Hz beside a 100 Hz gyro (held between its
readings: a zero-order hold); a temperature channel with its own sensor noise (0.2 °C white, a thermistor's);
two channels (temperature, supply voltage) where only the voltage couples; a 2 kHz gyro behind a 4th-order
Butterworth anti-alias filter, quantised, with 50 Hz mains pickup and its harmonics; a 1 Hz × 10⁵ FOG-like sensor
(tiny white noise, strong rate random walk) whose bias follows the temperature through a 900 s lag; random
telegraph (popcorn) noise, whose second-order statistics are exactly a Gauss–Markov term's (so it is judged as
one: σ the half-spacing of its two levels, T_c = 1/(2λ)); float32 samples of a 1 kHz gyro on a 250 °/s bias with
a line; a clock (1 Hz phase, turned to frequency: white phase noise, white and flicker frequency noise, an
air-conditioning cycle of 1100 s); and three axes of one call (``axis=``) with a temperature only the third axis
follows — and two effects **outside refine's family**: bias steps at three times, and a stretch clipped at the
sensor's full scale.

Judged as ``benches/refine_blind2.py`` judges (its ``_judged``: ``refine_blind.judge`` — named, parameters within
20 %, frequencies within 1 %, the chain's error falling in sample and held out, ``unexplained`` empty; a clean case:
nothing added but what it allows, nothing unexplained; an effect outside the family: something left unexplained;
a named channel: no regression on another). Every case with an effect in the family is refined again without its
effect's candidate, which must leave something unexplained.

Usage::

    python benches/refine_blind3.py                # -> benches/results/refine_blind3.{json,md}
    python benches/refine_blind3.py --case clock   # the cases whose name contains "clock", to a temporary folder
    python benches/refine_blind3.py --sizes        # each case's effect size only (no refine)
"""

from __future__ import annotations

import math

import numpy as np
from scipy import signal

import refine_blind as rb
import refine_blind2 as rb2

sensors = rb.sensors
Injected = sensors.Injected
Blind3 = rb2.Blind2


def _gyro_with_held_temperature(rng):
    fs, n = 100.0, 1_000_000  # 10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2e-3, B=4e-4, K=1e-5)
    temp = sensors.temperature_profile(t, "cycle", rng, lo=20.0, hi=40.0)
    comp = 6e-4 * (temp - temp.mean())
    held = temp[(np.arange(n) // int(fs)) * int(fs)]  # read once a second, held until the next reading
    logged = np.round(held * 16.0) / 16.0  # a 1/16 °C temperature register
    return y + comp, fs, {"temp": logged}, {}, comp


def _noisy_thermistor(rng):
    fs, n = 10.0, 500_000  # 5·10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=5e-3, B=1e-3, K=2e-5)
    temp = sensors.temperature_profile(t, "walk", rng, lo=18.0, hi=30.0)
    comp = -3e-3 * (temp - temp.mean())
    logged = temp + 0.2 * rng.standard_normal(n)
    return y + comp, fs, {"temp": logged}, {}, comp


def _voltage_couples(rng):
    fs, n = 200.0, 1_000_000  # 5000 s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=6e-4, K=1e-5)
    temp = sensors.temperature_profile(t, "swing", rng, lo=22.0, hi=31.0) + 0.02 * rng.standard_normal(n)
    walk = sensors.first_order_lag(np.cumsum(rng.standard_normal(n)), fs, 20.0)
    vdd = 3.3 + 0.03 * (walk - walk.mean()) / np.ptp(walk)
    comp = 0.5 * (vdd - vdd.mean())
    logged = vdd + 2e-4 * rng.standard_normal(n)
    return y + comp, fs, {"temp": temp, "vdd": logged}, {}, comp


#: 50 Hz mains pickup: (harmonic, amplitude °/s, phase)
MAINS = ((1, 0.24, 0.3), (2, 0.07, 1.1), (3, 0.14, 2.0), (5, 0.06, 0.7))


def _mains_2khz(rng):
    fs, n = 2000.0, 2_000_000  # 1000 s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=4e-3, B=1e-3, K=2e-5)
    comp = sum(a * np.sin(2 * np.pi * 50.0 * k * t + p) for k, a, p in MAINS)
    sos = signal.butter(4, 400.0, fs=fs, output="sos")
    out, comp_f = signal.sosfilt(sos, y + comp), signal.sosfilt(sos, comp)
    lsb = 1.0 * 4e-3 * math.sqrt(fs)  # one white-noise σ per step
    return np.round(out / lsb) * lsb, fs, {}, {}, comp_f


def _mains_rms() -> float:
    gains = np.abs(
        signal.sosfreqz(signal.butter(4, 400.0, fs=2000.0, output="sos"), [50.0 * k for k, _, _ in MAINS], fs=2000.0)[1]
    )
    return float(math.sqrt(sum((g * a) ** 2 / 2 for g, (_, a, _) in zip(gains, MAINS, strict=True))))


def _fog_lag(rng):
    fs, n = 1.0, 100_000
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2e-7, B=1e-7, K=2e-8)
    temp = sensors.temperature_profile(t, "cycle", rng, lo=15.0, hi=35.0)
    sensor = sensors.first_order_lag(temp, fs, 900.0)
    comp = 6e-7 * (sensor - sensor.mean())
    logged = temp + 0.01 * rng.standard_normal(n)
    return y + comp, fs, {"temp": logged}, {}, comp


#: random telegraph noise: levels ±h, switching at rate λ each way
RTN_H, RTN_LAMBDA = 4e-3, 0.05


def _telegraph(rng):
    fs, n = 50.0, 1_000_000  # 2·10⁴ s
    y = rb.noise(n, fs, rng, N=3e-3, B=3e-4, K=2e-6)
    flips = rng.random(n) < RTN_LAMBDA / fs
    comp = RTN_H * np.where(np.cumsum(flips) % 2 == 0, 1.0, -1.0)
    comp = comp - comp.mean()
    return y + comp, fs, {}, {}, comp


def _float32_line(rng):
    fs, n = 1000.0, 1_000_000
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2e-3, B=4e-4, K=1e-5)
    comp = 0.06 * np.sin(2 * np.pi * 13.3 * t + 0.8)
    return (y + comp + 250.0).astype(np.float32), fs, {}, {}, comp


def _clock(rng):
    fs, n = 1.0, 200_000
    t = np.arange(n) / fs
    freq = rb.noise(n, fs, rng, N=3e-12, B=4e-13)  # white FM 3·10⁻¹² /√Hz, flicker FM 4·10⁻¹³
    comp = 1.5e-12 * np.sin(2 * np.pi * t / 1100.0 + 0.4)  # air conditioning cycling every 1100 s
    phase = np.cumsum(freq + comp) / fs + 2e-12 * rng.standard_normal(n)  # white phase noise 2 ps
    y = np.diff(phase) * fs
    return y, fs, {}, {}, comp[1:]


def _bias_steps(rng):
    fs, n = 20.0, 600_000  # 3·10⁴ s
    y = rb.noise(n, fs, rng, N=3e-3, B=3e-4, K=1e-6)
    comp = np.zeros(n)
    for frac, jump in ((0.2, 2.5e-3), (0.5, -4e-3), (0.8, 3e-3)):
        comp[int(frac * n) :] += jump
    return y + comp, fs, {}, {}, comp


def _clipped(rng):
    fs, n = 400.0, 1_000_000  # 2500 s
    y = rb.noise(n, fs, rng, N=2e-3, B=4e-4, K=1e-5)
    full_scale = 0.08
    a, b = int(1200.0 * fs), int(1206.0 * fs)  # a knock on the bench: 6 s at the rail
    out = y.copy()
    out[a:b] = full_scale
    return out, fs, {}, {}, out - y


def _three_axes(axis):
    def build(rng):
        fs, n = 200.0, 600_000  # 3000 s
        t = np.arange(n) / fs
        x = np.column_stack([rb.noise(n, fs, rng, N=3e-3, B=6e-4, K=1e-5) for _ in range(3)])
        temp = sensors.temperature_profile(t, "cycle", rng, lo=25.0, hi=45.0)
        comp = 4e-4 * (temp - temp.mean())
        x[:, 2] += comp
        logged = temp + 0.02 * rng.standard_normal(n)
        return x, fs, {"temp": logged}, {"axis": axis}, (comp if axis == 2 else None)

    return build


_periodic = rb2._periodic


CASES = [
    Blind3(
        "temperature quantised to 1/16 °C, read at 1 Hz and held, 100 Hz gyro × 10⁶",
        _gyro_with_held_temperature,
        [Injected("regression", {"coefficient": 6e-4})],
        channel="temp",
        seed=301,
    ),
    Blind3(
        "temperature (random walk) with 0.2 °C thermistor noise, 10 Hz × 5·10⁵",
        _noisy_thermistor,
        [Injected("regression", {"coefficient": -3e-3})],
        channel="temp",
        seed=302,
    ),
    Blind3(
        "two channels: a temperature swing that does not couple, a 3.3 V supply that does (0.5 °/s per V), 200 Hz × 10⁶",
        _voltage_couples,
        [Injected("regression", {"coefficient": 0.5})],
        channel="vdd",
        seed=303,
    ),
    Blind3(
        "2 kHz × 2·10⁶, 4th-order Butterworth at 400 Hz, quantised, 50 Hz mains and harmonics 2, 3, 5",
        _mains_2khz,
        [_periodic([50.0], _mains_rms())],
        allowed=("bandwidth",),
        seed=304,
    ),
    Blind3(
        "FOG-like 1 Hz × 10⁵, white 2·10⁻⁷ rad/s/√Hz, strong rate random walk, temperature through a 900 s lag",
        _fog_lag,
        [Injected("regression", {"coefficient": 6e-7, "lag_s": 900.0})],
        channel="temp",
        unit="rad/s",
        seed=305,
    ),
    Blind3(
        "random telegraph (popcorn) noise ±4·10⁻³ °/s switching at 0.05 /s, 50 Hz × 10⁶",
        _telegraph,
        [Injected("gauss_markov", {"sigma": RTN_H, "tc": 1.0 / (2 * RTN_LAMBDA)})],
        seed=306,
    ),
    Blind3(
        "float32 samples on a 250 °/s bias, 1 kHz × 10⁶, line 0.06 °/s at 13.3 Hz",
        _float32_line,
        [Injected("sinusoid", {"amplitude": 0.06, "f0": 13.3}, ("f0",))],
        seed=307,
    ),
    Blind3(
        "clock: 1 Hz phase × 2·10⁵ turned to frequency, white PM, white and flicker FM, 1.5·10⁻¹² cycle of 1100 s",
        _clock,
        [Injected("sinusoid", {"amplitude": 1.5e-12, "f0": 1.0 / 1100.0}, ("f0",))],
        unit=None,
        seed=308,
    ),
    Blind3(
        "three axes with a temperature, 200 Hz × 6·10⁵: axis 0 (does not follow it)",
        _three_axes(0),
        channel="temp",
        seed=309,
    ),
    Blind3(
        "three axes with a temperature, 200 Hz × 6·10⁵: axis 2 (4·10⁻⁴ °/s per °C)",
        _three_axes(2),
        [Injected("regression", {"coefficient": 4e-4})],
        channel="temp",
        seed=309,
    ),
    Blind3(
        "outside the family: bias steps +2.5, −4, +3 ·10⁻³ °/s at 0.2, 0.5, 0.8 T, 20 Hz × 6·10⁵",
        _bias_steps,
        outside=True,
        seed=310,
    ),
    Blind3(
        "outside the family: 6 s clipped at the 0.08 °/s full scale, 400 Hz × 10⁶",
        _clipped,
        outside=True,
        seed=311,
    ),
]


def _size(y, comp, fs: float, kw: dict) -> float | None:
    """``refine_blind2.effect_size`` on the refined axis (a three-axis record: the call's ``axis``)."""
    y = np.asarray(y, dtype=np.float64)
    return rb2.effect_size(y[:, kw.get("axis", 0)] if y.ndim == 2 else y, comp, fs)


def run_case(case) -> dict:
    y, fs, channels, kw, comp = case.build(np.random.default_rng(case.seed))
    size = _size(y, comp, fs, kw)
    return rb.refined(case, y, fs, channels, kw, rb2._judged) | {"size": size, "outside": case.outside}


#: What the table shows and why (kept true to the recorded run).
NOTES: list = [
    "**First run** (at 4001644, the suite as committed, before any change; load 81 % from other processes; its "
    'table and JSON are in commit e76b09a — its header\'s "+dirty" is the channel checks edited while it ran, '
    "after the process had imported the library): **9 of 12 passed**, without the candidate 9 of 9 flagged. A "
    "rerun at e76b09a (the channel checks of `channels=` tightened, no decision of refine's "
    "changed): every row's effects, parameters, errors and words the same (CPU column aside). The table "
    "above is the rerun after the Butterworth orders 2–6 joined the bandwidth family (at 21e7e2d): **10 of 12** — the 2 kHz row now "
    "passes; the float32 row's without-candidate entry found 3 regions (2 before); every other row the same. "
    "The six channel rows (`--case temp`) rerun at 2b6cb2a, a lag its test cannot resolve now profiled for the "
    "removal; the thermistor's coefficient −1.3 → −0.8 % (held out 2.35 → 2.33 %), every other channel row the "
    'same; the bias-steps row rerun alone (`--case steps`, at 4c0e450 with lint-only edits) once the `"steps"` '
    "check of `unexplained` joined; the other rows as recorded at 21e7e2d: **12 of 12** — the FOG row and the "
    "bias-steps row pass. The table above is the whole suite rerun once every branch of the session had merged "
    "(f97e098; its header's \"+dirty\" is the other suites' pages written before it): **12 of 12**, every row as "
    "the partial reruns recorded but the clipped row, which now also says the step of the mean at the rail.",
    "",
    "Passed as a user would want: the temperature read once a second, held and quantised to 1/16 °C "
    "(coefficient +0.5 %); the thermistor with 0.2 °C of its own white noise (−0.8 %: the Whittle regression "
    "weighs the frequencies where the channel's swing is, far above its noise); the supply voltage taken and "
    "the temperature not (−6.5 %); the float32 line on a 250 °/s bias; the clock's 1100 s cycle in frequency "
    "turned from phase (unit None, 10⁻¹² scale); the three axes (axis 0 takes nothing, axis 2 the temperature "
    "at +0.1 %). The popcorn noise is read as a Gauss–Markov term (σ −0.1 %, T_c −4.3 %): random telegraph "
    "noise's second-order statistics are exactly a Gauss–Markov term's, so that is the right Allan model — but "
    "nothing says the rate sits at two levels (no check looks at the distribution of a slow component). "
    "The 6 s clipped at the rail was at first said only by its consequences (a change point at 1184 s and the "
    "curve departing at τ 7.5–278 s); rerun alone at the `clipped` check's commit (r6clip), it is now named "
    'first, the rest of its row unchanged: "t 1200–1206 s: the record holds one value for 2400 samples in a row '
    'at 0.08 deg/s … clipped or stuck" (not "clipped at its largest value": the simulated noise elsewhere reaches'
    " beyond the 0.08 rail, so the run is said as a run of one value too long for the record's quantisation).",
    "",
    "Why three failed at the first run — all three since fixed:",
    "",
    "- *2 kHz, 4th-order Butterworth at 400 Hz, mains 50 Hz and harmonics* — at the first run the roll-off was "
    "not in the bandwidth family (single pole, moving average, Bartlett, boxcar, pole + boxcar, 2nd-order "
    "Butterworth): read as a single pole + boxcar with a 208 Hz resonance (Q 8) standing in for the knee, χ²/dof "
    "4.7·10⁴ → 515, `unexplained` τ 0.5 ms–0.26 s. **Fixed since**: Butterworth orders 2–6 "
    "(`butterworth2` … `butterworth6`, the autocorrelation from the poles): now `butterworth4` at 402.5 Hz "
    "(+0.6 %), χ²/dof → 4.23, nothing unexplained, the mains family as before — but a broad 704 Hz resonance "
    "(Q 2) stood in for the quantisation's white noise added after the filter (the bandwidth effect replaced "
    "the N column; the same record unquantised gave `butterworth4` at 399.8 Hz and no resonance). **Fixed "
    "since** (this row alone rerun, at the branch r6quant): beside a Butterworth the N column stays as white "
    "noise after the filter, the bandwidth's `floor` — `butterworth4` at 400.8 Hz (+0.2 %), floor 0.00102 "
    "°/s·√s (the step's Δ·√(τ0/12) = 0.00115: −12 %), no resonance, χ²/dof → 0.816, held-out 2.35 % "
    "(docs/refinement.md).",
    "- *FOG-like 1 Hz × 10⁵, temperature through a 900 s lag* — the regression is named (coefficient −5.5 %) "
    "and the lag is not carried by the record at its test's level (statistic 2.27 at ν 39.3 against 16.5, "
    "p 0.36, best at 389 s), χ²/dof 2.50 → 0.78; but the held-out error rises 2.13 → 2.76 %. The truth does "
    "not make it fall either: the injected coupling removed exactly and the five terms fitted, the held-out "
    "error is 2.32 % (refine's start protocol on the corrected samples) — with rate random walk dominating a "
    "1 Hz × 10⁵ record, its two held-out parts' curves differ by more than the coupling moves them; refine's "
    "0.44 points above the truth are the lag left in the residual. The step's own held-out test on the chain's "
    "samples read 2.13 → 15.0 % and was overridden by the across-frequency variance ratio (0.31 < 1), as for "
    "every slow-channel regression. **Fixed since** (the cause measured, not the judge retuned): the lag left in "
    "the residual — on this record the chain's held-out error with the removal at lag 0 is 2.76 %, at the true "
    "900 s 0.79 %, the true component removed without a refit 0.76 %. A lag its test does not keep is now "
    "profiled, and where the profile prefers it to none at the intervals' level (2Δℓ 2.14 over no lag) the "
    'removal takes the channel through it, reported as not resolved (`evidence["lag"]`): 498 s (153–910 s), '
    "coefficient −3.8 %, χ²/dof 2.50 → 0.76, held out 2.13 → 1.28 %. Over 34 lagged and unlagged records "
    "(`benches/results/refine_channel_lag.md`) the step's held-out error rose on 1 before, on none now.",
    "- *Bias steps +2.5, −4, +3·10⁻³ °/s at 0.2, 0.5, 0.8 T* (outside the family) — **said since** (r6steps): "
    'refine adds nothing (the curve fits, χ²/dof 0.64) and the `"steps"` check of `unexplained` says "the mean '
    "steps by 0.0025 deg/s at t ≈ 5972.1 s; by -0.0043 deg/s at t ≈ 14988.8 s; and by 0.0027 deg/s at t ≈ "
    '24005.5 s" (statistic 4.73 against 2.58; the three steps within 28 s, sizes within 10 %). Before, the '
    '`"mean"` check tested one split against a null from the model refitted without the located step; the other '
    "two steps stayed in that record, its K refitted at 2.7·10⁻⁵ (true 10⁻⁶) and the threshold was 5.1·10⁻³ "
    "against a statistic of 1.05·10⁻³ (one split's two sides mix steps of opposite signs); a null refitted "
    "without several located steps (an experiment) rejected 1.0 % of clean records at its α, removing steps that "
    'are not there lowering K. The `"steps"` check does not hang on K: the block means\' largest increment over '
    "their own robust scale (T/32, T/64, T/128; steps are a few outlying increments, flicker's and a random "
    "walk's are Gaussian), its null simulated under the final model with its slow terms at the upper end, "
    "steps located step-down. Six more records of this configuration: said in 6 of 6 (1.3–1.7× the threshold), "
    "the −4·10⁻³ step located in all, the others in 1–3 (each alone is 5–8 of the increments' SDs, the "
    "threshold ≈ 6.6). On 300 clean records (`benches/results/refine_mean_step_null.md`, gate off): 0 at its α, "
    "2.0 % at 1 %, 5.7 % at 5 %.",
    "**Rerun at 44eba23** (every branch of the 2026-11-27 afternoon merged: the sinc^k kind chain, the family fold, the mean check's per-term nulls, the coupling test's bootstrap where its dof is small, the cost round, the module splits): the table above, **12 of 12**, without the candidate **9 of 9** — every row's effects, parameters and words as at bfcb29f (only the CPU column moved).",
    '**The 1/16 °C row rerun with the channel read back** (r9chan, `--case "quantised to 1/16"`; its row above replaced, the other rows as at 44eba23): the channel is read as quantised at 0.0625 (a slow staircase) and held for 1 s (`evidence["channel_form"]`, docs/channels.md "Quantised and held channels") — coefficient 6.027 → 6.031·10⁻⁴ (+0.5 %), RMS ADEV 1.68 → 1.36 → now 1.35 %, held out 5.29 → 2.27 % as before, nothing unexplained; ✓ as before.',
    "**Rerun whole at ba83de7** (every branch of the 2026-11-27 evening merged but r11lagrate, whose rule runs only where a d(ch)/dt term passes; this suite's channel rows keep none): the table above, **12 of 12** — every row's verdict and effects as before; the clock's final χ²/dof 9.06 → 1.6 (its sinusoid as before), the clipped record's change point at 1198 s (1184 before).",
    "**Rerun whole at a593464** (every branch of the 2026-11-27 night merged: r12adis, r12chanres, r12burst, r12lag, r12blind10, r12wline, r12ci, r12lineamp; CI, other suites and the ADIS16405 run shared the 2 cores, so the CPU column is not a cost measurement): **12 of 12**, every row's verdict, effects, parameters and words as recorded but one number: the 6 s clipped stretch's level entry reads 1.12× over t 1199–1206 s (was 1.11× over 1198–1206 s; change points located beside their bound).",
    "**Rerun whole at 55d58e5** (every branch of the 2026-11-28 night merged: r13heldout, r13gain, r13swing, r13rate, r13cover, r13cost, r13slowline; the other suites, the ADIS16405 run and CI shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict, effects, parameters and words as recorded.",
    "Rerun whole at 9eaf694 (the 2026-11-28 morning's branches merged: r14house, r14blind11, r14modline, r14pump, r14cost, r14lagrate, r14fir; r14reson merged and reverted; another suite chain, the ADIS16405 run and CI shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict, effects, parameters and χ²/dof as recorded — 12 of 12.",
    "**Rerun whole at 44c3f2f** (the 2026-11-28 late-morning branches merged: r16heldout — the chain's deviance and AIC, keys only —, r16family, r16reson, r16burst; other suites and the false-alarm bench shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict, effects, parameters and words as recorded — 12 of 12 (the popcorn row still a Gauss–Markov term, as recorded; r16burst measured its telegraph declined, the levels 3.07 σ apart).",
    "Rerun whole on 2026-11-28 at 45caf74 (the r17 merges: the alternative chains unified and memoised, the declared filter, the follows check, the channel check's first quadratic, the level test's runs of blocks, the slow-line test's second reading; r17cost2's cheaper arithmetic, equal to 1e-9, was merged after) with 044680b's why_not_kept fix: every row's verdict, effects and unexplained domains as recorded, and every without-candidate flag.",
    "",
    "Rerun whole on 2026-11-28 at da6740f (the r18 merges: r18cost's and r18boot's cheaper arithmetic, the sigma-delta's shaped quantisation (r18sdm), a quantised output's floor (r18bartlett), sharp rippled filter kinds (r18sharp), line families whose fundamental hunts (r18hunt); other suites, CI and the false-alarm bench shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict and effects as recorded — 12 of 12.",
]


def main(argv=None) -> None:
    rb2.suite_main(argv, __doc__, CASES, run_case, _size, NOTES, "refine_blind3", "third")


if __name__ == "__main__":
    main()
