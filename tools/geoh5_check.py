"""Cross-check geobrep's geoh5 adapter with geoh5py, which cannot share geobrep's environment
(it pins numpy<1.27): ``make geoh5-check`` runs the three steps, each in its own environment.

1. ``write DIR`` (geobrep's venv): geobrep writes ``geobrep.geoh5`` and, beside it,
   ``geobrep-expected.npz``: every object's vertices, cells and data as geobrep wrote them.
2. ``geoh5py DIR`` (the geoh5py venv, no geobrep): geoh5py reads ``geobrep.geoh5`` and must
   find exactly those arrays; then it writes ``geoh5py.geoh5`` (points, curve, surface, block
   model with data) and ``geoh5py-expected.npz`` (what geoh5py says the file holds).
3. ``read DIR`` (geobrep's venv): geobrep reads ``geoh5py.geoh5`` and must find those arrays.

Each step prints what it compared and exits 1 on the first difference.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import numpy as np


def _fail(message: str) -> None:
    print(f"geoh5-check FAILED: {message}")
    raise SystemExit(1)


def _same(name: str, got: Any, want: Any) -> None:
    got, want = np.asarray(got), np.asarray(want)
    if got.shape != want.shape or not np.array_equal(got, want):
        _fail(f"{name}: geoh5 holds {got.shape} {got.dtype}, expected {want.shape} {want.dtype}")


def write_step(folder: Path) -> None:
    import geobrep
    from geobrep.adapters._grid_cells import Grid

    cake = geobrep.datasets.faulted_layer_cake()
    rng = np.random.default_rng(7)
    surfaces = [
        s.replace(
            point_data={"depth": -s.vertices[:, 2]},
            cell_data={"face": np.arange(s.n_faces, dtype=np.int32)},
        )
        for s in cake.surfaces
    ]
    wells = geobrep.PointSet(
        vertices=rng.uniform(0, 1000, (20, 3)) + np.array([450000, 6700000, -500]), name="wells"
    )
    trace = geobrep.PolyLine.from_parts(
        rng.uniform(0, 100, (6, 3)), [[0, 1, 2], [3, 4, 5]], name="trace"
    )
    grid = Grid(
        origin=(450000.0, 6700000.0, -800.0),
        sizes=(np.full(4, 25.0), np.full(3, 50.0), np.full(2, 10.0)),
    )
    blocks = grid.point_set("grade model", point_data={"grade": np.arange(24.0)})
    scene = geobrep.Scene(entities=[*surfaces, wells, trace, blocks], name="check")
    geobrep.write(scene, folder / "geobrep.geoh5")
    expected: dict[str, Any] = {}
    for entity in scene.entities:
        if entity.name == blocks.name:
            expected[f"{entity.name}|grade"] = _geoh5_order_values(
                grid, entity.point_data["grade"].values
            )
            continue
        expected[f"{entity.name}|vertices"] = entity.vertices
        cells = (
            getattr(entity, "faces", None)
            if entity.type == "Surface"
            else getattr(entity, "segments", None)
        )
        if cells is not None:
            expected[f"{entity.name}|cells"] = cells
        for name, prop in {**entity.point_data, **entity.cell_data}.items():
            expected[f"{entity.name}|{name}"] = prop.values
    np.savez(folder / "geobrep-expected.npz", **expected)
    print(f"geobrep wrote {len(scene.entities)} objects to {folder / 'geobrep.geoh5'}")


def _geoh5_order_values(grid: Any, values: Any) -> Any:
    nu, nv, nw = grid.shape
    v, u, w = np.meshgrid(np.arange(nv), np.arange(nu), np.arange(nw), indexing="ij")
    return np.asarray(values)[(u + nu * (v + nv * w)).ravel()]


def geoh5py_step(folder: Path) -> None:
    from geoh5py.objects import BlockModel, Curve, Points, Surface
    from geoh5py.workspace import Workspace

    expected = np.load(folder / "geobrep-expected.npz")
    compared = 0
    with Workspace(folder / "geobrep.geoh5", mode="r") as workspace:
        for obj in workspace.objects:
            if getattr(obj, "vertices", None) is not None:
                _same(f"{obj.name} vertices", obj.vertices, expected[f"{obj.name}|vertices"])
                compared += 1
            if isinstance(obj, Surface | Curve):
                _same(f"{obj.name} cells", obj.cells, expected[f"{obj.name}|cells"])
                compared += 1
            for data in obj.children:
                _same(f"{obj.name} {data.name}", data.values, expected[f"{obj.name}|{data.name}"])
                compared += 1
    if compared != len(expected.files):
        _fail(f"geoh5py found {compared} of the {len(expected.files)} arrays geobrep wrote")
    print(f"geoh5py read the {compared} arrays geobrep wrote, all equal")

    target = folder / "geoh5py.geoh5"
    target.unlink(missing_ok=True)
    offset = np.array([450000.25, 6700000.5, -10.0])
    vertices = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 1.5]]) + offset
    found: dict[str, Any] = {}
    with Workspace.create(target) as workspace:
        surface = Surface.create(
            workspace,
            name="surf",
            vertices=vertices,
            cells=np.array([[0, 1, 2], [1, 3, 2]], dtype=np.int32),
        )
        surface.add_data({"z": {"values": vertices[:, 2].copy(), "association": "VERTEX"}})
        points = Points.create(workspace, name="pts", vertices=vertices)
        points.add_data({"t": {"values": np.arange(4.0)}})
        curve = Curve.create(
            workspace,
            name="crv",
            vertices=vertices,
            cells=np.array([[0, 1], [1, 2], [2, 3]], dtype=np.uint32),
        )
        curve.add_data(
            {"id": {"values": np.array([1, 2, 3], dtype=np.int32), "association": "CELL"}}
        )
        model = BlockModel.create(
            workspace,
            name="bm",
            origin=[10.0, 20.0, 30.0],
            u_cell_delimiters=np.array([0.0, 1, 3]),
            v_cell_delimiters=np.array([0.0, 2]),
            z_cell_delimiters=np.array([-2.0, -1, 0]),
        )
        model.add_data({"rho": {"values": np.arange(4.0), "association": "CELL"}})
        for obj in (surface, points, curve):
            found[f"{obj.name}|vertices"] = obj.vertices
            for data in obj.children:
                found[f"{obj.name}|{data.name}"] = data.values
        found["surf|cells"] = surface.cells
        found["crv|cells"] = curve.cells
        found["bm|centroids"] = model.centroids
        found["bm|rho"] = model.children[0].values
    np.savez(folder / "geoh5py-expected.npz", **found)
    print(f"geoh5py wrote {target}")


def read_step(folder: Path) -> None:
    import geobrep

    expected = np.load(folder / "geoh5py-expected.npz")
    scene = geobrep.read(folder / "geoh5py.geoh5")
    surf, pts, crv, bm = (scene[n] for n in ("surf", "pts", "crv", "bm"))
    _same("surf vertices", surf.vertices, expected["surf|vertices"])
    _same("surf cells", surf.faces, expected["surf|cells"])
    _same("surf z", surf.point_data["z"].values, expected["surf|z"])
    _same("pts vertices", pts.vertices, expected["pts|vertices"])
    _same("pts t", pts.point_data["t"].values, expected["pts|t"])
    _same("crv vertices", crv.vertices, expected["crv|vertices"])
    _same("crv segments", crv.segments, expected["crv|cells"])
    _same("crv id", crv.cell_data["id"].values, expected["crv|id"])
    # geobrep holds cells u fastest; geoh5 v slowest, z fastest: compare as sets of (centre, value)
    ours = np.column_stack([bm.vertices, bm.point_data["rho"].values])
    theirs = np.column_stack([expected["bm|centroids"], expected["bm|rho"]])
    _same("bm cells", ours[np.lexsort(ours.T)], theirs[np.lexsort(theirs.T)])
    print("geobrep read what geoh5py wrote: 4 objects, all arrays equal")


if __name__ == "__main__":
    step, where = sys.argv[1], Path(sys.argv[2])
    where.mkdir(parents=True, exist_ok=True)
    {"write": write_step, "geoh5py": geoh5py_step, "read": read_step}[step](where)
