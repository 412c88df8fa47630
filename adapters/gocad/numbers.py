"""Numbers in GOCAD text: tolerant parsing of single tokens and exact, fast formatting.

Every float is written with the shortest text that reads back to the same float64 (Python's
``repr``; orjson's equivalent in bulk), so read → write → read is bit-identical.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.gocad.lexer import ORJSON

__all__ = ["format_float", "format_rows", "parse_float", "parse_int"]

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
            raise ValueError(f"{token!r} is not a number") from None
        return special


def parse_int(token: str) -> int:
    """An integer id; ValueError for anything else (``"1.5"``, ``"x"``)."""
    try:
        return int(token)
    except ValueError:
        raise ValueError(f"{token!r} is not an integer") from None


def format_float(value: float) -> str:
    """Shortest exact text of a float (``nan``/``inf`` spelled as Python does)."""
    return repr(float(value))


def _column_texts(column: NDArray[Any]) -> list[bytes]:
    """One exact text per value of a 1-D numeric column."""
    if column.dtype.kind in "iub":
        return [str(v).encode() for v in column.astype(np.int64).tolist()]
    return [repr(v).encode() for v in column.astype(np.float64).tolist()]


def format_rows(prefix: bytes, ids: NDArray[np.int64] | None, values: NDArray[Any] | None) -> bytes:
    """``prefix ids... values...`` lines (no final newline), one per row.

    ``ids`` ((N,) or (N, k), written as integers) and ``values`` ((N, m): integers as
    integers, floats with their shortest exact text) may each be None. With orjson installed,
    finite blocks are formatted in one call (ids ride along as floats below 2**53, whose
    shortest text is the integer itself once the ``.0`` is dropped).
    """
    blocks = []
    for block in (ids, values):
        if block is None:
            continue
        array = np.asarray(block)
        if array.ndim == 1:
            array = array.reshape(-1, 1)
        if array.shape[1]:
            blocks.append(array)
    if not blocks or blocks[0].shape[0] == 0:
        return b""
    n = blocks[0].shape[0]
    if len(blocks) == 2 and _fast_floats(blocks[1]) and np.abs(blocks[0]).max() < 2**53:
        blocks = [np.concatenate([blocks[0].astype(np.float64), blocks[1]], axis=1)]
    if len(blocks) == 1:
        block = blocks[0]
        if ORJSON is not None and (block.dtype.kind in "iub" or bool(np.isfinite(block).all())):
            rows = _format_block(block, join=False)
            return (prefix + b" " + rows.replace(b"],[", b"\n" + prefix + b" ")).translate(_SPACES)
        return prefix + b" " + _format_block(block).replace(b"\n", b"\n" + prefix + b" ")
    first = _format_block(blocks[0]).split(b"\n")
    second = _format_block(blocks[1]).split(b"\n")
    flat: list[bytes] = [b""] * (2 * n)
    flat[0::2] = first
    flat[1::2] = second
    text: bytes = (prefix + b" %s %s\n") * n % tuple(flat)
    return text[:-1]


_SPACES = bytes.maketrans(b",", b" ")


def _fast_floats(values: NDArray[Any]) -> bool:
    """Float values orjson can print whose integral members may drop their ``.0``."""
    return (
        ORJSON is not None
        and values.dtype.kind == "f"
        and bool(np.isfinite(values).all())
        and not bool((np.signbit(values) & (values == 0)).any())
    )


def _format_block(values: NDArray[Any], join: bool = True) -> bytes:
    """Rows of space-separated numbers joined by newlines (``join=False``: orjson's rows,
    comma-separated and joined by ``],[``, for the caller to finish)."""
    if values.shape[1] == 0:
        return b"\n" * (int(values.shape[0]) - 1)
    integer = values.dtype.kind in "iub"
    if ORJSON is not None and (integer or bool(np.isfinite(values).all())):
        array = values.astype(np.int64 if integer else np.float64, copy=False)
        text: bytes = ORJSON.dumps(np.ascontiguousarray(array), option=ORJSON.OPT_SERIALIZE_NUMPY)
        if not integer and _fast_floats(array) and bool((array == np.floor(array)).any()):
            # "2.0" → "2": the same float, shorter, and integer-only lines parse faster
            text = text.replace(b".0,", b",").replace(b".0]", b"]")
        text = text[2:-2]
        if not join:
            return text
        return text.replace(b"],[", b"\n").translate(_SPACES)
    if not join:
        raise ValueError("unjoined rows need orjson and finite values")
    columns = [_column_texts(values[:, j]) for j in range(values.shape[1])]
    k = len(columns)
    flat: list[bytes] = [b""] * (k * values.shape[0])
    for j, texts in enumerate(columns):
        flat[j::k] = texts
    line = b" ".join([b"%s"] * k) + b"\n"
    block: bytes = line * values.shape[0] % tuple(flat)
    return block[:-1]
