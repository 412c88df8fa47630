"""The .glb container geobrep writes itself: the layout glTF 2.0 (section 4.4) prescribes, and
the same document and binary chunk pygltflib's own writer makes of it."""

from __future__ import annotations

import json
import struct
from pathlib import Path

import numpy as np
import pytest
from formats_support import rich_scene

from geobrep.model.entities import PointSet, Surface
from geobrep.model.properties import Property
from geobrep.model.scene import Scene
from geobrep.ops.io import read, write

pygltflib = pytest.importorskip("pygltflib")


def _chunks(data: bytes) -> list[tuple[int, bytes]]:
    magic, version, total = struct.unpack_from("<III", data)
    assert (magic, version, total) == (0x46546C67, 2, len(data))
    chunks, offset = [], 12
    while offset < len(data):
        length, kind = struct.unpack_from("<II", data, offset)
        assert length % 4 == 0
        chunks.append((kind, data[offset + 8 : offset + 8 + length]))
        offset += 8 + length
    assert offset == len(data)
    return chunks


def test_the_container_has_a_padded_json_chunk_then_the_binary_chunk(tmp_path: Path) -> None:
    path = write(rich_scene(), tmp_path / "rich.glb")
    (json_kind, text), (bin_kind, blob) = _chunks(path.read_bytes())
    assert (json_kind, bin_kind) == (0x4E4F534A, 0x004E4942)
    document = json.loads(text.decode("utf-8"))  # the space padding is JSON whitespace
    assert text.rstrip(b" ").endswith(b"}")
    assert document["buffers"] == [{"byteLength": len(blob)}]
    for view in document["bufferViews"]:
        assert view["byteOffset"] % 4 == 0
        assert view["byteOffset"] + view["byteLength"] <= len(blob)


def test_pygltflib_reads_the_same_document_and_binary_chunk(tmp_path: Path) -> None:
    path = write(rich_scene(), tmp_path / "rich.glb")
    (_, text), (_, blob) = _chunks(path.read_bytes())
    document = json.loads(text)
    gltf = pygltflib.GLTF2.load_binary(str(path))
    assert gltf.binary_blob() == blob
    assert [m.name for m in gltf.meshes] == [m["name"] for m in document["meshes"]]
    views = [(v.byteOffset, v.byteLength, v.target) for v in gltf.bufferViews]
    assert views == [
        (v["byteOffset"], v["byteLength"], v.get("target")) for v in document["bufferViews"]
    ]
    for accessor, mine in zip(gltf.accessors, document["accessors"], strict=True):
        assert (accessor.bufferView, accessor.count, accessor.type) == (
            mine["bufferView"], mine["count"], mine["type"],
        )  # fmt: skip
        if "min" in mine:  # positions: the bounds of the float32 values stored
            view = gltf.bufferViews[accessor.bufferView]
            values = np.frombuffer(blob, "<f4", view.byteLength // 4, view.byteOffset)
            values = values.reshape(-1, 3)
            assert accessor.min == values.min(axis=0).tolist()
            assert accessor.max == values.max(axis=0).tolist()
    assert gltf.asset.extras["geobrep"] == document["asset"]["extras"]["geobrep"]


def test_arrays_written_from_their_own_memory_keep_their_values(tmp_path: Path) -> None:
    """Non-contiguous, big-endian and boolean arrays reach the file as the values they hold."""
    rng = np.random.default_rng(3)
    grid = rng.random((40, 3)) * 1000 + [500_000.0, 6_700_000.0, -2_000.0]
    faces = np.array([[i, i + 1, i + 2] for i in range(38)])
    strided = np.arange(80, dtype=np.float64)[::2]  # a view with a stride of 16 bytes
    big = np.arange(38, dtype=">i4")
    surface = Surface(
        vertices=grid,
        faces=faces,
        name="s",
        point_data={
            "strided": Property(values=strided),
            "flag": Property(values=grid[:, 0] > 500_500),
        },
        cell_data={"big": Property(values=big)},
    )
    cloud = PointSet(vertices=grid[::3], name="p")
    back = read(write(Scene(entities=[surface, cloud]), tmp_path / "arrays.glb"))
    got = back.surfaces[0]
    assert np.array_equal(got.point_data["strided"].values, strided)
    assert np.array_equal(got.point_data["flag"].values, grid[:, 0] > 500_500)
    assert np.array_equal(got.cell_data["big"].values, big.astype("<i4"))
    assert np.array_equal(got.faces, faces)
    assert np.abs(got.vertices - grid).max() < 1e-3


def _glb(
    version: int = 2, chunks: tuple[tuple[int, bytes], ...] = (), length: int | None = None
) -> bytes:
    body = b"".join(struct.pack("<II", len(data), kind) + data for kind, data in chunks)
    total = 12 + len(body) if length is None else length
    return struct.pack("<III", 0x46546C67, version, total) + body


_JSON, _BIN = 0x4E4F534A, 0x004E4942
_DOCUMENT = b'{"asset": {"version": "2.0"}}   '


@pytest.mark.parametrize(
    ("data", "message"),
    [
        (_glb(version=1, chunks=((_JSON, _DOCUMENT),)), "version 1"),
        (_glb(chunks=((_JSON, _DOCUMENT),), length=4096), "only complete version 2"),
        (_glb(chunks=((_BIN, b"\0" * 8),)), "no JSON chunk"),
        (_glb(chunks=((_JSON, b"\xff\xfe{}  "),)), "not UTF-8"),
        (_glb(chunks=((_JSON, _DOCUMENT),), length=44)[:44], "runs past the end"),
        (_glb(chunks=((_JSON, b"[1, 2]  "),)), "not a valid glTF"),
    ],
)
def test_a_damaged_container_is_a_format_error_naming_the_file(
    tmp_path: Path, data: bytes, message: str
) -> None:
    from geobrep.errors import FormatError

    path = tmp_path / "damaged.glb"
    path.write_bytes(data)
    with pytest.raises(FormatError, match=message) as caught:
        read(path)
    assert "damaged.glb" in str(caught.value)


def test_chunks_of_unknown_types_are_skipped(tmp_path: Path) -> None:
    original = write(rich_scene(), tmp_path / "rich.glb").read_bytes()
    (_, text), (_, blob) = _chunks(original)
    extra = (0x12345678, b"\1\2\3\4")
    path = tmp_path / "extra.glb"
    path.write_bytes(_glb(chunks=((_JSON, text), extra, (_BIN, blob))))
    assert read(path) == read(tmp_path / "rich.glb")
