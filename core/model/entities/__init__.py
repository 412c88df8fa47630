"""The entity types of a geobrep scene."""

from __future__ import annotations

from typing import Annotated, TypeAlias

from pydantic import Field

from geobrep.model.entities.annotation import Annotation
from geobrep.model.entities.base import Entity, VertexEntity
from geobrep.model.entities.block import UNIVERSE_KIND, Block, PatchSide
from geobrep.model.entities.grid import RegularGrid
from geobrep.model.entities.nurbs import NurbsSurface
from geobrep.model.entities.octree import LinearOctree
from geobrep.model.entities.pointset import PointSet
from geobrep.model.entities.polygon import Polygon
from geobrep.model.entities.polyline import PolyLine
from geobrep.model.entities.structured import StructuredGrid
from geobrep.model.entities.surface import Surface
from geobrep.model.entities.tetmesh import TetMesh
from geobrep.model.entities.well import Well, WellLog, WellMarker, WellZone

__all__ = [
    "ENTITY_TYPES",
    "UNIVERSE_KIND",
    "Annotation",
    "AnyEntity",
    "Block",
    "Entity",
    "LinearOctree",
    "NurbsSurface",
    "PatchSide",
    "PointSet",
    "PolyLine",
    "Polygon",
    "RegularGrid",
    "StructuredGrid",
    "Surface",
    "TetMesh",
    "VertexEntity",
    "Well",
    "WellLog",
    "WellMarker",
    "WellZone",
]

#: Every concrete entity class, by its ``type`` name.
ENTITY_TYPES: dict[str, type[Entity]] = {
    cls.__name__: cls
    for cls in (
        PointSet,
        PolyLine,
        Polygon,
        Surface,
        TetMesh,
        NurbsSurface,
        Annotation,
        Block,
        LinearOctree,
        RegularGrid,
        StructuredGrid,
        Well,
    )
}

AnyEntity: TypeAlias = Annotated[
    PointSet
    | PolyLine
    | Polygon
    | Surface
    | TetMesh
    | NurbsSurface
    | Annotation
    | Block
    | LinearOctree
    | RegularGrid
    | StructuredGrid
    | Well,
    Field(discriminator="type"),
]
