"""Subcommands derived from operation declarations: the parser from the options models.

A subcommand of an operation has two models: the operation's options (the pipeline step's
body; :class:`~geobrep.host.operations.OperationSpec`) and the command's own (its files and
what only the command line has, such as ``--json``), :class:`SceneCommand` by default. Both
become argparse arguments (:func:`~geobrep.host.operations.add_arguments`); the command's
``run(options, command)`` receives both validated. An operation a plugin registers gets
:func:`run_scene_operation`: read ``IN``, apply the operation, write ``OUT``.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict

from geobrep.cli.common import format_name, is_empty, read_input, refuse_empty
from geobrep.host.operations import Cli, OperationSpec, add_arguments, options_from_args

__all__ = ["Run", "SceneCommand", "add_operation_parser", "run_scene_operation"]

OptionsFor = Callable[[Any, dict[str, Any]], Any]
"""``options_for(command, values) -> options``: when the command picks the operation's options."""
Run = Callable[[Any, Any], int]
"""``run(options, command) -> exit code``: the operation's options and the command's."""


class SceneCommand(BaseModel):
    """The files of a command that reads one model and writes one."""

    model_config = ConfigDict(extra="forbid", frozen=True, use_attribute_docstrings=True)

    input: Annotated[str, Cli(positional=True, metavar="IN")]
    """model to read (any readable format)"""
    output: Annotated[str, Cli(positional=True, metavar="OUT")]
    """file to write (its extension picks the format)"""
    format: Annotated[str | None, Cli(parse=format_name("read"))] = None
    """input format, when the extension is not enough"""
    output_format: Annotated[str | None, Cli(parse=format_name("write"))] = None
    """output format name"""
    allow_empty: bool = False
    """accept a result with nothing in it (otherwise: a warning and exit 4)"""

    def operation_data(self) -> dict[str, Any]:
        """Options of the operation this command's own options give (a shortcut's plane)."""
        return {}


def add_operation_parser(
    subparsers: Any,
    spec: OperationSpec,
    run: Run,
    command: type[BaseModel] = SceneCommand,
    description: str | None = None,
    options_for: OptionsFor | None = None,
    extra: type[BaseModel] | None = None,
) -> argparse.ArgumentParser:
    """The subcommand of ``spec``: its arguments from ``command`` and ``spec.options`` (and
    ``extra``, the options model of the plugin item the operation runs by default)."""
    parser: argparse.ArgumentParser = subparsers.add_parser(
        spec.command_name,
        help=spec.summary,
        description=description or spec.description or spec.summary,
    )
    add_arguments(parser, command)
    add_arguments(parser, spec.options, skip=command.model_fields)
    if extra is not None:  # the options of the plugin item the operation runs (a builder's)
        add_arguments(parser, extra, skip=[*command.model_fields, *spec.options.model_fields])

    def call(args: argparse.Namespace) -> int:
        given = options_from_args(command, args)
        values = {k: v for k, v in vars(args).items() if k not in command.model_fields}
        if options_for is not None:
            return run(options_for(given, values), given)
        data: dict[str, Any] = getattr(given, "operation_data", dict)()
        return run(options_from_args(spec.options, {**values, **data}), given)

    parser.set_defaults(run=call)
    return parser


def run_scene_operation(spec: OperationSpec) -> Run:
    """The command of an operation without its own: read ``IN``, apply, write ``OUT``."""

    def run(options: Any, command: SceneCommand) -> int:
        from geobrep.ops.io import write

        scene = read_input(command, command.input, format=command.format)
        result = spec.function(scene, options)
        if is_empty(result):
            refuse_empty(
                command, [f"{command.output}: {spec.name} left nothing"], "no file written"
            )
        path = write(result, command.output, format=command.output_format)
        print(f"{path}: {len(result.entities)} entities ({spec.name})")
        return 0

    return run
