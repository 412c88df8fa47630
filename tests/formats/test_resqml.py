"""RESQML 2.0.1 through resqpy: exact round trips, and what resqpy itself reads from our files."""

from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np
import pytest
from formats_support import rich_scene

import geobrep
from geobrep.errors import FormatError, OptionsError
from geobrep.model.crs import CRS
from geobrep.model.entities import Surface
from geobrep.model.scene import Scene
from geobrep.ops.io import read, write

rq = pytest.importorskip("resqpy.model")
rqs = pytest.importorskip("resqpy.surface")


def _resqml_scene() -> Scene:
    """The rich scene without what RESQML does not hold (the tetrahedra)."""
    scene = rich_scene()
    return scene.replace(entities=[e for e in scene.entities if e.type != "TetMesh"])


def test_roundtrip_is_exact_and_writes_the_pair(tmp_path: Path) -> None:
    scene = _resqml_scene()
    path = write(scene, tmp_path / "model.epc")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["model.epc", "model.h5"]
    back = read(path)
    assert back == scene  # entities, float64 vertices, properties, ids, topology, CRS, groups
    for got, want in zip(back.surfaces, scene.surfaces, strict=True):
        assert got.vertices.tobytes() == want.vertices.tobytes()
        assert got.point_data["depth"].unit == "m"


def test_resqpy_reads_the_same_objects(tmp_path: Path) -> None:
    scene = _resqml_scene()
    path = write(scene, tmp_path / "model.epc")
    model = rq.Model(str(path))
    surfaces = {
        model.title(uuid=u): rqs.Surface(model, uuid=u)
        for u in model.uuids(obj_type="TriangulatedSetRepresentation")
    }
    assert set(surfaces) == {s.name for s in scene.surfaces}
    for surface in scene.surfaces:
        triangles, points = surfaces[surface.name].triangles_and_points()
        assert np.array_equal(points, surface.vertices)
        assert np.array_equal(triangles, surface.faces)
    kinds = {
        "HorizonInterpretation": {"H1", "H2"},
        "FaultInterpretation": {"fault"},
        "BoundaryFeatureInterpretation": {"top", "bottom", "west", "east", "south", "north"},
    }
    for obj_type, names in kinds.items():
        assert {model.title(uuid=u) for u in model.uuids(obj_type=obj_type)} == names
    assert {model.title(uuid=u) for u in model.uuids(obj_type="GeobodyInterpretation")} == {
        b.name for b in scene.of_type(geobrep.Block)
    }
    point_set = rqs.PointSet(model, uuid=model.uuid(obj_type="PointSetRepresentation"))
    assert np.array_equal(point_set.full_array_ref(), scene["well tops"].vertices)
    import resqpy.crs as rqc
    import resqpy.property as rqp

    crs = rqc.Crs(model, uuid=model.uuid(obj_type="LocalDepth3dCrs"))
    assert (crs.epsg_code, crs.xy_units, crs.z_inc_down) == ("32631", "m", False)
    h1 = surfaces["H1"]
    collection = rqp.PropertyCollection(support=h1)
    depth = collection.singleton(citation_title="depth")
    assert collection.uom_for_part(depth) == "m"
    assert np.array_equal(collection.cached_part_array_ref(depth), -scene["H1"].vertices[:, 2])


def test_depth_crs_and_offset_are_written_and_undone_exactly(tmp_path: Path) -> None:
    scene = _resqml_scene()
    crs = CRS(epsg=32631, z_positive="down")
    scene = scene.replace(crs=crs)
    offset = (450000.0, 6700000.0, 0.0)
    path = write(scene, tmp_path / "deep.epc", offset=offset)
    model = rq.Model(str(path))
    uuid = next(
        u
        for u in model.uuids(obj_type="TriangulatedSetRepresentation")
        if model.title(uuid=u) == "H1"
    )
    _, local = rqs.Surface(model, uuid=uuid).triangles_and_points()
    expected = scene["H1"].vertices * [1, 1, -1] - offset
    assert np.array_equal(local, expected)  # depth, relative to the local origin
    back = read(path)
    assert back == scene
    assert back.crs is not None
    assert back.crs.z_positive == "down"


def test_an_offset_that_would_change_coordinates_is_refused(tmp_path: Path) -> None:
    scene = Scene(entities=[geobrep.PointSet(vertices=[[0.1, 0.2, 0.3]], name="p")])
    with pytest.raises(OptionsError, match="offset"):
        write(scene, tmp_path / "p.epc", offset=(1e17, 0.0, 0.0))
    assert list(tmp_path.iterdir()) == []  # neither file of the pair


def test_foreign_model_reads_from_its_resqml_content(tmp_path: Path) -> None:
    """A model resqpy writes (two patches, local origin, depth): world coordinates, z up."""
    import resqpy.crs as rqc
    import resqpy.organize as rqo
    import resqpy.property as rqp

    model = rq.new_model(str(tmp_path / "foreign.epc"))
    crs = rqc.Crs(model, x_offset=1000.0, y_offset=2000.0, z_offset=100.0, z_inc_down=True)
    crs.create_xml()
    feature = rqo.TectonicBoundaryFeature(model, kind="fault", feature_name="F1")
    feature.create_xml()
    interpretation = rqo.FaultInterpretation(model, title="F1", tectonic_boundary_feature=feature)
    interpretation.create_xml()
    a = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    b = np.array([[0.0, 0, 5], [1, 0, 5], [0, 1, 6]])
    triangles = np.array([[0, 1, 2]])
    surface = rqs.Surface(model, crs_uuid=crs.uuid, title="F1")
    surface.set_multi_patch_from_triangles_and_points([(triangles, a), (triangles, b)])
    surface.set_represented_interpretation_root(interpretation.root)
    surface.write_hdf5()
    surface.create_xml()
    collection = rqp.PropertyCollection()
    collection.set_support(support=surface)
    collection.add_cached_array_to_imported_list(
        np.array([1.5, 2.5]),
        "test",
        "throw",
        uom="ft",
        property_kind="length",
        indexable_element="faces",
    )
    collection.write_hdf5_for_imported_list()
    collection.create_xml_for_imported_list_and_add_parts_to_model()
    model.store_epc()

    back = read(tmp_path / "foreign.epc")
    (fault,) = back.surfaces
    assert (fault.name, fault.kind) == ("F1", "fault")
    expected = np.concatenate([a, b]) + np.array([1000.0, 2000.0, 100.0])
    expected[:, 2] *= -1  # depth below the origin -> z up
    assert np.array_equal(fault.vertices, expected)
    assert fault.patch_labels is not None
    assert fault.patch_labels.tolist() == [0, 1]
    assert fault.cell_data["throw"].unit == "ft"
    assert back.crs is not None
    assert back.crs.z_positive == "down"


def test_clipped_model_roundtrips(tmp_path: Path) -> None:
    scene = geobrep.datasets.faulted_layer_cake()
    clipped = geobrep.clip(scene, geobrep.Plane.x(450500.0))
    assert isinstance(clipped, Scene)
    assert read(write(clipped, tmp_path / "clipped.epc")) == clipped


def test_quads_are_refused_with_the_surface_named(tmp_path: Path) -> None:
    quad = Surface(vertices=np.eye(4, 3), faces=[[0, 1, 2, 3]], name="quad")
    with pytest.raises(FormatError, match=r"quad.*triangulate"):
        write(Scene(entities=[quad]), tmp_path / "q.epc")
    assert list(tmp_path.iterdir()) == []


def test_damaged_files_are_format_errors(tmp_path: Path) -> None:
    path = write(_resqml_scene(), tmp_path / "m.epc")
    (tmp_path / "m.h5").unlink()
    with pytest.raises(FormatError) as caught:
        read(path)
    assert caught.value.path == path
    (tmp_path / "bad.epc").write_bytes(b"PK\x03\x04 not a zip")
    with pytest.raises(FormatError, match="EPC"):
        read(tmp_path / "bad.epc")


def test_declared_sizes_beyond_the_budget_are_refused(tmp_path: Path) -> None:
    path = tmp_path / "bomb.epc"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("[Content_Types].xml", b"<" + b" " * (200 * 2**20))
    with pytest.raises(FormatError, match="declares"):
        read(path)


def _two_patch_model(path: Path) -> None:
    """Two patches (the second's triangles index its own points), a float node property and
    an integer face property, written by resqpy."""
    import resqpy.crs as rqc
    import resqpy.property as rqp

    model = rq.new_model(str(path))
    crs = rqc.Crs(model, z_inc_down=False)
    crs.create_xml()
    rng = np.random.default_rng(5)
    a, b = rng.uniform(0, 100, (6, 3)), rng.uniform(0, 100, (5, 3))
    ta = np.array([[0, 1, 2], [2, 3, 4], [3, 4, 5]])
    tb = np.array([[0, 1, 2], [1, 3, 4]])
    surface = rqs.Surface(model, crs_uuid=crs.uuid, title="S")
    surface.set_multi_patch_from_triangles_and_points([(ta, a), (tb, b)])
    surface.write_hdf5()
    surface.create_xml()
    collection = rqp.PropertyCollection()
    collection.set_support(support=surface)
    collection.add_cached_array_to_imported_list(
        rng.uniform(size=11), "test", "t", property_kind="continuous", indexable_element="nodes"
    )
    collection.add_cached_array_to_imported_list(
        np.arange(5) * 3,
        "test",
        "n",
        property_kind="discrete",
        discrete=True,
        indexable_element="faces",
    )
    collection.write_hdf5_for_imported_list()
    collection.create_xml_for_imported_list_and_add_parts_to_model()
    model.store_epc()


def _resqpy_view(path: Path) -> tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]]:
    import resqpy.property as rqp

    model = rq.Model(str(path))
    rep = rqs.Surface(model, uuid=model.uuid(obj_type="TriangulatedSetRepresentation"))
    triangles, points = rep.triangles_and_points()
    collection = rqp.PropertyCollection(support=rep)
    values = {
        collection.citation_title_for_part(p): np.asarray(collection.cached_part_array_ref(p))
        for p in collection.parts()
    }
    return np.asarray(triangles, dtype=np.int64), np.asarray(points, dtype=np.float64), values


@pytest.mark.parametrize("through", ["hdf5", "resqpy"])
@pytest.mark.parametrize("points_dtype", ["<f8", "<f4"])
def test_arrays_read_straight_equal_resqpys(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, through: str, points_dtype: str
) -> None:
    """geobrep reads a surface's arrays straight from the HDF5 file (``through="hdf5"``) or,
    for layouts it does not read so, through resqpy: the same arrays and dtypes either way,
    several patches and float32 points included."""
    import h5py

    from geobrep.adapters.resqml import _reader

    path = tmp_path / "two.epc"
    _two_patch_model(path)
    if points_dtype == "<f4":
        with h5py.File(path.with_suffix(".h5"), "r+") as store:
            names: list[str] = []
            store.visit(names.append)
            for name in [n for n in names if n.rsplit("/", 1)[-1].startswith("points_patch")]:
                values = store[name][()].astype(np.float32)
                del store[name]
                store.create_dataset(name, data=values)
    if through == "resqpy":
        monkeypatch.setattr(_reader, "_read_whole", lambda *args: None)
    triangles, points, values = _resqpy_view(path)
    (surface,) = read(path).surfaces
    assert surface.faces.dtype == np.int64
    assert surface.vertices.dtype == np.float64
    assert np.array_equal(surface.faces, triangles)
    assert surface.vertices.tobytes() == points.tobytes()
    assert surface.patch_labels is not None
    assert surface.patch_labels.tolist() == [0, 0, 0, 1, 1]
    for name, want in values.items():
        data = surface.point_data if want.shape[0] == 11 else surface.cell_data
        got = data[name].values
        assert got.dtype == want.dtype, name
        assert got.tobytes() == want.tobytes(), name
