"""Calibration of refine's Allan-curve score test on clean records, and its power on an injected effect.

The test whitens the residual of the fitted Allan curve by the estimates' covariance across τ and compares the
largest score over a family of columns with its parametric bootstrap under the fitted model. Both need the
estimates' true variances: a mixture's EDF combined per term leaves out the cross terms of its noise types and
under-states the variance of mid- and long-τ estimates of white + flicker + random walk up to 2×, and the final
"allan" check then flagged 22 % of clean 1 Hz records at a nominal 5 % (benches/results/refine_calibration.md;
on the 1 Hz records below, 32 of 60 at 10 % with the sinusoids' nulls in its family, 10 of 60 without them).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal
from scipy.linalg import solve_triangular
from scipy.stats import binom

import allanite
from allanite.model import tracing
from allanite.model.refinement.calibrated import curve_test
from allanite.model.refinement.candidates import CURVE_CANDIDATES, families
from allanite.model.refinement.curvefit import Curve, solve
from allanite.model.refinement.levels import LEVEL, alpha
from allanite.model.refinement.missing import allan_family
from allanite.model.terms import design_matrix

START = ("Q", "N", "B", "K", "R")


def _grid(n: int, fs: float, points: int = 80) -> np.ndarray:
    return np.unique(np.round(np.geomspace(1, n // 9, points)).astype(int)).astype(np.float64)


def _fitted(y: np.ndarray, fs: float, m: np.ndarray):
    """(thinned curve, score test under the five-term fit) of the record ``y`` on the τ of ``m``."""
    cur = Curve(m / fs, m, allanite.avar(y, fs, taus=m / fs).avar, fs, y.size + 1, "oavar")
    thin = tracing.thin_indices(cur.tau)
    return cur.subset(thin), curve_test(cur, thin, solve(cur, START, []), START, [], True)


def test_score_test_variances_match_the_estimates_scatter():
    # N + B + K, 2·10⁴ samples: the test's covariance at the true model against the estimates' scatter over 150
    # seeded records; with the per-term EDF the whitened long-τ residual had a variance of ≈ 1.6
    fs, n, kw = 100.0, 20_000, {"N": 2e-3, "B": 5e-4, "K": 5e-5}
    m = _grid(n, fs)
    model = design_matrix(m / fs, m, fs, START) @ np.array([0.0, 4e-6, 2.5e-7, 2.5e-9, 0.0])
    cur = Curve(m / fs, m, model, fs, n + 1, "oavar")
    thin = tracing.thin_indices(cur.tau)
    test = curve_test(cur, thin, solve(cur, START, []), START, [], True)
    w = np.array(
        [
            solve_triangular(
                test.chol,
                allanite.avar(allanite.simulate(n, fs, seed=s, **kw), fs, taus=cur.tau[thin]).avar - test.model,
                lower=True,
            )
            for s in range(150)
        ]
    )
    per_tau = np.mean(w**2, axis=0)
    half = per_tau.size // 2
    assert 0.85 < float(np.mean(per_tau[:half])) < 1.15
    assert 0.8 < float(np.mean(per_tau[half:])) < 1.2


@pytest.mark.parametrize("records", [30, pytest.param(60, marks=pytest.mark.slow)])
def test_allan_check_rejects_clean_records_at_its_level(records):
    # the final "allan" check's family (every curve candidate, the start terms' columns) on 60 seeded clean 1 Hz
    # records of N + B + K + R, read at 10 % (where 60 records resolve a rate): a calibrated test rejects 6 on
    # average, more than 13 with probability < 0.2 % (the default run: the first 30, more than 9 with < 0.2 %)
    fs, n, lv = 1.0, 20_000, 0.1
    m = _grid(n, fs)
    fam = None
    hits = 0
    for s in range(records):
        y = allanite.simulate(n, fs, N=1.5e-3, B=2e-4, K=2e-6, R=2e-9, seed=500 + s)
        sub, test = _fitted(y, fs, m)
        if fam is None:  # every record has the same τ: one family
            fam = allan_family(sub, START, True)
        hits += test.max_statistic(sub.avar, fam) > test.threshold(fam, lv, 400, seed=s)
    assert hits <= binom.isf(0.002, records, lv)


def test_threshold_is_the_monte_carlo_critical_value():
    # the ⌈(B + 1)(1 − α)⌉-th smallest of B draws: a statistic exchangeable with them exceeds it with
    # probability ≤ α
    rng = np.random.default_rng(0)
    m = _grid(100_000, 100.0)
    sub, test = _fitted(allanite.simulate(100_000, 100.0, N=2e-3, seed=rng), 100.0, m)
    fam = families(sub, ("gauss_markov",), True)
    draws = np.sort(test.null_maxima(fam, 999, seed=3))
    assert test.threshold(fam, 0.01, 999, seed=3) == draws[989]
    assert test.threshold(fam, 0.0025, 999, seed=3) == draws[997]


def test_curve_test_still_fires_on_an_injected_resonance():
    # power: a resonance σ 5e-3 at 12 Hz (Q 4) on N + K, 10⁵ samples, is far beyond the step's threshold at
    # its share of level (the statistic over the threshold ≫ 1), and the resonance's column is the one it asks for
    fs, n = 100.0, 100_000
    rho = np.exp(-np.pi * 12.0 / (4.0 * fs) + 2j * np.pi * 12.0 / fs)
    rng = np.random.default_rng(7)
    e = (rng.normal(size=n) + 1j * rng.normal(size=n)) * np.sqrt(1 - abs(rho) ** 2)
    y = allanite.simulate(n, fs, N=2e-3, K=2e-5, seed=4) + 5e-3 * signal.lfilter([1], [1, -rho], e).real
    sub, test = _fitted(y, fs, _grid(n, fs, 200))
    fam = families(sub, tuple(CURVE_CANDIDATES), True)
    thr = test.threshold(fam, alpha("curve", LEVEL), 1000, seed=0)
    res = families(sub, ("resonance",), True)
    assert test.max_statistic(sub.avar, res) > 10 * thr
    assert test.max_statistic(sub.avar, res) == test.max_statistic(sub.avar, fam)
