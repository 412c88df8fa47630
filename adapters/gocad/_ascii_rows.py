"""Rows of numbers from an ASCII table (a Voxet's ``ASCII_DATA_FILE``), parsed vectorised.

A table of ``I J K value...`` rows is tens of millions of numbers; numpy's text parsers spend
about 150 ns on each (a call to the C library's ``strtod`` per token), which is most of the
time of reading a big Voxet. Here the bytes are cut into tokens with a few whole-buffer numpy
passes, chunk by chunk (bounded memory), and the tokens are converted with integer arithmetic
on 8-byte words (eight digits in three multiplications, as in ``fast_float``):

* the integer columns (``I J K``) become int64 directly;
* a decimal ``[-+]digits[.digits][e[-+]digits]`` becomes the integer of its digits ``m``
  (at most 19 significant ones) and a power of ten ``10**e`` (``|e| <= 27``), both exact in
  the x87 80-bit ``long double``; ``m * 10**e`` (or ``m / 10**-e``) is then rounded once to
  its 64-bit significand and once more to float64. The second rounding is the correctly
  rounded float64 of the decimal unless the extended result lies exactly half way between
  two doubles (its low 11 significand bits ``10000000000``), since the decimal is within half
  an extended unit of it: those tokens, and every other token outside the fast grammar
  (``nan``, ``1.#INF``, more digits, larger exponents), are parsed one by one with Python's
  ``float``. The result is the float64 ``float()`` gives, bit for bit.

A chunk whose rows do not all have the same number of tokens (blank lines, comment lines, a
missing or extra column) or whose integer columns are not plain digits is parsed line by line
in Python, which also names the line of any malformed number. Every FormatError names the
file and the line.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.gocad._numbers import parse_float, shown
from geobrep.adapters.limits import parse_numbers
from geobrep.errors import FormatError
from geobrep.geometry.arrays import FloatArray, IntArray

__all__ = ["RowChunk", "exact_floats", "iter_rows"]

_PAD = 32
_CHUNK = 1 << 22  # bytes of a chunk (about 130,000 rows of a Voxet table)
_U64 = np.uint64
_ZEROS = _U64(0x3030303030303030)
_ALL = _U64(0xFFFFFFFFFFFFFFFF)
_LOW_BYTE_PAIRS = _U64(0x000000FF000000FF)
_MUL1 = _U64(0x000F424000000064)  # 100 + (1000000 << 32)
_MUL2 = _U64(0x0000271000000001)  # 1 + (10000 << 32)
_F0 = _U64(0xF0F0F0F0F0F0F0F0)
_SIX = _U64(0x0606060606060606)
_THREES = _U64(0x3333333333333333)
#: ``keep[r]``: the mask of the last ``r`` bytes of a little-endian word (its high bytes).
_KEEP = np.array(
    [0] + [(0xFFFFFFFFFFFFFFFF << (8 * (8 - r))) & 0xFFFFFFFFFFFFFFFF for r in range(1, 9)],
    dtype=_U64,
)
_POW10_U64 = np.array([10**k for k in range(20)], dtype=_U64)
_MAX_EXP10 = 27  # 5**27 < 2**64: 10**27 is exact in a 64-bit significand
_EXTENDED = (
    np.finfo(np.longdouble).nmant == 63
    and np.dtype(np.longdouble).itemsize == 16
    and sys.byteorder == "little"
)
_POW10_LD = np.array([10**k for k in range(_MAX_EXP10 + 1)], dtype=np.longdouble)


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
        self.buffer = bytearray(size + 2 * _PAD)
        view = memoryview(self.buffer)
        with side.open("rb") as stream:
            done = 0
            while done < size:
                got = stream.readinto(view[_PAD + done : _PAD + size])
                if not got:
                    break
                done += got
        self.size = done
        self.buffer[_PAD - 1] = 10  # a line break before the first line

    def chunks(self) -> Iterator[RowChunk]:
        buffer = self.buffer
        start, line = _PAD, 1
        end = _PAD + self.size
        while start < end:  # the blank and comment lines at the head
            stop = buffer.find(b"\n", start, end)
            stop = end if stop < 0 else stop + 1
            text = bytes(buffer[start:stop]).strip()
            if text and text[:1] not in (b"*", b"#"):
                break
            start, line = stop, line + 1
        while end > start and buffer[end - 1] in b" \t\r\n\v\f":
            end -= 1
        if end <= start:
            return
        buffer[end] = 10  # every row ends with a line break
        end += 1
        data = np.frombuffer(buffer, dtype=np.uint8)
        words = _words(buffer)
        while start < end:
            stop = buffer.find(b"\n", min(start + _CHUNK, end - 1), end) + 1
            chunk = self._fast(data, words, start, stop, line)
            if chunk is None:
                chunk = self._slow(start, stop, line)
                line += buffer.count(b"\n", start, stop)
            else:
                line += chunk.ints.shape[0]
            yield chunk
            start = stop

    def _fast(
        self, data: NDArray[np.uint8], words: NDArray[np.uint64], start: int, stop: int, line: int
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
        if controls != rows + 1 and bool(_CONTROL[bytes_].any()):
            return None  # a control byte other than a line break, tab or carriage return
        token_start = token_start.reshape(rows, columns)
        token_end = token_end.reshape(rows, columns)
        before = np.empty(rows, dtype=np.int64)
        before[0] = start - 1
        before[1:] = breaks[:-1]
        if not ((token_start[:, 0] > before).all() and (token_end[:, -1] <= breaks).all()):
            return None
        ints = _digits(words, token_start[:, self._ints], token_end[:, self._ints])
        if ints is None:
            return None
        floats = np.empty((rows, len(self.float_columns)), dtype=np.float64)
        if self.float_columns and not _EXTENDED:  # no 80-bit long double: numpy's parser
            try:
                numbers = parse_numbers(bytes(self.buffer[start:stop]))
            except ValueError:
                return None  # parsed line by line, to name the line
            floats[:] = numbers.reshape(rows, columns)[:, list(self.float_columns)]
        elif self.float_columns:
            dots = np.flatnonzero(bytes_ == 46)
            dots += start - 1
            exponents: IntArray | None = None
            if self.buffer.find(b"e", start, stop) >= 0 or self.buffer.find(b"E", start, stop) >= 0:
                exponents = np.flatnonzero((bytes_ | 32) == 101)
                exponents += start - 1
            for k, column in enumerate(self.float_columns):
                first, last = token_start[:, column], token_end[:, column]
                values, slow = exact_floats(words, data, first, last, dots, exponents)
                for row in np.flatnonzero(slow).tolist():
                    token = bytes(self.buffer[int(first[row]) : int(last[row])])
                    values[row] = self._float(token, line + row)
                floats[:, k] = values
        return RowChunk(ints, floats, line)

    def _float(self, token: bytes, line: int) -> float:
        text = token.decode("latin-1")
        try:
            if "_" in text:  # Python's float takes 1_000, numbers in a file do not
                raise ValueError(f"{shown(text)} is not a number")
            return parse_float(text)
        except ValueError as exc:
            raise FormatError(f"ASCII data file: {exc}", self.side, line) from None

    def _slow(self, start: int, stop: int, line: int) -> RowChunk:
        """Line by line (blank and comment lines, ragged rows): errors name the line."""
        ints: list[list[int]] = []
        floats: list[list[float]] = []
        lines: list[int] = []
        for number, row in enumerate(bytes(self.buffer[start:stop]).split(b"\n"), start=line):
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


_CONTROL = np.zeros(256, dtype=bool)
_CONTROL[:32] = True
_CONTROL[[9, 10, 13]] = False  # tab, line feed, carriage return


def _words(buffer: bytearray) -> NDArray[np.uint64]:
    """The little-endian 8-byte word at every byte offset of ``buffer`` (a view)."""
    return np.ndarray(shape=(len(buffer) - 7,), dtype="<u8", buffer=buffer, strides=(1,))


_FILL = _ZEROS & ~_KEEP  # "0" digits in the bytes a word keeps not


def _run(
    words: NDArray[np.uint64], last: IntArray, length: IntArray
) -> tuple[NDArray[np.uint64], NDArray[np.uint64]]:
    """The integers of the digit runs of ``length`` (0 to 24) bytes ending before ``last``
    (a longer run: its last 24 bytes; more than 19 digits wrap around), and for each a word
    that is 0 when every byte of the run is a digit."""
    longest = int(length.max(initial=0))
    n_words = min(3, max(1, (longest + 7) // 8))
    value = np.zeros(0, dtype=_U64)
    bad = np.zeros(0, dtype=_U64)
    for k in range(n_words):  # the word of the digits 8k + 1 ... 8k + 8 from the end
        taken = length if k == 0 and longest <= 8 else np.clip(length - 8 * k, 0, 8)
        word = words[last - 8 * (k + 1)]
        word &= _KEEP[taken]
        word |= _FILL[taken]
        check = word + _SIX
        check &= _F0
        check >>= _U64(4)
        check |= word & _F0
        check ^= _THREES
        part = word - _ZEROS
        part *= _U64(10)
        word -= _ZEROS
        word >>= _U64(8)
        part += word
        high = part >> _U64(16)
        high &= _LOW_BYTE_PAIRS
        high *= _MUL2
        part &= _LOW_BYTE_PAIRS
        part *= _MUL1
        part += high
        part >>= _U64(32)
        if k == 0:
            value, bad = part, check
        else:
            part *= _POW10_U64[8 * k]
            value += part
            bad |= check
    return value, bad


def _digits(words: NDArray[np.uint64], first: IntArray, last: IntArray) -> IntArray | None:
    """Tokens of one to eight digits → int64 (shaped like ``first``); None when one is
    anything else."""
    length = (last - first).reshape(-1)
    if length.size and (length.min() < 1 or length.max() > 8):
        return None
    value, bad = _run(words, last.reshape(-1), length)
    if bad.any():
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
    8-byte words at every offset, :func:`_words`; ``dots`` and
    ``exponents``: the sorted positions of the ``.`` and ``e``/``E`` bytes) and a mask of the
    tokens left to parse one by one (their value is then meaningless).

    ``data`` must hold 24 bytes before the first token."""
    n = first.shape[0]
    if not _EXTENDED:
        return np.zeros(n, dtype=np.float64), np.ones(n, dtype=bool)
    lead = data[first]
    negative = lead == 45
    body = first + (negative | (lead == 43))
    mantissa_end = last
    exponent: IntArray | int = 0
    slow = np.zeros(n, dtype=bool)
    n_exp, e_at = _locate(exponents, first, last)
    if bool(n_exp.any()):
        has = n_exp > 0
        mantissa_end = np.where(has, e_at, last)
        lead_e = data[np.where(has, e_at + 1, first)]
        e_first = np.where(has, e_at + 1 + ((lead_e == 45) | (lead_e == 43)), last)
        e_len = last - e_first
        e_value, bad = _run(words, last, np.minimum(e_len, 8))
        slow |= (n_exp > 1) | (has & ((e_len < 1) | (e_len > 4) | (bad != 0)))
        e_signed = e_value.astype(np.int64)
        np.negative(e_signed, out=e_signed, where=has & (lead_e == 45))
        exponent = np.where(has, e_signed, 0)
    n_dot, dot = _locate(dots, first, mantissa_end)
    if n_dot.shape[0] and int(n_dot.min()) == 1 and int(n_dot.max()) == 1:
        int_end, frac_first = dot, dot + 1
    else:
        slow |= n_dot > 1
        int_end = np.where(n_dot > 0, dot, mantissa_end)
        frac_first = np.where(n_dot > 0, dot + 1, mantissa_end)
    n_int = int_end - body
    n_frac = mantissa_end - frac_first
    whole, bad = _run(words, int_end, n_int)
    fraction, bad_fraction = _run(words, mantissa_end, n_frac)
    bad |= bad_fraction
    total = n_int + n_frac
    slow |= (bad != 0) | (total < 1) | (n_int > 24) | (n_frac > 24)
    longer = np.flatnonzero(total > 19)
    if longer.size:  # leading zeros, or more than 19 digits: m may not fit in 64 bits
        size = whole[longer].astype(np.float64) * 10.0 ** n_frac[longer].astype(np.float64)
        slow[longer[size + fraction[longer].astype(np.float64) >= 1.8e19]] = True
    mantissa = whole * _POW10_U64[np.minimum(n_frac, 19)]
    mantissa += fraction
    exponent = exponent - n_frac
    low, high = int(np.min(exponent, initial=0)), int(np.max(exponent, initial=0))
    if low < -_MAX_EXP10 or high > _MAX_EXP10:
        slow |= (exponent > _MAX_EXP10) | (exponent < -_MAX_EXP10)
        exponent = np.clip(exponent, -_MAX_EXP10, _MAX_EXP10)
    extended = mantissa.astype(np.longdouble)
    if high > 0:
        power = _POW10_LD[np.abs(exponent)]
        extended = np.where(exponent >= 0, extended * power, extended / power)
    else:
        extended /= _POW10_LD[-exponent]
    significand = extended.view(np.uint64)[0::2]
    slow |= (significand & _U64(0x7FF)) == _U64(0x400)  # half way: the double rounding may err
    values = extended.astype(np.float64)
    np.negative(values, out=values, where=negative)
    return values, slow
