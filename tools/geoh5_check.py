"""Cross-check geobrep's geoh5 adapter with geoh5py, which cannot share geobrep's environment
(it pins numpy<1.27): ``make geoh5-check`` runs the three steps, each in its own environment.

1. ``write DIR`` (geobrep's venv): geobrep writes ``geobrep.geoh5`` and, beside it,
   ``geobrep-expected.npz``: every object's vertices, cells and data as geobrep wrote them.
2. ``geoh5py DIR`` (the geoh5py venv, no geobrep): geoh5py reads ``geobrep.geoh5`` and must
   find exactly those arrays; then it writes ``geoh5py.geoh5`` (points, curve, surface, block
   model with data) and ``geoh5py-expected.npz`` (what geoh5py says the file holds).
3. ``read DIR`` (geobrep's venv): geobrep reads ``geoh5py.geoh5`` and must find those arrays.

Step 2 also writes ``drillhole-group.geoh5``: a ``DrillholeGroup`` whose drillholes geoh5py
files concatenated (geoh5 2.1), with surveys, depth logs (float, integer, a gap), referenced
depth data, referenced and numeric interval tables, and ``drillhole-group-expected.npz``:
geoh5py's collars, surveys, desurveyed stations, logs, markers and zones; step 3 reads it with
geobrep and compares them array by array. ``group FILE`` (geoh5py venv) writes just that file
and its ``.npz`` beside it: tests/data/geoh5/ holds one made so (tests/data/geoh5/SOURCES.md).

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
    well = _well()
    scene = geobrep.Scene(entities=[*surfaces, wells, trace, blocks, well], name="check")
    geobrep.write(scene, folder / "geobrep.geoh5")
    expected: dict[str, Any] = _well_expected(well)
    for entity in scene.entities:
        if entity.type == "Well":
            continue
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


def _well() -> Any:
    """A deviated well (minimum curvature, turning in azimuth) with logs, markers and zones."""
    import geobrep
    from geobrep.geometry.trajectory import minimum_curvature
    from geobrep.model.entities import WellLog, WellMarker, WellZone

    md = np.arange(0.0, 1501.0, 100.0)
    head = np.array([450100.0, 6700200.0, 120.0])
    stations = head + minimum_curvature(md, np.clip(md / 30.0, 0.0, 40.0), 20.0 + md / 25.0)
    rng = np.random.default_rng(3)
    return geobrep.Well(
        name="W-1",
        head=head,
        vertices=stations,
        md=md,
        markers=[
            WellMarker(name="H1 pick", md=412.5, surface="H1"),
            WellMarker(name="F1 pick", md=412.5, surface="F1"),
            WellMarker(name="H2 pick", md=980.0, surface="H2"),
        ],
        zones=[
            WellZone(name="U1", top_md=412.5, base_md=980.0),
            WellZone(name="U2", top_md=980.0, base_md=1500.0),
        ],
        logs={
            "GR": WellLog(md=np.arange(5.0, 1495.0, 0.5), values=rng.normal(80.0, 9.0, 2980)),
            "FACIES": WellLog(
                md=np.arange(100.0, 1400.0, 12.5), values=(np.arange(104) % 3).astype(np.int32)
            ),
        },
    )


def _well_expected(well: Any) -> dict[str, Any]:
    """What geoh5py must find of the well: collar, float32 surveys, where geoh5's desurveying
    puts the stations' depths (geobrep's port of it), logs, markers and zones."""
    from geobrep.adapters.geoh5._desurvey import desurvey, station_surveys

    rows = station_surveys(well.vertices, well.md)
    table = np.column_stack([rows[k] for k in ("Depth", "Azimuth", "Dip")]).astype(np.float64)
    found = {
        "well|collar": np.asarray(well.head),
        "well|surveys": table,
        "well|md": well.md,
        "well|desurvey": desurvey(well.head, table, float(well.md[-1]), well.md),
        "well|markers": np.array([f"{m.name}@{m.md}@{m.surface}" for m in well.markers]),
        "well|zones": np.array([f"{z.name}@{z.top_md}@{z.base_md}" for z in well.zones]),
    }
    for name, log in well.logs.items():
        found[f"well|log|{name}|md"], found[f"well|log|{name}|values"] = log.md, log.values
    return found


def _geoh5_order_values(grid: Any, values: Any) -> Any:
    nu, nv, nw = grid.shape
    v, u, w = np.meshgrid(np.arange(nv), np.arange(nu), np.arange(nw), indexing="ij")
    return np.asarray(values)[(u + nu * (v + nv * w)).ravel()]


def _close(name: str, got: Any, want: Any, metres: float = 1e-6) -> None:
    got, want = np.asarray(got, dtype=float), np.asarray(want, dtype=float)
    if got.shape != want.shape or not np.allclose(got, want, rtol=0.0, atol=metres):
        _fail(f"{name}: {got.shape} positions differ from {want.shape} by more than {metres} m")


def _picks(depth: Any, names: Any, keys: Any, surfaces: Any = None) -> Any:
    """``name@depth@surface`` of each keyed row (``obj``'s value maps name the keys)."""
    rows = np.flatnonzero(np.asarray(keys) > 0)
    surface = [surfaces.value_map()[k] if k else "" for k in surfaces.values] if surfaces else None
    return np.array(
        [f"{names[int(keys[r])]}@{float(depth[r])}@{surface[r] if surface else ''}" for r in rows]
    )


def _check_drillhole(obj: Any, expected: Any) -> int:
    """geoh5py's view of geobrep's well: collar, surveys, desurveying, logs, markers, zones."""
    collar = [obj.collar["x"], obj.collar["y"], obj.collar["z"]]
    _same("well collar", np.asarray(collar, dtype=float).ravel(), expected["well|collar"])
    _same("well surveys", obj.surveys, expected["well|surveys"])
    _close("well desurvey", obj.desurvey(expected["well|md"]), expected["well|desurvey"])
    data = {d.name: d for d in obj.children}
    depth = np.asarray(data["DEPTH"].values)
    compared = 4
    for name in [k.split("|")[2] for k in expected.files if k.endswith("|values")]:
        values = np.asarray(data[name].values)
        kept = ~np.isnan(values) if values.dtype.kind == "f" else values != data[name].ndv
        _same(f"well {name} depths", depth[kept], expected[f"well|log|{name}|md"])
        _same(f"well {name} values", values[kept], expected[f"well|log|{name}|values"])
        compared += 2
    marker = data["MARKER"]
    markers = _picks(depth, marker.value_map(), marker.values, data["MARKER SURFACE"])
    _same("well markers", markers, expected["well|markers"])
    zone = data["ZONE"]
    tops, bases = data["FROM"].values, data["TO"].values
    zones = [
        f"{zone.value_map()[int(k)]}@{t}@{b}"
        for k, t, b in zip(zone.values, tops, bases, strict=True)
    ]
    _same("well zones", np.array(zones), expected["well|zones"])
    return compared + 2


def _geoh5py_drillhole(workspace: Any) -> dict[str, Any]:
    """A drillhole as geoh5py writes one (surveys, a depth log, referenced intervals) and what
    geoh5py says it holds: the desurveyed stations, the log and the intervals."""
    from geoh5py.objects import Drillhole

    surveys = np.array([[0.0, 45, -90], [150, 50, -80], [400, 70, -60], [700, 90, -50]])
    hole = Drillhole.create(
        workspace, name="dh", collar=np.array([450500.0, 6700600, 95]), surveys=surveys
    )
    hole.end_of_hole = 800.0
    depth = np.arange(2.0, 790.0, 1.5)
    intervals = np.array([[10.0, 120.0], [120.0, 300.5], [300.5, 640.0]])
    hole.add_data(
        {
            "gr": {"values": 60 + 50 * np.sin(depth / 20), "depth": depth},
            "litho": {
                "type": "referenced",
                "values": np.array([1, 2, 1], dtype=np.int32),
                "value_map": {1: "sand", 2: "shale"},
                "from-to": intervals,
            },
        }
    )
    md = np.unique(np.r_[0.0, hole.surveys[:, 0], hole.end_of_hole])
    return {
        "dh|md": md,
        "dh|stations": hole.desurvey(md),
        "dh|gr depth": depth,
        "dh|gr": hole.get_data("gr")[0].values[~np.isnan(hole.get_data("gr")[0].values)],
        "dh|zones": np.array(
            [f"{n}@{t}@{b}" for n, (t, b) in zip(["sand", "shale", "sand"], intervals, strict=True)]
        ),
    }


def _group_holes() -> list[dict[str, Any]]:
    """Three drillholes: deviated with a log gap, an integer log and picks; one survey row."""
    depth = np.arange(1.0, 420.0, 2.5)
    gr = 60 + 50 * np.sin(depth / 20)
    gr[40:46] = np.nan  # not logged there: geoh5's no-data value
    picks = np.zeros(depth.shape, dtype=np.int32)
    picks[[12, 70, 131]] = [1, 2, 1]
    return [
        {
            "name": "DH-1",
            "collar": [450500.0, 6700600.0, 95.0],
            "surveys": [[0.0, 45.0, -90.0], [150.0, 50.0, -80.0], [400.0, 70.0, -60.0]],
            "data": {
                "gr": {"values": gr, "depth": depth},
                "litho": {
                    "type": "referenced",
                    "values": np.array([1, 2, 1], dtype=np.int32),
                    "value_map": {1: "sand", 2: "shale"},
                    "from-to": np.array([[10.0, 120.0], [120.0, 300.5], [300.5, 440.0]]),
                },
                "au": {
                    "values": np.array([0.25, 1.5, 0.125]),
                    "from-to": np.array([[12.0, 14.0], [14.0, 16.5], [30.0, 31.0]]),
                },
            },
        },
        {
            "name": "DH-2",
            "collar": [450620.0, 6700580.0, 101.5],
            "surveys": [[0.0, 120.0, -75.0], [90.0, 125.0, -70.0], [210.0, 140.0, -62.5]],
            "data": {
                "facies": {
                    "values": (np.arange(depth.size) % 4).astype(np.int32),
                    "depth": depth,
                },
                "picks": {
                    "type": "referenced",
                    "values": picks,
                    "value_map": {1: "H1 top", 2: "F1"},
                    "depth": depth,
                },
            },
        },
        {
            "name": "DH-3",
            "collar": [450480.0, 6700720.0, 90.0],
            "surveys": [[0.0, 0.0, -90.0]],
            "data": {
                "unit": {
                    "type": "referenced",
                    "values": np.array([3, 1], dtype=np.int32),
                    "value_map": {1: "U1", 3: "U3"},
                    "from-to": np.array([[0.0, 55.0], [55.0, 80.25]]),
                },
            },
        },
    ]


def write_drillhole_group(target: Path) -> dict[str, Any]:
    """Write the drillhole group with geoh5py; what geoh5py then says each drillhole holds."""
    from geoh5py.groups import DrillholeGroup
    from geoh5py.objects import Drillhole
    from geoh5py.workspace import Workspace

    target.unlink(missing_ok=True)
    with Workspace.create(target) as workspace:
        group = DrillholeGroup.create(workspace, name="holes")
        for spec in _group_holes():
            hole = Drillhole.create(
                workspace,
                name=spec["name"],
                collar=np.array(spec["collar"]),
                surveys=np.array(spec["surveys"]),
                parent=group,
            )
            hole.add_data(spec["data"])
    found: dict[str, Any] = {}
    with Workspace(target, mode="r") as workspace:
        holes = [o for o in workspace.objects if type(o).__name__ == "ConcatenatedDrillhole"]
        for hole in sorted(holes, key=lambda h: h.name):
            found.update(_hole_expected(hole))
    return found


def _hole_expected(hole: Any) -> dict[str, Any]:
    """geoh5py's view of a concatenated drillhole, keyed ``name|...``: collar, surveys, the
    stations geobrep places (depth 0, survey depths, end of hole, deepest sample: geoh5py's
    desurveying there), logs without their no-data rows, markers and zones."""
    key = hole.name
    found: dict[str, Any] = {
        f"{key}|collar": np.array([hole.collar["x"], hole.collar["y"], hole.collar["z"]]),
        f"{key}|surveys": np.asarray(hole.surveys, dtype=np.float64),
    }
    markers, zones, deepest = [], [], 0.0
    for group in hole.property_groups or []:
        members = [hole.get_data(u)[0] for u in group.properties]
        if group.property_group_type == "Depth table":
            depth = np.asarray(members[0].values, dtype=np.float64)
            for member in members[1:]:
                values = np.asarray(member.values)
                kept = ~np.isnan(values) if values.dtype.kind == "f" else values != member.ndv
                if type(member).__name__.endswith("ReferencedData"):
                    names = member.value_map()
                    markers += [
                        f"{names[int(values[r])]}@{float(depth[r])}"
                        for r in np.flatnonzero(kept & (values > 0))
                    ]
                else:
                    found[f"{key}|log|{member.name}|md"] = depth[kept]
                    found[f"{key}|log|{member.name}|values"] = values[kept]
                deepest = max(deepest, float(depth[kept].max(initial=0.0)))
        else:
            tops = np.asarray(members[0].values, dtype=np.float64)
            bases = np.asarray(members[1].values, dtype=np.float64)
            deepest = max(deepest, float(bases.max(initial=0.0)))
            for member in members[2:]:
                values = np.asarray(member.values)
                if type(member).__name__.endswith("ReferencedData"):
                    names = member.value_map()
                    zones += [
                        f"{names[int(v)]}@{t}@{b}@{member.name}"
                        for v, t, b in zip(values, tops, bases, strict=True)
                        if v > 0
                    ]
                else:
                    zones += [
                        f"{member.name}@{t}@{b}@{v.item()!r}"
                        for v, t, b in zip(values, tops, bases, strict=True)
                    ]
    surveys = found[f"{key}|surveys"]
    end = hole.end_of_hole
    stops = [[0.0], surveys[:, 0], [] if end is None else [end]]
    if deepest > max(float(surveys[-1, 0]), end or 0.0):
        stops.append([deepest])
    md = np.unique(np.concatenate(stops))
    found[f"{key}|md"] = md
    found[f"{key}|stations"] = hole.desurvey(md)
    found[f"{key}|markers"] = np.array(sorted(markers, key=lambda m: float(m.split("@")[1])))
    found[f"{key}|zones"] = np.array(zones)
    return found


def group_step(target: Path) -> None:
    found = write_drillhole_group(target)
    np.savez(target.with_suffix(".npz"), **found)
    print(f"geoh5py wrote {target} and what it holds, {target.with_suffix('.npz')}")


def check_drillhole_group(scene: Any, expected: Any, metres: float = 1e-9) -> int:
    """Compare geobrep's Wells of the drillhole group with geoh5py's view; arrays compared."""
    names = sorted({k.split("|")[0] for k in expected.files})
    compared = 0
    for name in names:
        well = scene[name]
        _same(f"{name} collar", well.head, expected[f"{name}|collar"])
        _same(f"{name} md", well.md, expected[f"{name}|md"])
        _close(f"{name} stations", well.vertices, expected[f"{name}|stations"], metres)
        compared += 3
        for log in [k.split("|")[2] for k in expected.files if k.startswith(f"{name}|log|")]:
            _same(f"{name} {log} depths", well.logs[log].md, expected[f"{name}|log|{log}|md"])
            want = expected[f"{name}|log|{log}|values"]
            _same(f"{name} {log} values", well.logs[log].values, want)
            compared += 1
        markers = [f"{m.name}@{m.md}" for m in well.markers]
        _same(f"{name} markers", np.array(markers), expected[f"{name}|markers"])
        zones = [
            f"{z.name}@{z.top_md}@{z.base_md}@"
            + (repr(z.metadata["value"]) if "value" in z.metadata else z.metadata["geoh5 data"])
            for z in well.zones
        ]
        _same(f"{name} zones", np.array(zones), expected[f"{name}|zones"])
        compared += 2
    return compared


def geoh5py_step(folder: Path) -> None:
    from geoh5py.objects import BlockModel, Curve, Drillhole, Points, Surface
    from geoh5py.workspace import Workspace

    expected = np.load(folder / "geobrep-expected.npz")
    compared = 0
    with Workspace(folder / "geobrep.geoh5", mode="r") as workspace:
        for obj in workspace.objects:
            if isinstance(obj, Drillhole):
                compared += _check_drillhole(obj, expected)
                continue
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
        found.update(_geoh5py_drillhole(workspace))
    np.savez(folder / "geoh5py-expected.npz", **found)
    print(f"geoh5py wrote {target}")
    group_step(folder / "drillhole-group.geoh5")


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
    dh = scene["dh"]
    _same("dh md", dh.md, expected["dh|md"])
    _close("dh stations", dh.vertices, expected["dh|stations"], metres=1e-9)
    _same("dh gr depth", dh.logs["gr"].md, expected["dh|gr depth"])
    _same("dh gr", dh.logs["gr"].values, expected["dh|gr"])
    zones = [f"{z.name}@{z.top_md}@{z.base_md}" for z in dh.zones]
    _same("dh zones", np.array(zones), expected["dh|zones"])
    print("geobrep read what geoh5py wrote: 5 objects, all arrays equal")
    group = np.load(folder / "drillhole-group.npz")
    wells = geobrep.read(folder / "drillhole-group.geoh5")
    compared = check_drillhole_group(wells, group)
    print(f"geobrep read geoh5py's drillhole group: {len(wells.entities)} wells, {compared} equal")


if __name__ == "__main__":
    step, where = sys.argv[1], Path(sys.argv[2])
    if step == "group":
        where.parent.mkdir(parents=True, exist_ok=True)
        group_step(where)
    else:
        where.mkdir(parents=True, exist_ok=True)
        {"write": write_step, "geoh5py": geoh5py_step, "read": read_step}[step](where)
