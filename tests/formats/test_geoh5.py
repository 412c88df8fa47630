"""geoh5 on h5py (geoh5py itself is checked by ``make geoh5-check``), and the round trips of the
formats that keep geometry, names and properties but not ids or kinds (geoh5, OMF)."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from formats_support import rich_scene

import geobrep
from geobrep.adapters._grid_cells import GRID_KEY, Grid
from geobrep.batch.conversion import convert
from geobrep.errors import FormatError
from geobrep.host.capabilities import restrict_scene
from geobrep.model.scene import Scene
from geobrep.ops.io import read, write
from geobrep.plugins import registries

h5py = pytest.importorskip("h5py")

GOCAD = Path(__file__).parent.parent / "data" / "gocad"
SURFACE_TYPE = "{F26FEBA3-ADED-494B-B9E9-B2BBCBE298E1}"


def _scene() -> Scene:
    scene = rich_scene()
    return Scene(
        entities=[e for e in scene.entities if e.type in ("Surface", "PointSet", "PolyLine")]
    )


def assert_geometry_names_and_data_kept(original: Scene, back: Scene, name: str) -> None:
    """Entities in order with their names, float64 vertices bit for bit, cells and the
    values of every scalar property (vectors are dropped by geoh5: reported)."""
    expected = restrict_scene(original, registries().formats.get(name).capabilities)
    assert [(e.type, e.name) for e in back.entities] == [
        (e.type, e.name) for e in expected.entities
    ]
    for got, want in zip(back.entities, expected.entities, strict=True):
        assert got.vertices.tobytes() == want.vertices.tobytes(), want.label
        cells = (
            "faces" if want.type == "Surface" else "segments" if want.type == "PolyLine" else None
        )
        if cells:
            assert np.array_equal(getattr(got, cells), getattr(want, cells)), want.label
        for field in ("point_data", "cell_data"):
            for prop_name, prop in getattr(want, field).items():
                if prop.values.ndim == 1 or name == "omf":
                    assert np.array_equal(getattr(got, field)[prop_name].values, prop.values)


def test_roundtrip_keeps_geometry_names_and_data(tmp_path: Path) -> None:
    scene = _scene()
    back = read(write(scene, tmp_path / "m.geoh5"))
    assert_geometry_names_and_data_kept(scene, back, "geoh5")
    assert back.surfaces[0].cell_data["face_index"].values.dtype == np.int32


def test_the_file_follows_the_geoh5_schema(tmp_path: Path) -> None:
    scene = _scene()
    with h5py.File(write(scene, tmp_path / "m.geoh5"), "r") as store:
        root = store["GEOSCIENCE"]
        assert root.attrs["Version"] == 2.0
        assert root.attrs["Distance unit"] == "meter"
        assert {"Data", "Groups", "Objects", "Types", "Root"} <= set(root)
        workspace = root["Root"]
        assert set(workspace["Objects"]) == set(root["Objects"])  # the objects hang from the root
        h1 = next(o for o in root["Objects"].values() if o.attrs["Name"] == "H1")
        assert h1["Type"].attrs["ID"] == SURFACE_TYPE
        assert h1["Type"] == root["Types/Object types"][SURFACE_TYPE]  # a hard link, one group
        assert h1["Vertices"].dtype.names == ("x", "y", "z")
        assert h1["Vertices"].dtype["x"] == np.float64
        assert h1["Cells"].shape == (scene["H1"].n_faces, 3)
        data = {d.attrs["Name"]: d for d in h1["Data"].values()}
        assert data["depth"].attrs["Association"] == "Vertex"
        assert data["face_index"].attrs["Association"] == "Cell"
        assert data["depth"]["Type"].attrs["Primitive type"] == "Float"
        assert data["depth"] == root["Data"][data["depth"].attrs["ID"]]
        assert "gradient" not in data  # a vector: reported as lost


def test_block_models_come_back_as_the_same_grid(tmp_path: Path) -> None:
    grid = Grid(
        origin=(100.0, 200.0, -50.0),
        sizes=(np.full(3, 10.0), np.array([5.0, 20.0]), np.full(2, 2.5)),
    )
    cells = grid.point_set("model", point_data={"grade": np.arange(12.0)})
    path = write(Scene(entities=[cells]), tmp_path / "g.geoh5")
    with h5py.File(path, "r") as store:
        (obj,) = store["GEOSCIENCE/Objects"].values()
        assert obj["Type"].attrs["Name"] == "Block model"
        assert obj["V cell delimiters"][()].tolist() == [0.0, 5.0, 25.0]
        (data,) = obj["Data"].values()
        # geoh5 orders cells v slowest, z fastest: cell (u=0, v=0, w=1) is second
        assert data["Data"][()][:2].tolist() == [0.0, 6.0]
    (back,) = read(path).entities
    assert back.vertices.tobytes() == cells.vertices.tobytes()
    assert back.point_data["grade"].values.tolist() == list(range(12))
    assert Grid.of(back) == grid
    assert back.metadata[GRID_KEY] == cells.metadata[GRID_KEY]
    # and the centres are where the cell sizes put them
    assert back.vertices[1].tolist() == [115.0, 202.5, -48.75]


def test_conversion_reports_what_geoh5_cannot_hold(tmp_path: Path) -> None:
    source = write(rich_scene(), tmp_path / "rich.geobrep")
    report = convert(source, tmp_path / "rich.geoh5", verify=True).reports[0]
    assert report.status == "converted"
    lost = " | ".join(report.lost)
    for expected in (
        "7 Block entities dropped",
        "1 TetMesh entities dropped",
        "topology dropped",
        "CRS EPSG:32631 dropped",
        "patch labels of 9 surfaces dropped",
        "'gradient': vector property dropped",
        "'depth': unit, no-data value and metadata dropped",
    ):
        assert expected in lost, expected


@pytest.mark.parametrize("name", ["geoh5", "omf"])
@pytest.mark.parametrize(
    "file_name", ["modelA1.ml", "split_cube.ml", "ts-2props.ts", "normal_lines.pl", "points.vs"]
)
def test_roundtrip_gocad_files(name: str, file_name: str, tmp_path: Path) -> None:
    pytest.importorskip("omf") if name == "omf" else None
    source = tmp_path / file_name
    shutil.copy(GOCAD / file_name, source)
    scene = read(source)
    back = read(write(scene, tmp_path / f"out.{name}"))
    assert_geometry_names_and_data_kept(scene, back, name)


@pytest.mark.parametrize("name", ["geoh5", "omf"])
def test_roundtrip_sample_and_clipped_models(name: str, tmp_path: Path) -> None:
    pytest.importorskip("omf") if name == "omf" else None
    scene = geobrep.datasets.faulted_layer_cake()
    clipped = geobrep.clip(scene, geobrep.Plane.x(450500.0))
    assert isinstance(clipped, Scene)
    for model in (scene, clipped):
        back = read(write(model, tmp_path / f"m.{name}"))
        assert_geometry_names_and_data_kept(model, back, name)


def test_damaged_files_are_format_errors(tmp_path: Path) -> None:
    (tmp_path / "junk.geoh5").write_bytes(b"\x89HDF\r\n\x1a\n" + bytes(100))
    with pytest.raises(FormatError, match="geoh5"):
        read(tmp_path / "junk.geoh5")
    with h5py.File(tmp_path / "other.geoh5", "w") as store:
        store.create_dataset("x", data=np.arange(3))
    with pytest.raises(FormatError, match="GEOSCIENCE"):
        read(tmp_path / "other.geoh5")
    path = write(_scene(), tmp_path / "m.geoh5")
    with h5py.File(path, "r+") as store:
        h1 = next(o for o in store["GEOSCIENCE/Objects"].values() if o.attrs["Name"] == "H1")
        cells = h1["Cells"][()]
        cells[0, 0] = 10**6
        h1["Cells"][...] = cells
    with pytest.raises(FormatError) as caught:
        read(path)
    assert caught.value.path == path


@pytest.mark.parametrize("name", ["geoh5", "omf"])
def test_regular_grids_come_back_exactly(name: str, tmp_path: Path) -> None:
    pytest.importorskip("omf") if name == "omf" else None
    grid = geobrep.RegularGrid(
        origin=[450000.0, 6700000.0, -900.0],
        u=[25.0, 0, 0],
        v=[0, 50.0, 0],
        w=[0, 0, 12.5],
        counts=(4, 3, 2),
        cell_data={"grade": np.linspace(0.0, 1.0, 24)},
        name="grade model",
    )
    (back,) = read(write(Scene(entities=[grid]), tmp_path / f"g.{name}")).entities
    assert isinstance(back, geobrep.RegularGrid)
    for field in ("origin", "u", "v", "w"):
        assert getattr(back, field).tobytes() == getattr(grid, field).tobytes(), field
    assert back.counts == grid.counts
    assert back.cell_data["grade"].values.tobytes() == grid.cell_data["grade"].values.tobytes()


def test_a_block_model_rotated_in_plan_keeps_its_rotation(tmp_path: Path) -> None:
    angle = np.radians(30.0)
    c, s = np.cos(angle), np.sin(angle)
    grid = geobrep.RegularGrid(
        origin=[0.0, 0, 0],
        u=[10 * c, 10 * s, 0],
        v=[-5 * s, 5 * c, 0],
        w=[0, 0, 2.0],
        counts=(2, 2, 1),
        name="rotated",
    )
    path = write(Scene(entities=[grid]), tmp_path / "r.geoh5")
    with h5py.File(path, "r") as store:
        (obj,) = store["GEOSCIENCE/Objects"].values()
        assert obj.attrs["Rotation"] == pytest.approx(30.0)
    (back,) = read(path).entities
    assert isinstance(back, geobrep.RegularGrid)
    np.testing.assert_allclose(back.axes, grid.axes, rtol=0, atol=1e-12)


def test_datasets_declaring_more_than_the_budget_are_refused_before_reading(
    tmp_path: Path,
) -> None:
    path = write(_scene(), tmp_path / "m.geoh5")
    with h5py.File(path, "r+") as store:
        obj = next(iter(store["GEOSCIENCE/Objects"].values()))
        data = next(iter(obj["Data"].values()))
        del data["Data"]  # a value array of 10^10 floats, none of them stored: a tiny file
        data.create_dataset("Data", shape=(10**10,), dtype="<f8", chunks=(4096,))
    with pytest.raises(FormatError, match="its objects' datasets declares"):
        read(path)
