"""The drift test once more beside slow lines (``_in_time.TimeRemovals.drift_beside_slow_lines``): a warm-up
beside a line whose period spans many of the drift test's block means (``benches/refine_blind8.py``'s warm-up
beside a 500 s line) — the first test, with the line in the block means, turns it down; the retest, the line
taken out by least squares and the null from that record's curve, takes it. The false-alarm side (records with a
slow line and no warm-up): ``benches/results/drift_beside_lines_null.md``."""

from __future__ import annotations

import numpy as np

import allanite
from allanite.model.refinement._slow_lines import lines_component, slow_lines
from allanite.simulation import kasdin_walter

FS, N = 10.0, 100_000  # 10⁴ s
WARM, T_WARM, LINE, PERIOD = 0.02, 900.0, 2e-3, 500.0


def _record(seed: int, warm: bool = True) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = np.arange(N) / FS
    y = allanite.simulate(N, FS, N=3e-3, K=5e-6, seed=rng) + 3e-4 * kasdin_walter(4 * N, 1.0, rng)[-N:]
    if warm:
        y = y + WARM * np.exp(-t / T_WARM)
    return y + LINE * np.sin(2 * np.pi * t / PERIOD + 1.1)


def test_a_warmup_beside_a_slow_line_is_taken_by_the_retest():
    r = allanite.refine(_record(1), FS, progress=False, candidates=("outliers", "drift", "periodic", "sinusoid"))
    first = r.considered["drift"][0]
    assert first["statistic"] < first["threshold"]  # the line in the block means: turned down
    (drift,) = [s for s in r.steps if s.effect == "drift"]
    assert abs(drift.evidence["beside_lines_hz"][0] * PERIOD - 1.0) < 0.01
    assert abs(drift.params["amplitude"] / WARM - 1.0) < 0.2
    assert abs(drift.params["T"] / T_WARM - 1.0) < 0.2
    assert "sinusoid" in r.found  # the line itself stays for the curve candidate


def test_the_slow_lines_component_is_the_lines_least_squares_fit():
    t = np.arange(N) / FS
    line = LINE * np.sin(2 * np.pi * t / PERIOD + 1.1)
    y = 0.5 + 1e-7 * t + line + 1e-4 * np.random.default_rng(3).standard_normal(N)
    got = lines_component(y, FS, [1.0 / PERIOD])
    assert np.max(np.abs(got - line)) < 0.02 * LINE  # the offset and the ramp are not the line's
    assert slow_lines(None, N / FS, []) == []
