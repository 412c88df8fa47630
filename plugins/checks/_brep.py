"""B-Rep topology checks: patches bounded by arcs, arcs between corners, patches with a block on
each side, blocks closed, outward and of positive volume, the universe closed, the volumes
adding up, and the sides a block lists (GOCAD REGION signs) agreeing with the geometry."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep import Block, Scene, Surface
from geobrep.errors import GeobrepError
from geobrep.geometry import mesh
from geobrep.geometry.orientation import orientation_flips
from geobrep.plugins import CheckContext, Defect
from geobrep.plugins.checks._common import label, mesh_entities, triangles, welded

__all__ = [
    "arc_ends",
    "block_closure",
    "block_orientation",
    "patch_boundaries",
    "patch_sides",
    "region_sides",
    "universe_closure",
    "volume_balance",
]

IntArray = NDArray[np.int64]


@dataclass(frozen=True)
class _Shell:
    """What one block's boundary says: open edges, volume, sides against the shell."""

    block: Block
    open_edges: IntArray
    vertices: NDArray[np.float64]
    volume: float
    conflicts: int
    against: tuple[int, ...]  # patch ids whose listed side runs against the rest
    error: str = ""


def _shell(scene: Scene, block: Block) -> _Shell:
    empty = np.zeros((0, 2), dtype=np.int64)
    try:
        shell = scene.block_mesh(block)
    except GeobrepError as exc:
        return _Shell(block, empty, np.zeros((0, 3)), 0.0, 0, (), str(exc))
    faces = np.asarray(shell.faces, dtype=np.int64)
    internal = block.internal_patches
    sides = [s for s in block.sides if s.patch not in internal]
    labels = np.asarray(shell.patch_labels, dtype=np.int64)
    result = orientation_flips(faces)
    areas = mesh.face_areas(shell.vertices, faces)
    flip = result.flip.copy()
    flipped_area = np.bincount(result.piece, weights=areas * flip, minlength=result.n_pieces)
    total_area = np.bincount(result.piece, weights=areas, minlength=result.n_pieces)
    flip ^= (flipped_area * 2 > total_area)[result.piece]
    turned = np.bincount(labels, weights=flip, minlength=len(sides))
    against = tuple(sides[int(k)].patch for k in np.flatnonzero(turned > 0))
    centre = shell.vertices.mean(axis=0)
    volume = mesh.signed_volume(shell.vertices - centre, faces)
    return _Shell(
        block, mesh.boundary_edges(faces), shell.vertices, volume, result.n_conflicts, against
    )


def _shells(scene: Scene, context: CheckContext) -> list[_Shell]:
    if "shells" not in context.cache:
        context.cache["shells"] = [
            _shell(scene, b)
            for b in scene.of_type(Block)
            if any(s.patch not in b.internal_patches for s in b.sides)
        ]
    shells: list[_Shell] = context.cache["shells"]
    return shells


def _block_defect(shell: _Shell, message: str, value: float | None = None) -> Defect:
    block = shell.block
    if shell.open_edges.size:
        where = shell.vertices[shell.open_edges[0]].mean(axis=0)
        points = tuple(tuple(p) for p in shell.vertices[shell.open_edges[0]].tolist())
    elif shell.vertices.size:
        where, points = shell.vertices.mean(axis=0), ()
    else:
        where, points = np.zeros(3), ()
    x, y, z = (float(c) for c in where)
    return Defect(
        entity=label(block),
        entity_id=block.id,
        element="block",
        ids=(int(block.id or 0),),
        location=(x, y, z),
        value=value,
        message=message,
        points=points or ((x, y, z),),
    )


def block_closure(scene: Scene, options: Any, context: CheckContext) -> list[Defect]:
    """Blocks whose boundary is not closed (edges used by one face only)."""
    return [
        _block_defect(s, "boundary not closed (value: open edges)", float(s.open_edges.shape[0]))
        for s in _shells(scene, context)
        if not s.block.is_universe and (s.open_edges.size or s.error)
    ]


def _free_borders(scene: Scene, context: CheckContext) -> tuple[IntArray, NDArray[np.float64]]:
    """Edges (welded vertices) used by one face of all the scene's surfaces together."""
    points, maps = welded(scene, context)
    position = {id(e): k for k, e in enumerate(mesh_entities(scene))}
    parts = [maps[position[id(s)]][triangles(s, context)[0]] for s in scene.surfaces]
    faces = np.concatenate(parts) if parts else np.zeros((0, 3), np.int64)
    return mesh.boundary_edges(faces) if faces.size else np.zeros((0, 2), np.int64), points


def universe_closure(scene: Scene, options: Any, context: CheckContext) -> list[Defect]:
    """The universe (the outside) must be closed: a model with a universe but no closed
    boundary (every patch inside it: the surfaces do not seal any block) is not sealed."""
    universes = [b for b in scene.of_type(Block) if b.is_universe]
    shells = [s for s in _shells(scene, context) if s.block.is_universe]
    if universes and not shells:
        edges, points = _free_borders(scene, context)
        where = points[edges[0]] if edges.size else np.zeros((1, 3))
        empty = np.zeros((0, 2), np.int64)
        shell = _Shell(universes[0], empty, where, 0.0, 0, ())
        return [
            _block_defect(
                shell,
                "the model is not sealed: no patch bounds the universe (value: free border "
                "edges of the surfaces)",
                float(edges.shape[0]),
            )
        ]
    return [
        _block_defect(
            s, "the universe is not closed (value: open edges)", float(s.open_edges.shape[0])
        )
        for s in shells
        if s.open_edges.size or s.error
    ]


def block_orientation(scene: Scene, options: Any, context: CheckContext) -> list[Defect]:
    """Closed blocks whose boundary, as listed, is not consistently oriented or does not enclose
    a positive volume (the universe: a negative one)."""
    found = []
    for s in _shells(scene, context):
        if s.open_edges.size or s.error:
            continue
        if s.conflicts:
            found.append(_block_defect(s, "boundary cannot be oriented", float(s.conflicts)))
        elif s.against:
            found.append(_block_defect(s, "boundary not consistently oriented", s.volume))
        elif (s.volume <= 0.0) != s.block.is_universe:
            found.append(_block_defect(s, "boundary not outward (value: volume)", s.volume))
    return found


def region_sides(scene: Scene, options: Any, context: CheckContext) -> list[Defect]:
    """Sides a block lists (GOCAD REGION signs) running against the rest of its boundary."""
    found = []
    for s in _shells(scene, context):
        for patch_id in s.against:
            patch = scene.topology.patch(patch_id)
            surface = scene.get(patch.surface)
            assert isinstance(surface, Surface)
            faces = surface.patch_faces(patch.label)
            where = surface.vertices[surface.faces[faces[:1]].reshape(-1)].mean(axis=0)
            x, y, z = (float(c) for c in where)
            found.append(
                Defect(
                    entity=label(s.block),
                    entity_id=s.block.id,
                    element="patch",
                    ids=(patch_id,),
                    location=(x, y, z),
                    other_entity=label(surface),
                    other_entity_id=surface.id,
                    other_ids=tuple(int(f) for f in faces[:1]),
                    message="the side listed runs against the rest of the block's boundary",
                    points=((x, y, z),),
                )
            )
    return found


def volume_balance(scene: Scene, options: Any, context: CheckContext) -> list[Defect]:
    """The blocks' volumes must add up to the universe's (closed, oriented blocks only)."""
    shells = [s for s in _shells(scene, context) if not s.open_edges.size and not s.error]
    universe = [s for s in shells if s.block.is_universe]
    units = [s for s in shells if not s.block.is_universe]
    if len(universe) != 1 or not units:
        return []
    total = sum(abs(s.volume) for s in units)
    outside = abs(universe[0].volume)
    if abs(total - outside) <= options.relative_tolerance * max(outside, total):
        return []
    return [
        _block_defect(
            universe[0],
            f"the blocks' volumes add up to {total:.9g}, the universe's is {outside:.9g} "
            "(value: the difference)",
            total - outside,
        )
    ]


def _patch_defect(scene: Scene, patch_id: int, message: str) -> Defect:
    patch = scene.topology.patch(patch_id)
    surface = scene.get(patch.surface)
    assert isinstance(surface, Surface)
    faces = surface.patch_faces(patch.label)
    where = (
        surface.vertices[surface.faces[faces[:1]].reshape(-1)].mean(axis=0)
        if faces.size
        else np.zeros(3)
    )
    x, y, z = (float(c) for c in where)
    return Defect(
        entity=label(surface),
        entity_id=surface.id,
        element="patch",
        ids=(patch_id,),
        location=(x, y, z),
        message=message,
        points=((x, y, z),),
    )


def patch_boundaries(scene: Scene, options: Any, context: CheckContext) -> list[Defect]:
    """Patches with a border (edges of one face) but no arcs bounding them."""
    if not scene.topology.arcs:
        return []
    found = []
    for patch in scene.topology.patches:
        if patch.arcs:
            continue
        surface = scene.get(patch.surface)
        if not isinstance(surface, Surface):
            continue
        faces = surface.faces[surface.patch_faces(patch.label)]
        if faces.shape[0] and mesh.boundary_edges(mesh.triangulate(faces)[0]).size:
            found.append(_patch_defect(scene, patch.id, "bordered patch without arcs"))
    return found


def arc_ends(scene: Scene, options: Any, context: CheckContext) -> list[Defect]:
    """Open arcs (first point not the last) that do not run between two corners."""
    found = []
    for arc in scene.topology.arcs:
        closed = bool(np.array_equal(arc.points[0], arc.points[-1]))
        if closed or (arc.start is not None and arc.end is not None):
            continue
        x, y, z = (float(c) for c in arc.points[0])
        found.append(
            Defect(
                entity=f"arc {arc.id}",
                element="arc",
                ids=(arc.id,),
                location=(x, y, z),
                message="open arc missing a corner at an end",
                points=tuple(tuple(p) for p in arc.points[[0, -1]].tolist()),
            )
        )
    return found


def patch_sides(scene: Scene, options: Any, context: CheckContext) -> list[Defect]:
    """In a model with blocks, every patch has a block (or the universe) on each side."""
    if not scene.blocks:
        return []
    return [
        _patch_defect(
            scene,
            p.id,
            "no block on its " + ("positive" if p.positive_block is None else "negative") + " side",
        )
        for p in scene.topology.patches
        if p.positive_block is None or p.negative_block is None
    ]
