"""The entity types of a geobrep scene."""

from __future__ import annotations

from typing import Annotated, TypeAlias

from pydantic import Field

from geobrep.entities.annotation import Annotation
from geobrep.entities.base import Entity, VertexEntity
from geobrep.entities.block import UNIVERSE_KIND, Block, PatchSide
from geobrep.entities.nurbs import NurbsSurface
from geobrep.entities.octree import LinearOctree
from geobrep.entities.pointset import PointSet
from geobrep.entities.polygon import Polygon
from geobrep.entities.polyline import PolyLine
from geobrep.entities.surface import Surface
from geobrep.entities.tetmesh import TetMesh

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
    "Surface",
    "TetMesh",
    "VertexEntity",
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
    | LinearOctree,
    Field(discriminator="type"),
]
