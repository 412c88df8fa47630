"""Reading and writing a 1M-triangle surface with properties: geobrep vs the libraries directly.

For VTU (meshio), PLY (plyfile) and VTP (pyvista), times geobrep's ``write``/``read`` against
calling the library itself on the same arrays, with the same settings, in the same run, and
prints best and median of N interleaved runs and their ratios: geobrep's overhead target is at
most 10 %. The direct calls do what a user of the library needs for the same result and no
more: writing builds the library's mesh object from the surface's arrays (points, faces, one
point and one cell property); reading returns float64 points, int64 (M, 3) faces and both
property arrays, which is what a geobrep ``Surface`` holds.

Writes are timed twice: into a new file, and over the file just written (geobrep's atomic write
renames a temporary file onto it, which ext4 follows with a flush of the new file's blocks;
the libraries truncate the file in place). plyfile writes list properties (the faces) one row
at a time, so its direct write is slow; geobrep packs fixed-length lists itself, hence a ratio
far below 1.

    .venv/bin/python benchmarks/formats_io.py [--triangles 1000000] [--repeat 3]
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from geobrep.model.entities import Surface
from geobrep.model.scene import Scene
from geobrep.ops.io import read, write


def make_surface(triangles: int) -> Surface:
    """A folded UTM-located grid surface with a point and a cell property."""
    side = int(np.ceil(np.sqrt(triangles / 2))) + 1
    x, y = np.meshgrid(np.linspace(0, 5000, side), np.linspace(0, 5000, side))
    z = 200 * np.sin(x / 700) * np.cos(y / 900)
    vertices = np.column_stack([x.ravel() + 450000.0, y.ravel() + 6700000.0, z.ravel()])
    i, j = np.meshgrid(np.arange(side - 1), np.arange(side - 1))
    a = (j * side + i).ravel()
    quads = np.column_stack([a, a + 1, a + side + 1, a + side])
    faces = np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])[:triangles]
    return Surface(
        vertices=vertices,
        faces=faces,
        name="horizon",
        point_data={"depth": -vertices[:, 2]},
        cell_data={"zone": (np.arange(len(faces)) % 7).astype(np.int32)},
    )


def timed(function: Callable[[], Any]) -> float:
    start = time.perf_counter()
    function()
    return time.perf_counter() - start


def direct_meshio(surface: Surface, folder: Path) -> tuple[Callable[[], Any], Callable[[], Any]]:
    import meshio

    path = folder / "direct.vtu"

    def write_direct() -> None:
        mesh = meshio.Mesh(
            surface.vertices,
            [("triangle", surface.faces)],
            point_data={"depth": surface.point_data["depth"].values},
            cell_data={"zone": [surface.cell_data["zone"].values]},
        )
        meshio.write(path, mesh, file_format="vtu", binary=True, compression=None)

    def read_direct() -> Any:
        mesh = meshio.read(path, file_format="vtu")
        # what a Surface holds: float64 points, int64 faces, the property arrays
        faces = np.asarray(mesh.cells_dict["triangle"], dtype=np.int64)
        return mesh.points, faces, mesh.point_data["depth"], mesh.cell_data["zone"][0]

    return write_direct, read_direct


def direct_plyfile(surface: Surface, folder: Path) -> tuple[Callable[[], Any], Callable[[], Any]]:
    import plyfile

    path = folder / "direct.ply"

    def write_direct() -> None:
        vertex = np.empty(
            surface.n_vertices, dtype=[("x", "<f8"), ("y", "<f8"), ("z", "<f8"), ("depth", "<f8")]
        )
        for k, axis in enumerate("xyz"):
            vertex[axis] = surface.vertices[:, k]
        vertex["depth"] = surface.point_data["depth"].values
        face = np.empty(surface.n_faces, dtype=[("vertex_indices", "<i4", (3,)), ("zone", "<i4")])
        face["vertex_indices"] = surface.faces
        face["zone"] = surface.cell_data["zone"].values
        elements = [
            plyfile.PlyElement.describe(vertex, "vertex"),
            plyfile.PlyElement.describe(face, "face", len_types={"vertex_indices": "u1"}),
        ]
        plyfile.PlyData(elements).write(str(path))

    def read_direct() -> Any:
        ply = plyfile.PlyData.read(str(path), known_list_len={"face": {"vertex_indices": 3}})
        vertex, face = ply["vertex"].data, ply["face"].data
        # what a Surface holds: float64 points, int64 faces, the property arrays
        points = np.column_stack([vertex["x"], vertex["y"], vertex["z"]])
        faces = np.asarray(face["vertex_indices"], dtype=np.int64)
        return points, faces, np.array(vertex["depth"]), np.array(face["zone"])

    return write_direct, read_direct


def direct_pyvista(surface: Surface, folder: Path) -> tuple[Callable[[], Any], Callable[[], Any]]:
    import pyvista as pv

    path = folder / "direct.vtp"

    def write_direct() -> None:
        faces = np.hstack([np.full((surface.n_faces, 1), 3), surface.faces]).ravel()
        mesh = pv.PolyData(surface.vertices.copy(), faces)  # VTK needs writable points
        mesh.point_data["depth"] = surface.point_data["depth"].values
        mesh.cell_data["zone"] = surface.cell_data["zone"].values
        mesh.save(path)

    def read_direct() -> Any:
        mesh = pv.read(path)
        # what a Surface holds: float64 points, int64 (M, 3) faces, the property arrays
        faces = np.asarray(mesh.regular_faces, dtype=np.int64)
        return mesh.points, faces, mesh.point_data["depth"], mesh.cell_data["zone"]

    return write_direct, read_direct


def summary(times: list[float]) -> tuple[float, float]:
    return min(times), statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--triangles", type=int, default=1_000_000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    surface = make_surface(args.triangles)
    scene = Scene(entities=[surface])
    print(f"surface: {surface.n_vertices} vertices, {surface.n_faces} triangles, 2 properties")
    print(
        f"{'format':7}{'op':7}{'geobrep best/median s':>22}{'direct best/median s':>22}"
        f"{'ratio best':>12}{'ratio median':>14}  anchor"
    )
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for name, extension, anchor, direct in (
            ("vtu", ".vtu", "meshio", direct_meshio),
            ("ply", ".ply", "plyfile", direct_plyfile),
            ("vtp", ".vtp", "pyvista", direct_pyvista),
        ):
            ours = folder / f"ours{extension}"
            theirs = folder / f"direct{extension}"
            write_direct, read_direct = direct(surface, folder)
            write_direct()  # warm up imports and both files
            read_direct()
            write(scene, ours)
            assert read(ours).surfaces[0].replace(id=None) == surface
            times: dict[str, list[float]] = {}
            writers = [
                ("ours", ours, lambda: write(scene, ours)),  # noqa: B023
                ("direct", theirs, write_direct),
            ]
            readers = [("ours", lambda: read(ours)), ("direct", read_direct)]  # noqa: B023
            for run in range(args.repeat):
                # Interleaved, so that both see the same load, and each goes first every other
                # run (the first read after the writes is slower, whoever does it).
                order = slice(None, None, -1 if run % 2 else 1)
                for key, target, function in writers[order]:
                    target.unlink()
                    times.setdefault(f"new {key}", []).append(timed(function))
                    times.setdefault(f"over {key}", []).append(timed(function))
                for key, function in readers[order]:
                    times.setdefault(f"read {key}", []).append(timed(function))
            for op, label in (("new", "write"), ("over", "write*"), ("read", "read")):
                (mb, mm), (tb, tm) = summary(times[f"{op} ours"]), summary(times[f"{op} direct"])
                print(
                    f"{name:7}{label:7}{mb:11.3f} /{mm:7.3f}{tb:12.3f} /{tm:7.3f}"
                    f"{mb / tb:12.2f}{mm / tm:14.2f}  {anchor}"
                )
    print(
        "write: a new file; write*: over an existing file (geobrep renames a temporary file "
        "onto it, which ext4 follows with a flush of the new blocks; the direct call truncates)"
    )


if __name__ == "__main__":
    main()
