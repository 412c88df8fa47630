"""Which entry points are geobrep's own: answered from the metadata, without loading a plugin."""

from __future__ import annotations

from importlib.metadata import Distribution, EntryPoint

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
    found = _NAMES.get(id(dist))
    if found is None or found[0] is not dist:
        # ``dist.name`` and ``dist.version`` each parse the METADATA file again: once per
        # distribution object (which all its entry points share) is enough
        found = _NAMES[id(dist)] = (dist, dist.name, dist.version)
    return found[1], found[2]


#: ``id(dist)`` -> the distribution (kept, so its id is not reused), its name and version.
_NAMES: dict[int, tuple[Distribution, str, str]] = {}


def is_own(entry_point: EntryPoint) -> bool:
    """A built-in module declared by geobrep's own distribution (or by code, without one)."""
    return is_builtin(entry_point) and distribution(entry_point)[0] in (None, PROJECT_NAME)
