"""The simulator: every term's Allan variance against its closed form (docs/FORMULAS.md §4.4, §5), within the
estimate's own χ² interval across τ; time-varying coefficients; bad parameters.

How the check works. For each term a few records (10⁵ and 10⁶ samples at 100 Hz, fixed seeds) are
analysed on the octave τ grid, 95 % intervals are put on every estimate with the *known* noise type
(``with_confidence(alpha=…)``, Greenhall EDF), and the closed form must fall inside. Estimates at
neighbouring τ are correlated, so misses come in runs; the tolerance is binomial-style on the pooled
τ of all records: at least 85 % inside 95 % intervals (a wrong closed form — a factor 1.5 at m = 1, a
missing 2/π — puts nearly every short-τ point outside, where the intervals are ±0.5 %).

Discrete-time effects, handled rather than skipped:

* rate random walk: the sampled walk's exact K²τ0(2m² + 1)/(6m) (1.5 × K²τ/3 at m = 1);
* flicker (bias instability): the Kasdin–Walter sequence's exact Allan variance
  2B²∫₀^½ sin⁴(πmf)/(m² sin³(πf)) df — 2/π·B² at m = 1 (1/ln 2 × the plateau), 1.5 % above the
  plateau (2 ln2/π)B² at m = 8, 0.04 % at m = 64; the plateau itself from m > 1024;
* Gauss–Markov: the discrete AR(1) form σ_w²[n − 3φ − nφ² + 4φ^(n+1) − φ^(2n+1)]/[n²(1−φ)²(1−φ²)];
* sinusoid: the m-sample average's exact Ω0²·sin²(πf0τ)·[sin(πf0τ)/(m·sin(πf0τ0))]², which tends
  to the continuous Ω0²·sin⁴(πf0τ)/(πf0τ)² (docs/FORMULAS.md §5 writes it Ω0²[sin²(πf0τ)/(πf0τ)]²);
* quantization (white angle, differenced), white rate and the ramp are exact for sampled data.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

import allanite
from allanite import ParameterError

FS = 100.0
TAU0 = 1.0 / FS
PLATEAU = 2.0 * math.log(2.0) / math.pi


# ------------------------------------------------------------------------------------------
# closed forms


def flicker_avar(m: int) -> float:
    """Allan variance of Kasdin–Walter flicker (white-noise variance 1) at averaging factor m.

    The sequence has two-sided PSD 1/(2|sin πf|) (f in cycles per sample); the Allan filter's
    |H|² is 2 sin⁴(πmf)/(m² sin²(πf)), so σ²(m) = 2∫₀^½ sin⁴(πmf)/(m² sin³(πf)) df → (2 ln2/π).
    """
    m = int(m)
    if m > 1024:
        return PLATEAU  # within 2e-6 of the integral
    f = lambda x: np.sin(np.pi * m * x) ** 4 / (m * m * np.sin(np.pi * x) ** 3)  # noqa: E731
    edges = np.append(np.arange(0, m // 2 + 1) / m, 0.5)
    return 2.0 * sum(quad(f, a, b, limit=200)[0] for a, b in zip(edges[:-1], edges[1:]) if b > a)


def ar1_avar(m, phi, sigma):
    """Discrete AR(1) of stationary std sigma (drive variance σ²(1 − φ²)), cluster of m samples."""
    m = np.asarray(m, dtype=np.float64)
    num = m - 3 * phi - m * phi**2 + 4 * phi ** (m + 1) - phi ** (2 * m + 1)
    return sigma**2 * (1 - phi**2) * num / (m**2 * (1 - phi) ** 2 * (1 - phi**2))


def sinusoid_avar(m, amp, f0):
    m = np.asarray(m, dtype=np.float64)
    x = np.pi * f0 * m * TAU0
    return amp**2 * np.sin(x) ** 2 * (np.sin(x) / (m * np.sin(np.pi * f0 * TAU0))) ** 2


def alpha_from_slope(tau, avar_model):
    """Noise type per τ from the closed form's local log-log slope μ (σ² ∝ τ^μ): α = −μ − 1,
    rounded — white rate (μ = −1) → 0, flat → −1 (flicker), μ = +1 → −2 (random walk)."""
    mu = np.gradient(np.log(avar_model), np.log(tau))
    return np.clip(np.round(-mu - 1.0), -2, 2).astype(int)


def inside_share(records, closed_form, alpha, confidence=0.95):
    """Pooled share of τ (over all records) whose closed form lies in the estimate's interval."""
    hits = []
    for y in records:
        r = allanite.avar(y, FS)
        model = closed_form(r)
        a = alpha(r, model) if callable(alpha) else alpha
        r = r.with_confidence(alpha=a, confidence=confidence)
        hits.append((r.ci_low <= model) & (model <= r.ci_high))
    return float(np.mean(np.concatenate(hits)))


def records(n_short=4, **kw):
    """n_short records of 1e5 samples and one of 1e6, fixed seeds."""
    out = [allanite.simulate(100_000, FS, seed=100 + s, **kw) for s in range(n_short)]
    out.append(allanite.simulate(1_000_000, FS, seed=7, **kw))
    return out


# ------------------------------------------------------------------------------------------
# each term against its closed form


def test_flicker_closed_form_is_the_kasdin_walter_sequence():
    # m = 1: 2/π = 1/ln 2 × the plateau; → the plateau (2 ln2/π) for large m
    assert flicker_avar(1) == pytest.approx(2.0 / math.pi, rel=1e-9)
    assert flicker_avar(8) / PLATEAU == pytest.approx(1.0154, abs=1e-3)
    assert flicker_avar(1024) / PLATEAU == pytest.approx(1.0, abs=3e-6)


@pytest.mark.parametrize(
    "name, kw, closed, alpha",
    [
        ("Q", dict(Q=1e-3), lambda r: 3 * 1e-6 / r.tau**2, 2),
        ("N", dict(N=1e-2), lambda r: 1e-4 / r.tau, 0),
        ("B", dict(B=1e-3), lambda r: 1e-6 * np.array([flicker_avar(m) for m in r.m]), -1),
        ("K", dict(K=1e-4), lambda r: 1e-8 * TAU0 * (2 * r.m**2 + 1) / (6 * r.m), -2),
    ],
)
def test_power_law_terms_match_their_closed_forms(name, kw, closed, alpha):
    share = inside_share(records(**kw), closed, alpha)
    assert share >= 0.85, f"{name}: only {share:.0%} of τ have the closed form inside the 95 % interval"


def test_wrong_closed_forms_are_rejected():
    # the check has teeth: K²τ/3 without the sampled-walk factor, and the flicker plateau at every τ
    ys = records(n_short=1, K=1e-4)
    r = allanite.avar(ys[-1], FS).with_confidence(alpha=-2, confidence=0.95)
    naive = 1e-8 * r.tau / 3
    assert not (r.ci_low[0] <= naive[0] <= r.ci_high[0])  # m = 1: off by 1.5×
    ys = records(n_short=1, B=1e-3)
    r = allanite.avar(ys[-1], FS).with_confidence(alpha=-1, confidence=0.95)
    plateau = np.full(r.tau.size, 1e-6 * PLATEAU)
    assert not np.any((r.ci_low[:3] <= plateau[:3]) & (plateau[:3] <= r.ci_high[:3]))


def test_sampled_random_walk_is_one_and_a_half_times_k2tau_over_3_at_m1():
    y = allanite.simulate(1_000_000, FS, K=1e-4, seed=3)
    r = allanite.avar(y, FS, taus=[TAU0]).with_confidence(alpha=-2, confidence=0.95)
    assert r.ci_low[0] <= 1.5 * 1e-8 * TAU0 / 3 <= r.ci_high[0]


def test_rate_ramp_is_exact():
    r_coef = 2e-5
    y = allanite.simulate(100_000, FS, R=r_coef)
    res = allanite.avar(y, FS)
    assert np.allclose(res.avar, r_coef**2 * res.tau**2 / 2, rtol=1e-6, atol=0)


def test_ramp_plus_white_noise():
    r_coef, n_coef = 2e-5, 1e-2
    closed = lambda r: n_coef**2 / r.tau + r_coef**2 * r.tau**2 / 2  # noqa: E731
    share = inside_share(records(N=n_coef, R=r_coef), closed, 0)  # the ramp adds no variance
    assert share >= 0.85


def test_gauss_markov_matches_the_discrete_ar1_form():
    sigma, tc = 0.1, 0.5
    phi = math.exp(-TAU0 / tc)
    closed = lambda r: ar1_avar(r.m, phi, sigma)  # noqa: E731
    share = inside_share(records(gauss_markov=[(sigma, tc)]), closed, lambda r, mdl: alpha_from_slope(r.tau, mdl))
    assert share >= 0.85
    # the peak of the ADEV: τ ≈ 1.893 Tc, σ ≈ 0.4365·q_c·√Tc with q_c = σ√(2/Tc) (docs/FORMULAS.md §5)
    tau = np.linspace(0.2, 3.0, 2801)
    adev = np.sqrt(ar1_avar(tau * FS, phi, sigma))
    assert tau[np.argmax(adev)] == pytest.approx(1.893 * tc, rel=0.01)
    assert adev.max() == pytest.approx(0.4365 * sigma * math.sqrt(2 / tc) * math.sqrt(tc), rel=0.01)


def test_sinusoid_matches_its_closed_form_and_nulls():
    amp, f0 = 0.5, 0.5  # nulls at τ = 2 s, 4 s, …
    y = allanite.simulate(200_000, FS, sinusoid=[(amp, f0, 0.3)])
    taus = [0.01, 0.1, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 10.0, 33.0]
    r = allanite.avar(y, FS, taus=taus)
    closed = sinusoid_avar(r.m, amp, f0)
    # deterministic: the estimate differs from the phase-averaged form by O(1/periods in the record)
    assert np.allclose(r.avar, closed, rtol=1e-2, atol=1e-3 * amp**2)
    assert r.avar[r.tau == 2.0][0] < 1e-6 * amp**2 and r.avar[r.tau == 4.0][0] < 1e-6 * amp**2
    # the continuous-time form of docs/FORMULAS.md §5, Ω0²[sin²(πf0τ)/(πf0τ)]², is the same to < 1e-3
    x = np.pi * f0 * r.tau
    assert np.allclose(closed, amp**2 * (np.sin(x) ** 2 / x) ** 2, rtol=1e-3, atol=1e-9)


def test_sum_of_terms_is_the_sum_of_closed_forms():
    kw = dict(Q=3.5e-4, N=2e-3, B=1e-3, K=6e-5)

    def closed(r):
        return (
            3 * kw["Q"] ** 2 / r.tau**2
            + kw["N"] ** 2 / r.tau
            + kw["B"] ** 2 * np.array([flicker_avar(m) for m in r.m])
            + kw["K"] ** 2 * TAU0 * (2 * r.m**2 + 1) / (6 * r.m)
        )

    def alpha(r, model):
        # the dominant term's noise type at each τ
        parts = np.vstack(
            [
                3 * kw["Q"] ** 2 / r.tau**2,
                kw["N"] ** 2 / r.tau,
                np.full(r.tau.size, kw["B"] ** 2 * PLATEAU),
                kw["K"] ** 2 * r.tau / 3,
            ]
        )
        return np.array([2, 0, -1, -2])[np.argmax(parts, axis=0)]

    share = inside_share(records(n_short=2, **kw), closed, alpha)
    assert share >= 0.85


# ------------------------------------------------------------------------------------------
# time-varying coefficients


def _segment_share(y, lo, hi, closed, alpha):
    seg = y[lo:hi]
    r = allanite.avar(seg, FS, taus=[0.01, 0.1, 1.0, 10.0]).with_confidence(alpha=alpha, confidence=0.95)
    c = closed(r)
    return (r.ci_low <= c) & (c <= r.ci_high)


def test_piecewise_white_noise_gives_each_level_locally():
    t_switch = 1_000.0  # s: sample 100 000 of 200 000
    hits = []
    for seed in range(3):
        y = allanite.simulate(200_000, FS, N=[(0.0, 1e-3), (t_switch, 4e-3)], seed=seed)
        hits.append(_segment_share(y, 0, 100_000, lambda r: 1e-6 / r.tau, 0))
        hits.append(_segment_share(y, 100_000, 200_000, lambda r: 16e-6 / r.tau, 0))
    assert np.mean(np.concatenate(hits)) >= 0.85


def test_callable_white_noise_follows_the_function():
    n = 200_000
    fn = lambda t: 1e-3 * (1.0 + 3.0 * t / (n / FS))  # noqa: E731 — N grows linearly 1e-3 → 4e-3
    hits = []
    for seed in range(3):
        y = allanite.simulate(n, FS, N=fn, seed=seed)
        for lo in range(0, n, 50_000):
            t = np.arange(lo, lo + 50_000) / FS
            n2 = float(np.mean(fn(t) ** 2))  # the segment's mean variance level
            hits.append(_segment_share(y, lo, lo + 50_000, lambda r, n2=n2: n2 / r.tau, 0))
    assert np.mean(np.concatenate(hits)) >= 0.85
    # and the levels really differ: last quarter vs first quarter, 13.19/1.94 = 6.8 in variance
    r0 = allanite.avar(y[:50_000], FS, taus=[0.1]).avar[0]
    r1 = allanite.avar(y[-50_000:], FS, taus=[0.1]).avar[0]
    t0, t1 = np.arange(50_000) / FS, np.arange(n - 50_000, n) / FS
    assert r1 / r0 == pytest.approx(np.mean(fn(t1) ** 2) / np.mean(fn(t0) ** 2), rel=0.1)


def test_piecewise_bias_instability_and_random_walk():
    y = allanite.simulate(400_000, FS, B=[(0.0, 1e-3), (2_000.0, 4e-3)], seed=5)
    first = allanite.avar(y[:200_000], FS, taus=[1.0, 10.0])
    second = allanite.avar(y[200_000:], FS, taus=[1.0, 10.0])
    assert np.allclose(second.avar / first.avar, 16.0, rtol=0.35)
    assert np.allclose(first.avar, 1e-6 * PLATEAU, rtol=0.25)
    # rate random walk: the step size is what varies; local Allan variance at short τ follows K(t)²
    y = allanite.simulate(400_000, FS, K=lambda t: np.where(t < 2_000.0, 1e-4, 3e-4), seed=6)
    a = allanite.avar(y[:200_000], FS, taus=[0.1, 1.0]).with_confidence(alpha=-2, confidence=0.95)
    b = allanite.avar(y[200_000:], FS, taus=[0.1, 1.0]).with_confidence(alpha=-2, confidence=0.95)
    rw = lambda k, r: k**2 * TAU0 * (2 * r.m**2 + 1) / (6 * r.m)  # noqa: E731
    assert np.all((a.ci_low <= rw(1e-4, a)) & (rw(1e-4, a) <= a.ci_high))
    assert np.all((b.ci_low <= rw(3e-4, b)) & (rw(3e-4, b) <= b.ci_high))


def test_piecewise_ramp_and_gauss_markov_sigma():
    # the ramp integrates R(t): the rate's slope changes at the switch
    y = allanite.simulate(20_000, FS, R=[(0.0, 1e-3), (100.0, 3e-3)])
    t = np.arange(20_000) / FS
    s1 = np.polyfit(t[:10_000], y[:10_000], 1)[0]
    s2 = np.polyfit(t[10_000:], y[10_000:], 1)[0]
    assert s1 == pytest.approx(1e-3, rel=1e-9) and s2 == pytest.approx(3e-3, rel=1e-9)
    # Gauss–Markov with a piecewise σ (paper 001's record): the std follows the profile
    sig = [(0.0, math.sqrt(1e-3)), (400.0, math.sqrt(1e-2)), (800.0, math.sqrt(1e-3))]
    y = allanite.simulate(40_000, 25.0, gauss_markov=[(sig, 0.5)], seed=8)
    t = np.arange(40_000) / 25.0
    inside, outside = y[(t > 420) & (t < 780)], y[(t < 380) | (t > 820)]
    assert np.var(inside) == pytest.approx(1e-2, rel=0.2)
    assert np.var(outside) == pytest.approx(1e-3, rel=0.2)


def test_reproducible_with_seed_and_generator():
    a = allanite.simulate(1_000, FS, N=1e-3, B=1e-4, seed=42)
    b = allanite.simulate(1_000, FS, N=1e-3, B=1e-4, seed=42)
    c = allanite.simulate(1_000, FS, N=1e-3, B=1e-4, seed=np.random.default_rng(42))
    assert np.array_equal(a, b) and np.array_equal(a, c)
    assert not np.array_equal(a, allanite.simulate(1_000, FS, N=1e-3, B=1e-4, seed=43))
    assert np.array_equal(allanite.simulate(10, FS), np.zeros(10))


# ------------------------------------------------------------------------------------------
# bad parameters


@pytest.mark.parametrize(
    "kw, message",
    [
        (dict(N=-1.0), r"N must be finite and ≥ 0 everywhere"),
        (dict(Q=float("nan")), r"Q must be finite and ≥ 0 everywhere"),
        (dict(B="big"), r"B must be a number, a callable of t or a list of \(t_start, value\) pairs"),
        (dict(K=True), r"K must be a number, a callable of t"),
        (dict(N=[]), r"N must be a number, a callable of t"),
        (dict(N=lambda t: -t), r"N must be finite and ≥ 0 everywhere"),
        (dict(N=lambda t: np.ones(3)), r"N: the callable must return a number or an array of 100 numbers"),
        (dict(K=lambda t: "x"), r"K: the callable must return a number or an array"),
        (dict(N=[(0.0, 1e-3, 5)]), r"N as a piecewise profile must be a list of \(t_start, value\) pairs"),
        (dict(N=[(0.0, "a")]), r"N as a piecewise profile must be a list of \(t_start, value\) pairs"),
        (dict(N=[(0.0, 1e-3), 2.0]), r"N as a piecewise profile must be a list"),
        (dict(N=[(float("nan"), 1e-3)]), r"N: piecewise start times must be finite seconds"),
        (dict(R=[(0.0, -1.0)]), r"R must be finite and ≥ 0 everywhere"),
        (dict(gauss_markov=[(1.0,)]), r"gauss_markov entries must be \(sigma, tc\) pairs"),
        (dict(gauss_markov=[(1.0, 0.0)]), r"gauss_markov correlation time must be a positive number of seconds"),
        (dict(gauss_markov=[(1.0, float("inf"))]), r"gauss_markov correlation time must be a positive"),
        (dict(gauss_markov=[(-1.0, 1.0)]), r"gauss_markov sigma must be finite and ≥ 0"),
        (dict(sinusoid=[(1.0,)]), r"sinusoid entries must be \(amplitude, f0\) or \(amplitude, f0, phase\)"),
        (dict(sinusoid=[1.0]), r"sinusoid entries must be"),
        (dict(sinusoid=[(1.0, -0.5)]), r"sinusoid frequency must be a positive number of Hz"),
        (dict(sinusoid=[(-1.0, 0.5)]), r"sinusoid amplitude must be finite and ≥ 0"),
        # not numbers at all: named, as the others (they raised a bare ValueError or TypeError of float())
        (dict(gauss_markov=[(1.0, "a")]), r"gauss_markov correlation time must be a positive .* got 'a'"),
        (dict(gauss_markov=[(1.0, None)]), r"gauss_markov correlation time must be a positive .* got None"),
        (dict(gauss_markov=[(1.0, -2)]), r"gauss_markov correlation time must be a positive .* got -2\.0$"),
        (dict(sinusoid=[(1.0, "a")]), r"sinusoid frequency must be a positive number of Hz, got 'a'"),
        (dict(sinusoid=[(1.0, None)]), r"sinusoid frequency must be a positive number of Hz, got None"),
        # a phase that is not a finite number made every sample NaN without a word
        (dict(sinusoid=[(1.0, 0.5, float("nan"))]), r"sinusoid phase must be a finite number of radians, got nan"),
        (dict(sinusoid=[(1.0, 0.5, "p")]), r"sinusoid phase must be a finite number of radians, got 'p'"),
    ],
)
def test_bad_parameters_raise_parameter_error(kw, message):
    with pytest.raises(ParameterError, match=message):
        allanite.simulate(100, 10.0, **kw)


@pytest.mark.parametrize(
    "n, fs, message",
    [
        (1, 10.0, r"n must be an integer ≥ 2, got 1"),
        (10.5, 10.0, r"n must be an integer ≥ 2, got 10.5"),
        (10, 0.0, r"fs must be a positive finite number"),
        (10, float("nan"), r"fs must be a positive finite number"),
    ],
)
def test_bad_size_or_rate(n, fs, message):
    with pytest.raises(ParameterError, match=message):
        allanite.simulate(n, fs, N=1.0)
