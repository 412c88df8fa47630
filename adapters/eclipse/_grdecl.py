"""Eclipse GRDECL corner-point grids: ``SPECGRID``, ``COORD``, ``ZCORN``, ``ACTNUM`` and cell
properties, to and from :class:`~geobrep.StructuredGrid`.

A GRDECL file is keywords, each followed by its values and a ``/``; ``--`` starts a comment and
``n*v`` repeats ``v`` n times. Depths (COORD z, ZCORN) are positive down: geobrep negates them
(z up) on reading and again on writing. Any other keyword with one value per cell is a cell
property (integer region keywords such as SATNUM stay integers); the rest is reported as
skipped.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.limits import check_declared, human_bytes, parse_numbers
from geobrep.errors import EntityValidationError, FormatError
from geobrep.host.capabilities import SKIPPED_ON_READ
from geobrep.model.entities import StructuredGrid
from geobrep.model.properties import Property
from geobrep.model.scene import Scene

__all__ = ["INTEGER_KEYWORDS", "grdecl_text", "looks_like_grdecl", "read_grdecl", "write_grdecl"]

#: Cell keywords whose values are integers (region numbers).
INTEGER_KEYWORDS = frozenset(
    {"SATNUM", "FIPNUM", "EQLNUM", "PVTNUM", "MULTNUM", "ROCKNUM", "IMBNUM", "FLUXNUM", "OPERNUM"}
)
#: Keywords that stand alone (no values, no slash).
_BARE = frozenset({"ECHO", "NOECHO", "GRID", "EDIT", "PROPS", "REGIONS", "SOLUTION", "NONNC"})
_KEYWORD = re.compile(rb"(?m)^[ \t]*([A-Za-z][A-Za-z0-9_]{0,31})[ \t]*\r?$")
_GEOMETRY = frozenset({"SPECGRID", "DIMENS", "COORD", "ZCORN", "ACTNUM"})
_COMMENT = re.compile(rb"--[^\n]*")
_MAX_FILE = 1 << 34


def looks_like_grdecl(head: bytes) -> bool:
    """True when one of the first keyword lines is SPECGRID, COORD or ZCORN."""
    text = _COMMENT.sub(b"", head)
    return any(
        m.group(1).upper() in (b"SPECGRID", b"COORD", b"ZCORN") for m in _KEYWORD.finditer(text)
    )


def _numbers(block: bytes, path: Path, keyword: str, line: int) -> NDArray[np.float64]:
    """The values of one keyword, ``n*v`` repeats expanded."""
    if b"*" not in block:
        try:
            return parse_numbers(block)
        except ValueError as exc:
            raise FormatError(f"{keyword}: a value is not a number ({exc})", path, line) from None
    out: list[NDArray[np.float64]] = []
    for token in block.split():
        count, star, value = token.partition(b"*")
        try:
            if star:
                repeat = int(count)
                if not 0 < repeat <= 2**31:
                    raise ValueError(f"repeat count {repeat} out of range")
                out.append(np.full(repeat, float(value) if value else np.nan))
            else:
                out.append(np.array([float(token)]))
        except ValueError as exc:
            raise FormatError(f"{keyword}: {exc}", path, line) from None
    return np.concatenate(out) if out else np.zeros(0)


def _records(data: bytes, path: Path) -> list[tuple[str, int, bytes]]:
    """``(keyword, line, values text)`` of every keyword, in file order."""
    text = _COMMENT.sub(b"", data)
    records: list[tuple[str, int, bytes]] = []
    position = 0
    counted, line = 0, 1  # line numbers are counted forward only: linear in the file
    for match in _KEYWORD.finditer(text):
        if match.start() < position:
            continue  # a word inside an earlier keyword's values
        keyword = match.group(1).decode().upper()
        line += text.count(b"\n", counted, match.start())
        counted = match.start()
        if keyword in _BARE:
            position = match.end()
            continue
        end = text.find(b"/", match.end())
        if end < 0:
            raise FormatError(f"{keyword} has no closing '/'", path, line)
        records.append((keyword, line, text[match.end() : end]))
        position = end + 1
    return records


def _specgrid(records: dict[str, tuple[int, bytes]], path: Path) -> tuple[int, int, int]:
    if "SPECGRID" not in records and "DIMENS" not in records:
        raise FormatError("no SPECGRID (or DIMENS) keyword: the grid size is unknown", path)
    keyword = "SPECGRID" if "SPECGRID" in records else "DIMENS"
    line, block = records[keyword]
    tokens = block.split()[:3]
    try:
        counts = tuple(int(t) for t in tokens)
    except ValueError:
        raise FormatError(f"{keyword}: the grid size must be three integers", path, line) from None
    if len(counts) != 3 or min(counts) < 1 or max(counts) > 2**24:
        raise FormatError(f"{keyword}: grid size {tokens} is not three counts ≥ 1", path, line)
    return counts[0], counts[1], counts[2]


def _sized(
    records: dict[str, tuple[int, bytes]], keyword: str, count: int, path: Path
) -> NDArray[np.float64]:
    if keyword not in records:
        raise FormatError(f"no {keyword} keyword", path)
    line, block = records[keyword]
    values = _numbers(block, path, keyword, line)
    if values.shape[0] != count:
        raise FormatError(
            f"{keyword} has {values.shape[0]} values, the grid needs {count}", path, line
        )
    return values


def read_grdecl(path: Path) -> Scene:
    """The corner-point grid of a GRDECL file (depths turned into z up)."""
    size = path.stat().st_size
    if size > _MAX_FILE:
        raise FormatError(f"the file is {human_bytes(size)}, more than a GRDECL file may be", path)
    listed = _records(path.read_bytes(), path)
    records = {keyword: (line, block) for keyword, line, block in listed}
    ni, nj, nk = _specgrid(records, path)
    n_cells = ni * nj * nk
    check_declared(8 * (8 * n_cells + 6 * (ni + 1) * (nj + 1)), size, "SPECGRID", path)
    coord = _sized(records, "COORD", 6 * (ni + 1) * (nj + 1), path).reshape(-1, 6)
    coord[:, [2, 5]] *= -1.0
    zcorn = -_sized(records, "ZCORN", 8 * n_cells, path)
    actnum = None
    if "ACTNUM" in records:
        actnum = _sized(records, "ACTNUM", n_cells, path) != 0
    cell_data: dict[str, Property] = {}
    skipped: list[str] = []
    for keyword, line, block in listed:
        if keyword in _GEOMETRY:
            continue
        values = _numbers(block, path, keyword, line)
        if values.shape[0] != n_cells:
            skipped.append(f"{path.name}:{line}: keyword {keyword} ({values.shape[0]} values)")
            continue
        if keyword in INTEGER_KEYWORDS and np.all(values == np.round(values)):
            cell_data[keyword] = Property(values=values.astype(np.int32))
        else:
            cell_data[keyword] = Property(values=values)
    try:
        grid = StructuredGrid(
            id=0,
            name=path.stem,
            counts=(ni, nj, nk),
            coord=coord,
            zcorn=zcorn,
            actnum=actnum,
            cell_data=cell_data,
        )
    except EntityValidationError as exc:
        raise FormatError(f"the grid is invalid: {exc}", path) from None
    metadata: dict[str, Any] = {SKIPPED_ON_READ: skipped} if skipped else {}
    return Scene(entities=[grid], name=path.stem, metadata=metadata)


def _values_text(values: NDArray[Any], per_line: int = 8) -> str:
    """Values ``per_line`` to a line, then ``/`` alone on its line (as OpenGeode reads it)."""
    if values.dtype.kind in "iub":
        texts = values.astype(np.int64).astype(str).tolist()
    else:
        texts = list(map(repr, values.astype(np.float64).tolist()))
    rows = [" ".join(texts[i : i + per_line]) for i in range(0, len(texts), per_line)]
    return "\n".join(rows) + "\n/\n"


def grdecl_text(grid: StructuredGrid) -> str:
    """The GRDECL text of a corner-point grid."""
    if grid.coord is None or grid.zcorn is None:
        raise FormatError(f"{grid.label} has no pillars: GRDECL holds corner-point grids only")
    ni, nj, nk = grid.counts
    coord = np.array(grid.coord)
    coord[:, [2, 5]] *= -1.0
    parts = [f"-- {grid.name or 'grid'} written by geobrep\n", f"SPECGRID\n{ni} {nj} {nk} 1 F\n/\n"]
    parts += [
        "COORD\n",
        _values_text(coord.ravel(), per_line=6),
        "ZCORN\n",
        _values_text(-grid.zcorn),
    ]
    if grid.actnum is not None:
        parts += ["ACTNUM\n", _values_text(grid.actnum.astype(np.int8))]
    for name, prop in grid.cell_data.items():
        keyword = name.upper()
        if not re.fullmatch(r"[A-Z][A-Z0-9_]{0,31}", keyword) or keyword in _GEOMETRY:
            raise FormatError(f"{grid.label}: property {name!r} cannot be a GRDECL keyword")
        values = np.asarray(prop.values)
        if values.ndim != 1:
            raise FormatError(f"{grid.label}: property {name!r} has vector values")
        parts += [f"{keyword}\n", _values_text(values)]
    return "".join(parts)


def write_grdecl(scene: Scene, path: Path, options: object) -> None:
    """Write the scene's first corner-point grid."""
    grids = [e for e in scene.entities if isinstance(e, StructuredGrid) and e.is_corner_point]
    if not grids:
        raise FormatError("the scene has no corner-point StructuredGrid to write as GRDECL", path)
    path.write_text(grdecl_text(grids[0]), encoding="ascii")
