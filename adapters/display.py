"""What viewers draw of a scene: every mesh entity, and every block as its closed boundary.

Shared by the glTF writer and the HTML viewer: a block has no mesh of its own, so it is shown
as :meth:`~geobrep.model.scene.Scene.block_mesh` (the universe, the outside, is not drawn).

>>> import geobrep
>>> scene = geobrep.datasets.faulted_layer_cake()
>>> [source.type for _, source in drawn_meshes(scene)].count("Block")
6
"""

from __future__ import annotations

from geobrep.model.entities import Entity, PointSet, PolyLine, Surface
from geobrep.model.scene import Scene

__all__ = ["drawn_meshes"]


def drawn_meshes(scene: Scene, blocks: bool = True) -> list[tuple[Entity, Entity]]:
    """``(geometry, source)`` pairs: every mesh entity (``geometry is source``), then every
    block's boundary surface (``source`` is the block)."""
    pairs: list[tuple[Entity, Entity]] = [
        (e, e) for e in scene.entities if isinstance(e, Surface | PolyLine | PointSet)
    ]
    if blocks:
        # block meshes cache bounds on the entities: work on copies, not the caller's scene
        copies = scene.replace(entities=[e.model_copy() for e in scene.entities])
        for block in copies.blocks:
            if block is not copies.universe and block.sides:
                pairs.append((copies.block_mesh(block), block))
    return pairs
