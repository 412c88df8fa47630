"""Reading and writing the points table of the ``csv`` format (see :mod:`geobrep.adapters.csv`)."""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import orjson
from numpy.typing import NDArray

from geobrep.adapters import _strict_json as strict_json
from geobrep.adapters.casting import misfit_rows
from geobrep.errors import FileAccessError, FormatError, GeobrepError
from geobrep.model.crs import CRS
from geobrep.model.entities import PointSet
from geobrep.model.properties import Property
from geobrep.model.scene import Scene

__all__ = ["looks_like_points_table", "read_points_table", "write_points_table"]

METADATA_PREFIX = "# geobrep:"
_SPLIT = re.compile(r"[,;\s]+")
_COMPONENT = re.compile(r"^(.*)\[(\d+)\]$")
_SPLIT_BYTES = re.compile(rb"[,;\s]+")
_NAME = re.compile(rb'"?[A-Za-z_][\w.\[\]-]*"?')


def looks_like_points_table(head: bytes) -> bool:
    """True when the file starts like a points table (the sniffer): an optional header, then
    rows of at least three numbers, every row as wide as the header and the first row."""
    if b"\0" in head:
        return False
    lines = head.splitlines()
    if not head.endswith((b"\n", b"\r")):
        lines = lines[:-1]  # the last line may be cut short
    rows = [
        line.strip() for line in lines[:20] if line.strip() and not line.lstrip().startswith(b"#")
    ]
    if not rows:
        return False
    widths = set()
    for index, row in enumerate(rows):
        tokens = [t for t in _SPLIT_BYTES.split(row) if t]
        try:
            [float(t) for t in tokens]
        except ValueError:
            if index > 0 or not all(_NAME.fullmatch(t) for t in tokens):
                return False
        widths.add(len(tokens))
    return len(widths) == 1 and widths.pop() >= 3 and len(rows) > 1


def _tokens(line: str) -> list[str]:
    return [token for token in _SPLIT.split(line.strip()) if token]


class _Constant(str):
    """``NaN``, ``Infinity`` or ``-Infinity`` as a metadata line spelled it (not JSON)."""


def _misplaced_constant(data: Any) -> str | None:
    """Where ``data`` holds a :class:`_Constant` other than a property's no-data value.

    Older geobrep wrote NaN no-data values as bare ``NaN``: those are read; anywhere else a
    NaN would make the scene unwritable to JSON later.
    """

    def misplaced(value: Any, where: tuple[str, ...]) -> bool:
        no_data = len(where) == 3 and where[0] == "properties" and where[2] == "no_data_value"
        return isinstance(value, _Constant) and not no_data

    found = strict_json.find_leaf(data, misplaced)
    return None if found is None else ".".join(found) or "(the line)"


def _metadata(line: str, path: Path, number: int) -> dict[str, Any]:
    try:
        data = json.loads(line[len(METADATA_PREFIX) :], parse_constant=_Constant)
        misplaced = _misplaced_constant(data)
    except json.JSONDecodeError as exc:
        raise FormatError(
            f"the '# geobrep:' line is not valid JSON ({exc.msg})", path, number
        ) from None
    except RecursionError:
        raise FormatError("the '# geobrep:' line nests too deeply", path, number) from None
    if not isinstance(data, dict):
        raise FormatError("the '# geobrep:' line must hold a JSON object", path, number)
    if misplaced is not None:
        raise FormatError(
            f"the '# geobrep:' line holds a NaN or infinity at {misplaced} (JSON has none; "
            "only a property's no_data_value may be one)",
            path,
            number,
        )
    return data


def _parse_rows(lines: list[tuple[int, str]], width: int, path: Path) -> NDArray[np.float64]:
    joined = "\n".join(line for _, line in lines)
    try:
        rows = np.array(_SPLIT.split(joined.strip()), dtype=np.float64)
        if rows.size != len(lines) * width:
            raise ValueError("ragged rows")
        return rows.reshape(len(lines), width)
    except ValueError:
        for number, line in lines:  # find the first bad line for the message
            tokens = _tokens(line)
            if len(tokens) != width:
                raise FormatError(
                    f"expected {width} values, found {len(tokens)}", path, number
                ) from None
            for token in tokens:
                try:
                    float(token)
                except ValueError:
                    raise FormatError(f"not a number: {token!r}", path, number) from None
        raise FormatError("cannot parse the points", path) from None


def _typed(
    values: NDArray[np.float64], dtype: np.dtype[Any], columns: list[str], table: _Table
) -> NDArray[Any]:
    """``values`` as the integer or boolean ``dtype`` the metadata line declares, when every
    value fits it; otherwise a FormatError naming the column and the line."""
    bad = misfit_rows(values, dtype)
    if bad.any():
        row = int(np.argmax(bad))
        column = int(np.argmax(misfit_rows(values[row : row + 1].T, dtype)))
        raise FormatError(
            f"column {columns[column]!r} holds {float(values[row, column])!r}, which does not "
            f"fit the {dtype} its '# geobrep:' line declares",
            table.path,
            table.line_numbers[row],
        )
    return values.astype(dtype)


@dataclass(frozen=True)
class _Table:
    """Where the rows of a points table come from: the file and the line of each row."""

    path: Path
    line_numbers: list[int]


def _properties(
    names: list[str],
    rows: NDArray[np.float64],
    xyz: list[int],
    meta: dict[str, Any],
    table: _Table,
) -> dict[str, Property]:
    groups: dict[str, list[tuple[int, int]]] = {}
    for column, name in enumerate(names):
        if column in xyz:
            continue
        match = _COMPONENT.match(name)
        base, index = (match.group(1), int(match.group(2))) if match else (name, 0)
        groups.setdefault(base, []).append((index, column))
    described = meta.get("properties") or {}
    result: dict[str, Property] = {}
    for base, members in groups.items():
        members.sort()
        values = rows[:, [column for _, column in members]]
        info = described.get(base) or {}
        dtype = np.dtype(info.get("dtype", "float64"))
        if dtype.kind in "iub":
            values = _typed(values, dtype, [names[column] for _, column in members], table)
        no_data = info.get("no_data_value")
        result[base] = Property(
            values=values[:, 0] if len(members) == 1 else values,
            unit=info.get("unit"),
            no_data_value=float(no_data) if isinstance(no_data, _Constant) else no_data,
        )
    return result


def read_points_table(path: Path) -> Scene:
    """One PointSet from a delimited text file; FormatError names the line of a bad row."""
    try:
        text = path.read_text(encoding="utf-8-sig")
    except OSError as exc:
        raise FileAccessError(f"cannot be read ({exc.strerror or exc})", path) from exc
    except UnicodeDecodeError as exc:
        raise FormatError(f"not a text file ({exc.reason})", path) from exc
    meta: dict[str, Any] = {}
    lines: list[tuple[int, str]] = []
    for number, line in enumerate(text.splitlines(), 1):
        stripped = line.strip()
        if stripped.startswith(METADATA_PREFIX):
            meta = _metadata(stripped, path, number)
        elif stripped and not stripped.startswith("#"):
            lines.append((number, line))
    if not lines:
        raise FormatError("no points in the file", path)
    first = _tokens(lines[0][1])
    header: list[str] | None = None
    try:
        [float(token) for token in first]
    except ValueError:
        header = [token.strip().strip('"') for token in first]
        lines = lines[1:]
    if not lines:
        raise FormatError("the file has a header but no points", path)
    width = len(_tokens(lines[0][1]))
    if width < 3:
        raise FormatError(f"need x, y, z columns, found {width}", path, lines[0][0])
    if header is not None and len(header) != width:
        raise FormatError(
            f"the header names {len(header)} columns but the rows have {width}", path, lines[0][0]
        )
    rows = _parse_rows(lines, width, path)
    names = header or ["x", "y", "z", *(f"column_{k + 1}" for k in range(3, width))]
    lowered = [name.lower() for name in names]
    xyz = [lowered.index(a) for a in "xyz"] if {"x", "y", "z"} <= set(lowered) else [0, 1, 2]
    bad = ~np.isfinite(rows[:, xyz]).all(axis=1)
    if bad.any():
        number = lines[int(np.argmax(bad))][0]
        raise FormatError("coordinates must be finite (NaN or inf found)", path, number)
    table = _Table(path, [number for number, _ in lines])
    try:
        points = PointSet(
            vertices=rows[:, xyz],
            point_data=_properties(names, rows, xyz, meta, table),
            name=meta.get("name", path.stem),
            kind=meta.get("kind"),
        )
        crs = CRS.model_validate(meta["crs"]) if meta.get("crs") else None
        return Scene(entities=[points], crs=crs, name=meta.get("scene", ""))
    except FormatError:
        raise
    except (GeobrepError, ValueError, TypeError, AttributeError) as exc:
        where = "the '# geobrep:' line" if meta else "the table"
        raise FormatError(f"{where} does not describe valid points: {exc}", path) from None


def _text_block(block: NDArray[np.float64], delimiter: str) -> bytes:
    """Rows of shortest round-trip float texts (orjson prints floats exactly)."""
    if np.isfinite(block).all():
        text = orjson.dumps(np.ascontiguousarray(block), option=orjson.OPT_SERIALIZE_NUMPY)
        body = text[2:-2].replace(b"],[", b"\n")
        return body if delimiter == "," else body.replace(b",", delimiter.encode())
    rows = (delimiter.join(repr(v) for v in row) for row in block.tolist())
    return "\n".join(rows).encode()


def _json_float(value: float | None) -> float | str | None:
    """A no-data value as JSON: NaN and infinities as the strings Property reads back."""
    if value is None or np.isfinite(value):
        return value
    return "NaN" if np.isnan(value) else ("Infinity" if value > 0 else "-Infinity")


def _merged(scene: Scene) -> PointSet:
    points = scene.point_sets
    if not points:
        raise FormatError("a points table needs a PointSet; the scene has none")
    if len(points) == 1:
        return points[0]
    shared = set.intersection(*(set(p.point_data) for p in points))
    data = {
        name: np.concatenate([p.point_data[name].values for p in points]) for name in sorted(shared)
    }
    return PointSet(vertices=np.concatenate([p.vertices for p in points]), point_data=data)


def write_points_table(scene: Scene, path: Path, *, delimiter: str, metadata: bool) -> None:
    """Write the scene's PointSet (several are merged into one) as a points table."""
    if delimiter not in (",", ";", "\t", " "):
        raise FormatError(f"delimiter {delimiter!r} must be one of ',', ';', tab or space", path)
    points = _merged(scene)
    columns: list[NDArray[Any]] = [points.vertices]
    header = ["x", "y", "z"]
    described: dict[str, Any] = {}
    for name, prop in points.point_data.items():
        if _SPLIT.search(name) or _COMPONENT.match(name):
            raise FormatError(f"property name {name!r} cannot be a column name", path)
        values = prop.values.reshape(points.n_points, -1)
        header += (
            [name] if values.shape[1] == 1 else [f"{name}[{k}]" for k in range(values.shape[1])]
        )
        if misfit_rows(values, np.float64).any():
            raise FormatError(
                f"property {name!r} holds integers beyond 2**53, which a text column of "
                "floats cannot hold exactly",
                path,
            )
        columns.append(values.astype(np.float64))
        info = {"unit": prop.unit, "no_data_value": _json_float(prop.no_data_value)}
        info["dtype"] = str(prop.dtype)
        described[name] = {k: v for k, v in info.items() if v is not None and v != "float64"}
    block = np.concatenate(columns, axis=1)
    with path.open("wb") as handle:
        if metadata:
            meta: dict[str, Any] = {"name": points.name, "kind": points.kind, "scene": scene.name}
            if scene.crs is not None:
                meta["crs"] = scene.crs.model_dump(mode="json", exclude_defaults=True)
            meta["properties"] = {k: v for k, v in described.items() if v}
            compact = {k: v for k, v in meta.items() if v or k == "name"}
            try:
                text = json.dumps(compact, allow_nan=False)
            except ValueError as exc:
                raise FormatError(f"the metadata cannot be written as JSON: {exc}", path) from None
            handle.write(f"{METADATA_PREFIX} {text}\n".encode())
        handle.write(delimiter.join(header).encode() + b"\n")
        handle.write(_text_block(block, delimiter) + b"\n")
