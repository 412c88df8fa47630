"""The records of a Model3d header and of a TSolid MODEL section, and the drafts the parser
fills while it reads their lines (:meth:`ModelDraft.freeze`, :meth:`SolidDraft.freeze` give the
records).

Imported when a file has a Model3d, TSolid or LightTSolid object. The records are named
tuples and the drafts plain classes with slots: a frozen dataclass costs about half a
millisecond to make at import (its generated methods are compiled), which every first read of
such a file would pay.
"""

from __future__ import annotations

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
class TFaceEntry(NamedTuple):
    """``TFACE <id> <geological type> <TSurf name>`` of a Model3d header and its key triangle
    (three coordinate lines, as written: z not yet turned by ZPOSITIVE)."""

    id: int
    type: str
    tsurf: str
    key: tuple[tuple[float, float, float], ...]
    line: int


class RegionEntry(NamedTuple):
    """``REGION <id> <name>`` and the signed TFACE ids that follow it."""

    id: int
    name: str
    items: tuple[int, ...]
    line: int


class ModelList(NamedTuple):
    """``LAYER`` / ``FAULT_BLOCK`` (REGION ids) or ``SURFACE`` / ``FAULT`` / ``BOUNDARY`` /
    ``UNIT`` (TFACE ids) of a Model3d header."""

    keyword: str
    name: str
    items: tuple[int, ...]
    line: int


class Model3dHeader(NamedTuple):
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


class SolidTFace(NamedTuple):
    """``TFACE <id>`` of a TSolid MODEL surface: its key triangle and triangles."""

    id: int
    key: KeyVertices | None
    triangles: tuple[SolidTriangle, ...]


class SolidSurface(NamedTuple):
    """``SURFACE <name>`` of a TSolid MODEL section."""

    name: str
    tfaces: tuple[SolidTFace, ...]


class ModelRegion(NamedTuple):
    """``MODEL_REGION <name> <±tface>``: the region on that side of the TFACE's key triangle."""

    name: str
    signed_tface: int


class SolidModel(NamedTuple):
    """The ``MODEL`` section of a TSolid / LightTSolid."""

    surfaces: tuple[SolidSurface, ...] = ()
    regions: tuple[ModelRegion, ...] = ()


# -- drafts -----------------------------------------------------------------------------------
class TFaceDraft:
    """A header ``TFACE`` line and the key-triangle lines read after it."""

    __slots__ = ("id", "key", "line", "tsurf", "type")

    def __init__(self, id: int, type: str, tsurf: str, line: int) -> None:
        self.id = id
        self.type = type
        self.tsurf = tsurf
        self.line = line
        self.key: list[tuple[float, float, float]] = []


class ListDraft:
    """A ``REGION`` / ``LAYER`` / ... line and the ids read after it."""

    __slots__ = ("closed", "items", "keyword", "line", "name", "region_id")

    def __init__(self, keyword: str, name: str, line: int, region_id: int | None = None) -> None:
        self.keyword = keyword
        self.name = name
        self.line = line
        self.region_id = region_id  # REGION only
        self.items: list[int] = []
        self.closed = False  # the list's 0 was read


class ModelDraft:
    """A Model3d header while its lines are read; :meth:`freeze` gives the record."""

    __slots__ = ("current", "key_for", "lists", "tfaces", "tsurfs")

    def __init__(self) -> None:
        self.tsurfs: list[str] = []
        self.tfaces: list[TFaceDraft] = []
        self.lists: list[ListDraft] = []
        self.key_for: TFaceDraft | None = None  # the TFACE whose key-triangle lines may follow
        self.current: ListDraft | None = None  # the list whose ids may follow

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


class SolidTFaceDraft:
    """A ``TFACE`` of a TSolid MODEL surface while its lines are read."""

    __slots__ = ("id", "key", "triangles")

    def __init__(self, id: int) -> None:
        self.id = id
        self.key: KeyVertices | None = None
        self.triangles: list[SolidTriangle] = []

    def add(self, keyword: str, ids: tuple[int, int, int], line: int) -> None:
        """A ``TRGL`` line (one of the TFACE's triangles) or ``KEYVERTICES`` (its key)."""
        triangle = SolidTriangle(ids, line)
        if keyword == "TRGL":
            self.triangles.append(triangle)
        else:
            self.key = triangle


class SolidDraft:
    """A TSolid's MODEL section while its lines are read; :meth:`freeze` gives the record."""

    __slots__ = ("in_model", "regions", "surfaces")

    def __init__(self) -> None:
        self.in_model = False
        self.surfaces: list[tuple[str, list[SolidTFaceDraft]]] = []
        self.regions: list[ModelRegion] = []

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
