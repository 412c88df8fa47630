"""Argument parsing and error handling shared by every subcommand."""

from __future__ import annotations

import argparse
import importlib
import os
import sys
import traceback
from collections.abc import Sequence
from types import ModuleType

from geobrep.errors import GeobrepError

__all__ = ["build_parser", "main"]

EXIT_OK, EXIT_ERROR, EXIT_USAGE, EXIT_INTERNAL, EXIT_INTERRUPTED = 0, 1, 2, 70, 130

#: Subcommand modules of ``geobrep.cli``, each with ``add_parser(subparsers)``, in help order.
COMMAND_MODULES = (
    "info",
    "plugins",
    "demo",
    "convert",
    "render",
    "reproject",
    "clip",
    "section",
    "blocks",
    "voxelize",
    "fit",
    "run",
)


def _command_modules() -> list[ModuleType]:
    return [importlib.import_module(f"geobrep.cli.{name}") for name in COMMAND_MODULES]


def build_parser() -> argparse.ArgumentParser:
    """The top-level parser with one subparser per command module."""
    from geobrep import __version__

    parser = argparse.ArgumentParser(
        prog="geobrep",
        description="Typed B-Rep scene graph for 3D geological structural models.",
    )
    parser.add_argument("--version", action="version", version=f"geobrep {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for command in _command_modules():
        command.add_parser(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code (also used by the console script)."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse: --help/--version (0) or a usage error (2)
        return int(exc.code or 0)
    try:
        return int(args.run(args))
    except GeobrepError as exc:
        print(f"geobrep: error: {exc}", file=sys.stderr)
        return EXIT_ERROR
    except KeyboardInterrupt:
        print("geobrep: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        return EXIT_OK
    except Exception as exc:
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
