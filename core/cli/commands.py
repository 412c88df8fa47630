"""The commands of ``geobrep``, declared cheaply: name, module and one-line help.

``geobrep --help`` lists them from here without importing a command's module (no pydantic
model, no numpy, no plugin); :mod:`geobrep.cli.main` imports a command's module only when the
command is chosen. A command derived from an operation takes its help from the operation's
summary (:data:`geobrep.batch.catalog.SUMMARIES`, which the operation's declaration uses too).
"""

from __future__ import annotations

from dataclasses import dataclass

from geobrep.batch.catalog import SUMMARIES

__all__ = ["COMMANDS", "Command"]


@dataclass(frozen=True)
class Command:
    """A subcommand: its module ``geobrep.cli.<module>`` has ``add_parser(subparsers)``, or
    ``OPERATION`` (then ``operation`` names it here) and the parser is derived from it."""

    name: str
    module: str
    operation: str | None = None
    """the built-in operation the command is derived from"""
    text: str = ""
    """the one-line help of a command that is not an operation's"""
    dense_linear_algebra: bool = False
    """whether the command may solve large dense systems (it keeps OpenBLAS's threads; see
    :mod:`geobrep.cli._blas_threads`)"""

    @property
    def help(self) -> str:
        """The one-line help ``geobrep --help`` shows."""
        return SUMMARIES[self.operation] if self.operation is not None else self.text


_RUN = "run a pipeline file (read, clip, fit, build blocks, voxelize, write, ...)"

#: Every built-in command, in help order.
COMMANDS: tuple[Command, ...] = (
    Command("info", "info", text="describe a file"),
    Command("plugins", "plugins", text="list plugins and what they register"),
    Command(
        "demo", "demo", text="run the demo on the built-in sample model", dense_linear_algebra=True
    ),
    Command("convert", "convert", operation="convert"),
    Command("render", "render", operation="render"),
    Command("view", "view", operation="view"),
    Command("reproject", "reproject", operation="reproject"),
    Command("clip", "clip", operation="clip"),
    Command("section", "section", operation="section"),
    Command("blocks", "blocks", operation="build_blocks"),
    Command("voxelize", "voxelize", operation="voxelize"),
    Command("check", "check", operation="check"),
    Command("repair", "repair", operation="repair"),
    Command("fit", "fit", operation="fit", dense_linear_algebra=True),
    Command("map", "map", operation="map_products", dense_linear_algebra=True),
    Command("run", "run", text=_RUN, dense_linear_algebra=True),
    Command("clean", "clean", text="remove temporaries left by interrupted writes"),
)
