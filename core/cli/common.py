"""What every subcommand shares: its parser, warning lines, format names and empty results.

* :class:`CliParser` names an unknown option (``unknown option '--xx' (did you mean '--x'?)``)
  with the usage of the command it was given to, instead of argparse's later, vaguer errors.
* :class:`WarningLines` turns the Python warnings raised while a command runs (GOCAD quirks,
  plugin problems, ...) into short ``warning:`` lines on stderr, one per kind with a count;
  ``-q`` hides them, ``-v`` shows each.
* :func:`format_name` is the ``type=`` of options that name a format (``unknown format 'vtuu'
  (known: ...; did you mean 'vtu'?)``).
* :class:`ProgressLines` writes a line per step of long work (a file, a check) on stderr when
  stderr is a terminal or once the work has run :data:`LONG_WORK_SECONDS`; stdout stays clean.
* :func:`read_input` and :func:`refuse_empty` make a result with nothing in it a ``warning:``
  line and exit status :data:`EXIT_EMPTY`, unless ``--allow-empty``.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
import time
import warnings
from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from types import TracebackType
from typing import TYPE_CHECKING, Any, Literal, NoReturn, TextIO

if TYPE_CHECKING:
    from geobrep.model.entities import Entity
    from geobrep.model.scene import Scene

__all__ = [
    "EXIT_EMPTY",
    "LONG_WORK_SECONDS",
    "CliParser",
    "CommandWarning",
    "EmptyResultError",
    "ProgressLines",
    "WarningLines",
    "add_allow_empty",
    "add_verbosity",
    "format_name",
    "is_empty",
    "progress_mode",
    "read_input",
    "recorded_warnings",
    "refuse_empty",
    "warn",
]

#: Exit status of a command whose result holds nothing (without ``--allow-empty``).
EXIT_EMPTY = 4

#: Work running longer than this (seconds) reports its progress even when stderr is no terminal.
LONG_WORK_SECONDS = 2.0

_NUMBER_LIKE = re.compile(r"-(?=[^a-zA-Z]*\d)[\d.,eE+\-]+")


# -- parsing ------------------------------------------------------------------------------------
class CliParser(argparse.ArgumentParser):
    """An argument parser that names an unknown option at once, with a close match.

    argparse keeps unknown options for the end: a required option then fails first (``--xx``
    gave "one of the arguments --plane --x ... is required") and a subcommand's leftovers are
    reported with the top-level usage. Here an unknown option (or a leftover argument) is an
    error of the parser that was given it, with its own usage. ``add_subparsers`` makes its
    subparsers of this class too.
    """

    def parse_known_args(  # type: ignore[override]
        self, args: Sequence[str] | None = None, namespace: argparse.Namespace | None = None
    ) -> tuple[argparse.Namespace, list[str]]:
        strings = self._join_negative_values(list(sys.argv[1:] if args is None else args))
        self._reject_unknown_options(strings)
        parsed, extras = super().parse_known_args(strings, namespace)
        if extras and self._subparsers is None:
            self.error(f"unrecognized arguments: {' '.join(extras)}")
        return parsed, extras

    def error(self, message: str) -> NoReturn:
        super().error(_with_choice_hint(message))

    def _join_negative_values(self, strings: list[str]) -> list[str]:
        """``--x -1e9`` as ``--x=-1e9``: argparse takes ``-1e9`` or ``-1,0,0,5`` for an option."""
        joined: list[str] = []
        index = 0
        while index < len(strings):
            arg = strings[index]
            action = self._option_string_actions.get(arg)
            following = strings[index + 1] if index + 1 < len(strings) else ""
            if action is not None and action.nargs is None and _NUMBER_LIKE.fullmatch(following):
                joined.append(f"{arg}={following}")
                index += 2
                continue
            if arg == "--":
                joined.extend(strings[index:])
                break
            joined.append(arg)
            index += 1
        return joined

    def _option_strings(self) -> list[str]:
        return list(self._option_string_actions)

    def _is_known(self, arg: str) -> bool:
        options = self._option_string_actions
        if arg in options or arg.split("=", 1)[0] in options:
            return True
        if arg[1] not in self.prefix_chars:  # -j4, -qv: a short option and its value or friends
            return arg[:2] in options
        if self.allow_abbrev:
            name = arg.split("=", 1)[0]
            return any(option.startswith(name) for option in options)
        return False

    def _reject_unknown_options(self, strings: Sequence[str]) -> None:
        for arg in strings:
            if arg == "--":
                return
            if len(arg) < 2 or arg[0] not in self.prefix_chars or " " in arg:
                if self._subparsers is not None:
                    return  # the command name: the rest belongs to its own parser
                continue
            if _NUMBER_LIKE.fullmatch(arg) or self._is_known(arg):
                continue
            name = arg.split("=", 1)[0]
            close = _close_matches(name, self._option_strings(), n=1, cutoff=0.6)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            self.error(f"unknown option {name!r}{hint}")


def _with_choice_hint(message: str) -> str:
    """argparse's "invalid choice: 'x' (choose from 'a', 'b')" with the closest choice named."""
    found = re.search(r"invalid choice: '([^']*)' \(choose from (.*)\)$", message)
    if not found:
        return message
    choices = re.findall(r"'([^']*)'", found.group(2))
    close = _close_matches(found.group(1), choices, n=1, cutoff=0.6)
    return f"{message}; did you mean {close[0]!r}?" if close else message


def add_verbosity(parser: argparse.ArgumentParser, top_level: bool = False) -> None:
    """``-q``/``--quiet`` and ``-v``/``--verbose``, accepted before or after the command."""
    default = 1 if top_level else argparse.SUPPRESS  # a subcommand must not reset the top's
    group = parser.add_mutually_exclusive_group()
    group.add_argument(
        "-q",
        "--quiet",
        dest="verbosity",
        action="store_const",
        const=0,
        default=default,
        help="no warning lines (errors are still printed)",
    )
    group.add_argument(
        "-v",
        "--verbose",
        dest="verbosity",
        action="store_const",
        const=2,
        default=default,
        help="every warning on its own line instead of one line per kind",
    )


def add_allow_empty(parser: argparse.ArgumentParser) -> None:
    """``--allow-empty``: a result with nothing in it is written and is not a failure."""
    parser.add_argument(
        "--allow-empty",
        action="store_true",
        default=False,
        help=f"accept a result with nothing in it (otherwise: a warning and exit {EXIT_EMPTY})",
    )


def format_name(action: Literal["read", "write"]) -> Callable[[str], str]:
    """The ``type=`` of an option naming a format (a registered name, or an extension)."""

    def check(text: str) -> str:
        from geobrep.host import registries

        formats = registries().formats
        able = [s for s in formats if (s.can_read if action == "read" else s.can_write)]
        names = [spec.name for spec in able]
        extensions = sorted({ext.lstrip(".") for spec in able for ext in spec.extensions})
        value = text.lstrip(".") if text.lstrip(".") in extensions else text
        if value in names or value in extensions:
            return value
        if text in formats:
            raise argparse.ArgumentTypeError(f"format {text!r} cannot {action} files")
        close = _close_matches(text, [*names, *extensions], n=1, cutoff=0.6)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise argparse.ArgumentTypeError(
            f"unknown format {text!r} (known: {', '.join(names)}{hint})"
        )

    check.__name__ = "format"
    return check


# -- warnings -----------------------------------------------------------------------------------
class CommandWarning(UserWarning):
    """A warning of the command line itself (an empty result that was allowed, ...)."""


def warn(message: str) -> None:
    """Report ``message`` as a ``warning:`` line (grouped, hidden by ``-q``)."""
    warnings.warn(message, CommandWarning, stacklevel=2)


def _kind(message: str) -> str:
    """The message with names and numbers blanked: warnings of one kind share it."""
    text = re.sub(r"'[^']*'|\"[^\"]*\"", "'…'", message)
    return re.sub(r"\d+(?:\.\d+)?(?:[eE][+-]?\d+)?", "#", text)


class WarningLines:
    """Collect the warnings raised while a command runs; print them as ``warning:`` lines.

    Warnings of the same category whose messages differ only in names and numbers are one kind:
    the first is printed with the count of the others. ``verbosity`` 0 prints nothing, 2 prints
    every warning as it comes. A warning raised in a worker process (forked from this one) is
    printed there at once, since it cannot be counted here.

    >>> import io
    >>> stream = io.StringIO()
    >>> with WarningLines(stream) as lines:
    ...     for name in ("a", "b", "c"):
    ...         warnings.warn(f"surface {name!r}: faces reordered")
    >>> print(stream.getvalue(), end="")
    warning: surface 'a': faces reordered (and 2 more like it; -v shows each)
    """

    def __init__(self, stream: TextIO | None = None, verbosity: int = 1) -> None:
        self.stream = stream
        self.verbosity = verbosity
        self.messages: list[warnings.WarningMessage] = []
        self._printed = 0
        self._pid = os.getpid()
        self._context = warnings.catch_warnings()

    def __enter__(self) -> WarningLines:
        self._context.__enter__()
        warnings.filterwarnings("always", category=UserWarning)  # count each, not once
        warnings.showwarning = self._show
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        value: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self._context.__exit__(kind, value, traceback)
        self.flush()

    def set_verbosity(self, verbosity: int) -> None:
        """Known once the arguments are parsed; ``-v`` then prints what came before."""
        self.verbosity = verbosity
        if verbosity >= 2:
            self._print_each()

    def _out(self) -> TextIO:
        return self.stream if self.stream is not None else sys.stderr

    def _show(
        self,
        message: Warning | str,
        category: type[Warning],
        filename: str,
        lineno: int,
        file: TextIO | None = None,
        line: str | None = None,
    ) -> None:
        if os.getpid() != self._pid:  # a forked worker: nobody will count it here
            if self.verbosity > 0:
                print(f"warning: {message}", file=self._out(), flush=True)
            return
        self.messages.append(warnings.WarningMessage(message, category, filename, lineno))
        if self.verbosity >= 2:
            self._print_each()

    def _print_each(self) -> None:
        for caught in self.messages[self._printed :]:
            print(f"warning: {caught.message}", file=self._out())
        self._printed = len(self.messages)

    def flush(self) -> None:
        """Print what was not printed yet: every warning (``-v``) or one line per kind."""
        if self.verbosity <= 0:
            self._printed = len(self.messages)
            return
        if self.verbosity >= 2:
            self._print_each()
            return
        for first, count in self.grouped(self.messages[self._printed :]):
            more = f" (and {count - 1} more like it; -v shows each)" if count > 1 else ""
            print(f"warning: {first}{more}", file=self._out())
        self._printed = len(self.messages)

    @staticmethod
    def grouped(messages: Iterable[warnings.WarningMessage]) -> list[tuple[str, int]]:
        """``(first message, count)`` per kind, in the order each kind first came."""
        kinds: dict[tuple[type[Warning], str], list[Any]] = {}
        for caught in messages:
            text = str(caught.message)
            entry = kinds.setdefault((caught.category, _kind(text)), [text, 0])
            entry[1] += 1
        return [(str(text), int(count)) for text, count in kinds.values()]


@contextmanager
def recorded_warnings() -> Iterator[list[warnings.WarningMessage]]:
    """The warnings raised inside, as a list, also passed on to the command's warning lines."""
    caught: list[warnings.WarningMessage] = []
    try:
        with warnings.catch_warnings(record=True) as inner:
            warnings.filterwarnings("always", category=UserWarning)
            try:
                yield caught
            finally:
                caught.extend(inner)
    finally:
        for item in caught:
            warnings.showwarning(item.message, item.category, item.filename, item.lineno)


# -- empty results ------------------------------------------------------------------------------
class EmptyResultError(Exception):
    """A command's result holds nothing; ``messages`` say which and why."""

    def __init__(self, messages: Sequence[str]) -> None:
        self.messages = list(messages)
        super().__init__("; ".join(self.messages))


def is_empty(data: Scene | Entity | Iterable[Entity] | None) -> bool:
    """True when nothing in ``data`` has geometry (no entity, or only empty ones) and it holds no
    stratigraphic column (:attr:`~geobrep.Scene.holds_nothing`)."""
    from geobrep.model.entities import Entity
    from geobrep.model.scene import Scene

    if data is None:
        return True
    if isinstance(data, Entity):
        return data.bounds is None
    scene = data if isinstance(data, Scene) else Scene(entities=list(data))
    return scene.holds_nothing


def refuse_empty(
    args: argparse.Namespace | Any, messages: Sequence[str], consequence: str | None = None
) -> None:
    """Each message (one empty result) is a warning; without ``--allow-empty`` a failure.

    Raises :class:`EmptyResultError` (the command line prints the messages, ending each with
    ``consequence``, e.g. ``"not written"``, and exits with :data:`EXIT_EMPTY`).
    """
    if not messages:
        return
    if getattr(args, "allow_empty", False):
        for message in messages:
            warn(message)
        return
    tail = f"; {consequence}" if consequence else ""
    raise EmptyResultError([f"{message}{tail} (--allow-empty accepts it)" for message in messages])


def read_input(
    args: argparse.Namespace | Any,
    path: str | Path,
    format: str | None = None,
    *,
    repair: bool = True,
) -> Scene:
    """Read a command's input; a file with nothing in it is refused (:func:`refuse_empty`).

    ``repair=False`` keeps the model as the file holds it (no on-read repairs)."""
    from geobrep.ops.io import read

    scene = read(path, format=format, repair=repair)
    if is_empty(scene):
        what = f"{len(scene.entities)} entities, none with geometry" if scene.entities else "none"
        refuse_empty(args, [f"{path}: nothing read (entities: {what})"])
    return scene


# -- progress -----------------------------------------------------------------------------------


class ProgressLines:
    """Progress of a command, one line per step on stderr (``geobrep check: a.ml check 3/23
    gaps 0.41 s``). ``mode``: ``"auto"`` (on a terminal, or once the work has run
    ``long_after`` seconds), ``"always"`` (``--progress``) or ``"never"`` (``--no-progress``)."""

    def __init__(
        self,
        command: str,
        mode: Literal["auto", "always", "never"] = "auto",
        long_after: float | None = None,
        stream: TextIO | None = None,
    ) -> None:
        self.command = command
        self.mode = mode
        self.long_after = LONG_WORK_SECONDS if long_after is None else long_after
        self.stream = sys.stderr if stream is None else stream
        self.started = time.perf_counter()

    @property
    def active(self) -> bool:
        if self.mode != "auto":
            return self.mode == "always"
        if time.perf_counter() - self.started >= self.long_after:
            return True
        isatty = getattr(self.stream, "isatty", None)
        return bool(isatty is not None and isatty())

    def line(self, text: str) -> None:
        """Write ``geobrep COMMAND: text`` when progress is shown."""
        if self.active:
            self.stream.write(f"geobrep {self.command}: {text}\n")
            self.stream.flush()

    def step(self, subject: str, kind: str = "step") -> Callable[[str, int, int, float], None]:
        """A ``progress(step, done, total, seconds)`` callback writing lines about ``subject``
        (``a.ml check 3/23 gaps 0.41 s``)."""

        def report(step: str, done: int, total: int, seconds: float) -> None:
            self.line(f"{subject} {kind} {done}/{total} {step} {seconds:.2f} s")

        return report


def progress_mode(progress: bool, no_progress: bool) -> Literal["auto", "always", "never"]:
    """The :class:`ProgressLines` mode of ``--progress`` / ``--no-progress`` (the latter wins)."""
    if no_progress:
        return "never"
    return "always" if progress else "auto"


def _close_matches(word: str, possibilities: Iterable[str], n: int, cutoff: float) -> list[str]:
    """:func:`difflib.get_close_matches`, its module imported only for a mistyped word."""
    import difflib

    return difflib.get_close_matches(word, possibilities, n=n, cutoff=cutoff)
