"""Reading and writing a 1M-triangle surface with properties: geobrep vs the libraries directly.

For VTU (meshio), PLY (plyfile) and VTP (pyvista), times geobrep's ``write``/``read`` against
calling the library itself on the same arrays, with the same settings, in the same run (best of
N), and prints the ratio: geobrep's overhead target is at most 10 %.

    .venv/bin/python benchmarks/formats_io.py [--triangles 1000000] [--repeat 3]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from geobrep.entities import Surface
from geobrep.io import read, write
from geobrep.scene import Scene


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


def best(function: Callable[[], Any], repeat: int) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def direct_meshio(surface: Surface, folder: Path) -> tuple[Callable[[], Any], Callable[[], Any]]:
    import meshio

    path = folder / "direct.vtu"
    mesh = meshio.Mesh(
        surface.vertices,
        [("triangle", surface.faces)],
        point_data={"depth": surface.point_data["depth"].values},
        cell_data={"zone": [surface.cell_data["zone"].values]},
    )
    return (
        lambda: meshio.write(path, mesh, file_format="vtu", binary=True, compression=None),
        lambda: meshio.read(path, file_format="vtu"),
    )


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
        # materialise what a caller needs: float64 points, int64 faces, property arrays
        points = np.column_stack([vertex["x"], vertex["y"], vertex["z"]])
        faces = np.asarray(face["vertex_indices"], dtype=np.int64)
        return points, faces, np.array(vertex["depth"]), np.array(face["zone"])

    return write_direct, read_direct


def direct_pyvista(surface: Surface, folder: Path) -> tuple[Callable[[], Any], Callable[[], Any]]:
    import pyvista as pv

    path = folder / "direct.vtp"

    def write_direct() -> None:
        faces = np.hstack([np.full((surface.n_faces, 1), 3), surface.faces]).ravel()
        mesh = pv.PolyData(surface.vertices.copy(), faces)
        mesh.point_data["depth"] = surface.point_data["depth"].values
        mesh.cell_data["zone"] = surface.cell_data["zone"].values
        mesh.save(path)

    return write_direct, lambda: pv.read(path)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--triangles", type=int, default=1_000_000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    surface = make_surface(args.triangles)
    scene = Scene(entities=[surface])
    print(f"surface: {surface.n_vertices} vertices, {surface.n_faces} triangles, 2 properties")
    print(f"{'format':8}{'op':7}{'geobrep s':>11}{'direct s':>11}{'ratio':>8}  anchor")
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for name, extension, anchor, direct in (
            ("vtu", ".vtu", "meshio", direct_meshio),
            ("ply", ".ply", "plyfile", direct_plyfile),
            ("vtp", ".vtp", "pyvista", direct_pyvista),
        ):
            ours = folder / f"ours{extension}"
            write_direct, read_direct = direct(surface, folder)
            write_direct()  # warm up imports
            write(scene, ours)
            ours_write = best(lambda: write(scene, ours), args.repeat)  # noqa: B023
            their_write = best(write_direct, args.repeat)
            ours_read = best(lambda: read(ours), args.repeat)  # noqa: B023
            their_read = best(read_direct, args.repeat)
            assert read(ours).surfaces[0].replace(id=None) == surface
            for op, mine, theirs in (("write", ours_write, their_write),
                                     ("read", ours_read, their_read)):  # fmt: skip
                print(f"{name:8}{op:7}{mine:11.3f}{theirs:11.3f}{mine / theirs:8.2f}  {anchor}")


if __name__ == "__main__":
    main()
