#!/usr/bin/env python3
"""``allanite.refine`` on a second blind suite of simulated sensors, unlike ``tests/sensors.py``, the first blind
suite (``benches/refine_blind.py``) and the ADIS16405.

**Written and committed before it was first run.** The first run's verdicts are recorded as they came out (the
notes below the table); any later change is judged against them, and the cases are not retuned after the run. The
effects' sizes were fixed beforehand by their Allan deviation alone (the column "size": the largest ratio, over the
τ refine scores, of the injected component's Allan deviation to that of the rest of the record — the suite asks
≥ 3× for curve effects; impulsive noise is sized by its count instead), never by refine's answer.

The cases: a 2 kHz MEMS gyro × 4·10⁶ with two extra channels — a temperature it follows with a quadratic term, and
a supply voltage (a random walk) it does not follow, which must not be taken; a 1 Hz × 10⁵ log in a thermal
chamber ramping between plateaus, the gyro following the temperature and dT/dt; bursts of spikes (clustered
impulsive noise, not iid); a square wave at 0.7 Hz on a 200 Hz quantised gyro (a period of 285.7 samples); an
amplitude-modulated 47.5 Hz carrier on a 1 kHz sensor; a 50 s record (10⁵ samples at 2 kHz) with a line; a 300 s
warm-up on a 400 Hz gyro with strong flicker; a clean 10⁷-sample 1 kHz record with strong flicker and rate random
walk (nothing may be added) — and three effects **outside refine's family**: a chirp (a line whose frequency drifts
along the record), a bias step (a jump of the mean, not of the noise level) and a sinusoid switched on halfway.

Judged as ``benches/refine_blind.py`` judges (its :func:`refine_blind.judge`, i.e. ``tests/sensors.py``'s
``judge`` plus the change-point and filter-kind rules; a clean case: nothing added, nothing unexplained). An effect
outside the family passes when ``unexplained`` is non-empty (refine may name its nearest effect, but must not call
the model complete). A case with a named channel passes only if every regression is on that channel. Every case
with an effect in the family is refined again without its effect's candidate, which must leave something
unexplained.

Usage::

    python benches/refine_blind2.py               # -> benches/results/refine_blind2.{json,md}
    python benches/refine_blind2.py --case chirp  # the cases whose name contains "chirp", to a temporary folder
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy import signal

import _common
import allanite
import refine_blind as rb
from allanite.model.refinement.words import describe_region

sensors = rb.sensors
Injected = sensors.Injected
HERE = Path(__file__).resolve().parent


@dataclass
class Blind2(rb.Blind):
    """A blind case (``refine_blind.Blind``) whose ``build(rng)`` returns (samples, fs, channels, keyword arguments,
    the injected component or None); ``outside``: its effect is outside refine's family (passes when something is
    left unexplained); ``channel``: the only channel a regression may be on."""

    outside: bool = False
    channel: str | None = None
    sizes: dict = field(default_factory=dict)


def _white(n, fs, rng, N) -> np.ndarray:
    return rng.standard_normal(n) * (N * math.sqrt(fs))


def _chamber(t: np.ndarray, lo: float, hi: float, hold: float, ramp: float) -> np.ndarray:
    """A thermal chamber's profile: plateaus at ``lo`` and ``hi`` held ``hold`` s, joined by ramps of ``ramp`` s."""
    period = 2 * (hold + ramp)
    p = np.mod(t, period)
    up = np.clip((p - hold) / ramp, 0.0, 1.0)
    down = np.clip((p - 2 * hold - ramp) / ramp, 0.0, 1.0)
    return lo + (hi - lo) * (up - down)


def _mems_two_channels(rng):
    fs, n = 2000.0, 4_000_000  # 2000 s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=1e-3, K=3e-5)
    temp = sensors.temperature_profile(t, "cycle", rng, lo=15.0, hi=35.0)
    d = temp - temp.mean()
    comp = 8e-4 * d + 1.2e-4 * (d * d - np.mean(d * d))
    walk = np.cumsum(rng.standard_normal(n))
    vdd = 5.0 + 0.05 * (walk - walk.mean()) / np.ptp(walk) + 1e-3 * rng.standard_normal(n)
    logged = temp + 0.01 * rng.standard_normal(n)
    return y + comp, fs, {"temp": logged, "vdd": vdd}, {}, comp


def _chamber_rate(rng):
    fs, n = 1.0, 100_000
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=1e-3, B=2e-4, K=2e-6)
    temp = _chamber(t + 1500.0, 10.0, 30.0, 6000.0, 1200.0)  # 1 °C/min ramps
    comp = 1e-4 * (temp - temp.mean()) + 0.12 * np.gradient(temp, 1.0 / fs)
    logged = temp + 0.01 * rng.standard_normal(n)
    return y + comp, fs, {"temp": logged}, {}, comp


def _bursts(rng):
    fs, n = 500.0, 1_000_000
    y = rb.noise(n, fs, rng, B=5e-4, K=1e-5)
    sigma = 2e-3 * math.sqrt(fs)
    white = sigma * rng.standard_normal(n)
    comp = np.zeros(n)
    starts = np.sort(rng.choice(np.arange(100, n // 50 - 1), 100, replace=False)) * 50  # 100 bursts of 0.1 s
    for s in starts:
        hit = s + rng.choice(50, 15, replace=False)  # 15 of its 50 samples spiked: 1500 in all, rate 1.5·10⁻³
        comp[hit] = sigma * 10.0 * (1.0 + rng.random(15)) * rng.choice([-1.0, 1.0], 15)
    return y + white + comp, fs, {}, {}, comp


def _square_quantised(rng):
    fs, n = 200.0, 1_000_000
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2e-3, B=5e-4, K=1e-5)
    comp = 0.012 * signal.square(2 * np.pi * 0.7 * t + 0.9)
    lsb = 1.5 * 2e-3 * math.sqrt(fs)
    return np.round((y + comp) / lsb) * lsb, fs, {}, {}, comp


def _am_1khz(rng):
    fs, n = 1000.0, 2_000_000
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2e-3, B=5e-4, K=1e-5)
    comp = 0.1 * (1.0 + 0.6 * np.cos(2 * np.pi * 1.9 * t)) * np.sin(2 * np.pi * 47.5 * t + 0.2)
    return y + comp, fs, {}, {}, comp


def _short_line(rng):
    fs, n = 2000.0, 100_000  # 50 s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=1e-3, K=2e-5)
    comp = 0.05 * np.sin(2 * np.pi * 3.7 * t + 2.0)
    return y + comp, fs, {}, {}, comp


def _warmup_flicker(rng):
    fs, n = 400.0, 1_000_000  # 2500 s
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2e-3, B=1e-3, K=1e-5)
    comp = 0.04 * np.exp(-t / 300.0)
    return y + comp, fs, {}, {}, comp


def _clean_long(rng):
    fs, n = 1000.0, 10_000_000
    return rb.noise(n, fs, rng, N=1e-3, B=1e-3, K=5e-5), fs, {}, {}, None


def _chirp(rng):
    fs, n = 100.0, 1_000_000
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=3e-3, B=1e-3, K=2e-5)
    f_a, f_b, span = 2.0, 2.6, n / fs  # the line's frequency drifts 2.0 → 2.6 Hz along the record
    comp = 0.04 * np.sin(2 * np.pi * (f_a * t + 0.5 * (f_b - f_a) * t * t / span) + 0.5)
    return y + comp, fs, {}, {}, comp


def _bias_step(rng):
    fs, n = 50.0, 1_000_000  # 20 000 s
    y = rb.noise(n, fs, rng, N=2e-3, B=3e-4, K=2e-6)
    comp = np.zeros(n)
    comp[int(0.55 * n) :] = 3e-3
    return y + comp, fs, {}, {}, comp


def _switch_on(rng):
    fs, n = 200.0, 1_000_000
    t = np.arange(n) / fs
    y = rb.noise(n, fs, rng, N=2e-3, B=5e-4, K=1e-5)
    comp = np.where(t >= 0.5 * n / fs, 0.05 * np.sin(2 * np.pi * 4.3 * t + 1.3), 0.0)
    return y + comp, fs, {}, {}, comp


def _periodic(fundamentals, rms) -> Injected:
    return Injected("periodic", {"fundamentals": list(fundamentals), "rms": rms}, ("fundamentals",))


CASES = [
    Blind2(
        "2 kHz MEMS × 4·10⁶, temperature with a quadratic term, an irrelevant supply voltage (random walk)",
        _mems_two_channels,
        [Injected("regression", {"coefficient": 8e-4, "quadratic": 1.2e-4})],
        channel="temp",
        seed=201,
    ),
    Blind2(
        "1 Hz × 10⁵, thermal chamber ramping 1 °C/min between 10 and 30 °C, gyro on T and dT/dt",
        _chamber_rate,
        [Injected("regression", {"coefficient": 1e-4, "rate_coefficient": 0.12})],
        channel="temp",
        unit="rad/s",
        seed=202,
    ),
    Blind2(
        "bursts of spikes (100 bursts of 0.1 s, 30 % of their samples at 10–20 σ), 500 Hz × 10⁶",
        _bursts,
        [Injected("outliers", {"rate": 1.5e-3})],
        seed=203,
    ),
    Blind2(
        "square wave 0.012 °/s at 0.7 Hz, 200 Hz × 10⁶, quantised to 1.5 σ of its white noise",
        _square_quantised,
        [_periodic([0.7], 0.012)],
        seed=204,
    ),
    Blind2(
        "AM carrier 47.5 Hz × 1.9 Hz (depth 0.6), 1 kHz × 2·10⁶",
        _am_1khz,
        [_periodic([47.5, 1.9], 0.1 * math.sqrt(0.5 * (1 + 0.5 * 0.36)))],
        seed=205,
    ),
    Blind2(
        "short record: 50 s at 2 kHz, line 0.05 °/s at 3.7 Hz",
        _short_line,
        [Injected("sinusoid", {"amplitude": 0.05, "f0": 3.7}, ("f0",))],
        seed=206,
    ),
    Blind2(
        "warm-up 0.04·e^{−t/300 s}, 400 Hz × 10⁶, strong flicker",
        _warmup_flicker,
        [Injected("drift", {"amplitude": 0.04, "T": 300.0})],
        seed=207,
    ),
    Blind2("clean 1 kHz × 10⁷, strong flicker and rate random walk", _clean_long, seed=208),
    Blind2(
        "outside the family: chirp 0.04 °/s drifting 2.0 → 2.6 Hz, 100 Hz × 10⁶",
        _chirp,
        outside=True,
        seed=209,
    ),
    Blind2(
        "outside the family: bias step 3·10⁻³ °/s at 0.55 T, 50 Hz × 10⁶",
        _bias_step,
        outside=True,
        seed=210,
    ),
    Blind2(
        "outside the family: line 0.05 °/s at 4.3 Hz switched on halfway, 200 Hz × 10⁶",
        _switch_on,
        outside=True,
        seed=211,
    ),
]


def effect_size(y: np.ndarray, comp, fs: float) -> float | None:
    """The largest ratio, over octave τ up to a quarter of the record, of the component's Allan deviation to that of
    the rest of the record (None for a clean case)."""
    if comp is None:
        return None
    a = allanite.avar(comp, fs)
    b = allanite.avar(np.asarray(y, dtype=np.float64) - comp, fs)
    keep = (a.tau <= 0.25 * y.shape[0] / fs) & (b.avar > 0)
    return float(np.sqrt(np.max(a.avar[keep] / b.avar[keep])))


def _judge_outside(r) -> dict:
    left = r.unexplained
    first, last = (r.steps[0], r.steps[-1]) if r.steps else (None, None)
    out = {"named": True, "params": True, "param_errors": {}, "found": list(r.found), "unexplained": left}
    out |= {"explained": not left, "passed": bool(left), "falling": True, "heldout_falling": True}
    if first is not None:
        out["chi2_dof"] = (first.before.get("chi2_dof"), last.after.get("chi2_dof"))
        out["rms_adev_pct"] = (first.before.get("rms_adev_pct"), last.after.get("rms_adev_pct"))
        out["heldout_rms_adev_pct"] = (first.before.get("heldout_rms_adev_pct"), last.after.get("heldout_rms_adev_pct"))
    return out


def _judge_channel(r, case: Blind2, v: dict) -> None:
    """Every regression on the case's channel (an irrelevant channel taken fails the case)."""
    if case.channel is None:
        return
    chans = [s.params.get("channel") for s in r.steps if s.effect == "regression"]
    v["regression_channels"] = chans
    if any(c != case.channel for c in chans):
        v["named"] = v["passed"] = False


def _judged(r, case: Blind2) -> dict:
    """The verdict: something left unexplained for an effect outside the family, else refine_blind's; an
    irrelevant channel taken fails either."""
    v = _judge_outside(r) if case.outside else rb.judge(r, case)
    _judge_channel(r, case, v)
    return v


def run_case(case: Blind2) -> dict:
    y, fs, channels, kw, comp = case.build(np.random.default_rng(case.seed))
    size = effect_size(y, comp, fs)
    return rb.refined(case, y, fs, channels, kw, _judged) | {"size": size, "outside": case.outside}


def _row(v) -> str:
    injected = ", ".join(i["effect"] for i in v["injected"]) or ("outside" if v["outside"] else "— (clean)")
    errs = _common.param_errors_cell(v["param_errors"])
    left = v["unexplained"]
    left_s = "none" if not left else "; ".join(describe_region(u) for u in left[:3])
    wc = v.get("without_candidate")
    blind_s = _common.without_candidate_cell(None if wc is None else wc["unexplained"])
    chi = _common.arrow_cell(v.get("chi2_dof")) if v.get("chi2_dof") else f"{v['start_chi2_dof']:.3g} (nothing added)"
    size = "—" if v["size"] is None else f"{v['size']:.3g}×"
    return (
        f"| {v['name']} | {size} | {injected} | {_common.steps_cell(v['steps'], 4)} | {errs or '—'} | {chi} | "
        f"{_common.arrow_cell(v.get('rms_adev_pct'))} | {_common.arrow_cell(v.get('heldout_rms_adev_pct'))} | {left_s} | {blind_s} | "
        f"{'✓' if v['passed'] else '✗'} | {v['cpu_seconds']:.0f} |"
    )


def write(results, out: Path, load, notes: list, stem: str = "refine_blind2", which: str = "second") -> None:
    """The suite's page and JSON, ``<stem>.{md,json}`` in ``out`` (blind suite 3 writes through this too: its
    ``which`` "third", judged as this suite judges)."""
    m = _common.machine_info()
    passed = sum(v["passed"] for v in results)
    with_inj = [v for v in results if v["injected"]]
    flagged = sum(v.get("without_candidate_flags", False) for v in with_inj)
    judged_as = "refine_blind.py" if stem == "refine_blind2" else "refine_blind2.py"
    lines = [
        f"# refine on {'an' if which[0] in 'aeiou' else 'a'} {which} blind suite of simulated sensors (issue 29)",
        "",
        f"Default call, `python benches/{stem}.py`, {m['cpu_model']}, {m['cpus_usable']} CPUs, allanite at "
        f"{m['git_commit']}, {m['date_utc'][:10]}; other processes used {load:.0%} of the CPUs during the run "
        "(the last column is this process's CPU seconds for the default call).",
        "",
        f"**Passed: {passed} of {len(results)}** (as `benches/{judged_as}`: named, parameters within 20 %, "
        "frequencies within 1 %, χ²/dof (the tests' GLS) or the RMS ADEV error falling in sample, the RMS ADEV "
        "error held out, nothing unexplained; a clean case: nothing added, nothing unexplained; an effect outside "
        "refine's family: something left unexplained; a named channel: no regression on another). **Without the "
        f"effect's candidate, `unexplained` is non-empty in {flagged} of {len(with_inj)}.** The suite was written "
        "and committed before its first run; size: the injected component's Allan deviation over the rest's, "
        "largest over τ ≤ T/4.",
        "",
        "| case | size | injected | found (at acceptance, input unit) | parameter errors | χ²/dof start → final | "
        "RMS ADEV % | held-out % | unexplained | unexplained without the candidate | pass | CPU s |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
        *(_row(v) for v in results),
        "",
        *notes,
    ]
    _common.write_results(out, stem, lines, results)


#: What the table shows and why (kept true to the recorded run).
NOTES: list = [
    "**First run** (at 270d294, the suite as committed, before any change; load 89 % from other processes): "
    "**6 of 11 passed**, without the candidate 7 of 7 flagged. Failed: the 2 kHz two-channel MEMS (the "
    "temperature's Whittle test accepts — LR 17.8 against 9.8, coefficient −3.6 %, quadratic +4.9 % — but the "
    "held-out ratio across frequency 3.17 rejects it; the voltage was not taken, the coupling said as unexplained); "
    "the thermal chamber (the channel classed fast — 7 cycles, its variance within the 8 blocks — so no dT/dt term "
    "is tried; a sinusoid at 0.003 Hz and lines at 0.0012–0.0013 Hz left standing in for it); the spike bursts "
    "(outliers named, rate −11.9 %, but a 167 Hz single pole and a 139.8 Hz resonance added before them, χ²/dof "
    "3.55 → 5.77); the bias step (nothing added, nothing said: a silent complete model); the line switched on "
    "halfway (a sinusoid at 0.0353 = A/√2 plus a change point of the noise level at 2500 s, nothing unexplained). "
    "The chirp passed (three sinusoids and two change points, the curve's misfit at 2.0–2.6 Hz said).",
    "",
    "**Changed since** (the first run's table and JSON are in commit 8a4201a, the rerun after this change at 915142b; the table above is the latest rerun, its commit in the header): the channel regression's held-out test "
    "across frequency (`channels.heldout_ratio`) now splits where the channel's information is shared more "
    "evenly — the even/odd DFT bins as before, or the record's two halves in time. A temperature cycling a whole "
    "number of times puts its power in one DFT bin, so on one side of the even/odd split: in the two-channel MEMS "
    "99.7 % of the information was on the odd bins, the way fitted there read 0.89, the other way 5.4 (that "
    "side's noise). Now the MEMS passes: regression on `temp` only, coefficient −3.6 %, quadratic +4.9 %, "
    "χ²/dof 6.44 → 0.99, held out 5.09 → 2.76 %, nothing unexplained; the voltage not taken "
    "(tests/test_channels.py: a 3-cycle temperature at LR 50 had been rejected at 1.05, now < 0.6; null ≈ 1). "
    "Unchanged by it: the six temperature cases of `benches/refine_sensors.py` (the same numbers as "
    "refine_sensors.md), the first blind suite's 48 h case, and 40 null records of `refine_false_alarms.py`'s "
    "channel mixtures (slow_1hz, channels_100hz: the Whittle test accepted none, so the held-out gate never "
    "came into play); the ADIS16405 rows (no channels) do not reach the changed code. The two channel rows rerun "
    "at 2b6cb2a, a lag its test cannot resolve now profiled for the removal (docs/channels.md): the MEMS "
    "coefficient −3.6 → −3.1 %, quadratic +4.9 → +4.7 %, χ²/dof → 0.994, held out 2.76 → 2.65 %; the thermal "
    "chamber the same (its d(ch)/dt term kept: no lag is profiled beside it).",
    "",
    "Why the other four failed — each a general gap:",
    "",
    "- *Thermal chamber, T and dT/dt* — **fixed since** (i29blind3): the channel is still classed fast (7 "
    "cycles, its variance within the 8 blocks), but once the within-block test accepts, the Whittle GLS's optional "
    "terms are tried, each by its own nested test at its own share of `level`; its fit replaces the block "
    "coefficient when its coupling test accepts too, a term is kept, and its component regressed within the "
    "blocks on the channel gives the rate's own block coefficient within the t threshold × its standard error "
    "(a coupling that differs across frequency fails that: ADIS16405 run 2 gyro_x on acc_z, 9.6 SE off). Now "
    "regression with coefficient −8.0 % and rate_coefficient −0.3 %, χ²/dof 2.93 → 1.6, held out 7.58 → 2.32 %, "
    "nothing unexplained (tests/test_channels.py: a 7-cycle chamber at 0.8 °C/min, both within 10 %).",
    "- *Bursts of spikes* — **fixed since** (i29blind3): the rule off both neighbours now flags runs of up to 4 "
    "samples off both outer neighbours (the differences into and out of the run beyond the cut with opposite "
    "signs, each sample beyond the cut from both), the Gaussian count bounded by L·λ for each run length that "
    "flags a sample, and a good sample between two same-sign spikes is unflagged (off its own neighbours, not off "
    "those of the flagged stretch). 1500 of the 1500 spikes flagged, no good sample; outliers alone (rate −0.1 %), "
    "χ²/dof 3.55 → 1.06, held out 4.97 → 3.26 %. The pole and the resonance had been the runs left behind: the "
    "outlier removal already runs before every curve effect (removals first, outliers first among them).",
    "- *Bias step* (outside the family) — **said since** (r3step): refine still adds nothing (the curve fits, "
    'χ²/dof 0.55), and now `unexplained` says the step (the `"mean"` check: the best single split of 48 block '
    "means against a null simulated from the final model refitted without the located step, its slow terms raised "
    "to the upper end the curve allows, at its own share of `level` taken from the drift check's): 0.0033 deg/s "
    "at t ≈ 11001.9 s (true 3·10⁻³ at 11000 s), statistic 1.62·10⁻³ against 8.8·10⁻⁴ (8.7·10⁻⁴ before its α "
    "was halved for the `steps` check), said because the step moves "
    "the Allan deviation by up to 264 % against a held-out error of 2.3 %. The final fit had absorbed the step "
    "into rate random walk (K 2.6·10⁻⁵ against the true 2·10⁻⁶) and a null drawn from that model covered it; the "
    "refit without it gives K 1.65·10⁻⁶ (the null's, raised, 4.3·10⁻⁶). False alarms of the check over 300 clean "
    "records: benches/results/refine_mean_step_null.md. Rerun at 92b277f: this row changed, the other ten rows' "
    "effects, numbers and words as before (CPU column aside).",
    "- *Line switched on halfway* (outside the family) — **said since** (r2line): refine still names a sinusoid at "
    "A/√2 and a change of the noise level at 2500 s, and now `unexplained` says the line's amplitude changes along "
    'the record (the `"line"` check: each accepted sinusoid\'s complex amplitude in blocks of ≥ 20 periods tested '
    "for constancy against the off-line noise of the same blocks, at its own share of `level` taken from the Allan "
    "check's; said only where the change exceeds the held-out error): ≈ 0 deg/s in t 0–2500 s, 0.050 deg/s in "
    "t 2500–5000 s. The model is not right, but it no longer reads as complete.",
    "**Rerun at 44eba23** (every branch of the 2026-11-27 afternoon merged: the sinc^k kind chain, the family fold, the mean check's per-term nulls, the coupling test's bootstrap where its dof is small, the cost round, the module splits): the table above, **11 of 11**, without the candidate **7 of 7** — every row's effects, parameters and words as at bfcb29f (only the CPU column moved).",
    "**Rerun whole at ba83de7** (every branch of the 2026-11-27 evening merged but r11lagrate, whose rule runs only where a d(ch)/dt term passes — none of this suite's rows but the chamber ramp, rerun on it unchanged): the table above, **11 of 11** — every row's verdict as before; the chirp (outside the family) is now read as a line whose frequency wanders (r11wander: a periodic at 2.30 Hz wandering 7.7 % rms, χ²/dof 2.08·10⁴ → 70.5, held out 40.5 → 5.6 %) and still said (the curve departs at τ 0.03–1.1 s), where three sinusoids and two change points stood in for it; the bursts' outlier threshold 0.2851 → 0.2858.",
    "**Rerun whole at a593464** (every branch of the 2026-11-27 night merged: r12adis, r12chanres, r12burst, r12lag, r12blind10, r12wline, r12ci, r12lineamp; CI, other suites and the ADIS16405 run shared the 2 cores, so the CPU column is not a cost measurement): **11 of 11**, every row's verdict, effects, parameters and words as recorded.",
    "**Rerun whole at 55d58e5** (every branch of the 2026-11-28 night merged: r13heldout, r13gain, r13swing, r13rate, r13cover, r13cost, r13slowline; the other suites, the ADIS16405 run and CI shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict, effects, parameters and words as recorded (the 2 kHz MEMS row as rerun on r13swing: coefficient −4.4 %, the slope at the whole record's mean).",
    "Rerun whole at 9eaf694 (the 2026-11-28 morning's branches merged: r14house, r14blind11, r14modline, r14pump, r14cost, r14lagrate, r14fir; r14reson merged and reverted; another suite chain, the ADIS16405 run and CI shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict, effects, parameters and χ²/dof as recorded — 11 of 11.",
    "**Rerun whole at 44c3f2f** (the 2026-11-28 late-morning branches merged: r16heldout — the chain's deviance and AIC, keys only —, r16family, r16reson, r16burst; other suites and the false-alarm bench shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict, effects, parameters and words as recorded — 11 of 11.",
    "Rerun whole on 2026-11-28 at 45caf74 (the r17 merges: the alternative chains unified and memoised, the declared filter, the follows check, the channel check's first quadratic, the level test's runs of blocks, the slow-line test's second reading; r17cost2's cheaper arithmetic, equal to 1e-9, was merged after) with 044680b's why_not_kept fix: every row as recorded; the thermal chamber's run without its candidate raised KeyError 'param' in unexplained before the fix (a line of few cycles left to the channel) and now says the chamber's cycle, flagged as before.",
    "",
    "Rerun whole on 2026-11-28 at da6740f (the r18 merges: r18cost's and r18boot's cheaper arithmetic, the sigma-delta's shaped quantisation (r18sdm), a quantised output's floor (r18bartlett), sharp rippled filter kinds (r18sharp), line families whose fundamental hunts (r18hunt); other suites, CI and the false-alarm bench shared the 2 cores, so the CPU column is not a cost measurement): every row's verdict and effects as recorded — 11 of 11.",
]


def suite_main(argv, doc: str, cases, run, size, notes: list, stem: str, which: str) -> None:
    """The command line of a blind suite (this one's and blind suites 3–12's): ``--case``, ``--out``, ``--sizes``
    (``size(y, comp, fs, kw)`` printed per case, no refine), ``--seed-offset`` (every case on other noise)."""
    ap = argparse.ArgumentParser(description=doc.split("\n")[0])
    ap.add_argument("--case", default=None, help="only cases whose name contains this text")
    ap.add_argument("--out", default=None, help="results folder (default benches/results)")
    ap.add_argument("--sizes", action="store_true", help="print each case's effect size only (no refine)")
    ap.add_argument(
        "--seed-offset",
        type=int,
        default=0,
        help="add this to every case's seed: the same sensors on other noise (written to --out, else a temporary "
        "folder, never over the recorded table)",
    )
    args = ap.parse_args(argv)
    chosen = [c for c in cases if args.case is None or args.case in c.name]
    if args.seed_offset:
        chosen = [dataclasses.replace(c, seed=c.seed + args.seed_offset) for c in chosen]
        notes = [f"Seeds offset by {args.seed_offset:+d} from the recorded cases' (`--seed-offset`).", "", *notes]
        args.out = args.out or tempfile.mkdtemp()
    if args.sizes:
        for case in chosen:
            y, fs, _ch, kw, comp = case.build(np.random.default_rng(case.seed))
            print(f"{case.name}: {size(y, comp, fs, kw)}", flush=True)
        return
    rb.run_suite(chosen, args, run, _row, lambda res, out, load: write(res, out, load, notes, stem, which), stem)


def main(argv=None) -> None:
    size = lambda y, comp, fs, _kw: effect_size(y, comp, fs)  # noqa: E731
    suite_main(argv, __doc__, CASES, run_case, size, NOTES, "refine_blind2", "second")


if __name__ == "__main__":
    main()
