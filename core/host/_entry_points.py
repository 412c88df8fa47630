"""geobrep's entry points, found without :mod:`importlib.metadata`, and which ones are its own.

:func:`entry_points` answers ``importlib.metadata.entry_points(group=...)``, with the same
entry points in the same order, by the rules :mod:`importlib.metadata` follows for the
distributions it finds on ``sys.path``: each folder's ``*.dist-info`` and ``*.egg-info``
entries, grouped by normalised name in the folder's listing order, the first of each
normalised name on ``sys.path`` kept (a distribution installed twice: the first wins), and
each one's ``entry_points.txt`` read as :mod:`importlib.metadata` reads it. A distribution's
name and version come from the header lines of its ``METADATA`` (or ``PKG-INFO``), as the
:mod:`email` parser that :mod:`importlib.metadata` uses would give them.

The scan does not import :mod:`importlib.metadata` and :mod:`email` (about 25 ms of a
``geobrep --help``) and does not parse a whole ``METADATA`` file (geobrep's, with its long
description, costs the :mod:`email` parser about 10 ms). Wherever those rules might not
settle the answer, it asks :mod:`importlib.metadata` itself: another finder on
``sys.meta_path`` that finds distributions, an entry of ``sys.path`` that is no folder (a zip
file) or no string, an ``.egg`` folder, a metadata folder whose suffix is not in lower case or
whose name is empty, an ``entry_points.txt`` line that is neither a section nor a pair, a file
that is no UTF-8, a header block with a carriage return, a line it does not recognise, or a
``Name``/``Version`` that is missing or runs over several lines.
"""

from __future__ import annotations

import os
import re
import sys
from functools import reduce
from importlib import import_module
from typing import Any, Protocol, cast

__all__ = [
    "ENTRY_POINT_GROUP",
    "PROJECT_NAME",
    "Distribution",
    "EntryPoint",
    "EntryPointLike",
    "distribution",
    "entry_points",
    "is_builtin",
    "is_own",
]

PROJECT_NAME = "geobrep"
ENTRY_POINT_GROUP = "geobrep.plugins"


class EntryPointLike(Protocol):
    """What the loader uses of an entry point (this module's or :mod:`importlib.metadata`'s)."""

    @property
    def name(self) -> str: ...

    @property
    def value(self) -> str: ...

    @property
    def group(self) -> str: ...

    @property
    def module(self) -> str: ...

    def load(self) -> Any: ...


class _UnsettledError(Exception):
    """The fast scan cannot be sure it answers as :mod:`importlib.metadata` would."""


#: importlib.metadata's ``EntryPoint.pattern``: ``module[:attr][ [extras]]``.
_PATTERN = re.compile(r"(?P<module>[\w.]+)\s*(:\s*(?P<attr>[\w.]+)\s*)?((?P<extras>\[.*\])\s*)?$")
#: A header line the email parser reads as ``name: value`` (the name has no colon, space or
#: control character), and a continuation line.
_HEADER = re.compile(r"[\x21-\x39\x3b-\x7e]+:")
_METADATA_SUFFIXES = (".dist-info", ".egg-info")


def _match(value: str) -> re.Match[str]:
    """The value's parts; a value of another form is None, whose ``.group`` then raises the
    AttributeError that importlib.metadata's ``EntryPoint.module`` raises."""
    return cast("re.Match[str]", _PATTERN.match(value))


def _normalize(name: str) -> str:
    """importlib.metadata's ``Prepared.normalize`` (PEP 503, dashes as underscores)."""
    return re.sub(r"[-_.]+", "-", name).lower().replace("-", "_")


def _read_text(path: str, filename: str) -> str | None:
    """``PathDistribution.read_text``: the file's text, None if it cannot be opened."""
    target = os.path.join(path, filename) if filename else path
    try:
        with open(target, encoding="utf-8") as file:
            return file.read()
    except (FileNotFoundError, IsADirectoryError, NotADirectoryError, PermissionError):
        return None
    except UnicodeDecodeError as exc:
        raise _UnsettledError(f"{target} is no UTF-8") from exc


def _headers(text: str, fields: tuple[str, ...]) -> dict[str, str]:
    """The first value of each of ``fields`` (lower case) in the header block of ``text``,
    as ``email.message_from_string(text)[field]`` gives it (compat32 policy)."""
    block = text.split("\n\n", 1)[0]
    if "\r" in block:
        raise _UnsettledError("carriage return in the header block")
    lines = block.split("\n")
    if lines and lines[-1] == "" and block.endswith("\n"):
        lines.pop()  # the text ends with the block's last newline
    found: dict[str, str] = {}
    multi: set[str] = set()
    last: str | None = None
    for number, line in enumerate(lines):
        if line[:1] in (" ", "\t"):
            if number == 0:
                raise _UnsettledError("the first header line is a continuation")
            if last is not None:
                multi.add(last)
            continue
        if line.startswith("From ") or not _HEADER.match(line):
            raise _UnsettledError(f"header line {line!r}")
        name, value = line.split(":", 1)
        key = name.lower()
        last = None
        if key in fields and key not in found:
            found[key] = value.lstrip(" \t")
            last = key
    if multi or any(field not in found for field in fields):
        raise _UnsettledError("a field is missing or runs over several lines")
    return found


class Distribution:
    """A distribution found on ``sys.path``: its metadata folder, name and version."""

    __slots__ = ("_fields", "path")

    def __init__(self, path: str) -> None:
        self.path = path
        self._fields: dict[str, str | None] | None = None

    def __repr__(self) -> str:
        return f"Distribution({self.path!r})"

    @property
    def name(self) -> str | None:
        """The ``Name`` of its metadata (``importlib.metadata.Distribution.name``)."""
        return self._metadata()["name"]

    @property
    def version(self) -> str | None:
        """The ``Version`` of its metadata (``importlib.metadata.Distribution.version``)."""
        return self._metadata()["version"]

    def _metadata(self) -> dict[str, str | None]:
        if self._fields is None:
            try:
                text = (
                    _read_text(self.path, "METADATA")
                    or _read_text(self.path, "PKG-INFO")
                    or _read_text(self.path, "")
                )
                if not text:
                    raise _UnsettledError("no metadata text")
                fields: dict[str, str | None] = dict(_headers(text, ("name", "version")))
            except _UnsettledError:
                from importlib.metadata import PathDistribution
                from pathlib import Path

                dist = PathDistribution(Path(self.path))
                fields = {"name": dist.name, "version": dist.version}
            self._fields = fields
        return self._fields


class EntryPoint:
    """An entry point as ``importlib.metadata.EntryPoint`` has it: name, value, group, dist."""

    __slots__ = ("dist", "group", "name", "value")

    def __init__(self, name: str, value: str, group: str, dist: Distribution | None) -> None:
        self.name = name
        self.value = value
        self.group = group
        self.dist = dist

    def __repr__(self) -> str:
        return f"EntryPoint(name={self.name!r}, value={self.value!r}, group={self.group!r})"

    @property
    def module(self) -> str:
        """The module part of the value."""
        return _match(self.value).group("module")

    @property
    def attr(self) -> str | None:
        """The attribute part of the value (None: the module itself)."""
        return _match(self.value).group("attr")

    def load(self) -> Any:
        """Import the module and return the attribute named by the value (or the module)."""
        module = import_module(self.module)
        attrs = filter(None, (self.attr or "").split("."))
        return reduce(getattr, attrs, module)


def _entry_points_of(text: str | None, dist: Distribution) -> list[EntryPoint]:
    """importlib.metadata's ``EntryPoints._from_text_for``: ``[group]`` lines and
    ``name = value`` pairs, blank lines and ``#`` comments skipped."""
    found: list[EntryPoint] = []
    group: str | None = None
    for raw in (text or "").splitlines():
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        if line.startswith("[") and line.endswith("]"):
            group = line.strip("[]")
            continue
        if group is None:
            continue
        if "=" not in line:
            raise _UnsettledError(f"entry_points.txt line {line!r}")
        name, value = line.split("=", 1)
        found.append(EntryPoint(name.strip(), value.strip(), group, dist))
    return found


def _distributions() -> list[Distribution]:
    """The distributions ``importlib.metadata.distributions()`` finds on ``sys.path``, the
    first of each normalised name only (as ``entry_points()`` keeps them)."""
    import importlib.machinery

    finders = [f for f in sys.meta_path if getattr(f, "find_distributions", None) is not None]
    if finders != [importlib.machinery.PathFinder]:
        raise _UnsettledError("another finder finds distributions")
    seen: set[str] = set()
    kept: list[Distribution] = []
    for root in sys.path:
        if not isinstance(root, str):
            raise _UnsettledError("a sys.path entry is no string")
        try:
            children = os.listdir(root or ".")
        except FileNotFoundError:
            continue
        except OSError as exc:
            raise _UnsettledError(f"sys.path entry {root!r} is no folder") from exc
        if os.path.basename(root).lower().endswith(".egg"):
            raise _UnsettledError("an .egg folder on sys.path")
        by_name: dict[str, list[str]] = {}
        for child in children:
            low = child.lower()
            if not low.endswith(_METADATA_SUFFIXES):
                continue
            if not child.endswith(_METADATA_SUFFIXES):
                raise _UnsettledError(f"metadata suffix not in lower case: {child!r}")
            normalized = _normalize(low.rpartition(".")[0].partition("-")[0])
            if not normalized:
                raise _UnsettledError(f"metadata folder without a name: {child!r}")
            by_name.setdefault(normalized, []).append(child)
        for normalized, names in by_name.items():
            if normalized in seen:
                continue
            seen.add(normalized)
            kept.append(Distribution(os.path.join(root, names[0])))
    return kept


def _scan(group: str) -> list[EntryPoint]:
    found: list[EntryPoint] = []
    for dist in _distributions():
        for entry_point in _entry_points_of(_read_text(dist.path, "entry_points.txt"), dist):
            if entry_point.group == group:
                found.append(entry_point)
    return found


def entry_points(*, group: str) -> list[EntryPointLike]:
    """The entry points of ``group``, as ``importlib.metadata.entry_points(group=group)``."""
    try:
        return list(_scan(group))
    except _UnsettledError:
        from importlib.metadata import entry_points as metadata_entry_points

        return list(metadata_entry_points(group=group))


def is_builtin(entry_point: EntryPointLike) -> bool:
    """The entry point names a module of the ``geobrep`` package."""
    return entry_point.module == PROJECT_NAME or entry_point.module.startswith(PROJECT_NAME + ".")


def distribution(entry_point: EntryPointLike) -> tuple[str | None, str | None]:
    """The name and version of the distribution declaring ``entry_point`` (None, None: code)."""
    dist = getattr(entry_point, "dist", None)
    if dist is None:
        return None, None
    if isinstance(dist, Distribution):
        return dist.name, dist.version
    found = _NAMES.get(id(dist))
    if found is None or found[0] is not dist:
        # ``dist.name`` and ``dist.version`` each parse the METADATA file again: once per
        # distribution object (which all its entry points share) is enough
        found = _NAMES[id(dist)] = (dist, dist.name, dist.version)
    return found[1], found[2]


#: ``id(dist)`` -> an importlib.metadata distribution (kept, so its id is not reused), its
#: name and version.
_NAMES: dict[int, tuple[Any, str, str]] = {}


def is_own(entry_point: EntryPointLike) -> bool:
    """A built-in module declared by geobrep's own distribution (or by code, without one)."""
    return is_builtin(entry_point) and distribution(entry_point)[0] in (None, PROJECT_NAME)
