"""geobrep's built-in clippers: one per entity type, registered like any plugin's.

The facade (:func:`geobrep.clip`) calls ``function(entity, plane, keep, options,
context)``; see ``docs/clipping.md``. Each clipper lives in its own module of this package.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from geobrep.plugins import hookimpl

if TYPE_CHECKING:
    from geobrep.plugins import ClipperRegistry

__all__ = ["geobrep_register_clippers"]


@hookimpl
def geobrep_register_clippers(registry: ClipperRegistry) -> None:
    """Register the built-in clippers (modules are imported here, on first use of a registry)."""
    from geobrep.plugins import ClipperSpec
    from geobrep.plugins.clip._blocks import clip_block, section_block
    from geobrep.plugins.clip._lines import clip_polyline, section_polyline
    from geobrep.plugins.clip._nurbs import clip_nurbs
    from geobrep.plugins.clip._octree import clip_octree
    from geobrep.plugins.clip._points import clip_pointset, section_pointset
    from geobrep.plugins.clip._polygons import clip_polygon, section_polygon
    from geobrep.plugins.clip._surfaces import clip_surface, section_surface
    from geobrep.plugins.clip.annotations import clip_annotation
    from geobrep.plugins.clip.options import (
        AnnotationClipOptions,
        ClipOptions,
        NurbsClipOptions,
        OctreeClipOptions,
        SurfaceClipOptions,
    )

    # name, entity type, clipper, section (or None), options model, description
    table: list[tuple[str, str, Callable[..., Any], Callable[..., Any] | None, type, str]] = [
        ("surface", "Surface", clip_surface, section_surface, SurfaceClipOptions,
         "Triangle and quad surfaces: shared cut vertices, interpolated point data, caps on "
         "closed surfaces"),
        ("polyline", "PolyLine", clip_polyline, section_polyline, ClipOptions,
         "Lines: runs of kept segments become parts, crossing points exact"),
        ("polygon", "Polygon", clip_polygon, section_polygon, ClipOptions,
         "Filled polygons with holes: pieces closed along the cut, holes nested"),
        ("pointset", "PointSet", clip_pointset, section_pointset, ClipOptions,
         "Points: those on the kept side (on the plane: both sides)"),
        ("annotation", "Annotation", clip_annotation, None, AnnotationClipOptions,
         "Text at string, character or stroke precision (built-in stroke font)"),
        ("octree", "LinearOctree", clip_octree, None, OctreeClipOptions,
         "Linear octrees: leaves kept, dropped, or split down to the finest level"),
        ("nurbs", "NurbsSurface", clip_nurbs, None, NurbsClipOptions,
         "NURBS surfaces: exact trimming by half-spaces, found on the tessellation"),
        ("block", "Block", clip_block, section_block, ClipOptions,
         "Blocks of a scene: each cut block is closed by a cap patch"),
    ]  # fmt: skip
    for name, entity_type, function, section, options, description in table:
        registry.add(
            ClipperSpec(
                name=name,
                description=description,
                entity_type=entity_type,
                function=function,
                section=section,
                options=options,
            )
        )
