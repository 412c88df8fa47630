"""Parse a GOCAD ASCII file into :class:`GocadObject` records (no geobrep entities yet).

One object is ``GOCAD <Type> <version>``, ``HEADER {...}``, an optional CRS block, geology
lines, property headers, a body and ``END``. Files can hold several objects and groups
(``BEGIN_MEMBERS ... END_MEMBERS``). Unknown object types (SGrid, Voxet, Well, ...) are
skipped with a warning. Every recovered oddity is a :class:`GocadWarning`; every
unrecoverable one a :class:`~geobrep.errors.FormatError` with the path and line.
"""

from __future__ import annotations

import math
import re
import warnings
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.gocad._bodies import read_body
from geobrep.adapters.gocad._headers import (
    PROPERTY_KEYWORDS,
    PropertyHeader,
    parse_property_line,
)
from geobrep.adapters.gocad._lexer import (
    BulkParseError,
    Line,
    Run,
    Source,
    decode,
    parse_run,
    scan,
    split_tokens,
)
from geobrep.adapters.gocad._numbers import INT_LIMIT, parse_float, parse_int
from geobrep.adapters.gocad._records import (
    Border,
    BStone,
    CellRows,
    CrsBlock,
    CTetra,
    Geology,
)
from geobrep.adapters.gocad._tables import (
    CellTable,
    ResolvedVertices,
    VertexTable,
    check_finite_ids,
)
from geobrep.adapters.limits import human_bytes, read_budget
from geobrep.errors import FormatError
from geobrep.model.entities import Entity

if TYPE_CHECKING:  # made for a Model3d, TSolid or LightTSolid object only
    from geobrep.adapters.gocad._model_records import (
        ListDraft,
        Model3dHeader,
        ModelDraft,
        SolidDraft,
        SolidModel,
        SolidTFaceDraft,
    )

__all__ = ["GocadObject", "GocadWarning", "parse_source"]

#: Object types with a reader, by lowercase spelling (``Vset`` and ``PLINE`` occur).
KNOWN_TYPES = {
    "tsurf": "TSurf",
    "pline": "PLine",
    "vset": "VSet",
    "tsolid": "TSolid",
    "lighttsolid": "LightTSolid",
    "model3d": "Model3d",
    "heterogeneousgroup": "HeterogeneousGroup",
    "homogeneousgroup": "HomogeneousGroup",
}
GROUP_TYPES = ("HeterogeneousGroup", "HomogeneousGroup")
#: Object types a group member may be that are read by their own line readers (side files).
GRID_MEMBER_TYPES = {"voxet": "Voxet", "sgrid": "SGrid", "well": "Well"}
FLAG_NAMES = {"CNXYZ": 1, "XYZ": 2}
_CELL_PREFIX = {"TSurf": "TRGL_", "PLine": "SEG_", "TSolid": "TETRA_", "LightTSolid": "TETRA_"}
_ABSENT_SHARE = 8
_CELL_WIDTH = {"TSurf": 3, "PLine": 2, "TSolid": 4, "LightTSolid": 4, "Model3d": 3}
_CELL_KEYWORD = {"TSurf": "TRGL", "PLine": "SEG", "TSolid": "TETRA", "LightTSolid": "TETRA"}
_PART_KEYWORDS = {"TFACE", "3DFACE", "ILINE", "TVOLUME", "SUBVSET"}
#: Keywords that start the data of an object (the first one sizes the vertex and cell tables).
_DATA_KEYWORDS = {
    "VRTX",
    "PVRTX",
    "ATOM",
    "PATOM",
    "SHAREDVRTX",
    "SHAREDPVRTX",
    "TRGL",
    "SEG",
    "TETRA",
    "BSTONE",
    "BORDER",
    "MODEL",
    *_PART_KEYWORDS,
}
_SKIP_BLOCKS = {
    "BEGIN_ATOM_REGION_INDICATORS": "END_ATOM_REGION_INDICATORS",
    "BEGIN_VERTEX_REGION_INDICATORS": "END_VERTEX_REGION_INDICATORS",
    "PROPERTY_CN": "END_PROPERTY_CN",
}


class GocadWarning(UserWarning):
    """A recoverable oddity in a GOCAD file (the message says where and what was done)."""


@dataclass
class GocadObject:
    """One object of a GOCAD file, parsed but not yet turned into entities."""

    type: str
    version: str
    line: int
    header: list[tuple[str, str]] = field(default_factory=list)
    crs: CrsBlock | None = None
    inherited_crs: bool = False  # crs is a group's, given to its member by the reader
    geology: Geology = field(default_factory=dict)
    point_header: PropertyHeader = field(default_factory=PropertyHeader)
    cell_header: PropertyHeader = field(default_factory=PropertyHeader)
    class_headers: dict[str, dict[str, str]] = field(default_factory=dict)
    vertices: ResolvedVertices | None = None
    cells: CellRows | None = None
    part_names: list[str] = field(default_factory=list)
    part_vertex_starts: list[int] = field(default_factory=list)
    part_lines: list[int] = field(default_factory=list)  # where each part starts
    declared_parts: int = 0  # TFACE / ILINE / TVOLUME / SUBVSET lines (not implicit parts)
    nonfinite: dict[tuple[str, int], tuple[int, int]] = field(default_factory=dict)
    """(``"point"``/``"cell"``, property index) → (count, first line) of non-finite values."""
    bstones: list[BStone] = field(default_factory=list)
    borders: list[Border] = field(default_factory=list)
    ctetra: list[CTetra] = field(default_factory=list)
    header_of_model: Model3dHeader | None = None  # a Model3d's (see model3d)
    model_of_solid: SolidModel | None = None  # a TSolid's MODEL section (see solid_model)
    member_type: str | None = None  # a group's TYPE line
    members: list[GocadObject] = field(default_factory=list)
    extra_lines: list[str] = field(default_factory=list)
    grid: Entity | None = None  # a Voxet, SGrid or Well member, read by its own reader

    @property
    def model3d(self) -> Model3dHeader:
        """What a Model3d's header declares (an empty header for other objects)."""
        if self.header_of_model is None:
            from geobrep.adapters.gocad._model_records import Model3dHeader

            self.header_of_model = Model3dHeader()
        return self.header_of_model

    @property
    def solid_model(self) -> SolidModel:
        """A TSolid's MODEL section (an empty one for other objects)."""
        if self.model_of_solid is None:
            from geobrep.adapters.gocad._model_records import SolidModel

            self.model_of_solid = SolidModel()
        return self.model_of_solid

    @property
    def name(self) -> str:
        for key, value in self.header:
            if key.lower() == "name":
                return value
        return ""

    def header_value(self, key: str) -> str | None:
        for k, value in self.header:
            if k == key:
                return value
        return None


class _Stream:
    """Items of the file with one-item look-ahead."""

    def __init__(self, source: Source) -> None:
        self.source = source
        self._items: Iterator[Line | Run] = scan(source)
        self._next: Line | Run | None = None

    def peek(self) -> Line | Run | None:
        if self._next is None:
            self._next = next(self._items, None)
        return self._next

    def take(self) -> Line | Run | None:
        item = self.peek()
        self._next = None
        return item

    def skip_to(self, index: int) -> None:
        """Go on from the 0-based line ``index`` (lines before it were read in bulk)."""
        self._items = scan(self.source, index)
        self._next = None


def _keyword(text: str) -> str:
    head = text.split(None, 1)
    return head[0].upper() if head else ""


class _Parser:
    def __init__(self, source: Source) -> None:
        self.source = source
        self.stream = _Stream(source)
        self.skipped: list[str] = []
        """What was in the file and is not read (objects of unknown type, skipped blocks)."""

    # -- diagnostics ----------------------------------------------------------------------------
    def error(self, message: str, line: int | None) -> FormatError:
        return FormatError(message, self.source.path, line)

    def warn(self, message: str, line: int | None) -> None:
        where = f"{self.source.path.name}:{line}: " if line is not None else ""
        warnings.warn(f"{where}{message}", GocadWarning, stacklevel=6)

    # -- objects --------------------------------------------------------------------------------
    def parse_all(self) -> list[GocadObject]:
        objects: list[GocadObject] = []
        while True:
            item = self.stream.take()
            if item is None:
                break
            if isinstance(item, Run):
                raise self.error(
                    f"{item.keyword} line outside an object (expected 'GOCAD <type>')", item.first
                )
            if _keyword(item.text) != "GOCAD":
                raise self.error(
                    f"expected 'GOCAD <type>' to start an object, found {item.text[:40]!r}",
                    item.number,
                )
            parsed = self.parse_object(item)
            if parsed is not None:
                objects.append(parsed)
        if not objects:
            raise self.error("no GOCAD object with a known type in the file", None)
        return objects

    def parse_object(self, start: Line, group: GocadObject | None = None) -> GocadObject | None:
        tokens = start.text.split()
        if len(tokens) < 2:
            raise self.error("'GOCAD' without an object type", start.number)
        kind = KNOWN_TYPES.get(tokens[1].lower())
        grid_kind = GRID_MEMBER_TYPES.get(tokens[1].lower())
        if grid_kind is not None and group is not None:
            return self._grid_member(start, grid_kind, tokens, group)
        if kind is None:
            self.warn(f"skipping GOCAD {tokens[1]} object (no reader for this type)", start.number)
            name = self._skip_object()
            named = f" {name!r}" if name else ""
            self.skipped.append(
                f"GOCAD {tokens[1]}{named} (line {start.number}): no reader for this type"
            )
            return None
        obj = GocadObject(kind, tokens[2] if len(tokens) > 2 else "1", start.number)
        if kind in _CELL_WIDTH or kind in ("VSet",):
            self._parse_body(obj)
        else:
            self._parse_group(obj)
        return obj

    def _skip_object(self) -> str | None:
        """Pass over an object of unknown type; its header ``name`` if it has one."""
        return self._object_end(0)[0]

    def _object_end(self, last: int) -> tuple[str | None, int]:
        """Pass over an object up to its ``END``: its header ``name`` if it has one, and the
        number of its last line (``last`` if it has no line after its ``GOCAD`` line)."""
        name = None
        while True:
            item = self.stream.peek()
            if item is None:
                return name, last
            if isinstance(item, Line):
                keyword = _keyword(item.text)
                if keyword == "GOCAD":
                    self.warn("object without END before the next 'GOCAD' line", item.number)
                    return name, last
                self.stream.take()
                last = item.number
                if keyword == "END":
                    return name, last
                if name is None and item.text.lstrip().lower().startswith("name:"):
                    name = item.text.split(":", 1)[1].strip() or None
            else:
                self.stream.take()
                last = item.first + item.count - 1

    def _grid_member(
        self, start: Line, kind: str, tokens: list[str], group: GocadObject
    ) -> GocadObject:
        """A Voxet, SGrid or Well inside a group, read by its own reader from its lines (with
        the lines before it blank, so that errors give the group file's line numbers); its side
        files are found beside the group file."""
        from geobrep.adapters.gocad._grid_members import read_member

        _, last = self._object_end(start.number)
        data = self.source.data[self.source.starts[start.number - 1] : self.source.ends[last - 1]]
        text = "\n" * (start.number - 1) + decode(data)
        obj = GocadObject(kind, tokens[2] if len(tokens) > 2 else "1", start.number)
        obj.grid, obj.crs = read_member(self.source.path, text, kind, group.crs)
        return obj

    # -- shared header parts --------------------------------------------------------------------
    def _header_block(self, obj: GocadObject, line: Line) -> None:
        rest = line.text.split("{", 1)[1] if "{" in line.text else ""
        pending = [(line.number, rest)] if rest.strip() else []
        closed = "}" in rest
        if closed:
            pending = [(line.number, rest.split("}", 1)[0])]
        while not closed:
            item = self.stream.peek()
            if item is None or isinstance(item, Run):
                self.warn("HEADER is not closed with '}'", line.number)
                break
            text = item.text
            if ":" not in text and "}" not in text and _keyword(text) in _BODY_START:
                self.warn("HEADER is not closed with '}'", line.number)
                break
            self.stream.take()
            if "}" in text:
                text = text.split("}", 1)[0]
                closed = True
            if text.strip():
                pending.append((item.number, text))
        for number, text in pending:
            self._header_entry(obj, text, number)

    def _header_entry(self, obj: GocadObject, text: str, number: int) -> None:
        text = text.strip()
        if not text:
            return
        if ":" not in text:
            if obj.header and _NUMBERS_ONLY.fullmatch(text):  # a wrapped list of numbers
                key, value = obj.header[-1]
                obj.header[-1] = (key, f"{value}\n{text}")
                self.warn(f"header value of {key!r} continues on this line", number)
            else:
                self.warn(f"header line {text[:40]!r} has no 'key:value'; ignored", number)
            return
        key, value = text.split(":", 1)
        obj.header.append((key.strip(), value.strip()))

    def _class_header(self, obj: GocadObject, line: Line) -> None:
        head = line.text[len("PROPERTY_CLASS_HEADER") :]
        name, _, rest = head.partition("{")
        name = name.strip().strip('"').strip() if name.strip() else ""
        entries: dict[str, str] = {}
        closed = "}" in rest
        body = [rest.split("}", 1)[0]] if rest.strip() else []
        while not closed:
            item = self.stream.peek()
            if item is None or isinstance(item, Run):
                self.warn(f"PROPERTY_CLASS_HEADER {name} is not closed with '}}'", line.number)
                break
            text = item.text
            if ":" not in text and "}" not in text and _keyword(text) in _BODY_START:
                self.warn(f"PROPERTY_CLASS_HEADER {name} is not closed with '}}'", line.number)
                break
            self.stream.take()
            if "}" in text:
                text = text.split("}", 1)[0]
                closed = True
            body.append(text)
        for text in body:
            if ":" in text:
                key, value = text.split(":", 1)
                entries[key.strip()] = value.strip()
        obj.class_headers[name] = entries

    def _crs_block(self, obj: GocadObject, line: Line) -> None:
        crs: CrsBlock = {}
        while True:
            item = self.stream.peek()
            if item is None or isinstance(item, Run):
                self.warn("coordinate-system block is not closed", line.number)
                break
            keyword = _keyword(item.text)
            if keyword in _BODY_START and keyword not in _CRS_KEYS:
                self.warn("coordinate-system block is not closed", line.number)
                break
            self.stream.take()
            if keyword == "END_ORIGINAL_COORDINATE_SYSTEM":
                break
            value = item.text[len(keyword) :].strip()
            if keyword in ("AXIS_NAME", "AXIS_UNIT"):
                parts = split_tokens(value)
                if len(parts) != 3:
                    self.warn(
                        f"{keyword} needs 3 entries, found {len(parts)}; ignored", item.number
                    )
                    continue
                empty = [i for i, part in enumerate(parts, start=1) if not part.strip()]
                if empty:
                    raise self.error(
                        f"{keyword} entry {empty[0]} is empty (axis names and units need text)",
                        item.number,
                    )
                crs[keyword] = parts
            elif keyword == "ZPOSITIVE":
                direction = value.split()[0].capitalize() if value.split() else ""
                if direction not in ("Depth", "Elevation"):
                    self.warn(f"ZPOSITIVE {value!r} is neither Depth nor Elevation", item.number)
                    direction = "Elevation"
                crs[keyword] = direction
            elif keyword == "NAME":
                crs[keyword] = _unquote(value)
            else:  # PROJECTION, DATUM and others: kept verbatim
                crs[keyword] = value
        obj.crs = crs

    def _common(self, obj: GocadObject, item: Line, keyword: str | None = None) -> bool:
        """Handle a header-part line (its :func:`_keyword` ``keyword`` when known); False when
        it is not one."""
        if keyword is None:
            keyword = _keyword(item.text)
        if keyword == "HEADER" or keyword.startswith("HEADER{"):
            self._header_block(obj, item)
        elif keyword == "GOCAD_ORIGINAL_COORDINATE_SYSTEM":
            self._crs_block(obj, item)
        elif keyword.startswith("PROPERTY_CLASS_HEADER"):
            self._class_header(obj, item)
        elif keyword in ("GEOLOGICAL_FEATURE", "GEOLOGICAL_TYPE"):
            obj.geology[keyword] = _unquote(item.text[len(keyword) :].strip())
        elif keyword == "STRATIGRAPHIC_POSITION":
            obj.geology[keyword] = split_tokens(item.text)[1:]
        else:
            prefix = _CELL_PREFIX.get(obj.type, "")
            if (
                prefix
                and keyword.startswith(prefix)
                and keyword[len(prefix) :] in PROPERTY_KEYWORDS
            ):
                parse_property_line(
                    obj.cell_header, keyword[len(prefix) :], item.text, item.number, self.warn
                )
            elif keyword in PROPERTY_KEYWORDS:
                parse_property_line(obj.point_header, keyword, item.text, item.number, self.warn)
            else:
                return False
        return True

    # -- element bodies -------------------------------------------------------------------------
    def _parse_body(self, obj: GocadObject) -> None:
        vertices: VertexTable | None = None
        cells: CellTable | None = None
        part = -1
        header: ModelDraft | None = None
        solid: SolidDraft | None = None
        if obj.type == "Model3d":
            from geobrep.adapters.gocad._model_records import ModelDraft

            header = ModelDraft()
        elif obj.type in ("TSolid", "LightTSolid"):
            from geobrep.adapters.gocad._model_records import SolidDraft

            solid = SolidDraft()
        while True:
            item = self.stream.peek()
            if item is None:
                self.warn(f"{obj.type} {obj.name!r} has no END", obj.line)
                break
            keyword = "" if isinstance(item, Run) else _keyword(item.text)
            if keyword == "GOCAD":
                self.warn(f"{obj.type} {obj.name!r} has no END", obj.line)
                break
            self.stream.take()
            if isinstance(item, Run):
                if vertices is None:
                    vertices, cells = self._tables(obj)
                    if self._bulk_body(obj, item.first, vertices, cells):
                        break
                part = self._run(obj, item, vertices, cells, part, solid)
                continue
            if keyword == "END":
                break
            if header is not None:  # a Model3d
                if not self._common(obj, item, keyword):
                    self._model3d_entry(obj, item, keyword, header)
                continue
            if vertices is None:
                # Header part: the property header is only complete at the first data line.
                if self._common(obj, item, keyword):
                    continue
                if keyword in _SKIP_BLOCKS:
                    self._skip_block(keyword, item.number)
                    continue
                if keyword not in _DATA_KEYWORDS:
                    self.warn(
                        f"unknown keyword {keyword!r} in the header of a {obj.type}; line kept",
                        item.number,
                    )
                    obj.extra_lines.append(item.text)
                    continue
                vertices, cells = self._tables(obj)
                if self._bulk_body(obj, item.number, vertices, cells):
                    break
            elif self._common(obj, item, keyword):
                self.warn(f"{keyword} after the object's data lines", item.number)
                continue
            part = self._element_line(obj, item, keyword, vertices, cells, part, solid)
        if header is not None:
            obj.header_of_model = self._finish_model3d(header)
            return
        if vertices is None:
            vertices, cells = self._tables(obj)
        self._report_nonfinite(obj)
        obj.vertices = vertices.finish(self.error)
        obj.cells = CellRows(*cells.finish()) if cells is not None else None
        if solid is not None:
            obj.model_of_solid = solid.freeze()

    def _tables(self, obj: GocadObject) -> tuple[VertexTable, CellTable | None]:
        """The vertex and cell tables, sized by the (now complete) property headers."""
        obj.point_header.resolve(self.warn)
        obj.cell_header.resolve(self.warn)
        # A value takes at least two bytes ("0 "): a header declaring more values per element
        # than the whole file could hold would only make every element a row of padding.
        room = max(64, len(self.source.data) // 2)
        for kind, header in (("vertex", obj.point_header), ("cell", obj.cell_header)):
            if header.n_values > room:
                raise self.error(
                    f"{obj.type} {obj.name!r}: the property header declares {header.n_values} "
                    f"values per {kind}, more than this {len(self.source.data)}-byte file holds",
                    None,
                )
        width = _CELL_WIDTH.get(obj.type)
        cells = CellTable(width, obj.cell_header.n_values) if width else None
        # Values no line holds (VRTX lines in an object with properties, ATOM lines inheriting
        # theirs) are filled in: at most an eighth of the read budget of them (8 bytes each),
        # since the vertex table is copied a few times on its way to the properties.
        absent_limit = read_budget(len(self.source.data)) // _ABSENT_SHARE // 8
        return VertexTable(obj.point_header.n_values, absent_limit), cells

    def _bulk_body(
        self, obj: GocadObject, first: int, vertices: VertexTable, cells: CellTable | None
    ) -> bool:
        """The whole body from line ``first`` to its END read in bulk (``_bodies``); False
        when it is not one the bulk reader takes (nothing is read then)."""
        limit = vertices.absent_limit
        body = read_body(
            self.source,
            first,
            obj.type,
            obj.point_header.n_values,
            obj.cell_header.n_values,
            None if limit is None else limit - vertices.absent,
        )
        if body is None:
            return False
        for keyword, text, line, start in body.parts:
            obj.declared_parts += 1
            obj.part_names.append(_unquote(text[len(keyword) :].strip()))
            obj.part_vertex_starts.append(start)
            obj.part_lines.append(line)
        if body.absent_rows:
            vertices.allow_absent(body.absent_rows)
        rows = body.vertices
        vertices.add_rows(rows.ids, rows.xyz, rows.refs, rows.values, rows.flags, rows.lines)
        if cells is not None and body.cells is not None:
            cells.add_rows(*body.cells)
        obj.bstones.extend(body.bstones)
        obj.borders.extend(body.borders)
        self.stream.skip_to(body.end + 1)
        return True

    def _check_absent(
        self, obj: GocadObject, vertices: VertexTable, rows: int, keyword: str, line: int
    ) -> None:
        """Count ``rows`` vertices from ``line`` on that carry no property values; FormatError
        at the first of them past the limit of values filled in."""
        past = vertices.allow_absent(rows)
        if past is None:
            return
        n_values = vertices.n_values
        limit = human_bytes(8 * (vertices.absent_limit or 0)).replace(".0 ", " ")
        raise self.error(
            f"{keyword}: {obj.type} {obj.name!r} declares {n_values} property values per vertex "
            f"and its vertices up to this line carry none of their own (VRTX lines, ATOM lines "
            f"inheriting them): filling them in would take more than {limit}, an eighth of the "
            f"read budget of "
            f"this {len(self.source.data)}-byte file (write the values on PVRTX lines)",
            line + past,
        )

    def _new_part(self, obj: GocadObject, name: str, vertices: VertexTable, line: int) -> int:
        obj.part_names.append(name)
        obj.part_vertex_starts.append(vertices.count)
        obj.part_lines.append(line)
        return len(obj.part_names) - 1

    def _ensure_part(self, obj: GocadObject, part: int, vertices: VertexTable, line: int) -> int:
        if part >= 0 or obj.type == "VSet":
            return part
        if obj.type in ("TSurf", "PLine"):
            missing = "TFACE" if obj.type == "TSurf" else "ILINE"
            self.warn(f"data before any {missing}: starting one", line)
        return self._new_part(obj, "", vertices, line)

    def _run(
        self,
        obj: GocadObject,
        run: Run,
        vertices: VertexTable,
        cells: CellTable | None,
        part: int,
        solid: SolidDraft | None,
    ) -> int:
        if run.keyword == "ATOM":
            return self._atom_run(obj, run, vertices, cells, part, solid)
        if run.keyword == "PATOM":
            return self._patom_run(obj, run, vertices, cells, part, solid)
        if run.keyword in ("VRTX", "PVRTX"):
            part = self._ensure_part(obj, part, vertices, run.first)
            width = 4 + (obj.point_header.n_values if run.keyword == "PVRTX" else 0)
            try:
                if run.count < 2:
                    raise BulkParseError
                block = parse_run(self.source, run, integer=False)
                if block.shape[1] != width:
                    raise BulkParseError
            except BulkParseError:
                self._run_lines(obj, run, vertices, cells, part, solid)
                return part
            block = block.astype(np.float64, copy=False)
            ids = check_finite_ids(self.error, block, run.first, run.keyword)
            if run.keyword == "PVRTX":
                values = self._finite(obj, "point", block[:, 4:], run.first)
            else:
                self._check_absent(obj, vertices, run.count, run.keyword, run.first)
                values = self._no_values(obj, run.count)
            vertices.add_block(ids, np.ascontiguousarray(block[:, 1:4]), values, run.first)
            return part
        expected = _CELL_KEYWORD.get(obj.type)
        if cells is None or run.keyword != expected:
            if obj.type in ("TSolid", "LightTSolid") and run.keyword == "TRGL":
                self._run_lines(obj, run, vertices, cells, part, solid)
                return part
            raise self.error(f"{run.keyword} lines are not allowed in a {obj.type}", run.first)
        part = self._ensure_part(obj, part, vertices, run.first)
        width = cells.width + cells.n_values
        try:
            if run.count < 2:
                raise BulkParseError
            block = parse_run(self.source, run, integer=not cells.n_values)
            if block.shape[1] != width:
                raise BulkParseError
            ids = block[:, : cells.width]
            if ids.dtype != np.int64:
                if (ids != np.floor(ids)).any() or (np.abs(ids) > 2**53).any():
                    raise BulkParseError
                ids = ids.astype(np.int64)
        except BulkParseError:
            self._run_lines(obj, run, vertices, cells, part, solid)
            return part
        cells.add_block(
            np.ascontiguousarray(ids),
            np.ascontiguousarray(
                self._finite(obj, "cell", block[:, cells.width :], run.first), dtype=np.float64
            ),
            part,
            run.first,
        )
        return part

    def _atom_run(
        self,
        obj: GocadObject,
        run: Run,
        vertices: VertexTable,
        cells: CellTable | None,
        part: int,
        solid: SolidDraft | None,
    ) -> int:
        """A run of ``ATOM <new id> <id>`` lines in one bulk parse (line by line when it holds
        anything else, such as flags)."""
        part = self._ensure_part(obj, part, vertices, run.first)
        try:
            if run.count < 2:
                raise BulkParseError
            block = parse_run(self.source, run, integer=True)
            if block.shape[1] != 2:
                raise BulkParseError
        except BulkParseError:
            self._run_lines(obj, run, vertices, cells, part, solid)
            return part
        if obj.point_header.n_values:
            self._check_absent(obj, vertices, run.count, run.keyword, run.first)
        vertices.add_atoms(
            np.ascontiguousarray(block[:, 0]), np.ascontiguousarray(block[:, 1]), run.first
        )
        return part

    def _patom_run(
        self,
        obj: GocadObject,
        run: Run,
        vertices: VertexTable,
        cells: CellTable | None,
        part: int,
        solid: SolidDraft | None,
    ) -> int:
        """A run of ``PATOM <new id> <id> <values>`` lines in one bulk parse (line by line
        when it holds anything else, or no property header gives the lines values)."""
        part = self._ensure_part(obj, part, vertices, run.first)
        n_values = obj.point_header.n_values
        try:
            if run.count < 2 or not n_values:
                raise BulkParseError
            block = parse_run(self.source, run, integer=False)
            if block.shape[1] != 2 + n_values:
                raise BulkParseError
            ids = block[:, :2]
            if ids.dtype != np.int64:
                if (ids != np.floor(ids)).any() or (np.abs(ids) > 2**53).any():
                    raise BulkParseError  # the line parser says why they are no ids
                ids = ids.astype(np.int64)
        except BulkParseError:
            self._run_lines(obj, run, vertices, cells, part, solid)
            return part
        values = self._finite(obj, "point", np.asarray(block[:, 2:], dtype=np.float64), run.first)
        vertices.add_atoms(
            np.ascontiguousarray(ids[:, 0]),
            np.ascontiguousarray(ids[:, 1]),
            run.first,
            np.ascontiguousarray(values),
        )
        return part

    def _finite(
        self, obj: GocadObject, kind: str, values: NDArray[np.float64], first_line: int
    ) -> NDArray[np.float64]:
        """Property values with every non-finite one (``inf``, ``1.#INF``, ``nan``) replaced by
        its property's no-data value (NaN when it has none); counted for :meth:`_report`."""
        if values.size == 0 or np.isfinite(values).all():
            return values
        header = obj.point_header if kind == "point" else obj.cell_header
        spec_of = np.repeat(np.arange(len(header.specs)), [s.esize for s in header.specs])
        no_data = np.array(
            [np.nan if s.no_data is None else s.no_data for s in header.specs], dtype=np.float64
        )[spec_of]
        with np.errstate(invalid="ignore"):
            is_no_data = (values == no_data) | (np.isnan(values) & np.isnan(no_data))
        bad = ~np.isfinite(values) & ~is_no_data
        if not bad.any():
            return values
        rows, columns = np.nonzero(bad)
        counts = np.bincount(spec_of[columns], minlength=len(header.specs))
        for index in np.flatnonzero(counts).tolist():
            count, line = obj.nonfinite.get((kind, index), (0, first_line + int(rows[0])))
            obj.nonfinite[(kind, index)] = (count + int(counts[index]), line)
        return np.where(bad, no_data, values)

    def _report_nonfinite(self, obj: GocadObject) -> None:
        for (kind, index), (count, line) in sorted(obj.nonfinite.items()):
            header = obj.point_header if kind == "point" else obj.cell_header
            spec = header.specs[index]
            into = (
                "NaN (it has no no-data value)"
                if spec.no_data is None
                else f"its no-data value {spec.no_data!r}"
            )
            self.warn(
                f"{kind} property {spec.name!r}: {count} non-finite value(s) (inf, nan) "
                f"replaced by {into}; the first on this line",
                line,
            )

    def _no_values(self, obj: GocadObject, n: int) -> NDArray[np.float64]:
        return np.full((n, obj.point_header.n_values), np.nan)

    def _run_lines(
        self,
        obj: GocadObject,
        run: Run,
        vertices: VertexTable,
        cells: CellTable | None,
        part: int,
        solid: SolidDraft | None,
    ) -> None:
        for index in range(run.count):
            number = run.first + index
            text = self.source.text(number - 1).strip()
            self._element_line(obj, Line(number, text), run.keyword, vertices, cells, part, solid)

    def _element_line(
        self,
        obj: GocadObject,
        item: Line,
        keyword: str,
        vertices: VertexTable,
        cells: CellTable | None,
        part: int,
        solid: SolidDraft | None,
    ) -> int:
        """One line of an object's body; the part (TFACE, ILINE, ...) the next lines go to."""
        number = item.number
        try:
            if keyword in ("VRTX", "PVRTX"):
                part = self._ensure_part(obj, part, vertices, number)
                self._vertex_line(obj, item, keyword, vertices)
            elif keyword in ("ATOM", "PATOM", "SHAREDVRTX", "SHAREDPVRTX"):
                part = self._ensure_part(obj, part, vertices, number)
                self._atom_line(obj, item, keyword, vertices)
            elif keyword in _PART_KEYWORDS:
                part = self._part_line(obj, item, keyword, vertices, part, solid)
            elif cells is not None and keyword == _CELL_KEYWORD.get(obj.type):
                part = self._ensure_part(obj, part, vertices, number)
                self._cell_line(obj, item, keyword, cells, part)
            elif keyword == "# CTETRA" or (keyword == "#" and item.text.startswith("# CTETRA")):
                self._ctetra_line(obj, item, cells)
            elif keyword in ("BSTONE", "BORDER"):
                self._border_line(obj, item, keyword)
            elif keyword in _SKIP_BLOCKS:
                self._skip_block(keyword, number)
            elif solid is not None:  # a TSolid or LightTSolid
                self._tsolid_model_line(obj, item, keyword, solid)
            else:
                self.warn(f"unknown keyword {keyword!r} in a {obj.type}; line kept", number)
                obj.extra_lines.append(item.text)
        except ValueError as exc:
            if isinstance(exc, FormatError):
                raise
            raise self.error(f"{keyword}: {exc}", number) from None
        return part

    def _vertex_line(
        self, obj: GocadObject, item: Line, keyword: str, vertices: VertexTable
    ) -> None:
        """``VRTX`` / ``PVRTX <id> x y z [values] [CNXYZ|XYZ]``."""
        number = item.number
        n_values = obj.point_header.n_values
        flag, tokens = _strip_flags(item.text.split())
        count = 5 + (n_values if keyword == "PVRTX" else 0)
        if len(tokens) < count:
            raise self.error(
                f"{keyword} needs {count - 1} numbers, found {len(tokens) - 1}", number
            )
        if len(tokens) > count:
            self.warn(f"{keyword} has {len(tokens) - count} extra value(s); ignored", number)
        xyz = (parse_float(tokens[2]), parse_float(tokens[3]), parse_float(tokens[4]))
        values = [parse_float(t) for t in tokens[5:count]] if keyword == "PVRTX" else None
        if values is not None and not all(map(math.isfinite, values)):
            values = self._finite(obj, "point", np.array([values]), number)[0].tolist()
        if values is None and n_values:
            self._check_absent(obj, vertices, 1, keyword, number)
            values = [np.nan] * n_values
        vertices.add(parse_int(tokens[1]), xyz, None, values, flag, number)

    def _atom_line(self, obj: GocadObject, item: Line, keyword: str, vertices: VertexTable) -> None:
        """``ATOM`` / ``PATOM`` / ``SHAREDVRTX`` / ``SHAREDPVRTX <new id> <id> [values]``."""
        number = item.number
        n_values = obj.point_header.n_values
        flag, tokens = _strip_flags(item.text.split())
        with_values = keyword in ("PATOM", "SHAREDPVRTX")
        if len(tokens) < 3:
            raise self.error(f"{keyword} needs a new id and the id it refers to", number)
        values = None
        if with_values and n_values:
            if len(tokens) < 3 + n_values:
                raise self.error(
                    f"{keyword} needs {n_values} property values, found {len(tokens) - 3}",
                    number,
                )
            values = [parse_float(t) for t in tokens[3 : 3 + n_values]]
            if not all(map(math.isfinite, values)):
                values = self._finite(obj, "point", np.array([values]), number)[0].tolist()
        elif n_values:
            self._check_absent(obj, vertices, 1, keyword, number)
        vertices.add(parse_int(tokens[1]), None, parse_int(tokens[2]), values, flag, number)

    def _part_line(
        self,
        obj: GocadObject,
        item: Line,
        keyword: str,
        vertices: VertexTable,
        part: int,
        solid: SolidDraft | None,
    ) -> int:
        """``TFACE`` / ``3DFACE`` / ``ILINE`` / ``TVOLUME`` / ``SUBVSET``: a new part (a TFACE in
        a TSolid's MODEL section is one of the model's)."""
        if keyword == "SUBVSET" or obj.type in ("TSurf", "PLine", "TSolid", "LightTSolid"):
            if solid is not None and solid.in_model:
                self._tsolid_model_line(obj, item, keyword, solid)
                return part
            obj.declared_parts += 1
            name = _unquote(item.text[len(keyword) :].strip())
            return self._new_part(obj, name, vertices, item.number)
        self.warn(f"{keyword} is not used in a {obj.type}; ignored", item.number)
        return part

    def _cell_line(
        self, obj: GocadObject, item: Line, keyword: str, cells: CellTable, part: int
    ) -> None:
        """``TRGL`` / ``SEG`` / ``TETRA <vertex ids> [values]``."""
        tokens = item.text.split()
        number = item.number
        width, n_cell = cells.width, cells.n_values
        if len(tokens) < 1 + width + n_cell:
            raise self.error(
                f"{keyword} needs {width} vertex ids"
                + (f" and {n_cell} values" if n_cell else "")
                + f", found {len(tokens) - 1} entries",
                number,
            )
        if len(tokens) > 1 + width + n_cell:
            self.warn(f"{keyword} has extra entries; ignored", number)
        ids = [parse_int(t) for t in tokens[1 : 1 + width]]
        values = [parse_float(t) for t in tokens[1 + width : 1 + width + n_cell]]
        if not all(map(math.isfinite, values)):
            values = self._finite(obj, "cell", np.array([values]), number)[0].tolist()
        cells.add(ids, values, part, number)

    def _ctetra_line(self, obj: GocadObject, item: Line, cells: CellTable | None) -> None:
        """``# CTETRA <region> <4 faces>``: what the faces of the last TETRA lie on."""
        number = item.number
        if cells is None or cells.count == 0:
            raise self.error("'# CTETRA' before any TETRA", number)
        # entries like -(boundary)"fracture 1": quotes do not end an entry
        parts = _CTETRA_ENTRY.findall(item.text)[2:]
        if len(parts) > 5:
            raise self.error(
                f"'# CTETRA' needs a region and 4 face entries, found {len(parts)} entries",
                number,
            )
        if obj.ctetra and obj.ctetra[-1].cell == cells.count - 1:
            self.warn("a second '# CTETRA' line for one TETRA replaces the first", number)
            obj.ctetra.pop()
        region = _unquote(parts[0]) if parts else ""
        obj.ctetra.append(CTetra(cells.count - 1, region, tuple(parts[1:5]), number))

    def _border_line(self, obj: GocadObject, item: Line, keyword: str) -> None:
        """``BSTONE <vertex id>`` or ``BORDER <id> <vertex id> <vertex id>``."""
        tokens = item.text.split()
        if keyword == "BSTONE":
            if len(tokens) < 2:
                raise self.error("BSTONE needs a vertex id", item.number)
            obj.bstones.append(BStone(parse_int(tokens[1]), item.number))
            return
        if len(tokens) < 4:
            raise self.error("BORDER needs an id and two vertex ids", item.number)
        obj.borders.append(
            Border(parse_int(tokens[1]), parse_int(tokens[2]), parse_int(tokens[3]), item.number)
        )

    def _skip_block(self, keyword: str, number: int) -> None:
        end = _SKIP_BLOCKS[keyword]
        self.warn(f"skipping {keyword} block", number)
        self.skipped.append(f"{keyword} block (line {number}): not read")
        while True:
            item = self.stream.take()
            if item is None:
                raise self.error(f"{keyword} is not closed by {end}", number)
            if isinstance(item, Line) and _keyword(item.text) == end:
                return

    # -- TSolid model section -------------------------------------------------------------------
    def _tsolid_model_line(
        self, obj: GocadObject, item: Line, keyword: str, solid: SolidDraft
    ) -> None:
        tokens = split_tokens(item.text)
        if keyword == "MODEL":
            solid.in_model = True
        elif keyword == "SURFACE":
            solid.surfaces.append((item.text[len(keyword) :].strip().strip('"'), []))
        elif keyword == "TFACE":
            if not solid.surfaces:
                raise self.error("TFACE before any SURFACE in the MODEL section", item.number)
            count = sum(len(tfaces) for _, tfaces in solid.surfaces)
            tface_id = parse_int(tokens[1]) if len(tokens) > 1 else count + 1
            solid.add_tface(tface_id)
        elif keyword in ("KEYVERTICES", "TRGL"):
            current = self._current_tface(solid, item)
            if len(tokens) < 4:
                raise self.error(f"{keyword} needs 3 vertex ids", item.number)
            a, b, c = (parse_int(t) for t in tokens[1:4])
            current.add(keyword, (a, b, c), item.number)
        elif keyword == "MODEL_REGION":
            if len(tokens) < 3:
                raise self.error("MODEL_REGION needs a name and a signed TFACE id", item.number)
            solid.add_region(" ".join(tokens[1:-1]), parse_int(tokens[-1]))
        else:
            self.warn(f"unknown keyword {keyword!r} in a {obj.type}; line kept", item.number)
            obj.extra_lines.append(item.text)

    def _current_tface(self, solid: SolidDraft, item: Line) -> SolidTFaceDraft:
        if not solid.surfaces or not solid.surfaces[-1][1]:
            raise self.error(f"{_keyword(item.text)} before any TFACE of the MODEL", item.number)
        return solid.surfaces[-1][1][-1]

    # -- Model3d header -------------------------------------------------------------------------
    def _model3d_entry(
        self, obj: GocadObject, item: Line, keyword: str, header: ModelDraft
    ) -> None:
        """:meth:`_model3d_line`, with a bad number named with its keyword and line."""
        try:
            self._model3d_line(obj, item, keyword, header)
        except ValueError as exc:
            if isinstance(exc, FormatError):
                raise
            raise self.error(f"{keyword}: {exc}", item.number) from None

    def _model3d_line(self, obj: GocadObject, item: Line, keyword: str, header: ModelDraft) -> None:
        text = item.text
        if keyword == "TSURF":
            name = _unquote(text[len(keyword) :].strip())
            if name in header.tsurfs:
                self.warn(f"TSURF {name!r} is listed twice", item.number)
            else:
                header.tsurfs.append(name)
            header.current = None
        elif keyword == "TFACE":
            tokens = text.split(None, 3)
            if len(tokens) < 4:
                raise self.error(
                    "TFACE needs an id, a geological type and a TSurf name", item.number
                )
            tface_id = parse_int(tokens[1])
            if tface_id < 1:
                raise self.error(f"TFACE id {tface_id} must be a positive number", item.number)
            entry = header.add_tface(tface_id, tokens[2], _unquote(tokens[3].strip()), item.number)
            header.key_for, header.current = entry, None
        elif keyword in _MODEL3D_LISTS:
            header.current = self._model3d_list(keyword, item, header)
            header.lists.append(header.current)
            header.key_for = None
        elif not self._model3d_numbers(item, header):
            self.warn(f"unknown line in the Model3d header: {text[:40]!r}; kept", item.number)
            obj.extra_lines.append(text)

    def _model3d_list(self, keyword: str, item: Line, header: ModelDraft) -> ListDraft:
        """The list a ``REGION <id> <name>`` (or ``LAYER <name>``, ...) line opens."""
        if keyword != "REGION":
            return header.new_list(
                keyword, _unquote(item.text[len(keyword) :].strip()), item.number
            )
        tokens = item.text.split(None, 2)
        if len(tokens) < 3:
            raise self.error("REGION needs an id and a name", item.number)
        region_id = parse_int(tokens[1])
        if region_id < 1:
            raise self.error(f"REGION id {region_id} must be a positive number", item.number)
        return header.new_list(keyword, _unquote(tokens[2].strip()), item.number, region_id)

    def _model3d_numbers(self, item: Line, header: ModelDraft) -> bool:
        """A key-triangle line or a line of list ids; False when the line is neither."""
        numbers = item.text.split()
        key_for = header.key_for
        if key_for is not None and len(key_for.key) < 3:
            try:
                point = [parse_float(t) for t in numbers]
            except ValueError as exc:
                raise self.error(f"key triangle: {exc}", item.number) from None
            if len(point) != 3:
                raise self.error("a key-triangle line needs 3 coordinates", item.number)
            key_for.key.append((point[0], point[1], point[2]))
            return True
        current = header.current
        if current is None or current.closed:
            return False
        values = _list_ids(numbers)
        if values is None:  # some token is no id: name the first
            for token in numbers:
                try:
                    parse_int(token)
                except ValueError as exc:
                    raise self.error(
                        f"{exc} in the list of {current.name!r}", item.number
                    ) from None
        assert values is not None
        if 0 in values:
            values = values[: values.index(0)]
            current.closed = True
        current.items.extend(values)
        return True

    def _finish_model3d(self, header: ModelDraft) -> Model3dHeader:
        for entry in header.tfaces:
            if len(entry.key) != 3:
                raise self.error(
                    f"TFACE {entry.id} needs a key triangle of 3 coordinate lines", entry.line
                )
        for draft in header.lists:
            if not draft.closed:
                self.warn(f"{draft.keyword} {draft.name!r} list does not end with 0", draft.line)
        return header.freeze()

    # -- groups ---------------------------------------------------------------------------------
    def _parse_group(self, obj: GocadObject) -> None:
        in_members = False
        while True:
            item = self.stream.peek()
            if item is None:
                self.warn(f"{obj.type} {obj.name!r} has no END", obj.line)
                return
            if isinstance(item, Run):
                raise self.error(f"{item.keyword} lines directly inside a group", item.first)
            keyword = _keyword(item.text)
            if keyword == "GOCAD":
                if not in_members:
                    self.warn("group member outside BEGIN_MEMBERS", item.number)
                self.stream.take()
                member = self.parse_object(item, obj)
                if member is not None:
                    obj.members.append(member)
                continue
            self.stream.take()
            if keyword == "BEGIN_MEMBERS":
                in_members = True
            elif keyword == "END_MEMBERS":
                in_members = False
            elif keyword == "END":
                return
            elif keyword == "TYPE":
                obj.member_type = item.text[len(keyword) :].strip()
            elif not self._common(obj, item, keyword):
                self.warn(f"unknown keyword {keyword!r} in a group; line kept", item.number)
                obj.extra_lines.append(item.text)


#: Model3d header keywords that open a list of ids ended by 0.
_MODEL3D_LISTS = ("REGION", "SURFACE", "LAYER", "FAULT_BLOCK", "FAULT", "BOUNDARY", "UNIT")
_CRS_KEYS = {
    "NAME",
    "PROJECTION",
    "DATUM",
    "AXIS_NAME",
    "AXIS_UNIT",
    "ZPOSITIVE",
    "END_ORIGINAL_COORDINATE_SYSTEM",
}
_BODY_START = {
    "GOCAD",
    "END",
    "GOCAD_ORIGINAL_COORDINATE_SYSTEM",
    "GEOLOGICAL_FEATURE",
    "GEOLOGICAL_TYPE",
    "STRATIGRAPHIC_POSITION",
    "PROPERTY_CLASS_HEADER",
    "TFACE",
    "3DFACE",
    "ILINE",
    "TVOLUME",
    "ATOM",
    "PATOM",
    "TSURF",
    "REGION",
    "MODEL",
    "BEGIN_MEMBERS",
    *PROPERTY_KEYWORDS,
}


_NUMBERS_ONLY = re.compile(r"[-+0-9.eE\s]+")
_CTETRA_ENTRY = re.compile(r'(?:[^\s"]+|"[^"]*")+')


def _list_ids(tokens: list[str]) -> list[int] | None:
    """The ids of a Model3d list line as :func:`parse_int` reads them, in one C-level pass
    (a line may hold a million); None when a token is not one."""
    try:
        values = list(map(int, tokens))
    except ValueError:
        return None
    if values and not -INT_LIMIT <= min(values) <= max(values) <= INT_LIMIT:
        return None
    return values


def _unquote(text: str) -> str:
    if len(text) >= 2 and text[0] == '"' and text.endswith('"'):
        return text[1:-1]
    return text


def _strip_flags(tokens: list[str]) -> tuple[int, list[str]]:
    """The trailing flag words (``CNXYZ``, ...) off ``tokens``: the first one's flag, the rest
    (one pass, one copy however many flags a line repeats)."""
    end = len(tokens)
    while end and tokens[end - 1].upper() in FLAG_NAMES:
        end -= 1
    if end == len(tokens):
        return 0, tokens
    return FLAG_NAMES[tokens[end].upper()], tokens[:end]


def parse_source(source: Source, skipped: list[str] | None = None) -> list[GocadObject]:
    """Every object (with known type) of a GOCAD file, in file order.

    ``skipped`` receives one sentence per part of the file that is not read.
    """
    parser = _Parser(source)
    objects = parser.parse_all()
    if skipped is not None:
        skipped.extend(parser.skipped)
    return objects
