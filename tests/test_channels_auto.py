"""The temperature column every IMU log has: recognised by its name (``read_log(channels="auto")``, the default), it
is never an axis; ``allanite report`` hands it to every axis's ``refine`` when the report refines (``--refine``;
recognising it does not imply refining), says so in words, and ``--channels none`` switches it off. ``allanite
batch`` takes ``--channels`` the same way. A channel's missing values are interpolated (a warning says how many);
an infinite value, a long run of NaN, an all-NaN, constant or text column is an error naming the column."""

from __future__ import annotations

import json
import warnings

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

import allanite  # noqa: E402
from allanite import cli  # noqa: E402
from allanite.errors import InputError, ParameterError  # noqa: E402
from allanite.io._columns import is_temperature  # noqa: E402

FS, N, COEF = 10.0, 10_000, 0.02  # 10 Hz, 1000 s; deg/s per unit of temperature on g_x only
SMALL = ["--window", "1000", "--hop", "250"]


def _temperature(n: int, seed: int) -> np.ndarray:
    t = np.arange(n) / FS
    rng = np.random.default_rng(seed)
    return 20.0 + 5.0 * np.sin(2 * np.pi * 1.5 * t / (n / FS)) + 0.02 * rng.standard_normal(n)


def _coupled_csv(path, temp_name="T [degC]", coef=COEF, seed=0):
    """g_x = noise + coef·(temp − mean), g_y = noise, and the temperature column named ``temp_name`` last."""
    temp = _temperature(N, 7 + seed)
    gx = allanite.simulate(N, FS, N=0.01, K=1e-4, seed=11 + seed) + coef * (temp - temp.mean())
    gy = allanite.simulate(N, FS, N=0.01, K=1e-4, seed=12 + seed)
    np.savetxt(path, np.c_[gx, gy, temp], delimiter=",", header=f"g_x,g_y,{temp_name}", comments="")
    return path


@pytest.mark.parametrize(
    "name",
    ["temp", "Temperature", "TEMP", "imu_temp", "TEMP_OUT", "boardTemperature", "temperature.x", "gyro temp 1",
     "T [degC]", "T (°C)", "t[K]", "die (celsius)", "Temp [C]"],
)  # fmt: skip
def test_temperature_names_are_recognised(name):
    assert is_temperature(name)


@pytest.mark.parametrize(
    "name", ["t", "T", "time", "timestamp", "gyro_x", "acc_z", "tempo", "template", "attempts", "omega [deg/s]", "col3"]
)
def test_other_names_are_not(name):
    assert not is_temperature(name)


def test_read_log_takes_a_temperature_column_as_a_channel_not_an_axis(tmp_path):
    path = _coupled_csv(tmp_path / "log.csv")
    log = allanite.read_log(path, fs=FS)
    assert log.columns == ["g_x", "g_y"] and log.data.shape == (N, 2)
    assert list(log.channels) == ["T [degC]"] and log.channels_recognised
    np.testing.assert_array_equal(log.channels["T [degC]"], np.loadtxt(path, delimiter=",", skiprows=1)[:, 2])
    assert "channels: T [degC] (recognised by name)" in repr(log)
    off = allanite.read_log(path, fs=FS, channels=None)  # no channel, and still no axis
    assert off.columns == ["g_x", "g_y"] and off.channels == {}
    named = allanite.read_log(path, fs=FS, columns=["g_x", "T [degC]"])  # asked for as a sample column: it is one
    assert named.columns == ["g_x", "T [degC]"] and named.channels == {}
    chosen = allanite.read_log(path, fs=FS, columns=["g_x"])  # sample columns chosen: the temperature still found
    assert chosen.columns == ["g_x"] and list(chosen.channels) == ["T [degC]"]
    by_index = allanite.read_log(path, fs=FS, columns=[0], channels=[1])  # any column, by index
    assert by_index.columns == ["g_x"] and list(by_index.channels) == ["g_y"] and not by_index.channels_recognised
    with pytest.raises(ParameterError, match="column 'g_x' is both a sample column and a channel"):
        allanite.read_log(path, fs=FS, columns=["g_x"], channels=["g_x"])


def test_structured_npy_and_parquet_fields_are_recognised(tmp_path):
    rec = np.zeros(500, dtype=[("gx", "f8"), ("imu_temp", "f4")])
    rec["gx"] = np.random.default_rng(1).normal(size=500)
    rec["imu_temp"] = np.linspace(20, 30, 500)
    np.save(tmp_path / "s.npy", rec)
    log = allanite.read_log(tmp_path / "s.npy", fs=FS)
    assert log.columns == ["gx"] and log.channels["imu_temp"][-1] == pytest.approx(30.0)
    pa = pytest.importorskip("pyarrow")
    import pyarrow.parquet as pq

    temp = pa.array([20.0, None, 22.0, 23.0] * 100, type=pa.float64())  # nulls: missing, like NaN
    pq.write_table(pa.table({"gx": rec["gx"][:400], "temperature": temp}), tmp_path / "p.parquet")
    with pytest.warns(UserWarning, match=r"'temperature': 100 of 400 values missing"):
        log = allanite.read_log(tmp_path / "p.parquet", fs=FS)
    assert log.columns == ["gx"] and log.channels["temperature"][1] == pytest.approx(21.0)


def test_missing_values_are_interpolated_and_said(tmp_path):
    t = np.arange(2_000) / 100.0
    temp = 20.0 + t  # linear: interpolation gives it back exactly
    holed = temp.copy()
    holed[[0, 7, 8, 9, 1_999]] = np.nan
    np.savetxt(tmp_path / "h.csv", np.c_[t, np.sin(t), holed], delimiter=",", header="t,gx,temp", comments="")
    with pytest.warns(UserWarning, match=r"'temp': 5 of 2000 values missing \(NaN; the longest run 3, from line 9\)"):
        log = allanite.read_log(tmp_path / "h.csv", time_column="t")
    mid = np.arange(1, 1_999)
    np.testing.assert_allclose(log.channels["temp"][mid], temp[mid], rtol=1e-12)
    assert log.channels["temp"][0] == temp[1] and log.channels["temp"][-1] == temp[-2]  # the ends: held


def test_empty_fields_of_a_channel_are_missing_values(tmp_path):
    """A temperature written every 10th row of a CSV, the fields between empty: interpolated; an empty field in a
    sample column still stops the reader, naming it."""
    rows = [f"{i % 7 * 0.1:.1f},{20 + i / 100 if i % 10 == 0 else ''}" for i in range(1_000)]
    (tmp_path / "s.csv").write_text("gx,temp\n" + "\n".join(rows) + "\n")
    with pytest.warns(UserWarning, match=r"'temp': 900 of 1000 values missing \(NaN; the longest run 9, from line 3\)"):
        log = allanite.read_log(tmp_path / "s.csv", fs=FS)
    np.testing.assert_allclose(log.channels["temp"][:991], 20 + np.arange(991) / 100, rtol=1e-12)
    assert np.all(log.channels["temp"][990:] == 29.9)  # after the last reading: held
    (tmp_path / "g.csv").write_text("gx,temp\n0.1,20\n,20.5\n0.3,21\n")
    with pytest.raises(InputError, match=r"line 3, column 1 \('gx'\): '\(empty\)' is not a number"):
        allanite.read_log(tmp_path / "g.csv", fs=FS)


@pytest.mark.parametrize(
    ("values", "message"),
    [
        ("inf", r"line 12, channel column 'temp': infinite value inf"),
        ("run", r"channel column 'temp' misses 30 values in a row from line 12 — more than 1 % of the 2000"),
        ("all-nan", r"channel column 'temp' has 0 finite value\(s\) of 2000"),
        ("text", r"line 12, column 3 \('temp'\): 'hot' is not a number — column 'temp' is read as a channel"),
    ],
)
def test_a_bad_channel_column_is_named(tmp_path, values, message):
    """Named (channels=["temp"]): an InputError naming the column. Recognised by its name: a warning, and the log
    is read without the channel — except a text column, which stops the reading as any other text in the log does."""
    n = 2_000
    temp = [f"{20 + i / n:.4f}" for i in range(n)]
    bad = {"inf": {10: "inf"}, "run": {i: "nan" for i in range(10, 40)}, "all-nan": dict.fromkeys(range(n), "nan")}
    for i, v in bad.get(values, {10: "hot"}).items():
        temp[i] = v
    rows = [f"{i / FS:.1f},{np.sin(i):.6f},{temp[i]}" for i in range(n)]
    (tmp_path / "b.csv").write_text("t,gx,temp\n" + "\n".join(rows) + "\n")
    with pytest.raises(InputError, match=message):
        allanite.read_log(tmp_path / "b.csv", time_column="t", channels=["temp"])
    if values == "text":
        with pytest.raises(InputError, match="recognised as a temperature by its name"):
            allanite.read_log(tmp_path / "b.csv", time_column="t")
        return
    with pytest.warns(UserWarning, match=message + ".*recognised as a temperature, is not used as a channel"):
        log = allanite.read_log(tmp_path / "b.csv", time_column="t")
    assert log.columns == ["gx"] and log.channels == {}


def test_channels_are_cut_at_the_gaps_with_the_samples(tmp_path):
    n = 1_000
    t = np.arange(n) / FS
    t[600:] += 5.0  # a 5 s gap after sample 599: the longest stretch is 0..599
    np.savetxt(tmp_path / "g.csv", np.c_[t, np.sin(t), np.arange(n)], delimiter=",",
               header="t,gx,temp", comments="")  # fmt: skip
    log = allanite.read_log(tmp_path / "g.csv", time_column="t", gaps="longest")
    np.testing.assert_array_equal(log.channels["temp"], np.arange(600.0))
    filled = allanite.read_log(tmp_path / "g.csv", time_column="t", gaps="nan")  # NaN where the samples are
    assert filled.channels["temp"].shape == filled.data.shape
    np.testing.assert_array_equal(np.isnan(filled.channels["temp"]), np.isnan(filled.data))


@pytest.fixture(scope="module")
def coupled(tmp_path_factory):
    return _coupled_csv(tmp_path_factory.mktemp("auto") / "log.csv")


def _report(path, out, *extra):
    argv = ["report", str(path), "--fs", "10", "--unit", "deg/s", *SMALL, "--out", str(out), *extra]
    rc = cli.main(argv)
    return rc, json.loads((out / "summary.json").read_text()) if rc == 0 else None


def test_default_report_refines_on_the_recognised_temperature(coupled, tmp_path, capsys):
    """No --columns, no --channels: the temperature is no axis; with --refine it is every axis's channel — the
    coupling found on g_x within 20 %, none on g_y — and the report says which column and how to switch it off."""
    rc, s = _report(coupled, tmp_path / "o", "--refine")
    printed = capsys.readouterr().out
    assert rc == 0 and s["record"]["axis_names"] == ["g_x", "g_y"]
    gx, gy = s["refinement"]["axes"]
    (st,) = [st for st in gx["steps"] if st["effect"] == "regression"]
    assert st["params"]["channel"] == "T [degC]"
    assert st["final_params"]["coefficient"] == pytest.approx(COEF, rel=0.2)
    assert not [st for st in gy["steps"] if st["effect"] == "regression"]
    src = s["record"]["source"]
    assert (src["channels"], src["channels_recognised"], src["channels_used"]) == (["T [degC]"], True, ["T [degC]"])
    (note,) = [n for n in s["notes"] if "recognised as a temperature" in n]
    assert "Column 'T [degC]' was recognised as a temperature by its name: not analysed as an axis" in note
    assert (
        "--channels none" in note
        and "tries a regression on it (kept where its test and the held-out error ask for it)" in note
    )
    assert note in printed and "°/s per unit of T [degC]" in printed
    page = (tmp_path / "o" / "report.html").read_text()
    assert note.replace("'", "&#39;") in page
    # g_y: the regression tried and not kept is said (the reader had only "nothing added" beside the note)
    assert gx["channels_not_kept"] == []
    (left,) = gy["channels_not_kept"]
    assert left["channel"] == "T [degC]" and (left["why"] is not None or left["statistic"] < left["threshold"])
    assert left["text"].startswith("A regression on T [degC] was tried and not kept: ") and left["text"] in printed
    assert "T [degC] (the refinement tried a regression on it), recognised by name" in page
    assert f"{gy['tau_from_s']:.4g}–{gy['tau_to_s']:.4g} s" in page  # the τ the refinement fitted and checked


def test_default_report_without_refine_leaves_the_temperature_out(coupled, tmp_path):
    rc, s = _report(coupled, tmp_path / "o")
    assert rc == 0 and s["record"]["axis_names"] == ["g_x", "g_y"] and s.get("refinement") is None
    assert s["record"]["source"]["channels"] == ["T [degC]"] and s["record"]["source"]["channels_used"] == []
    assert any("not used: no refinement was asked for (--refine)" in n for n in s["notes"])


def test_channels_none_switches_it_off(coupled, tmp_path):
    # the regression alone among the candidates: it is the step a channel would feed, and the whole default
    # refine on this record (a coupled temperature with no channel: a line of few cycles the slow-line test's
    # bootstrap reads) took 4× the time for nothing this test asks
    rc, s = _report(coupled, tmp_path / "o", "--refine", "--channels", "none", "--refine-candidates", "regression")
    assert rc == 0 and s["record"]["axis_names"] == ["g_x", "g_y"]
    assert all(st["effect"] != "regression" for ax in s["refinement"]["axes"] for st in ax["steps"])
    assert not any("recognised as a temperature" in n for n in s["notes"])
    assert s["record"]["source"]["channels"] == [] and s["record"]["source"]["channels_used"] == []
    assert not any("passed to every axis's model refinement" in n for n in s["notes"])  # build_report's channel note


@pytest.mark.slow  # a third report refine
def test_refine_candidates_without_regression_leave_it_out_with_a_note(coupled, tmp_path):
    rc, s = _report(coupled, tmp_path / "o", "--refine-candidates", "drift")
    assert rc == 0 and s["record"]["axis_names"] == ["g_x", "g_y"]
    assert any("not used: the refinement's effects leave out the regression" in n for n in s["notes"])


def test_a_constant_channel(tmp_path, capsys):
    """Recognised: not used, said; named with --channels: an error naming it (exit status 2)."""
    y = np.random.default_rng(0).normal(size=(3_000, 2))
    np.savetxt(tmp_path / "c.csv", np.c_[y, np.full(3_000, 25.0)], delimiter=",", header="gx,gy,temp", comments="")
    out = ["--fs", "10", "--window", "600", "--hop", "150", "-q"]
    assert cli.main(["report", str(tmp_path / "c.csv"), *out, "--refine-candidates", "regression", "--out",
                     str(tmp_path / "o")]) == 0  # fmt: skip
    s = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert "Column 'temp' (recognised as a temperature) is constant: not used as a channel." in s["notes"]
    assert cli.main(["report", str(tmp_path / "c.csv"), *out, "--channels", "temp", "--out", str(tmp_path / "p")]) == 2
    assert "channel 'temp' is constant (every sample 25.0)" in capsys.readouterr().err


def test_cli_errors_say_the_option(tmp_path, capsys):
    rows = [f"{np.sin(i):.5f},{'nan' if i >= 100 else 20.0 + i / 10}" for i in range(1_000)]
    (tmp_path / "n.csv").write_text("gx,temp\n" + "\n".join(rows) + "\n")
    assert cli.main(["report", str(tmp_path / "n.csv"), "--fs", "10", "--channels", "temp", "-q"]) == 2
    err = capsys.readouterr().err
    assert "channel column 'temp' misses 900 values in a row from line 102" in err and "(--channels none)" in err


@pytest.fixture(scope="module")
def client():
    pytest.importorskip("distributed", reason="allanite batch needs distributed (pip install 'allanite[dask]')")
    from distributed import Client, LocalCluster

    with (
        LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None) as cluster,
        Client(cluster, timeout="20s") as c,
    ):
        yield c


def _batch(tmp_path, client, **kw):
    from allanite.dask import batch

    (tmp_path / "logs").mkdir()
    _coupled_csv(tmp_path / "logs" / "a.csv", "imu_temp", seed=0)
    _coupled_csv(tmp_path / "logs" / "b.csv", "imu_temp", coef=0.0, seed=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return batch(
            str(tmp_path / "logs" / "*.csv"), out=tmp_path / "r", refine=True, fs=FS, unit="deg/s", window=1000,
            hop=250, client=client, **kw,
        )  # fmt: skip


@pytest.mark.slow  # a dask cluster and eight reports; the channels in the report: the tests above
def test_batch_takes_the_channels_as_report_does(tmp_path, client):
    import csv

    res = _batch(tmp_path, client)
    assert not res.failed
    rows = {(r["file"][-5:], r["axis"]): r for r in csv.DictReader((tmp_path / "r" / "fleet.csv").open())}
    assert set(rows) == {("a.csv", "g_x"), ("a.csv", "g_y"), ("b.csv", "g_x"), ("b.csv", "g_y")}  # no imu_temp axis
    assert "regression" in rows["a.csv", "g_x"]["effects"].split(";")
    assert not any("regression" in rows[k]["effects"] for k in rows if k != ("a.csv", "g_x"))


@pytest.mark.slow  # the same four refines again; channels=None is test_channels_none_switches_it_off's in the report
def test_batch_channels_none_switches_it_off(tmp_path, client):
    off = _batch(tmp_path, client, channels=None)
    assert not off.failed
    assert not any("regression" in (r["effects"] or "") for r in off.rows)
    assert {r["axis"] for r in off.rows} == {"g_x", "g_y"}


def test_batch_cli_has_channels(tmp_path, capsys):
    from allanite.dask.fleet import _channels, build_parser

    assert "--channels C1,C2,..." in build_parser().format_help()
    assert _channels(None) == "auto" and _channels("none") is None and _channels("temp,2") == ["temp", 2]


def test_what_is_not_read_is_said(tmp_path):
    """A log of nothing but time and temperature has no sample column; a plain 1-D array holds no channel."""
    np.savetxt(tmp_path / "only.csv", np.c_[np.arange(10.0), np.arange(10.0)], delimiter=",", header="t,temp",
               comments="")  # fmt: skip
    with pytest.raises(InputError, match=r"no sample columns besides 't', 'temp' \(the time column, the channels"):
        allanite.read_log(tmp_path / "only.csv")
    np.save(tmp_path / "one.npy", np.zeros(10))
    with pytest.raises(ParameterError, match="is one column, so it holds no other channel"):
        allanite.read_log(tmp_path / "one.npy", fs=FS, channels=[0])


def _imu_and_temperature_bag(path, ros, n, temp_stamps, temps):
    """Imu messages at 200 Hz from t = 1 s (angular velocity: noise) and sensor_msgs/Temperature on /imu/temp."""
    import inspect

    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS1_NOETIC if ros == 1 else Stores.ROS2_HUMBLE)
    T = ts.types
    Imu, Temp, Header, Time = (T[k] for k in ("sensor_msgs/msg/Imu", "sensor_msgs/msg/Temperature",
                                              "std_msgs/msg/Header", "builtin_interfaces/msg/Time"))  # fmt: skip
    V, Q = T["geometry_msgs/msg/Vector3"], T["geometry_msgs/msg/Quaternion"]
    if ros == 1:
        from rosbags.rosbag1 import Writer

        writer, ser = Writer(path), ts.serialize_ros1
    else:
        from rosbags.rosbag2 import Writer

        kw = {"version": 8} if "version" in inspect.signature(Writer.__init__).parameters else {}
        writer, ser = Writer(path, **kw), ts.serialize_cdr

    def header(i, ns):
        stamp = Time(sec=ns // 10**9, nanosec=ns % 10**9)
        return Header(seq=i, stamp=stamp, frame_id="imu") if ros == 1 else Header(stamp=stamp, frame_id="imu")

    w = np.random.default_rng(5).normal(scale=0.01, size=(n, 3))
    cov = np.zeros(9)
    with writer:
        imu = writer.add_connection("/imu/data", Imu.__msgtype__, typestore=ts)
        tc = writer.add_connection("/imu/temp", Temp.__msgtype__, typestore=ts)
        for i in range(n):
            ns = 10**9 + i * 5_000_000
            msg = Imu(header=header(i, ns), orientation=Q(x=0.0, y=0.0, z=0.0, w=1.0), orientation_covariance=cov,
                      angular_velocity=V(x=w[i, 0], y=w[i, 1], z=w[i, 2]), angular_velocity_covariance=cov,
                      linear_acceleration=V(x=0.0, y=0.0, z=9.81), linear_acceleration_covariance=cov)  # fmt: skip
            writer.write(imu, ns, ser(msg, Imu.__msgtype__))
        for i, (ns, v) in enumerate(zip(temp_stamps, temps)):
            msg = Temp(header=header(i, int(ns)), temperature=float(v), variance=0.0)
            writer.write(tc, int(ns), ser(msg, Temp.__msgtype__))
    return w


@pytest.mark.parametrize("ros", [1, 2])
def test_a_bags_temperature_topic_is_a_channel_at_the_imu_times(tmp_path, ros):
    pytest.importorskip("rosbags", reason="rosbags is not installed (pip install 'allanite[ros]')")
    n = 400  # 2 s at 200 Hz from t = 1 s; the temperature at 10 Hz from 0.95 s to 3.05 s, rising 1 °C/s
    stamps = np.arange(950_000_000, 3_100_000_000, 100_000_000)
    path = tmp_path / ("imu.bag" if ros == 1 else "imu_bag")
    w = _imu_and_temperature_bag(path, ros, n, stamps, 20.0 + stamps * 1e-9)
    log = allanite.read_log(path)
    np.testing.assert_array_equal(log.data, w)
    assert list(log.channels) == ["/imu/temp"] and log.channels_recognised
    np.testing.assert_allclose(log.channels["/imu/temp"], 21.0 + np.arange(n) * 0.005, rtol=1e-12)
    assert allanite.read_log(path, channels=None).channels == {}
    with pytest.raises(InputError, match=r"no sensor_msgs/Temperature topic '/t'; .* Temperature topics: /imu/temp"):
        allanite.read_log(path, channels=["/t"])
    notes: list = []
    from allanite.report._channels import log_channels

    assert log_channels(log, False, notes) is None
    assert notes[0].startswith(
        "Topic '/imu/temp' was recognised as a temperature by its type (sensor_msgs/Temperature)"
    )


def test_a_bags_temperature_that_stops_early_is_left_out_or_refused(tmp_path):
    pytest.importorskip("rosbags", reason="rosbags is not installed (pip install 'allanite[ros]')")
    stamps = np.arange(1_000_000_000, 2_000_000_000, 100_000_000)  # the first of the Imu's 2 s only
    _imu_and_temperature_bag(tmp_path / "early.bag", 1, 400, stamps, np.full(stamps.size, 30.0))
    with pytest.warns(UserWarning, match=r"'/imu/temp' misses 219 values in a row from message 181 on /imu/data"):
        log = allanite.read_log(tmp_path / "early.bag")
    assert log.channels == {}
    with pytest.raises(InputError, match=r"channel column '/imu/temp' misses"):
        allanite.read_log(tmp_path / "early.bag", channels=["/imu/temp"])
