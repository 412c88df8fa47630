"""The geobrep plugin hooks (pluggy project name ``"geobrep"``).

Every hook receives one registry and adds items to it. A plugin implements any subset of
the hooks with the :data:`hookimpl` marker::

    from geobrep.plugins import FormatSpec, hookimpl

    @hookimpl
    def geobrep_register_formats(registry):
        registry.add(FormatSpec(name="xyz", extensions=(".xyz",), reader=read_xyz))

Compatibility promise: hook specs only grow. A hook may gain new optional arguments, never
lose or rename one, so an implementation written today keeps working (pluggy passes an
implementation only the arguments it names). This module must stay cheap to import: it
needs pluggy only, the registry types are for annotations.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import pluggy

if TYPE_CHECKING:
    from geobrep.host.operations import OperationRegistry
    from geobrep.host.registry import (
        BuilderRegistry,
        CheckRegistry,
        ClipperRegistry,
        FitterRegistry,
        FormatRegistry,
        VoxelizerRegistry,
    )

__all__ = ["PROJECT_NAME", "GeobrepSpecs", "hookimpl", "hookspec"]

PROJECT_NAME = "geobrep"

hookspec = pluggy.HookspecMarker(PROJECT_NAME)
"""Marks a hook specification (geobrep's own use)."""

hookimpl = pluggy.HookimplMarker(PROJECT_NAME)
"""Marks a plugin's hook implementation: ``@hookimpl def geobrep_register_formats(registry)``."""


class GeobrepSpecs:
    """The hook specifications; plugins implement them as plain functions or methods."""

    @hookspec
    def geobrep_register_formats(self, registry: FormatRegistry) -> None:
        """Register file formats: one :class:`~geobrep.host.registry.FormatSpec` per format.

        Example::

            @hookimpl
            def geobrep_register_formats(registry):
                registry.add(FormatSpec(
                    name="xyz", extensions=(".xyz",), reader=read_xyz, writer=write_xyz,
                    sniff=looks_like_xyz, options=XyzOptions,
                    capabilities=FormatCapabilities(entity_types=frozenset({"PointSet"})),
                ))
        """

    @hookspec
    def geobrep_register_clippers(self, registry: ClipperRegistry) -> None:
        """Register plane clippers: one :class:`~geobrep.plugins.ClipperSpec` per entity type.

        Example::

            @hookimpl
            def geobrep_register_clippers(registry):
                registry.add(ClipperSpec(
                    name="pointset", entity_type="PointSet", function=clip_pointset,
                ))
        """

    @hookspec
    def geobrep_register_fitters(self, registry: FitterRegistry) -> None:
        """Register surface or curve fitters: :class:`~geobrep.plugins.FitterSpec` items.

        Example::

            @hookimpl
            def geobrep_register_fitters(registry):
                registry.add(FitterSpec(
                    name="plane", function=fit_plane, input_types=("PointSet",),
                ))
        """

    @hookspec
    def geobrep_register_builders(self, registry: BuilderRegistry) -> None:
        """Register topology or block builders: :class:`~geobrep.plugins.BuilderSpec` items.

        Example::

            @hookimpl
            def geobrep_register_builders(registry):
                registry.add(BuilderSpec(
                    name="blocks", function=build_blocks, input_types=("Surface",),
                ))
        """

    @hookspec
    def geobrep_register_voxelizers(self, registry: VoxelizerRegistry) -> None:
        """Register voxelizers: :class:`~geobrep.plugins.VoxelizerSpec` items, each turning the
        closed bodies of a scene into a :class:`~geobrep.LinearOctree`.

        Example::

            @hookimpl
            def geobrep_register_voxelizers(registry):
                registry.add(VoxelizerSpec(
                    name="octree", function=voxelize_scene, options=VoxelizeOptions,
                ))
        """

    @hookspec
    def geobrep_register_checks(self, registry: CheckRegistry) -> None:
        """Register inspection criteria: :class:`~geobrep.plugins.CheckSpec` items, each finding
        one kind of defect for :func:`geobrep.inspect` and ``geobrep check``.

        Example::

            @hookimpl
            def geobrep_register_checks(registry):
                registry.add(CheckSpec(
                    name="mesh.long_edges", function=find_long_edges, options=LongEdgeOptions,
                ))
        """

    @hookspec
    def geobrep_register_operations(self, registry: OperationRegistry) -> None:
        """Register operations: :class:`~geobrep.plugins.OperationSpec` items, each a function of
        a Scene with an options model. Each gets a Python function, a ``geobrep`` subcommand, a
        pipeline step and a line in ``geobrep plugins``, all derived from the declaration.

        Example::

            @hookimpl
            def geobrep_register_operations(registry):
                registry.add(OperationSpec(
                    name="thin", summary="keep every n-th point", function=thin,
                    options=ThinOptions,
                ))
        """
