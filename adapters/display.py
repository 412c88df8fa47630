"""What viewers draw of a scene: every mesh entity, and every block as its closed boundary.

Shared by the glTF writer and the HTML viewer: a block has no mesh of its own, so it is shown
as :meth:`~geobrep.model.scene.Scene.block_mesh` (the universe, the outside, is not drawn).
Grids and wells (:func:`drawn_grids_and_wells`, the HTML viewer) are the outer boundary of
their active cells (:func:`~geobrep.adapters._grid_boundary.grid_boundary`) and the polyline of
their stations; the markers are the wells' own (:meth:`~geobrep.Well.marker_positions`).

>>> import geobrep
>>> scene = geobrep.datasets.faulted_layer_cake()
>>> [source.type for _, source in drawn_meshes(scene)].count("Block")
6
"""

from __future__ import annotations

from geobrep.adapters._grid_boundary import grid_boundary
from geobrep.model.entities import (
    Entity,
    PointSet,
    PolyLine,
    RegularGrid,
    StructuredGrid,
    Surface,
    Well,
)
from geobrep.model.scene import Scene

__all__ = ["drawn_grids_and_wells", "drawn_meshes"]


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


def drawn_grids_and_wells(scene: Scene, property: str | None = None) -> list[tuple[Entity, Entity]]:
    """``(geometry, source)`` pairs for the grids (the Surface of their boundary, carrying the
    property ``property`` where the grid has it) and the wells with two stations or more (the
    PolyLine through their stations), in scene order.

    >>> import geobrep
    >>> well = geobrep.Well(head=[0, 0, 0], vertices=[[0, 0, 0], [0, 0, -5]], md=[0, 5])
    >>> [(g.type, s.type) for g, s in drawn_grids_and_wells(geobrep.Scene(entities=[well]))]
    [('PolyLine', 'Well')]
    """
    pairs: list[tuple[Entity, Entity]] = []
    for entity in scene.entities:
        if isinstance(entity, RegularGrid | StructuredGrid):
            pairs.append((grid_boundary(entity, property), entity))
        elif isinstance(entity, Well) and entity.n_stations >= 2:
            stations = [range(entity.n_stations)]
            trace = PolyLine.from_parts(entity.vertices, stations, name=entity.name)
            pairs.append((trace, entity))
    return pairs
