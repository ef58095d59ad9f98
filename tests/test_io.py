"""Log readers (allanite.read_log): round trips for every format, the malformed-file battery, gap
detection, units, and the real ADIS16405 run."""

from __future__ import annotations

import builtins
import doctest
import gzip
import inspect
import re
import sys

import numpy as np
import pytest

import allanite
from allanite import AllaniteError, InputError, Log, ParameterError, read_log
from allanite.io import Gap, MissingDependencyError

FS = 100.0
N = 400


@pytest.fixture
def record(rng):
    """(t, x): N samples at 100 Hz, 3 axes, values with ≤ 17 significant digits written by repr."""
    t = 12.5 + np.arange(N) / FS
    x = rng.normal(scale=[0.1, 0.2, 0.3], size=(N, 3))
    return t, x


def write_text(path, t, x, *, delim=",", header="t,gx,gy,gz", comments=("# test log",), newline="\n", compress=False):
    rows = []
    rows += list(comments)
    if header is not None:
        rows.append(header.replace(",", delim) if delim is not None else header.replace(",", " "))
    sep = delim if delim is not None else "  "
    for ti, xi in zip(t, x):
        rows.append(sep.join(repr(float(v)) for v in (ti, *xi)))
    text = newline.join(rows) + newline
    if compress:
        path.write_bytes(gzip.compress(text.encode()))
    else:
        path.write_bytes(text.encode())
    return path


def lines_file(tmp_path, name, lines):
    p = tmp_path / name
    p.write_text("\n".join(lines) + "\n")
    return p


# --------------------------------------------------------------------------------------------------
# Round trips
# --------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "name, delim, compress, newline",
    [
        ("log.csv", ",", False, "\n"),
        ("log.csv.gz", ",", True, "\n"),
        ("log.tsv", "\t", False, "\n"),
        ("log.txt", None, False, "\n"),  # whitespace
        ("log.dat", ";", False, "\r\n"),  # semicolons, Windows line ends
    ],
)
def test_text_round_trip_with_time_column(tmp_path, record, name, delim, compress, newline):
    t, x = record
    p = write_text(tmp_path / name, t, x, delim=delim, compress=compress, newline=newline)
    log = read_log(p, time_column="t", unit="deg/s")
    assert isinstance(log, Log)
    assert log.format == "text"
    assert log.data.dtype == np.float64 and log.data.shape == (N, 3)
    np.testing.assert_array_equal(log.data, x)  # exact: repr round-trips float64
    assert log.columns == ["gx", "gy", "gz"]
    assert log.fs == pytest.approx(FS, rel=1e-9)
    assert log.t0 == 12.5
    np.testing.assert_allclose(log.time, t - 12.5, atol=1e-12)
    assert log.gaps == [] and log.span == (0, N) and log.segments is None
    assert log.unit.name == "deg/s" and log.input == "rate"
    assert log.jitter < 1e-6


def test_text_round_trip_without_header_or_time(tmp_path, record):
    t, x = record
    p = write_text(tmp_path / "plain.csv", t, x, header=None, comments=())
    log = read_log(p, fs=FS, columns=[1, 2, 3])
    np.testing.assert_array_equal(log.data, x)
    assert log.columns == ["col1", "col2", "col3"]
    assert log.fs == FS and log.t0 == 0.0 and log.time is None and log.unit is None
    # all columns, the first being time: 4 axes
    assert read_log(p, fs=FS).data.shape == (N, 4)


def test_text_column_selection(tmp_path, record):
    t, x = record
    p = write_text(tmp_path / "log.csv", t, x)
    one = read_log(p, time_column=0, columns="gy")
    assert one.data.shape == (N,) and one.columns == ["gy"]
    np.testing.assert_array_equal(one.data, x[:, 1])
    two = read_log(p, fs=FS, columns=["gz", -3])  # by name and by (negative) index
    np.testing.assert_array_equal(two.data, x[:, [2, 0]])
    assert two.columns == ["gz", "gx"]
    lst = read_log(p, fs=FS, columns=["GY"])  # case-insensitive fallback; a list → 2-D
    assert lst.data.shape == (N, 1)


def test_text_savetxt_comment_header_and_inline_comments(tmp_path, record):
    t, x = record
    p = tmp_path / "np.txt"
    np.savetxt(p, np.c_[t, x], header="time gx gy gz", fmt="%.17g")  # writes "# time gx gy gz"
    log = read_log(p, time_column="time")
    assert log.columns == ["gx", "gy", "gz"]
    np.testing.assert_array_equal(log.data, x)
    q = lines_file(tmp_path, "inline.csv", ["a,b", "1,2 # first", "", "# middle", "3,4"])
    log = read_log(q, fs=1.0)
    np.testing.assert_array_equal(log.data, [[1.0, 2.0], [3.0, 4.0]])


def test_text_subset_with_commas_in_comments_and_quoted_header(tmp_path):
    # reading a subset of columns checks row lengths by counting delimiters; commas inside comments
    # must not turn into a false "ragged row"
    p = lines_file(
        tmp_path, "q.csv", ['"t","a","b","label"', "0,1,2,3", "# x, y, z", "0.5,4,5,6 # note, with commas", "1.0,7,8,9"]
    )
    log = read_log(p, time_column="t", columns=["b"])
    np.testing.assert_array_equal(log.data, [[2.0], [5.0], [8.0]])  # a list of columns gives 2-D
    assert log.fs == 2.0
    w = lines_file(tmp_path, "w.txt", ["t  a   b", "0 1\t2", "1   3 4"])  # mixed whitespace
    np.testing.assert_array_equal(read_log(w, time_column="t", columns="b").data, [2.0, 4.0])
    with pytest.raises(InputError, match=r"w2\.txt: line 3: ragged row — 4 fields \(separated by whitespace\)"):
        read_log(lines_file(tmp_path, "w2.txt", ["t a b", "0 1 2", "1 3 4 5"]), time_column="t", columns="b")


def test_npy_is_memory_mapped(tmp_path, record):
    t, x = record
    p = tmp_path / "x.npy"
    np.save(p, x)
    log = read_log(p, fs=FS, unit="rad/s")
    assert log.format == "npy"
    assert isinstance(log.data, np.memmap) and not log.data.flags.writeable
    np.testing.assert_array_equal(log.data, x)
    assert log.columns == ["col0", "col1", "col2"]
    # a contiguous run of columns is still a view of the map, not a copy
    sub = read_log(p, fs=FS, columns=[1, 2])
    assert isinstance(sub.data, np.memmap)
    np.testing.assert_array_equal(sub.data, x[:, 1:])
    one = read_log(p, fs=FS, columns=2)
    assert one.data.shape == (N,) and isinstance(one.data, np.memmap)
    # the estimators take the map as it is
    r = allanite.avar(log.data, log.fs, taus=[0.01, 0.1])
    np.testing.assert_allclose(r.avar, allanite.avar(x, FS, taus=[0.01, 0.1]).avar, rtol=0, atol=0)


def test_npy_with_time_column_and_dtypes(tmp_path, record):
    t, x = record
    p = tmp_path / "tx.npy"
    np.save(p, np.c_[t, x])
    log = read_log(p, time_column=0)
    np.testing.assert_array_equal(log.data, x)
    assert log.fs == pytest.approx(FS) and log.t0 == 12.5
    # integer counts (e.g. raw LSB) stay as they are
    q = tmp_path / "i.npy"
    np.save(q, np.arange(10, dtype=np.int16))
    lg = read_log(q, fs=10)
    assert lg.data.dtype == np.int16 and lg.data.tolist() == list(range(10))


def test_npy_structured(tmp_path, record):
    t, x = record
    rec = np.zeros(N, dtype=[("time", "f8"), ("wx", "f4"), ("wy", "f8"), ("wz", "f8")])
    rec["time"], rec["wx"], rec["wy"], rec["wz"] = t, x[:, 0], x[:, 1], x[:, 2]
    p = tmp_path / "s.npy"
    np.save(p, rec)
    log = read_log(p, time_column="time", columns=["wx", "wz"])
    assert log.columns == ["wx", "wz"]
    np.testing.assert_array_equal(log.data, np.c_[x[:, 0].astype(np.float32), x[:, 2]])


def test_npz_round_trip(tmp_path, record):
    t, x = record
    p = tmp_path / "one.npz"
    np.savez(p, gyro=x)
    log = read_log(p, fs=FS)
    assert log.format == "npz"
    np.testing.assert_array_equal(log.data, x)
    q = tmp_path / "two.npz"
    np.savez_compressed(q, gyro=x, acc=x * 2, t=t)
    log = read_log(q, array="gyro", time_column="t")  # the time array lives beside the samples
    np.testing.assert_array_equal(log.data, x)
    assert log.fs == pytest.approx(FS) and log.t0 == 12.5
    np.testing.assert_array_equal(read_log(q, array="acc", fs=FS, columns=[0]).data, x[:, :1] * 2)
    with pytest.raises(ParameterError, match=r"two\.npz: the archive holds arrays 'gyro', 'acc', 't'; pass array="):
        read_log(q, fs=FS)
    with pytest.raises(InputError, match=r"two\.npz: no array named 'gyr'; available: 'gyro', 'acc', 't'"):
        read_log(q, fs=FS, array="gyr")


def test_parquet_round_trip(tmp_path, record):
    pa = pytest.importorskip("pyarrow")
    pq = pytest.importorskip("pyarrow.parquet")
    t, x = record
    p = tmp_path / "log.parquet"
    pq.write_table(
        pa.table({"t": t, "gx": x[:, 0], "gy": x[:, 1], "gz": x[:, 2].astype(np.float32), "label": ["a"] * N}), p
    )
    log = read_log(p, time_column="t", columns=["gx", "gy", "gz"], unit="deg/h")
    assert log.format == "parquet"
    np.testing.assert_array_equal(log.data, np.c_[x[:, :2], x[:, 2].astype(np.float32)])
    assert log.fs == pytest.approx(FS) and log.t0 == 12.5 and log.unit.name == "deg/h"
    # a timestamp-typed time column (ns since the epoch)
    ns = 1_700_000_000_000_000_000 + np.arange(N, dtype=np.int64) * 10_000_000
    q = tmp_path / "ts.parquet"
    pq.write_table(pa.table({"stamp": pa.array(ns, type=pa.timestamp("ns")), "w": x[:, 0]}), q)
    log = read_log(q, time_column="stamp")
    np.testing.assert_array_equal(log.data, x[:, 0])
    assert log.fs == pytest.approx(FS, rel=1e-12) and log.t0 == pytest.approx(1.7e9, abs=1e-6)
    with pytest.raises(InputError, match=r"log\.parquet: column 'label' has type string, not a number"):
        read_log(p, fs=FS, columns=["gx", "label"])
    with pytest.raises(
        InputError, match=r"log\.parquet: no column named 'gw'; available: 't', 'gx', 'gy', 'gz', 'label'"
    ):
        read_log(p, fs=FS, columns=["gw"])
    nul = tmp_path / "null.parquet"
    pq.write_table(pa.table({"w": pa.array([1.0, 2.0, None, 4.0])}), nul)
    with pytest.raises(InputError, match=r"null\.parquet: row 2, column 'w': missing value \(null\)"):
        read_log(nul, fs=FS)


def _write_bag(path, ros, stamps_ns, w, topic="/imu/data"):
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS1_NOETIC if ros == 1 else Stores.ROS2_HUMBLE)
    T = ts.types
    Imu, Header, Time = T["sensor_msgs/msg/Imu"], T["std_msgs/msg/Header"], T["builtin_interfaces/msg/Time"]
    V, Q = T["geometry_msgs/msg/Vector3"], T["geometry_msgs/msg/Quaternion"]
    if ros == 1:
        from rosbags.rosbag1 import Writer

        writer = Writer(path)
    else:
        from rosbags.rosbag2 import Writer

        kw = {"version": 8} if "version" in inspect.signature(Writer.__init__).parameters else {}
        writer = Writer(path, **kw)
    cov = np.zeros(9)
    with writer:
        con = writer.add_connection(topic, Imu.__msgtype__, typestore=ts)
        for i, ns in enumerate(stamps_ns):
            ns = int(ns)
            header = (
                Header(seq=i, stamp=Time(sec=ns // 10**9, nanosec=ns % 10**9), frame_id="imu")
                if ros == 1
                else Header(stamp=Time(sec=ns // 10**9, nanosec=ns % 10**9), frame_id="imu")
            )
            msg = Imu(
                header=header,
                orientation=Q(x=0.0, y=0.0, z=0.0, w=1.0),
                orientation_covariance=cov,
                angular_velocity=V(x=float(w[i, 0]), y=float(w[i, 1]), z=float(w[i, 2])),
                angular_velocity_covariance=cov,
                linear_acceleration=V(x=0.0, y=0.0, z=9.81),
                linear_acceleration_covariance=cov,
            )
            raw = ts.serialize_ros1(msg, Imu.__msgtype__) if ros == 1 else ts.serialize_cdr(msg, Imu.__msgtype__)
            writer.write(con, ns + 1_000, raw)  # receive time a little after the stamp


@pytest.mark.parametrize("ros", [1, 2])
def test_ros_bag_round_trip(tmp_path, rng, ros):
    pytest.importorskip("rosbags", reason="rosbags is not installed (pip install 'allanite[ros]')")
    n = 60
    w = rng.normal(scale=0.01, size=(n, 3))
    stamps = 1_700_000_000_000_000_000 + np.arange(n, dtype=np.int64) * 5_000_000  # 200 Hz
    path = tmp_path / ("imu.bag" if ros == 1 else "imu_bag")
    _write_bag(path, ros, stamps, w)
    log = read_log(path)
    assert log.format == f"ros{ros}"
    np.testing.assert_array_equal(log.data, w)
    assert log.columns == ["angular_velocity_x", "angular_velocity_y", "angular_velocity_z"]
    assert log.fs == pytest.approx(200.0, rel=1e-9)
    assert log.t0 == pytest.approx(1.7e9, abs=1e-6)
    assert log.unit.name == "rad/s"  # REP 103 default
    acc = read_log(path, columns="linear_acceleration_z", unit="deg/s")
    np.testing.assert_array_equal(acc.data, np.full(n, 9.81))
    assert acc.unit.name == "deg/s"
    recv = read_log(path, time_column="receive")
    assert recv.t0 == pytest.approx(1.7e9 + 1e-6, abs=1e-6)
    with pytest.raises(InputError, match=r"no sensor_msgs/Imu topic '/gyro'; Imu topics: /imu/data"):
        read_log(path, topic="/gyro")
    with pytest.raises(ParameterError, match=r"time_unit='ns' is given for a ROS bag, whose stamps are seconds"):
        read_log(path, time_unit="ns")  # was silently unused


def test_ros_bag_gap(tmp_path, rng):
    pytest.importorskip("rosbags", reason="rosbags is not installed (pip install 'allanite[ros]')")
    n = 60
    w = rng.normal(size=(n, 3))
    stamps = np.arange(n, dtype=np.int64) * 5_000_000 + 10**9
    stamps[30:] += 100_000_000  # 0.1 s without messages after message 29
    path = tmp_path / "gappy"
    _write_bag(path, 2, stamps, w)
    with pytest.raises(
        InputError,
        match=r"gappy: 1 gap\(s\) in time column 'header\.stamp'.*0\.1 s \(≈20 samples\) "
        r"missing after sample 29 at t = 0\.145 s",
    ):
        read_log(path)
    log = read_log(path, gaps="longest")
    np.testing.assert_array_equal(log.data, w[:30])


def test_missing_optional_packages_are_named(tmp_path, monkeypatch):
    p = tmp_path / "x.parquet"
    p.write_bytes(b"PAR1" + b"\0" * 16 + b"PAR1")
    bag = tmp_path / "x.bag"
    bag.write_bytes(b"#ROSBAG V2.0\n")
    real_import = builtins.__import__

    def no_optional(name, *args, **kwargs):
        if name.split(".")[0] in ("pyarrow", "rosbags"):
            raise ImportError(f"No module named {name!r}")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_optional)
    for mod in [m for m in sys.modules if m.split(".")[0] in ("pyarrow", "rosbags")]:
        monkeypatch.delitem(sys.modules, mod)
    with pytest.raises(
        MissingDependencyError,
        match=r"Parquet files needs the optional package 'pyarrow': "
        r"pip install 'allanite\[parquet\]'",
    ):
        read_log(p, fs=1.0)
    with pytest.raises(
        MissingDependencyError,
        match=r"ROS bags needs the optional package 'rosbags': "
        r"pip install 'allanite\[ros\]'",
    ):
        read_log(bag)
    assert issubclass(MissingDependencyError, ImportError) and issubclass(MissingDependencyError, AllaniteError)


# --------------------------------------------------------------------------------------------------
# Malformed files: every error names the file and, where there is one, the line and the column
# --------------------------------------------------------------------------------------------------

GOOD = ["# comment", "t,gx,gy", "0.00,1,2", "0.01,3,4", "0.02,5,6", "0.03,7,8"]


def with_line(k, text):
    """GOOD with line k (1-based) replaced."""
    out = list(GOOD)
    out[k - 1] = text
    return out


@pytest.mark.parametrize(
    "lines, kwargs, pattern",
    [
        # ragged rows, short and long, with all columns and with a subset
        (
            with_line(5, "0.02,5"),
            {"time_column": "t"},
            r"bad\.csv: line 5: ragged row — 2 fields \(separated by ','\) where line 3 and the header have 3",
        ),
        (with_line(4, "0.01,3,4,9"), {"time_column": "t"}, r"bad\.csv: line 4: ragged row — 4 fields"),
        (with_line(6, "0.03,7,8,9"), {"fs": 100, "columns": ["gx"]}, r"bad\.csv: line 6: ragged row — 4 fields"),
        (with_line(6, "0.03"), {"fs": 100, "columns": ["gy"]}, r"bad\.csv: line 6: ragged row — 1 fields"),
        # text in a numeric column, and an empty field
        (
            with_line(4, "0.01,3,abc"),
            {"time_column": "t"},
            r"bad\.csv: line 4, column 3 \('gy'\): 'abc' is not a number",
        ),
        (
            with_line(5, "0.02,,6"),
            {"time_column": "t"},
            r"bad\.csv: line 5, column 2 \('gx'\): '\(empty\)' is not a number",
        ),
        (with_line(6, "oops,7,8"), {"time_column": "t"}, r"bad\.csv: line 6, column 1 \('t'\): 'oops' is not a number"),
        (
            with_line(3, "0.00,1e,2"),
            {"fs": 100, "columns": [1]},
            r"bad\.csv: line 3, column 2 \('gx'\): '1e' is not a number",
        ),
        # NaN / inf in the data
        (
            with_line(5, "0.02,nan,6"),
            {"time_column": "t"},
            r"bad\.csv: line 5, column 2 \('gx'\): non-finite value nan",
        ),
        (
            with_line(6, "0.03,7,-inf"),
            {"time_column": "t"},
            r"bad\.csv: line 6, column 3 \('gy'\): non-finite value -inf",
        ),
        (with_line(4, "nan,3,4"), {"time_column": "t"}, r"bad\.csv: line 4, time column 't': non-finite time nan"),
        # missing columns
        (
            GOOD,
            {"time_column": "t", "columns": ["gx", "gz"]},
            r"bad\.csv: no column named 'gz'; available: 't', 'gx', 'gy'",
        ),
        (
            GOOD,
            {"time_column": "t", "columns": [7]},
            r"bad\.csv: column index 7 is out of range: the file has 3 columns \(indices 0–2: t, gx, gy\)",
        ),
        (GOOD, {"time_column": "time"}, r"bad\.csv: no time column named 'time'; available: 't', 'gx', 'gy'"),
        # wrong time column: a gyro column is no clock
        (
            with_line(5, "0.02,-5,6"),
            {"time_column": "gx"},
            r"bad\.csv: line 5, time column 'gx': time goes backwards \(-5\.0 after 3\.0\); times must increase — is 'gx' "
            r"really the time column\?",
        ),
        # non-monotonic and repeated time
        (
            with_line(5, "0.005,5,6"),
            {"time_column": "t"},
            r"bad\.csv: line 5, time column 't': time goes backwards \(0\.005 after 0\.01\)",
        ),
        (
            with_line(4, "0.00,3,4"),
            {"time_column": 0},
            r"bad\.csv: line 4, time column 't': time repeats \(0\.0 after 0\.0\)",
        ),
        # a header that does not match the rows
        (
            ["t,gx,gy,gz", "0,1,2"],
            {"time_column": "t"},
            r"bad\.csv: the header on line 1 names 4 columns but line 2 has 3 fields",
        ),
        (
            ["# only a header", "t,gx,gy"],
            {"time_column": "t"},
            r"bad\.csv: line 2 is a header \(t, gx, gy\) but no data rows follow",
        ),
    ],
)
def test_malformed_text(tmp_path, lines, kwargs, pattern):
    p = lines_file(tmp_path, "bad.csv", lines)
    with pytest.raises(InputError, match=pattern) as info:
        read_log(p, **kwargs)
    assert str(p) in str(info.value)
    assert info.value.__cause__ is None or isinstance(info.value.__cause__, AllaniteError)


def test_malformed_errors_point_past_interleaved_comments(tmp_path):
    p = lines_file(tmp_path, "c.csv", ["t,w", "0,1", "# note", "", "0.1,2", "# note", "0.2,x3"])
    with pytest.raises(InputError, match=r"c\.csv: line 7, column 2 \('w'\): 'x3' is not a number"):
        read_log(p, time_column="t")
    q = lines_file(tmp_path, "d.csv", ["t,w", "0,1", "# note", "", "0.1,2", "# note", "0.2,nan"])
    with pytest.raises(InputError, match=r"d\.csv: line 7, column 2 \('w'\): non-finite value nan"):
        read_log(q, time_column="t")


def test_gzipped_malformed_line_numbers(tmp_path):
    p = tmp_path / "bad.csv.gz"
    p.write_bytes(gzip.compress("\n".join(with_line(6, "0.03,7,eight")).encode()))
    with pytest.raises(InputError, match=r"bad\.csv\.gz: line 6, column 3 \('gy'\): 'eight' is not a number"):
        read_log(p, time_column="t")


@pytest.mark.parametrize(
    "content, pattern",
    [
        ("", r"empty\.csv: empty file — it holds nothing, no data rows"),
        ("\n\n  \n", r"empty\.csv: empty file — it holds nothing, no data rows"),
        ("# just\n# comments\n", r"empty\.csv: empty file — it holds only comment lines, no data rows"),
    ],
)
def test_empty_files(tmp_path, content, pattern):
    p = tmp_path / "empty.csv"
    p.write_text(content)
    with pytest.raises(InputError, match=pattern):
        read_log(p, fs=100)


def test_broken_binary_files(tmp_path):
    gz = tmp_path / "broken.csv.gz"
    gz.write_bytes(gzip.compress(b"t,w\n0,1\n0.01,2\n")[:-12])  # truncated
    with pytest.raises(InputError, match=r"broken\.csv\.gz: cannot be read as gzip"):
        read_log(gz, fs=100)
    npy = tmp_path / "fake.npy"
    npy.write_text("1,2,3\n")
    with pytest.raises(InputError, match=r"fake\.npy: not a valid \.npy file"):
        read_log(npy, fs=100)
    bad_npy = tmp_path / "trunc.npy"
    np.save(bad_npy, np.arange(100.0))
    bad_npy.write_bytes(bad_npy.read_bytes()[:-80])
    with pytest.raises(InputError, match=r"trunc\.npy: not a readable \.npy file"):
        read_log(bad_npy, fs=100)
    npz = tmp_path / "fake.npz"
    npz.write_bytes(b"not a zip")
    with pytest.raises(InputError, match=r"fake\.npz: not a valid \.npz file"):
        read_log(npz, fs=100)
    with pytest.raises(InputError, match=r"nothere\.csv: no such file"):
        read_log(tmp_path / "nothere.csv", fs=100)
    with pytest.raises(InputError, match=r"is a folder, not a log file"):
        read_log(tmp_path, fs=100)


def test_non_finite_and_bad_arrays(tmp_path):
    x = np.ones((50, 3))
    x[17, 2] = np.nan
    p = tmp_path / "nan.npy"
    np.save(p, x)
    with pytest.raises(InputError, match=r"nan\.npy: row 17, column 'col2': non-finite value nan"):
        read_log(p, fs=100)
    s = tmp_path / "str.npy"
    np.save(s, np.array(["a", "b"]))
    with pytest.raises(InputError, match=r"str\.npy: the array has dtype <U1; samples must be real numbers"):
        read_log(s, fs=100)
    c = tmp_path / "cube.npy"
    np.save(c, np.zeros((4, 3, 2)))
    with pytest.raises(InputError, match=r"cube\.npy: the array has shape \(4, 3, 2\); samples must be 1-D"):
        read_log(c, fs=100)
    one = tmp_path / "one.npy"
    np.save(one, np.arange(5.0))
    with pytest.raises(
        InputError, match=r"one\.npy: the array is 1-D \(one column\), so it cannot hold a time column 0"
    ):
        read_log(one, time_column=0)
    e = tmp_path / "e.npy"
    np.save(e, np.zeros((0, 3)))
    with pytest.raises(InputError, match=r"e\.npy: no samples"):
        read_log(e, fs=100)


def test_parameter_errors(tmp_path, record):
    t, x = record
    p = write_text(tmp_path / "log.csv", t, x)
    # neither fs nor time_column: the column named "t" is recognised as the time column, and said so
    log = read_log(p, columns=["gx"])
    assert log.time_column == "t" and log.time_column_recognised and log.fs == FS
    assert "time column 't' (recognised by its name)" in repr(log)
    q = tmp_path / "nameless.csv"
    q.write_text("a,b\n1,2\n3,4\n")
    with pytest.raises(
        ParameterError,
        match=r"nameless\.csv: give the sampling rate \(fs=… in Hz\) or the time column "
        r"\(time_column=…\) — neither was passed, and no column is named like a time column",
    ):
        read_log(q)
    with pytest.raises(ParameterError, match=r"log\.csv: column 't' looks like a time column; pass time_column='t'"):
        read_log(p, fs=FS)
    with pytest.raises(
        ParameterError,
        match=r"log\.csv: fs = 50 Hz, but the median step of time column 't' is 0\.01 "
        r"\(100 Hz\)",
    ):
        read_log(p, fs=50, time_column="t")
    with pytest.raises(
        ParameterError,
        match=r"unit 'deg/s' is a rate unit, but an angle unit is needed here.*"
        r"input='increment' needs an angle unit",
    ):
        read_log(p, time_column="t", unit="deg/s", input="increment")
    with pytest.raises(ParameterError, match=r"unit 'rad' is an angle unit, but a rate unit is needed"):
        read_log(p, time_column="t", unit="rad")
    with pytest.raises(ParameterError, match=r"unknown unit 'deg/fortnight'; allowed rate units: deg/s"):
        read_log(p, time_column="t", unit="deg/fortnight")
    with pytest.raises(ParameterError, match=r"unknown gaps 'ignore'; allowed: 'error', 'longest', 'split'"):
        read_log(p, time_column="t", gaps="ignore")
    with pytest.raises(ParameterError, match=r"unknown input 'phases'"):
        read_log(p, time_column="t", input="phases")
    with pytest.raises(ParameterError, match=r"fs must be a positive finite number"):
        read_log(p, fs=-1)
    with pytest.raises(ParameterError, match=r"columns must be a column name or index, or a non-empty list"):
        read_log(p, time_column="t", columns=[])
    with pytest.raises(ParameterError, match=r"column 't' is both the time column and a sample column"):
        read_log(p, time_column="t", columns=["t", "gx"])
    with pytest.raises(ParameterError, match=r"delimiter must be one character"):
        read_log(p, time_column="t", delimiter=",,")
    # increments with an angle unit are fine
    inc = read_log(p, time_column="t", unit="arcsec", input="increment")
    assert inc.unit.name == "arcsec" and inc.input == "increment"


def test_every_failure_is_an_allanite_error(tmp_path, rng):
    """A fuzz of damaged CSV files: whatever is wrong, the error is an AllaniteError naming the file."""
    base = ["t,a,b"] + [f"{i / 100!r},{float(v[0])!r},{float(v[1])!r}" for i, v in enumerate(rng.normal(size=(30, 2)))]
    read_log(lines_file(tmp_path, "base.csv", base), time_column="t")  # the undamaged file reads
    junk = [
        "",
        "x",
        ",",
        ",,,",
        "1,2",
        "1,2,3,4",
        "nan",
        "1e999",
        "--1",
        "0x10",
        "\x00",
        "1;2;3",
        '"1",2,3',
        "1_0",
        "\u0661",
        "1.5e",
        " infinity",
    ]
    raised = 0
    for k in range(120):
        lines = list(base)
        i = int(rng.integers(1, len(lines)))
        j = int(rng.integers(0, 3))
        fields = lines[i].split(",")
        fields[j] = junk[int(rng.integers(len(junk)))]
        lines[i] = ",".join(fields)
        p = lines_file(tmp_path, f"f{k}.csv", lines)
        try:
            read_log(p, time_column="t", gaps="split")
        except AllaniteError as exc:
            raised += 1
            assert f"f{k}.csv" in str(exc)
            assert re.search(r"line \d+|header on line", str(exc)), str(exc)
    assert raised > 100


# --------------------------------------------------------------------------------------------------
# Gaps and irregular sampling
# --------------------------------------------------------------------------------------------------


def gappy(tmp_path, rng, remove):
    """A 100 Hz record of 1000 samples with the sample ranges in `remove` cut out."""
    t = np.arange(1000) / FS
    x = rng.normal(size=(1000, 2))
    keep = np.ones(1000, bool)
    for a, b in remove:
        keep[a:b] = False
    p = write_text(tmp_path / "gappy.csv", t[keep], x[keep], header="time,wx,wy")
    return p, t[keep], x[keep]


def test_gap_is_reported(tmp_path, rng):
    p, t, x = gappy(tmp_path, rng, [(400, 450)])
    with pytest.raises(InputError) as info:
        read_log(p, time_column="time")
    msg = str(info.value)
    assert "gappy.csv: 1 gap(s) in time column 'time'" in msg
    assert "0.5 s (≈50 samples) missing after sample 399 at t = 3.99 s" in msg
    assert "gaps='longest'" in msg and "gaps='split'" in msg


def test_gaps_longest_and_split(tmp_path, rng):
    p, t, x = gappy(tmp_path, rng, [(300, 310), (700, 900)])
    # kept record (790 samples): 0..299 (300), 310..699 (390), 900..999 (100)
    log = read_log(p, time_column="time", gaps="longest")
    assert log.gaps == [
        Gap(index=300, time=pytest.approx(2.99), duration=pytest.approx(0.1), missing=10),
        Gap(index=690, time=pytest.approx(6.99), duration=pytest.approx(2.0), missing=200),
    ]
    assert log.span == (300, 690) and log.n_record == 790
    np.testing.assert_array_equal(log.data, x[300:690])
    assert log.t0 == pytest.approx(3.10)
    assert log.time[0] == 0.0 and log.time[-1] == pytest.approx(3.89)
    assert log.fs == pytest.approx(FS)
    assert "2 gap(s)" in repr(log) and "kept samples 300–689 of 790" in repr(log)

    split = read_log(p, time_column="time", gaps="split")
    assert [s.shape[0] for s in split.segments] == [300, 390, 100]
    assert split.segment_spans == [(0, 300), (300, 690), (690, 790)]
    for (a, b), seg in zip(split.segment_spans, split.segments):
        np.testing.assert_array_equal(seg, x[a:b])
    np.testing.assert_array_equal(split.data, x[300:690])
    assert "segments: 3 (0–299, 300–689, 690–789)" in repr(split)


def test_no_gaps_split_gives_one_segment(tmp_path, rng):
    p, t, x = gappy(tmp_path, rng, [])
    log = read_log(p, time_column="time", gaps="split")
    assert log.gaps == [] and len(log.segments) == 1
    np.testing.assert_array_equal(log.segments[0], x)


def test_step_just_below_threshold_is_no_gap_but_jitter(tmp_path):
    t = np.arange(20) / FS
    t[10:] += 0.004  # one step of 1.4 nominal steps: irregular, not a gap
    p = write_text(tmp_path / "jit.csv", t, np.ones((20, 1)), header="t,w")
    with pytest.warns(UserWarning, match=r"jit\.csv: irregular sampling — a time step differs from the nominal"):
        log = read_log(p, time_column="t")
    assert log.gaps == [] and log.jitter == pytest.approx(0.4, rel=1e-6)
    t[10:] += 0.002  # now 1.6 steps: a gap of 0.006 s
    p = write_text(tmp_path / "gap.csv", t, np.ones((20, 1)), header="t,w")
    log = read_log(p, time_column="t", gaps="longest")
    assert len(log.gaps) == 1 and log.gaps[0].index == 10 and log.gaps[0].duration == pytest.approx(0.006)


def test_many_gaps_message_is_bounded(tmp_path):
    t = np.cumsum(np.tile([0.01, 0.01, 0.05], 40))
    p = write_text(tmp_path / "many.csv", t, np.zeros((t.size, 1)), header="t,w")
    with pytest.raises(InputError, match=r"many\.csv: 40 gap\(s\).*; … and 30 more"):
        read_log(p, time_column="t")


def test_time_unit(tmp_path):
    t_ms = 1000.0 + np.arange(50) * 2.0  # 500 Hz in milliseconds
    p = write_text(tmp_path / "ms.csv", t_ms, np.ones((50, 1)), header="time_ms,w")
    log = read_log(p, time_column="time_ms", time_unit="ms")
    assert log.fs == pytest.approx(500.0) and log.t0 == pytest.approx(1.0)
    np.testing.assert_allclose(log.time[:3], [0.0, 0.002, 0.004])


def test_log_repr_is_readable(tmp_path, record):
    t, x = record
    p = write_text(tmp_path / "log.csv", t, x)
    text = repr(read_log(p, time_column="t", unit="dps"))
    assert text.splitlines()[0] == "Log('log.csv', text)"
    assert "400 samples × 3 axes, float64, fs = 100 Hz (4 s)" in text
    assert "columns: gx, gy, gz" in text and "unit: deg/s (rate; given as unit=), input: rate" in text
    assert "t0 = 12.5 s, 0 gap(s)" in text


def test_docstring_examples():
    import allanite.io.reader as reader

    failures, tried = doctest.testmod(reader, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert tried > 0 and failures == 0


# --------------------------------------------------------------------------------------------------
# The real ADIS16405 run (shared data)
# --------------------------------------------------------------------------------------------------


def test_adis16405_run1(shared_data):
    path = shared_data / "adis16405" / "adis16405_run1_100Hz.csv.gz"
    if not path.is_file():
        pytest.skip(f"ADIS16405 run 1 not found at {path}")
    log = read_log(path, fs=100, columns=["gyro_x", "gyro_y", "gyro_z"], unit="deg/s")
    assert log.data.shape == (1_000_000, 3) and log.data.dtype == np.float64
    assert log.columns == ["gyro_x", "gyro_y", "gyro_z"]
    lsb = log.data / 0.05
    assert np.max(np.abs(lsb - np.round(lsb))) * 0.05 < 1e-9  # multiples of the 0.05 °/s LSB
    np.testing.assert_allclose(log.data.mean(axis=0), [0.40, -0.42, -0.29], atol=0.01)
    assert log.duration == pytest.approx(10_000.0)
    # the first data row, as in the file
    np.testing.assert_array_equal(log.data[0], [-0.05, -0.3, 0.7])
