"""geobrep's built-in clippers: one per entity type, registered like any plugin's.

The facade (:func:`geobrep.clip`) calls ``function(entity, plane, keep, options,
context)``; see ``docs/clipping.md``. Each clipper lives in its own module of this package.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from geobrep.plugins import hookimpl

if TYPE_CHECKING:
    from geobrep.plugins import ClipperRegistry

__all__ = ["geobrep_register_clippers"]


def _deferred(module: str, name: str) -> Callable[..., Any]:
    """``module.name``, imported on its first call: filling the registries imports no kernel."""
    function: Callable[..., Any] | None = None

    def call(*args: Any, **kwargs: Any) -> Any:
        nonlocal function
        if function is None:
            function = getattr(importlib.import_module(f"geobrep.plugins.clip.{module}"), name)
        return function(*args, **kwargs)

    call.__name__ = call.__qualname__ = name
    call.__module__ = f"geobrep.plugins.clip.{module}"
    return call


@hookimpl
def geobrep_register_clippers(registry: ClipperRegistry) -> None:
    """Register the built-in clippers (their modules are imported on a clipper's first call)."""
    from geobrep.plugins import ClipperSpec
    from geobrep.plugins.clip.options import (
        AnnotationClipOptions,
        ClipOptions,
        GridClipOptions,
        NurbsClipOptions,
        OctreeClipOptions,
        SurfaceClipOptions,
        WellClipOptions,
    )

    # name, entity type, module, clipper, section (or None), options model, description
    table: list[tuple[str, str, str, str, str | None, type, str]] = [
        ("surface", "Surface", "_surfaces", "clip_surface", "section_surface", SurfaceClipOptions,
         "Triangle and quad surfaces: shared cut vertices, interpolated point data, caps on "
         "closed surfaces"),
        ("polyline", "PolyLine", "_lines", "clip_polyline", "section_polyline", ClipOptions,
         "Lines: runs of kept segments become parts, crossing points exact"),
        ("polygon", "Polygon", "_polygons", "clip_polygon", "section_polygon", ClipOptions,
         "Filled polygons with holes: pieces closed along the cut, holes nested"),
        ("pointset", "PointSet", "_points", "clip_pointset", "section_pointset", ClipOptions,
         "Points: those on the kept side (on the plane: both sides)"),
        ("annotation", "Annotation", "annotations", "clip_annotation", None, AnnotationClipOptions,
         "Text at string, character or stroke precision (built-in stroke font)"),
        ("octree", "LinearOctree", "_octree", "clip_octree", None, OctreeClipOptions,
         "Linear octrees: leaves kept, dropped, or split down to the finest level"),
        ("nurbs", "NurbsSurface", "_nurbs", "clip_nurbs", None, NurbsClipOptions,
         "NURBS surfaces: exact trimming by half-spaces, found on the tessellation"),
        ("regular_grid", "RegularGrid", "_grids", "clip_regular_grid", "section_regular_grid",
         GridClipOptions,
         "Regular grids: whole cells kept by centre, inside or touching; sections as surfaces "
         "carrying the cell data"),
        ("structured_grid", "StructuredGrid", "_grids", "clip_structured_grid",
         "section_structured_grid", GridClipOptions,
         "Curvilinear and corner-point grids: whole cells kept, the rest made inactive; "
         "sections as surfaces carrying the cell data"),
        ("well", "Well", "_wells", "clip_well", "section_well", WellClipOptions,
         "Wells: the path cut on its minimum-curvature arcs at the MD of the cut; markers, "
         "zones and logs kept; sections: the crossing points or the well on the section"),
        ("block", "Block", "_blocks", "clip_block", "section_block", ClipOptions,
         "Blocks of a scene: each cut block is closed by a cap patch"),
    ]  # fmt: skip
    for name, entity_type, module, function, section, options, description in table:
        registry.add(
            ClipperSpec(
                name=name,
                description=description,
                entity_type=entity_type,
                function=_deferred(module, function),
                section=None if section is None else _deferred(module, section),
                options=options,
            )
        )
