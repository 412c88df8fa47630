"""GOCAD SGrid (.sg): a curvilinear grid of nodes with its coordinates and properties in side files.

``AXIS_N ni nj nk`` counts the *nodes* (i fastest), so an SGrid has ``(ni-1)(nj-1)(nk-1)``
hexahedral cells and reads as a points :class:`~geobrep.StructuredGrid`. The side files are
found beside the header and read through numpy memory maps:

* ``POINTS_FILE`` (from ``POINTS_OFFSET`` bytes): big-endian ``x y z`` per node, float32 or, with
  ``BINARY_POINTS_IN_DOUBLE_PRECISION 1``, float64;
* ``FLAGS_FILE`` (``FLAGS_OFFSET``, ``FLAGS_ESIZE`` bytes, 4 by default): one big-endian integer
  per node, kept as the point property ``sgrid_flags``;
* ``REGION_FLAGS_FILE``: ``REGION_FLAGS_ESIZE`` bytes per node whose bit ``b`` is the region
  ``REGION <name> <b>``: the point property ``sgrid_region_flags`` (names in the metadata);
* ``PROP_FILE`` per property: ``PROP_ALIGNMENT POINTS`` (one value per node, ``point_data``) or
  ``CELLS`` (one per cell, ``cell_data``), set for the whole grid or per property.

The ASCII variant (``ASCII_DATA_FILE``) is a table of ``X Y Z value... I J K`` rows, one per
node; a cell property's value is on the row of the cell's first corner.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.gocad._ascii_rows import NodeRows, iter_rows
from geobrep.adapters.gocad._keyed import MAX_TEXT, KeyedFile, KeyedLine, parse_keyed, read_text
from geobrep.adapters.gocad._objects import report
from geobrep.adapters.gocad._voxet import (
    PropertyFile,
    mapped_array,
    property_dtype,
    property_lines,
    property_meta,
    side_file,
)
from geobrep.adapters.limits import check_declared
from geobrep.errors import EntityValidationError, FormatError
from geobrep.model.entities import StructuredGrid
from geobrep.model.properties import Property

__all__ = ["FLAGS", "REGION_FLAGS", "SGridLayout", "read_sgrid"]

#: The point properties holding the FLAGS_FILE and REGION_FLAGS_FILE values.
FLAGS = "sgrid_flags"
REGION_FLAGS = "sgrid_region_flags"


@dataclass
class SGridLayout:
    """What an SGrid header says of its side files."""

    nodes: tuple[int, int, int] = (0, 0, 0)
    alignment: str = "POINTS"
    points_file: str | None = None
    points_offset: int = 0
    double: bool = False
    flags_file: str | None = None
    flags_offset: int = 0
    flags_esize: int = 4
    regions: dict[str, int] = field(default_factory=dict)
    region_file: str | None = None
    region_offset: int = 0
    region_esize: int = 1
    ascii_file: str | None = None
    splits: int = 0

    @property
    def n_nodes(self) -> int:
        return int(np.prod(self.nodes, dtype=np.int64))

    @property
    def n_cells(self) -> int:
        return int(np.prod([n - 1 for n in self.nodes], dtype=np.int64))


def _file_line(layout: SGridLayout, line: KeyedLine) -> bool:
    """Apply a side-file keyword; False when the line is not one."""
    keyword, value = line.keyword, line.rest()
    if keyword == "POINTS_FILE":
        layout.points_file = value
    elif keyword == "POINTS_OFFSET":
        layout.points_offset = line.int_at(0, 0, 2**50)
    elif keyword == "FLAGS_FILE":
        layout.flags_file = value
    elif keyword == "FLAGS_OFFSET":
        layout.flags_offset = line.int_at(0, 0, 2**50)
    elif keyword == "FLAGS_ESIZE":
        layout.flags_esize = _esize(line)
    elif keyword == "REGION_FLAGS_FILE":
        layout.region_file = value
    elif keyword == "REGION_FLAGS_OFFSET":
        layout.region_offset = line.int_at(0, 0, 2**50)
    elif keyword == "REGION_FLAGS_ESIZE":
        layout.region_esize = _esize(line)
    elif keyword == "ASCII_DATA_FILE":
        layout.ascii_file = value
    else:
        return False
    return True


def _esize(line: KeyedLine) -> int:
    size = line.int_at(0, 1, 8)
    if size not in (1, 2, 4, 8):
        raise line.error(f"{size} bytes is not an integer size (1, 2, 4 or 8)")
    return size


def _layout(keyed: KeyedFile) -> SGridLayout:
    layout = SGridLayout()
    layout.double = keyed.header.get("double_precision_binary", "").lower() in ("on", "true")
    have_counts = False
    for line in keyed.lines:
        keyword = line.keyword
        if keyword == "AXIS_N":
            n = [line.int_at(a, 2, 2**31) for a in range(3)]
            layout.nodes, have_counts = (n[0], n[1], n[2]), True
        elif keyword == "PROP_ALIGNMENT" and len(line.tokens) == 1:  # not PROP_ALIGNMENT <n> ..
            layout.alignment = _alignment(line, 0)
        elif keyword == "BINARY_POINTS_IN_DOUBLE_PRECISION":
            layout.double = line.int_at(0, 0, 1) == 1
        elif keyword == "REGION" and len(line.tokens) >= 2:
            layout.regions[line.tokens[0]] = line.int_at(1, 0, 63)
        elif keyword == "SPLIT":
            layout.splits += 1
        else:
            _file_line(layout, line)
    if not have_counts:
        raise FormatError("the header has no AXIS_N line", keyed.path)
    return layout


def _alignment(line: KeyedLine, index: int) -> str:
    value = line.tokens[index].upper() if len(line.tokens) > index else ""
    if value not in ("POINTS", "CELLS"):
        raise line.error(f"alignment {value!r} is neither POINTS nor CELLS")
    return value


def _binary_points(layout: SGridLayout, path: Path, z_sign: float) -> NDArray[np.float64]:
    if layout.points_file is None:
        raise FormatError("the header has no POINTS_FILE (nor ASCII_DATA_FILE)", path)
    dtype = np.dtype(">f8" if layout.double else ">f4")
    flat = mapped_array(
        path, layout.points_file, "POINTS_FILE", dtype, layout.points_offset, 3 * layout.n_nodes
    )
    points = flat.astype(np.float64).reshape(-1, 3)
    points[:, 2] *= z_sign
    return points


def _integers(path: Path, name: str, what: str, esize: int, offset: int, count: int) -> Any:
    dtype = np.dtype(f">i{esize}" if what == "FLAGS_FILE" else f">u{esize}")
    return mapped_array(path, name, what, dtype, offset, count)


def _flag_properties(layout: SGridLayout, path: Path) -> dict[str, Property]:
    out: dict[str, Property] = {}
    n = layout.n_nodes
    if layout.flags_file is not None:
        values = _integers(
            path, layout.flags_file, "FLAGS_FILE", layout.flags_esize, layout.flags_offset, n
        )
        out[FLAGS] = Property(values=values)
    if layout.region_file is not None:
        values = _integers(
            path,
            layout.region_file,
            "REGION_FLAGS_FILE",
            layout.region_esize,
            layout.region_offset,
            n,
        )
        out[REGION_FLAGS] = Property(values=values)
    return out


def _prop_alignment(prop: PropertyFile, layout: SGridLayout) -> str:
    value = prop.extra.get("PROP_ALIGNMENT", layout.alignment).upper()
    if value not in ("POINTS", "CELLS"):
        raise FormatError(
            f"property {prop.name!r}: alignment {value!r} is neither POINTS nor CELLS",
            None,
            prop.line or None,
        )
    return value


def _ascii_rows(layout: SGridLayout, path: Path, n_props: int) -> NDArray[np.float64]:
    """The ``X Y Z value... I J K`` rows of the ASCII data file, in node order (each node
    once), parsed vectorised and exactly like a Voxet's table (:mod:`._ascii_rows`)."""
    assert layout.ascii_file is not None
    side = side_file(path, layout.ascii_file, "ASCII_DATA_FILE")
    if not side.is_file():
        raise FormatError(f"the ASCII_DATA_FILE {str(side)!r} is missing", path)
    columns = 6 + n_props
    check_declared(8 * columns * layout.n_nodes, side.stat().st_size, "AXIS_N", side)
    ijk = (3 + n_props, 4 + n_props, 5 + n_props)
    ordered = np.empty((layout.n_nodes, 3 + n_props), dtype=np.float64)
    nodes = NodeRows(layout.nodes, side)  # a node listed twice is a FormatError naming the line
    for chunk in iter_rows(side, columns, ijk, MAX_TEXT):
        ordered[nodes.place(chunk)] = chunk.floats
    missing = nodes.first_missing()
    if missing is not None:
        raise FormatError(
            f"ASCII data file: no row for node I J K {missing} ({nodes.listed} rows of "
            f"{columns} columns, X Y Z, {n_props} properties, I J K, for {layout.n_nodes} "
            "nodes)",
            side,
        )
    return ordered


def _cell_rows(layout: SGridLayout) -> NDArray[np.int64]:
    """The node row of each cell's first corner (i fastest)."""
    ni, nj, nk = layout.nodes
    k, j, i = np.meshgrid(np.arange(nk - 1), np.arange(nj - 1), np.arange(ni - 1), indexing="ij")
    return (i + ni * (j + nj * k)).ravel()


def _values(
    props: list[PropertyFile], layout: SGridLayout, path: Path, z_sign: float
) -> tuple[NDArray[np.float64], dict[int, NDArray[Any]]]:
    """The node coordinates and each property's values (by property number)."""
    counts = {"POINTS": layout.n_nodes, "CELLS": layout.n_cells}
    if layout.ascii_file is None:
        points = _binary_points(layout, path, z_sign)
        values: dict[int, NDArray[Any]] = {}
        for prop in props:
            if prop.file is None:
                raise FormatError(f"property {prop.name!r} has no PROP_FILE", path, prop.line)
            dtype = property_dtype(prop, None, path)
            count = counts[_prop_alignment(prop, layout)]
            what = f"property {prop.name!r}: PROP_FILE"
            values[prop.number] = mapped_array(path, prop.file, what, dtype, prop.offset, count)
        return points, values
    rows = _ascii_rows(layout, path, len(props))
    points = rows[:, :3].copy()
    points[:, 2] *= z_sign
    cells = _cell_rows(layout)
    values = {}
    for column, prop in enumerate(props, start=3):
        cell = _prop_alignment(prop, layout) == "CELLS"
        values[prop.number] = rows[cells, column] if cell else rows[:, column].copy()
    return points, values


def read_sgrid(
    path: Path, text: str | None = None, inherited: dict[str, Any] | None = None
) -> tuple[StructuredGrid, KeyedFile]:
    """The grid of a .sg file with its properties; and the parsed header (``text`` and
    ``inherited``: a group member's text and the group's CRS block, as for a Voxet)."""
    if text is None:
        text = read_text(path, "SGrid header")
    keyed, _ = parse_keyed(path, text)
    layout = _layout(keyed)
    z_sign = -1.0 if (keyed.crs or inherited or {}).get("ZPOSITIVE") == "Depth" else 1.0
    props = [p for _, p in sorted(property_lines(keyed).items())]
    if layout.splits:
        report(f"{path.name}: {layout.splits} SPLIT nodes are not read (the grid is unsplit)")
    points, values = _values(props, layout, path, z_sign)
    point_data = _flag_properties(layout, path) if layout.ascii_file is None else {}
    cell_data: dict[str, Property] = {}
    for prop in props:
        target = cell_data if _prop_alignment(prop, layout) == "CELLS" else point_data
        target[prop.name] = Property(
            values=values[prop.number],
            unit=prop.unit,
            no_data_value=prop.no_data,
            metadata=property_meta(prop),
        )
    gocad: dict[str, Any] = {"type": "SGrid"}
    if layout.regions:
        gocad["regions"] = dict(layout.regions)
    ni, nj, nk = layout.nodes
    try:
        grid = StructuredGrid(
            name=keyed.name,
            counts=(ni - 1, nj - 1, nk - 1),
            points=points,
            point_data=point_data,
            cell_data=cell_data,
            metadata={"gocad": gocad},
        )
    except EntityValidationError as exc:
        raise FormatError(f"the SGrid is invalid: {exc}", path) from None
    return grid, keyed
