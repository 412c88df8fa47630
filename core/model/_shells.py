"""The boundary shells of many blocks at once, for :mod:`geobrep.model.orientation`.

:meth:`Scene.block_mesh` builds one block's shell and joins its coincident vertices; orienting
every block of a model that way merges the same vertices once per block. Here the vertices of
all the surfaces are joined once (the same tolerance) and each patch's triangles are gathered
once: each shell is then a few slices of them.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import NamedTuple

import numpy as np

from geobrep.geometry import mesh
from geobrep.geometry.arrays import FloatArray, IntArray
from geobrep.model.entities import Block, Surface
from geobrep.model.scene import RELATIVE_MERGE_TOLERANCE, Scene

__all__ = ["Shell", "block_shells"]


class Shell(NamedTuple):
    """A block's boundary: its vertices, triangles and the boundary side of each triangle."""

    vertices: FloatArray
    faces: IntArray
    patch_labels: IntArray


def _patch_triangles(scene: Scene, blocks: list[Block]) -> tuple[FloatArray, dict[int, IntArray]]:
    """All the surfaces' vertices (joined) and each listed patch's triangles in their ids."""
    surfaces: dict[int, Surface] = {}
    for block in blocks:
        for side in block.sides:
            patch = scene.topology.patch(side.patch)
            if patch.surface not in surfaces:
                surface = scene.get(patch.surface)
                assert isinstance(surface, Surface)  # checked at construction
                surfaces[patch.surface] = surface
    offsets: dict[int, int] = {}
    total = 0
    for surface_id, surface in surfaces.items():
        offsets[surface_id] = total
        total += surface.n_vertices
    by_patch: dict[tuple[int, int], IntArray] = {}
    for surface_id, surface in surfaces.items():
        triangles, source = mesh.triangulate(surface.faces)
        labels = (
            np.zeros(source.shape[0], dtype=np.int64)
            if surface.patch_labels is None
            else np.asarray(surface.patch_labels, dtype=np.int64)[source]
        )
        order = np.argsort(labels, kind="stable")
        bounds = np.searchsorted(labels[order], np.arange(surface.n_patches + 1))
        shifted = triangles.astype(np.int64)[order] + offsets[surface_id]
        for label in range(surface.n_patches):
            by_patch[(surface_id, label)] = shifted[bounds[label] : bounds[label + 1]]
    vertices = np.concatenate([s.vertices for s in surfaces.values()] or [np.zeros((0, 3))])
    gathered = [by_patch[key] for key in by_patch]
    used, _ = mesh.compact_indices(
        np.concatenate(gathered) if gathered else np.zeros((0, 3), np.int64), total
    )
    box = scene.bounds
    tolerance = RELATIVE_MERGE_TOLERANCE * (box.diagonal if box else 1.0)
    points, inverse = mesh.merge_close_vertices(vertices[used], tolerance)
    renumber = np.full(total, -1, dtype=np.int64)
    renumber[used] = inverse
    triangles_of = {
        patch.id: renumber[by_patch[(patch.surface, patch.label)]]
        for patch in scene.topology.patches
        if (patch.surface, patch.label) in by_patch
    }
    return points, triangles_of


def block_shells(scene: Scene, blocks: list[Block]) -> Iterator[Shell]:
    """The boundary of each of ``blocks`` as :meth:`Scene.block_mesh` builds it (faces flipped
    where the block is on a patch's positive side, patches listed with both sides left out,
    triangles the joining collapses dropped, one patch label per boundary side), in order."""
    points, triangles_of = _patch_triangles(scene, blocks)
    n = int(points.shape[0])
    for block in blocks:
        internal = block.internal_patches
        pieces: list[IntArray] = []
        labels: list[IntArray] = []
        for patch_id, side in block.sides:
            if patch_id in internal:
                continue
            triangles = triangles_of[patch_id]
            pieces.append(mesh.flip_faces(triangles) if side == 1 else triangles)
            labels.append(np.full(triangles.shape[0], len(labels), dtype=np.int64))
        faces = np.concatenate(pieces)
        a, b, c = faces.T
        keep = (a != b) & (b != c) & (a != c)
        used, compact = mesh.compact_indices(faces[keep], n)
        yield Shell(points[used], compact, np.concatenate(labels)[keep])
