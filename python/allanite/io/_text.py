"""The text reader: CSV, TSV and whitespace-separated logs, optionally gzipped."""

from __future__ import annotations

import gzip
import os
import warnings
import zlib
from functools import cached_property

import numpy as np

from .. import _core
from ..errors import InputError, ParameterError
from ._columns import AUTO_CHANNELS, Record, first_nonfinite, pick_channels, select_columns
from ._isotime import is_iso_time, iso_seconds


def _is_number(s: str) -> bool:
    """What NumPy's text parser accepts: Python's float() also takes "1_0" and non-ASCII digits."""
    if not s.isascii() or "_" in s:
        return False
    try:
        float(s)
    except ValueError:
        return False
    return True


def _split(line: str, delim):
    fields = line.split(delim) if delim is not None else line.split()
    return [f.strip() for f in fields]


def _strip_comment(line: str) -> str:
    k = line.find("#")
    return line if k < 0 else line[:k]


def _guess_delimiter(line: str):
    for d in (",", "\t", ";"):
        if d in line:
            return d
    return None


#: Characters of a text log's beginning split into lines to find its header and first data row (the fast path
#: reads the rest as bytes; a log whose header is not found within them is split whole).
HEAD_CHARS = 1 << 16
#: Bytes of a text log's body the core's parser reads at a time (line-aligned pieces streamed from the file into
#: arrays allocated once for the rows the head's line length promises: the file is never held whole, the read
#: peaks near the arrays' size).
CHUNK_BYTES = 1 << 22


class _Text:
    """A text log's bytes (gunzipped) and, decoded on first use, its text (UTF-8, else Latin-1, without a
    byte-order mark), the codec and whether a mark was dropped; its lines split on first use. A large log's body
    is read by the core's parser in line-aligned pieces streamed from the file (:meth:`pieces`): the whole file is
    read into ``raw`` only for a log the core's parser leaves to NumPy, or an error message. Where the head
    decodes alone (ASCII, or UTF-8 cut at a character), only the head is decoded.

    ``_Text(raw)`` holds bytes already read; :meth:`open` reads only the head of a file, the rest on use."""

    def __init__(self, raw: bytes | None = None, *, path=None, gz: bool = False, prefix: bytes | None = None):
        self._path, self._gz = path, gz
        self._streamed = raw is None  # only the head read: a log longer than HEAD_CHARS bytes
        if raw is not None:
            self.raw = raw
            prefix = raw[: HEAD_CHARS + 1]
        assert prefix is not None
        self._prefix = prefix
        # the first HEAD_CHARS + 1 bytes, where ASCII: the text's first HEAD_CHARS + 1 characters in either codec
        self._ascii_head = prefix.decode("ascii") if prefix.isascii() else None

    @classmethod
    def open(cls, path, gz: bool) -> _Text:
        """The log at ``path`` (gunzipped when ``gz``), its head read; a short log is read whole."""
        with _open(path, gz) as f:
            prefix = f.read(HEAD_CHARS + 1)
        if len(prefix) <= HEAD_CHARS:
            return cls(prefix, path=path, gz=gz)
        return cls(path=path, gz=gz, prefix=prefix)

    @cached_property
    def raw(self) -> bytes:
        """The whole file's bytes (gunzipped)."""
        with _open(self._path, self._gz) as f:
            return f.read()

    def pieces(self, offset: int):
        """The bytes from ``offset`` on in pieces of about ``CHUNK_BYTES``, each ending at a line end (the last
        at the end of the file): what the core's parser reads one at a time."""
        if "raw" in self.__dict__:
            raw, a = self.raw, offset
            while a < len(raw):
                b = raw.rfind(b"\n", a, a + CHUNK_BYTES) + 1 if a + CHUNK_BYTES < len(raw) else len(raw)
                b = b if b > a else (raw.find(b"\n", a + CHUNK_BYTES) + 1 or len(raw))
                yield raw[a:b]
                a = b
            return
        with _open(self._path, self._gz) as f:
            f.seek(offset)
            rest = b""
            while block := f.read(CHUNK_BYTES):
                k = block.rfind(b"\n") + 1
                if not self._gz and 0 < k < len(block):  # a file seeks back to the line's start: one copy less
                    f.seek(k - len(block), 1)
                    yield block[:k]
                    continue
                buf = rest + block if rest else block
                k = buf.rfind(b"\n") + 1
                rest = buf[k:]
                if k:
                    yield buf if k == len(buf) else buf[:k]
            if rest:
                yield rest

    def rows_hint(self, offset: int) -> int:
        """About how many data rows lie from ``offset`` on: the body's bytes over the bytes per line of the head's
        complete lines past ``offset`` (+ 5 %); counted for a log read whole, or whose head holds no such line. The
        body's bytes: the file's size, a gzip file's from its trailer (ISIZE; its size × 4 where that is less)."""
        if "raw" in self.__dict__:
            return self.raw.count(b"\n", offset) + 1
        seg = self._prefix[offset : self._prefix.rfind(b"\n") + 1]
        lines = seg.count(b"\n")
        if not lines:
            return self._count_lines(offset)
        size = os.path.getsize(self._path)
        if self._gz:
            with open(self._path, "rb") as f:
                f.seek(-4, os.SEEK_END)
                size = max(int.from_bytes(f.read(4), "little"), 4 * size)  # ISIZE: the size mod 2³²
        return int((size - offset) / (len(seg) / lines) * 1.05) + 64

    def _count_lines(self, offset: int) -> int:
        """The line ends from ``offset`` on + 1: a bound on the data rows (the file read once more)."""
        n, buf = 1, bytearray(CHUNK_BYTES)
        with _open(self._path, self._gz) as f:
            f.seek(offset)
            while got := f.readinto(buf):
                n += buf.count(b"\n", 0, got)
        return n

    @cached_property
    def _decoded(self) -> tuple[str, str, bool]:
        try:
            text, codec = self.raw.decode("utf-8"), "utf-8"
        except UnicodeDecodeError:
            text, codec = self.raw.decode("latin-1"), "latin-1"
        bom = text.startswith("\ufeff")
        return (text[1:] if bom else text), codec, bom

    @property
    def text(self) -> str:
        return self._decoded[0]

    @property
    def codec(self) -> str:
        return self._decoded[1]

    @property
    def bom(self) -> bool:
        return self._decoded[2]

    @cached_property
    def lines(self) -> list[str]:
        return self.text.splitlines()

    @cached_property
    def _utf8_head(self) -> str | None:
        """The head decoded alone where it is UTF-8 (a character cut at its end dropped), without a byte-order
        mark; None where it is not (the whole file's codec then decides)."""
        for cut in range(4):
            try:
                text = self._prefix[: len(self._prefix) - cut].decode("utf-8")
            except UnicodeDecodeError:
                continue
            return text[1:] if text.startswith("\ufeff") else text
        return None

    def _head_text(self) -> str:
        """The text's first characters: HEAD_CHARS + 1 of them or more (all of a shorter text)."""
        if self._ascii_head is not None:
            return self._ascii_head
        if "raw" not in self.__dict__ and self._utf8_head is not None:
            return self._utf8_head
        return self.text[: HEAD_CHARS + 1]

    def head(self) -> tuple[list[str], bool]:
        """(the first lines — all of them when the text is short, else those in its first ``HEAD_CHARS``
        characters, complete lines only —, whether that is every line)."""
        head = self._head_text()
        if len(head) <= HEAD_CHARS and not self._streamed:
            return self.lines, True
        k = head.rfind("\n", 0, HEAD_CHARS) + 1  # (a streamed log is longer than HEAD_CHARS bytes)
        return head[:k].splitlines(), False

    def byte_offset(self, start: int) -> int:
        """Where line ``start`` begins in ``raw``."""
        head = self._head_text()
        kept = head.splitlines(keepends=True)[:start]
        chars = sum(map(len, kept))
        if len(kept) < start or chars > HEAD_CHARS:  # line `start` begins beyond the head
            chars = sum(map(len, self.text.splitlines(keepends=True)[:start]))
        if self._ascii_head is not None and chars <= HEAD_CHARS:
            return chars  # ASCII: a character is a byte, and there is no byte-order mark
        if "raw" not in self.__dict__ and self._utf8_head is not None and chars <= HEAD_CHARS:
            bom = self._prefix.startswith(b"\xef\xbb\xbf")
            return len(self._utf8_head[:chars].encode("utf-8")) + (3 if bom else 0)
        return len(self.text[:chars].encode(self.codec)) + (3 if self.bom else 0)


def _open(path, gz):
    """The file, as a binary stream gunzipped when ``gz``."""
    return gzip.open(path, "rb") if gz else open(path, "rb")


def _decode(path, gz) -> _Text:
    """The file, gunzipped when ``gz``, its head read (the rest on use: :class:`_Text`)."""
    try:
        return _Text.open(path, gz)
    except (OSError, zlib.error, EOFError, gzip.BadGzipFile) as exc:
        raise InputError(f"{path}: cannot be read{' as gzip' if gz else ''} ({exc})") from None


def _layout(path, lines, delimiter):
    """(first content line, first data line, delimiter, number of fields, column names) of a text log."""
    # first content line: the header or the first data row
    i0 = next((i for i, ln in enumerate(lines) if _strip_comment(ln).strip()), None)
    if i0 is None:
        what = "only comment lines" if any(ln.strip() for ln in lines) else "nothing"
        raise InputError(f"{path}: empty file — it holds {what}, no data rows")
    if delimiter is None:
        delim = _guess_delimiter(_strip_comment(lines[i0]))
    else:
        if not isinstance(delimiter, str) or len(delimiter) != 1 and delimiter.strip() != "":
            raise ParameterError(
                f"delimiter must be one character (',', '\\t', ';', …) or ' ' for whitespace, got {delimiter!r}"
            )
        delim = None if delimiter.strip() == "" else delimiter
    first = _split(_strip_comment(lines[i0]), delim)
    header = None
    # a header has no numeric field; a line mixing numbers and text is a (bad) data row
    if not any(_is_number(f) for f in first):
        header = [f.strip().strip('"').strip("'").strip() for f in first]
        start = i0 + 1
        i1 = next((i for i in range(start, len(lines)) if _strip_comment(lines[i]).strip()), None)
        if i1 is None:
            raise InputError(f"{path}: line {i0 + 1} is a header ({', '.join(header)}) but no data rows follow")
        ncols = len(_split(_strip_comment(lines[i1]), delim))
        if len(header) != ncols:
            raise InputError(
                f"{path}: the header on line {i0 + 1} names {len(header)} columns but line {i1 + 1} has {ncols} fields"
            )
    else:
        start = i0
        ncols = len(first)
        # a header written as a comment (np.savetxt's "# a,b,c") right before the data
        if i0 > 0 and lines[i0 - 1].lstrip().startswith("#"):
            cand = [f.strip().strip('"').strip("'") for f in _split(lines[i0 - 1].lstrip()[1:], delim)]
            if len(cand) == ncols and all(c and not _is_number(c) for c in cand):
                header = cand
    names = [h if h else f"col{k}" for k, h in enumerate(header)] if header else [f"col{k}" for k in range(ncols)]
    return i0, start, delim, ncols, names


def read_text(path, columns, time_column, delimiter, gz, channels=None):
    """The record of a text log: the header (or ``col0``, ``col1``, …), the chosen columns and ``channels`` parsed
    (by the core's decimal parser, else by NumPy), and on a parse error the first bad line found and named."""
    doc = _decode(path, gz)
    head, whole = doc.head()
    try:
        i0, start, delim, ncols, names = _layout(path, head, delimiter)
    except InputError:
        if whole:
            raise
        head, whole = doc.lines, True  # the header or the first data row lies beyond the head
        i0, start, delim, ncols, names = _layout(path, head, delimiter)
    idx, t_idx, squeeze = select_columns(columns, time_column, names, path, channels=channels)
    if columns is None:
        idx, squeeze = _without_text(path, head, start, delim, names, idx, squeeze)
    ch = pick_channels(channels, idx, t_idx, names, path)
    iso = t_idx is not None and delim is not None and _first_field_iso(head, start, delim, t_idx)
    need = sorted(set(idx + ch + ([t_idx] if t_idx is not None and not iso else [])))
    # parse only the needed columns when a one-character delimiter makes skipping safe
    usecols = need if (delim is not None and len(need) < ncols) else None
    parsed = usecols if usecols is not None else list(range(ncols))
    pos = {c: j for j, c in enumerate(parsed)}
    timed = [[pos[t_idx]]] if t_idx is not None and not iso else []
    groups = [[pos[c] for c in idx], *timed, *([pos[i]] for i in ch)]
    outs = _parse_fast(doc, doc.byte_offset(start), delim, ncols, parsed, groups, squeeze)
    if outs is None:  # not plain decimal rows: NumPy reads them, and a bad line is found and named
        try:
            arr = _parse_lines(path, doc, start, delim, ncols, need, names, usecols, blank=set(ch))
        except InputError as exc:
            raise _as_channel(exc, [names[i] for i in ch], channels) from None
        outs = _split_parsed(arr, groups, squeeze)
        del arr
    data, rest = outs[0], outs[1:]
    if data.shape[0] == 0:
        raise InputError(f"{path}: no data rows after the header on line {i0 + 1}")

    def where(r):
        return f"line {_line_of_row(doc.lines, start, r)}"

    hit = first_nonfinite(data if data.ndim == 2 else data[:, None])
    if hit is not None:
        r, c = hit
        raise InputError(
            f"{path}: {where(r)}, column {idx[c] + 1} ({names[idx[c]]!r}): non-finite value "
            f"{(data if data.ndim == 2 else data[:, None])[r, c]} (NaN or inf); only finite numbers are allowed"
        )
    t_first, secs, time = 0.0, False, None
    if iso:  # ISO 8601 date-times: seconds from the first, the first kept as POSIX seconds
        fields = [_split(ln, delim)[t_idx] for ln in doc.lines[start:] if _strip_comment(ln).strip()]
        (time, t_first), secs = iso_seconds(path, fields, where), True
    elif t_idx is not None:
        time = rest.pop(0)
    chans = {names[i]: c for i, c in zip(ch, rest)}
    return Record(
        data=data,
        names=[names[i] for i in idx],
        time=time,
        time_name=names[t_idx] if t_idx is not None else None,
        where=where,
        time_is_seconds=secs,
        t_first=t_first,
        checked_finite=True,
        channels=chans,
        channels_recognised=isinstance(channels, str) and channels == AUTO_CHANNELS,
        time_owned=time is not None,
    )


def _parse_fast(doc, offset, delim, ncols, parsed, groups, squeeze):
    """The body parsed by the core's decimal parser, piece by piece (:meth:`_Text.pieces`), into one preallocated
    array per group of ``parsed``'s positions — the samples' (rows, k), or (rows,) when ``squeeze``; each other
    group one column, (rows,) —; None when a piece is outside its grammar (or the core has no such parser)."""
    fast = getattr(_core, "parse_decimal_table", None)  # (a core built before the fast parser: the NumPy way)
    if fast is None:
        return None
    cap = max(16, doc.rows_hint(offset))  # pages past the rows written are never touched
    outs = [np.empty(cap if (squeeze or k) else (cap, len(g))) for k, g in enumerate(groups)]
    # a group of adjacent columns is a view of the parsed block (no copy by fancy indexing); one column a 1-D view
    takes = [g[0] if out.ndim == 1 else (slice(g[0], g[-1] + 1) if g == list(range(g[0], g[-1] + 1)) else g)
             for out, g in zip(outs, groups)]  # fmt: skip
    r = 0
    for piece in doc.pieces(offset):
        arr = fast(piece, 0, delim, ncols, parsed)
        if arr is None:
            return None
        m = arr.shape[0]
        if r + m > cap:  # more rows than the hint: grown in place (realloc), rarely
            cap = max(r + m, int(cap * 1.25))
            for out in outs:
                out.resize((cap, *out.shape[1:]), refcheck=False)
        for out, take in zip(outs, takes):
            out[r : r + m] = arr[:, take]
        r += m
    for out in outs:  # cut to the rows read: the arrays own just them
        out.resize((r, *out.shape[1:]), refcheck=False)
    return outs


def _split_parsed(arr, groups, squeeze) -> list:
    """NumPy's parsed columns as :func:`_parse_fast` returns them: the samples' (rows, k) (``arr`` itself where it
    is just them), or (rows,) when ``squeeze``; each other group's one column (rows,)."""
    outs = []
    for k, g in enumerate(groups):
        if k == 0 and not squeeze:
            outs.append(arr if g == list(range(arr.shape[1])) else np.ascontiguousarray(arr[:, g]))
        else:
            outs.append(arr[:, g[0]].copy())
    return outs


def _without_text(path, lines, start, delim, names, idx, squeeze):
    """Without ``columns=``: a column that holds text on the first and the last data row of the file's head
    (``rostopic echo -p``'s ``field.header.frame_id``) is no axis — left out with a warning, as a row counter is;
    kept (and reported as not a number) when every chosen column holds text, or one damaged row does."""
    rows = [_split(_strip_comment(ln), delim) for ln in lines[start:] if _strip_comment(ln).strip()]
    if not rows:
        return idx, squeeze
    fields = rows[0]

    def text_in(row, i):
        return i < len(row) and bool(row[i].strip()) and not _is_number(row[i])

    text = [i for i in idx if text_in(fields, i) and text_in(rows[-1], i)]
    if not text or len(text) == len(idx):
        return idx, squeeze
    warnings.warn(
        f"{path}: column(s) {', '.join(repr(names[i]) for i in text)} hold text ({fields[text[0]].strip()!r} on "
        "the first data row): not analysed as an axis; name the columns to analyse with columns= (--columns)",
        stacklevel=4,
    )
    kept = [i for i in idx if i not in text]
    return kept, len(kept) == 1


def _first_field_iso(lines, start, delim, k) -> bool:
    """Whether field ``k`` of the first data row is an ISO 8601 date-time (:mod:`._isotime`)."""
    row = next((ln for ln in lines[start:] if _strip_comment(ln).strip()), None)
    fields = _split(_strip_comment(row), delim) if row is not None else []
    return k < len(fields) and is_iso_time(fields[k])


def _as_channel(exc: InputError, chans: list, channels) -> InputError:
    """A parse error that names a channel column, with how to leave the channel out."""
    hit = next((c for c in chans if f"({c!r})" in str(exc)), None)
    if hit is None:
        return exc
    why = " (recognised as a temperature by its name)" if channels == AUTO_CHANNELS else ""
    return InputError(f"{exc} — column {hit!r} is read as a channel{why}; channels=None leaves it out")


def _number_or_nan(field: str) -> float:
    """A channel's field: an empty one is a missing value (NaN), as a sparse temperature leaves in a text export."""
    return float(field) if field.strip() else float("nan")


def _parse_lines(path, doc, start, delim, ncols, need, names, usecols, blank=frozenset()):
    """The data rows parsed by ``np.loadtxt`` (what the core's fast parser leaves: NaN, inf, other number
    forms, bad rows), the first bad line found and named. An empty field of a ``blank`` column (a channel) is NaN."""
    lines = doc.lines
    conv = {c: _number_or_nan for c in blank} if blank and delim is not None else None
    try:
        arr = np.loadtxt(
            lines[start:], delimiter=delim, comments="#", usecols=usecols, ndmin=2, dtype=np.float64, converters=conv
        )
    except (ValueError, IndexError) as exc:
        _diagnose(path, lines, start, delim, ncols, need, names, first_line=start + 1, blank=blank)
        raise InputError(f"{path}: cannot parse the numeric data ({exc})") from None
    if usecols is not None:
        # loadtxt skips unused fields, so it cannot see ragged rows: compare the number of delimiters
        # with what `rows × (columns − 1)` needs, and look closer only when they differ.
        found = doc.text.count(delim) - sum(ln.count(delim) for ln in lines[:start])
        if found != arr.shape[0] * (ncols - 1):
            _diagnose(path, lines, start, delim, ncols, [], names, first_line=start + 1)
    elif arr.shape[1] != ncols:  # pragma: no cover - loadtxt raises on ragged rows
        _diagnose(path, lines, start, delim, ncols, need, names, first_line=start + 1)
    return arr


def _line_of_row(lines, start, r):
    """1-based line number of data row r (comments and blank lines skipped) — only on error paths."""
    k = -1
    for i in range(start, len(lines)):
        if _strip_comment(lines[i]).strip():
            k += 1
            if k == r:
                return i + 1
    return len(lines)


def _diagnose(path, lines, start, delim, ncols, need, names, first_line, blank=frozenset()):
    """Find the first bad line the slow, precise way and raise an InputError naming it (an empty field of a
    ``blank`` column is no error)."""
    sep = "whitespace" if delim is None else repr(delim)
    for i in range(start, len(lines)):
        content = _strip_comment(lines[i])
        if not content.strip():
            continue
        fields = _split(content, delim)
        if len(fields) != ncols:
            raise InputError(
                f"{path}: line {i + 1}: ragged row — {len(fields)} fields (separated by {sep}) where line "
                f"{first_line} and the header have {ncols}"
            )
        for c in need:
            if not _is_number(fields[c]) and not (c in blank and not fields[c]):
                shown = fields[c] if fields[c] else "(empty)"
                comma = _is_number(fields[c].replace(",", ".", 1)) and fields[c].count(",") == 1
                raise InputError(
                    f"{path}: line {i + 1}, column {c + 1} ({names[c]!r}): {shown!r} is not a number"
                    + ("; a decimal comma is not read: write the file with decimal points" if comma else "")
                )
