"""OMF v1 through the omf package: what geobrep writes omf reads, and the other way round."""

from __future__ import annotations

import zlib
from pathlib import Path

import numpy as np
import pytest
from formats_support import rich_scene

import geobrep
from geobrep.batch.conversion import convert
from geobrep.errors import FormatError
from geobrep.model.scene import Scene
from geobrep.ops.io import read, write

omf = pytest.importorskip("omf")


def _scene() -> Scene:
    scene = rich_scene()
    kept = [e for e in scene.entities if e.type in ("Surface", "PointSet", "PolyLine")]
    coloured = [kept[0].replace(metadata={"color": [1.0, 0.0, 0.2]}), *kept[1:]]
    return Scene(entities=coloured, name="rich")


def test_roundtrip_keeps_geometry_names_data_and_colours(tmp_path: Path) -> None:
    scene = _scene()
    back = read(write(scene, tmp_path / "m.omf"))
    assert [e.name for e in back.entities] == [e.name for e in scene.entities]
    for got, want in zip(back.entities, scene.entities, strict=True):
        assert got.type == want.type
        assert got.vertices.tobytes() == want.vertices.tobytes()  # float64, bit for bit
        for field in ("point_data", "cell_data"):
            assert set(getattr(got, field)) == set(getattr(want, field)), (want.label, field)
            for name, prop in getattr(want, field).items():
                assert np.array_equal(getattr(got, field)[name].values, prop.values)
    for got, want in zip(back.surfaces, scene.surfaces, strict=True):
        assert np.array_equal(got.faces, want.faces)
    (line,) = back.polylines
    want_line = scene["fault trace"]
    assert np.array_equal(line.segments, want_line.segments)
    assert line.closed.tolist() == want_line.closed.tolist()
    assert back.entities[0].metadata["color"] == [1.0, 0.0, 0.2]


def test_omf_reads_what_geobrep_wrote(tmp_path: Path) -> None:
    scene = _scene()
    project = omf.OMFReader(str(write(scene, tmp_path / "m.omf"))).get_project()
    elements = {e.name: e for e in project.elements}
    h1 = elements["H1"]
    assert type(h1).__name__ == "SurfaceElement"
    assert np.array_equal(h1.geometry.vertices, scene["H1"].vertices)
    assert np.array_equal(h1.geometry.triangles, scene["H1"].faces)
    data = {d.name: d for d in h1.data}
    assert data["depth"].location == "vertices"
    assert np.array_equal(data["depth"].array, scene["H1"].point_data["depth"].values)
    assert type(data["gradient"]).__name__ == "Vector3Data"
    assert data["face_index"].location == "faces"
    assert tuple(h1.color) == (255, 0, 51)
    trace = elements["fault trace"]
    assert np.array_equal(trace.geometry.segments, scene["fault trace"].segments)
    assert np.array_equal(trace.data[0].array, scene["fault trace"].cell_data["throw"].values)
    assert np.array_equal(elements["well tops"].geometry.vertices, scene["well tops"].vertices)


def _foreign_project(path: Path) -> None:
    vertices = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    surface = omf.SurfaceElement(
        name="s",
        geometry=omf.SurfaceGeometry(
            vertices=vertices, triangles=np.array([[0, 1, 2]]), origin=[1.0, 2, 3]
        ),
        data=[omf.ScalarData(name="t", array=np.array([7.5]), location="faces")],
        color=[10, 20, 30],
    )
    volume = omf.VolumeElement(
        name="block model",
        geometry=omf.VolumeGridGeometry(
            tensor_u=np.array([1.0, 2.0]),
            tensor_v=np.array([3.0]),
            tensor_w=np.array([1.0, 1.0, 4.0]),
            origin=[10.0, 20.0, 30.0],
        ),
        data=[omf.ScalarData(name="grade", array=np.arange(6.0), location="cells")],
    )
    project = omf.Project(name="foreign", origin=[1000.0, 0.0, 0.0], elements=[surface, volume])
    project.validate()
    omf.OMFWriter(project, str(path))


def test_foreign_project_reads_in_world_coordinates_and_volumes_come_back(tmp_path: Path) -> None:
    _foreign_project(tmp_path / "f.omf")
    scene = read(tmp_path / "f.omf")
    surface = scene["s"]
    assert np.array_equal(surface.vertices, [[1001.0, 2, 3], [1002, 2, 3], [1001, 3, 3]])
    assert surface.cell_data["t"].values.tolist() == [7.5]
    assert surface.metadata["color"] == [round(c / 255, 6) for c in (10, 20, 30)]
    grid = scene["block model"]
    assert isinstance(grid, geobrep.PointSet)
    # cell centres, u fastest: u centres 0.5, 2; v 1.5; w 0.5, 1.5, 4
    expected = np.array([[1010.0 + u, 21.5, 30.0 + w] for w in (0.5, 1.5, 4.0) for u in (0.5, 2.0)])
    assert np.array_equal(grid.vertices, expected)
    assert grid.point_data["grade"].values.tolist() == list(range(6))
    # the grid writes back as the same volume
    again = omf.OMFReader(str(write(scene, tmp_path / "again.omf"))).get_project()
    volume = next(e for e in again.elements if e.name == "block model")
    assert type(volume).__name__ == "VolumeElement"
    assert np.array_equal(volume.geometry.tensor_w, [1.0, 1.0, 4.0])
    assert np.array_equal(volume.geometry.origin, [1010.0, 20.0, 30.0])
    assert np.array_equal(volume.data[0].array, np.arange(6.0))


def test_conversion_reports_what_omf_cannot_hold(tmp_path: Path) -> None:
    source = write(geobrep.datasets.faulted_layer_cake(), tmp_path / "cake.geobrep")
    report = convert(source, tmp_path / "cake.omf", verify=True).reports[0]
    assert report.status == "converted"
    lost = " | ".join(report.lost)
    for expected in ("7 Block entities dropped", "topology dropped", "CRS EPSG:32631 dropped"):
        assert expected in lost
    assert "ids of 9 entities dropped" in lost
    assert "kinds of 9 entities dropped" in lost
    assert "patch labels of 9 surfaces dropped" in lost


def test_damaged_files_are_format_errors(tmp_path: Path) -> None:
    path = write(_scene(), tmp_path / "m.omf")
    data = bytearray(path.read_bytes())
    (tmp_path / "short.omf").write_bytes(bytes(data[:40]))
    with pytest.raises(FormatError, match="OMF v1"):
        read(tmp_path / "short.omf")
    (tmp_path / "cut.omf").write_bytes(bytes(data[: len(data) - 30]))
    with pytest.raises(FormatError, match="JSON"):
        read(tmp_path / "cut.omf")


def test_an_array_inflating_past_the_budget_is_refused(tmp_path: Path) -> None:
    import json
    import struct

    bomb = zlib.compress(bytes(300 * 2**20))
    header = b"\x84\x83\x82\x81" + b"OMF-v0.9.0".ljust(32, b"\x00") + bytes(16)
    start = len(header) + 8
    document = {
        "u": {
            "__class__": "Vector3Array",
            "array": {"start": start, "length": len(bomb), "dtype": "<f8"},
        }
    }
    body = header + struct.pack("<Q", start + len(bomb)) + bomb + json.dumps(document).encode()
    (tmp_path / "bomb.omf").write_bytes(body)
    with pytest.raises(FormatError, match="inflates"):
        read(tmp_path / "bomb.omf")
