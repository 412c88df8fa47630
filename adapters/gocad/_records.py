"""Typed records the GOCAD parser hands to the reader (what a file says, before any entity).

The records are frozen. Those of a Model3d header and a TSolid MODEL section, and the drafts
the parser builds them from, are in :mod:`geobrep.adapters.gocad._model_records`, imported when
a file has such an object. What a reader keeps of them in ``metadata["gocad"]`` is JSON (lists,
strings, numbers), never these types: that is stored data the native round trip and the GOCAD
writer rely on.
"""

from __future__ import annotations

from typing import NamedTuple, Protocol

import numpy as np
from numpy.typing import NDArray

from geobrep.errors import FormatError

__all__ = [
    "BStone",
    "Border",
    "CTetra",
    "CellRows",
    "CrsBlock",
    "Diagnostics",
    "ErrorFactory",
    "Geology",
    "Warn",
]

#: A ``GOCAD_ORIGINAL_COORDINATE_SYSTEM`` block: keyword → value (AXIS_NAME / AXIS_UNIT: 3
#: strings). JSON data: a reader keeps it as it is in ``metadata["gocad"]["crs"]``.
CrsBlock = dict[str, str | list[str]]
#: GEOLOGICAL_FEATURE / GEOLOGICAL_TYPE (a string) and STRATIGRAPHIC_POSITION (a list).
Geology = dict[str, str | list[str]]


class Warn(Protocol):
    """Report a recovered oddity at a line of the file (a :class:`GocadWarning`)."""

    def __call__(self, message: str, line: int | None, /) -> None: ...


class ErrorFactory(Protocol):
    """Build the :class:`~geobrep.errors.FormatError` (path and line) the caller raises."""

    def __call__(self, message: str, line: int | None, /) -> FormatError: ...


class Diagnostics(Protocol):
    """Where the reader's helpers report: warnings and errors naming the file and line."""

    def warn(self, message: str, line: int | None = None) -> None: ...

    def error(self, message: str, line: int | None) -> FormatError: ...


# -- element bodies ---------------------------------------------------------------------------
class BStone(NamedTuple):
    """``BSTONE <vertex id>``."""

    vertex_id: int
    line: int


class Border(NamedTuple):
    """``BORDER <new id> <vertex id> <vertex id>``."""

    border_id: int
    v0: int
    v1: int
    line: int


class CTetra(NamedTuple):
    """``# CTETRA <region> <4 faces>`` after the TETRA at index ``cell``."""

    cell: int
    region: str
    faces: tuple[str, ...]
    line: int


class CellRows(NamedTuple):
    """The cell lines (TRGL, SEG, TETRA) of an object as arrays, one row per line."""

    ids: NDArray[np.int64]  # (M, width) vertex ids
    values: NDArray[np.float64]  # (M, n_values) property values
    parts: NDArray[np.int64]  # (M,) TFACE / ILINE / TVOLUME index
    lines: NDArray[np.int64]  # (M,) line numbers
