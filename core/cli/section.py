"""``geobrep section IN OUT --plane ...``: the cut itself — block section polygons and traces."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from geobrep.cli.clip import add_plane_arguments, plane_from_args, plane_text, span_text
from geobrep.cli.common import add_allow_empty, format_name, is_empty, read_input, refuse_empty
from geobrep.errors import OptionsError

__all__ = ["add_parser", "run"]


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "section",
        help="section polygons of blocks and traces of surfaces on a plane",
        description="Write the section of a model by a plane: one polygon (with holes) per cut "
        "block, carrying the block's id and attributes, and the trace of every cut surface.",
    )
    parser.add_argument("input", help="model to cut (any readable format)")
    parser.add_argument("output", help="file to write (its extension picks the format)")
    add_plane_arguments(parser)
    parser.add_argument("--tolerance", type=float, help="on-plane distance (model units)")
    parser.add_argument(
        "--format", type=format_name("read"), help="input format, when the extension is not enough"
    )
    parser.add_argument("--output-format", type=format_name("write"), help="output format name")
    parser.add_argument(
        "--coordinates",
        choices=("auto", "world", "plane", "both"),
        default="auto",
        help="where the section of a plane that is not horizontal goes: 'world' (map "
        "coordinates: a vertical section has no area in map view), 'plane' (distance along the "
        "section line and elevation, in *_plane layers: valid polygons a GIS can draw), 'both'; "
        "'auto' (default): both for a GeoPackage, world otherwise",
    )
    add_allow_empty(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from geobrep.ops.clipping import section
    from geobrep.ops.io import write

    scene = read_input(args, args.input, format=args.format)
    plane = plane_from_args(args)
    if plane is None:  # pragma: no cover - argparse requires one plane option
        raise OptionsError("give --plane, --x, --y or --z")
    panel = section(scene, plane, tolerance=args.tolerance)
    if is_empty(panel):
        message = f"{args.output}: {plane_text(args)} touches nothing ({span_text(scene)})"
        refuse_empty(args, [message], consequence="no file written")
    polygons = sum(1 for e in panel.entities if e.kind == "section")
    traces = len(panel.entities) - polygons
    panel, in_plane = _in_coordinates(panel, plane, _coordinates(args))
    write(panel, Path(args.output), format=args.output_format)
    where = " (also in section-plane coordinates)" if in_plane else ""
    print(f"{args.output}: {polygons} block sections, {traces} traces{where}")
    return 0


def _coordinates(args: argparse.Namespace) -> str:
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
