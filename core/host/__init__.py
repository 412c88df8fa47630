"""The plugin host: hook specifications, the registries plugins fill, and the plugin loader.

Core finds formats, clippers, fitters, builders and voxelizers here (:func:`registries`);
plugin authors import the same functions and types from :mod:`geobrep.plugins`. Importing this
package is cheap: the loader (pluggy, entry points, pydantic) is imported on first use.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from geobrep.host.loader import PluginInfo
    from geobrep.host.registry import Registries

__all__ = ["list_plugins", "only_own_plugins", "register", "registries", "reload"]


def registries() -> Registries:
    """The registries filled by all loaded plugins (discovering them on first use).

    Example:
        >>> registries().formats.choose_reader("model.ml").name
        'gocad'
    """
    from geobrep.host.loader import get_host

    return get_host().registries


def list_plugins() -> list[PluginInfo]:
    """Every discovered plugin with its status, distribution and registered items.

    Example:
        >>> ("gocad", "loaded") in [(p.name, p.status) for p in list_plugins()]
        True
    """
    from geobrep.host.loader import get_host

    return get_host().plugins


def register(plugin: object, name: str) -> PluginInfo:
    """Register an in-process plugin (a module or object with ``@hookimpl`` functions).

    It is isolated like an installed plugin: a failure warns and returns status ``"failed"``.
    First registration of a name wins, so installed plugins keep theirs.

    Example:
        >>> from geobrep.plugins import FitterSpec, hookimpl
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


def only_own_plugins() -> bool:
    """True when every plugin is one of geobrep's own, found without loading any plugin.

    The plugins registered in this process are asked when they were loaded, else the installed
    entry points (their metadata only). The command line lists its commands without loading
    plugins when this holds: geobrep's own plugins add no command.
    """
    import sys

    from geobrep.host._entry_points import ENTRY_POINT_GROUP, entry_points, is_own

    loader = sys.modules.get("geobrep.host.loader")
    host = getattr(loader, "_host", None) if loader is not None else None
    if host is not None:
        return all(info.builtin for info in host.plugins)
    return all(is_own(entry_point) for entry_point in entry_points(group=ENTRY_POINT_GROUP))
