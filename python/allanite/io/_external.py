"""The readers that need optional packages: Parquet (pyarrow) and ROS 1/2 bags (rosbags)."""

from __future__ import annotations

import numpy as np

from ..errors import InputError, MissingDependencyError, ParameterError
from ._columns import AUTO_CHANNELS, Record, pick_channels, select_columns

_IMU_TYPES = ("sensor_msgs/msg/Imu", "sensor_msgs/Imu")
_TEMPERATURE_TYPES = ("sensor_msgs/msg/Temperature", "sensor_msgs/Temperature")
_BAG_FIELDS = (
    "angular_velocity_x",
    "angular_velocity_y",
    "angular_velocity_z",
    "linear_acceleration_x",
    "linear_acceleration_y",
    "linear_acceleration_z",
)


def _need(module: str, extra: str, what: str):
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        raise MissingDependencyError(
            f"reading {what} needs the optional package {module.split('.')[0]!r}: pip install 'allanite[{extra}]'"
        ) from None


def read_parquet(path, columns, time_column, channels=None):
    pq = _need("pyarrow.parquet", "parquet", "Parquet files")
    pa = _need("pyarrow", "parquet", "Parquet files")
    try:
        schema = pq.read_schema(path)
    except Exception as exc:  # pyarrow raises ArrowInvalid / OSError subclasses
        raise InputError(f"{path}: not a readable Parquet file ({exc})") from None
    names = list(schema.names)
    if not names:
        raise InputError(f"{path}: the Parquet file has no columns")
    idx, t_idx, squeeze = select_columns(columns, time_column, names, path, channels=channels)
    ch = pick_channels(channels, idx, t_idx, names, path)
    want = [names[i] for i in idx + ch] + ([names[t_idx]] if t_idx is not None else [])
    try:
        table = pq.read_table(path, columns=want)
    except Exception as exc:
        raise InputError(f"{path}: cannot read columns {want} ({exc})") from None

    def column(name, is_time, nulls=False):
        col = table.column(name)
        typ = col.type
        if nulls and col.null_count and (pa.types.is_integer(typ) or pa.types.is_floating(typ)):
            # a channel's missing values (nulls) are NaN, filled where the log is finished (io._timing)
            return np.asarray(col.cast(pa.float64()).fill_null(float("nan")).to_numpy(), dtype=np.float64), None
        if col.null_count:
            mask = np.asarray(col.is_null().to_numpy(zero_copy_only=False))
            raise InputError(
                f"{path}: row {int(np.argmax(mask))}, column {name!r}: missing value (null); "
                f"only finite numbers are allowed"
            )
        if is_time and pa.types.is_timestamp(typ):
            ns = np.asarray(col.cast(pa.timestamp("ns")).cast(pa.int64()).to_numpy(), dtype=np.int64)
            if ns.size == 0:
                return ns.astype(np.float64), 0.0
            return (ns - ns[0]).astype(np.float64) * 1e-9, float(ns[0]) * 1e-9
        if not (pa.types.is_integer(typ) or pa.types.is_floating(typ)):
            raise InputError(f"{path}: column {name!r} has type {typ}, not a number")
        return np.asarray(col.to_numpy(), dtype=np.float64), None

    cols = [column(names[i], False)[0] for i in idx]
    data = np.column_stack(cols) if cols else np.empty((0, 0))
    if squeeze:
        data = data[:, 0]
    time, t_first, secs = None, 0.0, False
    if t_idx is not None:
        time, first = column(names[t_idx], True)
        if first is not None:
            t_first, secs = first, True
    return Record(
        data=data,
        names=[names[i] for i in idx],
        time=time,
        time_name=names[t_idx] if t_idx is not None else None,
        where=lambda r: f"row {r}",
        time_is_seconds=secs,
        t_first=t_first,
        channels={names[i]: column(names[i], False, nulls=True)[0] for i in ch},
        channels_recognised=isinstance(channels, str) and channels == AUTO_CHANNELS,
    )


def read_bag(path, fmt, columns, time_column, topic, channels=AUTO_CHANNELS):
    hl = _need("rosbags.highlevel", "ros", "ROS bags")
    bag = path.parent if (fmt == "ros2" and path.is_file()) else path
    if time_column not in (None, "header", "receive"):
        raise ParameterError(
            f"for a ROS bag, time_column must be None or 'header' (header.stamp) or 'receive' "
            f"(the bag's receive time), got {time_column!r}"
        )
    names = list(_BAG_FIELDS)
    idx, _, squeeze = select_columns(columns, None, names, path, default=None if columns is not None else names[:3])
    try:
        reader = hl.AnyReader([bag])
        reader.open()
    except Exception as exc:  # rosbags raises its own ReaderError / AnyReaderError
        raise InputError(f"{path}: not a readable ROS bag ({type(exc).__name__}: {exc})") from None
    try:
        imu = [c for c in reader.connections if c.msgtype in _IMU_TYPES]
        topics = sorted({c.topic for c in imu})
        if topic is None:
            if len(topics) != 1:
                others = sorted({f"{c.topic} ({c.msgtype})" for c in reader.connections})
                if not topics:
                    raise InputError(
                        f"{path}: no sensor_msgs/Imu topic in the bag; it holds: {', '.join(others) or 'nothing'}"
                    )
                raise ParameterError(f"{path}: several sensor_msgs/Imu topics ({', '.join(topics)}); pass topic=…")
            topic = topics[0]
        elif topic not in topics:
            raise InputError(f"{path}: no sensor_msgs/Imu topic {topic!r}; Imu topics: {', '.join(topics) or 'none'}")
        conns = [c for c in imu if c.topic == topic]
        temps = _temperature_topics(reader, channels, time_column, path)
        vals = []
        stamps = []
        for k, (con, t_recv, raw) in enumerate(reader.messages(connections=conns)):
            try:
                m = reader.deserialize(raw, con.msgtype)
            except Exception as exc:
                raise InputError(f"{path}: message {k} on {topic} cannot be decoded ({exc})") from None
            w, a = m.angular_velocity, m.linear_acceleration
            vals.append((w.x, w.y, w.z, a.x, a.y, a.z))
            if time_column == "receive":
                stamps.append(int(t_recv))
            else:
                st = m.header.stamp
                stamps.append(int(st.sec) * 1_000_000_000 + int(getattr(st, "nanosec", getattr(st, "nsec", 0))))
    finally:
        reader.close()
    if not vals:
        raise InputError(f"{path}: topic {topic} holds no messages")
    allv = np.asarray(vals, dtype=np.float64)
    data = allv[:, idx]
    if squeeze:
        data = data[:, 0].copy()
    ns = np.asarray(stamps, dtype=np.int64)
    if time_column != "receive" and not ns.any():
        raise InputError(
            f"{path}: every header.stamp on {topic} is zero; pass time_column='receive' to use the bag's receive times"
        )
    time = (ns - ns[0]).astype(np.float64) * 1e-9
    tname = "receive time" if time_column == "receive" else "header.stamp"
    # each temperature at the Imu messages' times: linear between its own, NaN beyond them (io._channels)
    t_ch = {
        k: np.interp((ns - ns[0]) * 1e-9, (t - ns[0]) * 1e-9, v, left=np.nan, right=np.nan)
        for k, (t, v) in temps.items()
    }
    return Record(
        data=data,
        names=[names[i] for i in idx],
        time=time,
        time_name=tname,
        where=lambda r: f"message {r} on {topic}",
        time_is_seconds=True,
        t_first=float(ns[0]) * 1e-9,
        channels=t_ch,
        channels_recognised=isinstance(channels, str) and channels == AUTO_CHANNELS,
    )


def _temperature_topics(reader, channels, time_column, path) -> dict:
    """The bag's ``sensor_msgs/Temperature`` topics asked for (``"auto"``: every one; else those named; None: none)
    as topic → (stamps in ns, temperatures), in time order."""
    if channels is None:
        return {}
    found = sorted({c.topic for c in reader.connections if c.msgtype in _TEMPERATURE_TYPES})
    if isinstance(channels, str) and channels == AUTO_CHANNELS:
        want = found
    else:
        want = [channels] if isinstance(channels, str) else list(channels)
        bad = [w for w in want if w not in found]
        if bad:
            raise InputError(
                f"{path}: no sensor_msgs/Temperature topic {bad[0]!r}; a bag's channels are its Temperature "
                f"topics: {', '.join(found) or 'none'}"
            )
    out = {}
    for name in want:
        stamps, temps = [], []
        for con, t_recv, raw in reader.messages(connections=[c for c in reader.connections if c.topic == name]):
            m = reader.deserialize(raw, con.msgtype)
            st = m.header.stamp
            sec = int(st.sec) * 1_000_000_000 + int(getattr(st, "nanosec", getattr(st, "nsec", 0)))
            stamps.append(int(t_recv) if time_column == "receive" else sec)
            temps.append(float(m.temperature))
        order = np.argsort(np.asarray(stamps, dtype=np.int64), kind="stable")
        out[name] = (np.asarray(stamps, dtype=np.int64)[order], np.asarray(temps, dtype=np.float64)[order])
    return out
