"""Check a built scene: every block closed, outward-oriented and of positive volume, every patch
with a block on both sides, and the block volumes adding up to the volume inside the universe.

The checks read the scene the builder wrote — its surfaces, patches and block side lists — and
give the same answers as :meth:`~geobrep.Scene.block_mesh` with ``Surface.is_closed``,
``is_consistently_oriented`` and ``volume`` for each block, in one vectorised pass over all
blocks instead of one weld and edge sort per block:

* the scene's surfaces are first checked to be, bit for bit, the welded triangles the builder
  worked on (same vertex coordinates, same triangles, patch labels naming the same patches), so
  the builder's weld, edge-to-triangle map and per-patch volumes describe the scene exactly;
* a block's boundary is the faces of its patch sides (flipped on positive sides; patches listed
  with both sides are inside it and left out). It is closed when every edge is used by exactly
  two of its faces and consistently oriented when no edge is traversed twice in one direction.
  An edge inside a patch (two triangles of that patch) meets both with the two blocks on its
  sides, so only edges where patches meet or stop are grouped by block;
* a block's volume is the sum of its patch sides' signed volumes, normals turned outwards.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geobrep import Block, Scene, Surface
from geobrep.errors import TopologyError
from geobrep.geometry.arrays import BoolArray, IntArray
from geobrep.plugins.blocks._csr import concatenated_ranges
from geobrep.plugins.blocks._measures import PatchMeasures
from geobrep.plugins.blocks._patches import PatchSplit
from geobrep.plugins.blocks._soup import Soup
from geobrep.plugins.blocks.report import BlockCheck

__all__ = ["Validation", "validate_scene"]


_MAX_LISTED = 10


@dataclass(frozen=True)
class Validation:
    checks: list[BlockCheck]
    universe_closed: bool | None
    volume_balance: float | None


def _surface_mismatches(
    scene: Scene, soup: Soup, split: PatchSplit, vertex_ids: dict[int, IntArray]
) -> list[str]:
    """Surfaces of ``scene`` that are not exactly the soup's triangles of their surface."""
    patch_of = {(p.surface, p.label): p.id for p in scene.patches}
    wrong: list[str] = []
    bounds = np.searchsorted(soup.triangle_surface, np.arange(len(soup.surfaces) + 1))
    for index, source in enumerate(soup.surfaces):
        start, stop = int(bounds[index]), int(bounds[index + 1])
        key = int(source.id or 0)
        if start == stop:
            if key in vertex_ids:
                wrong.append(f"{source.label} should have been removed")
            continue
        built = scene.get(key)
        ids = vertex_ids.get(key)
        if not isinstance(built, Surface) or ids is None or built.patch_labels is None:
            wrong.append(f"{source.label} is missing or has no patch labels")
            continue
        labels = built.patch_labels
        lookup = np.array(
            [patch_of.get((key, label), -1) for label in range(int(labels.max()) + 1)],
            dtype=np.int64,
        )
        same = (
            built.faces.shape == (stop - start, 3)
            and np.array_equal(built.vertices, np.take(soup.vertices, ids, axis=0))
            and np.array_equal(ids[built.faces], soup.triangles[start:stop])
            and np.array_equal(lookup[labels], split.triangle_patch[start:stop])
        )
        if not same:
            wrong.append(f"{built.label} differs from the triangles the blocks were built from")
    return wrong


def _block_sides(
    scene: Scene, blocks: list[Block], n_patches: int
) -> tuple[IntArray, IntArray, list[str]]:
    """Block (position in ``blocks``) on the positive and negative side of every patch (-1: none)
    from the blocks' side lists, and what disagrees with the patches' own block fields."""
    sides = np.full((2, n_patches), -1, dtype=np.int64)
    problems: list[str] = []
    listed_twice: list[int] = []
    for k, block in enumerate(blocks):
        for patch, side in block.sides:
            row = 0 if side == 1 else 1
            if not 0 <= patch < n_patches:
                problems.append(f"{block.label} lists patch {patch}, which does not exist")
            elif sides[row, patch] >= 0:
                listed_twice.append(patch)
            else:
                sides[row, patch] = k
    if listed_twice:
        problems.append(f"patch sides listed by two blocks: {listed_twice[:_MAX_LISTED]}")
    block_ids = np.array([int(b.id or 0) for b in blocks] + [-1], dtype=np.int64)
    one_sided = [
        p.id for p in scene.patches if p.positive_block is None or p.negative_block is None
    ]
    if one_sided:
        problems.append(f"patches without a block on both sides: {one_sided[:_MAX_LISTED]}")
    disagree = [
        p.id
        for p in scene.patches
        if 0 <= p.id < n_patches
        and (
            (p.positive_block is not None and p.positive_block != block_ids[sides[0, p.id]])
            or (p.negative_block is not None and p.negative_block != block_ids[sides[1, p.id]])
        )
    ]
    if disagree:
        problems.append(f"patches whose blocks disagree with the blocks' sides: {disagree[:10]}")
    return sides[0], sides[1], problems


def _edge_checks(
    soup: Soup, split: PatchSplit, positive: IntArray, negative: IntArray, n_blocks: int
) -> tuple[BoolArray, BoolArray]:
    """Per block: every boundary edge used by exactly two faces; no edge used twice one way."""
    closed = np.ones(n_blocks, dtype=np.bool_)
    oriented = np.ones(n_blocks, dtype=np.bool_)
    offsets, triangle, side = split.offsets, split.incident_triangles, split.incident_sides
    corner = soup.triangles.reshape(-1)
    counted = positive != negative  # patches inside a block are left out
    # Only arc edges need looking at: every other edge has two triangles of one patch that
    # traverse it oppositely (the split's rule), so each block on its sides uses it once each way.
    arc = split.arc_edges
    size = offsets[arc + 1] - offsets[arc]
    # Arc edges of two triangles of one patch (a seam the patch closes around): both are faces
    # of the same two blocks, and they traverse it oppositely unless both start it at one vertex.
    pair = np.flatnonzero(size == 2)
    first = offsets[arc[pair]]
    one, two = triangle[first], triangle[first + 1]
    patch = split.triangle_patch[one]
    inner = patch == split.triangle_patch[two]
    same_way = corner[3 * one + side[first]] == corner[3 * two + side[first + 1]]
    twisted = patch[inner & same_way & counted[patch]]
    oriented[positive[twisted]] = False
    oriented[negative[twisted]] = False
    # Every other arc edge: its faces grouped by block.
    size[pair[inner]] = 0
    live = np.flatnonzero(size)
    others, size = arc[live], size[live]
    edge = np.repeat(others, size)
    rows = concatenated_ranges(offsets[others], size)
    patch = split.triangle_patch[triangle[rows]]
    keep = counted[patch]
    edge, rows, patch = edge[keep], rows[keep], patch[keep]
    forward = corner[3 * triangle[rows] + side[rows]] == split.edges[edge, 0]
    # The block on the positive side sees the face flipped.
    block = np.concatenate([positive[patch], negative[patch]])
    along = np.concatenate([~forward, forward]).astype(np.int64)
    key = np.sort(np.concatenate([edge, edge]) * (2 * n_blocks) + 2 * block + along)
    if key.size:
        half = key // 2  # sorted: groups are runs
        starts = np.ones(half.shape[0], dtype=np.bool_)
        starts[1:] = half[1:] != half[:-1]
        first_of = np.flatnonzero(starts)
        group = half[first_of]
        count = np.diff(np.append(first_of, key.shape[0]))
        ahead = np.add.reduceat(key % 2, first_of)
        group_block = group % n_blocks
        closed[group_block[count != 2]] = False
        oriented[group_block[(ahead > 1) | (count - ahead > 1)]] = False
    return closed, oriented


def validate_scene(
    scene: Scene,
    soup: Soup,
    split: PatchSplit,
    measures: PatchMeasures,
    vertex_ids: dict[int, IntArray],
    relative_volume_tolerance: float = 1e-6,
) -> Validation:
    """Validate the blocks of ``scene``, built from ``soup`` and ``split`` (``measures`` are their
    patch sums, ``vertex_ids`` the soup vertex of every vertex of each built surface, by surface
    id); a failure is a :class:`TopologyError` naming the blocks."""
    problems = _surface_mismatches(scene, soup, split, vertex_ids)
    if problems:
        raise TopologyError("block validation failed: " + "; ".join(problems))
    universe = scene.universe
    blocks = list(scene.blocks) + ([universe] if universe is not None else [])
    n_blocks = len(blocks)
    positive, negative, side_problems = _block_sides(scene, blocks, split.n_patches)
    problems += side_problems
    # Patch sides no block lists count for a block of their own, which then cannot be closed.
    positive = np.where(positive < 0, n_blocks, positive)
    negative = np.where(negative < 0, n_blocks, negative)
    closed, oriented = _edge_checks(soup, split, positive, negative, n_blocks + 1)
    counted = positive != negative
    counts = split.patch_triangle_counts()
    volume = np.bincount(negative[counted], measures.volume[counted], n_blocks + 1) - np.bincount(
        positive[counted], measures.volume[counted], n_blocks + 1
    )
    triangles = np.bincount(negative[counted], counts[counted], n_blocks + 1) + np.bincount(
        positive[counted], counts[counted], n_blocks + 1
    )
    checks: list[BlockCheck] = []
    for k, block in enumerate(blocks[: len(scene.blocks)]):
        check = BlockCheck(
            id=int(block.id or 0),
            name=block.name,
            unit_name=block.unit_name,
            volume=float(volume[k]),
            triangles=int(triangles[k]),
            closed=bool(closed[k] and triangles[k] > 0),
            oriented=bool(oriented[k]),
        )
        checks.append(check)
        if not (check.closed and check.oriented and check.volume > 0.0):
            problems.append(
                f"{block.label}: closed={check.closed}, oriented={check.oriented}, "
                f"volume={check.volume:.6g}"
            )
    universe_closed: bool | None = None
    balance: float | None = None
    if universe is not None and universe.sides:
        k = n_blocks - 1
        universe_closed = bool(closed[k] and oriented[k] and triangles[k] > 0)
        model_volume = -float(volume[k])
        if model_volume > 0.0:
            balance = abs(sum(c.volume for c in checks) - model_volume) / model_volume
        if not universe_closed:
            problems.append("the universe's boundary (the model's outer shell) is not closed")
        elif balance is None or balance > relative_volume_tolerance:
            problems.append(
                "the block volumes do not add up to the model volume "
                f"(relative difference {balance})"
            )
    if problems:
        raise TopologyError("block validation failed: " + "; ".join(problems))
    return Validation(checks, universe_closed, balance)
