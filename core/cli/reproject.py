"""``geobrep reproject IN OUT --to EPSG:xxxx``: transform every entity into another CRS."""

from __future__ import annotations

import argparse
from typing import Any

from geobrep.cli.common import add_allow_empty, format_name, read_input

__all__ = ["add_parser", "run"]


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "reproject",
        help="transform a model into another CRS",
        description=(
            "Reproject every entity of a file into another CRS with pyproj (3D when both CRSs "
            "have a vertical axis, otherwise horizontally with z converted between units). "
            "Properties, ids and topology are kept; a file without a CRS needs --from."
        ),
    )
    parser.add_argument("input", help="file to read (any readable format)")
    parser.add_argument("output", help="file to write (format from the extension or --to-format)")
    parser.add_argument(
        "--to", required=True, dest="target", help="target CRS: EPSG:xxxx, WKT or PROJ string"
    )
    parser.add_argument(
        "--from", dest="source", help="source CRS, when the file has none (or to override it)"
    )
    parser.add_argument(
        "--format", type=format_name("read"), help="input format, when the extension is not enough"
    )
    parser.add_argument("--to-format", type=format_name("write"), help="output format name")
    add_allow_empty(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from geobrep.gis.crs_ops import to_crs
    from geobrep.ops.io import write

    scene = read_input(args, args.input, format=args.format)
    moved = to_crs(scene, args.target, source=args.source)
    write(moved, args.output, format=args.to_format)
    source = args.source or (scene.crs.label if scene.crs else "?")
    print(
        f"{args.output}: {len(moved.entities)} entities reprojected from {source} "
        f"to {moved.crs.label if moved.crs else args.target}"
    )
    return 0
