#!/usr/bin/env python3
"""``allanite.refine`` on a fourth blind suite of simulated sensors, unlike ``tests/sensors.py``, the three earlier
blind suites (``benches/refine_blind.py``, ``refine_blind2.py``, ``refine_blind3.py``) and the ADIS16405 — what a
user brings with default arguments.

**Written and committed before it was first run.** The effects' sizes were fixed beforehand by their Allan
deviation alone (``--sizes``: the largest ratio over τ ≤ T/4 of the injected component's Allan deviation to that of
the rest of the record, ≥ 3× for every effect a case asks refine to find; with two effects, the smaller of the
two; a filter, which lowers the curve, by the unfiltered record's Allan deviation over the record's — the sinc³
decimator's own 1.73×, where a 2-tap moving average's is 2×), never by refine's answer; the first run's verdicts
are recorded as they came out (the notes below the table) and the cases are not retuned after it.

The cases: a gyro's g-sensitivity to an accelerometer channel under 20–80 Hz vibration (a fast channel, 400 Hz);
a MEMS behind a sinc³ (CIC) decimation filter, 3200 Hz → 200 Hz (not a moving average); a 400 Hz automotive gyro
started cold, its bias quadratic in the temperature; a 24 h log at 10 Hz with a diurnal temperature and an
air-conditioning cycle of 900 s; a ring-laser gyro read out by pulse counting (angle quantised) with its 612 Hz
dither residual aliased to 388 Hz at 1 kHz; a flicker-dominated gyro at 20 Hz × 2·10⁶ with nothing else (a hard
clean case); a heater switched on for a stretch (the white noise 1.8× from 0.3 T to 0.55 T: two change points); a
10⁷-sample 1 kHz record with a 0.01 Hz line; a magnetometer (µT, ``unit=None``) with 50 Hz mains and its odd
harmonics; a warm-up of a sixth of the detectable size (a clean case in disguise: nothing may be added); an
accelerometer (m/s², ``unit=None``) with a warm-up and a line.

``unit=None`` for the accelerometer and the magnetometer: refine's units are rate and angle units (gyros'); an
accelerometer's or a magnetometer's unit string is refused with the list of allowed units, and the terms are then
reported in the samples' own unit and seconds.

Judged as ``benches/refine_blind3.py`` judges (``refine_blind2._judged``), a heater's two change points each within
20 % of their true time (``sensors.judge`` keeps one ``t`` per effect).

Usage::

    python benches/refine_blind4.py                 # -> benches/results/refine_blind4.{json,md}
    python benches/refine_blind4.py --case heater   # the cases whose name contains "heater", to a temporary folder
    python benches/refine_blind4.py --sizes         # each case's effect size only (no refine)
"""

from __future__ import annotations

import math

import numpy as np
from scipy import optimize, signal

import allanite
import refine_blind as rb
import refine_blind2 as rb2

sensors = rb.sensors
Injected = sensors.Injected
Blind4 = rb2.Blind2


def _band_noise(n, fs, rng, lo, hi, rms) -> np.ndarray:
    sos = signal.butter(4, [lo, hi], btype="bandpass", fs=fs, output="sos")
    v = signal.sosfilt(sos, rng.standard_normal(n))
    return rms * v / np.std(v)


#: g-sensitivity (°/s per g) and the vibration's rms (g)
G_SENS, VIB_RMS = 0.08, 2.0


def _vibration(rng):
    fs, n = 400.0, 1_000_000  # 2500 s
    y = rb.noise(n, fs, rng, N=4e-3, B=8e-4, K=2e-5)
    acc = _band_noise(n, fs, rng, 20.0, 80.0, VIB_RMS)
    comp = G_SENS * acc
    logged = acc + 3e-3 * rng.standard_normal(n)  # the accelerometer's own noise (g)
    return y + comp, fs, {"acc": logged}, {}, comp


#: sinc³ (CIC) decimation: internal rate, decimation factor
CIC_FS, CIC_R = 3200.0, 16


def _cic_cutoff() -> float:
    """The −3 dB frequency (Hz) of the cascade of three boxcars of CIC_R taps at CIC_FS."""

    def gain(f):
        x = math.pi * f / CIC_FS
        return (math.sin(CIC_R * x) / (CIC_R * math.sin(x))) ** 3 - 1 / math.sqrt(2)

    return float(optimize.brentq(gain, 1e-6, CIC_FS / (2 * CIC_R)))


def _cic(rng):
    fs, n = CIC_FS / CIC_R, 500_000  # 200 Hz × 2500 s
    N = 3e-3
    white = N * math.sqrt(CIC_FS) * rng.standard_normal(n * CIC_R + 3 * CIC_R)
    box = np.ones(CIC_R) / CIC_R
    kernel = np.convolve(np.convolve(box, box), box)
    filtered = signal.oaconvolve(white, kernel, mode="valid")[::CIC_R][:n]
    slow = rb.noise(n, fs, rng, B=6e-4, K=1e-5)
    unfiltered = white[len(kernel) - 1 :: CIC_R][:n] * math.sqrt(1.0 / CIC_R)  # white of density N at 200 Hz
    return filtered + slow, fs, {}, {}, {"without": unfiltered + slow}


def _cold_start(rng):
    fs, n = 400.0, 1_000_000  # 2500 s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=4e-3, B=8e-4, K=2e-5)
    temp = sensors.temperature_profile(t, "swing", rng, lo=-10.0, hi=40.0)
    d = temp - temp.mean()
    comp = 2.5e-4 * d + 5e-5 * (d * d - np.mean(d * d))
    logged = temp + 0.05 * rng.standard_normal(n)
    return y + comp, fs, {"temp": logged}, {}, comp


HVAC_S = 900.0


def _day(rng):
    fs, n = 10.0, 864_000  # 24 h
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-5, B=4e-6, K=1e-7)
    wander = sensors.first_order_lag(np.cumsum(rng.standard_normal(n)), fs, 600.0)
    temp = 21.0 + 4.0 * np.sin(2 * np.pi * t / 86_400.0 - 2.0) + 0.6 * (wander - wander.mean()) / np.ptp(wander)
    coupling = 2e-5 * (temp - temp.mean())
    line = 1.8e-5 * np.sin(2 * np.pi * t / HVAC_S + 0.3)
    logged = temp + 0.02 * rng.standard_normal(n)
    return y + coupling + line, fs, {"temp": logged}, {}, [coupling, line]


#: ring-laser gyro: dither residual (Hz, rad/s), readout rate, pulse weight (rad)
RLG_DITHER, RLG_AMP, RLG_FS, RLG_PULSE = 612.0, 3.75e-4, 1000.0, 1e-7


def _rlg(rng):
    fs, n = RLG_FS, 2_000_000  # 2000 s
    t = np.arange(n) / fs
    rate = rb.noise(n, fs, rng, N=3e-6, B=2e-7, K=2e-9)
    comp = RLG_AMP * np.sin(2 * np.pi * RLG_DITHER * t + 0.7)  # seen at |612 − 1000| = 388 Hz
    angle = np.cumsum(rate + comp) / fs
    counts = np.diff(np.floor(angle / RLG_PULSE), prepend=0.0)  # pulses counted in each sample
    return counts * RLG_PULSE * fs, fs, {}, {}, comp


def _flicker_clean(rng):
    fs, n = 20.0, 2_000_000  # 10⁵ s
    return rb.noise(n, fs, rng, N=1e-3, B=5e-4, K=2e-7), fs, {}, {}, None


#: heater on from 0.3 T to 0.55 T of a 20 000 s record: white noise 1.8×
HEATER = (6000.0, 11000.0, 1.8)


def _heater(rng):
    fs, n = 50.0, 1_000_000
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, B=3e-4, K=2e-6)
    white = 3e-3 * math.sqrt(fs) * rng.standard_normal(n)
    on = (t >= HEATER[0]) & (t < HEATER[1])
    white[on] *= HEATER[2]
    return y + white, fs, {}, {}, None


def _tiny_line(rng):
    fs, n = 1000.0, 10_000_000
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=1e-3, B=3e-4, K=1e-5)
    comp = 1.2e-3 * np.sin(2 * np.pi * 0.01 * t + 1.9)
    return y + comp, fs, {}, {}, comp


#: mains in a magnetometer (µT): (harmonic, amplitude, phase)
MAG_MAINS = ((1, 1.0, 0.2), (3, 0.4, 1.4), (5, 0.2, 2.6), (7, 0.1, 0.9))


def _magnetometer(rng):
    fs, n = 1000.0, 2_000_000
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=0.02, B=0.01, K=2e-4)
    comp = sum(a * np.sin(2 * np.pi * 50.0 * k * t + p) for k, a, p in MAG_MAINS)
    return y + comp, fs, {}, {}, comp


def _small_warmup(rng):
    fs, n = 100.0, 1_000_000  # 10⁴ s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2e-3, B=5e-4, K=1e-5)
    comp = 2.5e-3 * np.exp(-t / 1000.0)
    return y + comp, fs, {}, {}, comp


def _accelerometer(rng):
    fs, n = 200.0, 1_000_000  # 5000 s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=1e-3, B=2e-4, K=5e-6) + 9.81
    warm = 0.012 * np.exp(-t / 400.0)
    line = 0.018 * np.sin(2 * np.pi * 6.2 * t + 2.2)
    return y + warm + line, fs, {}, {}, [warm, line]


_periodic = rb2._periodic

CASES = [
    Blind4(
        "fast channel: g-sensitivity 0.08 °/s/g to a 20–80 Hz vibration of 2 g rms, accelerometer channel, 400 Hz × 10⁶",
        _vibration,
        [Injected("regression", {"coefficient": G_SENS})],
        channel="acc",
        seed=401,
    ),
    Blind4(
        "sinc³ (CIC) decimation 3200 → 200 Hz, 200 Hz × 5·10⁵",
        _cic,
        [Injected("bandwidth", {"cutoff": _cic_cutoff()})],
        seed=402,
    ),
    Blind4(
        "automotive gyro started cold (−10 → 40 °C), bias quadratic in T, 400 Hz × 10⁶",
        _cold_start,
        [Injected("regression", {"coefficient": 2.5e-4, "quadratic": 5e-5})],
        channel="temp",
        seed=403,
    ),
    Blind4(
        "24 h at 10 Hz: diurnal temperature (2·10⁻⁵ rad/s per °C) and an air-conditioning cycle of 900 s",
        _day,
        [
            Injected("regression", {"coefficient": 2e-5}),
            Injected("sinusoid", {"amplitude": 1.8e-5, "f0": 1.0 / HVAC_S}, ("f0",)),
        ],
        channel="temp",
        unit="rad/s",
        seed=404,
    ),
    Blind4(
        "ring-laser gyro, pulse-counted (10⁻⁷ rad), 612 Hz dither residual aliased to 388 Hz, 1 kHz × 2·10⁶",
        _rlg,
        [Injected("sinusoid", {"amplitude": RLG_AMP, "f0": RLG_FS - RLG_DITHER}, ("f0",))],
        unit="rad/s",
        seed=405,
    ),
    Blind4("flicker-dominated gyro, 20 Hz × 2·10⁶ (28 h), nothing else (clean)", _flicker_clean, seed=406),
    Blind4(
        "heater on for a stretch: white noise 1.8× from 6000 to 11 000 s, 50 Hz × 10⁶",
        _heater,
        [Injected("change_point", {"t": [HEATER[0], HEATER[1]]})],
        seed=407,
    ),
    Blind4(
        "1 kHz × 10⁷, a 1.2·10⁻³ °/s line at 0.01 Hz",
        _tiny_line,
        [Injected("sinusoid", {"amplitude": 1.2e-3, "f0": 0.01}, ("f0",))],
        seed=408,
    ),
    Blind4(
        "magnetometer (µT, unit None), 50 Hz mains and odd harmonics 3, 5, 7, 1 kHz × 2·10⁶",
        _magnetometer,
        [_periodic([50.0], math.sqrt(sum(a * a / 2 for _k, a, _p in MAG_MAINS)))],
        unit=None,
        seed=409,
    ),
    Blind4(
        "a warm-up a sixth of the detectable size, 100 Hz × 10⁶ (clean in disguise: nothing may be added)",
        _small_warmup,
        seed=410,
    ),
    Blind4(
        "accelerometer (m/s², unit None) on 1 g: warm-up 0.012·e^{−t/400 s} and a 6.2 Hz line, 200 Hz × 10⁶",
        _accelerometer,
        [
            Injected("drift", {"amplitude": 0.012, "T": 400.0}),
            Injected("sinusoid", {"amplitude": 0.018, "f0": 6.2}, ("f0",)),
        ],
        unit=None,
        seed=411,
    ),
]


def _size(y, comp, fs: float, _kw: dict) -> float | None:
    """``refine_blind2.effect_size`` of the component; of several, the smallest of each against the record less
    all of them; of a filter (``{"without": the record unfiltered}``), the largest ratio of the unfiltered
    record's Allan deviation to the record's — what the model without the roll-off puts there over the truth."""
    if isinstance(comp, dict):
        a, b = allanite.avar(comp["without"], fs), allanite.avar(np.asarray(y, dtype=np.float64), fs)
        keep = a.tau <= 0.25 * len(y) / fs
        return float(np.sqrt(np.max(a.avar[keep] / b.avar[keep])))
    if not isinstance(comp, list):
        return rb2.effect_size(y, comp, fs)
    rest = np.asarray(y, dtype=np.float64) - sum(comp)
    return min(rb2.effect_size(rest + c, c, fs) for c in comp)


def _change_times(r, case, v: dict) -> None:
    """A change point injected at several times: each true time within 20 % of a found one (``sensors.judge``
    keeps one ``t`` per effect, the first step's)."""
    inj = [i for i in case.injected if i.effect == "change_point" and isinstance(i.truth.get("t"), list)]
    if not inj or case.outside:
        return
    found = [s.params.get("t") for s in r.steps if s.effect == "change_point"]
    errs = [min((abs(f / t - 1) for f in found), default=None) for t in inj[0].truth["t"]]
    ok = bool(found) and all(e is not None and e <= sensors.PARAM_TOL for e in errs)
    v["param_errors"]["change_point.t"] = None if None in errs or not errs else max(errs)
    v["params"] = ok  # the only injected effect of such a case
    v["passed"] = bool(v["named"] and v["params"] and v["falling"] and v["heldout_falling"] and v["explained"])


def _judged(r, case) -> dict:
    v = rb2._judged(r, case)
    _change_times(r, case, v)
    return v


def run_case(case) -> dict:
    y, fs, channels, kw, comp = case.build(np.random.default_rng(case.seed))
    size = _size(y, comp, fs, kw)
    return rb.refined(case, y, fs, channels, kw, _judged) | {"size": size, "outside": case.outside}


#: What the table shows and why (kept true to the recorded run).
NOTES: list = [
    "**First run** (at 5b4c9e3, the suite as committed, before any change; load 70 % from other processes; its "
    "table and JSON are in commit 44120db): **8 of 11 passed**, without the candidate 8 of 9 flagged. The table "
    "above is the suite rerun once every branch of the session had merged (f97e098, after the fixes below; its "
    "header's \"+dirty\" is the other suites' pages written before it), as the rerun at 5229dd3: **8 of 11**, without the "
    "candidate 8 of 9 (the cold start's drift stands in for its temperature, as before) — the cold start now names its temperature (regression, coefficient +30.3 %, quadratic +5.9 %) but still fails "
    "on the coefficient's 20 %; every other row's effects, parameters and words as at the first run. The sinc³ row "
    "alone rerun on branch r7cic (the sinc^k kinds; its line in the table and JSON replaced): it passes — "
    "**9 of 11**, without the candidate 8 of 9. Passed as a user would want: the g-sensitivity "
    "on the accelerometer channel (+0.1 %); the 24 h log's temperature (−3.0 %) and its 900 s cycle (+1.8 %, a "
    "Gauss–Markov term of T_c 388 s beside them); the pulse-counted RLG's dither line at its alias, 388 Hz "
    "(+0.0 %); the flicker-dominated clean gyro (nothing added); the heater's two change points (6000 and "
    "11 000 s); the 0.01 Hz line in 10⁷ samples (−1.1 %); the magnetometer's 50 Hz family of 4 odd harmonics "
    "(rms +0.1 %); the warm-up of a sixth of the detectable size (nothing added, nothing said)."
    + " The accelerometer's row (warm-up and line) was rerun alone since, once the drift's held-out test moved into time (r7heldout): **9 of 11**."
    + " **The table above** is the whole suite rerun at bfcb29f (every branch of the 2026-11-27 forenoon merged: the"
    " sinc^k kinds, the warm-up held out in time, the coupling's test of any phase, the floor beside single poles):"
    " **10 of 11**, without the candidate **9 of 9** — the sinc³ named `sinc3` (cutoff +0.1 %), the accelerometer's"
    " warm-up kept beside its line (a +6.4 %, T +11.1 %), and the cold start refined without the regression no"
    " longer has a drift standing in for its temperature (a drift a given channel explains is not kept, with or"
    " without the regression candidate): its swing is said. The cold start still fails on its coefficient (+30.3 %).",
    "",
    "Why three failed at the first run:",
    "",
    "- *sinc³ (CIC) decimation 3200 → 200 Hz* — the roll-off is named (a boxcar of 1.66 samples, cutoff "
    "53.4 Hz, +1.8 %; χ²/dof 1068 → 2.80) but its shape is not in the bandwidth family (a sinc³ read at the "
    "output rate is a B-spline of three output samples, not a triangle), and the Allan curve's departure at "
    "τ 5 ms–0.56 s is said (statistic 52.1 against 43.9). **Named since** (branch r7cic, this row alone rerun): "
    "the sinc^k kinds `sinc2` … `sinc5` (k boxcars of span D output samples, the samples' autocorrelation the "
    "B-spline M_2k(l/D)) — `sinc3` at a span of 0.997 samples, cutoff 52.54 Hz (+0.1 %), χ²/dof 1068 → 0.94, "
    "nothing unexplained. Orders 2–4 fit within 2 of χ² 83 here (sinc² at 1.24 samples, sinc⁴ at 0.87; the "
    "boxcar 156): the order whose span is nearest one output sample is named, as a CIC read at its own output "
    "rate has (`benches/results/refine_cic.md`: orders 3–5, decimations 4–64, 100 Hz–2 kHz, 9 of 11 CIC "
    "records; the curve test's threshold on clean records unchanged or ≤ 0.7 % higher).",
    "- *automotive gyro started cold, bias quadratic in T* — read as a warm-up drift (a 0.102, T 41.9 s) and the "
    "temperature not taken: the swing (time constant 100 s) lies within the first of the 8 blocks, so the "
    "channel is classed fast (most of its variance within a block) and its within-block t test has ≈ 1 dof "
    "(t 5.9 against 170); and the drift, tested before the regressions, takes the swing first. Without the "
    "regression candidate the drift says it all (nothing unexplained). **Named since** (d3048bc, 5229dd3): a "
    "channel whose within-block test has fewer than 2 dof takes the Whittle GLS as a slow one does (0 of 201 "
    "null records of such swings at 10 Hz × 10⁵ accepted at α 0.375 %: `benches/regression_swing_null.py`), and a drift the test finds is left to a "
    "channel whose regression, accepted on the samples as they are, leaves a record the drift test no longer "
    "accepts (here 1332 → 7.3 against 910; a warm-up of 1500 s beside a swing of 300 s stays a drift: "
    "tests/test_refine_blind4_fixes.py). Now regression with a quadratic term (kept: 126 against 13.1), "
    "χ²/dof 2.44 → 1.11, held out 4.47 → 3.81 %, nothing unexplained — and still ✗: the coefficient reads "
    "3.26·10⁻⁴ (+30.3 %), its own 68 % interval [2.47, 4.05]·10⁻⁴ holding the truth: along one monotone swing T "
    "and T² are nearly collinear and their errors tied (the quadratic +5.9 %, its interval ±3.5 %). The judge's 20 % is tighter than this record allows; not retuned. Unchanged by the fix: the six "
    "temperature rows of `benches/refine_sensors.py`, blind2's two channel rows, blind3's six and blind1's "
    "48 h row (effects, parameters and words as recorded).",
    "- *accelerometer (m/s²) on 1 g, warm-up and a 6.2 Hz line* — at the first run the line was named "
    "(−0.1 %) and the warm-up's test accepted (statistic 1516 against 126; a 0.0128, +6 %, T 445 s, +11 "
    "%) but its held-out Allan-curve error rose 42.36 → 42.52 %, and the warm-up was only said in "
    "`unexplained` (τ 223–556 s, T ≈ 447 s). Why: the held-out split's alternate eighths (625 s) are "
    "longer than the warm-up (T 400 s), so one part holds the whole warm-up and the other almost none; "
    "the held-in parts' fits are poor (the odd blocks' a 0.0086, T 528 s here; on other seeds and rates T"
    " from 25 to 5000 s, one amplitude 10⁷), no τ where the two parts' own curves agree holds the warm-"
    "up, and the scored τ (EDF ≥ 50: up to 30 s) are decided by the line's misfit, which the five terms "
    "do not model (without the line: 3.68 → 3.69 %). Over 20 such warm-ups (T 40–1500 s, 100 Hz–1 kHz × "
    "10⁵–10⁶, with and without the line) that test kept 9. **Kept since** (r7heldout): a drift is held "
    "out in time on its own time scale (`allanite.model.warmup.warmup_heldout`: block means interleaved "
    "in groups ≤ T/2, here 220 s, each part with a block at the record's start; the held-in parts' fits a"
    " 0.0127, T 436 s and a 0.0130, T 445 s; the held-out block means' conditional χ² under the record's "
    "noise 0.45 of that without the warm-up, z 16.5 against 4) — 18 of those 20 kept (the two at 1 kHz "
    "with T 100 s and the line read z 3.0 and 3.6), while on 20 random-walk and flicker records at 10 "
    "Hz–1 kHz the warm-up fitted to their wander reached z ≤ 2.1; `refine_injected`'s two warm-up rows "
    "and `refine_sensors`' three, blind2's one as recorded. The row above is this case rerun alone "
    "(`--case accelerometer`, its neighbour the vibration row unchanged): drift (a +6.4 %, T +11.1 %) and"
    " sinusoid, χ²/dof 4.29·10⁴ → 1.56, RMS ADEV 39.6 → 0.881 %, nothing unexplained. The chain's held-"
    "out Allan-curve error rises at the drift step, 3.53 → 3.85 % (said in the step's `heldout_note`): on"
    " that split's eighths the warm-up is still refitted on a part that holds it alone; the final 3.85 % "
    "where the first run ended at 3.53 %.",
    "**Rerun at 44eba23** (every branch of the 2026-11-27 afternoon merged: the sinc^k kind chain, the family fold, the mean check's per-term nulls, the coupling test's bootstrap where its dof is small, the cost round, the module splits): the table above, **10 of 11**, without the candidate **9 of 9** — every row's effects, parameters and words as at bfcb29f but the 24 h log's: refined without the regression candidate it now leaves 2 regions unexplained (1 before; the coupling test's bootstrap). The cold start still fails on its coefficient (+30.3 %, its interval holding the truth).",
    "**Rerun whole at ba83de7** (every branch of the 2026-11-27 evening merged but r11lagrate, whose rule runs only where a d(ch)/dt term passes; none of this suite's rows keeps one): the table above, **10 of 11** — every row's verdict as before; the 24 h log no longer adds a Gauss–Markov beside its 900 s cycle (the sinusoid and the regression as before; χ²/dof 1.19 → 1.94 at the end, held out 0.70 → 0.72 %). The cold start still fails on its coefficient (+30.3 %).",
    "**Rerun whole at a593464** (every branch of the 2026-11-27 night merged: r12adis, r12chanres, r12burst, r12lag, r12blind10, r12wline, r12ci, r12lineamp; CI, other suites and the ADIS16405 run shared the 2 cores, so the CPU column is not a cost measurement): **10 of 11**, every row's verdict, effects, parameters and words as recorded.",
    "**Rerun whole at 55d58e5** (every branch of the 2026-11-28 night merged: r13heldout, r13gain, r13swing, r13rate, r13cover, r13cost, r13slowline; the other suites, the ADIS16405 run and CI shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict, effects, parameters and words as recorded (the cold start as rerun on r13swing: +30.3 %, scatter — s.d. 38 % over 40 seeds, benches/results/channel_swing_quadratic.md).",
    "Rerun whole at 9eaf694 (the 2026-11-28 morning's branches merged: r14house, r14blind11, r14modline, r14pump, r14cost, r14lagrate, r14fir; r14reson merged and reverted; another suite chain, the ADIS16405 run and CI shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict, effects, parameters and χ²/dof as recorded — 10 of 11.",
    "**Rerun whole at 44c3f2f** (the 2026-11-28 late-morning branches merged: r16heldout — the chain's deviance and AIC, keys only —, r16family, r16reson, r16burst; other suites and the false-alarm bench shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict, effects, parameters and words as recorded — 10 of 11.",
    "**r17nocand: the heater on for a stretch without its candidate** (2026-11-28, `/tmp` driver at c2f778e; load 8–13 on the 2 cores, other helpers' runs beside): still flagged, now as the stretch it is — \"the noise level changes along the record: the Allan deviation at τ₀ within t 6000–11000 s: 1.80× the rest of the record's (44 % off the record's level; held-out error 4.5 %)\" (the level test's runs of blocks, 51.2 against 4.75; recorded: \"1.30× … of t 1…\", a split of the CUSUM's).",
    "Rerun whole on 2026-11-28 at 45caf74 (the r17 merges: the alternative chains unified and memoised, the declared filter, the follows check, the channel check's first quadratic, the level test's runs of blocks, the slow-line test's second reading; r17cost2's cheaper arithmetic, equal to 1e-9, was merged after) with 044680b's why_not_kept fix: every row's verdict, effects and unexplained domains as recorded, and every without-candidate flag.",
    "",
    "Rerun whole on 2026-11-28 at da6740f (the r18 merges: r18cost's and r18boot's cheaper arithmetic, the sigma-delta's shaped quantisation (r18sdm), a quantised output's floor (r18bartlett), sharp rippled filter kinds (r18sharp), line families whose fundamental hunts (r18hunt); other suites, CI and the false-alarm bench shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict and effects as recorded — 10 of 11.",
]


def main(argv=None) -> None:
    rb2.suite_main(argv, __doc__, CASES, run_case, _size, NOTES, "refine_blind4", "fourth")


if __name__ == "__main__":
    main()
