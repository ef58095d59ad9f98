#!/usr/bin/env python3
"""``allanite.refine`` on a fifth blind suite of simulated sensors, unlike ``tests/sensors.py``, the four earlier
blind suites (``benches/refine_blind.py`` … ``refine_blind4.py``) and the ADIS16405 — what a user brings with
default arguments.

**Written and committed before it was first run.** The effects' sizes were fixed beforehand by their Allan
deviation alone (``--sizes``: the largest ratio over τ ≤ T/4 of the injected component's Allan deviation to that of
the rest of the record, ≥ 3× for every curve effect a case asks refine to find; with two effects, the smaller of
the two; a filter by the unfiltered record's Allan deviation over the record's; impulsive noise by its count),
never by refine's answer; the first run's verdicts are recorded as they came out (the notes below the table) and
the cases are not retuned after it.

The cases: float32 samples of a quiet accelerometer sitting on 1 g (9.81 m/s², ``unit=None``), whose white noise
per sample is a third of float32's own step there (2⁻²⁰ ≈ 9.5·10⁻⁷): a hidden quantisation, nothing to add; a
72 h log at 1 Hz with two channels — a diurnal temperature that does not couple and a battery's voltage
(discharging, load switched on and off, a little temperature in it) that does; a 2 kHz tactical FOG × 10⁷ whose
bias follows the temperature through a 600 s lag; white noise whose level grows smoothly 5× along the record
(outside refine's family); a sample-rate beat at 2 kHz (a 137 Hz tone read by a sensor that repeats a sample every
1.25 s); 50 sparse spikes in a short 1 Hz record (10⁵ samples); Student-t (3 dof) white noise at 1 kHz; a
Gauss–Markov-dominated MEMS (T_c 30 s) with a 0.3 Hz line beside it; an AM carrier at 0.4·fs whose upper sideband
folds about fs/2; a gyro whose temperature coupling has a level and a d(T)/dt term (a lead no lag can give) on a
cycling profile; 2·10⁴ samples at 10 Hz with a line; and a clean 2 kHz × 10⁷ record behind a 4th-order
Butterworth at 500 Hz (only the roll-off to find).

Truths are in the unit refine reports: the samples' own (°/s for the gyros, rad/s where the case says so, m/s²
under ``unit=None``). A heavy tail has no true share of outliers but at a cut: its ``rate`` is the share the
Student-t noise puts beyond the threshold the step reports, by the step's rule (:func:`student_flag_rate`).

Judged as ``benches/refine_blind4.py`` judges (``refine_blind2._judged``: named, parameters within 20 %,
frequencies within 1 %, the chain's error falling in sample and held out, ``unexplained`` empty; a clean case:
nothing added but what it allows, nothing unexplained; an effect outside the family: something left unexplained;
a named channel: no regression on another; a filter's kind where the case names it).

Usage::

    python benches/refine_blind5.py                # -> benches/results/refine_blind5.{json,md}
    python benches/refine_blind5.py --case spikes  # the cases whose name contains "spikes", to a temporary folder
    python benches/refine_blind5.py --sizes        # each case's effect size only (no refine)
"""

from __future__ import annotations

import math

import numpy as np
from scipy import signal
from scipy.stats import t as student_t

import allanite
import refine_blind as rb
import refine_blind2 as rb2
import refine_blind4 as rb4

sensors = rb.sensors
Injected = sensors.Injected
Blind5 = rb2.Blind2
_periodic = rb2._periodic


def _float32_accelerometer(rng):
    fs, n = 10.0, 1_000_000  # 10⁵ s
    y = rb.noise(n, fs, rng, N=1e-7, B=3e-7, K=5e-9) + 9.81  # m/s²: σ per sample 3.2·10⁻⁷ ≈ a third of a step
    return y.astype(np.float32), fs, {}, {}, None


#: the battery's coupling (rad/s per V)
VDD_COUPLING = 9e-5


def _battery(rng):
    fs, n = 1.0, 259_200  # 72 h
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2e-5, B=2e-6, K=2e-8)
    wander = sensors.first_order_lag(np.cumsum(rng.standard_normal(n)), fs, 3600.0)
    temp = 20.0 + 5.0 * np.sin(2 * np.pi * t / 86_400.0 - 1.2) + 1.0 * (wander - wander.mean()) / np.ptp(wander)
    switches = np.sort(rng.choice(n, 24, replace=False))  # a load switched on and off 12 times
    load = np.zeros(n)
    for on, off in zip(switches[::2], switches[1::2], strict=True):
        load[on:off] = 1.0
    vdd = 12.6 - 0.6 * t / t[-1] - 0.15 * load + 0.004 * (temp - temp.mean())
    comp = VDD_COUPLING * (vdd - vdd.mean())
    channels = {"temp": temp + 0.02 * rng.standard_normal(n), "vdd": vdd + 2e-3 * rng.standard_normal(n)}
    return y + comp, fs, channels, {}, comp


#: the FOG's temperature coupling (°/s per °C) and its lag (s)
FOG_COUPLING, FOG_LAG = 2e-4, 600.0


def _fog_lag(rng):
    fs, n = 2000.0, 10_000_000  # 5000 s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=8e-4, B=1.4e-4, K=2e-6)
    temp = sensors.temperature_profile(t, "cycle", rng, lo=20.0, hi=45.0)
    sensor = sensors.first_order_lag(temp, fs, FOG_LAG)
    comp = FOG_COUPLING * (sensor - sensor.mean())
    logged = temp + 0.01 * rng.standard_normal(n)
    return y + comp, fs, {"temp": logged}, {}, comp


def _growing_noise(rng):
    fs, n = 200.0, 1_000_000  # 5000 s
    y = rb.noise(n, fs, rng, B=4e-4, K=1e-5)
    grow = 5.0 ** (np.arange(n) / (n - 1))  # smoothly 1× → 5×
    white = 1.5e-3 * math.sqrt(fs) * rng.standard_normal(n) * grow
    return y + white, fs, {}, {}, None


#: sample-rate beat: tone (Hz, °/s), one sample repeated every 1/BEAT_F2 s
BEAT_F1, BEAT_AMP, BEAT_F2 = 137.0, 0.2, 0.8


def _beat(rng):
    fs, n = 2000.0, 2_000_000  # 1000 s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2e-3, B=5e-4, K=1e-5)
    comp = sensors._sample_rate_beat(t, BEAT_AMP, BEAT_F1, BEAT_F2, fs, "repeat")
    return y + comp, fs, {}, {}, comp


SPIKES = 50


def _sparse_spikes(rng):
    fs, n = 1.0, 100_000
    y = rb.noise(n, fs, rng, B=2e-4, K=1e-6)
    sigma = 3e-3
    white = sigma * rng.standard_normal(n)
    comp = np.zeros(n)
    hit = rng.choice(np.arange(10, n - 10), SPIKES, replace=False)
    comp[hit] = sigma * 6.0 * (1.0 + rng.random(SPIKES)) * rng.choice([-1.0, 1.0], SPIKES)  # 6–12 σ
    return y + white + comp, fs, {}, {}, comp


#: Student-t white noise: degrees of freedom, its scale (°/s per sample) at 1 kHz
T_DOF, T_SCALE = 3, 0.05


def _student(rng):
    fs, n = 1000.0, 1_000_000
    y = rb.noise(n, fs, rng, B=2e-4, K=2e-6)
    return y + T_SCALE * rng.standard_t(T_DOF, n), fs, {}, {}, None


def student_flag_rate(threshold: float, scale: float = T_SCALE, dof: int = T_DOF, rule: str = "level") -> float:
    """The share of Student-t white samples (``dof``, ``scale``) that ``outliers.outlier_test`` flags at
    ``threshold`` by its ``rule`` (as ``sensors.mixture_flag_rate`` for a Gaussian mixture): ``"level"``, beyond
    the threshold from the slow level, 2·S(thr/scale); ``"neighbours"``, off both neighbours by more than it on
    opposite sides, ∫ f(x) [F(x − thr)² + (1 − F(x + thr))²] dx. Other noise terms negligible at the shortest lag."""
    if rule == "level":
        return float(2 * student_t.sf(threshold / scale, dof))
    x = np.linspace(-400 * scale, 400 * scale, 800_001)
    f = student_t.pdf(x / scale, dof) / scale
    p = f * (student_t.cdf((x - threshold) / scale, dof) ** 2 + student_t.sf((x + threshold) / scale, dof) ** 2)
    return float(np.sum(p) * (x[1] - x[0]))


def _student_truth(params: dict, steps: list) -> dict:
    thr = params.get("threshold")
    rule = next((st.evidence.get("rule") for st in steps if "rule" in st.evidence), "neighbours")
    return {} if thr is None else {"rate": student_flag_rate(thr, rule=rule)}


#: Gauss–Markov (°/s, s) and the line beside it (°/s, Hz)
GM_SIGMA, GM_TC, GM_LINE, GM_F0 = 4e-3, 30.0, 4.2e-3, 0.3


def _gm_line(rng):
    fs, n = 100.0, 1_000_000  # 10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=1e-3, B=1e-4, K=1e-6)
    gm = allanite.simulate(n, fs, gauss_markov=[(GM_SIGMA, GM_TC)], seed=rng)
    line = GM_LINE * np.sin(2 * np.pi * GM_F0 * t + 0.6)
    return y + gm + line, fs, {}, {}, [gm, line]


#: AM carrier at 0.4·fs: (carrier Hz, modulation Hz, depth, amplitude °/s) at 100 Hz; 51 Hz folds to 49 Hz
AM_F1, AM_F2, AM_DEPTH, AM_AMP = 40.0, 11.0, 0.5, 0.035


def _am_folded(rng):
    fs, n = 100.0, 1_000_000
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=1e-3, B=3e-4, K=5e-6)
    comp = AM_AMP * (1.0 + AM_DEPTH * np.cos(2 * np.pi * AM_F2 * t)) * np.sin(2 * np.pi * AM_F1 * t + 0.4)
    return y + comp, fs, {}, {}, comp


def _am_rms() -> float:
    return AM_AMP * math.sqrt(0.5 * (1.0 + 0.5 * AM_DEPTH**2))


#: temperature coupling: level (°/s per °C) and a lead on dT/dt (°/s per °C/s)
LEAD_C, LEAD_R = 2e-4, 0.1


def _level_and_rate(rng):
    fs, n = 50.0, 1_000_000  # 2·10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=5e-4, K=1e-5)
    temp = sensors.temperature_profile(t, "cycle", rng, lo=10.0, hi=40.0)
    comp = LEAD_C * (temp - temp.mean()) + LEAD_R * np.gradient(temp, 1.0 / fs)
    logged = temp + 0.01 * rng.standard_normal(n)
    return y + comp, fs, {"temp": logged}, {}, comp


def _short_line(rng):
    fs, n = 10.0, 20_000  # 2000 s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=5e-3, B=1e-3, K=2e-5)
    comp = 0.026 * np.sin(2 * np.pi * 0.45 * t + 2.4)
    return y + comp, fs, {}, {}, comp


def _butterworth_clean(rng):
    fs, n = 2000.0, 10_000_000  # 5000 s
    y = rb.noise(n, fs, rng, N=2e-3, B=3e-4, K=5e-6)
    out = signal.sosfilt(signal.butter(4, 500.0, fs=fs, output="sos"), y)
    return out, fs, {}, {}, {"without": y}


CASES = [
    Blind5(
        "float32 accelerometer on 1 g (9.81 m/s², unit None), σ a third of float32's step there, 10 Hz × 10⁶ (clean)",
        _float32_accelerometer,
        unit=None,
        seed=501,
    ),
    Blind5(
        "72 h at 1 Hz, diurnal temperature (no coupling) and a discharging battery with load steps (9·10⁻⁵ rad/s per V)",
        _battery,
        [Injected("regression", {"coefficient": VDD_COUPLING})],
        channel="vdd",
        unit="rad/s",
        seed=502,
    ),
    Blind5(
        "2 kHz tactical FOG × 10⁷, bias follows the temperature (2·10⁻⁴ °/s per °C) through a 600 s lag",
        _fog_lag,
        [Injected("regression", {"coefficient": FOG_COUPLING, "lag_s": FOG_LAG})],
        channel="temp",
        seed=503,
    ),
    Blind5(
        "outside the family: white noise growing smoothly 5× along the record, 200 Hz × 10⁶",
        _growing_noise,
        outside=True,
        seed=504,
    ),
    Blind5(
        "sample-rate beat at 2 kHz: 137 Hz tone of 0.2 °/s, a sample repeated every 1.25 s, 2 kHz × 2·10⁶",
        _beat,
        [_periodic([BEAT_F1, BEAT_F2], BEAT_AMP / math.sqrt(2.0))],
        seed=505,
    ),
    Blind5(
        "50 sparse spikes (6–12 σ) in a short 1 Hz record of 10⁵ samples",
        _sparse_spikes,
        [Injected("outliers", {"rate": SPIKES / 100_000})],
        seed=506,
    ),
    Blind5(
        "Student-t white noise (3 dof), 1 kHz × 10⁶",
        _student,
        [Injected("outliers", {"rate": None}, truth_at=_student_truth)],
        seed=507,
    ),
    Blind5(
        "Gauss–Markov-dominated MEMS (4·10⁻³ °/s, T_c 30 s) with a 4.2·10⁻³ °/s line at 0.3 Hz, 100 Hz × 10⁶",
        _gm_line,
        [
            Injected("gauss_markov", {"sigma": GM_SIGMA, "tc": GM_TC}),
            Injected("sinusoid", {"amplitude": GM_LINE, "f0": GM_F0}, ("f0",)),
        ],
        seed=508,
    ),
    Blind5(
        "AM carrier 40 Hz × 11 Hz at 100 Hz: the upper sideband (51 Hz) folds to 49 Hz, 100 Hz × 10⁶",
        _am_folded,
        [
            Injected(
                "periodic",
                {"line_frequencies": [AM_F1 - AM_F2, AM_F1, 100.0 - (AM_F1 + AM_F2)], "rms": _am_rms()},
                ("line_frequencies",),
            )
        ],
        seed=509,
    ),
    Blind5(
        "temperature cycling 10–40 °C, gyro on T (2·10⁻⁴ °/s per °C) and dT/dt (0.1 °/s per °C/s, a lead), 50 Hz × 10⁶",
        _level_and_rate,
        [Injected("regression", {"coefficient": LEAD_C, "rate_coefficient": LEAD_R})],
        channel="temp",
        seed=510,
    ),
    Blind5(
        "short record: 2·10⁴ samples at 10 Hz, a 0.026 °/s line at 0.45 Hz",
        _short_line,
        [Injected("sinusoid", {"amplitude": 0.026, "f0": 0.45}, ("f0",))],
        seed=511,
    ),
    Blind5(
        "2 kHz × 10⁷ behind a 4th-order Butterworth at 500 Hz, nothing else (only the roll-off to find)",
        _butterworth_clean,
        [Injected("bandwidth", {"cutoff": 500.0})],
        filter="butterworth4",
        forbidden=("resonance",),
        seed=512,
    ),
]


def run_case(case) -> dict:
    y, fs, channels, kw, comp = case.build(np.random.default_rng(case.seed))
    size = rb4._size(y, comp, fs, kw)
    return rb.refined(case, y, fs, channels, kw, rb4._judged) | {"size": size, "outside": case.outside}


#: What the table shows and why (kept true to the recorded run).
NOTES: list = [
    "**First run** (at f4205e4, the suite as committed, before any change; load 84 % from other processes; the table above, its JSON beside it, commit c65c26e): **11 of 12 passed**, without the candidate 9 of 10 flagged. Passed as a user would want: float32 samples on 1 g whose white noise is a third of float32's step there (nothing added, nothing said; start χ²/dof 0.37, the float64 copy's 0.42: nothing float32's own); the 72 h battery taken and the diurnal temperature not (−4.6 %); the noise growing 5× said (change points at 1036 and 2228 s and the level check, 1.57× at τ₀ over t 3618–5000 s); the 2 kHz sample-rate beat as one family (fundamentals 136.945 and 0.8 Hz — the carrier read at f1·(1 − f2/fs), as the repeated samples shift it — 29 lines, rms −0.1 %); the 50 spikes at 1 Hz (rate −18 %: 41 flagged at a cut of 6.4 σ, the spikes 6–12 σ); the Student-t tails (rate −1.7 % against the share beyond the reported cut); the Gauss–Markov term and the 0.3 Hz line beside it (each within 0.4 %); the AM carrier at 0.4·fs with its folded sideband (29, 40 and 49 Hz as one family, rms −0.0 %); the level and dT/dt lead (−4.1 %, −9.3 %; no lag in its place); the line in 2·10⁴ samples (−0.2 %); the Butterworth4 × 10⁷ (499.7 Hz, the kind right, a white floor of 2.8·10⁻⁵ beside it, nothing else).",
    "",
    "Why one failed, and what is still not said:",
    "",
    "- *2 kHz FOG × 10⁷, temperature through a 600 s lag* — the regression named and the lag kept (statistic 28.4 against 17.0) at 420 s (interval 298–628 s), coefficient −18.3 %. Cause measured: the lag's grid profile multiplies the channel's band sums by the lag's response (the lag applied circularly) where the coupling runs through the lag in time from equilibrium, and over a record a few lags long that reads T short — 8 records at 10 Hz × 5·10⁴ with this noise and profile (coefficient 10⁻³): median 473 s, coefficient −16 %; started in steady state 545 s, −4 %. **Changed since** (468cff5, 088d4b8): the lag that is used is refined on the channel lagged in time (docs/channels.md): those records 590 and 602 s, coefficients 0 and +1 %. This row rerun at 088d4b8: lag 475 s (interval 338–711 s; the grid's 420 s), coefficient −10.9 %, χ²/dof 1.9 → 1.02, RMS 0.91 → 1.03 %, held out 5.06 → 1.24 % (1.13 % before) — **still ✗**, the lag 0.8 points outside the judge's 20 % with the truth inside its interval. Not retuned.",
    "- *Without the regression candidate* the same FOG leaves nothing unexplained: its coupling (5.8× the noise's Allan deviation at the cycle's τ) is absorbed by the five terms (start χ²/dof 1.9, no check beyond its threshold). Related, measured and left: the coupling's first test looks for the channel at lag 0 only and the lag is tried once it accepts; at a 600 s lag on a 1667 s cycle (66° of phase) cos 66° = 0.4 of the coupling is in phase with the channel, and the same coupling at 10 Hz × 5·10⁴ (size 11×) is accepted in 0 of 12 records (statistic 6.3 against 12.6 on the first). A test over the lag family (T = 0 included, the upcrossing bound) would move every channel record's threshold — not tried in this session. **Changed since** (branch r7lagtest): the first test takes the channel and its quadrature jointly (2·F(2, ν) at the same α; docs/channels.md, \"The coupling's test sees every phase\") — 12 of 12 of those records accepted (median 45.1 against 18.1; the channel alone 6.8 against 12.6), false alarms 9 of 4000 null records at α = 0.375 % (the channel alone 15) (`benches/results/channel_lag_first_test.md`); this row not rerun (2 kHz × 10⁷).",
    "",
    "Rerun after the change (`--case`, at 088d4b8; every verdict as recorded): blind5's battery and lead rows the same; `refine_sensors.py --case temperature`: issue 29's log coefficient +0.3 → +0.2 %, χ²/dof 1.65 → 1.67, held out 1.01 → 1.02 %; the 300 s lag +1.5 → +1.9 %, χ²/dof 1.09 → 1.07, held out 1.05 → 1.06 %; the other four the same; blind3's channel rows: the thermistor −0.8 → −0.9 % (held out 2.33 → 2.34 %), the 900 s FOG −3.8 → −3.7 % (held out 1.28 → 1.19 %), the other four the same; blind2's MEMS −3.1 → −3.0 % (held out 2.65 → 2.63 %), the chamber the same; blind4's 24 h log −1.7 → −1.2 % (held out 0.696 → 0.702 %), the vibration and the cold start the same; blind1's 48 h row the same (nothing accepted).",
    "",
    "**The table above** is the whole suite rerun at bfcb29f (every branch of the 2026-11-27 forenoon merged: the lag refined in time, the coupling's test of any phase, the sinc^k kinds, the floor beside single poles, a warm-up held out in time, the chunked nulls; `unexplained`'s channel check the pair and the in-phase test, each at half its share): **11 of 12**, without the candidate **10 of 10** — the FOG's coupling, absorbed by the five terms unsaid without its candidate at the first run, is said since the coupling's test sees every phase. The FOG still fails on its lag (475 s for 600 s, −20.8 %; coefficient −10.9 %); every other row as at the first run.",
    "**Rerun at 44eba23** (every branch of the 2026-11-27 afternoon merged: the sinc^k kind chain, the family fold, the mean check's per-term nulls, the coupling test's bootstrap where its dof is small, the cost round, the module splits): the table above, **11 of 12**, without the candidate **10 of 10** — every row's effects, parameters and words as at bfcb29f (only the CPU column moved); the FOG still fails on its lag (−20.8 %).",
    "**The growing noise row above** is `--case growing` rerun at 34a55b6 (r10pump: several change points, the level check between them judged per segment; other rows as at 44eba23): three change points (522, 2026, 3350 s; two, 1036 and 2228 s, before) cut the smooth 5× growth into a staircase, and `unexplained` says the growth left within three of the segments (1.24–1.30× the Allan deviation at τ₀, 12–13 % off the segment's level) against the held-out error per segment with the change points, 5.7 % (the record's curve held out, 19.6 %, is the same with and without them and hid it: at c4dd92e, before the per-segment yardstick, four change points and nothing said); still ✓ — something is said.",
    "**Rerun whole at ba83de7** (every branch of the 2026-11-27 evening merged but r11lagrate; its rule reran on the cycling T and dT/dt row unchanged): the table above, **11 of 12** — every row's verdict and effects as before; the Student-t outliers' rate −1.7 → −1.1 %. The FOG's lag still fails (−20.8 %; the lag's own estimate, not the lag-or-rate choice).",
    "**r12lag** (`--case \"600 s lag\"` rerun after the change; the row as recorded, not replaced): exactly as in the table (lag 475.2 s, −20.8 %; coefficient −10.9 %; ✗). On 40 seeded replicas of this row (10 Hz × 5·10⁴, the same noise, profile and coupling; on this row's own record the replica reads 476.6 s) the lag is unbiased — median −1.1 % (95 % CI −7.4 … +8.4 %), sd 13 % — so −20.8 % is a 1.6σ draw and the judge's 20 % is below what one record carries (`benches/results/channel_lag_bias.md`). What the seeds showed wrong were the intervals: the coefficient's left out the lag's error (12 of 40 covered), the lag's was ±54 % wide; now the coefficient's is marginalised over the lag and the lag's is its profile in time at the refitted noise (21 of 40 and 19 of 33 covered, ±10 % and ±12 %; docs/channels.md, \"The lag's and the coefficient's intervals\"). This row's: lag 416–532 s (was 338–711 s), coefficient 1.60–1.97·10⁻⁴ (was 1.69–1.88·10⁻⁴).",
    "**Rerun whole at a593464** (every branch of the 2026-11-27 night merged: r12adis, r12chanres, r12burst, r12lag, r12blind10, r12wline, r12ci, r12lineamp; CI, other suites and the ADIS16405 run shared the 2 cores, so the CPU column is not a cost measurement): **11 of 12**, every row's verdict and effects as recorded; one row's words moved: the white noise growing 5× (outside the family, ✓) is now said at t 3171–4120 s (1.34× at τ₀) where it was t 522–1250 s (1.27×) — r12adis's change points located beside their bound. The FOG lag still fails (−20.8 %): r12lag measured it is a 1.6σ draw of an unbiased estimate (`benches/results/channel_lag_bias.md`; its interval now 416–532 s).",
    "**Rerun whole at 55d58e5** (every branch of the 2026-11-28 night merged: r13heldout, r13gain, r13swing, r13rate, r13cover, r13cost, r13slowline; the other suites, the ADIS16405 run and CI shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict, effects, parameters and words as recorded.",
    "Rerun whole at 9eaf694 (the 2026-11-28 morning's branches merged: r14house, r14blind11, r14modline, r14pump, r14cost, r14lagrate, r14fir; r14reson merged and reverted; another suite chain, the ADIS16405 run and CI shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict, effects, parameters and χ²/dof as recorded — 11 of 12.",
    "**Rerun whole at 44c3f2f** (the 2026-11-28 late-morning branches merged: r16heldout — the chain's deviance and AIC, keys only —, r16family, r16reson, r16burst; other suites and the false-alarm bench shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict, effects, parameters and words as recorded — 11 of 12.",
    "Rerun whole on 2026-11-28 at 45caf74 (the r17 merges: the alternative chains unified and memoised, the declared filter, the follows check, the channel check's first quadratic, the level test's runs of blocks, the slow-line test's second reading; r17cost2's cheaper arithmetic, equal to 1e-9, was merged after) with 044680b's why_not_kept fix: every row's verdict, effects and unexplained domains as recorded, and every without-candidate flag.",
    "",
    "Rerun whole on 2026-11-28 at da6740f (the r18 merges: r18cost's and r18boot's cheaper arithmetic, the sigma-delta's shaped quantisation (r18sdm), a quantised output's floor (r18bartlett), sharp rippled filter kinds (r18sharp), line families whose fundamental hunts (r18hunt); other suites, CI and the false-alarm bench shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict and effects as recorded — 11 of 12.",
]


def main(argv=None) -> None:
    rb2.suite_main(argv, __doc__, CASES, run_case, rb4._size, NOTES, "refine_blind5", "fifth")


if __name__ == "__main__":
    main()
