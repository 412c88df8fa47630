"""The body of a TSurf, PLine or VSet read in bulk: all its element lines at once.

The body of an object is everything from its first data line to its ``END``: runs of
``VRTX`` / ``PVRTX`` / ``ATOM`` / ``PATOM`` lines, runs of cell lines (``TRGL`` or ``SEG``),
part lines (``TFACE``, ``ILINE``, ``SUBVSET``) and ``BSTONE`` / ``BORDER`` lines. Rather than
walking it run by run, :func:`read_body` classifies every line of the body with the file's
keyword codes (:attr:`Source.codes`, numpy over the line starts), parses all the lines of
each keyword in one go (:func:`~geobrep.adapters.gocad._lexer.parse_rows`) and puts the rows
back in file order with array operations: a few Python steps per object, not per run or line.

It reads only bodies it can read exactly as the run-by-run parser does. Anything else (a
line it does not know, a flag word, a ragged or non-numeric row, data before the first part,
a non-finite property value, more filled-in values than allowed) makes it return None, and
the parser reads the object as before, with its warnings and its error messages naming the
line.
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.gocad._lexer import KEYWORDS, BulkParseError, Run, Source, parse_rows
from geobrep.adapters.gocad._numbers import parse_int
from geobrep.adapters.gocad._records import Border, BStone
from geobrep.geometry.arrays import FloatArray, IntArray

__all__ = ["BULK_BODIES", "Body", "VertexRows", "read_body"]

#: Read the bodies of TSurfs, PLines and VSets in bulk (tests turn it off to compare).
BULK_BODIES = True

#: Object type -> (its cell keyword and cell width, the keywords that start a part).
_KINDS: dict[str, tuple[str | None, int, tuple[str, ...]]] = {
    "TSurf": ("TRGL", 3, ("TFACE", "3DFACE", "ILINE", "TVOLUME", "SUBVSET")),
    "PLine": ("SEG", 2, ("TFACE", "3DFACE", "ILINE", "TVOLUME", "SUBVSET")),
    "VSet": (None, 0, ("SUBVSET",)),
}
_VERTEX_KEYWORDS = ("VRTX", "PVRTX", "ATOM", "PATOM")
_ID_LIMIT = 2**53  # ids read as floats are exact below this
#: Flag of a vertex whose property values come from the vertex it refers to (_tables).
INHERIT = 64


@dataclass(frozen=True)
class VertexRows:
    """The vertex lines of a body in file order (the columns of a vertex table chunk)."""

    ids: IntArray
    xyz: FloatArray
    refs: IntArray  # the vertex an ATOM / PATOM line refers to, else -1
    values: FloatArray
    flags: NDArray[np.int8]
    lines: IntArray


@dataclass(frozen=True)
class Body:
    """What :func:`read_body` read: the body's rows, and where it ends."""

    end: int
    """0-based index of the body's ``END`` line."""
    parts: list[tuple[str, str, int, int]]
    """Each part line: its keyword, its text, its line number and the vertices before it."""
    vertices: VertexRows
    absent_rows: int
    """Vertices without property values of their own when the object declares some."""
    cells: tuple[IntArray, FloatArray, IntArray, IntArray] | None
    """Cell vertex ids, values, part indices and line numbers (None for a VSet)."""
    bstones: list[BStone]
    borders: list[Border]


def _keyword(text: str) -> str:
    head = text.split(None, 1)
    return head[0].upper() if head else ""


def _row_lines(runs: list[Run]) -> IntArray:
    """The 1-based line numbers of the lines of ``runs``."""
    if len(runs) == 1:
        return np.arange(runs[0].first, runs[0].first + runs[0].count, dtype=np.int64)
    counts = np.array([run.count for run in runs], dtype=np.int64)
    firsts = np.array([run.first for run in runs], dtype=np.int64)
    offsets = np.cumsum(counts) - counts
    which = np.repeat(np.arange(len(runs)), counts)
    lines: IntArray = firsts[which] + (np.arange(which.shape[0]) - offsets[which])
    return lines


def _body_end(
    source: Source, lo: int, parts_allowed: tuple[str, ...]
) -> tuple[int, list[tuple[str, str, int]]] | None:
    """The 0-based index of the ``END`` that closes the body starting at line ``lo`` and the
    body's part lines (keyword, text, 1-based line); None when the body holds a line of
    another kind (the parser reads it)."""
    others = source.others
    parts: list[tuple[str, str, int]] = []
    for index in others[bisect.bisect_left(others, lo) :]:
        text = source.text(index).strip()
        if not text or (text.startswith("#") and not text.startswith("# CTETRA")):
            continue
        keyword = _keyword(text)
        if keyword == "END":
            return index, parts
        if keyword not in parts_allowed:
            return None
        parts.append((keyword, text, index + 1))
    return None


def _ids(block: NDArray[np.float64] | IntArray, columns: int) -> IntArray | None:
    """The first ``columns`` columns of a parsed block as int64 ids (None unless integral)."""
    ids = block[:, :columns]
    if ids.dtype == np.int64:
        return np.ascontiguousarray(ids)
    if ids.size and ((ids != np.floor(ids)).any() or (np.abs(ids) > _ID_LIMIT).any()):
        return None
    return np.ascontiguousarray(ids, dtype=np.int64)


def _single_ids_exact(source: Source, runs: list[Run], columns: int) -> bool:
    """Runs of one line are read line by line today, where an id must be an integer token
    (``1.0`` is not): the ids of those lines, checked that way."""
    for run in runs:
        if run.count > 1:
            continue
        tokens = source.text(run.first - 1).split()
        try:
            for token in tokens[1 : 1 + columns]:
                parse_int(token)
        except ValueError:
            return False
    return True


def read_body(
    source: Source,
    first: int,
    kind: str,
    n_point: int,
    n_cell: int,
    absent_room: int | None,
) -> Body | None:
    """The body of a ``kind`` object whose first data line is line ``first`` (1-based), or
    None when the body is not one this bulk reader reads exactly as the parser does.

    ``n_point`` / ``n_cell``: property values per vertex and per cell; ``absent_room``: how
    many more property values the vertex table may fill in (None: no limit).
    """
    if not BULK_BODIES or kind not in _KINDS:
        return None
    cell_keyword, _, part_keywords = _KINDS[kind]
    lo = first - 1
    found = _body_end(source, lo, part_keywords)
    if found is None:
        return None
    end, part_lines = found
    table = _FileRuns.of(source)
    runs: dict[str, list[int]] = {}
    for index in range(*table.between(lo, end)):
        runs.setdefault(table.runs[index].keyword, []).append(index)
    allowed = {*_VERTEX_KEYWORDS, "BSTONE", "BORDER"}
    if cell_keyword is not None:
        allowed.add(cell_keyword)
    if not allowed.issuperset(runs) or ("PATOM" in runs and not n_point):
        return None
    try:
        return _read(table, runs, part_lines, end, kind, n_point, n_cell, absent_room)
    except BulkParseError:
        return None


class _FileRuns:
    """Every run of lines of one of :data:`KEYWORDS` in a file, and their numbers parsed
    together: the runs of a keyword whose first lines have as many blanks make one group,
    parsed in one go the first time a body needs one of them (a group the bulk parse
    rejects is left unparsed: each body then parses its own runs)."""

    def __init__(self, source: Source) -> None:
        self.source = source
        codes = source.codes
        change = np.flatnonzero(codes[1:] != codes[:-1]) + 1
        bounds = np.concatenate([[0], change, [codes.shape[0]]])
        lo, hi = bounds[:-1], bounds[1:]
        keep = codes[lo] != 0
        lo, hi = lo[keep], hi[keep]
        self.firsts: list[int] = (lo + 1).tolist()
        self.runs = [
            Run(KEYWORDS[code - 1], first, count, start, end)
            for code, first, count, start, end in zip(
                codes[lo].tolist(),
                self.firsts,
                (hi - lo).tolist(),
                source.starts[lo].tolist(),
                source.ends[hi - 1].tolist(),
                strict=True,
            )
        ]
        self._place: dict[int, tuple[int, int]] = {}  # run -> (group, first row)
        self._blocks: list[NDArray[np.float64] | IntArray | None] = []
        self._parsed: set[str] = set()
        # keyword -> first-line width (blanks) -> its runs, in file order (made once)
        self._groups: dict[str, dict[int, list[int]]] | None = None

    @classmethod
    def of(cls, source: Source) -> _FileRuns:
        found = source.cache.get(cls)
        if not isinstance(found, cls):
            found = source.cache[cls] = cls(source)
        return found

    def between(self, lo: int, end: int) -> tuple[int, int]:
        """The indices of the runs within the 0-based lines ``[lo, end)``."""
        return bisect.bisect_left(self.firsts, lo + 1), bisect.bisect_left(self.firsts, end + 1)

    def rows(self, indices: list[int], integer: bool) -> NDArray[np.float64] | IntArray:
        """The numbers of the runs ``indices`` (runs of one keyword, in file order), as
        :func:`parse_rows` reads them; BulkParseError when it cannot."""
        keyword = self.runs[indices[0]].keyword
        if keyword not in self._parsed:
            self._parse_groups(keyword)
        group, offset = self._place.get(indices[0], (-1, 0))
        block = self._blocks[group] if group >= 0 else None
        count = sum(self.runs[i].count for i in indices)
        last_group, last_offset = self._place.get(indices[-1], (-2, 0))
        if (
            block is None
            or last_group != group
            or last_offset + self.runs[indices[-1]].count - offset != count
            or (integer and block.dtype != np.int64)
        ):
            return parse_rows(self.source, [self.runs[i] for i in indices], integer)
        return block[offset : offset + count]

    def _width_groups(self) -> dict[str, dict[int, list[int]]]:
        """The runs of each keyword by the number of blanks of their first line (a blank
        ending it aside), in file order."""
        if self._groups is None:
            data = self.source.data
            self._groups = {}
            first_ends = self.source.ends[[run.first - 1 for run in self.runs]].tolist()
            for index, (run, first_end) in enumerate(zip(self.runs, first_ends, strict=True)):
                width = data.count(b" ", run.start, first_end) - (data[first_end - 1] == 32)
                self._groups.setdefault(run.keyword, {}).setdefault(width, []).append(index)
        return self._groups

    def _parse_groups(self, keyword: str) -> None:
        self._parsed.add(keyword)
        for indices in self._width_groups().get(keyword, {}).values():
            try:
                block = parse_rows(self.source, [self.runs[i] for i in indices], False)
            except BulkParseError:
                continue
            self._blocks.append(block)
            offset = 0
            for index in indices:
                self._place[index] = (len(self._blocks) - 1, offset)
                offset += self.runs[index].count


def _read(
    table: _FileRuns,
    runs: dict[str, list[int]],
    part_lines: list[tuple[str, str, int]],
    end: int,
    kind: str,
    n_point: int,
    n_cell: int,
    absent_room: int | None,
) -> Body | None:
    cell_keyword, cell_width, _ = _KINDS[kind]
    source = table.source
    first_part = part_lines[0][2] if part_lines else None
    pieces: list[tuple[IntArray, FloatArray, IntArray, FloatArray, NDArray[np.int8], IntArray]]
    pieces = []
    # vertices without values of their own, counted before any is filled in
    absent_rows = (
        sum(table.runs[i].count for k in ("VRTX", "ATOM") for i in runs.get(k, ()))
        if n_point
        else 0
    )
    if absent_rows and absent_room is not None and absent_rows * n_point > absent_room:
        return None  # the parser names the line past the limit
    for keyword in _VERTEX_KEYWORDS:
        indices = runs.get(keyword)
        if not indices:
            continue
        these = [table.runs[i] for i in indices]
        if kind != "VSet" and (first_part is None or these[0].first < first_part):
            return None  # data before any part: the parser warns and starts one
        atom = keyword in ("ATOM", "PATOM")
        own_values = keyword in ("PVRTX", "PATOM")
        id_columns = 2 if atom else 1
        width = (2 if atom else 4) + (n_point if own_values else 0)
        block = table.rows(indices, integer=keyword == "ATOM")
        if block.shape[1] != width:
            return None
        ids = _ids(block, id_columns)
        if ids is None or not _single_ids_exact(source, these, id_columns):
            return None
        n = block.shape[0]
        if own_values:
            values = np.ascontiguousarray(block[:, width - n_point :], dtype=np.float64)
            if not np.isfinite(values).all():
                return None  # the parser counts and reports them
        else:
            values = np.full((n, n_point), np.nan)
        xyz = (
            np.full((n, 3), np.nan)
            if atom
            else np.ascontiguousarray(block[:, 1:4], dtype=np.float64)
        )
        inherit = INHERIT if keyword == "ATOM" and n_point else 0
        pieces.append(
            (
                ids[:, 0],
                xyz,
                ids[:, 1] if atom else np.full(n, -1, dtype=np.int64),
                values,
                np.full(n, inherit, dtype=np.int8),
                _row_lines(these),
            )
        )
    if not pieces:
        vertices = VertexRows(
            np.zeros(0, dtype=np.int64),
            np.zeros((0, 3)),
            np.zeros(0, dtype=np.int64),
            np.zeros((0, n_point)),
            np.zeros(0, dtype=np.int8),
            np.zeros(0, dtype=np.int64),
        )
    elif len(pieces) == 1:
        vertices = VertexRows(*pieces[0])
    else:
        columns = [np.concatenate(column) for column in zip(*pieces, strict=True)]
        order = np.argsort(columns[5], kind="stable")
        vertices = VertexRows(*(column[order] for column in columns))
    vertex_lines = vertices.lines
    parts = [
        (keyword, text, line, start)
        for (keyword, text, line), start in zip(
            part_lines,
            np.searchsorted(vertex_lines, [line for _, _, line in part_lines]).tolist(),
            strict=True,
        )
    ]
    cells = None
    if cell_keyword is not None:
        cells = _cells(table, runs.get(cell_keyword), part_lines, cell_width, n_cell)
        if cells is None:
            return None
    bstones: list[BStone] = []
    borders: list[Border] = []
    if "BSTONE" in runs:
        block = table.rows(runs["BSTONE"], integer=True)
        if block.shape[1] != 1:
            return None
        lines = _row_lines([table.runs[i] for i in runs["BSTONE"]]).tolist()
        bstones = list(map(BStone._make, zip(block[:, 0].tolist(), lines, strict=True)))
    if "BORDER" in runs:
        block = table.rows(runs["BORDER"], integer=True)
        if block.shape[1] != 3:
            return None
        lines = _row_lines([table.runs[i] for i in runs["BORDER"]]).tolist()
        borders = [
            Border(a, b, c, line) for (a, b, c), line in zip(block.tolist(), lines, strict=True)
        ]
    return Body(end, parts, vertices, absent_rows, cells, bstones, borders)


def _cells(
    table: _FileRuns,
    indices: list[int] | None,
    part_lines: list[tuple[str, str, int]],
    width: int,
    n_cell: int,
) -> tuple[IntArray, FloatArray, IntArray, IntArray] | None:
    """The cell lines of a body: vertex ids, values, part indices, line numbers."""
    if not indices:
        empty = np.zeros(0, dtype=np.int64)
        return np.zeros((0, width), dtype=np.int64), np.zeros((0, n_cell)), empty, empty.copy()
    runs = [table.runs[i] for i in indices]
    if not part_lines or runs[0].first < part_lines[0][2]:
        return None  # a cell before any part: the parser warns and starts one
    block = table.rows(indices, integer=not n_cell)
    if block.shape[1] != width + n_cell:
        return None
    ids = _ids(block, width)
    if ids is None or (n_cell and not _single_ids_exact(table.source, runs, width)):
        return None
    values = np.ascontiguousarray(block[:, width:], dtype=np.float64)
    if n_cell and not np.isfinite(values).all():
        return None
    lines = _row_lines(runs)
    part_starts = np.array([line for _, _, line in part_lines], dtype=np.int64)
    parts = np.searchsorted(part_starts, lines) - 1
    return ids, values, parts.astype(np.int64), lines
