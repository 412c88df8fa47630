"""Tell the outer "universe" from the real blocks, and find patches that bound nothing.

The signed volume of a region, summed over its patch sides with their normals turned outwards,
is positive for a closed body and negative for the region outside a connected set of patches —
so each connected set of patches has exactly one region of negative volume: its outside.
A set of patches lying inside a block of another one (a closed body floating in a layer) has its
outside merged into that block, found by the generalised winding number of one of its points;
the outsides of all the others are merged into the universe. Patches with the universe on both
sides stick out of the model, and a set of patches whose sides all fall into one region encloses
nothing (a floating sheet): both are dangling.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from geobrep.geometry.arrays import FloatArray, IntArray
from geobrep.geometry.bbox import column_extremes
from geobrep.plugins.blocks._csr import components, group_sums
from geobrep.plugins.blocks._measures import PatchMeasures
from geobrep.plugins.blocks._patches import PatchSplit
from geobrep.plugins.blocks._soup import Soup
from geobrep.plugins.blocks._traversal import Regions

__all__ = ["Bodies", "find_universe", "winding_number"]


#: Volume, relative to the model's bounding-box volume, under which a region encloses nothing.
_EMPTY_VOLUME_RTOL = 1e-12


@dataclass(frozen=True)
class Bodies:
    """Body of every patch side (blocks and the universe), their volumes, dangling patches."""

    positive: IntArray
    negative: IntArray
    volumes: FloatArray
    universe: int
    outside: IntArray
    floating: IntArray
    nested_components: int

    @property
    def n_bodies(self) -> int:
        return int(self.volumes.shape[0])

    @property
    def dangling(self) -> IntArray:
        return np.union1d(self.outside, self.floating).astype(np.int64)


def winding_number(point: FloatArray, a: FloatArray, b: FloatArray, c: FloatArray) -> float:
    """Generalised winding number of ``point`` for triangles ``(a, b, c)`` (1 inside a closed,
    outward-oriented surface, 0 outside).

    >>> import numpy as np
    >>> v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    >>> f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    >>> round(winding_number(np.array([0.1, 0.1, 0.1]), v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]), 9)
    1.0
    """
    p, q, r = a - point, b - point, c - point
    lp, lq, lr = (np.linalg.norm(x, axis=1) for x in (p, q, r))
    det = np.einsum("ij,ij->i", p, np.cross(q, r))
    den = (
        lp * lq * lr
        + np.einsum("ij,ij->i", p, q) * lr
        + np.einsum("ij,ij->i", q, r) * lp
        + np.einsum("ij,ij->i", r, p) * lq
    )
    return float(np.sum(2.0 * np.arctan2(det, den)) / (4.0 * math.pi))


def _region_triangles(
    soup: Soup, split: PatchSplit, regions: Regions, region: int
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Corners of the triangles bounding ``region``, turned to face out of it."""
    on_positive = regions.positive[split.triangle_patch] == region
    on_negative = regions.negative[split.triangle_patch] == region
    keep = on_positive ^ on_negative  # internal patches cancel out
    triangles = soup.triangles[keep]
    flip = on_positive[keep]
    triangles[flip] = triangles[flip][:, ::-1]
    local = soup.local_vertices
    return local[triangles[:, 0]], local[triangles[:, 1]], local[triangles[:, 2]]


def find_universe(
    soup: Soup, split: PatchSplit, regions: Regions, measures: PatchMeasures
) -> Bodies:
    """Merge the regions into bodies and pick the universe (see the module docstring)."""
    n_patches, n_regions = split.n_patches, regions.n_regions
    shares = measures.volume
    volume = group_sums(regions.positive, -shares, n_regions) + group_sums(
        regions.negative, shares, n_regions
    )
    a, b = regions.link_patches
    n_components, component = components(n_patches, a, b)
    region_component = np.empty(n_regions, dtype=np.int64)
    region_component[regions.positive] = component
    region_component[regions.negative] = component
    regions_per_component = np.bincount(region_component, minlength=n_components)

    lower, upper = column_extremes(soup.vertices)
    box_volume = float(np.prod(upper - lower))
    empty = _EMPTY_VOLUME_RTOL * max(box_volume, np.finfo(np.float64).tiny)
    order = np.lexsort((volume, region_component))
    first = np.ones(order.shape[0], dtype=np.bool_)
    first[1:] = region_component[order][1:] != region_component[order][:-1]
    outer = order[first]  # the smallest-volume region of each component
    encloses = (regions_per_component >= 2) & (volume[outer] < -empty)
    floating_components = np.flatnonzero(~encloses)

    body = np.arange(n_regions, dtype=np.int64)
    solid = np.flatnonzero(encloses)
    solid = solid[np.argsort(volume[outer[solid]], kind="stable")]  # largest first
    universe = int(outer[solid[0]]) if solid.size else -1
    nested = 0
    for c in solid.tolist():
        host = -1
        if c != solid[0]:
            host = _host_block(soup, split, regions, c, component, outer, region_component, volume)
        if host >= 0:
            nested += 1
        body[outer[c]] = host if host >= 0 else universe
    # Compact body ids (merged outsides leave gaps).
    used, body = np.unique(body, return_inverse=True)
    body_volume = group_sums(body, volume, used.shape[0])
    positive, negative = body[regions.positive], body[regions.negative]
    universe_body = int(body[universe]) if universe >= 0 else -1
    patch_floating = np.isin(component, floating_components)
    outside = np.flatnonzero((positive == universe_body) & (negative == universe_body))
    return Bodies(
        positive=positive,
        negative=negative,
        volumes=body_volume,
        universe=universe_body,
        outside=outside[~patch_floating[outside]].astype(np.int64),
        floating=np.flatnonzero(patch_floating).astype(np.int64),
        nested_components=nested,
    )


def _host_block(
    soup: Soup,
    split: PatchSplit,
    regions: Regions,
    component_id: int,
    component: IntArray,
    outer: IntArray,
    region_component: IntArray,
    volume: FloatArray,
) -> int:
    """The smallest block of another component that contains ``component_id``, or −1."""
    patch = int(np.flatnonzero(component == component_id)[0])
    triangle = int(np.flatnonzero(split.triangle_patch == patch)[0])
    point = soup.local(soup.vertices[soup.triangles[triangle, :1]])[0]
    candidates = np.flatnonzero(
        (region_component != component_id) & ~np.isin(np.arange(volume.shape[0]), outer)
    )
    for region in candidates[np.argsort(volume[candidates], kind="stable")].tolist():
        if volume[region] <= 0.0:
            continue
        a, b, c = _region_triangles(soup, split, regions, region)
        lower = column_extremes(np.minimum(np.minimum(a, b), c))[0]
        upper = column_extremes(np.maximum(np.maximum(a, b), c))[1]
        if np.any(point < lower) or np.any(point > upper):
            continue
        if winding_number(point, a, b, c) > 0.5:
            return int(region)
    return -1
