"""A scene as a glTF 2.0 binary (.glb): one named node and mesh per entity.

Surfaces are TRIANGLES, polylines LINES, point sets POINTS, each with a material of the
entity's colour (:func:`geobrep.adapters.colors.scene_colours`); every block (but the universe)
is one more mesh: its closed boundary, coloured by its unit. Positions are float32 in a local
frame (:mod:`._frame`) kept in the file. Everything else geobrep holds travels exactly in
``extras.geobrep`` of the nodes and the scene: id, name, kind, metadata, patch labels and
names, polyline parts, and every property as raw little-endian bytes in a buffer view of the
binary chunk (float64 stays float64). Each primitive also carries an EXT_mesh_features feature
id (``_FEATURE_ID_0``) into an EXT_structural_metadata property table of the meshes (name,
kind, entity id, unit), so 3D Tiles viewers show what a picked object is.

The JSON document is built as plain dicts and the binary container (a 12-byte header and two
chunk headers, glTF 2.0 section 4.4) written here, the arrays handed to the file from their own
memory: pygltflib's writer would turn the document into its dataclasses (about 25 ms a file)
and copy the binary chunk twice. pygltflib reads (:mod:`._read`), and the tests load every
kind of file written here with pygltflib and trimesh.
"""

from __future__ import annotations

import json
import struct
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Final

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.colors import RGBA, scene_colours
from geobrep.adapters.display import drawn_meshes
from geobrep.adapters.gltf._frame import Frame, OffsetFrame, to_y_up
from geobrep.errors import import_optional
from geobrep.geometry.bbox import column_extremes
from geobrep.model.entities import Block, Entity, PolyLine, Surface
from geobrep.model.properties import PropertyMap
from geobrep.model.scene import Scene

__all__ = ["GEOBREP_KEY", "TILE_PART_KEY", "GlbContent", "build_glb", "glb_meshes", "write_glb"]

GEOBREP_KEY: Final = "geobrep"
TILE_PART_KEY: Final = "tile_part"
"""The node extras key of a tile's piece of a mesh the tileset split (see :mod:`._split`)."""
FORMAT_VERSION: Final = 1
_FLOAT, _UINT, _USHORT = 5126, 5125, 5123
_ARRAY_BUFFER, _ELEMENT_BUFFER = 34962, 34963
_MODES: Final = {"Surface": 4, "PolyLine": 1, "PointSet": 0}


def import_pygltflib(feature: str) -> Any:
    """The ``pygltflib`` module, or :class:`MissingDependencyError` naming the ``web`` extra."""
    return import_optional("pygltflib", "web", feature)


def _bytes_of(data: bytes | NDArray[Any]) -> memoryview:
    """The bytes of ``data`` without a copy (an array is made contiguous first if it is not)."""
    if isinstance(data, np.ndarray):
        return memoryview(np.ascontiguousarray(data).reshape(-1).view(np.uint8).data)
    return memoryview(data)


@dataclass
class _Buffer:
    """The binary chunk being built: 4-byte aligned buffer views and their accessors.

    The views hold the arrays' own memory (no copy); :func:`glb_parts` hands them to the file.
    """

    chunks: list[memoryview] = field(default_factory=list)
    size: int = 0
    views: list[dict[str, Any]] = field(default_factory=list)
    accessors: list[dict[str, Any]] = field(default_factory=list)

    def view(self, data: bytes | NDArray[Any], target: int | None = None) -> int:
        chunk = _bytes_of(data)
        entry: dict[str, Any] = {"buffer": 0, "byteOffset": self.size, "byteLength": chunk.nbytes}
        if target is not None:
            entry["target"] = target
        self.views.append(entry)
        self.chunks.append(chunk)
        padding = (-chunk.nbytes) % 4
        if padding:
            self.chunks.append(memoryview(b"\0" * padding))
        self.size += chunk.nbytes + padding
        return len(self.views) - 1

    def raw(self, array: NDArray[Any]) -> dict[str, Any]:
        """An exact array: its buffer view, little-endian dtype and shape."""
        values = np.ascontiguousarray(array)
        little = values.astype(values.dtype.newbyteorder("<"), copy=False)
        return {
            "bufferView": self.view(little),
            "dtype": little.dtype.str,
            "shape": list(values.shape),
        }

    def accessor(
        self,
        array: NDArray[Any],
        component: int,
        kind: str,
        target: int | None,
        bounds: tuple[NDArray[Any], NDArray[Any]] | None = None,
    ) -> int:
        """An accessor of ``array``; ``bounds`` (its per-component minimum and maximum, of the
        array's own dtype) become the accessor's ``min`` and ``max``."""
        entry: dict[str, Any] = {
            "bufferView": self.view(array, target),
            "componentType": component,
            "count": int(array.shape[0]),
            "type": kind,
        }
        if bounds is not None and array.shape[0]:
            entry["min"] = [float(v) for v in bounds[0]]
            entry["max"] = [float(v) for v in bounds[1]]
        self.accessors.append(entry)
        return len(self.accessors) - 1


_GLB_MAGIC, _GLB_VERSION = 0x46546C67, 2
_JSON_CHUNK, _BIN_CHUNK = 0x4E4F534A, 0x004E4942


def glb_parts(document: dict[str, Any], buffer: _Buffer) -> list[memoryview]:
    """The pieces of a .glb file, in order: header, JSON chunk (padded with spaces), binary
    chunk (the buffer views, each padded with zeros to 4 bytes). The arrays are not copied."""
    text = json.dumps(document, allow_nan=False, separators=(",", ":")).encode("utf-8")
    text += b" " * ((-len(text)) % 4)
    chunks = [memoryview(struct.pack("<II", len(text), _JSON_CHUNK) + text)]
    if buffer.size:
        chunks.append(memoryview(struct.pack("<II", buffer.size, _BIN_CHUNK)))
        chunks.extend(buffer.chunks)
    total = 12 + sum(c.nbytes for c in chunks)
    return [memoryview(struct.pack("<III", _GLB_MAGIC, _GLB_VERSION, total)), *chunks]


@dataclass
class GlbContent:
    """What :func:`build_glb` made: the file's pieces and what it measured."""

    parts: list[memoryview]
    """The file's bytes in pieces (:func:`glb_parts`): write them in order."""
    max_rounding_m: float
    """Largest distance a vertex moved by the float32 rounding, in world units (metres)."""
    local_low: NDArray[np.float64]
    local_high: NDArray[np.float64]
    meshes: int

    @property
    def data(self) -> bytes:
        """The whole file as one bytes object (a copy of every array)."""
        return b"".join(self.parts)

    def write_to(self, path: Path) -> None:
        """Write the file to ``path``, the arrays straight from their own memory."""
        with path.open("wb") as file:
            file.writelines(self.parts)


def _properties(buffer: _Buffer, props: PropertyMap) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for name, prop in props.items():
        entry = prop.model_dump(mode="json", exclude={"values"})
        entry.update(buffer.raw(np.asarray(prop.values)))
        out[name] = entry
    return out


def _entity_extras(buffer: _Buffer, entity: Entity) -> dict[str, Any]:
    extras: dict[str, Any] = {
        "type": entity.type,
        "id": entity.id,
        "name": entity.name,
        "kind": entity.kind,
        "metadata": entity.metadata,
        "point_data": _properties(buffer, entity.point_data),
        "cell_data": _properties(buffer, entity.cell_data),
    }
    if isinstance(entity, Surface):
        extras["patch_names"] = list(entity.patch_names)
        if entity.patch_labels is not None:
            extras["patch_labels"] = buffer.raw(np.asarray(entity.patch_labels))
    if isinstance(entity, PolyLine):
        for name in ("indices", "part_offsets", "closed"):
            extras[name] = buffer.raw(np.asarray(getattr(entity, name)))
    if isinstance(entity, Block):
        extras["unit_name"] = entity.unit_name
        extras["derived"] = "boundary mesh of the block (not read back as a Block)"
    return extras


def _indices(entity: Entity) -> NDArray[np.uint32] | None:
    if isinstance(entity, Surface):
        return np.asarray(entity.faces, np.uint32).ravel()
    if isinstance(entity, PolyLine):
        return np.asarray(entity.segments, np.uint32).ravel()
    return None


@dataclass
class _Meshes:
    """The glTF objects made so far (JSON dicts) and the extent of the local coordinates."""

    nodes: list[dict[str, Any]] = field(default_factory=list)
    meshes: list[dict[str, Any]] = field(default_factory=list)
    materials: list[dict[str, Any]] = field(default_factory=list)
    rows: list[dict[str, Any]] = field(default_factory=list)
    rounding: float = 0.0
    low: NDArray[np.float64] = field(default_factory=lambda: np.full(3, np.inf))
    high: NDArray[np.float64] = field(default_factory=lambda: np.full(3, -np.inf))


_BLOCK_ROWS: Final = 1 << 16
"""Vertices converted per pass: the float64 block stays in cache while it is rounded,
measured and bounded."""


@dataclass
class _Positions:
    """A mesh's float32 y-up positions and what was measured on the float64 values."""

    single: NDArray[np.float32]
    low: NDArray[np.float64]
    """Per-axis minimum of the float64 y-up coordinates (``inf`` for no vertex)."""
    high: NDArray[np.float64]
    rounding: float
    """Largest change of a coordinate by the float32 rounding."""

    @property
    def float32_bounds(self) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
        """The per-axis minimum and maximum of :attr:`single`: rounding to float32 keeps order,
        so they are the float64 bounds rounded."""
        return self.low.astype(np.float32), self.high.astype(np.float32)


def _positions(frame: Frame, world: NDArray[np.float64]) -> _Positions:
    """``world`` in ``frame``, y-up, as float32, converted block by block."""
    n = world.shape[0]
    y_up_of: Callable[[NDArray[np.float64]], NDArray[np.float64]]
    if isinstance(frame, OffsetFrame):
        y_up_of, source = frame.y_up_from_world, world
    else:
        local = frame.to_local(world)
        y_up_of, source = to_y_up, local
    single = np.empty((n, 3), np.float32)
    low, high, rounding = np.full(3, np.inf), np.full(3, -np.inf), 0.0
    for start in range(0, n, _BLOCK_ROWS):
        y_up = y_up_of(source[start : start + _BLOCK_ROWS])
        block = single[start : start + len(y_up)]
        np.copyto(block, y_up, casting="same_kind")
        block_low, block_high = column_extremes(y_up)
        low, high = np.minimum(low, block_low), np.maximum(high, block_high)
        error = np.subtract(block, y_up)
        rounding = max(rounding, float(np.abs(error, out=error).max()))
    return _Positions(single, low, high, rounding)


def _add_mesh(
    out: _Meshes,
    buffer: _Buffer,
    frame: Frame,
    geometry: Entity,
    source: Entity,
    colour: RGBA,
    place: dict[str, Any] | None = None,
) -> None:
    """One node, mesh and material for ``geometry`` (``source`` is the entity it shows;
    ``place``: where a tile's piece of a split mesh sits in the whole, arrays kept exactly)."""
    world = np.asarray(geometry.vertices, np.float64)  # type: ignore[attr-defined]
    positions = _positions(frame, world)
    single = positions.single
    if len(single):  # local (x, y, z) is y-up (x, -z, y)
        low, high = positions.low, positions.high
        out.low = np.minimum(out.low, [low[0], -high[2], low[1]])
        out.high = np.maximum(out.high, [high[0], -low[2], high[1]])
        out.rounding = max(out.rounding, positions.rounding)
    row = len(out.rows)
    attributes = {
        "POSITION": buffer.accessor(
            single, _FLOAT, "VEC3", _ARRAY_BUFFER, positions.float32_bounds
        ),
        "_FEATURE_ID_0": buffer.accessor(
            np.full(len(single), row, np.float32), _FLOAT, "SCALAR", _ARRAY_BUFFER
        ),
    }
    primitive: dict[str, Any] = {
        "attributes": attributes,
        "mode": _MODES.get(geometry.type, 4),
        "material": len(out.materials),
        "extensions": {
            "EXT_mesh_features": {
                "featureIds": [{"featureCount": 1, "attribute": 0, "propertyTable": 0}]
            }
        },
    }
    indices = _indices(geometry)
    if indices is not None:
        primitive["indices"] = buffer.accessor(indices, _UINT, "SCALAR", _ELEMENT_BUFFER)
    label = source.name or source.label
    out.materials.append(
        {
            "name": label,
            "pbrMetallicRoughness": {
                "baseColorFactor": list(colour),
                "metallicFactor": 0.0,
                "roughnessFactor": 0.9,
            },
            "doubleSided": True,
        }
    )
    out.meshes.append({"name": label, "primitives": [primitive]})
    extras = _entity_extras(buffer, source)
    if place is not None:
        extras[TILE_PART_KEY] = {
            k: buffer.raw(v) if isinstance(v, np.ndarray) else v for k, v in place.items()
        }
    out.nodes.append({"name": label, "mesh": len(out.meshes) - 1, "extras": {GEOBREP_KEY: extras}})
    unit = source.unit_name if isinstance(source, Block) else None
    out.rows.append(
        {"name": label, "kind": source.kind or "", "entity": source.id, "unit": unit or ""}
    )


def _property_table(buffer: _Buffer, rows: list[dict[str, Any]]) -> dict[str, Any]:
    """EXT_structural_metadata: a schema and one property table, a row per mesh."""
    columns: dict[str, Any] = {}
    for key in ("name", "kind", "unit"):
        encoded = [str(r[key]).encode("utf-8") for r in rows]
        offsets = np.concatenate([[0], np.cumsum([len(e) for e in encoded])]).astype(np.uint32)
        columns[key] = {
            "values": buffer.view(b"".join(encoded)),
            "stringOffsets": buffer.view(offsets.tobytes()),
        }
    ids = np.array([-1 if r["entity"] is None else r["entity"] for r in rows], np.int32)
    columns["entity"] = {"values": buffer.view(ids.astype("<i4").tobytes())}
    return {
        "schema": {
            "id": "geobrep",
            "classes": {
                "entity": {
                    "name": "geobrep entity",
                    "properties": {
                        "name": {"type": "STRING"},
                        "kind": {"type": "STRING"},
                        "unit": {"type": "STRING"},
                        "entity": {"type": "SCALAR", "componentType": "INT32", "noData": -1},
                    },
                }
            },
        },
        "propertyTables": [{"class": "entity", "count": len(rows), "properties": columns}],
    }


def glb_meshes(scene: Scene, blocks: bool, written: Scene | None) -> list[tuple[Entity, Entity]]:
    """The ``(geometry, source)`` meshes a .glb of ``scene`` holds: the entities ``written``
    keeps (the scene restricted to the format), then the blocks' boundaries."""
    kept = written if written is not None else scene
    return [
        (geometry, source)
        for geometry, source in drawn_meshes(scene, blocks)
        if source is not geometry or source.id in kept.entity_by_id or isinstance(source, Block)
    ]


def build_glb(
    scene: Scene,
    frame: Frame,
    *,
    blocks: bool = True,
    written: Scene | None = None,
    extras: dict[str, Any] | None = None,
    meshes: list[tuple[Entity, Entity]] | None = None,
    places: list[dict[str, Any] | None] | None = None,
) -> GlbContent:
    """The .glb bytes of ``scene`` in ``frame``.

    ``written`` is what the file keeps as entities (``scene`` restricted to the format); the
    blocks' meshes come from the full ``scene``. ``meshes`` (from :func:`glb_meshes`) picks
    some of them: one tile of a tileset; ``places`` (beside ``meshes``) says which of them are
    pieces of a mesh the tileset split, and where they sit in it.
    """
    kept = written if written is not None else scene
    colours = scene_colours(scene)
    buffer, out = _Buffer(), _Meshes()
    default = (0.7, 0.7, 0.7, 1.0)
    chosen = glb_meshes(scene, blocks, written) if meshes is None else meshes
    for number, (geometry, source) in enumerate(chosen):
        colour = default if source.id is None else colours.get(source.id, default)
        place = None if places is None else places[number]
        _add_mesh(out, buffer, frame, geometry, source, colour, place)
    scene_extras: dict[str, Any] = {
        "version": FORMAT_VERSION,
        "name": kept.name,
        "crs": None if kept.crs is None else kept.crs.model_dump(mode="json"),
        "metadata": kept.metadata,
        "groups": [g.model_dump(mode="json") for g in kept.groups],
        "float32_rounding_m": out.rounding,
        **frame.describe(),
        **(extras or {}),
    }
    document: dict[str, Any] = {
        "asset": {"version": "2.0", "generator": "geobrep", "extras": {GEOBREP_KEY: scene_extras}},
        "scene": 0,
        "scenes": [{"name": kept.name or "scene", "nodes": list(range(len(out.nodes)))}],
        "nodes": out.nodes,
        "meshes": out.meshes,
        "materials": out.materials,
    }
    if out.rows:
        document["extensionsUsed"] = ["EXT_mesh_features", "EXT_structural_metadata"]
        document["extensions"] = {"EXT_structural_metadata": _property_table(buffer, out.rows)}
    document["accessors"] = buffer.accessors
    document["bufferViews"] = buffer.views
    document["buffers"] = [{"byteLength": buffer.size}]
    return GlbContent(glb_parts(document, buffer), out.rounding, out.low, out.high, len(out.meshes))


def write_glb(
    scene: Scene, path: Path, frame: Frame, *, blocks: bool = True, written: Scene | None = None
) -> GlbContent:
    """Write ``scene`` to ``path`` (see :func:`build_glb`)."""
    content = build_glb(scene, frame, blocks=blocks, written=written)
    content.write_to(path)
    return content
