"""Typed records the GOCAD parser hands to the reader (what a file says, before any entity).

The records are frozen: the parser builds them from private drafts once an object's lines are
read. What a reader keeps of them in ``metadata["gocad"]`` is JSON (lists, strings, numbers),
never these types: that is stored data the native round trip and the GOCAD writer rely on.
"""

from __future__ import annotations

from dataclasses import dataclass
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
    "KeyVertices",
    "Model3dHeader",
    "ModelList",
    "ModelRegion",
    "RegionEntry",
    "SolidModel",
    "SolidSurface",
    "SolidTFace",
    "SolidTriangle",
    "TFaceEntry",
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


# -- Model3d header ---------------------------------------------------------------------------
@dataclass(frozen=True)
class TFaceEntry:
    """``TFACE <id> <geological type> <TSurf name>`` of a Model3d header and its key triangle
    (three coordinate lines, as written: z not yet turned by ZPOSITIVE)."""

    id: int
    type: str
    tsurf: str
    key: tuple[tuple[float, float, float], ...]
    line: int


@dataclass(frozen=True)
class RegionEntry:
    """``REGION <id> <name>`` and the signed TFACE ids that follow it."""

    id: int
    name: str
    items: tuple[int, ...]
    line: int


@dataclass(frozen=True)
class ModelList:
    """``LAYER`` / ``FAULT_BLOCK`` (REGION ids) or ``SURFACE`` / ``FAULT`` / ``BOUNDARY`` /
    ``UNIT`` (TFACE ids) of a Model3d header."""

    keyword: str
    name: str
    items: tuple[int, ...]
    line: int


@dataclass(frozen=True)
class Model3dHeader:
    """What a Model3d object's header declares, in file order."""

    tsurfs: tuple[str, ...] = ()
    tfaces: tuple[TFaceEntry, ...] = ()
    regions: tuple[RegionEntry, ...] = ()
    lists: tuple[ModelList, ...] = ()


# -- TSolid MODEL section ---------------------------------------------------------------------
class SolidTriangle(NamedTuple):
    """A ``TRGL`` (or ``KEYVERTICES``) line of a TSolid MODEL section: 3 vertex ids."""

    ids: tuple[int, int, int]
    line: int


KeyVertices = SolidTriangle


@dataclass(frozen=True)
class SolidTFace:
    """``TFACE <id>`` of a TSolid MODEL surface: its key triangle and triangles."""

    id: int
    key: KeyVertices | None
    triangles: tuple[SolidTriangle, ...]


@dataclass(frozen=True)
class SolidSurface:
    """``SURFACE <name>`` of a TSolid MODEL section."""

    name: str
    tfaces: tuple[SolidTFace, ...]


@dataclass(frozen=True)
class ModelRegion:
    """``MODEL_REGION <name> <±tface>``: the region on that side of the TFACE's key triangle."""

    name: str
    signed_tface: int


@dataclass(frozen=True)
class SolidModel:
    """The ``MODEL`` section of a TSolid / LightTSolid."""

    surfaces: tuple[SolidSurface, ...] = ()
    regions: tuple[ModelRegion, ...] = ()
