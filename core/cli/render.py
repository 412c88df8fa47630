"""``geobrep render SCENE out.png``: a picture of a model, off-screen (no display needed).

Colour by entity, block or property, optionally cutting away the side of a plane its normal
points to. Rendering goes through the registered ``png`` format (pyvista, extra ``viz``).
"""

from __future__ import annotations

import argparse
from typing import Any

from geobrep.cli.common import add_allow_empty, format_name, read_input
from geobrep.errors import OptionsError
from geobrep.ops.io import write

__all__ = ["add_parser", "run"]


def _triple(text: str) -> tuple[float, float, float]:
    try:
        values = tuple(float(v) for v in text.replace(",", " ").split())
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected three numbers, got {text!r}") from None
    if len(values) != 3:
        raise argparse.ArgumentTypeError(f"expected three numbers, got {text!r}")
    return values[0], values[1], values[2]


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "render",
        help="render a picture of a model (PNG, off-screen)",
        description="Render a model to a PNG file without a display.",
    )
    parser.add_argument("scene", help="model file (any readable format)")
    parser.add_argument("output", help="picture to write (.png)")
    parser.add_argument(
        "--format", type=format_name("read"), help="input format, when the extension is not enough"
    )
    parser.add_argument(
        "--color-by",
        choices=("entity", "block", "property"),
        default=None,
        help="colour each entity, each block, or by a property "
        "(default: entity; property when --property is given)",
    )
    parser.add_argument("--property", help="property to colour by")
    parser.add_argument(
        "--clip-origin", type=_triple, metavar="X,Y,Z", help="a point of the cut-away plane"
    )
    parser.add_argument(
        "--clip-normal",
        type=_triple,
        metavar="NX,NY,NZ",
        help="normal of the cut-away plane (the side it points to is removed)",
    )
    parser.add_argument(
        "--size",
        type=int,
        nargs=2,
        metavar=("W", "H"),
        default=(1200, 900),
        help="picture size in pixels",
    )
    parser.add_argument("--edges", action="store_true", help="draw triangle edges")
    parser.add_argument("--vertical-exaggeration", type=float, default=1.0, metavar="F")
    add_allow_empty(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    if (args.clip_origin is None) != (args.clip_normal is None):
        raise OptionsError("--clip-origin and --clip-normal go together")
    color_by = args.color_by or ("property" if args.property else "entity")
    scene = read_input(args, args.scene, format=args.format)
    path = write(
        scene,
        args.output,
        format="png",
        color_by=color_by,
        property=args.property,
        clip_origin=args.clip_origin,
        clip_normal=args.clip_normal,
        window_size=tuple(args.size),
        show_edges=args.edges,
        vertical_exaggeration=args.vertical_exaggeration,
    )
    print(f"wrote {path}")
    return 0
