"""The records of a Model3d header and of a TSolid MODEL section, and the drafts the parser
fills while it reads their lines (:meth:`ModelDraft.freeze`, :meth:`SolidDraft.freeze` give the
records).

Imported when a file has a Model3d, TSolid or LightTSolid object: the dataclasses are made at
import (about 0.4 ms each), which a TSurf, PLine or VSet read does not need.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

__all__ = [
    "KeyVertices",
    "ListDraft",
    "Model3dHeader",
    "ModelDraft",
    "ModelList",
    "ModelRegion",
    "RegionEntry",
    "SolidDraft",
    "SolidModel",
    "SolidSurface",
    "SolidTFace",
    "SolidTFaceDraft",
    "SolidTriangle",
    "TFaceDraft",
    "TFaceEntry",
]


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


# -- drafts -----------------------------------------------------------------------------------
@dataclass
class TFaceDraft:
    id: int
    type: str
    tsurf: str
    line: int
    key: list[tuple[float, float, float]] = field(default_factory=list)


@dataclass
class ListDraft:
    keyword: str
    name: str
    line: int
    region_id: int | None = None  # REGION only
    items: list[int] = field(default_factory=list)
    closed: bool = False  # the list's 0 was read


@dataclass
class ModelDraft:
    """A Model3d header while its lines are read; :meth:`freeze` gives the record."""

    tsurfs: list[str] = field(default_factory=list)
    tfaces: list[TFaceDraft] = field(default_factory=list)
    lists: list[ListDraft] = field(default_factory=list)
    key_for: TFaceDraft | None = None  # the TFACE whose key-triangle lines may follow
    current: ListDraft | None = None  # the list whose ids may follow

    def add_tface(self, tface_id: int, kind: str, tsurf: str, line: int) -> TFaceDraft:
        """A header ``TFACE`` line: the TFACE whose key-triangle lines follow."""
        entry = TFaceDraft(tface_id, kind, tsurf, line)
        self.tfaces.append(entry)
        return entry

    @staticmethod
    def new_list(keyword: str, name: str, line: int, region_id: int | None = None) -> ListDraft:
        """The list a ``REGION`` (``region_id`` given), ``LAYER``, ... line opens."""
        return ListDraft(keyword, name, line, region_id=region_id)

    def freeze(self) -> Model3dHeader:
        return Model3dHeader(
            tsurfs=tuple(self.tsurfs),
            tfaces=tuple(
                TFaceEntry(t.id, t.type, t.tsurf, tuple(t.key), t.line) for t in self.tfaces
            ),
            regions=tuple(
                RegionEntry(d.region_id, d.name, tuple(d.items), d.line)
                for d in self.lists
                if d.keyword == "REGION" and d.region_id is not None
            ),
            lists=tuple(
                ModelList(d.keyword, d.name, tuple(d.items), d.line)
                for d in self.lists
                if d.keyword != "REGION"
            ),
        )


@dataclass
class SolidTFaceDraft:
    id: int
    key: KeyVertices | None = None
    triangles: list[SolidTriangle] = field(default_factory=list)

    def add(self, keyword: str, ids: tuple[int, int, int], line: int) -> None:
        """A ``TRGL`` line (one of the TFACE's triangles) or ``KEYVERTICES`` (its key)."""
        triangle = SolidTriangle(ids, line)
        if keyword == "TRGL":
            self.triangles.append(triangle)
        else:
            self.key = triangle


@dataclass
class SolidDraft:
    """A TSolid's MODEL section while its lines are read; :meth:`freeze` gives the record."""

    in_model: bool = False
    surfaces: list[tuple[str, list[SolidTFaceDraft]]] = field(default_factory=list)
    regions: list[ModelRegion] = field(default_factory=list)

    def add_tface(self, tface_id: int) -> None:
        """A ``TFACE`` of the last ``SURFACE``."""
        self.surfaces[-1][1].append(SolidTFaceDraft(tface_id))

    def add_region(self, name: str, signed_tface: int) -> None:
        self.regions.append(ModelRegion(name, signed_tface))

    def freeze(self) -> SolidModel:
        return SolidModel(
            surfaces=tuple(
                SolidSurface(
                    name, tuple(SolidTFace(t.id, t.key, tuple(t.triangles)) for t in tfaces)
                )
                for name, tfaces in self.surfaces
            ),
            regions=tuple(self.regions),
        )
