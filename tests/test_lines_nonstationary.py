"""The line search where the noise is not stationary (refine_blind7's pump): Welch's dof per band.

A band noise on for part of the record makes the Welch segments' powers differ there by orders of magnitude; the
average of K periodograms then scatters as one of far fewer, and with the dof of K the F test took that scatter
for lines — 24 to 39 false lines per record below, three sinusoids and two families on blind7's pump record
(:mod:`allanite.model._welch_spread`). A stationary record's dof are unchanged.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from allanite.model import lines

FS, N = 200.0, 400_000


def _pump(seed: int, line=()) -> np.ndarray:
    """White noise (2·10⁻³ °/√s) and a 20–40 Hz band noise of 0.15 °/s on for 3 × 6 % of the record."""
    rng = np.random.default_rng(seed)
    y = 2e-3 * np.sqrt(FS) * rng.standard_normal(N)
    v = signal.sosfilt(signal.butter(4, [20.0, 40.0], btype="bandpass", fs=FS, output="sos"), rng.standard_normal(N))
    t = np.arange(N) / FS
    on = np.zeros(N, dtype=bool)
    for a in (0.2, 0.5, 0.8):
        on |= (t >= a * t[-1]) & (t < (a + 0.06) * t[-1])
    y += np.where(on, 0.15 * v / v.std(), 0.0)
    for amp, f0 in line:
        y += amp * np.sin(2 * np.pi * f0 * t + 0.3)
    return y


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_band_noise_on_for_stretches_is_no_line(seed):
    found = lines.find_lines(_pump(seed), FS, 0.01)
    assert found["lines"] == []  # 24, 26, 31 lines with one dof for every band
    ps = found["passes"][-1]
    band = (ps["f"] > 22.0) & (ps["f"] < 38.0)
    assert np.all(ps["dof_bin"][band] < 0.5 * ps["dof"])  # the pump's segments: far fewer than K there
    quiet = (ps["f"] > 60.0) & (ps["f"] < 95.0)  # the band-pass's skirt leaves a few % there
    assert np.all(ps["dof_bin"][quiet] > 0.95 * ps["dof"])


def test_lines_in_and_beside_the_stretches_band_are_still_found():
    got = lines.find_lines(_pump(3, [(0.01, 10.3), (0.05, 30.7)]), FS, 0.01)["lines"]
    assert sorted(round(d["f"], 1) for d in got) == [10.3, 30.7]
    for d in got:
        assert d["amplitude"] == pytest.approx(0.01 if d["f"] < 20 else 0.05, rel=0.1)


def test_a_stationary_records_dof_are_unchanged():
    rng = np.random.default_rng(4)
    y = np.cumsum(rng.standard_normal(N)) * 1e-3 + rng.standard_normal(N)  # white and a random walk
    for ps in lines.line_spectrum(y, FS):
        assert np.all(ps["dof_bin"] == ps["dof"])
