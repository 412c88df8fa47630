"""The geobrep exception hierarchy.

Every error geobrep raises on purpose derives from :class:`GeobrepError` and from the
builtin exception a caller would naturally catch, so ``except ValueError`` keeps working::

    GeobrepError
    ├── EntityValidationError (ValueError)    an entity field is malformed
    ├── TopologyError (ValueError)            corners/arcs/patches/blocks do not fit together
    ├── DegenerateGeometryError (ValueError)  zero normal, zero-area plane, ...
    ├── OptionsError (ValueError)             bad options for a plugin item
    ├── FormatError (ValueError)              a file cannot be parsed or written (path, line)
    │   └── UnknownFormatError                no registered format matches
    ├── EntityNotFoundError (KeyError)        no entity with that id or name
    ├── FileAccessError (OSError)             missing or unreadable file
    ├── PluginError (RuntimeError)            a plugin failed to load or register
    └── MissingDependencyError (ImportError)  an optional extra is not installed

Third-party exceptions are translated where geobrep calls into a library, with
``raise ... from exc`` so the original traceback stays available.
"""

from __future__ import annotations

import importlib
from os import PathLike
from pathlib import Path
from typing import Any

__all__ = [
    "DegenerateGeometryError",
    "EntityNotFoundError",
    "EntityValidationError",
    "FileAccessError",
    "FormatError",
    "GeobrepError",
    "MissingDependencyError",
    "OptionsError",
    "PluginError",
    "TopologyError",
    "UnknownFormatError",
    "import_optional",
]


class GeobrepError(Exception):
    """Root of every error geobrep raises on purpose."""


class EntityValidationError(GeobrepError, ValueError):
    """An entity was given a malformed field.

    ``entity`` names the entity (``"Surface 'top'"``), ``field`` the offending field.
    """

    def __init__(self, entity: str, field: str, reason: str) -> None:
        self.entity = entity
        self.field = field
        self.reason = reason
        super().__init__(f"{entity}: {field}: {reason}")


class EntityNotFoundError(GeobrepError, KeyError):
    """No entity (or several, for an ambiguous name) answers a lookup."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


class TopologyError(GeobrepError, ValueError):
    """Corners, arcs, patches and blocks are inconsistent, or a model is not conformal."""


class DegenerateGeometryError(GeobrepError, ValueError):
    """Geometry too degenerate for the operation (zero normal, empty mesh, ...)."""


class OptionsError(GeobrepError, ValueError):
    """Options given to a plugin item (format, clipper, fitter, builder) are invalid."""


class FormatError(GeobrepError, ValueError):
    """A file cannot be read or written. ``path`` and ``line`` locate the fault when known."""

    def __init__(
        self, message: str, path: str | PathLike[str] | None = None, line: int | None = None
    ) -> None:
        self.path = Path(path) if path is not None else None
        self.line = line
        self.message = message
        where = ""
        if self.path is not None:
            where = f"{self.path}:{line}: " if line is not None else f"{self.path}: "
        super().__init__(f"{where}{message}")


class UnknownFormatError(FormatError):
    """No registered format matches a file, or a requested format name is unknown."""


class FileAccessError(GeobrepError, OSError):
    """A file is missing, is a directory, or cannot be read or written."""

    def __init__(self, message: str, path: str | PathLike[str]) -> None:
        self.path = Path(path)
        super().__init__(f"{self.path}: {message}")

    def __str__(self) -> str:
        return str(self.args[0])


class PluginError(GeobrepError, RuntimeError):
    """A plugin failed to import or to register its items (raised in strict mode)."""


class MissingDependencyError(GeobrepError, ImportError):
    """An optional dependency is not installed; the message names the extra to install."""

    def __init__(self, package: str, extra: str, feature: str) -> None:
        self.package = package
        self.extra = extra
        super().__init__(
            f"{feature} needs the optional package '{package}': pip install 'geobrep[{extra}]'"
        )


def import_optional(package: str, extra: str, feature: str) -> Any:
    """The module ``package``, or :class:`MissingDependencyError`: ``feature`` needs ``extra``.

    >>> import_optional("json", "none", "reading JSON").dumps([1])
    '[1]'
    >>> import_optional("no_such_package", "gis", "map products")
    Traceback (most recent call last):
    ...
    geobrep.errors.MissingDependencyError: map products needs the optional package \
'no_such_package': pip install 'geobrep[gis]'
    """
    try:
        return importlib.import_module(package)
    except ImportError as exc:
        raise MissingDependencyError(package, extra, feature) from exc
