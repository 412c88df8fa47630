"""``geobrep reproject IN OUT --to EPSG:xxxx``: transform every entity into another CRS.

The options are those of the ``reproject`` operation
(:class:`~geobrep.batch.pipeline.ReprojectStep`); the parser is derived from it and
:class:`ReprojectCommand`.
"""

from __future__ import annotations

from typing import Annotated

from pydantic import BaseModel, ConfigDict

from geobrep.batch.pipeline import ReprojectStep
from geobrep.cli.common import format_name, read_input
from geobrep.host.operations import Cli

__all__ = ["COMMAND", "DESCRIPTION", "OPERATION", "ReprojectCommand", "run"]

OPERATION = "reproject"
DESCRIPTION = (
    "Reproject every entity of a file into another CRS with pyproj (3D when both CRSs "
    "have a vertical axis, otherwise horizontally with z converted between units). "
    "Properties, ids and topology are kept; a file without a CRS needs --from."
)


class ReprojectCommand(BaseModel):
    """The files of ``geobrep reproject``."""

    model_config = ConfigDict(extra="forbid", frozen=True, use_attribute_docstrings=True)

    input: Annotated[str, Cli(positional=True)]
    """file to read (any readable format)"""
    output: Annotated[str, Cli(positional=True)]
    """file to write (format from the extension or --to-format)"""
    format: Annotated[str | None, Cli(parse=format_name("read"))] = None
    """input format, when the extension is not enough"""
    to_format: Annotated[str | None, Cli(parse=format_name("write"))] = None
    """output format name"""
    allow_empty: bool = False
    """accept a result with nothing in it (otherwise: a warning and exit 4)"""


def run(options: ReprojectStep, args: ReprojectCommand) -> int:
    from geobrep.gis.crs_ops import to_crs
    from geobrep.ops.io import write

    scene = read_input(args, args.input, format=args.format)
    moved = to_crs(scene, options.to, source=options.source)
    write(moved, args.output, format=args.to_format)
    source = options.source or (scene.crs.label if scene.crs else "?")
    print(
        f"{args.output}: {len(moved.entities)} entities reprojected from {source} "
        f"to {moved.crs.label if moved.crs else options.to}"
    )
    return 0


COMMAND = ReprojectCommand
