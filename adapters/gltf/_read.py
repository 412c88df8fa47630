"""Reading .glb files: geobrep's own back into entities, any other glTF 2.0 binary as meshes.

A file geobrep wrote (``asset.extras.geobrep``) gives back its surfaces, polylines and point
sets with their ids, names, kinds, metadata, patch labels and exact properties; positions come
back from float32 through the frame kept in the file (:mod:`._frame`). Block boundary meshes
are skipped (a Block needs the model's topology, which glTF does not hold) and listed in
``scene.metadata["skipped_on_read"]``. Other files read as one entity per primitive (TRIANGLES
as a surface, LINES as a polyline, POINTS as a point set) at its node's world transform,
turned from glTF's y-up to z-up, with the material's colour as ``metadata["color"]``.

A reader of untrusted input: every accessor and buffer view is checked against the binary
chunk before it is read, and counts are bounded by the file's size.
"""

from __future__ import annotations

import struct
from pathlib import Path
from typing import Any, Final

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.gltf._frame import EnuFrame, Frame, OffsetFrame, from_y_up
from geobrep.adapters.gltf._write import GEOBREP_KEY, TILE_PART_KEY, import_pygltflib
from geobrep.errors import FormatError
from geobrep.host.capabilities import SKIPPED_ON_READ
from geobrep.model.crs import CRS
from geobrep.model.entities import Entity, PointSet, PolyLine, Surface
from geobrep.model.properties import Property
from geobrep.model.scene import Group, Scene

__all__ = ["read_glb", "read_glb_parts"]

_COMPONENTS: Final = {5120: "i1", 5121: "u1", 5122: "<i2", 5123: "<u2", 5125: "<u4", 5126: "<f4"}
_JSON_CHUNK, _BIN_CHUNK = 0x4E4F534A, 0x004E4942
_WIDTH: Final = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}
_MAX_NODES: Final = 100_000


class _File:
    """A loaded .glb: its JSON document (pygltflib objects) and binary chunk, read safely."""

    def __init__(self, path: Path) -> None:
        pygltflib = import_pygltflib("reading glTF files")
        self.path = path
        with path.open("rb") as stream:  # the magic first: another file is not read whole
            head = stream.read(12)
            if len(head) < 12 or head[:4] != b"glTF":
                raise FormatError("not a binary glTF file (no 'glTF' magic)", path)
        json_text, self.blob = self._chunks(memoryview(path.read_bytes()))
        try:  # pygltflib's typed document; the binary chunk stays a view of the file's bytes
            self.gltf = pygltflib.GLTF2.from_json(json_text, infer_missing=True)
        except Exception as exc:
            raise FormatError(f"not a valid glTF file: {type(exc).__name__}: {exc}", path) from exc
        if len(self.gltf.nodes or ()) > _MAX_NODES:
            raise FormatError(f"{len(self.gltf.nodes)} nodes: more than {_MAX_NODES}", path)

    def _chunks(self, data: memoryview) -> tuple[str, memoryview]:
        """The JSON text and the binary chunk (empty if none) of the .glb bytes ``data``
        (glTF 2.0 section 4.4: a 12-byte header, then chunks of a length, a type and the bytes);
        chunks of other types are skipped, as the specification says."""
        if len(data) < 12 or bytes(data[:4]) != b"glTF":
            raise FormatError("not a binary glTF file (no 'glTF' magic)", self.path)
        version, length = struct.unpack_from("<II", data, 4)
        if version != 2 or length > len(data):
            raise FormatError(
                f"a glTF binary of version {version} and {length} bytes (the file holds "
                f"{len(data)}): only complete version 2 files are read",
                self.path,
            )
        text: str | None = None
        blob = memoryview(b"")
        offset = 12
        while offset + 8 <= length:
            size, kind = struct.unpack_from("<II", data, offset)
            start, offset = offset + 8, offset + 8 + size
            if offset > length:
                raise FormatError("a glTF chunk runs past the end of the file", self.path)
            if kind == _JSON_CHUNK and text is None:
                try:
                    text = str(data[start:offset], "utf-8")
                except UnicodeDecodeError as exc:
                    raise FormatError(
                        f"the glTF JSON chunk is not UTF-8: {exc}", self.path
                    ) from exc
            elif kind == _BIN_CHUNK and not len(blob):
                blob = data[start:offset]
        if text is None:
            raise FormatError("the glTF file has no JSON chunk", self.path)
        return text, blob

    def view(self, index: int) -> tuple[memoryview, int]:
        """The bytes of buffer view ``index`` and its byte stride (0: tightly packed)."""
        views = self.gltf.bufferViews
        if not 0 <= index < len(views):
            raise FormatError(f"buffer view {index} does not exist", self.path)
        view = views[index]
        if view.buffer != 0:
            raise FormatError("only the binary chunk (buffer 0) is read", self.path)
        start, length = int(view.byteOffset or 0), int(view.byteLength)
        if start < 0 or length < 0 or start + length > len(self.blob):
            raise FormatError(f"buffer view {index} lies outside the binary chunk", self.path)
        return self.blob[start : start + length], int(view.byteStride or 0)

    def accessor(self, index: int) -> NDArray[Any]:
        accessors = self.gltf.accessors
        if not 0 <= index < len(accessors):
            raise FormatError(f"accessor {index} does not exist", self.path)
        acc = accessors[index]
        if acc.sparse is not None or acc.bufferView is None:
            raise FormatError(f"accessor {index}: sparse accessors are not read", self.path)
        if acc.componentType not in _COMPONENTS or acc.type not in _WIDTH:
            raise FormatError(
                f"accessor {index}: unsupported {acc.componentType}/{acc.type}", self.path
            )
        data, stride = self.view(acc.bufferView)
        dtype = np.dtype(_COMPONENTS[acc.componentType])
        width, count = _WIDTH[acc.type], int(acc.count)
        item = dtype.itemsize * width
        stride = stride or item
        start = int(acc.byteOffset or 0)
        if count < 0 or (count and start + stride * (count - 1) + item > len(data)):
            raise FormatError(f"accessor {index} reads past its buffer view", self.path)
        if stride == item:
            values = np.frombuffer(data, dtype, count * width, start)
        else:
            rows = np.frombuffer(data, np.uint8, len(data) - start, start)
            picked = np.lib.stride_tricks.as_strided(rows, (count, item), (stride, 1))
            values = np.ascontiguousarray(picked).view(dtype).ravel()
        return values.reshape(count, width) if width > 1 else values

    def raw(self, entry: Any, what: str) -> NDArray[Any]:
        """An exact array stored by geobrep's writer (``{"bufferView", "dtype", "shape"}``)."""
        try:
            index = int(entry["bufferView"])
            dtype = np.dtype(str(entry["dtype"]))
            shape = tuple(int(n) for n in entry["shape"])
        except (KeyError, TypeError, ValueError) as exc:
            raise FormatError(f"{what}: bad array description ({exc})", self.path) from exc
        data, _ = self.view(index)
        if dtype.kind not in "biuf" or int(np.prod(shape)) * dtype.itemsize != len(data):
            raise FormatError(f"{what}: {len(data)} bytes do not hold {dtype} {shape}", self.path)
        return np.frombuffer(data, dtype).reshape(shape).astype(dtype.newbyteorder("="))


def _frame(extras: dict[str, Any], crs: CRS | None, path: Path) -> Frame:
    try:
        origin = tuple(float(v) for v in extras.get("origin", (0.0, 0.0, 0.0)))
        if extras.get("frame") == "enu":
            geodetic = tuple(float(v) for v in extras["geodetic_origin"])
            ecef = tuple(float(v) for v in extras["ecef_origin"])
            placed_by_crs = extras.get("placed_by", "crs") == "crs"
            return EnuFrame(origin, crs if placed_by_crs else None, geodetic, ecef)  # type: ignore[arg-type]
    except (KeyError, TypeError, ValueError) as exc:
        raise FormatError(f"bad frame in extras.geobrep: {exc}", path) from exc
    if len(origin) != 3:
        raise FormatError("extras.geobrep.origin needs three numbers", path)
    return OffsetFrame((origin[0], origin[1], origin[2]))


def _properties(file: _File, entries: Any, what: str) -> dict[str, Property]:
    out: dict[str, Property] = {}
    for name, entry in (entries or {}).items():
        described = {k: v for k, v in entry.items() if k not in ("bufferView", "dtype", "shape")}
        out[name] = Property(values=file.raw(entry, f"{what} {name!r}"), **described)
    return out


def _own_entity(file: _File, node: Any, frame: Frame) -> Entity | None:
    meta = node.extras[GEOBREP_KEY]
    kind = meta.get("type")
    if kind not in ("Surface", "PolyLine", "PointSet"):
        return None
    primitive = file.gltf.meshes[node.mesh].primitives[0]
    positions = file.accessor(primitive.attributes.POSITION)
    if isinstance(frame, OffsetFrame):
        vertices = frame.world_from_y_up(positions)
    else:
        vertices = frame.to_world(from_y_up(positions.astype(np.float64)))
    fields: dict[str, Any] = {
        "vertices": vertices,
        "id": meta.get("id"),
        "name": meta.get("name", ""),
        "kind": meta.get("kind"),
        "metadata": meta.get("metadata", {}),
        "point_data": _properties(file, meta.get("point_data"), "point property"),
        "cell_data": _properties(file, meta.get("cell_data"), "cell property"),
    }
    if kind == "Surface":
        fields["faces"] = file.accessor(primitive.indices).astype(np.int64).reshape(-1, 3)
        fields["patch_names"] = tuple(meta.get("patch_names", ()))
        if "patch_labels" in meta:
            fields["patch_labels"] = file.raw(meta["patch_labels"], "patch labels")
        return Surface(**fields)
    if kind == "PolyLine":
        for key in ("indices", "part_offsets", "closed"):
            fields[key] = file.raw(meta[key], f"polyline {key}")
        return PolyLine(**fields)
    return PointSet(**fields)


def _node_matrix(node: Any) -> NDArray[np.float64]:
    if node.matrix:
        return np.asarray(node.matrix, np.float64).reshape(4, 4).T  # column-major
    matrix = np.eye(4)
    if node.rotation:
        x, y, z, w = (float(v) for v in node.rotation)
        matrix[:3, :3] = [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    if node.scale:
        matrix[:3, :3] = matrix[:3, :3] * np.asarray(node.scale, np.float64)
    if node.translation:
        matrix[:3, 3] = node.translation
    return matrix


def _foreign_entities(file: _File) -> list[Entity]:
    """Every primitive of the default scene's nodes at its world transform, z up."""
    gltf = file.gltf
    roots = gltf.scenes[gltf.scene or 0].nodes if gltf.scenes else range(len(gltf.nodes))
    stack = [(int(i), np.eye(4), 0) for i in roots]
    entities: list[Entity] = []
    while stack:
        index, parent, depth = stack.pop()
        if not 0 <= index < len(gltf.nodes) or depth > 64:
            raise FormatError(f"node {index} does not exist or nests too deep", file.path)
        node = gltf.nodes[index]
        world = parent @ _node_matrix(node)
        stack.extend((int(c), world, depth + 1) for c in node.children or ())
        if node.mesh is None:
            continue
        mesh = gltf.meshes[node.mesh]
        for number, primitive in enumerate(mesh.primitives):
            name = node.name or mesh.name or f"mesh {node.mesh}"
            label = name if len(mesh.primitives) == 1 else f"{name} {number}"
            entity = _foreign_primitive(file, primitive, world, label)
            if entity is not None:
                entities.append(entity)
    return entities


def _foreign_primitive(
    file: _File, primitive: Any, world: NDArray[np.float64], name: str
) -> Entity | None:
    if primitive.attributes.POSITION is None:
        return None
    points = file.accessor(primitive.attributes.POSITION).astype(np.float64)
    vertices = from_y_up(points @ world[:3, :3].T + world[:3, 3])
    metadata: dict[str, Any] = {}
    materials = file.gltf.materials
    if primitive.material is not None and 0 <= primitive.material < len(materials):
        pbr = materials[primitive.material].pbrMetallicRoughness
        if pbr is not None and pbr.baseColorFactor:
            metadata["color"] = [float(c) for c in pbr.baseColorFactor]
    mode = 4 if primitive.mode is None else int(primitive.mode)
    if primitive.indices is not None:
        order = file.accessor(primitive.indices).astype(np.int64)
    else:
        order = np.arange(len(vertices))
    if len(order) and (order.min() < 0 or order.max() >= len(vertices)):
        raise FormatError(f"{name}: an index points past the {len(vertices)} vertices", file.path)
    if mode == 4:
        return Surface(
            vertices=vertices,
            faces=order[: len(order) // 3 * 3].reshape(-1, 3),
            name=name,
            metadata=metadata,
        )
    if mode == 1:
        pairs = order[: len(order) // 2 * 2].reshape(-1, 2)
        return (
            PolyLine.from_parts(vertices, [list(p) for p in pairs], name=name, metadata=metadata)
            if len(pairs)
            else None
        )
    if mode == 0:
        return PointSet(vertices=vertices[order], name=name, metadata=metadata)
    raise FormatError(f"{name}: primitive mode {mode} (strips, fans, loops) is not read", file.path)


def _place(file: _File, entry: Any) -> dict[str, Any]:
    """Where a tile's piece of a split mesh sits in the whole (node extras ``tile_part``)."""
    if not isinstance(entry, dict):
        raise FormatError("extras.geobrep.tile_part is not an object", file.path)
    out: dict[str, Any] = {}
    for key, value in entry.items():
        if key in ("vertex_ids", "cell_ids"):
            out[key] = file.raw(value, f"tile part {key}").astype(np.int64)
        elif key in ("key", "index", "count", "n_vertices", "n_cells"):
            if not isinstance(value, int) or value < 0:
                raise FormatError(f"tile part {key}: {value!r} is not a count", file.path)
            out[key] = value
    needed = {"key", "index", "count", "vertex_ids", "cell_ids", "n_vertices", "n_cells"}
    missing = needed - set(out)
    if missing:
        raise FormatError(f"tile part without {', '.join(sorted(missing))}", file.path)
    return out


def read_glb(path: Path) -> Scene:
    """The scene in the .glb file ``path``."""
    return read_glb_parts(path)[0]


def read_glb_parts(path: Path) -> tuple[Scene, dict[int, dict[str, Any]]]:
    """The scene in the .glb file ``path`` and, by entity position, where the pieces of split
    meshes (one tile of a tileset) sit in their whole."""
    file = _File(path)
    asset_extras = file.gltf.asset.extras or {}
    own = asset_extras.get(GEOBREP_KEY) if isinstance(asset_extras, dict) else None
    if not isinstance(own, dict):
        return Scene(entities=_foreign_entities(file), name=path.stem), {}
    crs = CRS.model_validate(own["crs"]) if own.get("crs") else None
    frame = _frame(own, crs, path)
    entities: list[Entity] = []
    places: dict[int, dict[str, Any]] = {}
    skipped: list[str] = []
    for node in file.gltf.nodes:
        extras = node.extras if isinstance(node.extras, dict) else {}
        if GEOBREP_KEY not in extras or node.mesh is None:
            continue
        try:
            entity = _own_entity(file, node, frame)
        except (KeyError, TypeError, IndexError, AttributeError) as exc:
            raise FormatError(f"node {node.name!r}: {type(exc).__name__}: {exc}", path) from exc
        part = extras[GEOBREP_KEY].get(TILE_PART_KEY)
        if entity is None:  # a block's boundary, listed once however many tiles it spans
            if not isinstance(part, dict) or part.get("index") == 0:
                skipped.append(f"boundary mesh of {extras[GEOBREP_KEY].get('type')} {node.name!r}")
            continue
        if part is not None:
            places[len(entities)] = _place(file, part)
        entities.append(entity)
    metadata = dict(own.get("metadata") or {})
    if skipped:
        metadata[SKIPPED_ON_READ] = skipped
    groups = [Group.model_validate(g) for g in own.get("groups", [])]
    scene = Scene(
        entities=entities, groups=groups, crs=crs, name=own.get("name", ""), metadata=metadata
    )
    return scene, places
