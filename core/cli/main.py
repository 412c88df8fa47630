"""Argument parsing and error handling shared by every subcommand.

The top-level parser lists every command from its declaration (:mod:`geobrep.cli.commands`)
and imports a command's module only when the command is chosen, so ``geobrep --help`` and
``geobrep info FILE`` load only what they use.
"""

from __future__ import annotations

import argparse
import atexit
import gc
import importlib
import os
import sys
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from geobrep.cli._blas_threads import one_blas_thread
from geobrep.cli._frame_stack import call_with_room
from geobrep.cli.commands import COMMANDS, Command
from geobrep.cli.common import EXIT_EMPTY, CliParser, EmptyResultError, WarningLines, add_verbosity
from geobrep.errors import GeobrepError

if TYPE_CHECKING:
    from geobrep.host.operations import OperationSpec

__all__ = ["COMMAND_MODULES", "build_parser", "main"]

EXIT_OK, EXIT_ERROR, EXIT_USAGE, EXIT_INTERNAL, EXIT_INTERRUPTED = 0, 1, 2, 70, 130

#: Subcommand modules of ``geobrep.cli``, in help order (:data:`~geobrep.cli.commands.COMMANDS`):
#: a command's module has ``add_parser(subparsers)``; an operation's has ``OPERATION`` (its
#: name), ``run(options, command)`` and optionally its command model (a class named
#: ``...Command``), ``DESCRIPTION`` and ``clip_options``-like ``OPTIONS_FOR``; its parser is
#: derived from the declarations.
COMMAND_MODULES = tuple(command.module for command in COMMANDS)

#: ``build(subparsers)`` adds a command's real parser.
Builder = Callable[[Any], None]


class LazySubParsers(argparse._SubParsersAction):  # type: ignore[type-arg]
    """Subcommands whose parsers are built when chosen: each starts as an empty placeholder
    with its one-line help (all ``geobrep --help`` needs) and a builder."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.builders: dict[str, Builder] = {}

    def add_lazy(self, name: str, help: str, build: Builder) -> None:
        """A command listed with ``help`` whose parser ``build(self)`` adds on first use."""
        self.add_parser(name, help=help)
        self.builders[name] = build

    def materialize(self, name: str) -> argparse.ArgumentParser:
        """The real parser of ``name`` (built now if it was not), in the placeholder's place."""
        build = self.builders.pop(name, None)
        if build is not None:
            parsers = self._name_parser_map  # also ``self.choices``: reordered in place
            order = list(parsers)
            del parsers[name]
            build(_Adding(self, name))
            for key in order:
                parsers[key] = parsers.pop(key)
            add_verbosity(parsers[name])
        parser: argparse.ArgumentParser = self._name_parser_map[name]
        return parser

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: Any,
        option_string: str | None = None,
    ) -> None:
        if values and values[0] in self._name_parser_map:
            self.materialize(values[0])
        super().__call__(parser, namespace, values, option_string)


class _Adding:
    """The subparsers action as a command's builder sees it: ``add_parser(name, ...)`` adds the
    real parser of ``name`` (its help is the placeholder's, already listed)."""

    def __init__(self, action: LazySubParsers, name: str) -> None:
        self.action, self.name = action, name

    def add_parser(self, name: str, **kwargs: Any) -> argparse.ArgumentParser:
        """The parser of the command being built (its one-line help: the declaration's)."""
        if name != self.name:
            raise ValueError(f"the builder of {self.name!r} added the command {name!r}")
        kwargs.pop("help", None)  # listed by the placeholder already
        parser: argparse.ArgumentParser = self.action.add_parser(name, **kwargs)
        return parser


def build_parser() -> argparse.ArgumentParser:
    """The top-level parser with every command's parser built (``main`` builds the chosen one)."""
    parser, commands = _lazy_parser()
    for name in list(commands.builders):
        commands.materialize(name)
    return parser


def _lazy_parser() -> tuple[argparse.ArgumentParser, LazySubParsers]:
    """The top-level parser; each command's own parser is built when the command is chosen."""
    from geobrep import __version__

    parser = CliParser(
        prog="geobrep",
        description="Typed B-Rep scene graph for 3D geological structural models.",
    )
    parser.add_argument("--version", action="version", version=f"geobrep {__version__}")
    add_verbosity(parser, top_level=True)
    subparsers = parser.add_subparsers(
        dest="command", metavar="COMMAND", required=True, action=LazySubParsers
    )
    assert isinstance(subparsers, LazySubParsers)
    for command in COMMANDS:
        subparsers.add_lazy(command.name, command.help, _module_builder(command))
    for spec in _plugin_operations():
        subparsers.add_lazy(str(spec.command_name), spec.summary, _plugin_builder(spec))
    return parser, subparsers


def _module_builder(command: Command) -> Builder:
    """The builder of a built-in command: its module's parser, or its operation's."""

    def build(subparsers: Any) -> None:
        module = importlib.import_module(f"geobrep.cli.{command.module}")
        if hasattr(module, "add_parser"):
            module.add_parser(subparsers)
            return
        from geobrep.batch.operations import operations
        from geobrep.cli.operation import SceneCommand, add_operation_parser

        add_operation_parser(
            subparsers,
            operations().get(module.OPERATION),
            module.run,
            command=getattr(module, "COMMAND", SceneCommand),
            description=getattr(module, "DESCRIPTION", None),
            options_for=getattr(module, "OPTIONS_FOR", None),
            extra=module.extra_options() if hasattr(module, "extra_options") else None,
        )

    return build


def _plugin_builder(spec: OperationSpec) -> Builder:
    """The builder of the command of a plugin's operation: read IN, apply, write OUT."""

    def build(subparsers: Any) -> None:
        from geobrep.cli.operation import add_operation_parser, run_scene_operation

        add_operation_parser(subparsers, spec, run_scene_operation(spec))

    return build


def _plugin_operations() -> list[OperationSpec]:
    """The operations of plugins that become commands (a name no command has yet).

    Plugins are loaded for them only when one may exist: geobrep's own plugins add none."""
    from geobrep.host import only_own_plugins

    if only_own_plugins():
        return []
    from geobrep.batch.operations import operations

    taken = {command.name for command in COMMANDS}
    found: list[OperationSpec] = []
    for spec in operations():
        name = spec.command_name
        if spec.builtin or name is None or name in taken:
            continue
        taken.add(name)
        found.append(spec)
    return found


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code (also used by the console script).

    Warnings raised meanwhile are printed as short ``warning:`` lines (see
    :class:`~geobrep.cli.common.WarningLines`), after the command's output and before its error.
    The command runs with room on the frame stack (:mod:`geobrep.cli._frame_stack`): however deep
    the caller, no loop of it maps and unmaps a frame chunk per call.
    """
    _freeze_heap_at_exit()
    if _one_blas_thread_suffices(sys.argv[1:] if argv is None else argv):
        one_blas_thread()
    return call_with_room(_main, argv)


def _one_blas_thread_suffices(argv: Sequence[str]) -> bool:
    """Whether the command line runs a built-in command that solves no large dense system (or
    none: help, version, a usage error). A plugin's command keeps OpenBLAS's threads."""
    word = _command_word(argv)
    if word is None:
        return True
    chosen = next((c for c in COMMANDS if c.name == word), None)
    return chosen is not None and not chosen.dense_linear_algebra


def _main(argv: Sequence[str] | None) -> int:
    with WarningLines() as lines:
        return _run(argv, lines)


#: The commands whose run reads or writes through the registries (every one of them loads the
#: plugin host); ``clean``, ``demo`` and ``run`` are left to load it when they do.
_HOST_COMMANDS = frozenset(
    command.name for command in COMMANDS if command.operation or command.name in ("info", "plugins")
)


def _uses_plugins(argv: Sequence[str]) -> bool:
    """Whether the command line runs a command that loads the plugin host anyway.

    The host is then loaded before the parser, which asks whether plugins add commands
    (:func:`geobrep.host.only_own_plugins`): the host answers from its plugins, where the
    question alone scans every installed distribution's entry points (~3.5 ms) and loading
    the host scans them again. A help request does not load it.
    """
    asks_help = any(word in ("-h", "--help") for word in argv)
    return _command_word(argv) in _HOST_COMMANDS and not asks_help


def _command_word(argv: Sequence[str]) -> str | None:
    """The first word of the command line that is no option: the command's name, if any."""
    return next((word for word in argv if not word.startswith("-")), None)


def _freeze_heap_at_exit() -> None:
    """Have the interpreter skip its last garbage collection when the process ends.

    That collection walks every object still alive (pydantic's schemas and validators, the
    modules' functions and types): ~35 ms of a ``geobrep info`` of a small file, for memory the
    process hands back anyway. :func:`gc.freeze`, run by :mod:`atexit` (so only when the
    interpreter exits, whoever called :func:`main`), moves them out of its reach. The other
    exit handlers still run, and the commands close the files they write themselves; only
    ``__del__`` of objects in reference cycles still alive at exit is not called, which
    Python does not promise either.
    """
    global _freezing
    if not _freezing:
        atexit.register(gc.freeze)
        _freezing = True


_freezing = False


def _run(argv: Sequence[str] | None, lines: WarningLines) -> int:
    try:  # the chosen command's parser may load the plugins (their operations are commands)
        if _uses_plugins(sys.argv[1:] if argv is None else argv):
            from geobrep.host.loader import get_host

            get_host()  # the command needs it: it also tells whether plugins add commands
        args = _lazy_parser()[0].parse_args(argv)
    except SystemExit as exc:  # argparse: --help/--version (0) or a usage error (2)
        return int(exc.code or 0)
    except GeobrepError as exc:
        lines.flush()
        print(f"geobrep: error: {exc}", file=sys.stderr)
        return EXIT_ERROR
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
            import traceback

            traceback.print_exc()
        print(
            f"geobrep: internal error: {type(exc).__name__}: {exc} "
            "(set GEOBREP_TRACEBACK=1 to see the traceback)",
            file=sys.stderr,
        )
        return EXIT_INTERNAL


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
