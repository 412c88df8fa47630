"""geobrep's built-in clippers: one per entity type, registered like any plugin's.

The facade (:func:`geobrep.clip`) calls ``function(entity, plane, keep, options,
context)``; see ``docs/clipping.md``. Each clipper lives in its own module of this package.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from geobrep.plugins import hookimpl

if TYPE_CHECKING:
    from geobrep.plugins import ClipperRegistry

__all__ = ["geobrep_register_clippers"]


@hookimpl
def geobrep_register_clippers(registry: ClipperRegistry) -> None:
    """Register the built-in clippers (modules are imported here, on first use of a registry)."""
    from geobrep.plugins import ClipperSpec
    from geobrep.plugins.clip.annotations import clip_annotation
    from geobrep.plugins.clip.blocks import clip_block, section_block
    from geobrep.plugins.clip.lines import clip_polyline, section_polyline
    from geobrep.plugins.clip.nurbs import clip_nurbs
    from geobrep.plugins.clip.octree import clip_octree
    from geobrep.plugins.clip.options import (
        AnnotationClipOptions,
        ClipOptions,
        NurbsClipOptions,
        OctreeClipOptions,
        SurfaceClipOptions,
    )
    from geobrep.plugins.clip.points import clip_pointset, section_pointset
    from geobrep.plugins.clip.polygons import clip_polygon, section_polygon
    from geobrep.plugins.clip.surfaces import clip_surface, section_surface

    registry.add(
        ClipperSpec(
            name="surface",
            description="Triangle and quad surfaces: shared cut vertices, interpolated point "
            "data, caps on closed surfaces",
            entity_type="Surface",
            function=clip_surface,
            section=section_surface,
            options=SurfaceClipOptions,
        )
    )
    registry.add(
        ClipperSpec(
            name="polyline",
            description="Lines: runs of kept segments become parts, crossing points exact",
            entity_type="PolyLine",
            function=clip_polyline,
            section=section_polyline,
            options=ClipOptions,
        )
    )
    registry.add(
        ClipperSpec(
            name="polygon",
            description="Filled polygons with holes: pieces closed along the cut, holes nested",
            entity_type="Polygon",
            function=clip_polygon,
            section=section_polygon,
            options=ClipOptions,
        )
    )
    registry.add(
        ClipperSpec(
            name="pointset",
            description="Points: those on the kept side (on the plane: both sides)",
            entity_type="PointSet",
            function=clip_pointset,
            section=section_pointset,
            options=ClipOptions,
        )
    )
    registry.add(
        ClipperSpec(
            name="annotation",
            description="Text at string, character or stroke precision (built-in stroke font)",
            entity_type="Annotation",
            function=clip_annotation,
            options=AnnotationClipOptions,
        )
    )
    registry.add(
        ClipperSpec(
            name="octree",
            description="Linear octrees: leaves kept, dropped, or split down to the finest level",
            entity_type="LinearOctree",
            function=clip_octree,
            options=OctreeClipOptions,
        )
    )
    registry.add(
        ClipperSpec(
            name="nurbs",
            description="NURBS surfaces: exact trimming by half-spaces, found on the tessellation",
            entity_type="NurbsSurface",
            function=clip_nurbs,
            options=NurbsClipOptions,
        )
    )
    registry.add(
        ClipperSpec(
            name="block",
            description="Blocks of a scene: each cut block is closed by a cap patch",
            entity_type="Block",
            function=clip_block,
            section=section_block,
            options=ClipOptions,
        )
    )
