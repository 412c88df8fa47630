"""The linear-octree voxelizer plugin (voxelizer ``voxelize``).

Registers one voxelizer, ``voxelize``: ``function(scene, options) -> LinearOctree``, the
octree of the scene's closed bodies (blocks or closed surfaces). Most callers use
:func:`geobrep.voxelize`. Heavy work is imported on first use.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from geobrep.plugins import VoxelizerSpec, hookimpl
from geobrep.plugins.voxelize.options import VoxelizeOptions

if TYPE_CHECKING:
    from geobrep import LinearOctree, Scene
    from geobrep.plugins import VoxelizerRegistry

__all__ = ["VoxelizeOptions", "geobrep_register_voxelizers"]


def _voxelize(scene: Scene, options: Any) -> LinearOctree:
    from geobrep.plugins.voxelize._builder import voxelize_scene

    octree: LinearOctree = voxelize_scene(scene, options).octrees[-1]
    return octree


@hookimpl
def geobrep_register_voxelizers(registry: VoxelizerRegistry) -> None:
    registry.add(
        VoxelizerSpec(
            name="voxelize",
            description="Linear octree (Morton codes) of closed bodies: depth buffers or exact",
            function=_voxelize,
            options=VoxelizeOptions,
        )
    )
