"""Lines made of one or more parts, each open or closed (fault traces, contours, PLine ILINEs)."""

from __future__ import annotations

from collections.abc import Sequence
from functools import cached_property
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import model_validator

from geobrep.model.arrays import BoolArray, IndexArray, Points
from geobrep.model.entities.base import VertexEntity

__all__ = ["PolyLine"]


class PolyLine(VertexEntity):
    """Vertices shared by parts; part ``p`` visits ``indices[part_offsets[p]:part_offsets[p+1]]``.

    Cells are the segments (in part order), so ``cell_data`` has one value per segment. A closed
    part has a last segment back to its first vertex. Without ``indices`` the line is one open part
    through all vertices in order.

    >>> import numpy as np
    >>> line = PolyLine.from_parts([[0, 0, 0], [1, 0, 0], [1, 1, 0]], [[0, 1, 2]], closed=[True])
    >>> line.n_cells, line.segments.tolist()
    (3, [[0, 1], [1, 2], [2, 0]])
    """

    type: Literal["PolyLine"] = "PolyLine"
    cell_noun = "segments"
    vertices: Points
    indices: IndexArray
    part_offsets: IndexArray
    closed: BoolArray

    @model_validator(mode="before")
    @classmethod
    def _default_single_part(cls, data: Any) -> Any:
        if isinstance(data, dict) and "vertices" in data and "indices" not in data:
            count = len(np.asarray(data["vertices"]))
            data = {**data, "indices": np.arange(count, dtype=np.int64)}
            data.setdefault("part_offsets", np.array([0, count] if count else [0], dtype=np.int64))
        if isinstance(data, dict) and "closed" not in data and "part_offsets" in data:
            parts = max(len(np.asarray(data["part_offsets"])) - 1, 0)
            data = {**data, "closed": np.zeros(parts, dtype=bool)}
        return data

    @classmethod
    def from_parts(
        cls,
        vertices: ArrayLike,
        parts: Sequence[Sequence[int]],
        closed: Sequence[bool] | bool = False,
        **fields: Any,
    ) -> PolyLine:
        """Build from vertex-index lists, one per part."""
        lengths = np.array([len(part) for part in parts], dtype=np.int64)
        offsets = np.concatenate([[0], np.cumsum(lengths)]).astype(np.int64)
        indices = (
            np.concatenate([np.asarray(p, dtype=np.int64) for p in parts])
            if parts
            else np.zeros(0, np.int64)
        )
        flags = np.broadcast_to(np.asarray(closed, dtype=bool), lengths.shape).copy()
        return cls(vertices=vertices, indices=indices, part_offsets=offsets, closed=flags, **fields)

    @classmethod
    def from_point_lists(
        cls, parts: Sequence[ArrayLike], closed: Sequence[bool] | bool = False, **fields: Any
    ) -> PolyLine:
        """Build from one ``(k, 3)`` coordinate array per part (vertices are not shared)."""
        arrays = [np.asarray(p, dtype=np.float64).reshape(-1, 3) for p in parts]
        vertices = np.concatenate(arrays) if arrays else np.zeros((0, 3))
        starts = np.cumsum([0] + [len(a) for a in arrays])
        index_lists = [
            list(range(int(s), int(s) + len(a))) for s, a in zip(starts, arrays, strict=False)
        ]
        return cls.from_parts(vertices, index_lists, closed, **fields)

    @property
    def n_parts(self) -> int:
        return int(self.part_offsets.shape[0] - 1)

    @cached_property
    def part_lengths(self) -> NDArray[np.int64]:
        """Number of vertices of each part."""
        return np.diff(self.part_offsets).astype(np.int64)

    @property
    def n_cells(self) -> int:
        return int(self.part_lengths.sum() - self.n_parts + self.closed.sum())

    @cached_property
    def segments(self) -> NDArray[np.int64]:
        """``(S, 2)`` vertex indices of every segment, parts in order, closing segments included."""
        idx = np.asarray(self.indices, dtype=np.int64)
        starts = self.part_offsets[:-1]
        ends = self.part_offsets[1:]
        # Each part of length L contributes L-1 segments (+1 if closed).
        part_of = np.repeat(np.arange(self.n_parts), self.part_lengths)
        position = np.arange(idx.shape[0])
        is_last = position == (ends[part_of] - 1) if idx.size else np.zeros(0, bool)
        open_from = position[~is_last]
        pairs = np.stack([idx[open_from], idx[open_from + 1]], axis=1)
        closing = np.flatnonzero(self.closed)
        close_pairs = np.stack([idx[ends[closing] - 1], idx[starts[closing]]], axis=1)
        segment_part = np.concatenate([part_of[open_from], closing])
        order = np.argsort(segment_part, kind="stable")
        result = np.concatenate([pairs, close_pairs])[order]
        result.flags.writeable = False
        return result

    def part(self, index: int) -> NDArray[np.float64]:
        """Coordinates ``(k, 3)`` of one part, in order."""
        lo, hi = self.part_offsets[index], self.part_offsets[index + 1]
        return np.asarray(self.vertices[self.indices[lo:hi]])

    @cached_property
    def length(self) -> float:
        """Total length of all segments."""
        seg = self.segments
        return float(
            np.linalg.norm(self.vertices[seg[:, 1]] - self.vertices[seg[:, 0]], axis=1).sum()
        )

    def _check(self) -> None:
        n = self.vertices.shape[0]
        offsets = self.part_offsets
        if offsets.shape[0] < 1 or offsets[0] != 0 or offsets[-1] != self.indices.shape[0]:
            raise self.fail(
                "part_offsets", f"must start at 0 and end at len(indices) = {self.indices.shape[0]}"
            )
        lengths = np.diff(offsets)
        if lengths.size and lengths.min() < 2:
            bad = int(np.argmax(lengths < 2))
            raise self.fail("part_offsets", f"part {bad} has {int(lengths[bad])} vertex; need ≥ 2")
        if self.closed.shape[0] != lengths.shape[0]:
            raise self.fail(
                "closed", f"has {self.closed.shape[0]} flags for {lengths.shape[0]} parts"
            )
        short_closed = self.closed & (lengths < 3)
        if short_closed.any():
            raise self.fail(
                "closed", f"closed part {int(np.argmax(short_closed))} has < 3 vertices"
            )
        if self.indices.size and (self.indices.min() < 0 or self.indices.max() >= n):
            raise self.fail("indices", f"refer to vertices outside 0..{n - 1}")
