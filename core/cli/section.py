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
    add_allow_empty(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from geobrep.clipping import section
    from geobrep.io import write

    scene = read_input(args, args.input, format=args.format)
    plane = plane_from_args(args)
    if plane is None:  # pragma: no cover - argparse requires one plane option
        raise OptionsError("give --plane, --x, --y or --z")
    panel = section(scene, plane, tolerance=args.tolerance)
    if is_empty(panel):
        message = f"{args.output}: {plane_text(args)} touches nothing ({span_text(scene)})"
        refuse_empty(args, [message], consequence="no file written")
    write(panel, Path(args.output), format=args.output_format)
    polygons = sum(1 for e in panel.entities if e.kind == "section")
    print(f"{args.output}: {polygons} block sections, {len(panel.entities) - polygons} traces")
    return 0
