"""Built-in geobrep plugins, and the one surface plugin authors import from.

A plugin is a module (or object) with ``@hookimpl`` functions, declared as an entry point
in the ``geobrep.plugins`` group of its distribution's ``pyproject.toml``::

    [project.entry-points."geobrep.plugins"]
    example = "geobrep_example_plugin"

and implementing any of the hooks of :mod:`geobrep.hookspecs`::

    from geobrep.plugins import FormatSpec, hookimpl

    @hookimpl
    def geobrep_register_formats(registry):
        registry.add(FormatSpec(name="xyz", extensions=(".xyz",), reader=read_xyz))

Everything a plugin needs is importable from here: the :data:`hookimpl` marker, the spec and
registry types (``FormatSpec``, ``ClipperSpec``, ``FitterSpec``, ``BuilderSpec``,
``VoxelizerSpec``, ``CheckSpec``, ``OperationSpec`` and its ``Cli`` marker, ...) and the
Protocols their callables follow (``Reader``, ``Writer``, ``ClipFunction``, ``FitFunction``,
...), the clipping context (``ClipContext``, ``SceneDraft``, ``halves``, ``pack_halves``), the
fit result types (``FitResult``, ``FitReport``), ``atomic_write``, the topology helpers
(``chain_arc_edges``, ``build_corners_and_arcs``) and the errors. The model itself (``Scene``,
``Surface``, ``Plane``, ...) comes from :mod:`geobrep`, the kernels from :mod:`geobrep.geometry`.
The built-in plugins below use only these three.

The entry-point name (``example``) is the plugin's name in ``geobrep plugins`` and in
``GEOBREP_DISABLE_PLUGINS``. Built-in plugins are entry points of geobrep itself and load
first. See ``docs/plugin-guide.md``. Importing this package is cheap (pluggy only: no numpy,
no entity models); every other name is imported on first use.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from geobrep.hookspecs import hookimpl
from geobrep.host import list_plugins, register, registries, reload

if TYPE_CHECKING:
    from geobrep.errors import (
        DegenerateGeometryError,
        EntityNotFoundError,
        EntityValidationError,
        FileAccessError,
        FormatError,
        GeobrepError,
        MissingDependencyError,
        OptionsError,
        PluginError,
        TopologyError,
        UnknownFormatError,
    )
    from geobrep.host.loader import (
        PluginInfo,
    )
    from geobrep.host.operations import (
        Cli,
        OperationFunction,
        OperationRegistry,
        OperationSpec,
        comma_items,
        comma_numbers,
    )
    from geobrep.host.registry import (
        SNIFF_BYTES,
        BuilderRegistry,
        BuilderSpec,
        BuildFunction,
        CheckFunction,
        CheckRegistry,
        CheckSpec,
        ClipFunction,
        ClipperRegistry,
        ClipperSpec,
        FitFunction,
        FitterRegistry,
        FitterSpec,
        FormatCapabilities,
        FormatRegistry,
        FormatSpec,
        LossReporter,
        NoOptions,
        Reader,
        Registries,
        SectionFunction,
        Sniffer,
        VoxelizeFunction,
        VoxelizerRegistry,
        VoxelizerSpec,
        Writer,
    )
    from geobrep.model.arcs import (
        ArcChains,
        build_corners_and_arcs,
        chain_arc_edges,
    )
    from geobrep.model.entities import (
        UNIVERSE_KIND,
    )
    from geobrep.model.properties import (
        PropertyMap,
    )
    from geobrep.ops.clipping import (
        ClipContext,
        Keep,
        SceneDraft,
        halves,
        pack_halves,
    )
    from geobrep.ops.fitting import (
        Deviation,
        FitReport,
        FitResult,
        SubsetReport,
    )
    from geobrep.ops.inspection import (
        CheckContext,
        Defect,
    )
    from geobrep.ops.io import (
        atomic_write,
    )

__all__ = [
    "SNIFF_BYTES",
    "UNIVERSE_KIND",
    "ArcChains",
    "BuildFunction",
    "BuilderRegistry",
    "BuilderSpec",
    "CheckContext",
    "CheckFunction",
    "CheckRegistry",
    "CheckSpec",
    "Cli",
    "ClipContext",
    "ClipFunction",
    "ClipperRegistry",
    "ClipperSpec",
    "Defect",
    "DegenerateGeometryError",
    "Deviation",
    "EntityNotFoundError",
    "EntityValidationError",
    "FileAccessError",
    "FitFunction",
    "FitReport",
    "FitResult",
    "FitterRegistry",
    "FitterSpec",
    "FormatCapabilities",
    "FormatError",
    "FormatRegistry",
    "FormatSpec",
    "GeobrepError",
    "Keep",
    "LossReporter",
    "MissingDependencyError",
    "NoOptions",
    "OperationFunction",
    "OperationRegistry",
    "OperationSpec",
    "OptionsError",
    "PluginError",
    "PluginInfo",
    "PropertyMap",
    "Reader",
    "Registries",
    "SceneDraft",
    "SectionFunction",
    "Sniffer",
    "SubsetReport",
    "TopologyError",
    "UnknownFormatError",
    "VoxelizeFunction",
    "VoxelizerRegistry",
    "VoxelizerSpec",
    "Writer",
    "atomic_write",
    "build_corners_and_arcs",
    "chain_arc_edges",
    "comma_items",
    "comma_numbers",
    "halves",
    "hookimpl",
    "list_plugins",
    "pack_halves",
    "register",
    "registries",
    "reload",
]

#: Where each lazily imported name lives.
_LAZY = {
    "PluginInfo": "geobrep.host.loader",
    "Cli": "geobrep.host.operations",
    "OperationFunction": "geobrep.host.operations",
    "OperationRegistry": "geobrep.host.operations",
    "OperationSpec": "geobrep.host.operations",
    "comma_items": "geobrep.host.operations",
    "comma_numbers": "geobrep.host.operations",
    "SNIFF_BYTES": "geobrep.host.registry",
    "BuilderRegistry": "geobrep.host.registry",
    "BuilderSpec": "geobrep.host.registry",
    "ClipperRegistry": "geobrep.host.registry",
    "ClipperSpec": "geobrep.host.registry",
    "CheckRegistry": "geobrep.host.registry",
    "CheckSpec": "geobrep.host.registry",
    "CheckFunction": "geobrep.host.registry",
    "CheckContext": "geobrep.ops.inspection",
    "Defect": "geobrep.ops.inspection",
    "FitterRegistry": "geobrep.host.registry",
    "FitterSpec": "geobrep.host.registry",
    "FormatCapabilities": "geobrep.host.registry",
    "FormatRegistry": "geobrep.host.registry",
    "FormatSpec": "geobrep.host.registry",
    "NoOptions": "geobrep.host.registry",
    "Registries": "geobrep.host.registry",
    "VoxelizerRegistry": "geobrep.host.registry",
    "VoxelizerSpec": "geobrep.host.registry",
    "ClipContext": "geobrep.ops.clipping",
    "Keep": "geobrep.ops.clipping",
    "SceneDraft": "geobrep.ops.clipping",
    "halves": "geobrep.ops.clipping",
    "pack_halves": "geobrep.ops.clipping",
    "Deviation": "geobrep.ops.fitting",
    "FitReport": "geobrep.ops.fitting",
    "FitResult": "geobrep.ops.fitting",
    "SubsetReport": "geobrep.ops.fitting",
    "atomic_write": "geobrep.ops.io",
    "ArcChains": "geobrep.model.arcs",
    "build_corners_and_arcs": "geobrep.model.arcs",
    "chain_arc_edges": "geobrep.model.arcs",
    "UNIVERSE_KIND": "geobrep.model.entities",
    "PropertyMap": "geobrep.model.properties",
    "DegenerateGeometryError": "geobrep.errors",
    "EntityNotFoundError": "geobrep.errors",
    "EntityValidationError": "geobrep.errors",
    "FileAccessError": "geobrep.errors",
    "FormatError": "geobrep.errors",
    "GeobrepError": "geobrep.errors",
    "MissingDependencyError": "geobrep.errors",
    "OptionsError": "geobrep.errors",
    "PluginError": "geobrep.errors",
    "TopologyError": "geobrep.errors",
    "UnknownFormatError": "geobrep.errors",
    "BuildFunction": "geobrep.host.registry",
    "ClipFunction": "geobrep.host.registry",
    "FitFunction": "geobrep.host.registry",
    "LossReporter": "geobrep.host.registry",
    "Reader": "geobrep.host.registry",
    "SectionFunction": "geobrep.host.registry",
    "Sniffer": "geobrep.host.registry",
    "VoxelizeFunction": "geobrep.host.registry",
    "Writer": "geobrep.host.registry",
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
