"""Dangling patches (the paper's 悬挂面片) and free borders.

An arc's **weight** (重度) is the number of patch occurrences around it; an arc of weight 1 is a
**free border**: the patch using it stops there without meeting anything. The paper removes every
patch with a free border before sorting. geobrep's default keeps such a patch when it ends inside
a block — a fault dying out in a layer is an internal surface, with the block on both of its
sides — and removes only patches that bound nothing (see :mod:`.universe`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geobrep.geometry.arrays import IntArray
from geobrep.plugins.blocks._arcs import ArcChains
from geobrep.plugins.blocks._csr import group_sums
from geobrep.plugins.blocks._patches import PatchSplit
from geobrep.plugins.blocks._soup import Soup

__all__ = ["DanglingPatch", "describe_dangling", "free_border_arcs", "free_border_patches"]


@dataclass(frozen=True)
class DanglingPatch:
    """A removed patch: where it was and why."""

    surface: str
    surface_id: int | None
    triangles: int
    reason: str
    centroid: tuple[float, float, float]


def arc_weights(split: PatchSplit, chains: ArcChains) -> IntArray:
    """Number of triangles (patch occurrences) around each arc, from its first edge."""
    edges = chains.edge_ids[chains.arc_offsets[:-1]]
    return (split.offsets[edges + 1] - split.offsets[edges]).astype(np.int64)


def free_border_arcs(split: PatchSplit, chains: ArcChains) -> IntArray:
    """Arcs used by a single patch occurrence."""
    return np.flatnonzero(arc_weights(split, chains) == 1).astype(np.int64)


def free_border_patches(split: PatchSplit, chains: ArcChains) -> IntArray:
    """Patches with at least one free border.

    >>> from geobrep.plugins.blocks._arcs import sample_model_arcs
    >>> soup, split, chains = sample_model_arcs()
    >>> free_border_patches(split, chains).tolist()  # sealed
    []"""
    arcs = free_border_arcs(split, chains)
    edges = chains.edge_ids[chains.arc_offsets[arcs]]
    triangles = split.incident_triangles[split.offsets[edges]]
    return np.unique(split.triangle_patch[triangles]).astype(np.int64)


def describe_dangling(
    soup: Soup, split: PatchSplit, patches: IntArray, reason: str
) -> list[DanglingPatch]:
    """Report entries for removed patches (surface, size, centroid in model coordinates)."""
    if patches.size == 0:
        return []
    counts = np.bincount(split.triangle_patch, minlength=split.n_patches)
    corners = soup.local_vertices[soup.triangles]
    centroids = corners.mean(axis=1)
    sums = group_sums(split.triangle_patch, centroids, split.n_patches)
    result = []
    for patch in patches.tolist():
        index = int(split.patch_surface[patch])
        centre = sums[patch] / counts[patch] + soup.centre
        x, y, z = (float(v) for v in centre)
        result.append(
            DanglingPatch(
                surface=soup.surface_name(index),
                surface_id=soup.surfaces[index].id,
                triangles=int(counts[patch]),
                reason=reason,
                centroid=(x, y, z),
            )
        )
    return result
