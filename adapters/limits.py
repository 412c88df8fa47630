"""How much a reader may allocate from what a file declares: the read budget.

File headers declare counts and sizes (a PLY ``element vertex 400000000``, a ``.npy`` shape, a
zip member's uncompressed size, a VTU zlib block header) before the data is seen. A reader
checks every such declaration against :func:`read_budget` of the file's size *before* it
allocates, and inflates compressed data in bounded steps, so a small hostile file is a
:class:`~geobrep.errors.FormatError` in milliseconds instead of gigabytes of memory.

The budget is :data:`BUDGET_FLOOR` or :data:`EXPANSION` times the file's size, whichever is
larger: an uncompressed file declares at most its own size, and real compressed geometry
inflates by a few times at most (a constant property can inflate much more: such a file needs
``compress=False``).

>>> read_budget(1000) == BUDGET_FLOOR
True
>>> read_budget(100 * 2**20) // 2**20
1600
>>> check_declared(2**40, 1000, "vertex element", "a.ply")
Traceback (most recent call last):
...
geobrep.errors.FormatError: a.ply: vertex element declares 1.0 TiB, more than the 128 MiB \
a file of 1000 bytes may hold (read budget: the larger of 128 MiB and 16 x the file's size)
"""

from __future__ import annotations

import lzma
import warnings
import zlib
from os import PathLike
from typing import Final, Literal

import numpy as np
from numpy.typing import NDArray

from geobrep.errors import FormatError

__all__ = [
    "BUDGET_FLOOR",
    "EXPANSION",
    "check_declared",
    "human_bytes",
    "inflate_bounded",
    "parse_numbers",
    "read_budget",
]

BUDGET_FLOOR: Final = 128 * 2**20
"""Bytes any file may declare, whatever its size (128 MiB)."""
EXPANSION: Final = 16
"""Declared bytes allowed per byte of file above the floor."""
_STEP: Final = 1 << 20


def read_budget(file_size: int) -> int:
    """The most bytes a reader allocates from the declarations of a file of ``file_size`` bytes."""
    return max(BUDGET_FLOOR, EXPANSION * int(file_size))


def human_bytes(count: float) -> str:
    """``count`` bytes in B, KiB, MiB, GiB or TiB."""
    for unit in ("B", "KiB", "MiB", "GiB"):
        if abs(count) < 1024:
            return f"{count:.0f} {unit}" if unit == "B" else f"{count:.1f} {unit}"
        count /= 1024
    return f"{count:.1f} TiB"


def _budget_text(file_size: int) -> str:
    budget = read_budget(file_size)
    floor = human_bytes(BUDGET_FLOOR).replace(".0 ", " ")
    return (
        f"more than the {human_bytes(budget).replace('.0 ', ' ')} a file of {file_size} bytes "
        f"may hold (read budget: the larger of {floor} and {EXPANSION} x the file's size)"
    )


def check_declared(
    nbytes: int,
    file_size: int,
    what: str,
    path: str | PathLike[str] | None,
    line: int | None = None,
) -> None:
    """Raise :class:`FormatError` when ``what`` declares more than the read budget allows."""
    if nbytes > read_budget(file_size):
        raise FormatError(
            f"{what} declares {human_bytes(nbytes)}, {_budget_text(file_size)}", path, line
        )


def _inflated_zlib(data: bytes, stop_after: int) -> int:
    inflater = zlib.decompressobj()
    total, pending = 0, data
    while total <= stop_after:
        chunk = inflater.decompress(pending, _STEP)
        pending = inflater.unconsumed_tail
        total += len(chunk)
        if not chunk and not pending:
            break
    return total


def _inflated_lzma(data: bytes, stop_after: int) -> int:
    inflater = lzma.LZMADecompressor()
    total, pending = 0, data
    while total <= stop_after and not inflater.eof:
        chunk = inflater.decompress(pending, _STEP)
        pending = b""
        total += len(chunk)
        if not chunk and inflater.needs_input:
            break
    return total


def inflate_bounded(
    data: bytes,
    limit: int,
    what: str,
    path: str | PathLike[str] | None,
    method: Literal["zlib", "lzma"] = "zlib",
) -> int:
    """The size ``data`` inflates to, found in bounded steps (nothing is kept), at most ``limit``.

    Raises :class:`FormatError` when ``data`` inflates to more than ``limit`` bytes (a
    decompression bomb, or a header that understates its data) or is not valid compressed data.

    >>> inflate_bounded(zlib.compress(bytes(1000)), 1000, "block", "a.vtu")
    1000
    >>> inflate_bounded(zlib.compress(bytes(10**6)), 1000, "block", "a.vtu")
    Traceback (most recent call last):
    ...
    geobrep.errors.FormatError: a.vtu: block inflates to more than the 1000 B it declares
    """
    try:
        total = _inflated_lzma(data, limit) if method == "lzma" else _inflated_zlib(data, limit)
    except (zlib.error, lzma.LZMAError, EOFError) as exc:
        raise FormatError(f"{what} is not valid {method} data ({exc})", path) from None
    if total > limit:
        raise FormatError(
            f"{what} inflates to more than the {human_bytes(limit)} it declares", path
        )
    return total


def parse_numbers(text: bytes | str) -> NDArray[np.float64]:
    """Every whitespace-separated number of ``text`` as float64, in one C-level pass.

    Raises ``ValueError`` naming the first token that is not a number.

    >>> parse_numbers(b"1 2.5\\n-3e2").tolist()
    [1.0, 2.5, -300.0]
    """
    data = text.decode("latin-1") if isinstance(text, bytes) else text
    if not data.strip():
        return np.zeros(0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # numpy warns, not raises, when it stops at a bad token
        try:
            return np.fromstring(data, dtype=np.float64, sep=" ")
        except (ValueError, DeprecationWarning):
            bad = next((t for t in data.split() if not _is_float(t)), data.split()[0])
    raise ValueError(f"{bad[:40]!r} is not a number")


def _is_float(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True
