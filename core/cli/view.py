"""``geobrep view MODEL -o model.html``: the model in one offline HTML page (three.js inlined).

The page lists the blocks and surfaces with their names and colours, each switchable, has a
clipping plane and axes labelled in world coordinates, and needs no server: open it from disk.
Writing goes through the registered ``html`` format.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from geobrep.cli.common import add_allow_empty, format_name, read_input
from geobrep.ops.io import write

__all__ = ["add_parser", "run"]


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "view",
        description="Write MODEL as a self-contained HTML page (3D view, no server needed).",
    )
    parser.add_argument("scene", help="model file (any readable format)")
    parser.add_argument(
        "-o", "--output", help="page to write (default: MODEL's name with .html, here)"
    )
    parser.add_argument(
        "--format", type=format_name("read"), help="input format, when the extension is not enough"
    )
    parser.add_argument("--title", help="the page's title (default: the model's name)")
    parser.add_argument(
        "--no-blocks", action="store_true", help="do not show blocks (only surfaces, lines, points)"
    )
    parser.add_argument(
        "--all-surfaces",
        action="store_true",
        help="with blocks, start with every surface shown too (default: only faults)",
    )
    add_allow_empty(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    scene = read_input(args, args.scene, format=args.format)
    output = args.output or Path(args.scene).with_suffix(".html").name
    path = write(
        scene,
        output,
        format="html",
        title=args.title,
        blocks=not args.no_blocks,
        surfaces_with_blocks=args.all_surfaces,
    )
    print(f"wrote {path}")
    return 0
