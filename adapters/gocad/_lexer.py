"""Split a GOCAD ASCII file into lines and bulk runs of numeric element lines.

GOCAD files are keyword-first text. Most of a large file is made of runs of ``VRTX``,
``PVRTX``, ``ATOM``, ``TRGL``, ``SEG`` and ``TETRA`` lines; :func:`scan` finds those runs with numpy
(one look at the first bytes of every line) so that a reader converts each run with one bulk
parse (:func:`parse_run`) and walks only the few remaining lines in Python.
"""

from __future__ import annotations

import bisect
import contextlib
import importlib
import itertools
import struct
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from geobrep.errors import FormatError

__all__ = [
    "BULK_KEYWORDS",
    "KEYWORDS",
    "ORJSON",
    "Line",
    "Run",
    "Source",
    "keyword_codes",
    "parse_rows",
    "parse_run",
    "scan",
    "split_tokens",
]

#: Keywords whose lines are parsed in bulk (the keyword, then numbers).
BULK_KEYWORDS: tuple[str, ...] = ("VRTX", "PVRTX", "TRGL", "SEG", "TETRA", "ATOM", "PATOM")
#: Every keyword :func:`keyword_codes` recognises: the bulk ones, then the id lines of a
#: TSurf's borders (read in bulk by a whole body, see ``_bodies``; never a :class:`Run`).
KEYWORDS: tuple[str, ...] = (*BULK_KEYWORDS, "BSTONE", "BORDER")


class Line(NamedTuple):
    """One line that is not part of a bulk run: its 1-based number and text (no newline)."""

    number: int
    text: str


class Run(NamedTuple):
    """Consecutive lines ``first .. first + count - 1`` starting with the same bulk keyword.

    (Runs and lines are named tuples: a file makes thousands, and a frozen dataclass costs
    about three times as much to make.)"""

    keyword: str
    first: int
    count: int  # type: ignore[assignment]  # (a field, not tuple.count)
    start: int  # byte offsets in Source.data
    end: int


class Source:
    """The file's bytes and where each line starts and ends (without its line break).

    LF and CRLF line breaks are kept as they are (a CR before an LF is no part of the line:
    :attr:`ends` stops before it); a file with lone CRs (old Mac) has them turned into LFs.
    """

    def __init__(self, path: Path, data: bytes) -> None:
        self.path = path
        buffer = np.frombuffer(data, dtype=np.uint8)
        breaks = np.flatnonzero(buffer == 10)
        crlf: NDArray[np.bool_] | None = None
        if b"\r" in data:  # (a memchr: most files have none)
            crlf = buffer[np.maximum(breaks - 1, 0)] == 13
            if np.count_nonzero(buffer == 13) != np.count_nonzero(crlf):  # lone CRs
                data = data.replace(b"\r\n", b"\n").replace(b"\r", b"\n")
                buffer = np.frombuffer(data, dtype=np.uint8)
                breaks = np.flatnonzero(buffer == 10)
                crlf = None
        self.data = data
        # a final newline starts no line
        n = breaks.shape[0] + (len(data) > 0 and not data.endswith(b"\n"))
        self.starts = np.empty(n, dtype=np.int64)
        self.ends = np.empty(n, dtype=np.int64)
        if n:
            self.starts[0] = 0
            self.starts[1:] = breaks[: n - 1] + 1
            self.ends[: breaks.shape[0]] = breaks
            self.ends[breaks.shape[0] :] = len(data)
        if crlf is not None:  # a line ends before its CR
            self.ends[: breaks.shape[0]] -= crlf
        self.runs: list[Run] = []
        """Every bulk run of the file (filled by :func:`scan`)."""
        self.batched: dict[int, NDArray[Any]] | None = None
        """Run first line -> its numbers, parsed together with the runs like it."""
        self._codes: NDArray[np.int8] | None = None
        self._pairs: list[tuple[int, int]] | None = None
        self._others: list[int] | None = None
        self.cache: dict[type, object] = {}
        """What readers of the file's parts keep about the whole file (by their type)."""

    @property
    def codes(self) -> NDArray[np.int8]:
        """Per line: index + 1 of its keyword in :data:`KEYWORDS`, or 0 (computed once)."""
        if self._codes is None:
            self._codes = keyword_codes(self)
        return self._codes

    @property
    def others(self) -> list[int]:
        """0-based indices of the lines that start with none of :data:`KEYWORDS`."""
        if self._others is None:
            self._others = np.flatnonzero(self.codes == 0).tolist()
        return self._others

    @classmethod
    def read(cls, path: Path) -> Source:
        return cls(path, path.read_bytes())

    @property
    def n_lines(self) -> int:
        return int(self.starts.shape[0])

    def text(self, index: int) -> str:
        """Line ``index`` (0-based) as text."""
        return decode(self.data[self.starts[index] : self.ends[index]])

    def error(self, message: str, line: int | None) -> FormatError:
        return FormatError(message, self.path, line)


def decode(raw: bytes) -> str:
    """UTF-8 when valid, else Latin-1 (GOCAD writers use either; never fails)."""
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError:
        return raw.decode("latin-1")


def keyword_codes(source: Source) -> NDArray[np.int8]:
    """Per line: index + 1 of the keyword of :data:`KEYWORDS` it starts with (followed by a
    blank or a tab), or 0."""
    data, starts = source.data, source.starts
    size = len(data)
    # The first 8 bytes of every line as one little-endian integer (bytes past the end of
    # the file are 0, never the blank or tab that must follow a keyword): one gather.
    heads = np.zeros(source.n_lines, dtype=np.uint64)
    inside = int(np.searchsorted(starts, size - 7)) if size >= 8 else 0
    if inside:
        words = np.ndarray(shape=(size - 7,), dtype="<u8", buffer=data, strides=(1,))
        heads[:inside] = words[starts[:inside]]
    for line in range(inside, source.n_lines):
        heads[line] = int.from_bytes(data[int(starts[line]) : int(starts[line]) + 8], "little")
    codes = np.zeros(source.n_lines, dtype=np.int8)
    masked: dict[int, NDArray[np.uint64]] = {}
    for index, keyword in enumerate(KEYWORDS, start=1):
        raw = keyword.encode()
        width = len(raw) + 1  # the keyword and its follower
        if width not in masked:
            masked[width] = heads & np.uint64((1 << (8 * width)) - 1)
        head = masked[width]
        match = head == np.uint64(int.from_bytes(raw + b" ", "little"))
        match |= head == np.uint64(int.from_bytes(raw + b"\t", "little"))
        codes[match] = index
    return codes


def _runs(source: Source) -> list[tuple[int, int]]:
    """The file's stretches of lines ``[lo, hi)`` (0-based), each a bulk run or lines that
    are none; fills :attr:`Source.runs` (computed once)."""
    if source._pairs is not None:
        return source._pairs
    codes = source.codes.copy()
    codes[codes > len(BULK_KEYWORDS)] = 0  # BSTONE, BORDER: lines of their own
    n = codes.shape[0]
    change = np.flatnonzero(codes[1:] != codes[:-1]) + 1
    bounds = np.concatenate([[0], change, [n]]).tolist() if n else [0]
    source._pairs = list(itertools.pairwise(bounds))
    bulk = [(lo, hi) for lo, hi in source._pairs if codes[lo]]
    starts = source.starts[[lo for lo, _ in bulk]].tolist()
    ends = source.ends[[hi - 1 for _, hi in bulk]].tolist()
    source.runs = [
        Run(BULK_KEYWORDS[int(codes[lo]) - 1], lo + 1, hi - lo, start, end)
        for (lo, hi), start, end in zip(bulk, starts, ends, strict=True)
    ]
    return source._pairs


def _first(run: Run) -> int:
    return run.first


def scan(source: Source, start: int = 0) -> Iterator[Line | Run]:
    """Yield the file's content in order: bulk :class:`Run` s and other :class:`Line` s,
    from the 0-based line ``start`` on (a run ``start`` cuts is yielded whole).

    Blank lines are dropped; so are comment lines starting with ``#``, except ``# CTETRA``
    lines, which carry TSolid data.
    """
    pairs = _runs(source)
    codes = source.codes
    first = max(bisect.bisect_right(pairs, (start, source.n_lines + 1)) - 1, 0)
    if first >= len(pairs):
        return
    runs = iter(source.runs[bisect.bisect_left(source.runs, pairs[first][0] + 1, key=_first) :])
    data, n_bulk = source.data, len(BULK_KEYWORDS)
    for lo, hi in pairs[first:]:
        if 0 < codes[lo] <= n_bulk:
            yield next(runs)
            continue
        lo = max(lo, start)
        # the stretch's line bounds as Python ints (a numpy scalar per line costs more)
        bounds = zip(source.starts[lo:hi].tolist(), source.ends[lo:hi].tolist(), strict=True)
        for index, (begin, end) in enumerate(bounds, start=lo):
            text = decode(data[begin:end]).strip()
            if not text or (text[0] == "#" and not text.startswith("# CTETRA")):
                continue
            yield Line(index + 1, text)


def split_tokens(text: str) -> list[str]:
    """Whitespace-separated tokens, with double-quoted tokens kept whole (quotes removed).

    A quote opens a token wherever it stands (``a"b c"d`` is ``a``, ``b c``, ``d``); an
    unbalanced quote makes the rest of the line one token. Linear time in the length of the
    line: one split at the quotes, then one whitespace split of each unquoted stretch.

    >>> split_tokens('PROPERTIES " default property"  def-prop')
    ['PROPERTIES', ' default property', 'def-prop']
    """
    if '"' not in text:
        return text.split()
    pieces = text.split('"')  # unquoted, quoted, unquoted, ...; the last is open when even
    tokens: list[str] = []
    for index, piece in enumerate(pieces):
        if index % 2:
            tokens.append(piece)
        else:
            tokens.extend(piece.split())
    return tokens


class BulkParseError(Exception):
    """The bulk parse cannot handle this run; parse it line by line instead."""


def _renormalised(raw: bytes, keyword: bytes) -> bytes:
    """The run's lines with single spaces and no tabs or trailing spaces, keywords kept.

    Every line of a run starts with the keyword and a blank, so once the blanks are single
    spaces each line still starts with ``keyword + b" "``: the common case (trailing blanks,
    as exporters on Windows leave them) costs one ``replace``.
    """
    body = raw.rstrip()
    if b"\r" in body:
        body = body.replace(b"\r", b" ")
    if b"\t" in body:
        body = body.replace(b"\t", b" ")
    while b"  " in body:
        body = body.replace(b"  ", b" ")
    if b" \n" in body:
        body = body.replace(b" \n", b"\n")
    if not body.startswith(keyword + b" "):
        raise BulkParseError
    return body


def _byte_map(kept: bytes, separators: bytes, separator: bytes) -> bytes:
    """A ``bytes.translate`` table: ``kept`` bytes stay, ``separators`` become ``separator``,
    a CR (of a CRLF line break) a blank, and every other byte ``!``, which no number parser
    accepts (odd content fails the parse)."""
    table = bytearray(b"!" * 256)
    for byte in kept:
        table[byte] = byte
    for byte in separators:
        table[byte] = separator[0]
    table[13] = 32
    return bytes(table)


#: Float runs become one JSON list: number bytes stay; blanks and line breaks are commas
#: (a blank ending a line stays a blank: JSON whitespace).
_JSON_MAP = _byte_map(b"0123456789.+-eE", b" \t\n", b",")
#: Integer runs stay blank-separated text for numpy (no sign but ``-``, no exponent).
_INT_MAP = _byte_map(b"0123456789-", b" \t\n", b" ")
_INT_LIMIT = 2**62


def _load_orjson() -> ModuleType | None:
    """orjson parses and prints floats exactly (shortest round trip) and fast."""
    try:
        return importlib.import_module("orjson")
    except ImportError:  # pragma: no cover - exercised only without the speed-up
        return None


#: The orjson module when installed (bulk number conversion), else None (line-by-line path).
ORJSON = _load_orjson()


def parse_run(source: Source, run: Run, integer: bool) -> NDArray[Any]:
    """The numbers after the keyword of every line of ``run`` as a 2-D array (int64 when the
    run holds integers only, else float64).

    ``integer``: the run must hold integers only (ids).

    Raises :class:`BulkParseError` when the run holds anything but a rectangle of plain
    numbers (flags, odd spellings of infinity, ragged lines, a missing speed-up library), so
    that the caller parses it line by line with exact error messages.

    The run is copied once from :attr:`Source.data` and translated with a byte table; a run
    this fast path rejects (repeated or trailing blanks) is rewritten with single spaces and
    tried once more.
    """
    if ORJSON is None:
        raise BulkParseError
    keyword = run.keyword.encode()
    data = source.data
    only_integers = _only_integers(data, run)
    if integer and not only_integers:
        raise BulkParseError  # "1.0", "1e0": the line parser says why they are no ids
    if source.batched is None:
        source.batched = _parse_batches(source)
    batched = source.batched.pop(run.first, None)
    if batched is not None:
        return batched
    starts, trailing = _line_offsets(source, [run])
    text = _padded([memoryview(data)[run.start : run.end]])
    with contextlib.suppress(BulkParseError):  # single blanks only: else renormalise, below
        return _parse_block(text, starts, len(keyword), only_integers, trailing)
    return _parse_renormalised(text, keyword, run.count, only_integers)


def parse_rows(source: Source, runs: list[Run], integer: bool) -> NDArray[Any]:
    """The numbers after the keyword of every line of ``runs`` (runs of one keyword, in file
    order) as one 2-D array, as :func:`parse_run` reads each run (int64 when the runs hold
    integers only, else float64; ``integer``: they must).

    Raises :class:`BulkParseError` when the lines are not a rectangle of plain numbers (or
    the speed-up library is missing): the caller then reads them the way it reads any run.
    """
    if ORJSON is None or not runs:
        raise BulkParseError
    keyword = runs[0].keyword.encode()
    view = memoryview(source.data)
    count = sum(run.count for run in runs)
    text = _padded([view[run.start : run.end] for run in runs])
    only_integers = (
        text.find(b".") < 0
        and text.find(b"e") < 0
        and text.count(b"E") == count * keyword.count(b"E")
    )
    if integer and not only_integers:
        raise BulkParseError
    starts, trailing = _line_offsets(source, runs)
    with contextlib.suppress(BulkParseError):  # single blanks only: else renormalise, below
        return _parse_block(text, starts, len(keyword), only_integers, trailing)
    return _parse_renormalised(text, keyword, count, only_integers)


def _padded(pieces: list[memoryview]) -> bytearray:
    """The pieces (runs of lines) joined by line breaks, with a blank before and after (room
    for the brackets of a JSON list): the one copy of the text made before it is translated."""
    parts: list[bytes | memoryview] = [b"\n"] * (2 * len(pieces) + 1)
    parts[1::2] = pieces
    parts[0] = parts[-1] = b" "
    return bytearray().join(parts)


def _parse_renormalised(
    text: bytearray, keyword: bytes, count: int, integers: bool
) -> NDArray[Any]:
    """:func:`_parse_block` of a padded text that the fast path rejected, once its blanks
    are single spaces (:func:`_renormalised`)."""
    raw = _renormalised(bytes(text[1:-1]), keyword)
    breaks = np.flatnonzero(np.frombuffer(raw, dtype=np.uint8) == 10)
    if breaks.shape[0] != count - 1:
        raise BulkParseError
    starts = np.concatenate([[0], breaks + 1])
    none = np.zeros(0, dtype=np.int64)
    return _parse_block(_padded([memoryview(raw)]), starts, len(keyword), integers, none)


def _only_integers(data: bytes, run: Run) -> bool:
    """No decimal point or exponent in the run (beyond the keyword's own letters)."""
    keyword = run.keyword.encode()
    return (
        data.find(b".", run.start, run.end) < 0
        and data.find(b"e", run.start, run.end) < 0
        and data.count(b"E", run.start, run.end) == run.count * keyword.count(b"E")
    )


def _line_offsets(source: Source, runs: list[Run]) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Where the lines of ``runs`` start and where a blank ends one (no separator, as many
    exporters leave it), as offsets into the runs' text joined by line breaks."""
    if len(runs) == 1:
        run = runs[0]
        rows: slice | NDArray[np.int64] = slice(run.first - 1, run.first - 1 + run.count)
        base: int | NDArray[np.int64] = run.start
    else:
        firsts = np.array([run.first - 1 for run in runs], dtype=np.int64)
        counts = np.array([run.count for run in runs], dtype=np.int64)
        spans = np.array([run.end - run.start + 1 for run in runs], dtype=np.int64)
        run_starts = np.array([run.start for run in runs], dtype=np.int64)
        shifts = np.concatenate([[0], np.cumsum(spans)[:-1]])
        offsets = np.concatenate([[0], np.cumsum(counts)[:-1]])
        which = np.repeat(np.arange(len(runs)), counts)
        rows = firsts[which] + (np.arange(which.shape[0]) - offsets[which])
        base = (run_starts - shifts)[which]
    absolute = source.ends[rows]
    start = source.starts[rows] - base
    buffer = np.frombuffer(source.data, dtype=np.uint8)
    trailing = (absolute - base)[np.take(buffer, absolute - 1) == 32] - 1
    return start, trailing


def _parse_batches(source: Source) -> dict[int, NDArray[Any]]:
    """The numbers of every run of two lines or more, parsed in one go with the runs of the
    same keyword, kind (integers or not) and first-line width: ``{run first line: array}``.

    A batch that the bulk parse rejects is left out, so each of its runs is parsed on its own
    (and line by line where that fails): the same results, with exact error messages.
    """
    data = source.data
    view = memoryview(data)
    groups: dict[tuple[str, bool, int], list[Run]] = {}
    for run in source.runs:
        if run.count < 2:
            continue
        first_end = int(source.ends[run.first - 1])
        width = data.count(b" ", run.start, first_end) - (data[first_end - 1] == 32)
        groups.setdefault((run.keyword, _only_integers(data, run), width), []).append(run)
    parsed: dict[int, NDArray[Any]] = {}
    for (keyword, only_integers, _), runs in groups.items():
        if len(runs) < 2:
            continue
        text = _padded([view[run.start : run.end] for run in runs])
        starts, trailing = _line_offsets(source, runs)
        try:
            block = _parse_block(text, starts, len(keyword), only_integers, trailing)
        except BulkParseError:
            continue
        cuts = np.cumsum([run.count for run in runs])[:-1]
        for run, rows in zip(runs, np.split(block, cuts), strict=True):
            parsed[run.first] = rows
    return parsed


def _parse_block(
    text: bytearray,
    starts: NDArray[np.int64],
    skip: int,
    integers: bool,
    trailing: NDArray[np.int64],
) -> NDArray[Any]:
    """Lines beginning at the offsets ``starts`` in ``text[1:-1]`` (``text``: padded with a
    blank at each end, see :func:`_padded`), each a keyword of ``skip`` bytes, a blank and
    numbers separated by single blanks; ``trailing``: the offsets of the blanks ending lines
    (no separators)."""
    count = starts.shape[0]
    heads = starts[:, None] + np.arange(1, skip + 2)  # each keyword and the blank after it
    if count and (np.frombuffer(text, np.uint8)[heads[:, -1]] != 32).any():
        raise BulkParseError  # a keyword without a blank after it (a bare TRGL): the line parser
    if integers:
        return _parse_integers(text, heads, count, trailing + 1)
    # Translated into a mutable copy (bytes.translate is a plain table walk; numpy's take is
    # slower); the blanks at the ends become the brackets.
    json = text.translate(_JSON_MAP)
    json[0], json[-1] = ord("["), ord("]")
    if trailing.size:
        np.frombuffer(json, dtype=np.uint8)[1 + trailing] = 32
    # Each keyword and its blank become a marker entry ("null", or "[]" after a 3-letter
    # keyword; nothing else can produce either) that tells where the lines start.
    marker: list[Any] | None = None if skip >= 4 else []
    head = b"null," if marker is None else b"[],"
    np.frombuffer(json, dtype=np.uint8)[heads] = np.frombuffer(
        head + b" " * (skip + 1 - len(head)), dtype=np.uint8
    )
    assert ORJSON is not None
    try:
        flat: list[Any] = ORJSON.loads(json)
    except ValueError as exc:  # letters, flags, "inf", repeated blanks ("1,,2")
        raise BulkParseError from exc
    del json
    step = len(flat) // count  # numbers per line + 1
    # A rectangle: one marker per line and every step-th entry a marker, so every line has
    # step - 1 numbers.
    if step < 2 or step * count != len(flat) or flat[::step].count(marker) != count:
        raise BulkParseError
    del flat[::step]
    # Only numbers are left (the markers counted above). struct converts each as float()
    # does (ints too), straight into the array: twice as fast as np.array(flat).
    array = np.empty((count, step - 1), dtype=np.float64)
    try:
        struct.pack_into(f"{len(flat)}d", array.data, 0, *flat)
    except (struct.error, OverflowError) as exc:
        raise BulkParseError from exc
    return array


def _parse_integers(
    text: bytearray,
    heads: NDArray[np.int64],
    count: int,
    trailing: NDArray[np.int64],
) -> NDArray[np.int64]:
    """A run of integers (numpy's integer parser is faster than JSON's objects); offsets
    into the padded ``text``.

    Each keyword and its blank become a marker number (``-9...9``, as wide as the keyword)
    that numpy reads with the rest: the lines are a rectangle when every row of the result
    starts with the marker and no other number is the marker (else the blanks of each line
    are counted instead)."""
    raw = np.frombuffer(text, dtype=np.uint8)
    if text.find(b"-") >= 0:  # numpy reads a lone "-" as 0 and "1-2" as 1, -2
        minus = np.flatnonzero(raw == 45)
        if minus[-1] + 2 == raw.shape[0]:
            raise BulkParseError
        digit, before = raw[minus + 1], raw[minus - 1]
        if not (((digit >= 48) & (digit <= 57)) & ((before == 32) | (before == 9))).all():
            raise BulkParseError
    translated = np.frombuffer(text.translate(_INT_MAP), np.uint8)
    skip = heads.shape[1]
    marker = -(10 ** (skip - 2) - 1)
    translated[heads] = np.frombuffer(str(marker).encode() + b" ", dtype=np.uint8)
    try:
        array = np.fromstring(translated, dtype=np.int64, sep=" ")  # type: ignore[call-overload]
    except ValueError as exc:  # numpy stopped before the end of the text
        raise BulkParseError from exc
    step = array.shape[0] // count
    if step >= 2 and step * count == array.shape[0]:
        grid = array.reshape(count, step)
        if (grid[:, 0] == marker).all() and np.count_nonzero(array == marker) == count:
            if np.abs(array).max() >= _INT_LIMIT:  # (the markers are small)
                raise BulkParseError  # numpy saturated: let the exact path decide
            result: NDArray[np.int64] = np.ascontiguousarray(grid[:, 1:])
            return result
    # A rectangle: as many blanks on every line (a blank ending one aside), hence as many
    # numbers once numpy (which would accept repeated ones) has read the right total.
    is_blank = raw[1:-1] == 32
    is_blank[trailing - 1] = False
    blanks = np.flatnonzero(is_blank)
    per_line = np.diff(np.searchsorted(blanks, heads[:, 0] - 1), append=blanks.shape[0])
    width = int(per_line[0])
    if width == 0 or not (per_line == width).all():
        raise BulkParseError
    translated[heads] = 32
    array = np.fromstring(translated, dtype=np.int64, sep=" ")  # type: ignore[call-overload]
    if array.shape[0] != count * width or (array.size and np.abs(array).max() >= _INT_LIMIT):
        raise BulkParseError  # a token numpy split or saturated: let the exact path decide
    result = array.reshape(count, width)
    return result
