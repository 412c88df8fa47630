"""Scenes to and from PLY with ``plyfile``: float64 coordinates, every property kept.

A scene is written as one ``vertex`` element (``x y z`` as ``double`` plus one PLY property
per point-property column), one ``face`` element (``vertex_indices`` plus the face
properties, among them :data:`~geobrep.adapters.cell_layout.ENTITY_ARRAY` and
:data:`~geobrep.adapters.cell_layout.PART_ARRAY`) and, for polylines, one ``edge`` element
(``vertex1 vertex2``). Names, ids, kinds, units, CRS and groups travel in a
``comment geobrep-header {json}`` line. Files from other programs read as one surface (or
point set) keeping all vertices and every vertex and face property under its PLY name.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Final

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters import _strict_json as strict_json
from geobrep.adapters.casting import cast_exactly
from geobrep.adapters.cell_layout import (
    ENTITY_ARRAY,
    CellLayout,
    check_header,
    header_applies,
    layout_to_scene,
    located,
    scene_to_layout,
)
from geobrep.adapters.ply._sizes import check_element_sizes
from geobrep.errors import FormatError, import_optional
from geobrep.model.entities import PointSet, PolyLine, Surface
from geobrep.model.properties import PropertyMap
from geobrep.model.scene import Scene

__all__ = ["HEADER_COMMENT", "read_ply", "write_ply"]

HEADER_COMMENT: Final = "geobrep-header "
FACE_WIDTH_KEY: Final = "ply_face_width"
_PLY_KINDS: Final = frozenset("iuf")
_INDEX_NAMES: Final = ("vertex_indices", "vertex_index")
_RESERVED: Final = frozenset({"x", "y", "z", "vertex1", "vertex2", *_INDEX_NAMES})


def _plyfile() -> Any:
    return import_optional("plyfile", "ply", "reading and writing PLY files")


def _storable(values: NDArray[Any]) -> NDArray[Any]:
    """Values in a dtype PLY has (no 64-bit integers, no bools), losslessly."""
    if values.dtype == np.bool_:
        return values.astype(np.uint8)
    if values.dtype.kind not in _PLY_KINDS:
        raise TypeError(f"PLY cannot store {values.dtype} values")
    if values.dtype.itemsize == 8 and values.dtype.kind in "iu":
        info = np.iinfo(np.int32 if values.dtype.kind == "i" else np.uint32)
        if values.size == 0 or (values.min() >= info.min and values.max() <= info.max):
            return values.astype(np.int32 if values.dtype.kind == "i" else np.uint32)
        return values.astype(np.float64)
    return values


def _columns(arrays: dict[str, NDArray[Any]], index: Any) -> list[tuple[str, NDArray[Any]]]:
    columns: list[tuple[str, NDArray[Any]]] = []
    for name, values in arrays.items():
        selected = _storable(np.asarray(values)[index])
        if selected.ndim == 1:
            columns.append((name, selected))
        else:
            columns.extend(
                (f"{name}__{k}", np.ascontiguousarray(selected[:, k]))
                for k in range(selected.shape[1])
            )
    return columns


def _element(plyfile: Any, name: str, columns: list[tuple[str, NDArray[Any]]], count: int) -> Any:
    dtype: list[tuple[Any, ...]] = []
    for column, values in columns:
        if values.ndim == 2:
            dtype.append((column, values.dtype.str, (values.shape[1],)))
        else:
            dtype.append((column, values.dtype.str))
    data = np.empty(count, dtype=dtype)
    for column, values in columns:
        data[column] = values
    return plyfile.PlyElement.describe(data, name, len_types={"vertex_indices": "u1"})


def _packed(data: NDArray[Any]) -> NDArray[Any]:
    """Rows as PLY binary little-endian records: fixed-length lists get their count byte."""
    fields: list[tuple[Any, ...]] = []
    assert data.dtype.names is not None
    for name in data.dtype.names:
        field = data.dtype[name]
        if field.subdtype is not None:
            base, shape = field.subdtype
            fields.append((f"{name}__count", "u1"))
            fields.append((name, base.newbyteorder("<"), shape))
        else:
            fields.append((name, field.newbyteorder("<")))
    packed = np.empty(len(data), dtype=np.dtype(fields, align=False))
    for name in data.dtype.names:
        field = data.dtype[name]
        if field.subdtype is not None:
            packed[f"{name}__count"] = field.subdtype[1][0]
        packed[name] = data[name]
    return packed


def write_ply(scene: Scene, path: Path, binary: bool = True) -> None:
    """Write the point sets, polylines and surfaces of ``scene`` to ``path``."""
    plyfile = _plyfile()
    layout = scene_to_layout(scene, _RESERVED)
    kinds = np.concatenate(
        [np.full(conn.shape[0], kind, dtype=object) for kind, conn in layout.blocks]
        or [np.zeros(0, dtype=object)]
    )
    face_kinds = {kind for kind, _ in layout.blocks if kind in ("triangle", "quad")}
    elements = [
        _element(
            plyfile,
            "vertex",
            [
                ("x", layout.points[:, 0]),
                ("y", layout.points[:, 1]),
                ("z", layout.points[:, 2]),
                *_columns(layout.point_data, slice(None)),
            ],
            len(layout.points),
        )
    ]
    if face_kinds:
        if len(face_kinds) > 1:
            raise FormatError("PLY writer: mix of triangle and quad surfaces", path)
        is_face = np.isin(kinds, list(face_kinds))
        faces = np.concatenate([c for k, c in layout.blocks if k in face_kinds])
        columns = [("vertex_indices", faces.astype(np.int32)), *_columns(layout.cell_data, is_face)]
        elements.append(_element(plyfile, "face", columns, len(faces)))
    if "line" in kinds:
        is_edge = kinds == "line"
        edges = np.concatenate([c for k, c in layout.blocks if k == "line"]).astype(np.int32)
        columns = [
            ("vertex1", edges[:, 0]),
            ("vertex2", edges[:, 1]),
            *_columns(layout.cell_data, is_edge),
        ]
        elements.append(_element(plyfile, "edge", columns, len(edges)))
    import json

    assert layout.header is not None
    if face_kinds:
        layout.header[FACE_WIDTH_KEY] = 3 if face_kinds == {"triangle"} else 4
    header = HEADER_COMMENT + json.dumps(layout.header, separators=(",", ":"), allow_nan=False)
    data = plyfile.PlyData(elements, text=not binary, byte_order="<", comments=[header])
    if not binary:
        data.write(str(path))
        return
    # plyfile writes list properties one row at a time; fixed-length lists pack in one go
    with path.open("wb") as stream:
        stream.write(data.header.encode("ascii") + b"\n")
        for element in elements:
            stream.write(_packed(element.data).tobytes())


def _header_of(ply: Any) -> dict[str, Any] | None:
    for comment in ply.comments:
        if comment.startswith(HEADER_COMMENT):
            try:
                header = strict_json.loads(comment[len(HEADER_COMMENT) :])
            except ValueError:
                return None
            return header if isinstance(header, dict) else None
    return None


def _gather(element: Any, skip: tuple[str, ...]) -> dict[str, NDArray[Any]]:
    data = element.data
    return {
        name: np.asarray(data[name])
        for name in data.dtype.names or ()
        if name not in skip and data.dtype[name].kind != "O"
    }


def _regroup(arrays: dict[str, NDArray[Any]]) -> dict[str, NDArray[Any]]:
    """Put ``name__0``, ``name__1`` ... columns back into ``(N, k)`` arrays."""
    grouped: dict[str, list[tuple[int, NDArray[Any]]]] = {}
    plain: dict[str, NDArray[Any]] = {}
    for name, values in arrays.items():
        base, sep, index = name.rpartition("__")
        if sep and index.isdigit():
            grouped.setdefault(base, []).append((int(index), values))
        else:
            plain[name] = values
    for base, columns in grouped.items():
        columns.sort(key=lambda item: item[0])
        plain[base] = np.column_stack([values for _, values in columns])
    return plain


def _faces_of(element: Any, path: Path) -> tuple[NDArray[np.int64], NDArray[np.int64] | None]:
    """Face connectivity; with polygons of several sizes, fan triangles and their source face."""
    data = element.data
    name = next((n for n in _INDEX_NAMES if n in (data.dtype.names or ())), None)
    if name is None:
        raise FormatError("PLY face element has no vertex_indices property", path)
    column = data[name]
    what = f"face {name}"
    if column.dtype.kind != "O":
        indices = cast_exactly(column, np.int64, what, path)
        return indices.reshape(len(data), -1) if len(data) else np.zeros((0, 3), np.int64), None
    lengths = np.fromiter((len(f) for f in column), dtype=np.int64, count=len(column))
    flat = (
        cast_exactly(np.concatenate(list(column)), np.int64, what, path)
        if len(column)
        else np.zeros(0, np.int64)
    )
    if len(lengths) and (lengths == lengths[0]).all() and lengths[0] in (3, 4):
        return flat.reshape(len(lengths), int(lengths[0])), None
    # polygons of several sizes: fan-triangulate every face
    if (lengths < 3).any():
        raise FormatError("PLY face with fewer than 3 vertices", path)
    starts = np.concatenate([[0], np.cumsum(lengths)[:-1]])
    owner = np.repeat(np.arange(len(lengths)), lengths - 2)
    rank = np.arange(len(owner)) - np.repeat(np.cumsum(lengths - 2) - (lengths - 2), lengths - 2)
    first = flat[starts[owner]]
    second, third = flat[starts[owner] + rank + 1], flat[starts[owner] + rank + 2]
    return np.column_stack([first, second, third]), owner


def read_ply(path: Path) -> Scene:
    """Read a PLY file (binary or ASCII); exactly the scene geobrep wrote, when it did.

    The element counts of the header are checked against the bytes the file holds (and the
    read budget, :mod:`geobrep.adapters.limits`) before plyfile allocates anything.
    """
    plyfile = _plyfile()
    check_element_sizes(path)
    peeked = _peek_header(path)
    width = peeked.get(FACE_WIDTH_KEY) if peeked else None
    known = {"face": {"vertex_indices": width}} if isinstance(width, int) and width > 0 else {}
    try:
        ply = plyfile.PlyData.read(str(path), known_list_len=known)
    except Exception as exc:
        raise FormatError(f"not a readable PLY file: {type(exc).__name__}: {exc}", path) from exc
    elements = _elements_of(ply, path)
    header = _header_of(ply)
    ids = {**elements.face_data, **elements.edge_data}
    with located(path):  # an entity refusing what the file holds says which file
        if header is not None and (header_applies(header, ids) or elements.faces is None):
            check_header(header, len(elements.points), path)
            return _from_header(path, header, elements)
        return _foreign(path, elements)


def _scalar_column(element: Any, name: str, path: Path) -> NDArray[Any]:
    """A scalar property of a PLY element as numbers; a list or missing property is an error."""
    data = element.data
    if name not in (data.dtype.names or ()):
        raise FormatError(f"PLY {element.name} element has no {name!r} property", path)
    column = data[name]
    if column.dtype.kind not in "biuf":
        raise FormatError(
            f"PLY {element.name} property {name!r} must be a number, not a list", path
        )
    return np.asarray(column)


def _elements_of(ply: Any, path: Path) -> _Elements:
    """The vertices, faces and edges of a parsed PLY file, with their properties."""
    names = [element.name for element in ply.elements]
    if "vertex" not in names:
        raise FormatError("PLY file has no vertex element", path)
    vertex = ply["vertex"]
    points = np.column_stack(
        [_scalar_column(vertex, a, path).astype(np.float64) for a in "xyz"]
    ).reshape(-1, 3)
    point_data = _gather(vertex, ("x", "y", "z"))
    faces, face_owner = _faces_of(ply["face"], path) if "face" in names else (None, None)
    face_data = _gather(ply["face"], _INDEX_NAMES) if "face" in names else {}
    if face_owner is not None:
        face_data = {name: values[face_owner] for name, values in face_data.items()}
    edge_data: dict[str, NDArray[Any]] = {}
    edges = None
    if "edge" in names:
        edge = ply["edge"]
        edge_data = _gather(edge, ("vertex1", "vertex2"))
        ends = [
            cast_exactly(_scalar_column(edge, end, path), np.int64, f"edge {end}", path)
            for end in ("vertex1", "vertex2")
        ]
        edges = np.column_stack(ends).reshape(-1, 2)
    return _Elements(points, point_data, faces, face_data, edges, edge_data)


def _peek_header(path: Path) -> dict[str, Any] | None:
    """geobrep's header comment, read from the PLY header text only."""
    with path.open("rb") as stream:
        head = stream.read(1 << 20)
    end = head.find(b"end_header")
    if not head.startswith(b"ply") or end < 0:
        return None
    for line in head[:end].decode("latin-1").splitlines():
        if line.startswith("comment " + HEADER_COMMENT):
            try:
                header = strict_json.loads(line[len("comment " + HEADER_COMMENT) :])
            except ValueError:
                return None
            return header if isinstance(header, dict) else None
    return None


@dataclass(frozen=True)
class _Elements:
    """What a PLY file holds: vertices, faces and edges, each with its properties."""

    points: NDArray[np.float64]
    point_data: dict[str, NDArray[Any]]
    faces: NDArray[np.int64] | None
    face_data: dict[str, NDArray[Any]]
    edges: NDArray[np.int64] | None
    edge_data: dict[str, NDArray[Any]]


def _from_header(path: Path, header: dict[str, Any], elements: _Elements) -> Scene:
    """The scene geobrep wrote, rebuilt from its header comment."""
    faces, edges = elements.faces, elements.edges
    blocks: list[tuple[str, NDArray[np.int64]]] = []
    pieces: list[dict[str, NDArray[Any]]] = []
    if faces is not None:
        blocks.append(("triangle" if faces.shape[1] == 3 else "quad", faces))
        pieces.append(_regroup(elements.face_data))
    if edges is not None:
        blocks.append(("line", edges))
        pieces.append(_regroup(elements.edge_data))
    point_sets = [r for r in header.get("entities", []) if r.get("type") == "PointSet"]
    for record in point_sets:
        start, stop = record["points"]
        blocks.append(("vertex", np.arange(start, stop, dtype=np.int64)[:, None]))
        pieces.append({ENTITY_ARRAY: np.full(stop - start, record["id"], dtype=np.int64)})
    names = {name for piece in pieces for name in piece}
    cell_data: dict[str, NDArray[Any]] = {}
    for name in names:
        parts = []
        for piece, (_, conn) in zip(pieces, blocks, strict=True):
            if name in piece:
                parts.append(piece[name])
            else:
                template = next(p[name] for p in pieces if name in p)
                fill = np.zeros((len(conn), *template.shape[1:]), dtype=template.dtype)
                parts.append(fill)
        cell_data[name] = parts[0] if len(parts) == 1 else np.concatenate(parts)
    layout = CellLayout(
        points=elements.points,
        blocks=blocks,
        point_data=_regroup(elements.point_data),
        cell_data=cell_data,
        header=header,
    )
    return layout_to_scene(layout, path)


def _foreign(path: Path, elements: _Elements) -> Scene:
    """A PLY file of another program: one surface (and its edges) keeping every property."""
    points, faces, edges = elements.points, elements.faces, elements.edges
    face_data, edge_data = elements.face_data, elements.edge_data
    name = path.stem
    entities: list[Any] = []
    props = PropertyMap(elements.point_data)
    if faces is not None and len(faces):
        if faces.min() < 0 or faces.max() >= len(points):
            raise FormatError(f"face refers to vertex {int(faces.max())} of {len(points)}", path)
        entities.append(
            Surface(
                vertices=points,
                faces=faces,
                point_data=props,
                cell_data=PropertyMap(face_data),
                name=name,
            )
        )
    if edges is not None and len(edges):
        if edges.min() < 0 or edges.max() >= len(points):
            raise FormatError(f"edge refers to vertex {int(edges.max())} of {len(points)}", path)
        entities.append(
            PolyLine(
                vertices=points,
                indices=edges.ravel(),
                part_offsets=np.arange(0, 2 * len(edges) + 1, 2, dtype=np.int64),
                closed=np.zeros(len(edges), dtype=bool),
                cell_data=PropertyMap(edge_data),
                point_data=props,
                name=f"{name} edges",
            )
        )
    if not entities:
        entities.append(PointSet(vertices=points, point_data=props, name=name))
    return Scene(entities=entities)
