"""``geobrep view MODEL -o model.html``: the model in one offline HTML page (three.js inlined).

The page lists the blocks and surfaces with their names and colours, each switchable, has a
clipping plane and axes labelled in world coordinates, and needs no server: open it from disk.
Writing goes through the registered ``html`` format. The parser is derived from the ``view``
operation (:class:`~geobrep.batch.pipeline.ViewStep`: ``--title``, ``--no-blocks``,
``--all-surfaces``) and :class:`ViewCommand` (the files).
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

from pydantic import BaseModel, ConfigDict

from geobrep.batch.operations import as_written
from geobrep.batch.pipeline import ViewStep
from geobrep.cli.common import format_name, read_input
from geobrep.host.operations import Cli
from geobrep.ops.io import write

__all__ = ["COMMAND", "OPERATION", "ViewCommand", "run"]

OPERATION = "view"


class ViewCommand(BaseModel):
    """The files of ``geobrep view``."""

    model_config = ConfigDict(extra="forbid", frozen=True, use_attribute_docstrings=True)

    scene: Annotated[str, Cli(positional=True)]
    """model file (any readable format)"""
    output: Annotated[str | None, Cli(flags=("-o", "--output"))] = None
    """page to write (default: MODEL's name with .html, here)"""
    format: Annotated[str | None, Cli(parse=format_name("read"))] = None
    """input format, when the extension is not enough"""
    allow_empty: bool = False
    """accept a result with nothing in it (otherwise: a warning and exit 4)"""


def run(step: ViewStep, command: ViewCommand) -> int:
    scene = read_input(command, command.scene, format=command.format)
    output = command.output or Path(command.scene).with_suffix(".html").name
    path = write(as_written(scene, step), output, format="html", **step.writer_options())
    print(f"wrote {path}")
    return 0


COMMAND = ViewCommand
