"""The in-time tests retried beside strong lone lines (``_in_time.TimeRemovals.outliers_beside_lines`` and
``drift_confirmed_beside_lines``; ``benches/refine_blind9.py``'s spikes on a 4 Hz line): a line 8× the
per-sample σ raises the robust scale the outlier test's cut is set in and bends the five-term fit the drift's
threshold and the outliers' materiality come from. Less the line, the spikes are taken and a drift the bent fit
let through is put back. The false-alarm side (a strong line, no spikes, no warm-up) and the drift's power beside
a line: ``benches/results/lines_intime_null.md``."""

from __future__ import annotations

import numpy as np

import allanite
from allanite.model.refinement._slow_lines import lines_in_differences, lines_less
from allanite.simulation import kasdin_walter

FS, F0, AMP = 100.0, 4.0, 0.08  # the line: 8× the white noise's σ per sample (0.01 °/s)


def _record(seed: int, n: int, spikes: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = np.arange(n) / FS
    y = allanite.simulate(n, FS, N=1e-3, K=2e-6, seed=rng) + 2e-4 * kasdin_walter(4 * n, 1.0, rng)[-n:]
    y = y + AMP * np.sin(2 * np.pi * F0 * t + 0.9)
    hit = rng.choice(np.arange(10, n - 10), spikes, replace=False)
    y[hit] += 0.01 * rng.uniform(8.0, 15.0, spikes) * rng.choice([-1.0, 1.0], spikes)
    return y


def test_spikes_on_a_strong_line_are_taken_less_the_line():
    # main: the sinusoid alone (the spikes' cut set in the line's scale: turned down as immaterial)
    r = allanite.refine(_record(1, 100_000, spikes=12), FS, progress=False, candidates=("outliers", "periodic"))
    (st,) = [s for s in r.steps if s.effect == "outliers"]
    (f_line,) = st.evidence["beside_lines_hz"]
    assert abs(f_line - F0) < 1e-3
    assert abs(st.params["rate"] / 1.2e-4 - 1.0) < 0.2  # 12 spikes in 10⁵ samples


def test_a_drift_the_line_let_through_is_put_back():
    # main takes a drift of 1.1·10⁻³ °/s (statistic 56.9 against 12.3; 158.8 on the record less the line)
    r = allanite.refine(_record(10, 200_000), FS, progress=False, candidates=("drift", "periodic"))
    assert "drift" not in r.found
    (entry,) = r.considered["drift"]
    assert "not found on the samples less the lines at 4 Hz" in entry["rejected"]
    assert entry["beside_lines"]["statistic"] < entry["beside_lines"]["threshold"]


def test_lines_less_removes_the_line_and_keeps_the_offset():
    n = 300_000
    t = np.arange(n) / FS
    line = AMP * np.sin(2 * np.pi * F0 * t + 0.9)
    noise = 1e-3 * np.random.default_rng(3).standard_normal(n)
    got = lines_less(0.5 + 1e-6 * t + line + noise, FS, [F0], chunk=65_536)  # several chunks
    assert np.max(np.abs(got - (0.5 + 1e-6 * t + noise))) < 0.01 * AMP
    assert lines_in_differences(None, got, FS, []) == []
