"""The built-in block builder: automatic block topology from conformal surfaces.

Registers the ``blocks`` builder (:class:`~geobrep.host.registry.BuilderSpec`), reached through
``geobrep.build_blocks(scene)`` and ``geobrep blocks IN... OUT``. The method follows An, Liu and
Wang (2012), "Automatic construction of topological relationship of 3D geological blocks based on
stratified geological structure", taken from a plain triangle soup to validated blocks; see
``docs/blocks.md``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from geobrep.plugins import hookimpl

if TYPE_CHECKING:
    from geobrep import Scene
    from geobrep.plugins import BuilderRegistry

__all__ = ["geobrep_register_builders"]


def _build_blocks(scene: Scene, options: Any) -> Scene:
    """The builder, imported on first use (not when the registries are filled)."""
    from geobrep.plugins.blocks._builder import build_blocks

    return build_blocks(scene, options)


@hookimpl
def geobrep_register_builders(registry: BuilderRegistry) -> None:
    from geobrep.plugins import BuilderSpec
    from geobrep.plugins.blocks.options import BlockBuilderOptions

    registry.add(
        BuilderSpec(
            name="blocks",
            description="Closed, oriented blocks and their topology from conformal surfaces",
            function=_build_blocks,
            input_types=("Surface",),
            options=BlockBuilderOptions,
        )
    )
