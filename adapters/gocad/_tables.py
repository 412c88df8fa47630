"""Vertex and cell tables of one GOCAD object, filled line by line or run by run.

Vertex ids are labels: any integers, in any order, with ATOM/PATOM (and LightTSolid's
SHAREDVRTX) lines naming a new id at the position of an earlier one. Ids are resolved to
0-based indices with sorted-array lookups, never with an offset.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.gocad._records import ErrorFactory
from geobrep.geometry.arrays import FloatArray, IntArray

__all__ = ["CellTable", "VertexTable"]


class _Pending:
    """Vertex lines read one at a time, not yet made arrays (a plain class: a dataclass costs
    about 0.4 ms to make at import)."""

    __slots__ = ("coordinates", "flags", "ids", "lines", "refs", "values")

    def __init__(self) -> None:
        self.ids: list[int] = []
        self.coordinates: list[tuple[float, float, float]] = []
        self.refs: list[int] = []
        self.values: list[list[float]] = []
        self.flags: list[int] = []
        self.lines: list[int] = []


class VertexTable:
    """Vertices in declaration order: ids, coordinates, property values, flags, lines."""

    def __init__(self, n_values: int, absent_limit: int | None = None) -> None:
        self.n_values = n_values
        self.absent = 0
        """Property values the file does not hold: vertices without values (VRTX lines, ATOM
        lines inheriting theirs) times ``n_values``."""
        self.absent_limit = absent_limit
        self._chunks: list[
            tuple[IntArray, FloatArray, IntArray, FloatArray, NDArray[np.int8], IntArray]
        ] = []
        self._pending = _Pending()

    def add(
        self,
        vertex_id: int,
        xyz: tuple[float, float, float] | None,
        ref: int | None,
        values: list[float] | None,
        flag: int,
        line: int,
    ) -> None:
        """One VRTX/PVRTX (``xyz``) or ATOM/PATOM (``ref``) line; ``values=None``: inherit."""
        pending = self._pending
        pending.ids.append(vertex_id)
        pending.coordinates.append(xyz if xyz is not None else (np.nan, np.nan, np.nan))
        pending.refs.append(-1 if ref is None else ref)
        pending.values.append(values if values is not None else [np.nan] * self.n_values)
        pending.flags.append(flag)
        pending.lines.append(line)
        if values is None and self.n_values:
            pending.flags[-1] |= _INHERIT

    def allow_absent(self, rows: int) -> int | None:
        """Count ``rows`` vertices that carry no values of their own; ``None`` while the values
        filled in for them stay within ``absent_limit``, else the index of the row past it."""
        before, self.absent = self.absent, self.absent + rows * self.n_values
        if self.absent_limit is None or self.absent <= self.absent_limit:
            return None
        return max(0, (self.absent_limit - before) // self.n_values)

    def add_block(
        self, ids: IntArray, xyz: FloatArray, values: FloatArray, first_line: int
    ) -> None:
        """A bulk run of VRTX/PVRTX lines."""
        self._flush()
        n = ids.shape[0]
        self._chunks.append(
            (
                ids,
                xyz,
                np.full(n, -1, dtype=np.int64),
                values,
                np.zeros(n, dtype=np.int8),
                np.arange(first_line, first_line + n, dtype=np.int64),
            )
        )

    def add_rows(
        self,
        ids: IntArray,
        xyz: FloatArray,
        refs: IntArray,
        values: FloatArray,
        flags: NDArray[np.int8],
        lines: IntArray,
    ) -> None:
        """Vertex lines of every kind in file order (a body read in bulk): ``refs`` -1 but
        for ATOM / PATOM lines, ``flags`` 64 where an ATOM inherits its vertex's values."""
        self._flush()
        if ids.shape[0]:
            self._chunks.append((ids, xyz, refs, values, flags, lines))

    def add_atoms(
        self, ids: IntArray, refs: IntArray, first_line: int, values: FloatArray | None = None
    ) -> None:
        """A bulk run of ATOM lines (new ids at the positions of earlier ones, values
        inherited) or of PATOM lines (``values``: their own)."""
        self._flush()
        n = ids.shape[0]
        inherit = values is None and self.n_values
        self._chunks.append(
            (
                ids,
                np.full((n, 3), np.nan),
                refs,
                np.full((n, self.n_values), np.nan) if values is None else values,
                np.full(n, _INHERIT if inherit else 0, dtype=np.int8),
                np.arange(first_line, first_line + n, dtype=np.int64),
            )
        )

    def _flush(self) -> None:
        pending = self._pending
        if not pending.ids:
            return
        self._chunks.append(
            (
                np.asarray(pending.ids, dtype=np.int64),
                np.asarray(pending.coordinates, dtype=np.float64).reshape(-1, 3),
                np.asarray(pending.refs, dtype=np.int64),
                np.asarray(pending.values, dtype=np.float64).reshape(
                    len(pending.ids), self.n_values
                ),
                np.asarray(pending.flags, dtype=np.int8),
                np.asarray(pending.lines, dtype=np.int64),
            )
        )
        self._pending = _Pending()

    @property
    def count(self) -> int:
        return int(sum(c[0].shape[0] for c in self._chunks)) + len(self._pending.ids)

    def finish(self, error: ErrorFactory) -> ResolvedVertices:
        """Resolve ATOM references; ``error(message, line)`` builds the FormatError to raise."""
        self._flush()
        if not self._chunks:
            empty = np.zeros(0, dtype=np.int64)
            return ResolvedVertices(
                empty,
                np.zeros((0, 3)),
                np.zeros((0, self.n_values)),
                empty.astype(np.int8),
                empty,
                empty.copy(),
                empty.copy(),
            )
        ids = np.concatenate([c[0] for c in self._chunks])
        xyz = np.concatenate([c[1] for c in self._chunks])
        refs = np.concatenate([c[2] for c in self._chunks])
        values = np.concatenate([c[3] for c in self._chunks])
        flags = np.concatenate([c[4] for c in self._chunks])
        lines = np.concatenate([c[5] for c in self._chunks])
        if bool((ids[1:] > ids[:-1]).all()):  # declared in increasing order: no sort
            order = np.arange(ids.shape[0], dtype=np.int64)
            sorted_ids = ids
            repeated = np.zeros(0, dtype=np.int64)
        else:
            order = np.argsort(ids, kind="stable")
            sorted_ids = ids[order]
            repeated = np.flatnonzero(sorted_ids[1:] == sorted_ids[:-1])
        if repeated.size:
            first, second = sorted((int(order[repeated[0]]), int(order[repeated[0] + 1])))
            raise error(
                f"vertex id {int(ids[second])} is already defined on line {int(lines[first])}",
                int(lines[second]),
            )
        lookup = IdLookup(sorted_ids, order)
        atoms = np.flatnonzero(refs >= 0) if refs.size else np.zeros(0, dtype=np.int64)
        atom_of = np.full(ids.shape[0], -1, dtype=np.int64)
        if atoms.size:
            targets, found = lookup.find(refs[atoms])
            bad = np.flatnonzero(~found | (targets >= atoms))
            if bad.size:
                k = int(atoms[bad[0]])
                raise error(
                    f"ATOM {int(ids[k])} refers to vertex {int(refs[k])} which is not defined "
                    "before it",
                    int(lines[k]),
                )
            atom_of[atoms] = targets
            root = targets.copy()
            while True:  # ATOM of an ATOM: follow to the vertex that has coordinates
                deeper = atom_of[root]
                chained = deeper >= 0
                if not chained.any():
                    break
                root = np.where(chained, deeper, root)
            xyz[atoms] = xyz[root]
            inherit = (flags[atoms] & _INHERIT) != 0
            if inherit.any():
                values[atoms[inherit]] = values[root[inherit]]
        flags = flags & ~_INHERIT
        return ResolvedVertices(ids, xyz, values, flags.astype(np.int8), lines, atom_of, order)


_INHERIT = 64


class ResolvedVertices(NamedTuple):
    """The vertices of an object once ATOM references are resolved."""

    ids: IntArray
    xyz: FloatArray
    values: FloatArray
    flags: NDArray[np.int8]
    lines: IntArray
    atom_of: IntArray  # index of the referenced vertex for ATOM lines, else -1
    order: IntArray  # argsort of ids

    @property
    def lookup(self) -> IdLookup:
        return IdLookup(self.ids[self.order], self.order)


class IdLookup:
    """Vectorised id → index lookup over sorted ids."""

    def __init__(self, sorted_ids: IntArray, order: IntArray) -> None:
        self.sorted_ids = sorted_ids
        self.order = order
        n = sorted_ids.shape[0]
        # Ids declared in order as first, first + 1, ... (the usual case): index = id - first.
        self.first = int(sorted_ids[0]) if n else 0
        self.consecutive = bool(
            n and int(sorted_ids[-1]) - self.first == n - 1 and np.array_equal(order, np.arange(n))
        )

    def find(self, ids: NDArray[Any]) -> tuple[IntArray, NDArray[np.bool_]]:
        """Indices of ``ids`` and whether each was found."""
        flat = np.asarray(ids, dtype=np.int64).reshape(-1)
        if self.sorted_ids.size == 0:  # no vertices: nothing is found (shaped like ``ids``)
            return np.zeros(np.shape(ids), dtype=np.int64), np.zeros(np.shape(ids), dtype=bool)
        if self.consecutive:
            index = flat - self.first
            found = (index >= 0) & (index < self.sorted_ids.shape[0])
            if not found.all():
                index = np.where(found, index, 0)
            return index.reshape(np.shape(ids)), found.reshape(np.shape(ids))
        pos = np.searchsorted(self.sorted_ids, flat)
        pos = np.minimum(pos, self.sorted_ids.shape[0] - 1)
        found = self.sorted_ids[pos] == flat
        return self.order[pos].reshape(np.shape(ids)), found.reshape(np.shape(ids))

    def require(
        self, ids: IntArray, lines: IntArray, keyword: str, error: ErrorFactory
    ) -> IntArray:
        """Indices of ``ids`` (rows of a cell table); FormatError naming the first unknown id."""
        index, found = self.find(ids)
        if not found.all():
            bad = np.argwhere(~found)[0]
            row = int(bad[0])
            missing = int(ids[tuple(bad)])
            raise error(
                f"{keyword} refers to vertex {missing} which is not defined", int(lines[row])
            )
        return index


class CellTable:
    """Cells (TRGL, SEG, TETRA) as vertex ids, with values, part labels and line numbers."""

    def __init__(self, width: int, n_values: int) -> None:
        self.width = width
        self.n_values = n_values
        self._chunks: list[tuple[IntArray, FloatArray, IntArray, IntArray]] = []
        self._rows: list[list[int]] = []
        self._values: list[list[float]] = []
        self._parts: list[int] = []
        self._lines: list[int] = []

    def add(self, ids: list[int], values: list[float], part: int, line: int) -> None:
        self._rows.append(ids)
        self._values.append(values)
        self._parts.append(part)
        self._lines.append(line)

    def add_block(self, ids: IntArray, values: FloatArray, part: int, first_line: int) -> None:
        self._flush()
        n = ids.shape[0]
        self._chunks.append(
            (
                ids,
                values,
                np.full(n, part, dtype=np.int64),
                np.arange(first_line, first_line + n, dtype=np.int64),
            )
        )

    def add_rows(self, ids: IntArray, values: FloatArray, parts: IntArray, lines: IntArray) -> None:
        """Cell lines with their part indices (a body read in bulk)."""
        self._flush()
        if ids.shape[0]:
            self._chunks.append((ids, values, parts, lines))

    def _flush(self) -> None:
        if not self._rows:
            return
        self._chunks.append(
            (
                np.asarray(self._rows, dtype=np.int64).reshape(-1, self.width),
                np.asarray(self._values, dtype=np.float64).reshape(len(self._rows), self.n_values),
                np.asarray(self._parts, dtype=np.int64),
                np.asarray(self._lines, dtype=np.int64),
            )
        )
        self._rows, self._values, self._parts, self._lines = [], [], [], []

    @property
    def count(self) -> int:
        return int(sum(c[0].shape[0] for c in self._chunks)) + len(self._rows)

    def finish(self) -> tuple[IntArray, FloatArray, IntArray, IntArray]:
        """``(vertex_ids (M, width), values (M, n_values), parts (M,), lines (M,))``."""
        self._flush()
        if not self._chunks:
            return (
                np.zeros((0, self.width), dtype=np.int64),
                np.zeros((0, self.n_values)),
                np.zeros(0, dtype=np.int64),
                np.zeros(0, dtype=np.int64),
            )
        return (
            np.concatenate([c[0] for c in self._chunks]),
            np.concatenate([c[1] for c in self._chunks]),
            np.concatenate([c[2] for c in self._chunks]),
            np.concatenate([c[3] for c in self._chunks]),
        )


def check_finite_ids(
    error: ErrorFactory, values: FloatArray, first_line: int, keyword: str
) -> IntArray:
    """Vertex ids read as floats in a bulk run → int64; FormatError when not integral."""
    column = values[:, 0]
    bad = np.flatnonzero(column != np.floor(column))
    if bad.size:
        raise error(f"{keyword} id {column[bad[0]]!r} is not an integer", first_line + int(bad[0]))
    if column.size and np.abs(column).max() > 2**53:
        row = int(np.argmax(np.abs(column) > 2**53))
        raise error(f"{keyword} id {column[row]!r} is too large", first_line + row)
    return column.astype(np.int64)
