"""refine() with default arguments on data with an undeclared effect: bandwidth, drift, regression on another
channel, spectral lines — simulated and injected into real ADIS16405 noise; the calibrated test and the
held-out error."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

import allanite
from allanite.errors import ParameterError
from allanite.model.channels import regress_channel
from allanite.model.effects import (
    EFFECTS,
    drift_avar,
    filter_autocorrelation,
    filter_cutoff,
    filtered_white_avar,
    resonance_avar,
)
from allanite.model.refinement.levels import LEVEL, alpha
from allanite.model.tracing import band_component, band_regression, regression_fit, regression_heldout

FS = 100.0


_LOGS: dict = {}


def _adis(shared_data, run, cols):
    """Channels of an ADIS16405 run (each log is read once per session; callers get copies)."""
    path = shared_data / "adis16405" / f"adis16405_run{run}_100Hz.csv.gz"
    if not path.is_file():
        pytest.skip(f"{path} not found")
    key = (str(path), tuple(cols))
    if key not in _LOGS:
        log = allanite.read_log(path, fs=FS, columns=cols, unit="deg/s")
        _LOGS[key] = np.asarray(log.data, dtype=np.float64).reshape(-1, len(cols)).T
    return _LOGS[key].copy()


def _within(a, b, blocks=8):
    """Σ a·b over blocks in time, each block de-meaned (what `regression_fit`'s coefficient is made of)."""
    per = a.size // blocks
    a = a[: per * blocks].reshape(blocks, per)
    b = b[: per * blocks].reshape(blocks, per)
    return float(np.sum((a - a.mean(axis=1, keepdims=True)) * (b - b.mean(axis=1, keepdims=True))))


def _tumble(n, seed, turns):
    """A multi-position profile of n samples: ±1 g, turned every 200–600 s (seeded)."""
    edges = np.cumsum(np.random.default_rng(seed).uniform(200, 600, size=turns) * FS).astype(int)
    return np.where(np.searchsorted(edges, np.arange(n), side="right") % 2 == 0, 1.0, -1.0)


def _adis_multi_position(shared_data):
    """Run 2's gyro_x and acc_z, a zero-mean ±1 g profile (seed 5, 400 turns), the channel a multi-position
    test would record (acc_z's own noise plus the profile) and gyro_x's coefficient on the static acc_z (its
    noise coupling, part of the truth)."""
    gx, az = _adis(shared_data, 2, ["gyro_x", "acc_z"])
    tumble = _tumble(gx.size, seed=5, turns=400)
    tumble -= tumble.mean()
    ch = az - az.mean() + tumble
    return gx, az, tumble, ch, regression_fit(gx, az)["coefficient"]


def _falls(st):
    # in sample χ²/dof or the RMS ADEV error, and the held-out error. χ²/dof is the tests' GLS
    # χ² under each model's own covariance — a goodness of fit, not the chain's objective: a step the score test
    # and the held-out error accept can raise it (ADIS run 5 y + a 0.02 Hz sinusoid 1300 → 1352; a Gauss–Markov
    # term beside a multi-position g-sensitivity 3.51 → 3.90), as the suite's judge allows (tests/sensors.py)
    assert any(st.after[k] < st.before[k] for k in ("chi2_dof", "rms_adev_pct")), (st.before, st.after)
    assert st.after["heldout_rms_adev_pct"] < st.before["heldout_rms_adev_pct"]


@pytest.mark.parametrize("kind, p", [("single_pole", 5.0), ("moving_average", 4), ("bartlett", 3)])
def test_filtered_white_avar_matches_a_simulation(kind, p):
    tau = np.array([0.01, 0.02, 0.05, 0.1, 1.0])
    w = np.random.default_rng(0).normal(size=1_000_000) * np.sqrt(FS)
    if kind == "single_pole":
        a = np.exp(-2 * np.pi * p / FS)
        y = signal.lfilter([1 - a], [1, -a], w)
    else:
        h = np.ones(p) / p
        y = signal.lfilter(np.convolve(h, h) if kind == "bartlett" else h, [1], w)
    sim = allanite.avar(y, FS, taus=tau).avar
    exact = filtered_white_avar(tau, kind, p, FS)
    np.testing.assert_allclose(sim, exact, rtol=0.03)
    # unity DC gain: the curve tends to N²/τ
    assert filtered_white_avar(100.0, kind, p, FS)[0] * 100.0 == pytest.approx(1.0, rel=1e-3)


def test_boxcar_of_any_span_matches_a_simulation():
    # a boxcar of 1.4 output samples: a 14-tap average at 10× the output rate, read every 10th sample
    w = np.random.default_rng(1).normal(size=4_000_000) * np.sqrt(10 * FS)
    y = signal.lfilter(np.ones(14) / 14, [1], w)[13::10]
    tau = np.array([0.01, 0.02, 0.03, 0.05, 0.1, 1.0])
    sim, exact = allanite.avar(y, FS, taus=tau).avar, filtered_white_avar(tau, "boxcar", 1.4, FS)
    # the shape (N is the output's own long-τ white level: overlapping reads count some input twice)
    np.testing.assert_allclose(sim / sim[-1], exact / exact[-1], rtol=0.03)
    r = filter_autocorrelation("boxcar", 1.4, FS)
    assert r[1] / r[0] == pytest.approx(1 - 1 / 1.4) and r.size == 2
    # a whole span is the moving average of that many taps; the cutoff is the continuous boxcar's
    np.testing.assert_allclose(
        filter_autocorrelation("boxcar", 3.0, FS), filter_autocorrelation("moving_average", 3, FS)
    )
    assert filter_cutoff("boxcar", 2.0, FS) == pytest.approx(0.44295 * FS / 2.0)


def test_filter_cutoffs_and_drift_closed_form():
    assert filter_cutoff("moving_average", 2, FS) == pytest.approx(25.0, rel=0.01)  # cos²(πf/fs) = ½
    fc = filter_cutoff("moving_average", 4, FS)
    x = np.pi * fc / FS
    assert (np.sin(4 * x) / (4 * np.sin(x))) ** 2 == pytest.approx(0.5, abs=2e-3)  # the −3 dB point
    t = np.arange(200_000) / FS
    tau = np.array([0.01, 1.0, 10.0, 100.0])
    np.testing.assert_allclose(
        drift_avar(tau, 300.0, FS, t.size), allanite.avar(np.exp(-t / 300.0), FS, taus=tau).avar, rtol=1e-9
    )


def test_registry_documents_every_effect():
    for name in ("bandwidth", "drift", "regression", "sinusoid", "gauss_markov", "change_point", "resonance"):
        e = EFFECTS[name]
        assert e.params and all(unit is not None for _, unit, _ in e.params)
        assert name in (allanite.refine.__doc__ or "")
    assert EFFECTS["bandwidth"].params[0][:2] == ("cutoff", "Hz")
    assert EFFECTS["drift"].params[1][:2] == ("T", "s")
    assert [p[:2] for p in EFFECTS["regression"].params] == [
        ("channel", ""),
        ("coefficient", "rate unit per channel unit"),
        ("quadratic", "rate unit per channel unit²"),
        ("rate_coefficient", "rate unit per (channel unit/s)"),
        ("lag_s", "s"),
    ]


def test_finds_a_simulated_bandwidth():
    w = allanite.simulate(400_000, FS, N=2e-3, K=2e-5, seed=3)
    a = np.exp(-2 * np.pi * 8.0 / FS)
    y = signal.lfilter([1 - a], [1, -a], w)
    r = allanite.refine(y, FS)
    assert r.found[0] == "bandwidth"
    st = r.steps[0]
    assert abs(st.params["cutoff"] / 8.0 - 1) < 0.2
    # a second domain: the roll-off the filter predicts in the Welch PSD is the data's
    assert st.evidence["psd"]["predicted"] == pytest.approx(st.evidence["psd"]["measured"], rel=0.1)
    _falls(st)
    assert r.fit.coefficients["N"].value == pytest.approx(2e-3, rel=0.1)


def test_finds_a_simulated_warm_up_drift():
    n = 400_000
    t = np.arange(n) / FS
    # a warm-up that stands out on the Allan curve (ADEV ≈ 5× the noise's near τ ≈ T/2)
    y = allanite.simulate(n, FS, N=2e-3, K=2e-5, seed=6) + 0.03 * np.exp(-t / 400.0)
    r = allanite.refine(y, FS, truth={"drift": {"amplitude": 0.03, "T": 400.0}})
    st = next(s for s in r.steps if s.effect == "drift")
    assert abs(st.truth_error["T"]) < 0.2 and abs(st.truth_error["amplitude"]) < 0.2
    _falls(st)


@pytest.mark.slow  # simulated: test_finds_a_simulated_warm_up_drift
def test_finds_a_warm_up_drift_injected_into_adis_noise(shared_data):
    # run 3 gyro x has no warm-up of its own (drift statistic 2 against a threshold of ~650)
    (y,) = _adis(shared_data, 3, ["gyro_x"])
    t = np.arange(y.size) / FS
    r = allanite.refine(y + 0.2 * np.exp(-t / 600.0), FS, truth={"drift": {"amplitude": 0.2, "T": 600.0}})
    assert "drift" in r.found
    st = next(s for s in r.steps if s.effect == "drift")
    assert abs(st.truth_error["T"]) < 0.2 and abs(st.truth_error["amplitude"]) < 0.2
    lo, hi = st.intervals["T"]
    assert lo < st.params["T"] < hi
    # removed before the curve effects were searched; on the chain it comes after them and is scored with them
    # (bandwidth and what follows) in the model, with and without the drift
    assert r.found[: len(r.effects)] == st.evidence["scored_with"] and r.found[len(r.effects)] == "drift"
    # held out the drift's removal lowers the error; in sample it did only beside a Gauss–Markov term, whose
    # score (15.7 against 11.8) passed while the curve test whitened by the mixture's per-term EDF (variances up
    # to 2× too small): scored with the sinusoid and the bandwidth alone, the five terms fitted on the corrected
    # curve plus the drift's exact change fit the record's curve worse (χ²/dof 0.64 → 1.39) than the five terms
    # fitted on it — the chain's open question, not the drift's
    assert st.after["heldout_rms_adev_pct"] < st.before["heldout_rms_adev_pct"]
    assert st.after["chi2_dof"] < 2.0


def test_clean_adis_run_names_its_bandwidth_not_sinusoids(shared_data):
    (y,) = _adis(shared_data, 5, ["gyro_y"])
    r = allanite.refine(y, FS)
    assert r.found[0] == "bandwidth"
    st = r.steps[0]
    # the gyro's samples are an MA(1)-like process (lag-1 correlation ≈ 0.2, none beyond): a boxcar a little
    # longer than one sample — averaged at the part's internal rate, read at 100 Hz — not a 2-tap average
    # (lag-1 correlation 0.5), which with white angle noise on top fits the Allan curve as well
    assert st.params["filter"] == "boxcar" and 1.05 < st.params["taps"] < 2.0
    assert st.params["cutoff"] == pytest.approx(0.443 * FS / st.params["taps"], rel=1e-3)
    # the named filter predicts the measured spectrum's roll-off (Welch PSD 40–48 Hz over 2–10 Hz: 0.30;
    # a 2-tap average would say 0.04)
    f, p = signal.welch(y - y.mean(), fs=FS, nperseg=1024)
    measured = p[(f >= 40) & (f <= 48)].mean() / p[(f >= 2) & (f <= 10)].mean()
    rr = filter_autocorrelation("boxcar", st.params["taps"], FS)

    def psd(fr):
        return rr[0] + 2 * np.cos(2 * np.pi * np.outer(fr / FS, np.arange(1, rr.size))) @ rr[1:]

    assert psd(np.arange(40, 49)).mean() / psd(np.arange(2, 11)).mean() == pytest.approx(measured, rel=0.15)
    assert st.evidence["psd"]["predicted"] == pytest.approx(
        st.evidence["psd"]["measured"], rel=0.1
    )  # the same, as refine reports it
    assert "sinusoid" not in r.found and "drift" not in r.found
    _falls(st)
    assert st.before["chi2_dof"] > 100 and st.after["chi2_dof"] < 2


@pytest.mark.slow  # ADIS bandwidth: test_clean_adis_run_names_its_bandwidth...
def test_roll_off_is_kept_where_the_record_reproduces_itself(shared_data):
    # run 1 y: over every informative τ the held-out error rose with the bandwidth (7.24 → 7.83 %), decided by
    # τ ≥ 40 s where the two parts differ by more than ±20 %; scored where they agree, it falls
    (y,) = _adis(shared_data, 1, ["gyro_y"])
    r = allanite.refine(y, FS)
    assert r.found[0] == "bandwidth" and r.steps[0].params["filter"] == "boxcar"
    _falls(r.steps[0])
    # on the tests' covariance (the chain's χ²/dof since it is the acceptance tests' GLS χ²): 1.21, nothing left
    # unexplained; with the EDF variances, which leave out the noise types' cross terms, it had read 0.38
    assert r.steps[0].after["chi2_dof"] < 1.5 and not r.unexplained


@pytest.mark.slow  # ADIS bandwidth: the clean run and the single pole
def test_adis_through_an_injected_decimation_filter(shared_data):
    # the ADIS run filtered by a further 8-tap moving average: the cascade (−3 dB at 5.46 Hz) is named a
    # bandwidth with its cutoff (the nearest of the family: a Bartlett FIR)
    (y,) = _adis(shared_data, 5, ["gyro_y"])
    z = signal.lfilter(np.ones(8) / 8, [1], y - y.mean())
    r = allanite.refine(z, FS)
    st = r.steps[0]
    assert st.effect == "bandwidth" and abs(st.params["cutoff"] / 5.46 - 1) < 0.2
    _falls(st)


def test_adis_through_an_injected_single_pole(shared_data):
    # a 5 Hz single pole after the part's own averaging: named as the cascade, its −3 dB point within 20 %
    (y,) = _adis(shared_data, 5, ["gyro_y"])
    a = np.exp(-2 * np.pi * 5.0 / FS)
    r = allanite.refine(signal.lfilter([1 - a], [1, -a], y - y.mean()), FS, truth={"bandwidth": {"cutoff": 5.0}})
    st = r.steps[0]
    assert st.effect == "bandwidth" and st.params["filter"] == "single_pole+boxcar"
    assert abs(st.truth_error["cutoff"]) < 0.2 and abs(st.params["pole_cutoff"] / 5.0 - 1) < 0.2
    _falls(st)
    assert st.after["chi2_dof"] < 3


def test_cascade_matches_a_simulation():
    # a 1.4-sample boxcar (a 14-tap average at 10× the rate, read every 10th sample), then a 5 Hz single pole
    w = np.random.default_rng(2).normal(size=4_000_000)
    b = signal.lfilter(np.ones(14) / 14, [1], w)[13::10]
    a = np.exp(-2 * np.pi * 5.0 / FS)
    y = signal.lfilter([1 - a], [1, -a], b)
    tau = np.array([0.01, 0.02, 0.05, 0.1, 0.2, 1.0])
    sim = allanite.avar(y, FS, taus=tau).avar
    exact = filtered_white_avar(tau, "single_pole+boxcar:1.4", 5.0, FS)
    np.testing.assert_allclose(sim / sim[-1], exact / exact[-1], rtol=0.03)


@pytest.mark.slow  # a line: test_refine.py's test_finds_an_undeclared_sinusoid
def test_adis_with_injected_sinusoid_at_0p02_hz(shared_data):
    # issue 16: run 5 y + 0.03 °/s at 0.02 Hz was not found with default arguments (f0 reported 1.54 Hz)
    (y,) = _adis(shared_data, 5, ["gyro_y"])
    t = np.arange(y.size) / FS
    sn = {"amplitude": 0.03, "f0": 0.02}
    r = allanite.refine(y + sn["amplitude"] * np.sin(2 * np.pi * sn["f0"] * t + 0.3), FS, truth={"sinusoid": sn})
    st = next(s for s in r.steps if s.effect == "sinusoid")
    assert abs(st.truth_error["f0"]) < 0.02 and abs(st.truth_error["amplitude"]) < 0.2
    assert st.evidence["domain"] == "psd"
    assert r.found.count("sinusoid") == 1
    _falls(st)


@pytest.mark.slow  # two effects: test_two_effects_at_once
def test_adis_with_injected_gauss_markov_and_g_sensitivity(shared_data):
    # two effects at once in real noise: a Gauss–Markov rate and a g-sensitivity through the accelerometer
    gx, az = _adis(shared_data, 2, ["gyro_x", "acc_z"])
    gm = {"sigma": 0.05, "tc": 20.0}
    g_sens = 2.0  # °/s per g: large, so that its Allan curve shows (the static log's acc_z is mostly noise)
    y = gx + allanite.simulate(gx.size, FS, gauss_markov=[(gm["sigma"], gm["tc"])], seed=8) + g_sens * az
    # the clean log already couples gyro_x to acc_z (within 500-s blocks ≈ 0.42 °/s per g, t ≈ 5.4 over 8
    # blocks: what the data really has; across the whole record, slow drifts the two share made it 1.03);
    # the injected sensitivity adds to it
    base = regression_fit(gx, az)["coefficient"]
    assert base == pytest.approx(0.42, abs=0.05)
    r = allanite.refine(
        y, FS, channels={"acc_z": az}, truth={"gauss_markov": gm, "regression": {"coefficient": g_sens + base}}
    )
    st = next(s for s in r.steps if s.effect == "gauss_markov")
    assert abs(st.truth_error["tc"]) < 0.2 and abs(st.truth_error["sigma"]) < 0.2
    assert st.evidence["autocorrelation"]["tc"] == pytest.approx(gm["tc"], rel=0.2)  # in time, too
    _falls(st)
    rg = next(s for s in r.steps if s.effect == "regression")
    assert rg.params["channel"] == "acc_z" and abs(rg.truth_error["coefficient"]) < 0.2
    # held out in time: each half's coefficient lowers the other half's variance — what decides a regression.
    # On the Allan curve a white-like component is absorbed by N: the in-sample RMS error falls (0.71 → 0.63 %)
    # but χ²/dof (≈ 0.5) and the held-out curve error (3.39 → 3.45 %) stay within their scatter
    # (docs/refinement.md)
    assert rg.evidence["heldout_variance_ratio"] < 1.0
    assert rg.after["rms_adev_pct"] < rg.before["rms_adev_pct"]
    assert rg.after["heldout_rms_adev_pct"] == pytest.approx(rg.before["heldout_rms_adev_pct"], rel=0.05)


def test_band_regression_keeps_one_coefficient_unless_the_bands_differ():
    rng = np.random.default_rng(1)
    n = 400_000
    a = rng.normal(size=n)
    # one coupling at every frequency: no band keeps its own, the component is c·(a − mean) exactly
    y = rng.normal(size=n) + 0.5 * a
    br = band_regression(y, a, FS, 0.01)
    assert not any(b["own"] for b in br["bands"]) and br["coefficient"] == pytest.approx(0.5, abs=0.01)
    np.testing.assert_array_equal(band_component(a - a.mean(), br["used"]), br["coefficient"] * (a - a.mean()))
    # the bands sum to the channel, and they span 0 … fs/2
    assert sum(b["f_hi"] - b["f_lo"] for b in br["bands"]) == pytest.approx(FS / 2)
    # a coupling of 1 above 10 Hz and of 0.05 below (the whole-record coefficient, 0.81, fits neither): the
    # bands away from 10 Hz find their own, and the residual falls
    hi = signal.sosfiltfilt(signal.butter(8, 10.0, "high", fs=FS, output="sos"), a)
    noise = 0.3 * rng.normal(size=n)
    y = noise + 0.05 * (a - hi) + 1.0 * hi
    br = band_regression(y, a, FS, 0.01)
    assert br["coefficient"] == pytest.approx(0.81, abs=0.02)
    top = [b for b in br["bands"] if b["f_lo"] >= 12.5]
    low = [b for b in br["bands"] if b["f_hi"] <= 6.25 and b["se"] < 0.005]  # well-determined ones
    assert len(top) == 2 and all(b["own"] and b["coefficient"] == pytest.approx(1.0, abs=0.02) for b in top)
    assert len(low) >= 3 and all(b["own"] and b["coefficient"] == pytest.approx(0.05, abs=0.015) for b in low)
    one = np.var(y - y.mean() - br["coefficient"] * (a - a.mean()))
    banded = np.var(y - y.mean() - band_component(a - a.mean(), br["used"]))
    assert banded < 0.8 * one
    assert regression_heldout(y, a, FS, 0.01) < regression_heldout(y, a)


@pytest.mark.slow  # simulated: test_simulated_multi_position_g_sensitivity
def test_adis_multi_position_g_sensitivity(shared_data):
    # a realistic g-sensitivity test: acc_z turned between ±1 g every 200–600 s, the gyro responding to the
    # true acceleration at 0.01 °/s/g (the log's own noise and its coupling to acc_z's noise kept)
    gx, az, tumble, ch, base = _adis_multi_position(shared_data)
    truth = _within(0.01 * tumble + base * az, ch) / _within(ch, ch)
    r = allanite.refine(gx + 0.01 * tumble, FS, channels={"acc_z": ch}, truth={"regression": {"coefficient": truth}})
    rg = next(s for s in r.steps if s.effect == "regression")
    assert abs(rg.truth_error["coefficient"]) < 0.2
    assert rg.evidence["heldout_variance_ratio"] < 1.0
    _falls(rg)


@pytest.mark.slow  # simulated: test_simulated_multi_position_...
def test_adis_gauss_markov_and_multi_position_g_sensitivity_at_once(shared_data):
    # two effects at once in real noise: a Gauss–Markov rate and a g-sensitivity seen through a ±1 g
    # multi-position profile. The regression goes first (its test is in time): left in, the profile's steps
    # would be taken by the Gauss–Markov term
    gx, az, tumble, ch, base = _adis_multi_position(shared_data)
    gm = {"sigma": 0.05, "tc": 20.0}
    y = gx + allanite.simulate(gx.size, FS, gauss_markov=[(gm["sigma"], gm["tc"])], seed=8) + 0.03 * tumble
    truth = {
        "gauss_markov": gm,
        "regression": {"coefficient": _within(0.03 * tumble + base * az, ch) / _within(ch, ch)},
    }
    r = allanite.refine(y, FS, channels={"acc_z": ch}, truth=truth)
    assert "regression" in r.found and "gauss_markov" in r.found
    # searched first, scored after the curve effects (the chain's order): with the Gauss–Markov term in the model
    assert "gauss_markov" in next(s for s in r.steps if s.effect == "regression").evidence["scored_with"]
    for effect in ("regression", "gauss_markov"):
        st = next(s for s in r.steps if s.effect == effect)
        assert all(abs(v) < 0.2 for v in st.truth_error.values()), (effect, st.truth_error)
        _falls(st)


def _multi_position(n: int = 400_000):
    """A 4000-s multi-position test in simulated noise (white + random walk of rate): the gyro responds to ±1 g
    turns every 200–600 s at 0.01 °/s/g; (the noise, the coupling's component, the accelerometer)."""
    tumble = _tumble(n, seed=9, turns=200)
    acc = tumble + 2e-3 * np.random.default_rng(10).normal(size=n)
    return allanite.simulate(n, FS, N=2e-3, K=2e-5, seed=12), 0.01 * tumble, acc


def test_simulated_multi_position_g_sensitivity():
    # Most 500-s blocks see one turn or none, so the coefficient is weighed within blocks (a per-block-coefficient
    # error put t at 1.3 here; within blocks it is ≈ 220)
    noise, comp, acc = _multi_position()
    y = noise + comp
    truth = _within(comp, acc) / _within(acc, acc)
    r = allanite.refine(y, FS, channels={"acc_z": acc}, truth={"regression": {"coefficient": truth}})
    rg = next(s for s in r.steps if s.effect == "regression")
    assert abs(rg.truth_error["coefficient"]) < 0.2
    assert rg.evidence["test"]["t"] > 10 * rg.evidence["test"]["threshold"]
    _falls(rg)
    # and the same record without the coupling: the regression refine tries turns it down at refine's own share
    # of the level (statistic 1.1 against its threshold 12.9); refine on it (2 s more): the slow twin below
    r0 = regress_channel(noise, acc, FS, name="acc_z", alpha=alpha("regression", LEVEL), level=LEVEL)
    assert not r0.accepted and r0.test["statistic"] < r0.test["threshold"]


@pytest.mark.slow  # the default run tests the same null record's regression alone (above)
def test_simulated_multi_position_without_the_coupling_adds_nothing():
    noise, _comp, acc = _multi_position()
    assert "regression" not in allanite.refine(noise, FS, channels={"acc_z": acc}).found


def test_calibrated_test_and_heldout_are_reported():
    # on samples, the calibrated test's score against its threshold and the held-out error before and after are
    # test_refine.py::test_finds_an_undeclared_gauss_markov's (a refine of samples fewer here: 1.5 CPU s)
    y = allanite.simulate(200_000, FS, N=2e-3, K=2e-5, gauss_markov=[(6e-3, 5.0)], seed=12)
    # curve-only input: no held-out error, and the result says so
    c = allanite.refine(allanite.avar(y, FS, taus=allanite.tau_grid(y.size, FS, "exp", points=300)))
    assert c.found[:1] == ["gauss_markov"]
    assert c.steps[0].evidence["test"]["gls_score"] > c.steps[0].evidence["test"]["threshold"] > 0
    assert c.start_heldout_rms_adev_pct is None and "no held-out error" in c.heldout_note
    assert all(s.after["heldout_rms_adev_pct"] is None for s in c.steps)


def test_tau_range_auto_and_bad_arguments():
    y = allanite.simulate(100_000, FS, N=2e-3, K=2e-5, seed=1)
    r = allanite.refine(y, FS, tau_range="auto")
    assert r.tau_range[0] >= 0.0 and not r.steps
    with pytest.raises(ParameterError, match="tau_range"):
        allanite.refine(y, FS, tau_range="all")
    with pytest.raises(ParameterError, match="level"):
        allanite.refine(y, FS, level=1.5)
    with pytest.raises(ParameterError, match="channel 'T'"):
        allanite.refine(y, FS, channels={"T": y[:10]})
    with pytest.raises(ParameterError, match="channels need samples"):
        allanite.refine(allanite.avar(y, FS), channels={"T": y})


def _narrowband(n, f_r, q, sigma, seed):
    """Narrowband noise with autocorrelation σ²·e^{−πf_r·l/(q·f_s)}·cos(2πf_r·l/f_s): a complex AR(1)'s real part."""
    rho = np.exp(-np.pi * f_r / (q * FS) + 2j * np.pi * f_r / FS)
    rng = np.random.default_rng(seed)
    e = (rng.normal(size=n) + 1j * rng.normal(size=n)) * np.sqrt(1 - abs(rho) ** 2)
    return sigma * signal.lfilter([1], [1, -rho], e).real


def test_resonance_avar_matches_a_simulation():
    y = _narrowband(2_000_000, 20.0, 2.0, 1.0, 0)
    tau = np.array([0.01, 0.02, 0.03, 0.05, 0.1, 0.2, 1.0])
    np.testing.assert_allclose(
        allanite.avar(y, FS, taus=tau).avar / y.var(), resonance_avar(tau, 20.0, 2.0, FS), rtol=0.02
    )
    # the closed geometric sums equal the lag sum Σ_l A_m(l)·R(l)/2m² term by term
    m = 7
    lag = np.arange(-400, 401)
    r = np.exp(-np.pi * 20.0 * np.abs(lag) / (2.0 * FS)) * np.cos(2 * np.pi * 20.0 * lag / FS)
    tri = lambda x: np.maximum(0, m - np.abs(x))  # noqa: E731
    direct = np.sum((2 * tri(lag) - tri(lag - m) - tri(lag + m)) * r) / (2 * m * m)
    assert resonance_avar(m / FS, 20.0, 2.0, FS)[0] == pytest.approx(direct, rel=1e-12)


def test_finds_a_simulated_resonance():
    n = 400_000
    y = allanite.simulate(n, FS, N=2e-3, K=2e-5, seed=4) + _narrowband(n, 12.0, 4.0, 1e-2, 7)
    r = allanite.refine(y, FS, truth={"resonance": {"sigma": 1e-2, "f0": 12.0}})
    assert r.found == ["resonance"]
    st = r.steps[0]
    assert abs(st.truth_error["f0"]) < 0.02 and abs(st.truth_error["sigma"]) < 0.2 and st.params["q"] == 4.0
    # the band-pass shape was offered (its nested test asked) and the simulated Lorentzian kept
    assert st.params["shape"] == "lorentzian" and st.evidence["shape_test"]["tested"] is True
    lo, hi = st.intervals["f0"]
    assert lo <= 12.0 <= hi or abs(st.truth_error["f0"]) < 0.005
    _falls(st)


@pytest.mark.slow  # simulated: test_finds_a_simulated_resonance
def test_adis_z_gyro_hump_is_a_resonance(shared_data):
    # the z gyros' broad PSD hump near 20 Hz (5× the floor from ~18 to ~23 Hz): named a resonance there
    (y,) = _adis(shared_data, 1, ["gyro_z"])
    r = allanite.refine(y, FS)
    st = next(s for s in r.steps if s.effect == "resonance")
    assert 18.0 < st.params["f0"] < 23.0 and st.params["q"] >= 4
    _falls(st)


def test_leftover_lines_are_reported_as_bands_not_one_entry_per_line():
    # a comb of five weak lines 0.2 Hz apart near 10 Hz and a lone line at 31 Hz left in the final samples: two
    # entries (the comb's band with its count and rms, the lone line), not six
    from types import SimpleNamespace

    from allanite.model.refinement import missing

    fs, n = 100.0, 2**17
    t = np.arange(n) / fs
    rng = np.random.default_rng(3)
    comb = [9.6 + 0.2 * i for i in range(5)]
    y = rng.normal(size=n) + sum(0.1 * np.sin(2 * np.pi * f * t + i) for i, f in enumerate(comb))
    y = y + 0.2 * np.sin(2 * np.pi * 31.0 * t)  # at 0.1 it would move τ₀'s estimate by 1.8 SE only: immaterial
    tau = np.geomspace(0.01, 100.0, 40)
    m = np.maximum(np.round(tau * fs), 1.0)
    # the final model: the unit white noise (AVAR 1/m, EDF ≈ n/m); the lines move its curve by far more than 2 SE
    sol = SimpleNamespace(z=np.ones(40), model=1.0 / m, nu=n / m)
    ctx = SimpleNamespace(y=y, fs=fs, effects=[], curve=SimpleNamespace(tau=tau), sol=sol, slow_lines=[])
    ctx.considered, ctx.offered_lines = {"sinusoid": [{"param": 31.0, "statistic": 9.0, "threshold": 3.0}]}, comb
    out = missing._lines(ctx, 1e-3)
    assert len(out) == 2
    band, lone = sorted(out, key=lambda r: r["band_hz"][0])
    assert band["lines"] == 5 and band["band_hz"][0] < 9.6 < 10.4 < band["band_hz"][1] < 10.5
    assert band["rms"] == pytest.approx(0.1 * np.sqrt(5 / 2), rel=0.2) and "5 spectral lines" in band["what"]
    assert lone["lines"] == 1 and lone["band_hz"][0] < 31.0 < lone["band_hz"][1] and "a spectral line" in lone["what"]
    # each entry says why the sinusoid candidate did not keep it: tested and turned down, or never reached
    assert (
        lone["not_kept"] == "tested as a sinusoid (31 Hz) and not kept: not taken" and lone["not_kept"] in lone["what"]
    )
    assert band["not_kept"].startswith("the sinusoid search found them but no step tested them")


def test_unexplained_says_why_refine_did_not_keep_a_line_it_names():
    # a short 7.3 Hz record (2·10⁴ samples) with a weak 2.9 Hz line and a step of the mean: refine tested the line as
    # a sinusoid and turned it down by the held-out error, and unexplained named "a spectral line at 2.9 Hz" as if
    # nothing had looked at it. It now says why it was not kept (docs/refinement.md, "What the model still misses")
    from types import SimpleNamespace

    from allanite.model.refinement.missing import why_not_kept

    fs, n = 7.3, 20_000
    y = allanite.simulate(n, fs, N=0.01, K=1e-4, seed=1) + 0.3 * 0.01 * np.sqrt(fs) * np.sin(
        2 * np.pi * 2.9 * np.arange(n) / fs + 0.3
    )
    y[n // 2 :] += 0.5 * 0.01 * np.sqrt(fs)
    r = allanite.refine(y, fs, progress=False)
    (tried,) = [e for e in r.considered["sinusoid"] if abs(e["param"] - 2.9) < 0.01]
    assert tried["rejected"].startswith("held-out error") and not any(s.effect == "sinusoid" for s in r.steps)
    (said,) = [u for u in r.unexplained if u["domain"] == "psd"]
    assert said["band_hz"][0] < 2.9 < said["band_hz"][1]
    assert said["not_kept"] == f"tested as a sinusoid (2.9 Hz) and not kept: {tried['rejected']} (a step must lower it)"
    assert said["not_kept"] in r.missing_sentences()[0]
    # the other reasons, on the context alone: left out, found but never offered, not found
    ctx = SimpleNamespace(considered={}, offered_lines=None)
    assert (
        why_not_kept(ctx, (2.8, 3.0))
        == "the sinusoid candidate was not among the candidates refine ran, so no line was tested"
    )
    ctx.offered_lines = [2.9]
    assert "the sinusoid search found it but no step tested it" in why_not_kept(ctx, (2.8, 3.0))
    assert "did not find it" in why_not_kept(ctx, (3.1, 3.2))


def test_why_not_kept_reads_a_line_left_to_a_channel():
    # the removal in time records a line of few cycles that a channel explains as {"f0", "amplitude", "rejected",
    # "explained_by", ...} — no "param", no statistic: blind2's thermal chamber (1 Hz, T and dT/dt) raised KeyError
    # 'param' in unexplained once the slow-line test's second reading found the chamber's cycle
    from types import SimpleNamespace

    from allanite.model.refinement.missing import why_not_kept

    left = {"f0": 1.2e-3, "amplitude": 0.4, "rejected": "a channel's", "explained_by": "temp"}
    tested = {"param": 2.9, "statistic": 5.0, "threshold": 3.0, "rejected": "not taken: drift was taken at this step"}
    ctx = SimpleNamespace(considered={"sinusoid": [left, tested]}, offered_lines=[2.9])
    assert why_not_kept(ctx, (1e-3, 1.5e-3)) == (
        "a line of few cycles there (0.0012 Hz) was left to channel 'temp', which explains it in time"
    )
    assert why_not_kept(ctx, (2.8, 3.0)).startswith("tested as a sinusoid (2.9 Hz) and not kept: not taken")
