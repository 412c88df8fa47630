"""Well deviation tables: Petrel ``.dev`` files and plain ``X Y Z`` path tables (.dat, .txt).

A ``.dev`` file has ``#`` comment lines (the well name, head and datum among them), a header line
naming the columns (``MD X Y Z TVD DX DY AZIM_TN INCL DLS AZIM_GN``) and one row per station. X,
Y and Z (elevation, decreasing downwards) are the station; MD its measured depth; the other
columns become station properties (``INCL`` and ``AZIM_*`` in degrees). A table without a
header is ``X Y Z`` rows, whose MD is the length along the stations.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.limits import human_bytes
from geobrep.errors import EntityValidationError, FormatError
from geobrep.model.entities import Well
from geobrep.model.properties import Property
from geobrep.model.scene import Scene

__all__ = ["deviation_text", "read_deviation", "write_deviation"]

_MAX_FILE = 1 << 30
_NUMBER = re.compile(r"^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")
_HEADER = {
    "name": re.compile(r"#\s*WELL NAME:\s*(.+)"),
    "datum": re.compile(r"#\s*WELL DATUM \(([^,)]+)[^:]*:\s*([-+0-9.eE]+)"),
}


def _is_numeric_row(tokens: list[str]) -> bool:
    return bool(tokens) and all(_NUMBER.match(t) for t in tokens)


def _table(path: Path) -> tuple[list[str], list[str], NDArray[np.float64], int]:
    """Comment lines, column names, the numeric rows and the first row's line number."""
    size = path.stat().st_size
    if size > _MAX_FILE:
        raise FormatError(f"the file is {human_bytes(size)}, more than a well table may be", path)
    lines = path.read_bytes().decode("latin-1").replace("\r", "\n").split("\n")
    comments = [t for t in lines if t.lstrip().startswith("#")]
    columns: list[str] = []
    rows: list[str] = []
    first = 0
    for number, text in enumerate(lines, start=1):
        stripped = text.strip()
        if not stripped or stripped.startswith("#"):
            continue
        tokens = stripped.split()
        if _is_numeric_row(tokens):
            first = first or number
            rows.append(stripped)
        elif not rows and not columns:
            columns = [t.upper() for t in tokens]
        else:
            raise FormatError(f"not a row of numbers: {stripped[:60]!r}", path, number)
    if not rows:
        raise FormatError("the table has no rows of numbers", path)
    width = len(rows[0].split())
    try:
        values = np.array(" ".join(rows).split(), dtype=np.float64)
    except ValueError as exc:
        raise FormatError(f"the table holds a value that is not a number: {exc}", path) from None
    if values.size % width or any(
        len(r.split()) != width for r in rows[:: max(len(rows) // 50, 1)]
    ):
        raise FormatError(f"the rows do not all have {width} values", path, first)
    if columns and len(columns) != width:
        raise FormatError(f"{len(columns)} column names for rows of {width} values", path, first)
    return comments, columns, values.reshape(-1, width), first


def read_deviation(path: Path) -> Scene:
    """The well of a deviation table."""
    comments, columns, table, first = _table(path)
    if not columns:
        if table.shape[1] != 3:
            raise FormatError(
                f"a table without a header needs X Y Z rows, not {table.shape[1]} values",
                path,
                first,
            )
        columns = ["X", "Y", "Z"]
    missing = [c for c in ("X", "Y", "Z") if c not in columns]
    if missing:
        raise FormatError(f"no {' '.join(missing)} column (columns: {' '.join(columns)})", path)
    xyz = table[:, [columns.index(c) for c in ("X", "Y", "Z")]]
    if "MD" in columns:
        md = table[:, columns.index("MD")]
    else:
        md = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(xyz, axis=0), axis=1))])
    props = {
        name: Property(values=np.ascontiguousarray(table[:, k]), unit=_unit(name))
        for k, name in enumerate(columns)
        if name not in ("MD", "X", "Y", "Z")
    }
    fields: dict[str, Any] = {"name": path.stem}
    kept = [c for c in comments if _HEADER["name"].match(c.strip()) is None]
    for line in comments:
        if (found := _HEADER["name"].match(line.strip())) is not None:
            fields["name"] = found.group(1).strip()
        elif (found := _HEADER["datum"].match(line.strip())) is not None:
            fields["datum"] = found.group(1).strip()
            fields["datum_elevation"] = float(found.group(2))
    try:
        well = Well(
            id=0,
            head=xyz[0],
            vertices=xyz,
            md=md,
            point_data=props,
            metadata={"deviation": {"header": kept}} if kept else {},
            **fields,
        )
    except EntityValidationError as exc:
        raise FormatError(f"the well path is invalid: {exc}", path) from None
    return Scene(entities=[well], name=path.stem)


def _unit(column: str) -> str | None:
    if column.startswith(("AZIM", "INCL")):
        return "deg"
    if column == "DLS":
        return "deg/30m"
    return None


def deviation_text(well: Well) -> str:
    """The .dev text of a well: a name line and the header comments kept from its source, then
    MD X Y Z and the station properties."""
    section = well.metadata.get("deviation")
    kept = section.get("header") if isinstance(section, dict) else None
    comments = [f"# WELL NAME: {well.name}"] if well.name else []
    comments += [str(c) for c in kept] if isinstance(kept, list) else []
    names = [n for n, p in well.point_data.items() if np.asarray(p.values).ndim == 1]
    if any(not re.fullmatch(r"\S+", n) or n.upper() != n for n in names):
        raise FormatError(f"{well.label}: station property names must be upper case words")
    columns = [well.md, *well.vertices.T, *(np.asarray(well.point_data[n].values) for n in names)]
    table = np.stack([np.asarray(c, dtype=np.float64) for c in columns], axis=1)
    rows = [" ".join(map(repr, row)) for row in table.tolist()]
    return "\n".join([*comments, " ".join(["MD", "X", "Y", "Z", *names]), *rows]) + "\n"


def write_deviation(scene: Scene, path: Path, options: object) -> None:
    wells = [e for e in scene.entities if isinstance(e, Well)]
    if not wells:
        raise FormatError("the scene has no Well to write as a deviation table", path)
    path.write_text(deviation_text(wells[0]), encoding="latin-1")
