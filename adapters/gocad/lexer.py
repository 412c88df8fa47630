"""Split a GOCAD ASCII file into lines and bulk runs of numeric element lines.

GOCAD files are keyword-first text. Most of a large file is made of runs of ``VRTX``,
``PVRTX``, ``TRGL``, ``SEG`` and ``TETRA`` lines; :func:`scan` finds those runs with numpy
(one look at the first bytes of every line) so that a reader converts each run with one bulk
parse (:func:`parse_run`) and walks only the few remaining lines in Python.
"""

from __future__ import annotations

import importlib
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep.errors import FormatError

__all__ = ["BULK_KEYWORDS", "ORJSON", "Line", "Run", "Source", "parse_run", "scan", "split_tokens"]

#: Keywords whose lines are parsed in bulk (the keyword, then numbers).
BULK_KEYWORDS: tuple[str, ...] = ("VRTX", "PVRTX", "TRGL", "SEG", "TETRA")


@dataclass(frozen=True)
class Line:
    """One line that is not part of a bulk run: its 1-based number and text (no newline)."""

    number: int
    text: str


@dataclass(frozen=True)
class Run:
    """Consecutive lines ``first .. first + count - 1`` starting with the same bulk keyword."""

    keyword: str
    first: int
    count: int
    start: int  # byte offsets in Source.data
    end: int


class Source:
    """The file's bytes with line endings normalised to LF, and where each line starts."""

    def __init__(self, path: Path, data: bytes) -> None:
        self.path = path
        if b"\r" in data:
            data = data.replace(b"\r\n", b"\n").replace(b"\r", b"\n")
        self.data = data
        buffer = np.frombuffer(data, dtype=np.uint8)
        breaks = np.flatnonzero(buffer == 10)
        self.starts = np.concatenate([[0], breaks + 1]).astype(np.int64)
        self.ends = np.concatenate([breaks, [len(data)]]).astype(np.int64)
        if self.starts[-1] == len(data):  # a final newline does not start a line
            self.starts, self.ends = self.starts[:-1], self.ends[:-1]

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


def _keyword_codes(source: Source) -> NDArray[np.int8]:
    """Per line: index + 1 of its bulk keyword in :data:`BULK_KEYWORDS`, or 0."""
    width = 7
    buffer = np.frombuffer(source.data + b"\0" * width, dtype=np.uint8)
    columns = [buffer[source.starts + k] for k in range(width)]  # one gather per byte
    codes = np.zeros(source.n_lines, dtype=np.int8)
    for index, keyword in enumerate(BULK_KEYWORDS, start=1):
        match = np.ones(source.n_lines, dtype=bool)
        for k, byte in enumerate(keyword.encode()):
            match &= columns[k] == byte
        follower = columns[len(keyword)]
        match &= (follower == 32) | (follower == 9)
        codes[match] = index
    return codes


def scan(source: Source) -> Iterator[Line | Run]:
    """Yield the file's content in order: bulk :class:`Run` s and other :class:`Line` s.

    Blank lines are dropped; so are comment lines starting with ``#``, except ``# CTETRA``
    lines, which carry TSolid data.
    """
    codes = _keyword_codes(source)
    n = codes.shape[0]
    if n == 0:
        return
    change = np.flatnonzero(codes[1:] != codes[:-1]) + 1
    bounds = np.concatenate([[0], change, [n]])
    for lo, hi in zip(bounds[:-1].tolist(), bounds[1:].tolist(), strict=True):
        code = int(codes[lo])
        if code:
            yield Run(
                BULK_KEYWORDS[code - 1],
                lo + 1,
                hi - lo,
                int(source.starts[lo]),
                int(source.ends[hi - 1]),
            )
            continue
        for index in range(lo, hi):
            text = source.text(index).strip()
            if not text or (text.startswith("#") and not text.startswith("# CTETRA")):
                continue
            yield Line(index + 1, text)


def split_tokens(text: str) -> list[str]:
    """Whitespace-separated tokens, with double-quoted tokens kept whole (quotes removed).

    >>> split_tokens('PROPERTIES " default property"  def-prop')
    ['PROPERTIES', ' default property', 'def-prop']
    """
    if '"' not in text:
        return text.split()
    tokens: list[str] = []
    rest = text
    while True:
        rest = rest.lstrip()
        if not rest:
            return tokens
        if rest[0] == '"':
            close = rest.find('"', 1)
            if close < 0:  # unbalanced quote: the rest of the line is the token
                tokens.append(rest[1:])
                return tokens
            tokens.append(rest[1:close])
            rest = rest[close + 1 :]
        else:
            cut = len(rest)
            for index, char in enumerate(rest):
                if char.isspace() or char == '"':
                    cut = index
                    break
            tokens.append(rest[:cut])
            rest = rest[cut:]


class BulkParseError(Exception):
    """The bulk parse cannot handle this run; parse it line by line instead."""


def _normalised_body(chunk: bytes, keyword: bytes) -> bytes:
    """``b"KW 1  2 \nKW 3\t4"`` → ``b"1 2\n3 4"``: single spaces, one line per element.

    Only C-level bytes operations; the searches that guard the rarer fixes are cheap.
    """
    body = chunk.rstrip()
    if b"\t" in body:
        body = body.replace(b"\t", b" ")
    while b"  " in body:
        body = body.replace(b"  ", b" ")
    if b" \n" in body:
        body = body.replace(b" \n", b"\n")
    head = keyword + b" "
    if not body.startswith(head):
        raise BulkParseError
    return body[len(head) :].replace(b"\n" + head, b"\n")


def _renormalised(raw: bytes, keyword: bytes) -> bytes:
    """The run's lines with single spaces and no tabs or trailing spaces, keywords kept."""
    head = keyword + b" "
    return head + _normalised_body(raw, keyword).replace(b"\n", b"\n" + head)


_TO_COMMAS = bytes.maketrans(b" \n", b",,")
_NUMBER_BYTES = b"0123456789.+-eE \n"
_INTEGER_BYTES = b"0123456789- \n"
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
    """The numbers after the keyword of every line of ``run`` as a 2-D array.

    Raises :class:`BulkParseError` when the run holds anything but a rectangle of plain
    numbers (flags, odd spellings of infinity, ragged lines, a missing speed-up library), so
    that the caller parses it line by line with exact error messages.
    """
    if ORJSON is None:
        raise BulkParseError
    keyword = run.keyword.encode()
    raw = source.data[run.start : run.end]
    if b"\t" in raw or raw.endswith(b" "):
        raw = _renormalised(raw, keyword)
    if raw.translate(None, _NUMBER_BYTES + keyword):
        raise BulkParseError  # letters, flags, "inf", "1.#INF": only plain numbers go in bulk
    buffer = np.frombuffer(raw, dtype=np.uint8)
    newline = buffer == 10
    separators = np.flatnonzero(newline | (buffer == 32))
    if separators.size and (np.diff(separators) == 1).any():  # repeated or trailing spaces
        raw = _renormalised(raw, keyword)
        buffer = np.frombuffer(raw, dtype=np.uint8)
        newline = buffer == 10
        separators = np.flatnonzero(newline | (buffer == 32))
    breaks = np.flatnonzero(newline[separators])
    if breaks.shape[0] != run.count - 1:
        raise BulkParseError
    width = int(breaks[0]) if breaks.size else separators.shape[0]  # numbers per line
    # Rectangular: every (width + 1)-th separator is a line break, and nothing else is.
    if separators.shape[0] != run.count * (width + 1) - 1 or width == 0:
        raise BulkParseError
    if breaks.size and not np.array_equal(breaks, np.arange(width, separators.shape[0], width + 1)):
        raise BulkParseError
    # Every line starts with the keyword and one space (the first separator of the line).
    starts = np.concatenate([[0], separators[breaks] + 1])
    head = np.frombuffer(keyword + b" ", dtype=np.uint8)
    if not (buffer[starts[:, None] + np.arange(head.shape[0])] == head).all():
        raise BulkParseError
    size = run.count * width
    letters = bytes(set(keyword))
    if len(raw) - len(raw.translate(None, letters)) != run.count * len(keyword):
        raise BulkParseError  # keyword letters elsewhere than in the keywords ("3X")
    if not raw.translate(None, _INTEGER_BYTES + keyword):  # integers only: numpy parses them
        text = raw.translate(bytes.maketrans(letters, b" " * len(letters)))
        try:
            array = np.fromstring(text, dtype=np.int64, sep=" ")
        except ValueError as exc:
            raise BulkParseError from exc
        if array.shape[0] != size or (array.size and np.abs(array).max() >= _INT_LIMIT):
            raise BulkParseError  # a token numpy split or saturated: let the exact path decide
        return array.reshape(run.count, width)
    if integer:
        raise BulkParseError
    # JSON: separators become commas, the keyword and the space after it whitespace.
    table = bytearray(_TO_COMMAS)
    for letter in letters:
        table[letter] = 32
    json = bytearray(b"[") + raw.translate(bytes(table)) + b"]"
    view = np.frombuffer(json, dtype=np.uint8)
    view[starts + 1 + len(keyword)] = 32  # the byte after each keyword (offset 1 for "[")
    try:
        flat = ORJSON.loads(json)
        array = np.fromiter(flat, dtype=np.float64, count=len(flat))
    except (ValueError, TypeError, OverflowError) as exc:
        raise BulkParseError from exc
    if array.shape[0] != size:
        raise BulkParseError
    return array.reshape(run.count, width)
