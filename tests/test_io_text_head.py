"""The text reader decodes only the head of a log whose head is ASCII (the core's parser reads the body from the
bytes): its head lines and the byte offset of a line are those of the whole text decoded, for ASCII, UTF-8 (with
and without a byte-order mark) and Latin-1 logs, short and long; the values read are NumPy's, bit for bit."""

from __future__ import annotations

import gzip

import numpy as np
import pytest

import allanite
from allanite.io import _text
from allanite.io._text import HEAD_CHARS, _Text


def _reference(raw: bytes, start: int):
    """The head and byte offset of line ``start`` computed from the whole text, as the reader did before."""
    try:
        text, codec = raw.decode("utf-8"), "utf-8"
    except UnicodeDecodeError:
        text, codec = raw.decode("latin-1"), "latin-1"
    bom = text.startswith("\ufeff")
    text = text[1:] if bom else text
    if len(text) <= HEAD_CHARS:
        head = (text.splitlines(), True)
    else:
        k = text.rfind("\n", 0, HEAD_CHARS) + 1
        head = (text[:k].splitlines(), False)
    chars = sum(map(len, text.splitlines(keepends=True)[:start]))
    return head, len(text[:chars].encode(codec)) + (3 if bom else 0)


def _body(rows: int) -> bytes:
    rng = np.random.default_rng(rows)
    return "".join(f"{a:.6g},{b:.4f}\n" for a, b in rng.normal(size=(rows, 2))).encode("ascii")


CASES = {
    "ascii short": b"a,b\n" + _body(10),
    "ascii long": b"# note\na,b\n" + _body(20_000),
    "ascii comments beyond the head": b"".join(b"# " + b"x" * 70 + b"\n" for _ in range(1200)) + b"a,b\n" + _body(50),
    "utf-8 unit in the header": "# rate in °/s\na,b\n".encode() + _body(20_000),
    "utf-8 byte-order mark": b"\xef\xbb\xbfa,b\n" + _body(20_000),
    "latin-1 header": "# rate in °/s\na,b\n".encode("latin-1") + _body(20_000),
    "ascii head, latin-1 body": b"a,b\n" + _body(20_000) + "# °\n".encode("latin-1"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_head_and_offsets_are_the_whole_texts(name):
    raw = CASES[name]
    doc = _Text(raw)
    head, whole = doc.head()
    for start in (0, 1, 2, len(head) - 1):
        ref_head, ref_offset = _reference(raw, start)
        assert (head, whole) == ref_head
        assert doc.byte_offset(start) == ref_offset


def test_an_ascii_head_is_all_that_is_decoded():
    doc = _Text(CASES["ascii long"])
    doc.head(), doc.byte_offset(2)
    assert "_decoded" not in doc.__dict__ and "lines" not in doc.__dict__
    doc = _Text(CASES["utf-8 unit in the header"])
    doc.head()
    assert "_decoded" in doc.__dict__  # a non-ASCII head: the codec is the whole file's


@pytest.mark.parametrize("name", ["ascii long", "utf-8 unit in the header", "latin-1 header"])
def test_values_are_numpys_bit_for_bit(tmp_path, name):
    path = tmp_path / "log.csv.gz"
    path.write_bytes(gzip.compress(CASES[name]))
    log = allanite.read_log(path, fs=100.0, columns=["a", "b"])
    text = CASES[name].decode("utf-8" if "latin" not in name else "latin-1")
    lines = text.splitlines()
    ref = np.loadtxt(lines[lines.index("a,b") + 1 :], delimiter=",")
    assert log.data.shape == ref.shape and np.array_equal(log.data.view(np.uint64), ref.view(np.uint64))


def test_a_latin1_body_goes_to_numpy_and_names_nothing_wrong(tmp_path):
    path = tmp_path / "log.csv"
    path.write_bytes(CASES["ascii head, latin-1 body"])
    assert _text.HEAD_CHARS < len(CASES["ascii head, latin-1 body"])
    log = allanite.read_log(path, fs=100.0)
    assert log.data.shape == (20_000, 2) and log.columns == ["a", "b"]


def test_a_text_parsed_in_pieces_is_numpys_and_a_bad_line_is_named(tmp_path):
    """Over 1 MiB the core parses line-aligned pieces on several threads: NumPy's values bit for bit, and a bad
    line in a late piece is still found and named."""
    rng = np.random.default_rng(8)
    x = rng.normal(size=(60_000, 3)) * np.array([1e-3, 1.0, 1e5])
    lines = ["t,a,b,c"] + [f"{i / 100:.2f},{float(a)!r},{b:.9g},{c:.6e}" for i, (a, b, c) in enumerate(x)]
    text = "\n".join(lines) + "\n"
    assert len(text) > 2 << 20
    path = tmp_path / "big.csv"
    path.write_text(text, encoding="ascii")
    log = allanite.read_log(path, time_column="t", columns=["a", "c"])
    ref = np.loadtxt(lines[1:], delimiter=",")
    assert np.array_equal(log.data.view(np.uint64), ref[:, [1, 3]].view(np.uint64))
    lines[50_001] = lines[50_001].replace(",", ",x", 1)
    path.write_text("\n".join(lines) + "\n", encoding="ascii")
    with pytest.raises(allanite.InputError, match=r"line 50002, column 2 \('a'\): 'x"):
        allanite.read_log(path, time_column="t", columns=["a", "c"])
