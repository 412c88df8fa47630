"""Write a points :class:`~geobrep.StructuredGrid` as a GOCAD SGrid: a .sg header, the node
coordinates (``<stem>__points@@``, big-endian float64 with ``BINARY_POINTS_IN_DOUBLE_PRECISION
1``, so they read back exactly) and one raw big-endian file per property beside it.

Point data are written with ``PROP_ALIGNMENT <n> POINTS``, cell data with ``CELLS``; the point
properties ``sgrid_flags`` and ``sgrid_region_flags`` the reader makes of ``FLAGS_FILE`` and
``REGION_FLAGS_FILE`` go back to those files. Each side file is written atomically before the
header.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.gocad._headers import quote_rest
from geobrep.adapters.gocad._objects import crs_block, gocad_metadata, report, z_sign_of
from geobrep.adapters.gocad._sgrid import FLAGS, REGION_FLAGS
from geobrep.adapters.gocad._voxet_writer import (
    SAFE_NAME,
    dtype_words,
    final_name,
    property_header,
)
from geobrep.errors import FormatError
from geobrep.model.crs import CRS
from geobrep.model.entities import StructuredGrid
from geobrep.model.properties import Property
from geobrep.ops.io import atomic_write

__all__ = ["sgrid_files", "write_sgrid"]


def _flag_lines(grid: StructuredGrid, stem: str, files: dict[str, NDArray[Any]]) -> list[str]:
    """FLAGS_FILE and REGION_FLAGS_FILE lines (and their arrays) from the flag properties."""
    lines: list[str] = []
    flags = grid.point_data.get(FLAGS)
    if flags is not None:
        values = np.asarray(flags.values)
        if values.dtype.kind not in "iub":
            raise FormatError(f"{grid.label}: {FLAGS} must hold integers, not {values.dtype}")
        name = f"{stem}__flags@@"
        files[name] = values.astype(">i4")
        lines += ["FLAGS_OFFSET 0", f"FLAGS_FILE {name}"]
    regions = gocad_metadata(grid).get("regions")
    if isinstance(regions, dict):
        lines += [f"REGION {quote_rest(str(n))} {int(b)}" for n, b in regions.items()]
    region_flags = grid.point_data.get(REGION_FLAGS)
    if region_flags is not None:
        values = np.asarray(region_flags.values)
        if values.dtype.kind not in "iub":
            raise FormatError(f"{grid.label}: {REGION_FLAGS} must hold integers")
        esize = max(1, values.dtype.itemsize)
        name = f"{stem}__region_flags@@"
        files[name] = values.astype(f">u{esize}")
        lines += [
            f"REGION_FLAGS_ARRAY_LENGTH {values.size}",
            f"REGION_FLAGS_ESIZE {esize}",
            "REGION_FLAGS_OFFSET 0",
            f"REGION_FLAGS_FILE {name}",
        ]
    return lines


def _property_lines(
    number: int, name: str, prop: Property, alignment: str, file: str
) -> tuple[list[str], NDArray[Any]]:
    values = np.asarray(prop.values)
    dtype, words = dtype_words(values, name)
    lines = property_header(number, name, prop)
    lines += [f"{k} {number} {v}" for k, v in zip(words[::2], words[1::2], strict=True)]
    lines += [
        f"PROP_ALIGNMENT {number} {alignment}",
        f"PROP_FORMAT {number} RAW",
        f"PROP_OFFSET {number} 0",
        f"PROP_FILE {number} {file}",
    ]
    return lines, values.astype(dtype)


def sgrid_files(
    grid: StructuredGrid, crs: CRS | None, stem: str
) -> tuple[str, dict[str, NDArray[Any]]]:
    """The header text and the big-endian arrays of each side file, by file name."""
    if grid.points is None:
        raise FormatError(
            f"{grid.label}: a corner-point grid has no SGrid form (write it as .grdecl)"
        )
    if grid.actnum is not None and not grid.actnum.all():
        report(f"{grid.label}: an SGrid keeps no inactive cells: actnum is not written")
    ni, nj, nk = grid.counts
    points = grid.points.copy()
    points[:, 2] *= z_sign_of(crs)
    files: dict[str, NDArray[Any]] = {f"{stem}__points@@": points.astype(">f8")}
    point_props = [n for n in grid.point_data if n not in (FLAGS, REGION_FLAGS)]
    only_cells = bool(grid.cell_data) and not point_props
    lines = ["GOCAD SGrid 1", "HEADER {", f"name:{quote_rest(grid.name or 'sgrid')}"]
    lines += ["ascii:off", "double_precision_binary:off", "}", *crs_block(crs)]
    lines += [
        f"AXIS_N {ni + 1} {nj + 1} {nk + 1}",
        f"PROP_ALIGNMENT {'CELLS' if only_cells else 'POINTS'}",
        "BINARY_POINTS_IN_DOUBLE_PRECISION 1",
        "POINTS_OFFSET 0",
        f"POINTS_FILE {stem}__points@@",
    ]
    lines += _flag_lines(grid, stem, files)
    tables = [
        *((n, grid.point_data[n], "POINTS") for n in point_props),
        *((n, p, "CELLS") for n, p in grid.cell_data.items()),
    ]
    for number, (name, prop, alignment) in enumerate(tables, start=1):
        file = f"{stem}__{alignment[0].lower()}{number}_{SAFE_NAME.sub('_', name)}@@"
        prop_lines, files[file] = _property_lines(number, name, prop, alignment, file)
        lines += prop_lines
    lines.append("END")
    return "\n".join(lines) + "\n", files


def write_sgrid(grid: StructuredGrid, crs: CRS | None, path: Path) -> None:
    """Write the side files beside the final name of ``path``, then the header to ``path``."""
    final = final_name(path)
    text, files = sgrid_files(grid, crs, final.stem)
    for name, values in files.items():
        with atomic_write(final.with_name(name)) as temporary:
            values.tofile(temporary)
    path.write_text(text, encoding="utf-8")
