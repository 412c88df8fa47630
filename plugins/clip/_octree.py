"""The LinearOctree clipper: leaves are cells of a grid, so a cut is a choice of cells.

Leaves entirely on the kept side are kept, leaves entirely beyond the plane dropped. A leaf the
plane crosses is, with ``straddling="subdivide"`` (the default), split into its eight children
level by level down to the octree's depth (children on one side kept or dropped whole, so the
result stays a compact linear octree), and the finest cells still crossed are kept by their
centre; with ``straddling="centre"`` the whole leaf is kept or dropped by its centre. A centre
exactly on the plane counts as positive, so ``keep="both"`` partitions the leaves. Labels and cell
data follow each leaf to its kept children.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep import LinearOctree
from geobrep.errors import DegenerateGeometryError
from geobrep.geometry import Plane, boxes_plane_side
from geobrep.geometry.arrays import FloatArray, IntArray, UIntArray
from geobrep.geometry.morton import morton_decode
from geobrep.plugins import ClipContext, Keep, halves, pack_halves
from geobrep.plugins.clip.options import OctreeClipOptions, tolerance_of

__all__ = ["clip_octree", "leaf_boxes"]


#: Most cells a subdivision may make along the plane at the finest level.
MAX_SUBDIVIDED_CELLS = 20_000_000


def leaf_boxes(
    tree: LinearOctree, codes: UIntArray, levels: NDArray[np.uint8]
) -> tuple[FloatArray, FloatArray]:
    """Minimum and maximum corners ``(n, 3)`` of leaves given by codes and levels."""
    cell = tree.size / float(2**tree.depth)
    span = np.exp2(tree.depth - levels.astype(np.float64)) * cell
    cells = np.stack(morton_decode(codes), axis=1).astype(np.float64)
    mins = tree.origin + cells * cell
    return mins, mins + span[:, None]


def clip_octree(
    tree: LinearOctree,
    plane: Plane,
    keep: Keep,
    options: OctreeClipOptions,
    context: ClipContext,
) -> Any:
    """Clipper of :class:`LinearOctree` entities (see the module docstring)."""
    tolerance = tolerance_of(options, context)
    parts: dict[int, LinearOctree | None] = {}
    for side in halves(keep):
        codes, levels, source = _kept_leaves(tree, plane, side, tolerance, options.straddling)
        if codes.shape[0] == tree.n_leaves:
            parts[side] = tree
        elif codes.shape[0] == 0:
            parts[side] = None
        else:
            parts[side] = tree.replace(
                codes=codes,
                levels=levels,
                labels=None if tree.labels is None else tree.labels[source],
                cell_data=tree.cell_data.take(source),
            )
    return pack_halves(keep, parts)


def _by_centre(mins: FloatArray, maxs: FloatArray, plane: Plane, side: int) -> NDArray[np.bool_]:
    distance = plane.signed_distance(0.5 * (mins + maxs))
    return np.asarray(distance < 0 if side < 0 else distance >= 0)


def _kept_leaves(
    tree: LinearOctree, plane: Plane, side: int, tolerance: float, straddling: str
) -> tuple[UIntArray, NDArray[np.uint8], IntArray]:
    codes = np.asarray(tree.codes, dtype=np.uint64)
    levels = np.asarray(tree.levels, dtype=np.uint8)
    source = np.arange(codes.shape[0], dtype=np.int64)
    kept_codes: list[UIntArray] = []
    kept_levels: list[NDArray[np.uint8]] = []
    kept_source: list[IntArray] = []
    while codes.shape[0]:
        mins, maxs = leaf_boxes(tree, codes, levels)
        where = boxes_plane_side(mins, maxs, plane, tolerance)
        take = where == side
        crossed = where == 0
        finest = levels >= tree.depth
        by_centre = crossed & (finest | (straddling == "centre"))
        take |= by_centre & _by_centre(mins, maxs, plane, side)
        kept_codes.append(codes[take])
        kept_levels.append(levels[take])
        kept_source.append(source[take])
        split = crossed & ~by_centre
        if not split.any():
            break
        # A plane crosses about 4× more cells at each finer level.
        remaining = tree.depth - int(levels[split].min())
        estimate = int(split.sum()) * 4.0**remaining
        if estimate > MAX_SUBDIVIDED_CELLS:
            raise DegenerateGeometryError(
                f"{tree.label}: subdividing the leaves the plane crosses down to level "
                f"{tree.depth} would make about {estimate:.3g} cells; use the option "
                "straddling='centre'"
            )
        parents, parent_levels = codes[split], levels[split]
        step = np.left_shift(
            np.uint64(1),
            (np.uint64(3) * (np.uint64(tree.depth) - parent_levels - 1).astype(np.uint64)),
        )
        children = parents[:, None] + step[:, None] * np.arange(8, dtype=np.uint64)[None, :]
        codes = children.reshape(-1)
        levels = np.repeat(parent_levels + np.uint8(1), 8)
        source = np.repeat(source[split], 8)
    all_codes = np.concatenate(kept_codes) if kept_codes else np.zeros(0, np.uint64)
    order = np.argsort(all_codes, kind="stable")
    return (
        all_codes[order],
        np.concatenate(kept_levels)[order].astype(np.uint8),
        np.concatenate(kept_source)[order],
    )
