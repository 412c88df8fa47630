"""Which entry points are geobrep's own: answered from the metadata, without loading a plugin."""

from __future__ import annotations

from importlib.metadata import EntryPoint

__all__ = ["ENTRY_POINT_GROUP", "PROJECT_NAME", "distribution", "is_builtin", "is_own"]

PROJECT_NAME = "geobrep"
ENTRY_POINT_GROUP = "geobrep.plugins"


def is_builtin(entry_point: EntryPoint) -> bool:
    """The entry point names a module of the ``geobrep`` package."""
    return entry_point.module == PROJECT_NAME or entry_point.module.startswith(PROJECT_NAME + ".")


def distribution(entry_point: EntryPoint) -> tuple[str | None, str | None]:
    """The name and version of the distribution declaring ``entry_point`` (None, None: code)."""
    dist = getattr(entry_point, "dist", None)
    if dist is None:
        return None, None
    return dist.name, dist.version


def is_own(entry_point: EntryPoint) -> bool:
    """A built-in module declared by geobrep's own distribution (or by code, without one)."""
    return is_builtin(entry_point) and distribution(entry_point)[0] in (None, PROJECT_NAME)
