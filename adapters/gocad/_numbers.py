"""Numbers in GOCAD text: tolerant parsing of single tokens and exact, fast formatting.

Every float is written with the shortest text that reads back to the same float64 (Python's
``repr``; orjson's equivalent in bulk), so read → write → read is bit-identical.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.gocad._lexer import ORJSON

__all__ = [
    "INT_LIMIT",
    "format_float",
    "format_rows",
    "parse_float",
    "parse_int",
    "row_pieces",
    "shown",
]

_SPECIAL = {
    "inf": math.inf,
    "+inf": math.inf,
    "-inf": -math.inf,
    "infinity": math.inf,
    "-infinity": -math.inf,
    "1.#inf": math.inf,
    "-1.#inf": -math.inf,
    "1.#inf00": math.inf,
    "-1.#inf00": -math.inf,
    "nan": math.nan,
    "-nan": math.nan,
    "1.#qnan": math.nan,
    "-1.#qnan": math.nan,
    "-1.#ind": math.nan,
    "1.#ind": math.nan,
}


def shown(token: str, limit: int = 40) -> str:
    """``repr`` of a token for a message, cut to about ``limit`` characters.

    >>> shown("1" * 100)
    "'1111111111111111111111111111111111111111…' (100 characters)"
    """
    if len(token) <= limit:
        return repr(token)
    return f"{token[:limit] + '…'!r} ({len(token)} characters)"


def parse_float(token: str) -> float:
    """A float from a token, accepting ``inf``, ``1.#INF`` and friends; ValueError if not one.

    >>> parse_float("1.#INF"), parse_float("-99999")
    (inf, -99999.0)
    """
    try:
        return float(token)
    except ValueError:
        special = _SPECIAL.get(token.lower())
        if special is None:
            raise ValueError(f"{shown(token)} is not a number") from None
        return special


#: Ids are stored as int64 and subtracted from one another (id lookups): magnitudes above
#: 2**62 are refused where they are read, so no id or difference of ids wraps around.
INT_LIMIT = 2**62


def parse_int(token: str) -> int:
    """An integer id; ValueError for anything else (``"1.5"``, ``"x"``, ``"0x10"``) and for an
    integer of magnitude above :data:`INT_LIMIT` (``2**62``).

    >>> parse_int("18446744073709551616")
    Traceback (most recent call last):
    ...
    ValueError: '18446744073709551616' is too large for an id (at most 2**62 in magnitude)
    """
    try:
        value = int(token)
    except ValueError:
        raise ValueError(f"{shown(token)} is not an integer") from None
    if not -INT_LIMIT <= value <= INT_LIMIT:
        raise ValueError(f"{shown(token)} is too large for an id (at most 2**62 in magnitude)")
    return value


def format_float(value: float) -> str:
    """Shortest exact text of a float (``nan``/``inf`` spelled as Python does)."""
    return repr(float(value))


def format_rows(prefix: bytes, ids: NDArray[np.int64] | None, values: NDArray[Any] | None) -> bytes:
    """``prefix ids... values...`` lines (no final newline), one per row.

    ``ids`` ((N,) or (N, k), written as integers) and ``values`` ((N, m): integers as
    integers, floats with their shortest exact text) may each be None.

    >>> format_rows(b"PVRTX", np.array([1, 2]), np.array([[0.5, 4.0], [1e-20, 3.0]]))
    b'PVRTX 1 0.5 4\\nPVRTX 2 1e-20 3'
    >>> format_rows(b"PVRTX", np.array([1, 2]), np.array([[0.5, -0.0], [1e-20, 3.0]]))
    b'PVRTX 1 0.5 -0.0\\nPVRTX 2 1e-20 3.0'
    >>> format_rows(b"TRGL", np.array([[1, 2, 3]]), np.array([[7.0]]))
    b'TRGL 1 2 3 7'
    """
    return b"".join(row_pieces(prefix, ids, values))


def row_pieces(
    prefix: bytes, ids: NDArray[np.int64] | None, values: NDArray[Any] | None
) -> list[bytes]:
    """The text of :func:`format_rows` as pieces to concatenate (or write one after the other):
    the first row's head, then the body, so that the body is never copied once more.

    With orjson, a block is printed in one call and reshaped with three C-level passes over
    the bytes: ``],[`` between rows becomes a line break, the next row's prefix and ``%d``
    slots for its ids (filled by one ``%`` formatting), then commas become blanks and the
    brackets go. Blocks whose values are all integers (ids, integral float properties) are
    printed as integers, which read back as the same floats; so are integral floats elsewhere.
    """
    id_block, value_block = _columns(ids), _columns(values)
    rows = id_block if id_block is not None else value_block
    if rows is None or rows.shape[0] == 0:
        return []
    if value_block is not None:
        integral = _as_integers(value_block)
        if integral is not None:
            value_block = None
            id_block = (
                integral
                if id_block is None
                else np.concatenate([id_block.astype(np.int64, copy=False), integral], axis=1)
            )
    if ORJSON is None or (value_block is not None and not np.isfinite(value_block).all()):
        return [_format_slow(prefix, id_block, value_block)]
    if value_block is None:
        assert id_block is not None
        block = np.ascontiguousarray(id_block, dtype=np.int64)
        text = ORJSON.dumps(block, option=ORJSON.OPT_SERIALIZE_NUMPY)
        body = text.replace(b"],[", b"\n" + prefix + b" ")
        return [prefix + b" ", body.translate(_SPACES, b"[]")]
    block = np.ascontiguousarray(value_block, dtype=np.float64)
    text = ORJSON.dumps(block, option=ORJSON.OPT_SERIALIZE_NUMPY)
    integral = (block == np.floor(block)).any(axis=0)
    if integral.any() and not bool((np.signbit(block) & (block == 0)).any()):
        # "2.0" → "2": the same float, shorter (-0.0 would lose its sign: then kept)
        if integral[:-1].any():
            text = text.replace(b".0,", b",")
        if integral[-1]:
            text = text.replace(b".0]", b"]")
    if id_block is None:
        body = text.replace(b"],[", b"\n" + prefix + b" ")
        return [prefix + b" ", body.translate(_SPACES, b"[]")]
    k = id_block.shape[1]
    slots = b"\n" + prefix + b" %d" * k + b" "
    head = b"%s %s " % (prefix, b" ".join(b"%d" % v for v in id_block[0].tolist()))
    body = text.replace(b"],[", slots) % tuple(id_block[1:].ravel().tolist())
    return [head, body.translate(_SPACES, b"[]")]


_SPACES = bytes.maketrans(b",", b" ")


def _columns(block: NDArray[Any] | None) -> NDArray[Any] | None:
    """A (N,) or (N, k) block as (N, k); None when absent or without columns."""
    if block is None:
        return None
    array = np.asarray(block)
    if array.ndim == 1:
        array = array[:, None]
    return array if array.shape[1] else None


def _as_integers(values: NDArray[Any]) -> NDArray[np.int64] | None:
    """``values`` as int64 when every one is an integer that reads back as the same float64
    (finite, integral, below 2**53, no -0.0); else None."""
    if values.dtype.kind in "iub":
        return values.astype(np.int64, copy=False)
    if values.dtype.kind != "f":
        return None
    array = values.astype(np.float64, copy=False)
    with np.errstate(invalid="ignore"):
        integral = bool((np.abs(array) < 2**53).all() and (array == np.floor(array)).all())
    if not integral or bool((np.signbit(array) & (array == 0)).any()):
        return None
    return array.astype(np.int64)


def _column_texts(column: NDArray[Any]) -> list[bytes]:
    """One exact text per value of a 1-D numeric column."""
    if column.dtype.kind in "iub":
        return [str(v).encode() for v in column.astype(np.int64).tolist()]
    return [repr(v).encode() for v in column.astype(np.float64).tolist()]


def _format_slow(prefix: bytes, ids: NDArray[Any] | None, values: NDArray[Any] | None) -> bytes:
    """Rows one number at a time (non-finite values, or no orjson): exact, slower."""
    columns = [
        _column_texts(block[:, j])
        for block in (ids, values)
        if block is not None
        for j in range(block.shape[1])
    ]
    k = len(columns)
    n = len(columns[0])
    flat: list[bytes] = [prefix] * ((k + 1) * n)
    for j, texts in enumerate(columns, start=1):
        flat[j :: k + 1] = texts
    line = b" ".join([b"%s"] * (k + 1)) + b"\n"
    text: bytes = line * n % tuple(flat)
    return text[:-1]
