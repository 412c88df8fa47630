"""The Block clipper: closing each cut block of a scene with a cap, and block sections.

A block is bounded by sides of patches. Its boundary edges along the cut are the on-plane edges
of its patches' faces on the kept side, oriented out of the block (a patch is flipped when the
block lies on its positive side); faces lying in the plane count when the block is on their kept
side. Opposite edges cancel; the rest, merged across surfaces within the clip's tolerance, form the
loops that the cap fills (:mod:`.caps`). The cap's triangles face out of the block; the facade
(:mod:`geobrep.ops._clip_topology`) turns it into a patch between the block and the universe.
Caps are always triangulated as seen from the plane's positive side, so a block cut into two
gets the same cap triangles in both halves (reversed), and its two parts' volumes add up to
the block's.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from geobrep import Block, Polygon, Scene, Surface
from geobrep.errors import TopologyError
from geobrep.geometry import Plane, boxes_plane_side, mesh
from geobrep.geometry.arrays import FloatArray, IntArray
from geobrep.plugins import ClipContext, Keep, halves, pack_halves
from geobrep.plugins.clip._caps import cap_rings, cap_triangles, open_boundary
from geobrep.plugins.clip._surfaces import surface_cut
from geobrep.plugins.clip.options import ClipOptions, tolerance_of

__all__ = ["block_cut_edges", "clip_block", "section_block"]


def clip_block(
    block: Block, plane: Plane, keep: Keep, options: ClipOptions, context: ClipContext
) -> Any:
    """Clipper of :class:`Block` entities: within a scene only (the block needs its patches)."""
    scene = _scene_of(block, context)
    tolerance = tolerance_of(options, context)
    ident = int(block.id or 0)
    parts: dict[int, Block | None] = {}
    for side in halves(keep):
        draft = context.drafts.get(side)
        if draft is None:
            raise TopologyError(f"{block.label}: the clip of its scene has no half {side:+d}")
        present = any(
            (p.positive_block == ident) != (p.negative_block == ident)
            for p in draft.patches.values()
        )
        if not present:
            parts[side] = None
            continue
        points, edges = block_cut_edges(scene, block, plane, side, tolerance, context, True)
        boundary = open_boundary(edges, points.shape[0])
        oriented = boundary if side < 0 else boundary[:, ::-1]
        cap = cap_triangles(points, oriented, plane.normal, f"{block.label} cap")
        if cap.shape[0]:
            if side > 0:
                cap = cap[:, [0, 2, 1]]
            used, local = np.unique(cap, return_inverse=True)
            draft.add_cap(
                ident, Surface(vertices=points[used], faces=local.reshape(-1, 3), name="cap")
            )
        parts[side] = block
    return pack_halves(keep, parts)


def section_block(
    block: Block, plane: Plane, options: ClipOptions, context: ClipContext
) -> Polygon | None:
    """The section of a block by the plane: its polygons with holes, carrying the block's id.

    A face of the block lying in the plane belongs to the section when the block lies on the
    face's negative side (below it, for the plane's normal pointing up).
    """
    scene = _scene_of(block, context)
    points, edges = block_cut_edges(
        scene, block, plane, -1, tolerance_of(options, context), context, False
    )
    boundary = open_boundary(edges, points.shape[0])
    polygons = cap_rings(points, boundary, plane.normal, f"{block.label} section")
    if not polygons:
        return None
    return Polygon.from_polygons(
        [(points[rings[0]], [points[h] for h in rings[1:]]) for rings in polygons],
        name=block.name,
        kind="section",
        metadata={
            **block.metadata,
            "block": int(block.id or 0),
            "unit_name": block.unit_name,
        },
    )


def _scene_of(block: Block, context: ClipContext) -> Scene:
    if context.scene is None:
        raise TopologyError(
            f"{block.label}: a Block is clipped with its scene (its patches live there)"
        )
    return context.scene


def block_cut_edges(
    scene: Scene,
    block: Block,
    plane: Plane,
    side: int,
    tolerance: float,
    context: ClipContext,
    lying_faces: bool,
) -> tuple[FloatArray, IntArray]:
    """Points on the plane and the directed edges (out of the block) of its kept boundary there.

    ``lying_faces`` counts the block's faces lying in the plane on the side their outward normal
    points away from (as the cut keeps them); without it they are left out (a section).
    """
    internal = block.internal_patches
    chunks: list[FloatArray] = []
    for patch_id, patch_side in block.sides:
        if patch_id in internal:
            continue
        patch = scene.topology.patch(patch_id)
        surface = scene.get(patch.surface)
        if not isinstance(surface, Surface) or surface.n_faces == 0:
            continue
        bounds = surface.bounds
        if (
            bounds is not None
            and boxes_plane_side(bounds.mins[None, :], bounds.maxs[None, :], plane, tolerance)[0]
        ):
            continue  # the plane misses this surface
        state = surface_cut(surface, plane, tolerance, context)
        half = state.half(side, "both")
        faces = half.plane_edge_faces
        if faces.shape[0] == 0:
            continue
        labels = state.labels(half)
        mine = (
            np.ones(faces.shape[0], dtype=np.bool_)
            if labels is None
            else (labels[faces] == patch.label)
        )
        first_lying = half.in_plane_faces[0] if half.in_plane_faces.shape[0] else -1
        lying = (
            (faces >= first_lying) & (faces < first_lying + half.in_plane_faces.shape[0])
            if first_lying >= 0
            else np.zeros(faces.shape[0], dtype=np.bool_)
        )
        if lying.any():
            tri = half.faces[faces[lying]]
            normals = mesh.face_normals(half.vertices, tri) @ plane.normal
            # Outward normal of the block: the patch normal, reversed on the patch's + side.
            outward = -normals if patch_side == 1 else normals
            keep_lying = (outward * side < 0) if lying_faces else np.zeros(tri.shape[0], bool)
            mine[np.flatnonzero(lying)] &= keep_lying
        edges = half.plane_edges[mine]
        if patch_side == 1:
            edges = edges[:, ::-1]
        chunks.append(half.vertices[edges].reshape(-1, 3))
    if not chunks:
        return np.zeros((0, 3)), np.zeros((0, 2), dtype=np.int64)
    coordinates = np.concatenate(chunks)
    merged, inverse = mesh.merge_close_vertices(coordinates, tolerance)
    # Number the points in lexicographic order: the same loops give the same caps on both sides.
    order = np.lexsort((merged[:, 2], merged[:, 1], merged[:, 0]))
    rank = np.empty_like(order)
    rank[order] = np.arange(order.shape[0])
    edges = rank[inverse].reshape(-1, 2)
    edges = edges[edges[:, 0] != edges[:, 1]]
    return merged[order], edges
