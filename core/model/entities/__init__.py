"""The entity types of a geobrep scene."""

from __future__ import annotations

from typing import Annotated, TypeAlias

from pydantic import Field

from geobrep.model.entities.annotation import Annotation
from geobrep.model.entities.base import Entity, VertexEntity
from geobrep.model.entities.block import UNIVERSE_KIND, Block, PatchSide
from geobrep.model.entities.nurbs import NurbsSurface
from geobrep.model.entities.octree import LinearOctree
from geobrep.model.entities.pointset import PointSet
from geobrep.model.entities.polygon import Polygon
from geobrep.model.entities.polyline import PolyLine
from geobrep.model.entities.surface import Surface
from geobrep.model.entities.tetmesh import TetMesh

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
