"""Write a :class:`~geobrep.RegularGrid` as a GOCAD Voxet: a .vo header and one raw big-endian
property file per property (``<stem>__<property>@@``) beside it.

Point data are the Voxet's nodes: ``AXIS_O`` is the grid's origin, ``AXIS_U/V/W`` its cell
vectors, ``AXIS_MIN 0 0 0`` and ``AXIS_MAX`` the cell counts (so the nodes are exactly the grid
points). A grid with only cell data is written on its dual lattice (nodes at the cell centres),
as GOCAD stores a block model. Each property file is written atomically before the header.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.gocad._headers import quote_rest
from geobrep.adapters.gocad._numbers import format_float
from geobrep.adapters.gocad._objects import crs_block, report, z_sign_of
from geobrep.errors import FormatError
from geobrep.model.crs import CRS
from geobrep.model.entities import RegularGrid
from geobrep.model.properties import Property
from geobrep.ops.io import atomic_write

__all__ = ["SAFE_NAME", "dtype_words", "final_name", "property_header", "voxet_text", "write_voxet"]

SAFE_NAME = re.compile(r"[^A-Za-z0-9_.-]+")


def final_name(path: Path) -> Path:
    """The name the user asked for, from a temporary name of ``atomic_write``."""
    name = re.sub(r"^\.(.*?)(?:\.tmp-[0-9]+-[0-9a-f]{8})+(\.[^.]*)?$", r"\1\2", path.name)
    return path.with_name(name)


def _vector(values: NDArray[np.float64]) -> str:
    return " ".join(format_float(v) for v in values)


def _layout(grid: RegularGrid) -> tuple[dict[str, Property], NDArray[np.float64], tuple[int, ...]]:
    """The properties written, the first node and the node counts."""
    if grid.point_data or not grid.cell_data:
        if grid.cell_data:
            report(f"{grid.label}: a Voxet holds node values: its cell data are not written")
        return dict(grid.point_data), grid.origin, grid.point_counts
    centre = grid.origin + 0.5 * (grid.u + grid.v + grid.w)
    return dict(grid.cell_data), centre, grid.counts


def property_header(number: int, name: str, prop: Property) -> list[str]:
    """The ``PROPERTY`` line of property ``number`` of a Voxet or SGrid header, with its kind,
    unit and no-data value (the lines on its file follow)."""
    lines = [f"PROPERTY {number} {quote_rest(name)}"]
    section = prop.metadata.get("gocad")
    kind = section.get("kind") if isinstance(section, dict) else None
    if isinstance(kind, str) and kind:
        lines.append(f"PROPERTY_KIND {number} {quote_rest(kind)}")
    if prop.unit:
        lines.append(f"PROP_UNIT {number} {prop.unit}")
    if prop.no_data_value is not None:
        lines.append(f"PROP_NO_DATA_VALUE {number} {format_float(prop.no_data_value)}")
    return lines


def dtype_words(values: NDArray[Any], name: str) -> tuple[np.dtype[Any], list[str]]:
    kind, size = values.dtype.kind, values.dtype.itemsize
    if values.ndim != 1:
        raise FormatError(f"property {name!r}: a Voxet property has one value per node")
    if kind == "b":
        return np.dtype(">u1"), ["PROP_ETYPE", "Octet", "PROP_SIGNED", "0", "PROP_ESIZE", "1"]
    if kind == "f" and size in (4, 8):
        return np.dtype(f">f{size}"), ["PROP_ETYPE", "IEEE", "PROP_ESIZE", str(size)]
    if kind in "iu":
        signed = "1" if kind == "i" else "0"
        return np.dtype(f">{kind}{size}"), [
            "PROP_ETYPE",
            "Octet",
            "PROP_SIGNED",
            signed,
            "PROP_ESIZE",
            str(size),
        ]
    raise FormatError(f"property {name!r}: values of dtype {values.dtype} have no Voxet type")


def voxet_text(
    grid: RegularGrid, crs: CRS | None, files: dict[str, str], ascii_file: str | None = None
) -> tuple[str, dict[str, NDArray[Any]]]:
    """The header text and the big-endian arrays to write under ``files[name]`` (or, with
    ``ascii_file``, the arrays of its table)."""
    props, first, counts = _layout(grid)
    flip = np.array([1.0, 1.0, z_sign_of(crs)])
    lines = ["GOCAD Voxet 1", "HEADER {", f"name:{quote_rest(grid.name or 'voxet')}", "}"]
    lines += crs_block(crs)
    lines += [
        f"AXIS_O {_vector(first * flip)}",
        f"AXIS_U {_vector(grid.u * flip)}",
        f"AXIS_V {_vector(grid.v * flip)}",
        f"AXIS_W {_vector(grid.w * flip)}",
        "AXIS_MIN 0 0 0",
        "AXIS_MAX " + " ".join(str(max(n - 1, 1)) for n in counts),
        "AXIS_N " + " ".join(str(n) for n in counts),
        "AXIS_TYPE even even even",
    ]
    if ascii_file is not None:
        lines.append(f"ASCII_DATA_FILE {ascii_file}")
    arrays: dict[str, NDArray[Any]] = {}
    for number, (name, prop) in enumerate(props.items(), start=1):
        values = np.asarray(prop.values)
        dtype, words = dtype_words(values, name)
        lines += property_header(number, name, prop)
        if ascii_file is not None:
            arrays[name] = values
            continue
        for key, value in zip(words[::2], words[1::2], strict=True):
            lines.append(f"{key} {number} {value}")
        lines.append(f"PROP_FORMAT {number} RAW")
        lines.append(f"PROP_OFFSET {number} 0")
        lines.append(f"PROP_FILE {number} {files[name]}")
        arrays[name] = values.astype(dtype)
    lines.append("END")
    return "\n".join(lines) + "\n", arrays


def _ascii_table(arrays: dict[str, NDArray[Any]], counts: tuple[int, ...]) -> str:
    """``I J K value...`` rows (i fastest) under a three-line ``*`` header, as GOCAD writes."""
    ni, nj, nk = counts
    k, j, i = np.meshgrid(np.arange(nk), np.arange(nj), np.arange(ni), indexing="ij")
    columns = [c.ravel().astype(str) for c in (i, j, k)]
    for values in arrays.values():
        as_text = values.astype(np.int64) if values.dtype.kind in "iub" else values
        columns.append(np.array(list(map(repr, as_text.tolist()))))
    rows = [" ".join(row) for row in zip(*columns, strict=True)]
    header = "*\n*  I  J  K  " + "  ".join(arrays) + "\n*\n"
    return header + "\n".join(rows) + "\n"


def write_voxet(grid: RegularGrid, crs: CRS | None, path: Path, ascii_data: bool = False) -> None:
    """Write the header to ``path`` and the property files (or the ASCII table) beside its
    final name."""
    final = final_name(path)
    props, _, counts = _layout(grid)
    if ascii_data:
        if any(not re.fullmatch(r"\S+", name) for name in props):
            raise FormatError(f"{grid.label}: an ASCII_DATA_FILE column name has no blanks")
        table = f"{final.stem}__ascii@@"
        text, arrays = voxet_text(grid, crs, {}, table)
        with atomic_write(final.with_name(table)) as temporary:
            temporary.write_text(_ascii_table(arrays, counts), encoding="utf-8")
        path.write_text(text, encoding="utf-8")
        return
    files = {name: f"{final.stem}__{SAFE_NAME.sub('_', name)}@@" for name in props}
    if len(set(files.values())) != len(files):
        files = {name: f"{final.stem}__{i}@@" for i, name in enumerate(props, start=1)}
    text, arrays = voxet_text(grid, crs, files)
    for name, values in arrays.items():
        with atomic_write(final.with_name(files[name])) as temporary:
            values.tofile(temporary)
    path.write_text(text, encoding="utf-8")
