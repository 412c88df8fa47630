"""Keyword lines of the GOCAD objects that are read line by line (Voxet, SGrid, Well).

:func:`parse_keyed` splits one such file into its object type, ``HEADER {...}`` entries, the
``GOCAD_ORIGINAL_COORDINATE_SYSTEM`` block and the remaining keyword lines (``{...}`` blocks of
property class headers are kept apart), each with its 1-based line number. Body lines are left
to the object's own reader.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from geobrep.adapters.gocad._lexer import split_tokens
from geobrep.adapters.gocad._numbers import parse_float, parse_int, shown
from geobrep.adapters.limits import human_bytes
from geobrep.errors import FormatError

__all__ = ["KeyedFile", "KeyedLine", "parse_keyed", "read_text"]

#: Text files read whole: the largest header (or ASCII table) a reader accepts.
MAX_TEXT = 1 << 30


@dataclass(frozen=True)
class KeyedLine:
    """One keyword line: its number, upper-case keyword and the tokens after it."""

    number: int
    keyword: str
    tokens: list[str]
    path: Path

    def error(self, message: str) -> FormatError:
        return FormatError(f"{self.keyword}: {message}", self.path, self.number)

    def floats(self, count: int, start: int = 0) -> list[float]:
        """``count`` numbers from token ``start``; a FormatError when they are not there."""
        values = self.tokens[start : start + count]
        if len(values) < count:
            raise self.error(f"needs {count} numbers, got {len(values)}")
        try:
            return [parse_float(v) for v in values]
        except ValueError as exc:
            raise self.error(str(exc)) from None

    def int_at(self, index: int = 0, low: int = 0, high: int = 2**40) -> int:
        """The integer token ``index``, within ``low .. high``."""
        if len(self.tokens) <= index:
            raise self.error(f"needs a value at position {index + 1}")
        try:
            value = parse_int(self.tokens[index])
        except ValueError as exc:
            raise self.error(str(exc)) from None
        if not low <= value <= high:
            raise self.error(f"{shown(self.tokens[index])} is not within {low} .. {high}")
        return value

    def rest(self, start: int = 0) -> str:
        return " ".join(self.tokens[start:])


@dataclass
class KeyedFile:
    """A GOCAD object read as keyword lines."""

    path: Path
    object_type: str
    header: dict[str, str] = field(default_factory=dict)
    crs: dict[str, str | list[str]] | None = None
    lines: list[KeyedLine] = field(default_factory=list)
    blocks: dict[str, dict[str, str]] = field(default_factory=dict)
    size: int = 0

    @property
    def name(self) -> str:
        return self.header.get("name", self.path.stem)


def read_text(path: Path, what: str = "file") -> str:
    """The text of ``path`` (Latin-1 bytes kept as they are), bounded in size."""
    try:
        size = path.stat().st_size
    except OSError as exc:
        raise FormatError(f"cannot open the {what}: {exc.strerror}", path) from None
    if size > MAX_TEXT:
        raise FormatError(f"the {what} is {human_bytes(size)}, more than a text file may be", path)
    data = path.read_bytes()
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        text = data.decode("latin-1")
    return text.replace("\r\n", "\n").replace("\r", "\n")


def _block(lines: list[str], start: int, path: Path) -> tuple[dict[str, str], int]:
    """``key: value`` entries of a ``{ ... }`` block opened on line ``start``; the next line."""
    entries: dict[str, str] = {}
    index = start + 1
    while index < len(lines):
        text = lines[index].strip()
        if text.startswith("}"):
            return entries, index + 1
        key, sep, value = text.partition(":")
        if sep:
            entries[key.strip()] = value.strip()
        index += 1
    raise FormatError("a '{' block is not closed by '}'", path, start + 1)


def _crs(lines: list[str], start: int, path: Path) -> tuple[dict[str, str | list[str]], int]:
    block: dict[str, str | list[str]] = {}
    index = start + 1
    while index < len(lines):
        tokens = split_tokens(lines[index])
        index += 1
        if not tokens:
            continue
        key = tokens[0].upper()
        if key == "END_ORIGINAL_COORDINATE_SYSTEM":
            return block, index
        if key in ("AXIS_NAME", "AXIS_UNIT"):
            block[key] = tokens[1:4]
        else:
            block[key] = " ".join(tokens[1:])
    raise FormatError(
        "the coordinate system block has no END_ORIGINAL_COORDINATE_SYSTEM", path, start + 1
    )


def parse_keyed(path: Path, text: str, stop: tuple[str, ...] = ("END",)) -> tuple[KeyedFile, int]:
    """The object of ``text`` up to its first ``stop`` keyword; the index of the line after it
    (``len(lines)`` when the object is not closed)."""
    lines = text.split("\n")
    first = next((i for i, t in enumerate(lines) if t.strip()), None)
    tokens = split_tokens(lines[first]) if first is not None else []
    if len(tokens) < 2 or tokens[0].upper() != "GOCAD":
        raise FormatError("not a GOCAD file (no 'GOCAD <type>' line)", path, 1)
    keyed = KeyedFile(path=path, object_type=tokens[1], size=len(text))
    index = (first or 0) + 1
    while index < len(lines):
        raw = lines[index]
        tokens = split_tokens(raw)
        if not tokens or tokens[0].startswith("#"):
            index += 1
            continue
        keyword = tokens[0].upper()
        if keyword.startswith("HEADER"):
            if "{" not in raw:
                index += 1
                continue
            entries, index = _block(lines, index, path)
            if not keyed.header:  # a Well's second HEADER holds its symbol: keep the first
                keyed.header.update(entries)
            continue
        if keyword == "GOCAD_ORIGINAL_COORDINATE_SYSTEM":
            keyed.crs, index = _crs(lines, index, path)
            continue
        if raw.rstrip().endswith("{"):
            entries, after = _block(lines, index, path)
            keyed.blocks[" ".join(tokens[:-1])] = entries
            index = after
            continue
        if keyword in stop:
            return keyed, index + 1
        keyed.lines.append(KeyedLine(index + 1, keyword, tokens[1:], path))
        index += 1
    return keyed, len(lines)
