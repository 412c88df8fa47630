"""Exchange formats: write and read a 1M-triangle surface through geobrep and through each
library directly (the anchors), and the overhead ratio geobrep / library.

* RESQML: ``geobrep.write/read`` of an ``.epc`` against resqpy's own calls (new model, CRS,
  ``Surface.set_from_triangles_and_points``, ``write_hdf5``, ``create_xml``, ``store_epc``;
  ``Model`` + ``Surface.triangles_and_points``);
* OMF: against ``omf.OMFWriter`` / ``omf.OMFReader`` of the same SurfaceElement;
* geoh5: against h5py writing and reading the same datasets (geoh5py cannot share this
  environment; ``make geoh5-check`` compares with it); ``read*`` against h5py reading them
  with ``read_direct`` into new arrays, as geobrep does (the quickest h5py reading).

Prints the best and the median of 5 interleaved runs (3 with ``--quick``, on 200k triangles;
``--runs=N`` for N) and their ratios (target: at most 1.10); geobrep's figures include
validating the entities it builds. Times are CPU times of the process (``time.process_time``,
every thread; the machine is shared), ``--wall`` for wall-clock times. glTF and 3D Tiles are
measured by benchmarks/web.py.

    python benchmarks/exchange.py [--quick] [--runs=N] [--wall] [--only=resqml,omf,geoh5]
        [--geoh5py=PYTHON]

``--geoh5py=PYTHON`` (an interpreter with geoh5py, e.g. the ``.venv-geoh5`` that
``make geoh5-check`` builds) adds the row ``read geoh5py``: geoh5py opening geobrep's file and
reading the surface's vertices, cells and data, timed in a child process of its own (after a
first read), next to geobrep's reads of the same file.
"""

from __future__ import annotations

import sys
import tempfile
import time
import warnings
from collections.abc import Callable
from pathlib import Path
from statistics import median
from typing import Any

import numpy as np

import geobrep

QUICK = "--quick" in sys.argv
RUNS = next((int(a.split("=", 1)[1]) for a in sys.argv if a.startswith("--runs=")), 0) or (
    3 if QUICK else 5
)
#: ``--wall``: wall-clock times instead of the process's CPU time.
CLOCK = time.perf_counter if "--wall" in sys.argv else time.process_time
#: ``--only resqml,omf``: just these formats.
ONLY = next((a.split("=", 1)[1].split(",") for a in sys.argv if a.startswith("--only=")), [])
#: ``--geoh5py=PYTHON``: an interpreter that has geoh5py (it cannot share this environment).
GEOH5PY = next((a.split("=", 1)[1] for a in sys.argv if a.startswith("--geoh5py=")), "")

_GEOH5PY_READ = """
import json, sys, time
from geoh5py.workspace import Workspace
clock = time.perf_counter if sys.argv[3] == "wall" else time.process_time
def read():
    with Workspace(sys.argv[1], mode="r") as ws:
        (surface,) = ws.get_entity("horizon")
        kept = [surface.vertices, surface.cells]
        kept.extend(d.values for d in surface.children if hasattr(d, "values"))
    return kept
read()
times = []
for _ in range(int(sys.argv[2])):
    start = clock(); read(); times.append(clock() - start)
print(json.dumps(times))
"""


def _geoh5py_reads(path: Path) -> list[float] | None:
    """geoh5py's read times of ``path`` in a child process of the ``--geoh5py`` interpreter."""
    import json
    import subprocess

    clock = "wall" if CLOCK is time.perf_counter else "cpu"
    done = subprocess.run(
        [GEOH5PY, "-c", _GEOH5PY_READ, str(path), str(RUNS), clock],
        capture_output=True,
        text=True,
        check=False,
    )
    if done.returncode != 0:
        print(f"geoh5py read failed: {done.stderr.strip().splitlines()[-1:]}")
        return None
    return [float(t) for t in json.loads(done.stdout)]


def _surface(n_triangles: int) -> geobrep.Surface:
    """A wavy grid of about ``n_triangles`` triangles at UTM coordinates, with a depth property."""
    side = int(np.sqrt(n_triangles / 2)) + 1
    x, y = np.meshgrid(np.linspace(0, 5000, side), np.linspace(0, 5000, side))
    z = -800 + 40 * np.sin(x / 700) * np.cos(y / 900)
    vertices = np.column_stack([x.ravel() + 450000.0, y.ravel() + 6700000.0, z.ravel()])
    idx = np.arange(side * side).reshape(side, side)
    a, b, c, d = (
        idx[:-1, :-1].ravel(),
        idx[:-1, 1:].ravel(),
        idx[1:, :-1].ravel(),
        idx[1:, 1:].ravel(),
    )
    faces = np.concatenate([np.column_stack([a, b, d]), np.column_stack([a, d, c])])
    return geobrep.Surface(
        vertices=vertices,
        faces=faces,
        name="horizon",
        kind="horizon",
        point_data={"depth": -vertices[:, 2]},
    )


def _timed(action: Callable[[], Any]) -> float:
    start = CLOCK()
    action()
    return CLOCK() - start


def _resqpy_direct(
    surface: geobrep.Surface, folder: Path
) -> tuple[Callable[[], Any], Callable[[], Any]]:
    """The objects geobrep writes: a z-up CRS, the horizon feature and interpretation, the
    triangulated set representing it and its node property; read back as a Surface holds
    them (float64 points, int64 triangles, the property)."""
    import resqpy.crs as rqc
    import resqpy.model as rq
    import resqpy.organize as rqo
    import resqpy.property as rqp
    import resqpy.surface as rqs

    path = folder / "direct.epc"

    def write() -> None:
        model = rq.new_model(str(path))
        crs = rqc.Crs(model, epsg_code="32631", z_inc_down=False)
        crs.create_xml()
        feature = rqo.GeneticBoundaryFeature(model, feature_name="horizon", kind="horizon")
        feature.create_xml()
        interpretation = rqo.HorizonInterpretation(
            model, title="horizon", genetic_boundary_feature=feature
        )
        interpretation.create_xml()
        rep = rqs.Surface(model, crs_uuid=crs.uuid, title="horizon")
        rep.set_from_triangles_and_points(surface.faces, surface.vertices)
        rep.set_represented_interpretation_root(interpretation.root)
        rep.write_hdf5()
        rep.create_xml()
        collection = rqp.PropertyCollection()
        collection.set_support(support=rep)
        collection.add_cached_array_to_imported_list(
            np.asarray(surface.point_data["depth"].values),
            "bench",
            "depth",
            uom="m",
            property_kind="continuous",
            indexable_element="nodes",
        )
        collection.write_hdf5_for_imported_list(use_int32=False)
        collection.create_xml_for_imported_list_and_add_parts_to_model()
        model.store_epc()

    def read() -> list[Any]:
        model = rq.Model(str(path))
        rep = rqs.Surface(model, uuid=model.uuid(obj_type="TriangulatedSetRepresentation"))
        triangles, points = rep.triangles_and_points()
        kept = [np.asarray(triangles, dtype=np.int64), np.asarray(points, dtype=np.float64)]
        collection = rqp.PropertyCollection(support=rep)
        kept.extend(collection.cached_part_array_ref(part) for part in collection.parts())
        return kept  # held to the end, as a Surface holds them

    return write, read


def _omf_direct(
    surface: geobrep.Surface, folder: Path
) -> tuple[Callable[[], Any], Callable[[], Any]]:
    import omf

    path = folder / "direct.omf"

    def write() -> None:
        element = omf.SurfaceElement(
            name="horizon",
            geometry=omf.SurfaceGeometry(
                vertices=np.ascontiguousarray(surface.vertices),
                triangles=np.ascontiguousarray(surface.faces),
            ),
            data=[
                omf.ScalarData(
                    name="depth",
                    array=np.ascontiguousarray(surface.point_data["depth"].values),
                    location="vertices",
                )
            ],
        )
        omf.OMFWriter(omf.Project(name="bench", elements=[element]), str(path))

    def read() -> None:
        project = omf.OMFReader(str(path)).get_project()
        element = project.elements[0]
        np.asarray(element.geometry.vertices), np.asarray(element.geometry.triangles)
        [np.asarray(d.array) for d in element.data]

    return write, read


def _h5py_direct(
    surface: geobrep.Surface, folder: Path
) -> tuple[Callable[[], Any], Callable[[], Any]]:
    """The geoh5 objects geobrep writes, by h5py: the workspace's groups and types, the
    Surface object (x, y, z records, int32 cells) and its vertex data with their attributes;
    read back as a Surface holds them (float64 points, the int32 triangles as stored, the
    data), every array held to the end of the read as the Surface holds them (an array freed
    at once lets the next reuse its memory, which a reader building entities cannot)."""
    import h5py

    path = folder / "direct.geoh5"
    xyz = np.dtype([("x", "<f8"), ("y", "<f8"), ("z", "<f8")])
    flags = {"Allow delete": 1, "Allow move": 1, "Allow rename": 1, "Public": 1, "Visible": 1}
    surface_type = "{F26FEBA3-ADED-494B-B9E9-B2BBCBE298E1}"

    def write() -> None:
        rows = np.empty(surface.n_vertices, dtype=xyz)
        rows["x"], rows["y"], rows["z"] = surface.vertices.T
        with h5py.File(path, "w") as store:
            root = store.create_group("GEOSCIENCE")
            root.attrs.update({"Version": 2.0, "Distance unit": "meter", "GA Version": "1"})
            for folder in ("Data", "Groups", "Objects", "Types/Data types", "Types/Group types"):
                root.create_group(folder, track_order=True)
            workspace = root["Groups"].create_group("{w}")
            workspace.attrs.update({"ID": "{w}", "Name": "Workspace", **flags})
            workspace.create_group("Objects", track_order=True)
            root["Root"] = workspace
            kind = root.create_group(f"Types/Object types/{surface_type}")
            kind.attrs.update({"ID": surface_type, "Name": "Surface", "Description": "Surface"})
            obj = root["Objects"].create_group("{s}")
            obj.attrs.update({"ID": "{s}", "Name": "horizon", "Last focus": "None", **flags})
            obj["Type"] = kind
            workspace["Objects"]["{s}"] = obj
            obj.create_dataset("Vertices", data=rows)
            obj.create_dataset("Cells", data=surface.faces.astype(np.int32))
            data = root["Data"].create_group("{d}")
            data.attrs.update({"ID": "{d}", "Name": "depth", "Association": "Vertex", **flags})
            data.create_dataset("Data", data=np.asarray(surface.point_data["depth"].values))
            data_type = root["Types/Data types"].create_group("{t}")
            data_type.attrs.update({"ID": "{t}", "Name": "depth", "Primitive type": "Float"})
            data["Type"] = data_type
            obj.create_group("Data")["{d}"] = data

    def read() -> list[Any]:
        kept = []  # held to the end, as a Surface holds them (not freed one by one)
        with h5py.File(path, "r") as store:
            for obj in store["GEOSCIENCE/Objects"].values():
                rows = obj["Vertices"][()]
                kept.append(np.column_stack([rows["x"], rows["y"], rows["z"]]))
                kept.append(obj["Cells"][()])
                kept.extend(data["Data"][()] for data in obj["Data"].values())
        return kept

    return write, read


def _h5py_read_direct(folder: Path) -> Callable[[], Any]:
    """The same reading with h5py's ``read_direct`` into new arrays (geobrep's way since it
    read so) and the x, y, z records viewed as ``(N, 3)``, not copied: the quickest h5py
    reading of those datasets, the stricter anchor."""
    import h5py

    path = folder / "direct.geoh5"

    def whole(dataset: Any) -> Any:
        array = np.empty(dataset.shape, dtype=dataset.dtype)
        dataset.read_direct(array)
        return array

    def read() -> list[Any]:
        kept = []
        with h5py.File(path, "r") as store:
            for obj in store["GEOSCIENCE/Objects"].values():
                kept.append(whole(obj["Vertices"]).view("<f8").reshape(-1, 3))
                kept.append(whole(obj["Cells"]))
                kept.extend(whole(data["Data"]) for data in obj["Data"].values())
        return kept

    return read


def _run(
    name: str, scene: geobrep.Scene, path: Path, direct: tuple[Callable[[], Any], Callable[[], Any]]
) -> None:
    """Interleaved runs of geobrep and the direct calls (each first in turn); best, median."""
    direct_write, direct_read = direct
    direct_write()  # imports, caches
    direct_read()
    geobrep.write(scene, path)
    times: dict[str, list[float]] = {}
    for op, ours, theirs in (
        ("write", lambda: geobrep.write(scene, path), direct_write),
        ("read", lambda: geobrep.read(path), direct_read),
    ):
        pair = [("ours", ours), ("direct", theirs)]
        for run in range(RUNS):
            for key, action in pair[:: -1 if run % 2 else 1]:
                times.setdefault(f"{op} {key}", []).append(_timed(action))
    if name == "geoh5":
        fast = _h5py_read_direct(path.parent)
        for run in range(RUNS):
            pair = [("ours", lambda: geobrep.read(path)), ("direct*", fast)]
            for key, action in pair[:: -1 if run % 2 else 1]:
                times.setdefault(f"read* {key}", []).append(_timed(action))
    if name == "geoh5" and GEOH5PY:
        library = _geoh5py_reads(path)
        if library:
            times["read geoh5py direct"] = library
            times["read geoh5py ours"] = times["read ours"]
    back = geobrep.read(path).surfaces[0]
    assert back.vertices.tobytes() == scene.surfaces[0].vertices.tobytes(), name
    for op in ("write", "read", "read*", "read geoh5py"):
        if f"{op} ours" not in times:
            continue
        ours_t, theirs_t = times[f"{op} ours"], times[f"{op} direct" + ("*" in op) * "*"]
        (ob, om), (tb, tm) = (min(ours_t), median(ours_t)), (min(theirs_t), median(theirs_t))
        print(
            f"{name:8}{op:13}{ob * 1e3:11.1f} /{om * 1e3:7.1f}{tb * 1e3:12.1f} /{tm * 1e3:7.1f}"
            f"{ob / tb:12.2f}{om / tm:14.2f}"
        )


def main() -> None:
    n = 200_000 if QUICK else 1_000_000
    surface = _surface(n)
    scene = geobrep.Scene(entities=[surface], crs=geobrep.CRS(epsg=32631))
    print(
        f"exchange formats: one surface of {surface.n_faces:,} triangles, "
        f"{surface.n_vertices:,} vertices; best and median of {RUNS} interleaved runs, "
        f"{'wall-clock' if CLOCK is time.perf_counter else 'CPU'} time"
    )
    print(
        f"{'format':8}{'op':13}{'geobrep best/median ms':>22}{'direct best/median ms':>22}"
        f"{'ratio best':>12}{'ratio median':>14}"
    )
    with tempfile.TemporaryDirectory() as tmp, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        folder = Path(tmp)
        for name, extension, direct in (
            ("resqml", ".epc", _resqpy_direct),
            ("omf", ".omf", _omf_direct),
            ("geoh5", ".geoh5", _h5py_direct),
        ):
            if ONLY and name not in ONLY:
                continue
            _run(name, scene, folder / f"ours{extension}", direct(surface, folder))


if __name__ == "__main__":
    main()
