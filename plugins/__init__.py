"""Built-in geobrep plugins, and the facade plugin authors import from.

A plugin is a module (or object) with ``@hookimpl`` functions, declared as an entry point
in the ``geobrep.plugins`` group of its distribution's ``pyproject.toml``::

    [project.entry-points."geobrep.plugins"]
    example = "geobrep_example_plugin"

and implementing any of the hooks of :mod:`geobrep.hookspecs`::

    from geobrep.plugins import FormatSpec, hookimpl

    @hookimpl
    def geobrep_register_formats(registry):
        registry.add(FormatSpec(name="xyz", extensions=(".xyz",), reader=read_xyz))

The entry-point name (``example``) is the plugin's name in ``geobrep plugins`` and in
``GEOBREP_DISABLE_PLUGINS``. Built-in plugins are entry points of geobrep itself and load
first. See ``docs/plugin-guide.md``.

Importing this package is cheap (pluggy only); the registry types and the loader are
imported on first use.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from geobrep.hookspecs import hookimpl

if TYPE_CHECKING:
    from geobrep.host.loader import PluginInfo
    from geobrep.host.registry import (
        BuilderSpec,
        ClipperSpec,
        FitterSpec,
        FormatCapabilities,
        FormatSpec,
        Registries,
    )

__all__ = [
    "BuilderSpec",
    "ClipperSpec",
    "FitterSpec",
    "FormatCapabilities",
    "FormatSpec",
    "PluginInfo",
    "Registries",
    "hookimpl",
    "list_plugins",
    "register",
    "registries",
    "reload",
]

_LAZY = {
    "BuilderSpec": "geobrep.host.registry",
    "ClipperSpec": "geobrep.host.registry",
    "FitterSpec": "geobrep.host.registry",
    "FormatCapabilities": "geobrep.host.registry",
    "FormatSpec": "geobrep.host.registry",
    "Registries": "geobrep.host.registry",
    "PluginInfo": "geobrep.host.loader",
}


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'geobrep.plugins' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


def list_plugins() -> list[PluginInfo]:
    """Every discovered plugin with its status, distribution and registered items.

    Example:
        >>> [(p.name, p.status) for p in list_plugins()]  # doctest: +SKIP
        [('native', 'loaded'), ('example', 'loaded')]
    """
    from geobrep.host.loader import get_host

    return get_host().plugins


def registries() -> Registries:
    """The registries filled by all loaded plugins (discovering them on first use).

    Example:
        >>> registries().formats.choose_reader("points.xyz").name  # doctest: +SKIP
        'xyz'
    """
    from geobrep.host.loader import get_host

    return get_host().registries


def register(plugin: object, name: str) -> PluginInfo:
    """Register an in-process plugin (a module or object with ``@hookimpl`` functions).

    It is isolated like an installed plugin: a failure warns and returns status ``"failed"``.
    First registration of a name wins, so installed plugins keep theirs.

    Example:
        >>> class MyPlugin:
        ...     @hookimpl
        ...     def geobrep_register_fitters(self, registry):
        ...         registry.add(FitterSpec(name="mine", function=lambda entities, options: None))
        >>> register(MyPlugin(), "my-plugin").registered["fitters"]  # doctest: +SKIP
        ('mine',)
    """
    from geobrep.host.loader import register_plugin

    return register_plugin(plugin, name)


def reload() -> None:
    """Forget every plugin (in-process ones too) and rediscover the installed ones.

    Example:
        >>> reload()  # doctest: +SKIP
    """
    from geobrep.host.loader import get_host, reset

    reset()
    get_host()
