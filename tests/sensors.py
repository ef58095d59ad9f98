"""Simulated sensors unlike the ADIS16405, each with an effect the five-term model lacks (issue 29's suite).

Every case is a static log of a simulated gyro: a rate (1 Hz … 2 kHz), a length (10⁵ … 10⁷ samples), a mixture
of the IEEE-952 terms, optionally a low-pass and a quantiser, and one or two injected effects of a detectable
size (the effect's Allan deviation ≥ 3× the noise model's at some τ of the curve; lines at 20/T ≤ f ≤ 0.4·fs):
temperature coupling through a slow temperature (cycling or random-walk profiles; one case with a lag, one with
a dT/dt term, never both), square and sawtooth waves, an amplitude-modulated carrier, a sample-rate beat, a
consumer IMU's line families, sparse spikes, heavy-tailed noise and warm-ups.

``make(case)`` builds the record; ``judge(refinement, case)`` says whether :func:`allanite.refine` with default
arguments named every injected effect with its parameters within 20 % (frequencies within 1 %), whether the
errors fell along the chain of steps (in sample and held out) and whether nothing is left unexplained.
``benches/refine_sensors.py`` runs the whole suite (and every case again without its effect's candidate, which
must leave something unexplained); ``tests/test_refine_sensors.py`` runs a fixed CI-sized subset.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from scipy import signal
from scipy.special import ndtr
from scipy.stats import f as f_dist

import allanite
from allanite.model.effects import EFFECTS
from allanite.simulation import kasdin_walter

#: Relative tolerance on parameters, and on frequencies.
PARAM_TOL = 0.2
FREQ_TOL = 0.01


@dataclass
class Injected:
    """One injected effect: the name refine should report, its true parameters, and which are frequencies."""

    effect: str
    truth: dict
    frequencies: tuple = ()
    #: truths that depend on what was found ((found parameters, the effect's steps) → {key: true value}): a heavy
    #: tail's share of flagged samples is defined only at the cut, and by the rule, the step reports
    truth_at: Callable[[dict, list], dict] | None = None


@dataclass
class Case:
    name: str
    fs: float
    n: int
    noise: dict  # Q, N, B, K, R for allanite.simulate (rate unit: the case's unit)
    effects: list  # of (kind, kwargs) for _inject
    unit: str = "deg/s"
    lowpass: tuple | None = None  # ("single_pole", cutoff Hz) or ("moving_average", taps)
    lsb: float | None = None  # quantiser step (rate unit)
    seed: int = 0
    ci: bool = False  # in the CI subset
    injected: list = field(default_factory=list)  # filled by make()


# ------------------------------------------------------------------------------------------------
# slow channels and injected components


def dropped(y: np.ndarray, seed: int, n_gaps: int = 20, frac: float = 0.01) -> np.ndarray:
    """``y`` with ``frac`` of its samples NaN in ``n_gaps`` equal gaps at seeded, non-overlapping places (a logger's
    dropped samples, as ``read_log(..., gaps="nan")`` marks them)."""
    z = y.copy()
    width = max(1, int(frac * y.size / n_gaps))
    slots = np.random.default_rng(seed).choice(y.size // width - 1, n_gaps, replace=False)
    for s in slots:
        z[s * width : (s + 1) * width] = np.nan
    return z


def temperature_profile(t: np.ndarray, kind: str, rng: np.random.Generator, lo=5.0, hi=20.0) -> np.ndarray:
    """A slow temperature (°C) over the record: ``"cycle"`` (a thermal chamber's cycles plus a little wander),
    ``"swing"`` (a housing warming up once, then steady) or ``"walk"`` (a room drifting: a random walk through
    the housing's thermal lag)."""
    span = t[-1] - t[0] if t.size > 1 else 1.0
    fs = (t.size - 1) / span if t.size > 1 else 1.0
    # a housing's thermal mass: the wander reaches the sensor through a lag of span/200 (smooth to minutes)
    wander = first_order_lag(np.cumsum(rng.standard_normal(t.size)), fs, span / 200.0)
    if kind == "swing":  # a housing warming up once: most of the change within the first eighth of the record
        x = -np.exp(-t / (span / 25.0)) + 0.1 * wander / max(np.ptp(wander), 1e-300)
    elif kind == "cycle":
        period = span / 3.0
        wander = 0.25 * wander / max(np.ptp(wander), 1e-300)
        x = np.sin(2 * np.pi * t / period - 0.5 * np.pi) + wander
    else:
        x = wander
    x = (x - x.min()) / max(x.max() - x.min(), 1e-300)
    return lo + (hi - lo) * x


def first_order_lag(x: np.ndarray, fs: float, lag_s: float) -> np.ndarray:
    """x through a first-order lag of time constant ``lag_s`` (unit DC gain), started at x[0]."""
    a = math.exp(-1.0 / (fs * lag_s))
    out = signal.lfilter([1.0 - a], [1.0, -a], x - x[0]) + x[0]
    return out


def _sample_rate_beat(t: np.ndarray, amp: float, f1: float, f2: float, fs: float, mode: str) -> np.ndarray:
    """A tone at f1 read by a sensor whose output drops (``"drop"``) or repeats (``"repeat"``) one sample every
    1/f2 s: the k-th output is the tone at the time of the sample it really took."""
    k = np.arange(t.size)
    per = fs / f2
    slips = np.floor(k / per)
    shift = slips if mode == "drop" else -slips
    taken = np.maximum(k + shift, 0) / fs
    return amp * np.sin(2 * np.pi * f1 * taken)


def _inject(kind: str, kw: dict, t: np.ndarray, fs: float, rng: np.random.Generator, base: np.ndarray):
    """(component or None, channels, Injected, replace) for one effect; ``replace`` is a function of the noise
    record for effects that change the noise itself (spikes, heavy tails)."""
    if kind == "temperature":
        temp = temperature_profile(t, kw.get("profile", "cycle"), rng)
        c = kw["coefficient"]
        drive = first_order_lag(temp, fs, kw["lag_s"]) if "lag_s" in kw else temp
        comp = c * (drive - drive.mean())
        truth = {"coefficient": c}
        if "lag_s" in kw:
            truth["lag_s"] = kw["lag_s"]
        if "rate_coefficient" in kw:
            comp = comp + kw["rate_coefficient"] * np.gradient(temp, 1.0 / fs)
            truth["rate_coefficient"] = kw["rate_coefficient"]
        # the logged temperature: the sensor's reading, with its own LSB noise
        logged = temp + rng.standard_normal(t.size) * kw.get("temp_noise", 0.01)
        return comp, {"temp": logged}, Injected("regression", truth), None
    if kind == "square":
        comp = kw["amplitude"] * signal.square(2 * np.pi * kw["f0"] * t + 0.3)
        return (
            comp,
            {},
            Injected("periodic", {"fundamentals": [kw["f0"]], "rms": kw["amplitude"]}, ("fundamentals",)),
            None,
        )
    if kind == "sawtooth":
        comp = kw["amplitude"] * signal.sawtooth(2 * np.pi * kw["f0"] * t + 1.1)
        rms = kw["amplitude"] / math.sqrt(3.0)
        return comp, {}, Injected("periodic", {"fundamentals": [kw["f0"]], "rms": rms}, ("fundamentals",)), None
    if kind == "am":
        a, f1, f2, m = kw["amplitude"], kw["carrier"], kw["modulation"], kw["depth"]
        comp = a * (1.0 + m * np.cos(2 * np.pi * f2 * t)) * np.sin(2 * np.pi * f1 * t)
        rms = a * math.sqrt(0.5 * (1.0 + 0.5 * m * m))
        return comp, {}, Injected("periodic", {"fundamentals": [f1, f2], "rms": rms}, ("fundamentals",)), None
    if kind == "beat":
        comp = _sample_rate_beat(t, kw["amplitude"], kw["f1"], kw["f2"], fs, kw.get("mode", "drop"))
        rms = kw["amplitude"] / math.sqrt(2.0)
        return (
            comp,
            {},
            Injected("periodic", {"fundamentals": [kw["f1"], kw["f2"]], "rms": rms}, ("fundamentals",)),
            None,
        )
    if kind == "lines":
        # a consumer IMU's families: a fundamental with harmonics, and pairs of sidebands k·f1 ± f2
        f0, f1, f2, a = kw["f0"], kw["f1"], kw["f2"], kw["amplitude"]
        comp = np.zeros(t.size)
        power = 0.0
        for k in range(1, 4):
            ak = a / k
            comp += ak * np.sin(2 * np.pi * k * f0 * t + 0.7 * k)
            power += ak * ak / 2
        for k in range(1, 4):
            for s in (-1, 1):
                ak = 0.6 * a / k
                comp += ak * np.sin(2 * np.pi * (k * f1 + s * f2) * t + 0.4 * k + s)
                power += ak * ak / 2
        return (
            comp,
            {},
            # the sidebands' lattice has more than one basis ((f1, f2) or (f1 + f2, f2), …): judged by the lines
            Injected(
                "periodic",
                {
                    "fundamentals": [f0, f2],
                    "line_frequencies": [k * f0 for k in range(1, 4)]
                    + [k * f1 + s * f2 for k in range(1, 4) for s in (-1, 1)],
                    "rms": math.sqrt(power),
                },
                ("fundamentals", "line_frequencies"),
            ),
            None,
        )
    if kind == "warmup":
        comp = kw["amplitude"] * np.exp(-t / kw["T"])
        return comp, {}, Injected("drift", {"amplitude": kw["amplitude"], "T": kw["T"]}), None
    if kind == "spikes":
        rate, amp = kw["rate"], kw["amplitude"]
        hit = rng.random(t.size) < rate
        comp = np.where(hit, amp * rng.choice([-1.0, 1.0], t.size) * (1 + rng.random(t.size)), 0.0)
        return comp, {}, Injected("outliers", {"rate": rate}), None
    if kind == "heavy_tails":
        return _heavy_tails(kw, rng)
    raise ValueError(f"unknown injected effect kind {kind!r}")


def _heavy_tails(kw: dict, rng: np.random.Generator):
    """Heavy-tailed white noise: a share ``fraction`` of the white samples ``wide`` × wider (``_inject``'s tuple)."""
    eps, wide = kw["fraction"], kw["wide"]

    def replace(white, eps=eps, wide=wide):
        pick = rng.random(white.size) < eps
        return np.where(pick, white * wide, white)

    # a continuous heavy tail has no true share of "outliers" (not the 20 % drawn wide: most of them lie
    # inside the Gaussian core): the share beyond a cut depends on the cut. The truth of ``rate`` is the share
    # the injected mixture flags at the threshold the step reports (:func:`mixture_flag_rate`)
    sigma = kw["white_sigma"]  # the white noise's σ per sample (the case's N·√fs)

    def truth_at(params, steps, eps=eps, wide=wide, sigma=sigma):
        thr = params.get("threshold")
        rule = next((st.evidence.get("rule") for st in steps if "rule" in st.evidence), "neighbours")
        return {} if thr is None else {"rate": mixture_flag_rate(thr, sigma, eps, wide, rule)}

    return None, {}, Injected("outliers", {"rate": None}, truth_at=truth_at), replace


def mixture_flag_rate(threshold: float, sigma: float, eps: float, wide: float, rule: str = "level") -> float:
    """The share of samples of white noise — Gaussian of σ ``sigma``, a share ``eps`` of it ``wide`` × wider —
    that :func:`allanite.model.outliers.outlier_test` flags at ``threshold`` by its ``rule``: ``"level"``, the
    distance from the slow level (a mean over at least ``LEVEL_SPAN`` samples: its own scatter is left out)
    beyond the threshold, 2[(1 − ε)Φ̄(thr/σ) + εΦ̄(thr/(wσ))]; ``"neighbours"``, off both neighbours by more
    than it on opposite sides, ∫ f(x) [F(x − thr)² + (1 − F(x + thr))²] dx with F the mixture's distribution.
    Other noise terms are taken as negligible at the shortest lag."""
    s_wide = sigma * wide
    if rule == "level":
        return float(2 * ((1 - eps) * ndtr(-threshold / sigma) + eps * ndtr(-threshold / s_wide)))
    x = np.linspace(-12 * s_wide, 12 * s_wide, 200_001)

    def cdf(v):
        return (1 - eps) * ndtr(v / sigma) + eps * ndtr(v / s_wide)

    pdf = (1 - eps) * np.exp(-0.5 * (x / sigma) ** 2) / sigma + eps * np.exp(-0.5 * (x / s_wide) ** 2) / s_wide
    pdf /= math.sqrt(2 * math.pi)
    p = pdf * (cdf(x - threshold) ** 2 + (1 - cdf(x + threshold)) ** 2)
    return float(np.sum(p) * (x[1] - x[0]))


def make(case: Case):
    """(samples, fs, channels) of ``case``; ``case.injected`` lists what refine should find."""
    rng = np.random.default_rng(case.seed)
    t = np.arange(case.n) / case.fs
    noise = dict(case.noise)
    n_white = noise.pop("N", 0.0)
    b = noise.pop("B", 0.0)
    y = allanite.simulate(case.n, case.fs, seed=rng, **noise)
    if b:
        # stationary flicker: Kasdin–Walter over up to 8× the record, its last part kept (started at the record's
        # first sample, the fractional integration lacks the power of f ≲ 10/T: −15 % Allan variance at T/9)
        pad = max(2, min(8, 2**25 // case.n))
        y = y + b * kasdin_walter(pad * case.n, 1.0, rng)[-case.n :]
    white = rng.standard_normal(case.n) * (n_white * math.sqrt(case.fs))
    channels: dict = {}
    case.injected = []
    comps = []
    for kind, kw in case.effects:
        comp, ch, inj, replace = _inject(kind, kw | {"white_sigma": n_white * math.sqrt(case.fs)}, t, case.fs, rng, y)
        channels.update(ch)
        case.injected.append(inj)
        if replace is not None:
            white = replace(white)
        if comp is not None:
            comps.append(comp)
    y = y + white
    if case.lowpass is not None:
        kind, p = case.lowpass
        if kind == "single_pole":
            a = math.exp(-2 * np.pi * p / case.fs)
            y = signal.lfilter([1 - a], [1, -a], y - y[0]) + y[0]
        else:
            y = np.convolve(y, np.full(int(p), 1.0 / int(p)), mode="same")
    for comp in comps:  # after the sensor's filter: what it measures and how it reads it differ per effect,
        y = y + comp  # but every injected component here is slow against the filters used
    if case.lsb:
        y = np.round(y / case.lsb) * case.lsb
    return y, case.fs, channels


# ------------------------------------------------------------------------------------------------
# the suite

CASES = [
    Case(
        "temperature, 1 Hz × 25 h (issue 29's log)",
        1.0,
        90_000,
        {"N": 1.5e-3, "B": 2e-4, "K": 2e-6},
        [("temperature", {"coefficient": 4.5e-4, "profile": "cycle"})],
        unit="rad/s",
        seed=1,
    ),
    Case(
        "temperature swinging once, 1 Hz × 25 h",
        1.0,
        90_000,
        {"N": 1.5e-3, "B": 2e-4, "K": 2e-6},
        [("temperature", {"coefficient": 4.5e-4, "profile": "swing"})],
        unit="rad/s",
        seed=17,
        ci=True,
    ),
    Case(
        "temperature random walk, 100 Hz × 10⁶",
        100.0,
        1_000_000,
        {"N": 3e-3, "B": 1.5e-3, "K": 2e-5},
        [("temperature", {"coefficient": 2e-3, "profile": "walk"})],
        lowpass=("single_pole", 20.0),
        seed=2,
    ),
    Case(
        "temperature through a 300 s lag, 10 Hz × 3·10⁵",
        10.0,
        300_000,
        {"N": 2e-3, "B": 5e-4, "K": 1e-5},
        [("temperature", {"coefficient": 1e-3, "profile": "cycle", "lag_s": 300.0})],
        seed=3,
    ),
    Case(
        "temperature with a dT/dt term, 1 Hz × 10⁵",
        1.0,
        100_000,
        {"N": 1e-3, "B": 2e-4, "K": 2e-6},
        [("temperature", {"coefficient": 4e-4, "profile": "cycle", "rate_coefficient": 2.0})],
        unit="rad/s",
        seed=4,
    ),
    Case(
        "square wave 0.37 Hz, 100 Hz × 4·10⁵",
        100.0,
        400_000,
        {"N": 4e-3, "B": 1e-3, "K": 2e-5},
        [("square", {"amplitude": 0.018, "f0": 0.37})],
        seed=5,
    ),
    Case(
        "sawtooth 2.3 Hz, 400 Hz × 10⁶, moving-average filter, quantised",
        400.0,
        1_000_000,
        {"N": 2e-3, "B": 5e-4, "K": 1e-5},
        [("sawtooth", {"amplitude": 0.045, "f0": 2.3})],
        lowpass=("moving_average", 4),
        lsb=1e-3,
        seed=6,
    ),
    Case(
        "AM carrier 7.3 Hz × 0.19 Hz, 100 Hz × 10⁶",
        100.0,
        1_000_000,
        {"N": 3e-3, "B": 1e-3, "K": 2e-5},
        [("am", {"amplitude": 0.07, "carrier": 7.3, "modulation": 0.19, "depth": 0.8})],
        seed=7,
    ),
    Case(
        "sample-rate beat: 11 Hz tone, a sample dropped every 2.5 s, 200 Hz × 10⁶",
        200.0,
        1_000_000,
        {"N": 3e-3, "B": 1e-3, "K": 2e-5},
        [("beat", {"amplitude": 0.085, "f1": 11.0, "f2": 0.4, "mode": "drop"})],
        seed=8,
    ),
    Case(
        "consumer IMU line families (0.19 Hz + sidebands of 3.1 Hz ± 0.45 Hz), 100 Hz × 10⁶",
        100.0,
        1_000_000,
        {"N": 5e-3, "B": 1e-3, "K": 3e-5},
        [("lines", {"f0": 0.19, "f1": 3.1, "f2": 0.45, "amplitude": 0.02})],
        lowpass=("single_pole", 30.0),
        seed=9,
    ),
    Case(
        "sparse spikes, 1 kHz × 10⁶",
        1000.0,
        1_000_000,
        {"N": 2e-3, "B": 5e-4, "K": 1e-5},
        [("spikes", {"rate": 1e-3, "amplitude": 5.0})],
        seed=10,
        ci=True,
    ),
    Case(
        "heavy-tailed noise (20 % of samples 6× wider), 100 Hz × 5·10⁵",
        100.0,
        500_000,
        {"N": 3e-3, "B": 5e-4, "K": 1e-5},
        [("heavy_tails", {"fraction": 0.2, "wide": 6.0})],
        seed=11,
    ),
    Case(
        "warm-up 0.05·e^{−t/120 s}, 2 kHz × 2·10⁶",
        2000.0,
        2_000_000,
        {"N": 2e-3, "B": 5e-4, "K": 1e-5},
        [("warmup", {"amplitude": 0.05, "T": 120.0})],
        seed=12,
    ),
    Case(
        "warm-up 0.03·e^{−t/1500 s}, 10 Hz × 10⁵",
        10.0,
        100_000,
        {"N": 2e-3, "B": 5e-4, "K": 1e-5},
        [("warmup", {"amplitude": 0.03, "T": 1500.0})],
        seed=13,
    ),
    Case(
        "temperature and spikes, 50 Hz × 5·10⁵",
        50.0,
        500_000,
        {"N": 3e-3, "B": 1e-3, "K": 2e-5},
        [("temperature", {"coefficient": 1e-3, "profile": "walk"}), ("spikes", {"rate": 1e-4, "amplitude": 5.0})],
        seed=14,
    ),
    Case(
        "square wave and a warm-up, 100 Hz × 10⁶, single pole 15 Hz",
        100.0,
        1_000_000,
        {"N": 3e-3, "B": 1e-3, "K": 2e-5},
        [("square", {"amplitude": 0.02, "f0": 0.9}), ("warmup", {"amplitude": 0.06, "T": 600.0})],
        lowpass=("single_pole", 15.0),
        seed=15,
    ),
    Case(
        "sawtooth 0.05 Hz, 1 kHz × 10⁷",
        1000.0,
        10_000_000,
        {"N": 1e-3, "B": 3e-4, "K": 5e-6},
        [("sawtooth", {"amplitude": 2e-3, "f0": 0.05})],
        seed=16,
    ),
]


# ------------------------------------------------------------------------------------------------
# judging a refinement


def _close(found, true, tol) -> bool:
    if isinstance(true, (list, tuple)):
        got = list(found) if isinstance(found, (list, tuple)) else [found]
        return all(any(abs(g / f - 1) <= tol for g in got) for f in true)
    return found is not None and not isinstance(found, str) and true != 0 and abs(found / true - 1) <= tol


def _step_params(steps) -> dict:
    """The parameters of an effect's steps, merged: lists joined (a record's line families, one step each), RMS
    amplitudes in quadrature, counts summed; a periodic effect's line frequencies from its evidence."""
    out: dict = {}
    for step in steps:
        params = dict(getattr(step, "final_params", None) or step.params)
        if "frequencies_hz" in step.evidence:
            params["line_frequencies"] = list(step.evidence["frequencies_hz"])
        for k, v in params.items():
            if k not in out:
                out[k] = list(v) if isinstance(v, (list, tuple)) else v
            elif isinstance(v, (list, tuple)):
                out[k] = list(out[k]) + list(v)
            elif k == "rms":
                out[k] = math.hypot(out[k], v)
            elif k == "lines":
                out[k] = out[k] + v
    return out


def _param_error(got, true) -> float | None:
    """Relative error of a found parameter; for a list, the largest over the true entries of the nearest found
    entry's (None where nothing numeric was found)."""
    if got is None or isinstance(got, str):
        return None
    if isinstance(true, (list, tuple)):
        found = list(got) if isinstance(got, (list, tuple)) else [got]
        if not found:
            return None
        return float(max(min(abs(g / f - 1) for g in found) for f in true))
    return float(got / true - 1)


#: A channel regression's optional terms (:data:`allanite.model.channels.SUBTERMS`): each is demanded only where
#: the record carries it at its own test's level (:func:`_optional_term_carried`).
OPTIONAL_TERMS = ("quadratic", "rate_coefficient", "lag_s")


def _optional_term_carried(steps, key: str) -> bool:
    """Whether the record carries a channel's optional term ``key`` at its test's level: its nested test's
    statistic beyond the F(1, ν) quantile at its α — for the lag, the plain quantile, without the penalty of
    the search over the lag grid (as if the lag were known). The issue keeps such a term "only by a nested test
    at its own share of ``level``"; where even the known lag's test would turn it down the record cannot show
    it, and demanding it would demand a false-alarm rate above the share (the 300 s lag case: statistic 14.6,
    F(1, 15.3) quantile 16.5 at α = 0.001, p = 0.0017 — the lag found at 296 s but not kept)."""
    for step in steps:
        t = step.evidence.get("terms", {}).get(key)
        if t is None:
            continue
        if t.get("kept"):
            return True
        if float(f_dist.sf(max(float(t["statistic"]), 0.0), 1, float(t["dof"]))) < float(t["alpha"]):
            return True
    return False


def judge(r, case: Case) -> dict:
    """What the default call got right on ``case``: per injected effect named / parameters within tolerance,
    and for the whole chain: errors falling in sample and held out, nothing left unexplained.

    A channel's optional term (a lag, a d(ch)/dt term) is judged only where the record carries it at its
    test's level (:func:`_optional_term_carried`; else its error reads "not carried"); a truth that depends on
    what was found (a heavy tail's flagged share at the reported cut, ``Injected.truth_at``) is computed there.

    The in-sample error "falls" when the chain's χ²/dof falls (the acceptance tests' GLS χ² on the exact
    covariance, :func:`allanite.model.refinement.scoring.settle_chi2`) or the RMS ADEV error falls. Not the
    RMS ADEV error alone: it weighs correlated τ alike, and where the five terms absorb an effect (a warm-up
    into R, a temperature into B, K and R) it rewards the absorption — the injected components removed exactly
    and the true noise model (the truth) score 1.01 → 1.89 % on the 25-hour temperature log, 1.41 → 1.78 % on
    the 1500 s warm-up and 0.70 → 0.91 % on the 300 s lag, while the tests' χ²/dof falls 5.3 → 1.25 on the
    first (refine: 5.3 → 1.7; the 1500 s warm-up 2.1 → 1.15, the 300 s lag 8.5 → 1.6)."""
    out: dict = {"named": True, "params": True, "param_errors": {}}
    for inj in case.injected:
        steps = [s for s in r.steps if s.effect == inj.effect]
        if not steps:
            out["named"] = out["params"] = False
            continue
        params = _step_params(steps)
        truth = dict(inj.truth) | (inj.truth_at(params, steps) if inj.truth_at is not None else {})
        for k, v in truth.items():
            if v is None:  # defined only at what was found, and nothing was
                out["params"] = False
                out["param_errors"][f"{inj.effect}.{k}"] = None
                continue
            got = params.get(k)
            if inj.effect == "regression" and k in OPTIONAL_TERMS and got is None:
                if not _optional_term_carried(steps, k):
                    out["param_errors"][f"{inj.effect}.{k}"] = "not carried"
                    continue
            tol = FREQ_TOL if k in inj.frequencies else PARAM_TOL
            ok = _close(got, v, tol)
            out["params"] &= ok
            out["param_errors"][f"{inj.effect}.{k}"] = _param_error(got, v)
    first, last = (r.steps[0], r.steps[-1]) if r.steps else (None, None)
    if first is not None:
        b, a = first.before, last.after
        out["chi2_dof"] = (b.get("chi2_dof"), a.get("chi2_dof"))
        out["rms_adev_pct"] = (b.get("rms_adev_pct"), a.get("rms_adev_pct"))
        out["heldout_rms_adev_pct"] = (b.get("heldout_rms_adev_pct"), a.get("heldout_rms_adev_pct"))
        out["falling"] = bool(a["rms_adev_pct"] < b["rms_adev_pct"] or a["chi2_dof"] < b["chi2_dof"])
        hb, ha = out["heldout_rms_adev_pct"]
        out["heldout_falling"] = hb is None or ha is None or ha < hb
    else:
        out["falling"] = out["heldout_falling"] = False
    unexplained = getattr(r, "unexplained", None)
    out["unexplained"] = unexplained
    out["explained"] = unexplained is not None and len(unexplained) == 0
    out["found"] = list(r.found)
    out["passed"] = bool(
        out["named"] and out["params"] and out["falling"] and out["heldout_falling"] and out["explained"]
    )
    return out


def candidates_without(case: Case) -> tuple:
    """The registry's candidates minus the effects injected into ``case``."""
    gone = {inj.effect for inj in case.injected}
    if "periodic" in gone:
        gone.add("sinusoid")  # an isolated-line reading of the same family is not its removal either
    return tuple(k for k in EFFECTS if k not in gone)
