"""allanite.to_kalibr: Kalibr / ROS imu.yaml from per-axis noise fits — checked against a hand computation
(the fitted N, K converted to SI by hand), against the conversions of Kalibr's IMU noise model documentation
(a sensor simulated the way that page defines its discrete-time noise must give back its continuous-time
densities), and on a real ADIS16405 run (gyro °/s, accelerometer g)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import allanite
from allanite.errors import ParameterError
from allanite.kalibr import kalibr_values
from allanite.units import STANDARD_GRAVITY, accel_factor

yaml = pytest.importorskip("yaml")

FS = 200.0


def kalibr_sensor(rng, n, sigma_c, sigma_bc, fs=FS):
    """Kalibr's discrete-time model (its wiki, "IMU Noise Model"): white noise of σ_d = σ/√Δt and a bias
    random walk with steps of σ_b,d = σ_b·√Δt, for continuous-time densities σ, σ_b."""
    dt = 1.0 / fs
    white = sigma_c / math.sqrt(dt) * rng.standard_normal(n)
    bias = np.cumsum(sigma_bc * math.sqrt(dt) * rng.standard_normal(n))
    return white + bias


def fits_of(y, unit=None):
    r = allanite.avar(y, FS)
    return (
        [allanite.fit(r, terms=("N", "B", "K"), unit=unit)]
        if y.ndim == 1
        else allanite.fit(r, terms=("N", "B", "K"), unit=unit)
    )


def read(path):
    text = path.read_text(encoding="utf-8")
    return yaml.safe_load(text), text


@pytest.fixture(scope="module")
def imu():
    rng = np.random.default_rng(18)
    n = 400_000  # 2000 s at 200 Hz
    gyro_true = [(1e-3, 2e-5), (2e-3, 1e-5), (1.5e-3, 4e-5)]  # rad/s/√Hz, rad/s²/√Hz
    acc_true = [(2e-3, 3e-4), (1e-3, 1e-4), (4e-3, 2e-4)]  # m/s²/√Hz, m/s³/√Hz
    g = np.column_stack([kalibr_sensor(rng, n, a, b) for a, b in gyro_true]) * (180 / math.pi)  # in deg/s
    a = np.column_stack([kalibr_sensor(rng, n, s, b) for s, b in acc_true]) / STANDARD_GRAVITY  # in g
    return {"gyro": fits_of(g, "deg/s"), "accel": fits_of(a), "gyro_true": gyro_true, "acc_true": acc_true}


def test_hand_computation_and_kalibr_conversions(imu, tmp_path):
    p = allanite.to_kalibr(
        tmp_path / "imu.yaml", gyro=imu["gyro"], accel=imu["accel"], update_rate=FS, accel_unit="g", rostopic="/imu"
    )
    y, text = read(p)
    # by hand: N, K in the samples' units (°/√s, °/s^1.5; g·√s, g/√s) → SI, the worst axis
    gN = max(f.coefficients["N"].value for f in imu["gyro"]) * math.pi / 180
    gK = max(f.coefficients["K"].value for f in imu["gyro"]) * math.pi / 180
    aN = max(f.coefficients["N"].value for f in imu["accel"]) * 9.80665
    aK = max(f.coefficients["K"].value for f in imu["accel"]) * 9.80665
    assert y["gyroscope_noise_density"] == pytest.approx(gN, rel=1e-6)  # written with 7 digits
    assert y["gyroscope_random_walk"] == pytest.approx(gK, rel=1e-6)
    assert y["accelerometer_noise_density"] == pytest.approx(aN, rel=1e-6)
    assert y["accelerometer_random_walk"] == pytest.approx(aK, rel=1e-6)
    assert y["update_rate"] == FS and y["rostopic"] == "/imu"
    # Kalibr's page: the densities of the simulated sensor come back (worst axis: 2e-3, 4e-5; 4e-3, 3e-4)
    assert y["gyroscope_noise_density"] == pytest.approx(2e-3, rel=0.02)
    assert y["gyroscope_random_walk"] == pytest.approx(4e-5, rel=0.35)
    assert y["accelerometer_noise_density"] == pytest.approx(4e-3, rel=0.02)
    assert y["accelerometer_random_walk"] == pytest.approx(3e-4, rel=0.35)
    # every axis, B and the intervals in the comment block, with the version and the τ range
    assert f"allanite {allanite.__version__}" in text
    assert text.count("axis 2:") == 6 and "bias instability B (not a Kalibr field)" in text
    assert "tau range fitted" in text and "interval [" in text and "  tau 0." in text


def test_per_axis_recovers_each_density(imu):
    vals = kalibr_values(imu["gyro"], "gyroscope")
    for ax, (sn, _sk) in zip(vals["N"]["axes"], imu["gyro_true"]):
        assert ax["value"] == pytest.approx(sn, rel=0.02)
        assert ax["ci"][0] <= ax["value"] <= ax["ci"][1]
    vals = kalibr_values(imu["accel"], "accelerometer", unit="g")
    for ax, (sn, _sk) in zip(vals["N"]["axes"], imu["acc_true"]):
        assert ax["value"] == pytest.approx(sn, rel=0.02)


def test_mean_aggregate_as_imu_utils(imu, tmp_path):
    y, _ = read(allanite.to_kalibr(tmp_path / "m.yaml", gyro=imu["gyro"], update_rate=FS, aggregate="mean"))
    want = np.mean([f.coefficients["N"].value for f in imu["gyro"]]) * math.pi / 180
    assert y["gyroscope_noise_density"] == pytest.approx(want, rel=1e-6)
    assert "accelerometer_noise_density" not in y  # none given: the file says Kalibr needs them
    assert "NOTE: no accelerometer fits" in (tmp_path / "m.yaml").read_text()


def test_unidentifiable_K_uses_the_upper_bound_flagged(tmp_path):
    rng = np.random.default_rng(5)
    y = rng.standard_normal(20_000) * 0.1  # white only, short: K's interval reaches 0
    f = allanite.fit(allanite.avar(y, FS), terms=("N", "K"), unit="deg/s")
    assert f.coefficients["K"].ci[0] == 0
    out, text = read(allanite.to_kalibr(tmp_path / "k.yaml", gyro=f, update_rate=FS))
    assert out["gyroscope_random_walk"] == pytest.approx(f.coefficients["K"].ci[1] * math.pi / 180, rel=1e-6)
    assert "WARNING: gyroscope axis 0: K is not identifiable" in text
    assert "gyroscope_random_walk: " in text and "# upper bound: not identifiable" in text


def test_bad_arguments_are_named(imu, tmp_path):
    with pytest.raises(ParameterError, match="aggregate must be one of"):
        allanite.to_kalibr(tmp_path / "x.yaml", gyro=imu["gyro"], update_rate=FS, aggregate="max")
    with pytest.raises(ParameterError, match="update_rate must be a positive"):
        allanite.to_kalibr(tmp_path / "x.yaml", gyro=imu["gyro"], update_rate=0)
    with pytest.raises(ParameterError, match="gyro fits carry no unit"):
        allanite.to_kalibr(tmp_path / "x.yaml", gyro=imu["accel"], update_rate=FS)
    with pytest.raises(ParameterError, match="unknown accelerometer unit 'gal'"):
        allanite.to_kalibr(tmp_path / "x.yaml", gyro=imu["gyro"], accel=imu["accel"], update_rate=FS, accel_unit="gal")
    with pytest.raises(ParameterError, match="must be a NoiseFit"):
        allanite.to_kalibr(tmp_path / "x.yaml", gyro=[1, 2], update_rate=FS)
    assert accel_factor("mg") == pytest.approx(9.80665e-3, rel=1e-15)


def test_adis16405_run(shared_data, tmp_path):
    path = shared_data / "adis16405" / "adis16405_run1_100Hz.csv.gz"
    if not path.exists():
        pytest.skip(f"{path} not present")
    log = allanite.read_log(path, fs=100.0)
    x = log.data[:300_000]  # 3000 s keeps the test fast
    names = list(log.columns)
    gi = [names.index(c) for c in ("gyro_x", "gyro_y", "gyro_z")]
    ai = [names.index(c) for c in ("acc_x", "acc_y", "acc_z")]
    gf = allanite.fit(allanite.avar(x[:, gi], 100.0), terms=("N", "B", "K"), unit="deg/s", tau_range="auto")
    af = allanite.fit(allanite.avar(x[:, ai], 100.0), terms=("N", "B", "K"), tau_range="auto")
    y, text = read(allanite.to_kalibr(tmp_path / "adis.yaml", gyro=gf, accel=af, update_rate=100, accel_unit="g"))
    assert y["gyroscope_noise_density"] == pytest.approx(
        max(f.coefficients["N"].value for f in gf) * math.pi / 180, rel=1e-6
    )
    assert y["accelerometer_noise_density"] == pytest.approx(
        max(f.coefficients["N"].value for f in af) * 9.80665, rel=1e-6
    )
    # the ADIS16405 datasheet's order of magnitude: ARW ≈ 2 °/√h (5.8e-4 rad/s/√Hz), VRW ≈ 0.2 m/s/√h (3e-3)
    assert 1e-4 < y["gyroscope_noise_density"] < 1e-2
    assert 3e-4 < y["accelerometer_noise_density"] < 3e-2


def test_cli_report_writes_kalibr_yaml(tmp_path):
    from allanite.cli import main

    rng = np.random.default_rng(7)
    n = 40_000
    g = np.column_stack([kalibr_sensor(rng, n, 1e-3, 2e-5, fs=100.0) for _ in range(3)]) * (180 / math.pi)
    a = np.column_stack([kalibr_sensor(rng, n, 2e-3, 1e-4, fs=100.0) for _ in range(3)]) / STANDARD_GRAVITY
    path = tmp_path / "imu.npz"
    np.savez(path, data=np.column_stack([g, a]))
    out = tmp_path / "rep"
    yml = tmp_path / "imu.yaml"
    argv = [
        "report", str(path), "--fs", "100", "--columns", "0,1,2", "--unit", "deg/s", "--accel-columns", "3,4,5",
        "--accel-unit", "g", "--kalibr", str(yml), "--out", str(out), "-q",
    ]  # fmt: skip
    assert main(argv) == 0
    y, text = read(yml)
    assert y["gyroscope_noise_density"] == pytest.approx(1e-3, rel=0.05)
    assert y["accelerometer_noise_density"] == pytest.approx(2e-3, rel=0.05)
    assert y["update_rate"] == 100 and y["rostopic"] == "/imu0"
    assert "accelerometer (samples in g)" in text
