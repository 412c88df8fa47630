"""``geobrep section IN OUT --plane ...``: the cut itself — block section polygons and traces.

The options are those of the ``section`` operation (:class:`~geobrep.batch.pipeline.SectionStep`);
``--x``, ``--y`` and ``--z`` (:class:`~geobrep.cli.clip.PlaneShortcuts`) name its plane too.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

from geobrep.batch.pipeline import SectionStep
from geobrep.cli.clip import PlaneShortcuts, plane_text, span_text
from geobrep.cli.common import is_empty, read_input, refuse_empty
from geobrep.geometry import Plane

__all__ = ["COMMAND", "DESCRIPTION", "OPERATION", "SectionCommand", "run"]

OPERATION = "section"
DESCRIPTION = (
    "Write the section of a model by a plane: one polygon (with holes) per cut "
    "block, carrying the block's id and attributes, and the trace of every cut surface."
)


class SectionCommand(PlaneShortcuts):
    """The files and command-line-only options of ``geobrep section``."""

    coordinates: Literal["auto", "world", "plane", "both"] = "auto"
    """where the section of a plane that is not horizontal goes: 'world' (map coordinates: a
    vertical section has no area in map view), 'plane' (distance along the section line and
    elevation, in *_plane layers: valid polygons a GIS can draw), 'both'; 'auto' (default):
    both for a GeoPackage, world otherwise"""


def run(options: SectionStep, args: SectionCommand) -> int:
    from geobrep.ops.clipping import section
    from geobrep.ops.io import write

    scene = read_input(args, args.input, format=args.format)
    plane = Plane(*options.plane)
    panel = section(
        scene,
        plane,
        tolerance=options.tolerance,
        options=options.options,
        clippers=options.clippers,
    )
    if is_empty(panel):
        message = f"{args.output}: {plane_text(args, options)} touches nothing ({span_text(scene)})"
        refuse_empty(args, [message], consequence="no file written")
    polygons = sum(1 for e in panel.entities if e.kind == "section")
    traces = len(panel.entities) - polygons
    panel, in_plane = _in_coordinates(panel, plane, _coordinates(args))
    write(panel, Path(args.output), format=args.output_format)
    where = " (also in section-plane coordinates)" if in_plane else ""
    print(f"{args.output}: {polygons} block sections, {traces} traces{where}")
    return 0


def _coordinates(args: SectionCommand) -> str:
    if args.coordinates != "auto":
        return str(args.coordinates)
    gpkg = args.output_format == "gpkg" or (
        args.output_format is None and Path(args.output).suffix.lower() == ".gpkg"
    )
    return "both" if gpkg else "world"


def _in_coordinates(panel: Any, plane: Any, coordinates: str) -> tuple[Any, bool]:
    """The panel in world coordinates, the plane's own, or both (layers ``*_plane``)."""
    import numpy as np

    from geobrep.gis.map_products import section_frame, to_section_plane
    from geobrep.model.entities import Polygon

    horizontal = float(np.hypot(plane.normal[0], plane.normal[1])) < 1e-12
    if coordinates == "world" or horizontal or not panel.entities:
        return panel, False
    layered = [
        e.replace(
            metadata={
                **e.metadata,
                "layer": "sections" if isinstance(e, Polygon) else "section_lines",
            }
        )
        for e in panel.entities
    ]
    vertices = np.concatenate([e.vertices for e in layered])
    moved = to_section_plane(layered, section_frame(plane, vertices))
    kept = layered if coordinates == "both" else []
    return panel.replace(entities=[*kept, *moved], topology={}), True


COMMAND = SectionCommand
