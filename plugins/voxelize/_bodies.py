"""The closed bodies to voxelize: blocks of a scene (their boundary meshes) or closed surfaces."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from geobrep import Block, Entity, Scene, Surface
from geobrep.errors import DegenerateGeometryError, OptionsError, TopologyError
from geobrep.geometry import mesh
from geobrep.geometry.bbox import column_extremes

__all__ = ["Body", "OctreeCube", "collect_bodies", "octree_cube"]


@dataclass(frozen=True)
class Body:
    """One closed body: its label (entity id), name, triangles and where it came from."""

    label: int
    name: str
    vertices: NDArray[np.float64]
    triangles: NDArray[np.int64]
    source: str  # "block" or "surface"

    @property
    def mins(self) -> NDArray[np.float64]:
        return np.asarray(column_extremes(self.vertices)[0], dtype=np.float64)

    @property
    def maxs(self) -> NDArray[np.float64]:
        return np.asarray(column_extremes(self.vertices)[1], dtype=np.float64)


@dataclass(frozen=True)
class OctreeCube:
    """The octree's cube ``origin + [0, size]³``."""

    origin: NDArray[np.float64]
    size: float


def _closed_body(
    surface: Surface, label: int, name: str, source: str, checked: bool = False
) -> Body:
    """``checked``: the surface is known closed (its triangles need no second look)."""
    faces = surface.faces
    # A triangle surface's faces are read-only: the body shares them, no copy is made.
    triangles = faces if faces.shape[1] == 3 else mesh.triangulate(faces)[0]
    if triangles.shape[0] == 0:
        raise TopologyError(f"{surface.label} has no faces: nothing to voxelize")
    if not checked and not mesh.is_closed(triangles):
        open_edges = mesh.boundary_edges(triangles).shape[0]
        raise TopologyError(
            f"{surface.label} is not closed ({open_edges} boundary edges, or edges shared by "
            "more than two faces): only closed bodies can be voxelized"
        )
    return Body(label, name, surface.vertices, triangles.astype(np.int64, copy=False), source)


def _body_of(scene: Scene, entity: Entity) -> Body:
    label = int(entity.id or 0)
    if isinstance(entity, Block):
        if entity.is_universe:
            raise OptionsError(f"{entity.label} is the universe around the model, not a body")
        boundary = scene.block_mesh(entity)
        return _closed_body(boundary, label, entity.name or entity.label, "block")
    if isinstance(entity, Surface):
        return _closed_body(entity, label, entity.name or entity.label, "surface")
    raise OptionsError(f"{entity.label} is neither a Block nor a closed Surface")


def collect_bodies(scene: Scene, selection: tuple[str | int, ...] | None) -> list[Body]:
    """Bodies in scene order: the selected entities, else every block, else closed surfaces.

    Raises:
        EntityNotFoundError: a selected name or id does not exist.
        TopologyError: a selected surface (or a block's boundary) is not closed.
    """
    if selection is not None:
        if not selection:
            raise OptionsError("option 'bodies': name at least one block or surface")
        chosen = [scene[item] for item in selection]
        return [_body_of(scene, entity) for entity in chosen]
    if scene.blocks:
        return [_body_of(scene, block) for block in scene.blocks]
    closed = [s for s in scene.surfaces if s.n_faces and mesh.is_closed(s.faces)]
    if not closed:
        raise TopologyError(
            f"scene {scene.name!r} has no blocks and no closed surface: nothing to voxelize"
        )
    return [
        # triangles found closed above are not checked again (quads are: on their triangles)
        _closed_body(s, int(s.id or 0), s.name or s.label, "surface", s.faces.shape[1] == 3)
        for s in closed
    ]


def octree_cube(
    bodies: list[Body], origin: tuple[float, float, float] | None, size: float | None
) -> OctreeCube:
    """The given cube, or the bodies' bounding box grown to a cube from its minimum corner."""
    mins = np.min([b.mins for b in bodies], axis=0)
    maxs = np.max([b.maxs for b in bodies], axis=0)
    corner = mins if origin is None else np.asarray(origin, dtype=np.float64)
    if size is None:
        edge = float(np.max(maxs - corner))
        if not edge > 0:
            raise DegenerateGeometryError(
                "the bodies have no extent beyond the cube origin: give 'size' (and 'origin')"
            )
        size = edge
    return OctreeCube(corner, float(size))
