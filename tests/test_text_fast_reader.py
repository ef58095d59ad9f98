"""The text reader's fast path (the core's decimal parser, allanite-core text.rs): the same numbers as
``np.loadtxt`` bit for bit on varied files, the slow path (NumPy) taken for anything else with its messages
unchanged, and the header found beyond the first lines."""

from __future__ import annotations

import gzip

import numpy as np
import pytest

from allanite import InputError, _core, read_log
from allanite.io import _text


@pytest.fixture
def calls(monkeypatch):
    """The fast parser's answers during a test: an array when it read the body, None when it left it."""
    seen = []
    real = _core.parse_decimal_table

    def spy(*args):
        out = real(*args)
        seen.append(out)
        return out

    monkeypatch.setattr(_text._core, "parse_decimal_table", spy)
    return seen


def slow_path(monkeypatch):
    monkeypatch.setattr(_text._core, "parse_decimal_table", lambda *args: None)


def same_bits(a, b):
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    return a.shape == b.shape and np.array_equal(a.view(np.int64), b.view(np.int64))


def numbers(rng, n):
    """Decimal strings of many forms: repr (17 digits), fixed, scientific, signs, leading/trailing dots,
    22+ significant digits (past the fast path's 19), subnormals and signed zeros."""
    x = rng.normal(scale=10.0 ** rng.integers(-12, 12, n), size=n)
    forms = [
        lambda v: repr(v),
        lambda v: f"{v:.6f}",
        lambda v: f"{v:.3e}",
        lambda v: f"{v:+.10E}",
        lambda v: f"{v:.25g}",
        lambda v: f"{abs(v):.4f}".lstrip("0") or "0.",
        lambda v: f"{round(v)}.",
        lambda v: f"{v * 1e-300:.17g}",
        lambda v: "-0" if v < 0 else "0.000",
        lambda v: f"{v:.22f}",
    ]
    return [forms[i % len(forms)](float(v)) for i, v in enumerate(x)]


@pytest.mark.parametrize(
    "delim, newline, comments, trailing, gz",
    [
        (",", "\n", False, False, False),
        (",", "\r\n", True, False, True),
        (";", "\n", True, False, False),
        ("\t", "\r\n", False, False, False),
        (None, "\n", True, False, False),
        (",", "\n", False, True, False),
    ],
)
def test_fast_path_equals_loadtxt_bit_for_bit(tmp_path, rng, calls, delim, newline, comments, trailing, gz):
    n, k = 600, 4
    vals = np.array(numbers(rng, n * k), dtype=object).reshape(n, k)
    sep = delim if delim is not None else "  "
    end = sep if trailing else ""
    lines = ["# a log written by hand", sep.join(["gx", "gy", "gz", "t"]) + end]
    body = []
    for i, row in enumerate(vals):
        if comments and i % 97 == 5:
            body += ["# a comment between rows", ""]
        pad = " " if (delim not in (None, "\t") and i % 7 == 0) else ""
        body.append(sep.join(f"{pad}{v}{pad}" for v in row) + end + (" # inline" if comments and i % 11 == 0 else ""))
    text = newline.join(lines + body) + newline
    p = tmp_path / ("log.csv.gz" if gz else "log.csv")
    p.write_bytes(gzip.compress(text.encode()) if gz else text.encode())
    log = read_log(p, fs=100.0, columns=["gx", "gz"])
    want = np.loadtxt(text.splitlines()[2:], delimiter=delim, comments="#", usecols=[0, 2], ndmin=2, dtype=np.float64)
    assert same_bits(log.data, want)
    assert isinstance(calls[-1], np.ndarray)  # the fast path read it


def test_fast_and_slow_paths_agree(tmp_path, rng, monkeypatch):
    vals = numbers(rng, 3000)
    text = "t,w\n" + "".join(f"{i / 100!r},{v}\n" for i, v in enumerate(vals))
    p = tmp_path / "w.csv"
    p.write_text(text)
    fast = read_log(p, time_column="t")
    slow_path(monkeypatch)
    slow = read_log(p, time_column="t")
    assert same_bits(fast.data, slow.data) and fast.fs == slow.fs


@pytest.mark.parametrize(
    "row, pattern",
    [
        ("0.03,7,eight", r"line 5, column 3 \('gy'\): 'eight' is not a number"),
        ("0.03,7", r"line 5: ragged row — 2 fields \(separated by ','\) where line 3 and the header have 3"),
        ("0.03,7,8,9", r"line 5: ragged row — 4 fields"),
        ("0.03,nan,8", r"line 5, column 2 \('gx'\): non-finite value nan"),
        ("0.03,7,1e999", r"line 5, column 3 \('gy'\): non-finite value inf"),
        ("0.03,1_0,8", r"line 5, column 2 \('gx'\): '1_0' is not a number"),
        ("0.03,\u00b07,8", r"line 5, column 2 \('gx'\): '°7' is not a number"),
    ],
)
def test_off_the_fast_path_errors_are_named_as_before(tmp_path, calls, row, pattern):
    lines = ["# log", "t,gx,gy", "0.00,1,2", "0.01,3,4", row, "0.04,5,6"]
    p = tmp_path / "bad.csv"
    p.write_bytes(("\n".join(lines) + "\n").encode())
    with pytest.raises(InputError, match=pattern):
        read_log(p, time_column="t")
    assert calls and calls[-1] is None  # the fast path left the file to NumPy


def test_ragged_row_in_an_unread_column(tmp_path):
    p = tmp_path / "r.csv"
    p.write_text("a,b,c\n1,2,3\n4,5\n6,7,8\n")
    with pytest.raises(InputError, match=r"line 3: ragged row — 2 fields"):
        read_log(p, fs=10.0, columns=["a"])


def test_unread_columns_are_not_parsed(tmp_path, calls):
    p = tmp_path / "u.csv"
    p.write_text("a,label,c\n1,x,3\n4,,6\n")
    log = read_log(p, fs=10.0, columns=["a", "c"])
    assert log.data.tolist() == [[1.0, 3.0], [4.0, 6.0]] and isinstance(calls[-1], np.ndarray)


def test_header_beyond_the_head_non_ascii_header_and_bom(tmp_path, calls):
    comments = "".join(f"# line {i} of a long preamble, °C and µs\n" for i in range(4000))  # > HEAD_CHARS
    assert len(comments) > _text.HEAD_CHARS
    body = "".join(f"{i * 0.01:.2f},{i * 0.5 - 3:.3f}\n" for i in range(50))
    p = tmp_path / "long.csv"
    p.write_bytes(b"\xef\xbb\xbf" + (comments + "t,rate \u00b0/s\n" + body).encode("utf-8"))
    log = read_log(p, time_column="t")
    assert log.columns == ["rate °/s"] and same_bits(log.data, [i * 0.5 - 3 for i in range(50)])
    q = tmp_path / "latin.csv"
    q.write_bytes(("# Temperatur \u00b0C\nt,w\u00e4rme\n" + body).encode("latin-1"))
    log = read_log(q, time_column="t")
    assert log.columns == ["wärme"] and log.data.size == 50 and isinstance(calls[-1], np.ndarray)


def test_data_rows_only_and_whitespace(tmp_path, calls):
    p = tmp_path / "plain.txt"
    p.write_text("   1   2\n\n 3 4   \n\t5\t6\n")
    log = read_log(p, fs=1.0)
    assert log.data.tolist() == [[1.0, 2.0], [3.0, 4.0], [5.0, 6.0]] and isinstance(calls[-1], np.ndarray)


def test_blank_line_with_a_delimiter_is_still_an_error(tmp_path, calls):
    p = tmp_path / "blank.csv"
    p.write_text("t,w\n0,1\n   \n0.1,2\n")
    with pytest.raises(InputError, match=r"blank\.csv"):
        read_log(p, time_column="t")
    assert calls[-1] is None
