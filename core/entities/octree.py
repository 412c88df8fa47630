"""Linear octrees: a body as the sorted Morton codes of its full leaves (voxelizer output)."""

from __future__ import annotations

from functools import cached_property
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field, model_validator

from geobrep.arrays import IndexArray, NumericArray, Vector3
from geobrep.entities.base import Entity, describe_entity
from geobrep.errors import EntityValidationError
from geobrep.geometry.bbox import BoundingBox

__all__ = ["MAX_OCTREE_DEPTH", "LinearOctree"]

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
