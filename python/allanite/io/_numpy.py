"""The NumPy readers: .npy (memory-mapped) and .npz, plain or structured arrays."""

from __future__ import annotations

import tokenize
import zipfile
import zlib

import numpy as np

from ..errors import AllaniteError, InputError, ParameterError
from ._columns import AUTO_CHANNELS, AUTO_TIME, Record, pick_channels, recognise_time, select_columns


def _numeric_check(path, arr, what):
    if arr.dtype.kind not in "iuf":
        raise InputError(f"{path}: {what} has dtype {arr.dtype}; samples must be real numbers (integer or float)")


def _columns_of(mm, idx):
    """Columns `idx` of a 2-D (possibly memory-mapped) array, as a view whenever possible."""
    if len(idx) == mm.shape[1] and idx == list(range(mm.shape[1])):
        return mm
    if idx == list(range(idx[0], idx[0] + len(idx))):
        return mm[:, idx[0] : idx[0] + len(idx)]
    return np.asarray(mm[:, idx])


def _array_record(path, arr, columns, time_column, label, extra_time=None, channels=None):
    """A record from a 1-D, 2-D or structured array (the .npy/.npz common path); ``channels`` only from a structured
    one's fields (an unstructured array's columns have no names to recognise)."""
    if arr.dtype.names:
        names = list(arr.dtype.names)
        if arr.ndim != 1:
            raise InputError(f"{path}: {label} is a structured array of shape {arr.shape}; 1-D is expected")
        idx, t_idx, squeeze = select_columns(columns, time_column, names, path, channels=channels)
        ch = pick_channels(channels, idx, t_idx, names, path)
        for i in idx + ch + ([t_idx] if t_idx is not None else []):
            _numeric_check(path, arr[names[i]], f"field {names[i]!r}")
        data = np.column_stack([np.asarray(arr[names[i]], dtype=np.float64) for i in idx])
        time = np.asarray(arr[names[t_idx]], dtype=np.float64) if t_idx is not None else None
        if squeeze:
            data = data[:, 0]
        return Record(
            data=data,
            names=[names[i] for i in idx],
            time=time,
            time_name=names[t_idx] if t_idx is not None else None,
            where=lambda r: f"row {r}",
            channels={names[i]: np.asarray(arr[names[i]], dtype=np.float64) for i in ch},
            channels_recognised=isinstance(channels, str) and channels == AUTO_CHANNELS,
        )
    _numeric_check(path, arr, label)
    if arr.ndim != 2 and channels is not None and not (isinstance(channels, str) and channels == AUTO_CHANNELS):
        raise ParameterError(f"{path}: channels={channels!r}: {label} is one column, so it holds no other channel")
    tname, chans = None, {}
    if arr.ndim == 1:
        names = ["col0"]
        if time_column is AUTO_TIME:
            recognise_time(names, path)  # a lone column is never a time column: fs is needed
        if time_column is not None and extra_time is None:
            raise InputError(
                f"{path}: {label} is 1-D (one column), so it cannot hold a time column "
                f"{time_column!r} besides the samples"
            )
        data, time = arr, extra_time
        if columns is not None:
            _, _, squeeze = select_columns(columns, None, names, path)
            if not squeeze:
                data = arr.reshape(-1, 1)
        out_names = names
    elif arr.ndim == 2:
        names = [f"col{k}" for k in range(arr.shape[1])]
        if extra_time is not None:
            idx, _, squeeze = select_columns(columns, None, names, path, channels=channels)
            t_idx = None
        else:
            idx, t_idx, squeeze = select_columns(columns, time_column, names, path, channels=channels)
        chans = {
            names[i]: np.asarray(arr[:, i], dtype=np.float64) for i in pick_channels(channels, idx, t_idx, names, path)
        }
        data = _columns_of(arr, idx)
        if squeeze:
            data = data[:, 0]
        time = np.asarray(arr[:, t_idx], dtype=np.float64) if t_idx is not None else extra_time
        out_names = [names[i] for i in idx]
    else:
        raise InputError(
            f"{path}: {label} has shape {arr.shape}; samples must be 1-D (samples,) or 2-D (samples, axes)"
        )
    if extra_time is not None:
        tname = time_column
        if extra_time.shape != (arr.shape[0],):
            raise InputError(
                f"{path}: time array {time_column!r} has shape {extra_time.shape} but the samples "
                f"have {arr.shape[0]} rows"
            )
    elif arr.ndim == 2 and time_column is not None:
        tname = names[t_idx]
    return Record(
        data=data, names=out_names, time=time, time_name=tname, where=lambda r: f"row {r}", channels=chans or None
    )


#: What NumPy's readers raise on damaged .npy/.npz bytes (header parser, zip layer, decompression).
_DAMAGED = (
    ValueError,
    OSError,
    EOFError,
    zlib.error,
    zipfile.BadZipFile,
    tokenize.TokenError,
    SyntaxError,
    KeyError,
    IndexError,
    TypeError,
    OverflowError,
    MemoryError,
    NotImplementedError,
    UnicodeDecodeError,
)


def read_npy(path, columns, time_column, channels=None):
    try:
        arr = np.load(path, mmap_mode="r", allow_pickle=False)
    except _DAMAGED as exc:  # a damaged header fails in NumPy's header parser with many exception types
        raise InputError(f"{path}: not a readable .npy file ({type(exc).__name__}: {exc})") from None
    return _array_record(path, arr, columns, time_column, "the array", channels=channels)


def read_npz(path, columns, time_column, array, channels=None):
    try:
        z = np.load(path, allow_pickle=False)
    except _DAMAGED as exc:
        raise InputError(f"{path}: not a readable .npz file ({type(exc).__name__}: {exc})") from None
    try:
        with z:
            files = list(z.files)
            if not files:
                raise InputError(f"{path}: the .npz archive holds no arrays")
            time_arr = None
            if isinstance(time_column, str) and time_column in files and time_column != array:
                t_raw = z[time_column]
                _numeric_check(path, t_raw, f"time array {time_column!r}")
                time_arr = np.asarray(t_raw, dtype=np.float64)
            if array is None:
                cand = [f for f in files if f != (time_column if time_arr is not None else None)]
                if len(cand) != 1:
                    raise ParameterError(
                        f"{path}: the archive holds arrays {', '.join(map(repr, files))}; pass "
                        f"array=… to choose the samples"
                    )
                array = cand[0]
            elif array not in files:
                raise InputError(f"{path}: no array named {array!r}; available: {', '.join(map(repr, files))}")
            try:
                arr = z[array]
            except _DAMAGED as exc:
                raise InputError(f"{path}: array {array!r} cannot be read ({type(exc).__name__}: {exc})") from None
            label = f"array {array!r}"
            return _array_record(path, arr, columns, time_column, label, extra_time=time_arr, channels=channels)
    except AllaniteError:
        raise
    except _DAMAGED as exc:  # damaged members: bad CRC, truncated streams, broken member headers
        raise InputError(f"{path}: not a readable .npz file ({type(exc).__name__}: {exc})") from None
