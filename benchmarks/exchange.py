"""Exchange formats: write and read a 1M-triangle surface through geobrep and through each
library directly (the anchors), and the overhead ratio geobrep / library.

* RESQML: ``geobrep.write/read`` of an ``.epc`` against resqpy's own calls (new model, CRS,
  ``Surface.set_from_triangles_and_points``, ``write_hdf5``, ``create_xml``, ``store_epc``;
  ``Model`` + ``Surface.triangles_and_points``);
* OMF: against ``omf.OMFWriter`` / ``omf.OMFReader`` of the same SurfaceElement;
* geoh5: against h5py writing and reading the same datasets (geoh5py cannot share this
  environment; ``make geoh5-check`` compares with it).

Every figure is the best of N runs (the machine may be shared); geobrep's figures include
validating the entity it builds.

    python benchmarks/exchange.py [--quick]
"""

from __future__ import annotations

import sys
import tempfile
import time
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

import geobrep

QUICK = "--quick" in sys.argv
RUNS = 2 if QUICK else 3


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


def _best(action: Callable[[], Any]) -> float:
    times = []
    for _ in range(RUNS):
        start = time.perf_counter()
        action()
        times.append(time.perf_counter() - start)
    return min(times)


def _resqpy_direct(
    surface: geobrep.Surface, folder: Path
) -> tuple[Callable[[], Any], Callable[[], Any]]:
    import resqpy.crs as rqc
    import resqpy.model as rq
    import resqpy.property as rqp
    import resqpy.surface as rqs

    path = folder / "direct.epc"

    def write() -> None:
        model = rq.new_model(str(path))
        crs = rqc.Crs(model, epsg_code="32631")
        crs.create_xml()
        rep = rqs.Surface(model, crs_uuid=crs.uuid, title="horizon")
        rep.set_from_triangles_and_points(surface.faces, surface.vertices)
        rep.write_hdf5()
        rep.create_xml()
        collection = rqp.PropertyCollection()
        collection.set_support(support=rep)
        collection.add_cached_array_to_imported_list(
            np.asarray(surface.point_data["depth"].values),
            "bench",
            "depth",
            uom="m",
            property_kind="depth",
            indexable_element="nodes",
        )
        collection.write_hdf5_for_imported_list()
        collection.create_xml_for_imported_list_and_add_parts_to_model()
        model.store_epc()

    def read() -> None:
        model = rq.Model(str(path))
        rep = rqs.Surface(model, uuid=model.uuid(obj_type="TriangulatedSetRepresentation"))
        rep.triangles_and_points()
        collection = rqp.PropertyCollection(support=rep)
        for part in collection.parts():
            collection.cached_part_array_ref(part)

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
    import h5py

    path = folder / "direct.geoh5"
    xyz = np.dtype([("x", "<f8"), ("y", "<f8"), ("z", "<f8")])

    def write() -> None:
        rows = np.empty(surface.n_vertices, dtype=xyz)
        rows["x"], rows["y"], rows["z"] = surface.vertices.T
        with h5py.File(path, "w") as store:
            obj = store.create_group("GEOSCIENCE/Objects/{s}")
            obj.create_dataset("Vertices", data=rows)
            obj.create_dataset("Cells", data=surface.faces.astype(np.int32))
            store.create_dataset(
                "GEOSCIENCE/Data/{d}/Data", data=np.asarray(surface.point_data["depth"].values)
            )

    def read() -> None:
        with h5py.File(path, "r") as store:
            rows = store["GEOSCIENCE/Objects/{s}/Vertices"][()]
            np.column_stack([rows["x"], rows["y"], rows["z"]])
            store["GEOSCIENCE/Objects/{s}/Cells"][()].astype(np.int64)
            store["GEOSCIENCE/Data/{d}/Data"][()]

    return write, read


def main() -> None:
    n = 200_000 if QUICK else 1_000_000
    surface = _surface(n)
    scene = geobrep.Scene(entities=[surface], crs=geobrep.CRS(epsg=32631))
    print(
        f"exchange formats: one surface of {surface.n_faces:,} triangles, "
        f"{surface.n_vertices:,} vertices; best of {RUNS}"
    )
    print(
        f"{'format':8} {'geobrep write':>14} {'direct write':>13} {'ratio':>6} "
        f"{'geobrep read':>13} {'direct read':>12} {'ratio':>6}"
    )
    with tempfile.TemporaryDirectory() as tmp, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        folder = Path(tmp)
        for name, extension, direct in (
            ("resqml", ".epc", _resqpy_direct),
            ("omf", ".omf", _omf_direct),
            ("geoh5", ".geoh5", _h5py_direct),
        ):
            path = folder / f"ours{extension}"
            direct_write, direct_read = direct(surface, folder)
            direct_write()  # imports, caches
            geobrep.write(scene, path)
            ours_write = _best(lambda target=path: geobrep.write(scene, target))
            ours_read = _best(lambda target=path: geobrep.read(target))
            lib_write = _best(direct_write)
            lib_read = _best(direct_read)
            back = geobrep.read(path).surfaces[0]
            assert back.vertices.tobytes() == surface.vertices.tobytes(), name
            print(
                f"{name:8} {ours_write:13.2f}s {lib_write:12.2f}s {ours_write / lib_write:6.2f} "
                f"{ours_read:12.2f}s {lib_read:11.2f}s {ours_read / lib_read:6.2f}"
            )


if __name__ == "__main__":
    main()
