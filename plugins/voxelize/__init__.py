"""The linear-octree voxelizer plugin (builder ``voxelize``).

Registers one builder, ``voxelize``: ``function(scene, options) -> Scene`` appends the
:class:`~geobrep.LinearOctree` of the scene's closed bodies (blocks or closed surfaces) to the
scene. Most callers use :func:`geobrep.voxelize`. Heavy work is imported on first use.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from geobrep.plugins import BuilderSpec, hookimpl
from geobrep.plugins.voxelize.options import VoxelizeOptions

if TYPE_CHECKING:
    from geobrep.host.registry import BuilderRegistry
    from geobrep.model.scene import Scene

__all__ = ["VoxelizeOptions", "geobrep_register_builders"]


def _voxelize(scene: Scene, options: Any) -> Scene:
    from geobrep.plugins.voxelize.builder import voxelize_scene

    return voxelize_scene(scene, options)


@hookimpl
def geobrep_register_builders(registry: BuilderRegistry) -> None:
    registry.add(
        BuilderSpec(
            name="voxelize",
            description="Linear octree (Morton codes) of closed bodies: depth buffers or exact",
            function=_voxelize,
            input_types=("Block", "Surface"),
            options=VoxelizeOptions,
        )
    )
