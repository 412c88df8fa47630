"""glTF and 3D Tiles: writing and reading a 1M-triangle surface, geobrep vs the libraries directly.

The same surface as benchmarks/formats_io.py (UTM-located, a point and a cell property). The
direct calls do what a user needs for the same file content and no more:

- pygltflib: rebase on the centre, turn y-up, float32 positions, uint32 indices, both
  properties as raw buffer views, one node; reading returns float64 world points, int64 faces
  and both properties. geobrep's file holds the same plus the feature ids and metadata table.
- trimesh: ``Trimesh(vertices - origin, faces).export("glb")`` (no properties: trimesh has no
  place for them) and ``trimesh.load``; a lower bound.
- 3D Tiles: pyproj to ECEF, the ENU rotation, then the pygltflib write above and the tileset
  JSON.

Prints best and median of N interleaved runs and their ratios (target: at most 1.10), in CPU
seconds of the process (``--wall`` for wall-clock ones: the machine may be shared).

The 3D Tiles rows: geobrep's default splits a mesh of more than 250,000 triangles into a k-d
tree of tiles (four here); the direct write is one tile. The ``3dtiles 1 tile`` row writes the
same content as the direct one (``max_tile_triangles`` above the model's size).

    .venv/bin/python benchmarks/web.py [--triangles 1000000] [--repeat 5] [--wall]
"""

from __future__ import annotations

import os

# One BLAS thread: the ENU rotation's small matrix products would otherwise spin idle BLAS
# threads whose CPU time counts against whichever side runs them.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import json
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

# formats_io.py lives beside this file
sys.path.append(str(Path(__file__).parent))
from formats_io import make_surface, summary

from geobrep.model.crs import CRS
from geobrep.model.entities import Surface
from geobrep.model.scene import Scene
from geobrep.ops.io import read, write

CLOCK = time.process_time


def timed(function: Callable[[], Any]) -> float:
    start = CLOCK()
    function()
    return CLOCK() - start


def _pygltflib_bytes(positions: np.ndarray, surface: Surface, extras: dict[str, Any]) -> bytes:
    import pygltflib

    faces = np.asarray(surface.faces, np.uint32).ravel()
    depth = np.asarray(surface.point_data["depth"].values, "<f8")
    zone = np.asarray(surface.cell_data["zone"].values, "<i4")
    chunks = [positions.tobytes(), faces.tobytes(), depth.tobytes(), zone.tobytes()]
    views, offset = [], 0
    for chunk in chunks:
        views.append(pygltflib.BufferView(buffer=0, byteOffset=offset, byteLength=len(chunk)))
        offset += len(chunk)
    gltf = pygltflib.GLTF2(
        asset=pygltflib.Asset(version="2.0", extras=extras),
        scene=0,
        scenes=[pygltflib.Scene(nodes=[0])],
        nodes=[pygltflib.Node(name=surface.name, mesh=0)],
        meshes=[
            pygltflib.Mesh(
                primitives=[
                    pygltflib.Primitive(attributes=pygltflib.Attributes(POSITION=0), indices=1)
                ]
            )
        ],
        accessors=[
            pygltflib.Accessor(
                bufferView=0,
                componentType=pygltflib.FLOAT,
                count=len(positions),
                type="VEC3",
                min=positions.min(axis=0).tolist(),
                max=positions.max(axis=0).tolist(),
            ),
            pygltflib.Accessor(
                bufferView=1, componentType=pygltflib.UNSIGNED_INT, count=len(faces), type="SCALAR"
            ),
        ],
        bufferViews=views,
        buffers=[pygltflib.Buffer(byteLength=offset)],
    )
    gltf.set_binary_blob(b"".join(chunks))
    return b"".join(gltf.save_to_bytes())


def _read_pygltflib(path: Path, origin: np.ndarray) -> Any:
    import pygltflib

    gltf = pygltflib.GLTF2.load_binary(str(path))
    blob = gltf.binary_blob()
    views = gltf.bufferViews

    def raw(k: int, dtype: str) -> np.ndarray:
        return np.frombuffer(blob, dtype, views[k].byteLength // np.dtype(dtype).itemsize,
                             views[k].byteOffset)  # fmt: skip

    y_up = raw(0, "<f4").reshape(-1, 3).astype(np.float64)
    points = np.column_stack([y_up[:, 0], -y_up[:, 2], y_up[:, 1]]) + origin
    faces = raw(1, "<u4").astype(np.int64).reshape(-1, 3)
    return points, faces, raw(2, "<f8").copy(), raw(3, "<i4").copy()


def direct_gltf(surface: Surface, folder: Path) -> tuple[Callable[[], Any], Callable[[], Any]]:
    path = folder / "direct.glb"
    origin = np.round((surface.vertices.min(axis=0) + surface.vertices.max(axis=0)) / 2)

    def write_direct() -> None:
        local = surface.vertices - origin
        positions = np.column_stack([local[:, 0], local[:, 2], -local[:, 1]]).astype("<f4")
        path.write_bytes(_pygltflib_bytes(positions, surface, {"origin": origin.tolist()}))

    return write_direct, lambda: _read_pygltflib(path, origin)


def direct_trimesh(surface: Surface, folder: Path) -> tuple[Callable[[], Any], Callable[[], Any]]:
    import trimesh

    path = folder / "direct-trimesh.glb"
    origin = np.round((surface.vertices.min(axis=0) + surface.vertices.max(axis=0)) / 2)

    def write_direct() -> None:
        mesh = trimesh.Trimesh(surface.vertices - origin, surface.faces, process=False)
        path.write_bytes(mesh.export(file_type="glb"))

    def read_direct() -> Any:
        mesh = trimesh.load(path, force="mesh", process=False)
        return np.asarray(mesh.vertices, np.float64) + origin, np.asarray(mesh.faces, np.int64)

    return write_direct, read_direct


def direct_tiles(surface: Surface, folder: Path) -> tuple[Callable[[], Any], Callable[[], Any]]:
    import pyproj

    path = folder / "direct" / "tileset.json"
    path.parent.mkdir(exist_ok=True)
    centre = (surface.vertices.min(axis=0) + surface.vertices.max(axis=0)) / 2
    source = pyproj.CRS.from_epsg(32631).to_3d()
    # made once, as a program writing many tilesets would (geobrep keeps its transformers too)
    to_ecef = pyproj.Transformer.from_crs(source, "EPSG:4978", always_xy=True)
    to_geo = pyproj.Transformer.from_crs("EPSG:4978", "EPSG:4979", always_xy=True)

    def write_direct() -> None:
        ecef0 = np.array(to_ecef.transform(*centre))
        lon, lat, _ = np.radians(to_geo.transform(*ecef0))
        rotation = np.array(
            [
                [-np.sin(lon), np.cos(lon), 0.0],
                [-np.sin(lat) * np.cos(lon), -np.sin(lat) * np.sin(lon), np.cos(lat)],
                [np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)],
            ]
        )
        ecef = np.column_stack(to_ecef.transform(*surface.vertices.T))
        local = (ecef - ecef0) @ rotation.T
        positions = np.column_stack([local[:, 0], local[:, 2], -local[:, 1]]).astype("<f4")
        (path.parent / "tileset.glb").write_bytes(_pygltflib_bytes(positions, surface, {}))
        matrix = np.eye(4)
        matrix[:3, :3], matrix[:3, 3] = rotation.T, ecef0
        low, high = local.min(axis=0), local.max(axis=0)
        half = (high - low) / 2
        box = [*((low + high) / 2), half[0], 0, 0, 0, half[1], 0, 0, 0, half[2]]
        tileset = {
            "asset": {"version": "1.1"},
            "geometricError": float(np.linalg.norm(high - low)),
            "root": {
                "transform": matrix.T.ravel().tolist(),
                "boundingVolume": {"box": [float(v) for v in box]},
                "geometricError": 0.0,
                "content": {"uri": "tileset.glb"},
            },
        }
        path.write_text(json.dumps(tileset))

    return write_direct, lambda: None


def _run(
    name: str, scene: Scene, ours: Path, direct: tuple[Callable[[], Any], Callable[[], Any]],
    repeat: int, anchor: str, read_too: bool, **options: Any,
) -> None:  # fmt: skip
    write_direct, read_direct = direct
    write_direct()
    read_direct()
    write(scene, ours, **options)
    times: dict[str, list[float]] = {}
    writers = [("ours", lambda: write(scene, ours, **options)), ("direct", write_direct)]
    readers = [("ours", lambda: read(ours)), ("direct", read_direct)]
    for run in range(repeat):
        order = slice(None, None, -1 if run % 2 else 1)  # interleaved, each first in turn
        for key, function in writers[order]:
            times.setdefault(f"write {key}", []).append(timed(function))
        if read_too:
            for key, function in readers[order]:
                times.setdefault(f"read {key}", []).append(timed(function))
    for op in ("write", "read") if read_too else ("write",):
        (mb, mm), (tb, tm) = summary(times[f"{op} ours"]), summary(times[f"{op} direct"])
        print(
            f"{name:15}{op:7}{mb:11.3f} /{mm:7.3f}{tb:12.3f} /{tm:7.3f}"
            f"{mb / tb:12.2f}{mm / tm:14.2f}  {anchor}"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--triangles", type=int, default=1_000_000)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--wall", action="store_true", help="wall-clock instead of CPU time")
    args = parser.parse_args()
    global CLOCK
    CLOCK = time.perf_counter if args.wall else time.process_time
    surface = make_surface(args.triangles)
    scene = Scene(entities=[surface], crs=CRS(epsg=32631))
    clock = "wall-clock" if args.wall else "CPU"
    print(f"surface: {surface.n_vertices} vertices, {surface.n_faces} triangles, 2 properties; "
          f"{clock} seconds, {args.repeat} interleaved runs")  # fmt: skip
    print(
        f"{'format':15}{'op':7}{'geobrep best/median s':>22}{'direct best/median s':>22}"
        f"{'ratio best':>12}{'ratio median':>14}  anchor"
    )
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        ours = folder / "ours.glb"
        _run("gltf", scene, ours, direct_gltf(surface, folder), args.repeat, "pygltflib", True)
        _run("gltf", scene, ours, direct_trimesh(surface, folder), args.repeat, "trimesh", True)
        back = read(ours).surfaces[0]
        error = float(np.abs(back.vertices - surface.vertices).max())
        (folder / "tiles").mkdir()
        tiles = folder / "tiles" / "tileset.json"
        direct = direct_tiles(surface, folder)
        _run("3dtiles", scene, tiles, direct, args.repeat, "pyproj + pygltflib", False)
        one = folder / "one" / "tileset.json"
        one.parent.mkdir()
        _run("3dtiles 1 tile", scene, one, direct, args.repeat, "pyproj + pygltflib", False,
             max_tile_triangles=args.triangles + 1)  # fmt: skip
        tiles_error = float(np.abs(read(tiles).surfaces[0].vertices - surface.vertices).max())
    print(f"float32 rounding, 5 km model rebased on its centre: glTF {error * 1000:.3f} mm, "
          f"3D Tiles (ENU) {tiles_error * 1000:.3f} mm")  # fmt: skip


if __name__ == "__main__":
    main()
