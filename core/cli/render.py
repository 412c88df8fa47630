"""``geobrep render SCENE out.png``: a picture of a model, off-screen (no display needed).

Colour by entity, block or property, optionally cutting away the side of a plane its normal
points to or drawing a section; a legend, axes in world coordinates, a scale bar and the CRS in
the title. Rendering goes through the registered ``png`` format (pyvista, extra ``viz``). The
flags are derived from :class:`RenderCommand` (:func:`~geobrep.host.operations.add_arguments`).
"""

from __future__ import annotations

import argparse
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict

from geobrep.cli.common import format_name, read_input
from geobrep.errors import OptionsError
from geobrep.host.operations import Cli, add_arguments, options_from_args
from geobrep.ops.io import write

__all__ = ["RenderCommand", "add_parser", "render", "run"]

Triple = tuple[float, float, float]


def _triple(text: str) -> Triple:
    try:
        values = tuple(float(v) for v in text.replace(",", " ").split())
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected three numbers, got {text!r}") from None
    if len(values) != 3:
        raise argparse.ArgumentTypeError(f"expected three numbers, got {text!r}")
    return values[0], values[1], values[2]


class RenderCommand(BaseModel):
    """The files and options of ``geobrep render`` (the ``png`` writer's, as flags)."""

    model_config = ConfigDict(extra="forbid", frozen=True, use_attribute_docstrings=True)

    scene: Annotated[str, Cli(positional=True)]
    """model file (any readable format)"""
    output: Annotated[str, Cli(positional=True)]
    """picture to write (.png)"""
    format: Annotated[str | None, Cli(parse=format_name("read"))] = None
    """input format, when the extension is not enough"""
    color_by: Literal["entity", "block", "property"] | None = None
    """colour each entity, each block, or by a property (default: entity; property when
    --property is given)"""
    property: str | None = None
    """property to colour by"""
    clip_origin: Annotated[Triple | None, Cli(parse=_triple, metavar="X,Y,Z")] = None
    """a point of the cut-away plane"""
    clip_normal: Annotated[Triple | None, Cli(parse=_triple, metavar="NX,NY,NZ")] = None
    """normal of the cut-away plane (the side it points to is removed)"""
    section_origin: Annotated[Triple | None, Cli(parse=_triple, metavar="X,Y,Z")] = None
    """a point of the section plane"""
    section_normal: Annotated[Triple | None, Cli(parse=_triple, metavar="NX,NY,NZ")] = None
    """normal of the section plane: the side it points to is removed, blocks are closed by the
    cut, and the picture looks at the cut"""
    view: Literal["isometric", "top", "bottom", "north", "south", "east", "west"] | None = None
    """where the camera looks from (default: isometric, or square to the section)"""
    azimuth: Annotated[float, Cli(metavar="DEG")] = 0.0
    """turn the camera about the vertical by DEG degrees"""
    elevation: Annotated[float, Cli(metavar="DEG")] = 0.0
    """raise the camera by DEG degrees"""
    title: str | None = None
    """the picture's title (default: model name and CRS)"""
    legend: Annotated[bool, Cli(negate="--no-legend")] = True
    """no legend of names and colours"""
    axes: Annotated[bool, Cli(negate="--no-axes")] = True
    """no axes with coordinates"""
    scale_bar: Annotated[bool, Cli(negate="--no-scale-bar")] = True
    """no scale bar"""
    size: Annotated[tuple[int, int], Cli(nargs=2, parse=int, metavar=("W", "H"))] = (1200, 900)
    """picture size in pixels"""
    edges: bool = False
    """draw triangle edges"""
    vertical_exaggeration: Annotated[float, Cli(metavar="F")] = 1.0
    """scale of z relative to x and y"""
    allow_empty: bool = False
    """accept a result with nothing in it (otherwise: a warning and exit 4)"""

    def png_options(self) -> dict[str, Any]:
        """The options of the ``png`` writer these flags give."""
        for name in ("clip", "section"):
            if (getattr(self, f"{name}_origin") is None) != (
                getattr(self, f"{name}_normal") is None
            ):
                raise OptionsError(f"--{name}-origin and --{name}-normal go together")
        return {
            "color_by": self.color_by or ("property" if self.property else "entity"),
            "property": self.property,
            "clip_origin": self.clip_origin,
            "clip_normal": self.clip_normal,
            "window_size": tuple(self.size),
            "show_edges": self.edges,
            "vertical_exaggeration": self.vertical_exaggeration,
            "section_origin": self.section_origin,
            "section_normal": self.section_normal,
            "view": self.view,
            "azimuth": self.azimuth,
            "elevation": self.elevation,
            "title": self.title,
            "legend": self.legend,
            "axes": self.axes,
            "scale_bar": self.scale_bar,
        }


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "render",
        description="Render a model to a PNG file without a display.",
    )
    add_arguments(parser, RenderCommand)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    return render(options_from_args(RenderCommand, args))


def render(command: RenderCommand) -> int:
    """Read the model and write its picture."""
    options = command.png_options()
    scene = read_input(command, command.scene, format=command.format)
    path = write(scene, command.output, format="png", **options)
    print(f"wrote {path}")
    return 0
