"""``geobrep render SCENE out.png``: a picture of a model, off-screen (no display needed).

Colour by entity, block or property, optionally cutting away the side of a plane its normal
points to or drawing a section; a legend, axes in world coordinates, a scale bar and the CRS in
the title. Rendering goes through the registered ``png`` format (pyvista, extra ``viz``).
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
        "--section-origin", type=_triple, metavar="X,Y,Z", help="a point of the section plane"
    )
    parser.add_argument(
        "--section-normal",
        type=_triple,
        metavar="NX,NY,NZ",
        help="normal of the section plane: the side it points to is removed, blocks are "
        "closed by the cut, and the picture looks at the cut",
    )
    parser.add_argument(
        "--view",
        choices=("isometric", "top", "bottom", "north", "south", "east", "west"),
        help="where the camera looks from (default: isometric, or square to the section)",
    )
    parser.add_argument(
        "--azimuth",
        type=float,
        default=0.0,
        metavar="DEG",
        help="turn the camera about the vertical by DEG degrees",
    )
    parser.add_argument(
        "--elevation",
        type=float,
        default=0.0,
        metavar="DEG",
        help="raise the camera by DEG degrees",
    )
    parser.add_argument("--title", help="the picture's title (default: model name and CRS)")
    parser.add_argument("--no-legend", action="store_true", help="no legend of names and colours")
    parser.add_argument("--no-axes", action="store_true", help="no axes with coordinates")
    parser.add_argument("--no-scale-bar", action="store_true", help="no scale bar")
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
    if (args.section_origin is None) != (args.section_normal is None):
        raise OptionsError("--section-origin and --section-normal go together")
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
        section_origin=args.section_origin,
        section_normal=args.section_normal,
        view=args.view,
        azimuth=args.azimuth,
        elevation=args.elevation,
        title=args.title,
        legend=not args.no_legend,
        axes=not args.no_axes,
        scale_bar=not args.no_scale_bar,
    )
    print(f"wrote {path}")
    return 0
