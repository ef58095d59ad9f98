"""A spectral line's amplitude is one number from acceptance to the final model, and the sensor's roll-off is
judged before the lines that would otherwise stand in for it (issue 29, items 2 and 5: ADIS16405 run 3 acc_x
and run 4 acc_z ended at χ²/dof 59 and 159)."""

from __future__ import annotations

import numpy as np
import pytest

import allanite

FS = 100.0


@pytest.fixture(scope="module")
def wandering_line():
    """A 2.7 Hz line of amplitude 4e-3 whose phase diffuses (Lorentzian width 0.02 Hz: it keeps its phase for
    ≈ 16 s of a 3000 s record) on white noise and rate random walk: the default call."""
    n = 300_000
    rng = np.random.default_rng(5)
    y = allanite.simulate(n, FS, N=2e-3, K=2e-5, seed=21)
    phase = np.cumsum(rng.normal(0.0, np.sqrt(2 * np.pi * 0.02 / FS), n))
    y += 4e-3 * np.sin(2 * np.pi * 2.7 * np.arange(n) / FS + phase)
    return allanite.refine(y, FS, progress=False)


def test_a_wandering_line_has_one_amplitude_its_power(wandering_line):
    r = wandering_line
    st = next(s for s in r.steps if s.effect == "sinusoid")
    assert abs(st.params["f0"] / 2.7 - 1) < 0.01
    # its power in the spectrum (what the Allan curve sees): the truth within 20 % — before, the step said the
    # least-squares amplitude at f0 over the whole record, 3.5e-4, a tenth of it (the phase wanders), and the
    # final model its free curve column's, 4.1e-3
    assert abs(st.params["amplitude"] / 4e-3 - 1) < 0.2
    # the part whose phase carries across the record is still reported, as evidence: well below the power's.
    # It is the least-squares amplitude at f0, so it depends on where f0 lands inside the line's 0.02 Hz width:
    # 0.02 of the power at 2.6905 Hz, 0.24 at 2.6931 Hz, where f0 lands since the family fit was changed for
    # lines inside each other's Welch width (r5f0): nearer the truth (2.7 Hz), and where the phase holds longer
    assert st.evidence["coherent_amplitude"] < 0.3 * st.params["amplitude"]
    # held in every fit of the curve: the final joint refit leaves it where it was accepted
    assert st.final_params == st.params and st.final_intervals == st.intervals
    name = [n for n in r.fit.coefficients if n.startswith("sinusoid")][0]
    assert r.fit.coefficients[name].value == pytest.approx(st.params["amplitude"], rel=1e-12)


def test_a_coherent_line_keeps_its_amplitude_in_the_final_model():
    n = 200_000
    y = allanite.simulate(n, FS, N=2e-3, K=2e-5, seed=3)
    y += 6e-3 * np.sin(2 * np.pi * 3.3 * np.arange(n) / FS)
    r = allanite.refine(y, FS, candidates=("sinusoid", "gauss_markov", "bandwidth"), progress=False)
    assert r.found == ["sinusoid"]
    st = r.steps[0]
    lo, hi = st.intervals["amplitude"]
    assert lo < 6e-3 < hi  # its power in the spectrum: the truth within ±1 SD
    assert st.final_params == st.params
    assert st.evidence["coherent_amplitude"] == pytest.approx(6e-3, rel=0.05)  # least squares at f0 agrees


@pytest.mark.parametrize(
    "run, axis, before",
    [(3, "acc_x", 59.0), pytest.param(4, "acc_z", 159.0, marks=pytest.mark.slow)],
)
def test_adis_accelerometers_take_the_roll_off_and_hold_their_lines(shared_data, run, axis, before):
    path = shared_data / "adis16405" / f"adis16405_run{run}_100Hz.csv.gz"
    if not path.is_file():
        pytest.skip(f"{path} not found")
    y = np.asarray(allanite.read_log(path, fs=FS, columns=[axis]).data, dtype=np.float64).ravel()
    r = allanite.refine(y, FS, progress=False)
    # the roll-off is in the final model: before, on run 3 the held-out error turned it down behind the lines
    # (5.01 → 6.93 %) and a broad resonance stood in (final χ²/dof 59); on run 4 the 1.61 Hz line's free curve
    # column took its place (1.4e-5 g by least squares, 5.8e-4 g on the curve; final 159)
    assert "bandwidth" in r.found
    assert r.fit.chi2_dof < 3.0 < before
    for st in r.steps:
        if st.effect == "sinusoid":  # one amplitude: measured in the samples, held in every fit
            assert st.final_params == st.params
            lo, hi = st.intervals["amplitude"]
            assert lo <= st.params["amplitude"] <= hi
