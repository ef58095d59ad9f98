"""Which format a log file is in, from its first bytes and its name."""

from __future__ import annotations

import gzip
import zlib
from pathlib import Path

from ..errors import InputError

__all__ = ["sniff_format"]


def sniff_format(path: Path) -> str:
    """The format of ``path`` from its content and name: "csv", "csv.gz", "npy", "npz", "parquet",
    "ros1" or "ros2" — or an InputError saying what the file is not."""
    if path.is_dir():
        if (path / "metadata.yaml").is_file() or any(path.glob("*.db3")) or any(path.glob("*.mcap")):
            return "ros2"
        raise InputError(f"{path}: is a folder, not a log file (a ROS 2 bag folder holds metadata.yaml)")
    try:
        with open(path, "rb") as f:
            head = f.read(16)
    except OSError as exc:
        raise InputError(f"{path}: cannot be opened ({exc.strerror or exc})") from None
    suffix = path.suffix.lower()
    if head.startswith(b"\x93NUMPY"):
        return "npy"
    if head.startswith(b"PK\x03\x04") or head.startswith(b"PK\x05\x06"):
        return "npz"
    if head.startswith(b"PAR1"):
        return "parquet"
    if head.startswith(b"#ROSBAG"):
        return "ros1"
    if suffix in (".db3", ".mcap"):
        return "ros2"
    if head.startswith(b"\x1f\x8b"):
        _check_text(path, gz=True)
        return "text.gz"
    if suffix == ".npy":
        raise InputError(f"{path}: not a valid .npy file (no NumPy header)")
    if suffix == ".npz":
        raise InputError(f"{path}: not a valid .npz file (not a zip archive)")
    if suffix in (".parquet", ".pq"):
        raise InputError(f"{path}: not a valid Parquet file (no PAR1 magic)")
    if suffix == ".bag":
        raise InputError(f"{path}: not a valid ROS 1 bag (no #ROSBAG header)")
    if suffix == ".gz":
        raise InputError(f"{path}: not a valid gzip file")
    _check_text(path, gz=False)
    return "text"


#: Bytes that never occur in a text log (NUL and the C0 controls other than tab, newline, CR, FF, VT).
_BINARY_BYTES = bytes(range(0, 9)) + bytes(range(14, 32))


def _check_text(path: Path, gz: bool) -> None:
    """An InputError naming what the file is not, when its first 4 KiB hold bytes no text log has."""
    try:
        with gzip.open(path, "rb") if gz else open(path, "rb") as f:
            head = f.read(4096)
    except (OSError, EOFError, zlib.error):
        return  # the reader reports a damaged gzip stream with its own message
    bad = sum(head.count(b) for b in _BINARY_BYTES)
    # one stray control byte is a damaged line (the text reader names it); many are not text at all
    if head and bad > max(2, len(head) // 100):
        kind = "gzip-compressed data that is not text" if gz else "binary data"
        raise InputError(
            f"{path}: not a log allanite can read — it holds {kind} ({bad} control bytes in the first "
            f"{len(head)}); allanite reads text (CSV/TSV, optionally .gz), .npy, .npz, Parquet and ROS bag files"
        )
