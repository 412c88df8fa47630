"""The entity types of a geobrep scene.

The entities a surface file holds (:class:`Surface`, :class:`PolyLine`, :class:`PointSet`,
:class:`Block`) are imported with the package; the others (grids, wells, tetrahedral meshes,
NURBS, octrees, polygons, annotations) on first use of their name (PEP 562), so reading a
TSurf does not load the models it does not hold. :data:`AnyEntity` and :data:`ENTITY_TYPES`
name every class and import them all.
"""

from __future__ import annotations

import importlib
import sys
from typing import TYPE_CHECKING, Annotated, Any, TypeAlias

from geobrep.model.entities.base import Entity, VertexEntity
from geobrep.model.entities.block import UNIVERSE_KIND, Block, PatchSide
from geobrep.model.entities.pointset import PointSet
from geobrep.model.entities.polyline import PolyLine
from geobrep.model.entities.surface import Surface

if TYPE_CHECKING:
    from pydantic import Field

    from geobrep.model.entities.annotation import Annotation
    from geobrep.model.entities.grid import RegularGrid
    from geobrep.model.entities.nurbs import NurbsSurface
    from geobrep.model.entities.octree import LinearOctree
    from geobrep.model.entities.polygon import Polygon
    from geobrep.model.entities.structured import StructuredGrid
    from geobrep.model.entities.tetmesh import TetMesh
    from geobrep.model.entities.well import Well, WellLog, WellMarker, WellZone

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
    ENTITY_TYPES: dict[str, type[Entity]]

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

#: Every concrete entity class a scene holds, by its ``type`` name, with the module that defines
#: it (under ``geobrep.model.entities``), in the order of the scene's union of entity types.
ENTITY_MODULES: dict[str, str] = {
    "PointSet": "pointset",
    "PolyLine": "polyline",
    "Polygon": "polygon",
    "Surface": "surface",
    "TetMesh": "tetmesh",
    "NurbsSurface": "nurbs",
    "Annotation": "annotation",
    "Block": "block",
    "LinearOctree": "octree",
    "RegularGrid": "grid",
    "StructuredGrid": "structured",
    "Well": "well",
}

#: The other public names imported on first use, with their modules.
_LAZY: dict[str, str] = {
    **{name: module for name, module in ENTITY_MODULES.items() if name not in globals()},
    "WellLog": "well",
    "WellMarker": "well",
    "WellZone": "well",
}


def is_entity_class(cls: type) -> bool:
    """True if ``cls`` is one of the classes of :data:`ENTITY_MODULES` (not a subclass), told
    without importing a module: a class whose module is not imported has no instances.

    >>> is_entity_class(Surface), is_entity_class(VertexEntity)
    (True, False)
    """
    module = ENTITY_MODULES.get(cls.__name__)
    if module is None:
        return False
    loaded = sys.modules.get(f"{__name__}.{module}")
    return loaded is not None and getattr(loaded, cls.__name__, None) is cls


def _every_type() -> dict[str, type[Entity]]:
    return {name: _class(name, module) for name, module in ENTITY_MODULES.items()}


def _class(name: str, module: str) -> Any:
    return getattr(importlib.import_module(f"{__name__}.{module}"), name)


def _any_entity() -> Any:
    from functools import reduce
    from operator import or_

    from pydantic import Field

    return Annotated[reduce(or_, _every_type().values()), Field(discriminator="type")]


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        value = _class(name, _LAZY[name])
    elif name == "ENTITY_TYPES":
        value = _every_type()
    elif name == "AnyEntity":
        value = _any_entity()
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
