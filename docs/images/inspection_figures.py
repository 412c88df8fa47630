"""Draw the pictures of docs/inspection.md: defective models (grey) and their defect layers
(``report.to_scene()``, in each check's colour).

Run from the repository root: ``.venv/bin/python docs/images/inspection_figures.py`` (needs
pyvista; renders off-screen).
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pyvista as pv

import geobrep
from geobrep import PolyLine, Scene, Surface

HERE = Path(__file__).parent
DATA = HERE.parent.parent / "tests" / "data" / "gocad"


def grid(n: int, name: str, x0: float = 0.0, z: float = 0.0, step: float = 1.0) -> Surface:
    xs, ys = np.meshgrid(np.arange(n + 1) * step + x0, np.arange(n + 1) * step)
    vertices = np.column_stack([xs.ravel(), ys.ravel(), np.full(xs.size, z)])
    i, j = np.meshgrid(np.arange(n), np.arange(n))
    a = (j * (n + 1) + i).ravel()
    faces = np.concatenate(
        [np.column_stack([a, a + 1, a + n + 2]), np.column_stack([a, a + n + 2, a + n + 1])]
    )
    return Surface(vertices=vertices, faces=faces, name=name)


def _poly(entity: geobrep.Entity) -> pv.PolyData:
    if isinstance(entity, Surface):
        faces = np.hstack([np.full((entity.n_faces, 1), 3), entity.faces]).ravel()
        return pv.PolyData(entity.vertices, faces)
    if isinstance(entity, PolyLine):
        lines = np.hstack([np.full((len(entity.segments), 1), 2), entity.segments]).ravel()
        return pv.PolyData(entity.vertices, lines=lines)
    return pv.PolyData(np.asarray(entity.vertices))


def draw(scene: Scene, checks: list[str], name: str, view: tuple[float, float, float]) -> None:
    report = geobrep.inspect(scene, checks)
    plotter = pv.Plotter(off_screen=True, window_size=(900, 650))
    for entity in scene.surfaces:
        plotter.add_mesh(
            _poly(entity), color="#dddddd", show_edges=True, edge_color="#888888", opacity=0.85
        )
    for entity in scene.polylines:
        plotter.add_mesh(_poly(entity), color="#444444", line_width=3)
    labels = []
    for entity in report.to_scene().entities:
        colour = str(entity.metadata["colour"])
        mesh = _poly(entity)
        if entity.type == "PointSet":
            plotter.add_mesh(mesh, color=colour, point_size=16, render_points_as_spheres=True)
            labels.append((mesh.points[0], str(entity.metadata["check"])))
        elif entity.type == "PolyLine":
            plotter.add_mesh(mesh, color=colour, line_width=6)
        else:
            plotter.add_mesh(mesh, color=colour, opacity=0.9)
    if labels:
        plotter.add_point_labels(
            [p for p, _ in labels],
            [t for _, t in labels],
            font_size=14,
            point_size=1,
            shape_opacity=0.6,
            always_visible=True,
        )
    plotter.view_vector(view)
    plotter.set_background("white")
    plotter.screenshot(str(HERE / f"inspection_{name}.png"))
    plotter.close()


def mesh_defects() -> Scene:
    surface = grid(8, "horizon")
    n = surface.n_vertices
    faces = surface.faces.copy()
    faces[[20, 75]] = faces[[20, 75]][:, ::-1]  # two flipped triangles
    vertices = np.vstack([surface.vertices, surface.vertices[[40]], [[4.0, 9.5, 0.0]]])
    row = int(np.flatnonzero((faces == 40).any(axis=1))[0])
    faces[row][faces[row] == 40] = n  # a duplicated vertex
    sliver = [[9.0, 2.0, 0.0], [9.0, 6.0, 0.0], [9.0, 4.0, 0.0]]
    vertices = np.vstack([vertices, sliver])
    faces = np.vstack([faces, [[n + 2, n + 3, n + 4]]])  # a zero-area triangle
    return Scene(entities=[Surface(vertices=vertices, faces=faces, name="horizon")])


def contacts() -> Scene:
    left = grid(2, "left", step=2.0)
    xs, ys = np.meshgrid([4.0, 6.0], np.arange(0.0, 4.01, 1.0))
    right_vertices = np.column_stack([xs.ravel(), ys.ravel(), np.zeros(xs.size)])
    faces = [[2 * j, 2 * j + 1, 2 * j + 3] for j in range(4)] + [
        [2 * j, 2 * j + 3, 2 * j + 2] for j in range(4)
    ]
    right = Surface(vertices=right_vertices, faces=faces, name="right")
    fault = Surface(
        vertices=[[1.0, -1, -1], [1.0, 5, -1], [1.0, 5, 1], [1.0, -1, 1]],
        faces=[[0, 1, 2], [0, 2, 3]],
        name="fault",
    )
    well = PolyLine.from_point_lists([[[5.0, 2.5, -1.5], [5.0, 2.5, 1.5]]], name="well")
    return Scene(entities=[left, right, fault, well])


def main() -> None:
    draw(
        mesh_defects(),
        ["colocated_vertices", "degenerate_elements", "inconsistent_orientation"],
        "mesh",
        (0.3, -1.0, 1.2),
    )
    draw(
        contacts(),
        ["t_junctions", "surface_intersections", "polyline_intersections"],
        "contacts",
        (0.4, -1.0, 0.7),
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        split = geobrep.read(DATA / "split_cube.ml", repair=False)
        unsealed = geobrep.read(DATA / "not_sealed_cube.ml", repair=False)
    draw(split, ["region_sides", "block_orientation"], "split_cube", (1.0, -1.2, 0.8))
    draw(unsealed, ["universe_closure"], "not_sealed_cube", (1.0, -1.2, 0.8))


if __name__ == "__main__":
    main()
