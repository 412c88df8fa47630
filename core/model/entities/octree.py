"""Linear octrees: a body as the sorted Morton codes of its full leaves (voxelizer output)."""

from __future__ import annotations

from functools import cached_property
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import Field, model_validator

from geobrep.errors import EntityValidationError
from geobrep.geometry.bbox import BoundingBox
from geobrep.geometry.morton import morton_decode, morton_encode, octant_span
from geobrep.model.arrays import IndexArray, NumericArray, Vector3
from geobrep.model.entities.base import Entity, describe_entity

if TYPE_CHECKING:
    import open3d
    import pyvista

__all__ = ["MAX_OCTREE_DEPTH", "LinearOctree"]

# Neighbour directions for face (6), face + edge (18) and all (26) connectivity.
_DIRECTIONS = np.array(
    [(dx, dy, dz) for dx in (-1, 0, 1) for dy in (-1, 0, 1) for dz in (-1, 0, 1) if dx or dy or dz],
    dtype=np.int64,
)
_DIRECTION_ORDER = np.abs(_DIRECTIONS).sum(axis=1)

#: 3 × 21 bits fit a uint64 Morton code.
MAX_OCTREE_DEPTH = 21


class LinearOctree(Entity):
    """Leaves of an octree over the cube ``origin + [0, size]³``, as Morton codes and levels.

    ``codes`` (uint64, strictly ascending) are the Morton codes of each leaf's minimum corner at
    the finest resolution ``2**depth`` per axis (bit ``3i`` from x, ``3i+1`` from y, ``3i+2`` from
    z); ``levels`` (uint8) give each leaf's level, 0 being the whole cube and ``depth`` a finest
    cell, so a leaf's code is a multiple of ``8**(depth - level)``. ``labels`` optionally carries a
    block id per leaf; ``cell_data`` has one value per leaf.

    >>> import numpy as np
    >>> tree = LinearOctree(codes=[0], levels=[1], depth=2, origin=[0, 0, 0], size=2.0)
    >>> tree.volume
    1.0
    """

    type: Literal["LinearOctree"] = "LinearOctree"
    cell_noun = "leaves"
    codes: NumericArray
    levels: NumericArray
    depth: int = Field(ge=0, le=MAX_OCTREE_DEPTH)
    origin: Vector3
    size: float = Field(gt=0, allow_inf_nan=False)
    labels: IndexArray | None = None

    @model_validator(mode="before")
    @classmethod
    def _normalise_dtypes(cls, data: Any) -> Any:
        if not isinstance(data, dict):
            return data
        data = dict(data)
        label = describe_entity(cls.__name__, data.get("name"), data.get("id"))
        for key, dtype in (("codes", np.uint64), ("levels", np.uint8)):
            value = data.get(key)
            if value is None or isinstance(value, dict):
                continue
            try:
                array = np.asarray(value)
            except (TypeError, ValueError) as exc:
                raise EntityValidationError(
                    label, key, f"cannot be read as an array: {exc}"
                ) from None
            if array.dtype == dtype:
                continue
            if array.dtype.kind not in "iu" and array.size:
                raise EntityValidationError(
                    label, key, f"must be integers, got dtype {array.dtype}"
                )
            if array.size and array.min() < 0:
                raise EntityValidationError(label, key, "must be non-negative")
            if key == "levels" and array.size and array.max() > MAX_OCTREE_DEPTH:
                raise EntityValidationError(label, key, f"must be ≤ {MAX_OCTREE_DEPTH}")
            data[key] = array.astype(dtype)
        return data

    @property
    def n_cells(self) -> int:
        return int(self.codes.shape[0])

    @property
    def n_leaves(self) -> int:
        return self.n_cells

    @cached_property
    def leaf_sizes(self) -> NDArray[np.float64]:
        """Edge length of each leaf."""
        return self.size / np.exp2(self.levels.astype(np.float64))

    @cached_property
    def volume(self) -> float:
        """Total volume of the leaves."""
        return float(np.sum(self.leaf_sizes**3))

    def leaf_count_per_level(self) -> NDArray[np.int64]:
        """Number of leaves at each level ``0..depth``."""
        return np.bincount(self.levels, minlength=self.depth + 1).astype(np.int64)

    @property
    def bounds(self) -> BoundingBox | None:
        """The octree's cube."""
        return BoundingBox(mins=self.origin, maxs=self.origin + self.size)

    @property
    def memory_bytes(self) -> int:
        """Bytes held by codes, levels and labels."""
        extra = 0 if self.labels is None else self.labels.nbytes
        return int(self.codes.nbytes + self.levels.nbytes + extra)

    # -- leaves as cells -------------------------------------------------------------------------
    @cached_property
    def spans(self) -> NDArray[np.uint64]:
        """Number of finest codes each leaf covers: ``8**(depth - level)``."""
        return octant_span(self.levels, self.depth)

    def leaf_cells(self) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """Each leaf's minimum finest cell ``(n, 3)`` and its edge in finest cells ``(n,)``."""
        i, j, k = morton_decode(self.codes)
        edge = np.left_shift(np.int64(1), (self.depth - self.levels.astype(np.int64)))
        return np.stack([i, j, k], axis=1), edge

    def leaf_bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Minimum and maximum corners ``(n, 3)`` of every leaf, in model coordinates."""
        cells, edge = self.leaf_cells()
        finest = self.size / float(1 << self.depth)
        mins = self.origin + cells * finest
        return mins, mins + (edge * finest)[:, None]

    def leaf_centers(self) -> NDArray[np.float64]:
        """Centre ``(n, 3)`` of every leaf, in model coordinates."""
        mins, maxs = self.leaf_bounds()
        return 0.5 * (mins + maxs)

    def label_volumes(self) -> dict[int, float]:
        """Volume held by each label (``{}`` without labels).

        >>> tree = LinearOctree(codes=[0, 8], levels=[1, 2], depth=2, origin=[0, 0, 0],
        ...                     size=4.0, labels=[7, 9])
        >>> tree.label_volumes()
        {7: 8.0, 9: 1.0}
        """
        if self.labels is None or self.labels.size == 0:
            return {}
        found, inverse = np.unique(self.labels, return_inverse=True)
        volumes = np.bincount(inverse, weights=self.leaf_sizes**3)
        return {int(label): float(volume) for label, volume in zip(found, volumes, strict=True)}

    # -- point queries ----------------------------------------------------------------------------
    def _finest_codes(self, cells: NDArray[np.int64]) -> NDArray[np.uint64]:
        return morton_encode(cells[:, 0], cells[:, 1], cells[:, 2])

    def _locate_codes(self, codes: NDArray[np.uint64]) -> NDArray[np.int64]:
        """Leaf holding each finest code, or -1."""
        if self.codes.size == 0:
            return np.full(codes.shape[0], -1, dtype=np.int64)
        position = np.searchsorted(self.codes, codes, side="right").astype(np.int64) - 1
        safe = np.maximum(position, 0)
        inside = (position >= 0) & (codes < self.codes[safe] + self.spans[safe])
        return np.where(inside, position, -1)

    def leaf_index(self, points: ArrayLike) -> NDArray[np.int64]:
        """Index of the leaf containing each point, or -1 (outside the cube or no leaf there).

        Cells are half-open: a point on a shared face belongs to the cell above it. Vectorised:
        one Morton code per point, then a binary search in the sorted codes.

        >>> tree = LinearOctree(codes=[0, 8], levels=[1, 2], depth=2, origin=[0, 0, 0], size=4)
        >>> tree.leaf_index([[0.5, 0.5, 0.5], [2.5, 0.5, 0.5], [3.5, 3.5, 3.5]]).tolist()
        [0, 1, -1]
        """
        p = np.asarray(points, dtype=np.float64)
        if p.ndim == 1 and p.shape[0] == 3:
            p = p.reshape(1, 3)
        if p.ndim != 2 or p.shape[1] != 3:
            raise self.fail("points", f"expected shape (3,) or (N, 3), got {np.shape(points)}")
        resolution = 1 << self.depth
        with np.errstate(invalid="ignore"):
            scaled = np.floor((p - self.origin) * (resolution / self.size))
        inside_cube = np.all((scaled >= 0) & (scaled < resolution), axis=1)
        cells = np.where(inside_cube[:, None], scaled, 0).astype(np.int64)
        found = self._locate_codes(self._finest_codes(cells))
        return np.where(inside_cube, found, -1)

    def contains(self, points: ArrayLike) -> NDArray[np.bool_]:
        """Whether each point lies in a leaf (a boolean array, vectorised over the points).

        >>> tree = LinearOctree(codes=[0], levels=[1], depth=2, origin=[0, 0, 0], size=4)
        >>> tree.contains([[1, 1, 1], [3, 3, 3]]).tolist()
        [True, False]
        """
        return self.leaf_index(points) >= 0

    def label_at(self, points: ArrayLike, missing: int = -1) -> NDArray[np.int64]:
        """Label of the leaf containing each point (``missing`` where none, or without labels)."""
        index = self.leaf_index(points)
        if self.labels is None:
            return np.full(index.shape[0], missing, dtype=np.int64)
        labels = self.labels.astype(np.int64)
        return np.where(index >= 0, labels[np.maximum(index, 0)], missing)

    def neighbours(self, leaf: int, connectivity: Literal[6, 18, 26] = 6) -> NDArray[np.int64]:
        """Indices of the leaves touching leaf ``leaf`` (ascending).

        ``connectivity`` 6: sharing part of a face; 18: also of an edge; 26: also a corner.
        Neighbours may be larger or smaller than the leaf: for each direction the octant of the
        leaf's size beside it is looked up, then the leaves inside it that touch the contact.

        >>> tree = LinearOctree(codes=[0, 8, 9, 16], levels=[1, 2, 2, 2], depth=2,
        ...                     origin=[0, 0, 0], size=4)
        >>> tree.neighbours(0).tolist(), tree.neighbours(1).tolist(), tree.neighbours(2).tolist()
        ([1, 3], [0, 2], [1])
        """
        if not -self.n_leaves <= leaf < self.n_leaves:
            raise self.fail("leaf", f"index {leaf} out of range for {self.n_leaves} leaves")
        if connectivity not in (6, 18, 26):
            raise self.fail("connectivity", f"must be 6, 18 or 26, got {connectivity!r}")
        leaf = leaf % self.n_leaves
        order = {6: 1, 18: 2, 26: 3}[connectivity]
        directions = _DIRECTIONS[order >= _DIRECTION_ORDER]
        cells, edges = self.leaf_cells()
        corner, edge = cells[leaf], int(edges[leaf])
        resolution = 1 << self.depth
        found: list[NDArray[np.int64]] = []
        for direction in directions:
            start = corner + direction * edge
            if np.any(start < 0) or np.any(start >= resolution):
                continue
            level = int(self.levels[leaf])
            first = self._finest_codes(start[None, :])
            span = octant_span([level], self.depth)
            holder = self._locate_codes(first)
            if holder[0] >= 0 and self.levels[holder[0]] <= level:
                found.append(holder)  # one leaf, as large or larger, covers the whole octant
                continue
            lo = int(np.searchsorted(self.codes, first[0], side="left"))
            hi = int(np.searchsorted(self.codes, first[0] + span[0], side="left"))
            if hi == lo:
                continue
            inner = np.arange(lo, hi)
            touch = np.ones(inner.size, dtype=np.bool_)
            for axis in range(3):
                if direction[axis] == 0:
                    continue
                if direction[axis] > 0:  # the neighbour's minimum face touches our maximum
                    touch &= cells[inner, axis] == corner[axis] + edge
                else:
                    touch &= cells[inner, axis] + edges[inner] == corner[axis]
            found.append(inner[touch])
        if not found:
            return np.zeros(0, dtype=np.int64)
        return np.unique(np.concatenate(found))

    # -- conversions ------------------------------------------------------------------------------
    def to_pyvista(
        self, kind: Literal["hexahedra", "image"] = "hexahedra"
    ) -> pyvista.UnstructuredGrid | pyvista.ImageData:
        """A VTK grid (needs the ``viz`` extra): one hexahedron per leaf, or image data.

        ``"hexahedra"``: an unstructured grid with cell arrays ``level``, ``label`` (if any) and
        every ``cell_data`` property. ``"image"``: the finest grid with cell array ``label``
        (``-1`` outside; ``1`` inside without labels) — ``8**depth`` cells, so keep depth small.
        """
        from geobrep.model.entities._octree_export import octree_to_pyvista

        return octree_to_pyvista(self, kind)

    def to_open3d(self, level: int | None = None) -> open3d.geometry.VoxelGrid:
        """An open3d ``VoxelGrid`` of the leaves at ``level`` (default: the depth; extra open3d).

        Larger leaves are split into voxels of that level; smaller ones mark their voxel.
        """
        from geobrep.model.entities._octree_export import octree_to_open3d

        return octree_to_open3d(self, level)

    def to_open3d_octree(self, level: int | None = None) -> open3d.geometry.Octree:
        """An open3d ``Octree`` built from :meth:`to_open3d` (extra ``open3d``)."""
        from geobrep.model.entities._octree_export import octree_to_open3d_octree

        return octree_to_open3d_octree(self, level)

    def _check(self) -> None:
        codes, levels = self.codes, self.levels
        if codes.dtype != np.uint64 or codes.ndim != 1:
            raise self.fail("codes", f"must be a 1-D uint64 array, got {codes.dtype} {codes.shape}")
        if levels.dtype != np.uint8 or levels.shape != codes.shape:
            raise self.fail("levels", f"must be uint8 with one level per code ({codes.shape[0]})")
        if self.labels is not None and self.labels.shape != codes.shape:
            raise self.fail(
                "labels", f"has {self.labels.shape[0]} labels for {codes.shape[0]} leaves"
            )
        if not codes.size:
            return
        if int(levels.max()) > self.depth:
            raise self.fail("levels", f"level {int(levels.max())} exceeds depth {self.depth}")
        span = np.left_shift(np.uint64(1), (3 * (self.depth - levels.astype(np.uint64))))
        if np.any(codes % span):
            bad = int(np.argmax(codes % span != 0))
            raise self.fail(
                "codes", f"leaf {bad} code is not aligned to its level {int(levels[bad])}"
            )
        if int(codes[-1]) >= 8**self.depth:  # Python ints: exact at depth 21 (8**21 = 2**63)
            raise self.fail(
                "codes", f"code {int(codes[-1])} lies outside an octree of depth {self.depth}"
            )
        if np.any(codes[1:] <= codes[:-1]):
            raise self.fail("codes", "must be strictly ascending (Morton order)")
        if np.any(codes[:-1] + span[:-1] > codes[1:]):
            bad = int(np.argmax(codes[:-1] + span[:-1] > codes[1:]))
            raise self.fail("codes", f"leaf {bad} overlaps leaf {bad + 1}")
