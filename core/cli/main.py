"""Argument parsing and error handling shared by every subcommand."""

from __future__ import annotations

import argparse
import importlib
import os
import sys
import traceback
from collections.abc import Sequence
from types import ModuleType
from typing import Any

from geobrep.cli.common import EXIT_EMPTY, CliParser, EmptyResultError, WarningLines, add_verbosity
from geobrep.errors import GeobrepError

__all__ = ["build_parser", "main"]

EXIT_OK, EXIT_ERROR, EXIT_USAGE, EXIT_INTERNAL, EXIT_INTERRUPTED = 0, 1, 2, 70, 130

#: Subcommand modules of ``geobrep.cli``, in help order: a command's module has
#: ``add_parser(subparsers)``; an operation's has ``OPERATION`` (its name), ``run(options,
#: command)`` and optionally its command model (a class named ``...Command``), ``DESCRIPTION``
#: and ``clip_options``-like ``OPTIONS_FOR``; its parser is derived from the declarations.
COMMAND_MODULES = (
    "info",
    "plugins",
    "demo",
    "convert",
    "render",
    "view",
    "reproject",
    "clip",
    "section",
    "blocks",
    "voxelize",
    "check",
    "repair",
    "fit",
    "run",
    "clean",
)


def _command_modules() -> list[ModuleType]:
    return [importlib.import_module(f"geobrep.cli.{name}") for name in COMMAND_MODULES]


def build_parser() -> argparse.ArgumentParser:
    """The top-level parser with one subparser per command module."""
    from geobrep import __version__

    parser = CliParser(
        prog="geobrep",
        description="Typed B-Rep scene graph for 3D geological structural models.",
    )
    parser.add_argument("--version", action="version", version=f"geobrep {__version__}")
    add_verbosity(parser, top_level=True)
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    _add_commands(subparsers)
    for subparser in {id(p): p for p in subparsers.choices.values()}.values():
        add_verbosity(subparser)
    return parser


def _add_commands(subparsers: Any) -> None:
    """Every command: the modules', then the operations of plugins that have none."""
    from geobrep.batch.operations import operations
    from geobrep.cli.operation import SceneCommand, add_operation_parser, run_scene_operation

    registry = operations()
    for module in _command_modules():
        if hasattr(module, "add_parser"):
            module.add_parser(subparsers)
            continue
        spec = registry.get(module.OPERATION)
        add_operation_parser(
            subparsers,
            spec,
            module.run,
            command=getattr(module, "COMMAND", SceneCommand),
            description=getattr(module, "DESCRIPTION", None),
            options_for=getattr(module, "OPTIONS_FOR", None),
            extra=module.extra_options() if hasattr(module, "extra_options") else None,
        )
    for spec in registry:
        name = spec.command_name
        if spec.builtin or name is None or name in subparsers.choices:
            continue
        add_operation_parser(subparsers, spec, run_scene_operation(spec))


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code (also used by the console script).

    Warnings raised meanwhile are printed as short ``warning:`` lines (see
    :class:`~geobrep.cli.common.WarningLines`), after the command's output and before its error.
    """
    with WarningLines() as lines:
        return _run(argv, lines)


def _run(argv: Sequence[str] | None, lines: WarningLines) -> int:
    try:
        parser = build_parser()  # loads the plugins: their operations are commands
    except GeobrepError as exc:
        lines.flush()
        print(f"geobrep: error: {exc}", file=sys.stderr)
        return EXIT_ERROR
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse: --help/--version (0) or a usage error (2)
        return int(exc.code or 0)
    lines.set_verbosity(args.verbosity)
    try:
        return int(args.run(args))
    except EmptyResultError as exc:
        lines.flush()
        for message in exc.messages:
            print(f"warning: {message}", file=sys.stderr)
        return EXIT_EMPTY
    except GeobrepError as exc:
        lines.flush()
        print(f"geobrep: error: {exc}", file=sys.stderr)
        return EXIT_ERROR
    except KeyboardInterrupt:
        print("geobrep: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        return EXIT_OK
    except Exception as exc:
        lines.flush()
        if os.environ.get("GEOBREP_TRACEBACK"):
            traceback.print_exc()
        print(
            f"geobrep: internal error: {type(exc).__name__}: {exc} "
            "(set GEOBREP_TRACEBACK=1 to see the traceback)",
            file=sys.stderr,
        )
        return EXIT_INTERNAL


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
