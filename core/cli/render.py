"""``geobrep render SCENE out.png``: a picture of a model, off-screen (no display needed).

Colour by entity, block or property, optionally cutting away the side of a plane its normal
points to or drawing a section; a legend, axes in world coordinates, a scale bar and the CRS in
the title. Rendering goes through the registered ``png`` format (pyvista, extra ``viz``). The
flags are derived from the ``render`` operation (:class:`~geobrep.batch.pipeline.RenderStep`,
also a pipeline step) and the files of :class:`RenderCommand`.
"""

from __future__ import annotations

from typing import Annotated, Any

from geobrep.batch.operations import as_written
from geobrep.batch.pipeline import RenderStep
from geobrep.cli.common import format_name, read_input
from geobrep.host.operations import Cli
from geobrep.ops.io import write

__all__ = ["COMMAND", "OPERATION", "RenderCommand", "render", "run"]

OPERATION = "render"


class RenderCommand(RenderStep):
    """The files and options of ``geobrep render``: the ``render`` step's options and the files."""

    scene: Annotated[str, Cli(positional=True)]
    """model file (any readable format)"""
    output: Annotated[str, Cli(positional=True)]
    """picture to write (.png)"""
    format: Annotated[str | None, Cli(parse=format_name("read"))] = None
    """input format, when the extension is not enough"""
    allow_empty: bool = False
    """accept a result with nothing in it (otherwise: a warning and exit 4)"""

    def operation_data(self) -> dict[str, Any]:
        """The options of the ``render`` operation these flags give."""
        return {name: getattr(self, name) for name in RenderStep.model_fields}

    def png_options(self) -> dict[str, Any]:
        """The options of the ``png`` writer these flags give."""
        return self.writer_options()


def run(step: RenderStep, command: RenderCommand) -> int:
    return render(command, step)


def render(command: RenderCommand, step: RenderStep | None = None) -> int:
    """Read the model and write its picture."""
    step = step if step is not None else RenderStep(**command.operation_data())
    options = step.writer_options()
    scene = read_input(command, command.scene, format=command.format)
    path = write(as_written(scene, step), command.output, format="png", **options)
    print(f"wrote {path}")
    return 0


COMMAND = RenderCommand
