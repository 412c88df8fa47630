"""Rows of numbers from an ASCII table (a Voxet or SGrid ``ASCII_DATA_FILE``), parsed vectorised.

A table of ``I J K value...`` rows is tens of millions of numbers; numpy's text parsers spend
about 150 ns on each (a call to the C library's ``strtod`` per token), which is most of the
time of reading a big Voxet. Here the file is read once, block by block into one reused buffer
of :data:`_CHUNK` bytes (a size that keeps the block and the temporaries of its passes in the
processor's cache), each block is cut into tokens with a few whole-block numpy passes, and the
tokens are converted with integer arithmetic on 8-byte words (eight digits in a handful of
shifts and multiplications, as in ``fast_float``):

* the integer columns (``I J K``) become int64 directly;
* a decimal ``[-+]digits[.digits][e[-+]digits]`` becomes the integer of its digits ``m``
  (at most 19 significant ones) and a power of ten ``10**e`` (``|e| <= 27``), both exact in
  the x87 80-bit ``long double``; ``m * 10**e`` (or ``m / 10**-e``) is then rounded once to
  its 64-bit significand and once more to float64. The second rounding is the correctly
  rounded float64 of the decimal unless the extended result lies exactly half way between
  two doubles (its low 11 significand bits ``10000000000``), since the decimal is within half
  an extended unit of it: those tokens, and every other token outside the fast grammar
  (``nan``, ``1.#INF``, more digits, larger exponents), are parsed one by one with Python's
  ``float``. The result is the float64 ``float()`` gives, bit for bit. Where numpy's
  ``longdouble`` is not the x87 format (:data:`_EXTENDED` false: ARM, PowerPC, Windows), the
  float columns are parsed by numpy's correctly rounded text parser instead, also bit for bit.

A block whose rows do not all have the same number of tokens (blank lines, comment lines, a
missing or extra column) or whose integer columns are not plain digits is parsed line by line
in Python, which also names the line of any malformed number. Every FormatError names the
file and the line. :class:`NodeRows` places ``I J K`` rows in a lattice and refuses a node
listed twice, naming the line of its second row.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from io import BufferedReader
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.gocad._numbers import parse_float, shown
from geobrep.adapters.limits import parse_numbers
from geobrep.errors import FormatError
from geobrep.geometry.arrays import FloatArray, IntArray

__all__ = ["NodeRows", "RowChunk", "exact_floats", "iter_rows"]

_PAD = 32  # bytes before a block (the words of a token's digits may start before it)
#: Bytes of a block (about 8,700 rows of a Voxet table): the block, its masks and the int64
#: arrays of its tokens stay in a 1 to 2 MiB L2 cache; 4 MiB blocks were 1.5x slower.
_CHUNK = 1 << 18
_U64 = np.uint64
_ZEROS = _U64(0x3030303030303030)
_NOT_DIGIT = _U64(0x7676767676767676)  # byte + 0x76 has its high bit set from 10 up
_HIGH = _U64(0x8080808080808080)
_LOW_BYTE_PAIRS = _U64(0x000000FF000000FF)
_MUL1 = _U64(0x000F424000000064)  # 100 + (1000000 << 32)
_MUL2 = _U64(0x0000271000000001)  # 1 + (10000 << 32)
#: ``_KEEP[r]``: the mask of the last ``r`` bytes of a little-endian word (its high bytes).
_KEEP = np.array(
    [0] + [(0xFFFFFFFFFFFFFFFF << (8 * (8 - r))) & 0xFFFFFFFFFFFFFFFF for r in range(1, 9)],
    dtype=_U64,
)
_U32 = np.uint32
_ZEROS32 = _U32(0x30303030)
_NOT_DIGIT32 = _U32(0x76767676)
_PAIRS32 = _U32(0x00FF00FF)
_MUL32 = _U32(0x00640001)  # 1 + (100 << 16)
_KEEP32 = np.array([0] + [(0xFFFFFFFF << (8 * (4 - r))) & 0xFFFFFFFF for r in range(1, 5)], _U32)
_POW10_U64 = np.array([10**k for k in range(20)], dtype=_U64)
_MAX_EXP10 = 27  # 5**27 < 2**64: 10**27 is exact in a 64-bit significand
#: The x87 80-bit extended format (64-bit significand, stored in 16 little-endian bytes).
_EXTENDED = (
    np.finfo(np.longdouble).nmant == 63
    and np.dtype(np.longdouble).itemsize == 16
    and sys.byteorder == "little"
)
_POW10_LD = np.array([10**k for k in range(_MAX_EXP10 + 1)], dtype=np.longdouble)
_BLANKS = b" \t\r\n\v\f"


@dataclass
class RowChunk:
    """Consecutive rows of a table: the integer and the float columns, and their lines."""

    ints: IntArray  # (n, number of integer columns)
    floats: FloatArray  # (n, number of float columns)
    first_line: int
    lines: IntArray | None = None  # the line of each row when they are not consecutive

    def line(self, row: int) -> int:
        """The 1-based line number of ``row``."""
        return int(self.lines[row]) if self.lines is not None else self.first_line + row


def iter_rows(
    side: Path, columns: int, int_columns: tuple[int, ...], max_bytes: int
) -> Iterator[RowChunk]:
    """The rows of ``columns`` numbers of the table ``side``, chunk by chunk: the columns of
    ``int_columns`` as integers (``1.0`` is accepted, ``1.5`` is a FormatError), the others as
    float64. Blank lines and ``*`` / ``#`` comment lines are skipped."""
    reader = _Table(side, columns, int_columns, max_bytes)
    yield from reader.chunks()


class NodeRows:
    """Where the ``I J K`` rows of a table go in a lattice of ``counts`` nodes (``I``
    fastest): each row's node is checked to be in the lattice and not listed before (a
    FormatError naming the file and the line of the second row). Rows in node order, the
    way GOCAD writes them, go to a slice (a copy, no scatter)."""

    def __init__(self, counts: tuple[int, int, int], side: Path) -> None:
        self.counts = counts
        self.side = side
        self.n = np.array(counts, dtype=np.int64)
        self.seen = np.zeros(int(np.prod(self.n)), dtype=bool)
        self.listed = 0  # rows placed (each a distinct node)
        self._high = -1  # the highest node placed

    def place(self, chunk: RowChunk) -> slice | IntArray:
        """The nodes of the rows of ``chunk`` (a slice when they are consecutive)."""
        ijk = chunk.ints
        rows = ijk.shape[0]
        if rows == 0:
            return slice(0, 0)
        highest = [int(ijk[:, axis].max()) for axis in range(3)]  # (faster than axis=0)
        if int(ijk.min()) < 0 or any(h >= n for h, n in zip(highest, self.counts, strict=True)):
            row = int(np.flatnonzero(((ijk < 0) | (ijk >= self.n)).any(axis=1))[0])
            raise FormatError(
                f"ASCII data file: I J K {tuple(ijk[row].tolist())} is not a node of {self.counts}",
                self.side,
                chunk.line(row),
            )
        index: IntArray = ijk[:, 1] * self.n[0]
        index += ijk[:, 2] * (self.n[0] * self.n[1])
        index += ijk[:, 0]
        first, last = int(index[0]), int(index[-1])
        rising = rows == 1 or bool((index[1:] > index[:-1]).all())
        if rising and first > self._high:  # every node new
            self.listed += rows
            self._high = last
            if last - first == rows - 1:
                self.seen[first : last + 1] = True
                return slice(first, last + 1)
            self.seen[index] = True
            return index
        before = self.seen[index]
        if bool(before.any()) or not (rising or _distinct(index)):
            self._twice(chunk, index, before)
        self.seen[index] = True
        self.listed += rows
        self._high = max(self._high, int(index.max()))
        return index

    def _twice(self, chunk: RowChunk, index: IntArray, before: NDArray[np.bool_]) -> None:
        _, firsts = np.unique(index, return_index=True)
        again = before.copy()
        repeat = np.ones(index.shape[0], dtype=bool)
        repeat[firsts] = False
        again |= repeat
        row = int(np.flatnonzero(again)[0])
        raise FormatError(
            f"ASCII data file: node I J K {tuple(chunk.ints[row].tolist())} is listed twice "
            "(a second row for it)",
            self.side,
            chunk.line(row),
        )

    def first_missing(self) -> tuple[int, int, int] | None:
        """The ``I J K`` of the first node no row lists (None when every node has one)."""
        if self.listed == self.seen.shape[0]:
            return None
        node = int(np.flatnonzero(~self.seen)[0])
        ni, nj = int(self.n[0]), int(self.n[1])
        return node % ni, (node // ni) % nj, node // (ni * nj)


def _distinct(index: IntArray) -> bool:
    ordered = np.sort(index)
    return not bool((ordered[1:] == ordered[:-1]).any())


class _Table:
    def __init__(
        self, side: Path, columns: int, int_columns: tuple[int, ...], max_bytes: int
    ) -> None:
        self.side = side
        self.columns = columns
        self.int_columns = int_columns
        self.float_columns = tuple(c for c in range(columns) if c not in int_columns)
        low = min(int_columns, default=0)
        consecutive = int_columns == tuple(range(low, low + len(int_columns)))
        self._ints: slice | list[int] = (
            slice(low, low + len(int_columns)) if consecutive else list(int_columns)
        )
        try:
            size = side.stat().st_size
        except OSError as exc:
            raise FormatError(f"cannot open the ASCII data file: {exc.strerror}", side) from None
        if size > max_bytes:
            raise FormatError("the ASCII data file is larger than allowed", side)
        self.max_bytes = max_bytes

    def chunks(self) -> Iterator[RowChunk]:
        try:
            stream = self.side.open("rb")
        except OSError as exc:
            raise FormatError(
                f"cannot open the ASCII data file: {exc.strerror}", self.side
            ) from None
        with stream:
            yield from self._blocks(stream)

    def _blocks(self, stream: BufferedReader) -> Iterator[RowChunk]:
        """Read the file block by block into one buffer; each block ends at a line break
        (a line longer than a block doubles the buffer) and its partial last line moves to
        the front for the next read."""
        capacity = _CHUNK
        buffer, data, words = _buffer(capacity)
        filled, line, head, total = 0, 1, True, 0
        while True:
            got = _fill(stream, buffer, _PAD + filled, _PAD + capacity)
            total += got
            if total > self.max_bytes:
                raise FormatError("the ASCII data file is larger than allowed", self.side)
            filled += got
            end = _PAD + filled
            last = filled < capacity  # the read stopped short: the end of the file
            if last:
                while end > _PAD and buffer[end - 1] in _BLANKS:
                    end -= 1
                buffer[end] = 10  # every row ends with a line break
                stop = end + 1 if end > _PAD else _PAD
            else:
                cut = buffer.rfind(b"\n", _PAD, end)
                if cut < 0:  # a line longer than the buffer
                    capacity *= 2
                    grown, data, words = _buffer(capacity)
                    grown[_PAD:end] = buffer[_PAD:end]
                    buffer = grown
                    continue
                stop = cut + 1
            start = _PAD
            if head:
                start, line, head = _skip_head(buffer, start, stop, line)
            if start < stop:
                chunk = self._fast(buffer, data, words, start, stop, line)
                if chunk is None:
                    chunk = self._slow(buffer, start, stop, line)
                    line += buffer.count(b"\n", start, stop)
                else:
                    line += chunk.ints.shape[0]
                yield chunk
            if last:
                return
            rest = _PAD + filled - stop
            buffer[_PAD : _PAD + rest] = buffer[stop : _PAD + filled]
            filled = rest

    def _fast(
        self,
        buffer: bytearray,
        data: NDArray[np.uint8],
        words: NDArray[np.uint64],
        start: int,
        stop: int,
        line: int,
    ) -> RowChunk | None:
        """The rows of ``[start, stop)`` when each holds ``columns`` tokens and the integer
        columns are plain digits; None otherwise (the chunk is parsed line by line)."""
        bytes_ = data[start - 1 : stop]  # from the line break before the chunk
        space = bytes_ <= 32
        edges = np.flatnonzero(space[1:] != space[:-1])
        edges += start
        token_start, token_end = edges[0::2], edges[1::2]
        breaks = np.flatnonzero(bytes_[1:] == 10)
        breaks += start
        rows, columns = breaks.shape[0], self.columns
        if token_start.shape[0] != rows * columns:
            return None
        controls = np.count_nonzero(bytes_ < 32)
        if controls != rows + 1:  # tabs or carriage returns, or other control bytes
            allowed = rows + 1 + np.count_nonzero(bytes_ == 13) + np.count_nonzero(bytes_ == 9)
            if controls != allowed:
                return None  # a control byte other than a line break, tab or carriage return
        token_start = token_start.reshape(rows, columns)
        token_end = token_end.reshape(rows, columns)
        if not (
            token_start[0, 0] >= start
            and (token_start[1:, 0] > breaks[:-1]).all()
            and (token_end[:, -1] <= breaks).all()
        ):
            return None
        ints = _digits(words, token_start[:, self._ints], token_end[:, self._ints])
        if ints is None:
            return None
        n_floats = len(self.float_columns)
        if n_floats and not _EXTENDED:  # no 80-bit long double: numpy's parser
            try:
                numbers = parse_numbers(bytes(buffer[start:stop]))
            except ValueError:
                return None  # parsed line by line, to name the line
            picked = numbers.reshape(rows, columns)[:, list(self.float_columns)]
            return RowChunk(ints, np.ascontiguousarray(picked), line)
        if not n_floats:
            return RowChunk(ints, np.zeros((rows, 0)), line)
        dots = np.flatnonzero(bytes_ == 46)
        dots += start - 1
        exponents: IntArray | None = None
        if buffer.find(b"e", start, stop) >= 0 or buffer.find(b"E", start, stop) >= 0:
            exponents = np.flatnonzero((bytes_ | 32) == 101)
            exponents += start - 1
        per_row = dots.shape[0] == rows * n_floats  # as many dots as values: one in each?
        floats = np.empty((rows, n_floats), dtype=np.float64) if n_floats > 1 else None
        values: FloatArray = np.zeros(0)
        for k, column in enumerate(self.float_columns):
            first, last = token_start[:, column], token_end[:, column]
            marks = dots[k::n_floats] if per_row and n_floats > 1 else dots
            values, slow = exact_floats(words, data, first, last, marks, exponents)
            for row in np.flatnonzero(slow).tolist():
                token = bytes(buffer[int(first[row]) : int(last[row])])
                values[row] = self._float(token, line + row)
            if floats is not None:
                floats[:, k] = values
        return RowChunk(ints, values.reshape(rows, 1) if floats is None else floats, line)

    def _float(self, token: bytes, line: int) -> float:
        text = token.decode("latin-1")
        try:
            if "_" in text:  # Python's float takes 1_000, numbers in a file do not
                raise ValueError(f"{shown(text)} is not a number")
            return parse_float(text)
        except ValueError as exc:
            raise FormatError(f"ASCII data file: {exc}", self.side, line) from None

    def _slow(self, buffer: bytearray, start: int, stop: int, line: int) -> RowChunk:
        """Line by line (blank and comment lines, ragged rows): errors name the line."""
        ints: list[list[int]] = []
        floats: list[list[float]] = []
        lines: list[int] = []
        for number, row in enumerate(bytes(buffer[start:stop]).split(b"\n"), start=line):
            tokens = row.split()  # ASCII blanks only
            if not tokens or tokens[0][:1] in (b"*", b"#"):
                continue
            values = [self._float(t, number) for t in tokens]
            if len(tokens) != self.columns:
                raise FormatError(
                    f"ASCII data file: {len(tokens)} numbers on a row of {self.columns}",
                    self.side,
                    number,
                )
            row_ints = []
            for column in self.int_columns:
                value = values[column]
                if not math.isfinite(value) or value != math.floor(value):
                    raise FormatError(
                        f"ASCII data file: {shown(tokens[column].decode('latin-1'))} is not "
                        "an integer index",
                        self.side,
                        number,
                    )
                row_ints.append(int(value))
            ints.append(row_ints)
            floats.append([values[c] for c in self.float_columns])
            lines.append(number)
        return RowChunk(
            np.array(ints, dtype=np.int64).reshape(-1, len(self.int_columns)),
            np.array(floats, dtype=np.float64).reshape(-1, len(self.float_columns)),
            line,
            np.array(lines, dtype=np.int64),
        )


def _buffer(capacity: int) -> tuple[bytearray, NDArray[np.uint8], NDArray[np.uint64]]:
    """A block buffer (``_PAD`` bytes before the block, a line break just before it, room for
    one more byte after it and for the last word) and its byte and word views."""
    buffer = bytearray(_PAD + capacity + _PAD)  # capacity: a multiple of 8
    buffer[_PAD - 1] = 10  # a line break before the first line
    return buffer, np.frombuffer(buffer, dtype=np.uint8), _words(buffer)


def _fill(stream: BufferedReader, buffer: bytearray, start: int, stop: int) -> int:
    """Read into ``buffer[start:stop]`` until it is full or the file ends; the bytes read."""
    view = memoryview(buffer)
    done = start
    try:
        while done < stop:
            got = stream.readinto(view[done:stop])
            if not got:
                break
            done += got
    finally:
        view.release()
    return done - start


def _skip_head(buffer: bytearray, start: int, stop: int, line: int) -> tuple[int, int, bool]:
    """Past the blank and comment lines at the head of the file: the start, its line and
    whether the head goes on past ``stop``."""
    while start < stop:
        end = buffer.find(b"\n", start, stop)
        end = stop if end < 0 else end + 1
        text = bytes(buffer[start:end]).strip()
        if text and text[:1] not in (b"*", b"#"):
            return start, line, False
        start, line = end, line + 1
    return start, line, True


def _words(buffer: bytearray) -> NDArray[np.uint64]:
    """The aligned little-endian 8-byte words of ``buffer`` (a view; its size is a multiple
    of 8). numpy gathers aligned words about 8 times faster than words at any byte offset."""
    return np.frombuffer(buffer, dtype="<u8")


def _before(words: NDArray[np.uint64], last: IntArray, count: int) -> list[NDArray[np.uint64]]:
    """The ``count`` 8-byte words that end before ``last``, ``last - 8``, ... (each from two
    aligned words ``words``, shifted)."""
    q = last >> 3
    low_bits = last & 7
    low_bits <<= 3
    right = low_bits.view(np.uint64)  # the bits of word q before byte `last`
    left = _U64(64) - right  # a shift by 64 gives 0: a word ending on a word boundary
    out = []
    high = words[q]
    for _ in range(count):
        q -= 1
        low = words[q]
        word = low >> right
        high <<= left
        word |= high
        out.append(word)
        high = low
    return out


def _eight(
    word: NDArray[np.uint64], taken: NDArray[np.uint64] | IntArray
) -> tuple[NDArray[np.uint64], NDArray[np.uint64]]:
    """The integer of the last ``taken`` (0 to 8) bytes of each ``word`` (in place) and a word
    whose high byte bits are set where one of them is not a digit."""
    word ^= _ZEROS  # digits to 0 ... 9, without carries
    word &= _KEEP[taken]  # the bytes before the run to 0 (leading zero digits)
    bad = word + _NOT_DIGIT
    bad |= word
    high = word >> _U64(8)  # eight digits, the first in the low byte, to their integer
    word *= _U64(10)
    word += high
    np.right_shift(word, _U64(16), out=high)
    high &= _LOW_BYTE_PAIRS
    high *= _MUL2
    word &= _LOW_BYTE_PAIRS
    word *= _MUL1
    word += high
    word >>= _U64(32)
    return word, bad


def _four(
    data: NDArray[np.uint8], last: IntArray, length: IntArray
) -> tuple[NDArray[np.uint32], NDArray[np.uint32]]:
    """:func:`_eight` for runs of 0 to 4 digits (I J K indices, the integer part of most
    values), in 4-byte words: half the memory traffic and twice the lanes."""
    words = data.view("<u4")
    q = last >> 2
    shift = last & 3
    shift <<= 3
    right = shift.astype(_U32)
    left = _U32(32) - right
    high = words[q]
    q -= 1
    word = words[q]
    word >>= right
    high <<= left
    word |= high
    word ^= _ZEROS32
    word &= _KEEP32[length]
    bad = word + _NOT_DIGIT32
    bad |= word
    high = word >> _U32(8)  # four digits, the first in the low byte, to their integer
    word *= _U32(10)
    word += high
    word &= _PAIRS32
    word *= _MUL32
    word >>= _U32(16)
    bad &= _U32(0x80808080)
    return word, bad


def _run(
    words: NDArray[np.uint64], last: IntArray, length: IntArray
) -> tuple[NDArray[np.uint64], NDArray[np.uint64]]:
    """The integers of the digit runs of ``length`` (0 to 24) bytes ending before ``last``
    (a longer run: its last 24 bytes; more than 19 digits wrap around), and for each a word
    whose high byte bits are set where a byte of the run is not a digit (0: all digits)."""
    longest = int(length.max(initial=0))
    count = min(3, max(1, (longest + 7) // 8))
    parts = _before(words, last, count)
    if count == 1:
        return _eight(parts[0], length)
    taken = np.minimum(length, 8)
    value, bad = _eight(parts[0], taken)
    rest = length - taken
    for k in range(1, count):  # the digits 8k + 1 ... 8k + 8 from the end
        if k == 2 or longest > 16:
            taken = np.minimum(rest, 8)
            rest -= taken
        else:
            taken = rest
        part, bad_part = _eight(parts[k], taken)
        part *= _POW10_U64[8 * k]
        value += part
        bad |= bad_part
    return value, bad


def _digits(words: NDArray[np.uint64], first: IntArray, last: IntArray) -> IntArray | None:
    """Tokens of one to eight digits → int64 (shaped like ``first``); None when one is
    anything else."""
    length = (last - first).reshape(-1)
    longest = int(length.max(initial=0))
    if length.size and (int(length.min()) < 1 or longest > 8):
        return None
    if longest <= 4:
        short, bad_short = _four(words.view(np.uint8), last.reshape(-1), length)
        if bool(bad_short.any()):
            return None
        return short.astype(np.int64).reshape(first.shape)
    value, bad = _eight(_before(words, last.reshape(-1), 1)[0], length)
    if bool((bad & _HIGH).any()):
        return None
    return value.view(np.int64).reshape(first.shape)


def _locate(marks: IntArray | None, first: IntArray, last: IntArray) -> tuple[IntArray, IntArray]:
    """For each token ``[first, last)``: how many of the sorted positions ``marks`` it holds
    and the first of them (``last`` when none)."""
    if marks is None or marks.size == 0:
        return np.zeros(first.shape[0], dtype=np.int64), last
    if marks.shape[0] == first.shape[0] and bool(
        ((marks >= first) & (marks < last)).all()
    ):  # one in each token (a dot in every value): no search
        return np.ones(first.shape[0], dtype=np.int64), marks
    lo = np.searchsorted(marks, first)
    hi = np.searchsorted(marks, last)
    count = hi - lo
    where = np.where(count > 0, marks[np.minimum(lo, marks.shape[0] - 1)], last)
    return count, where


def exact_floats(
    words: NDArray[np.uint64],
    data: NDArray[np.uint8],
    first: IntArray,
    last: IntArray,
    dots: IntArray | None,
    exponents: IntArray | None,
) -> tuple[FloatArray, NDArray[np.bool_]]:
    """The float64 of each token ``[first, last)`` of the bytes ``data`` (``words``: its
    aligned 8-byte words, :func:`_words`; ``dots`` and
    ``exponents``: the sorted positions of the ``.`` and ``e``/``E`` bytes) and a mask of the
    tokens left to parse one by one (their value is then meaningless).

    ``data`` must hold 24 bytes before the first token; ``first`` must be sorted."""
    n = first.shape[0]
    if not _EXTENDED:
        return np.zeros(n, dtype=np.float64), np.ones(n, dtype=bool)
    lead = data[first]
    negative = lead == 45
    body = first + (negative | (lead == 43))
    mantissa_end = last
    slow = np.zeros(n, dtype=bool)
    exponent: IntArray | None = None
    if exponents is not None and exponents.size:  # few tokens have one: work on those only
        owner = np.searchsorted(first, exponents, side="right") - 1
        inside = owner >= 0
        inside &= exponents < last[np.maximum(owner, 0)]
        owner, marks = owner[inside], exponents[inside]
        if owner.size:
            slow[owner[1:][owner[1:] == owner[:-1]]] = True  # two exponent marks
            mantissa_end = last.copy()
            mantissa_end[owner] = marks
            ends = last[owner]
            lead_e = data[marks + 1]
            e_first = marks + 1 + ((lead_e == 45) | (lead_e == 43))
            e_len = ends - e_first
            e_value, e_bad = _eight(_before(words, ends, 1)[0], np.clip(e_len, 0, 8))
            slow[owner[(e_len < 1) | (e_len > 4) | ((e_bad & _HIGH) != 0)]] = True
            e_signed = e_value.view(np.int64)
            np.negative(e_signed, out=e_signed, where=lead_e == 45)
            exponent = np.zeros(n, dtype=np.int64)
            exponent[owner] = e_signed
    n_dot, dot = _locate(dots, first, mantissa_end)
    if n_dot.shape[0] and int(n_dot.min()) == 1 and int(n_dot.max()) == 1:
        int_end, frac_first = dot, dot + 1
    else:
        slow |= n_dot > 1
        int_end = np.where(n_dot > 0, dot, mantissa_end)
        frac_first = np.where(n_dot > 0, dot + 1, mantissa_end)
    n_int = int_end - body
    n_frac = mantissa_end - frac_first
    fraction, bad = _run(words, mantissa_end, n_frac)
    bad &= _HIGH
    if int(n_int.max(initial=0)) <= 4:  # most values: |x| < 10000
        short, bad_short = _four(data, int_end, n_int)
        whole = short.astype(np.uint64)
        bad |= bad_short
    else:
        whole, bad_whole = _run(words, int_end, n_int)
        bad_whole &= _HIGH
        bad |= bad_whole
    total = n_int + n_frac
    if bool(bad.any()) or int(total.min(initial=1)) < 1:
        slow |= (bad != 0) | (total < 1)
    if int(n_int.max(initial=0)) > 19 or int(n_frac.max(initial=0)) > 19:
        slow |= (n_int > 19) | (n_frac > 19)  # more than 19 digits may not fit in 64 bits
    longer = np.flatnonzero(total > 19)
    if longer.size:  # leading zeros, or more than 19 digits: m may not fit in 64 bits
        size = whole[longer].astype(np.float64) * 10.0 ** n_frac[longer].astype(np.float64)
        slow[longer[size + fraction[longer].astype(np.float64) >= 1.8e19]] = True
    if int(n_frac.max(initial=0)) > 19:
        whole *= _POW10_U64[np.minimum(n_frac, 19)]
    else:
        whole *= _POW10_U64[n_frac]
    whole += fraction
    extended = whole.astype(np.longdouble)
    if exponent is None:
        if int(n_frac.max(initial=0)) > _MAX_EXP10:
            slow |= n_frac > _MAX_EXP10
            n_frac = np.minimum(n_frac, _MAX_EXP10)
        extended /= _POW10_LD[n_frac]
    else:
        exponent -= n_frac
        low, high = int(exponent.min(initial=0)), int(exponent.max(initial=0))
        if low < -_MAX_EXP10 or high > _MAX_EXP10:
            slow |= (exponent > _MAX_EXP10) | (exponent < -_MAX_EXP10)
            np.clip(exponent, -_MAX_EXP10, _MAX_EXP10, out=exponent)
        if high > 0:
            power = _POW10_LD[np.abs(exponent)]
            extended = np.where(exponent >= 0, extended * power, extended / power)
        else:
            np.negative(exponent, out=exponent)
            extended /= _POW10_LD[exponent]
    significand = extended.view(np.uint64)[0::2]
    slow |= (significand & _U64(0x7FF)) == _U64(0x400)  # half way: the double rounding may err
    values = extended.astype(np.float64)  # >= 0: the sign bit is set for a minus sign
    sign = negative.astype(np.uint64)
    sign <<= _U64(63)
    bits = values.view(np.uint64)
    bits |= sign
    return values, slow
