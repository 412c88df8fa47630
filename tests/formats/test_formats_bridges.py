"""pyvista and open3d bridges, meshio's failure modes, foreign VTK and PLY files."""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from formats_support import rich_scene

from geobrep.adapters.cell_layout import layout_to_scene, scene_to_layout
from geobrep.adapters.meshio import _bridge as bridge
from geobrep.errors import FormatError, MissingDependencyError
from geobrep.host.capabilities import restrict_scene
from geobrep.model.entities import LinearOctree, PointSet, PolyLine, Surface
from geobrep.model.scene import Scene
from geobrep.ops.io import read, write
from geobrep.plugins import registries


@pytest.fixture(scope="module")
def scene() -> Scene:
    return rich_scene()


def test_cell_layout_roundtrip_is_exact(scene: Scene) -> None:
    caps = registries().formats.get("vtu").capabilities
    expected = restrict_scene(scene, caps)
    assert layout_to_scene(scene_to_layout(scene)).entities == expected.entities


def test_pyvista_scene_roundtrip(scene: Scene) -> None:
    pv = pytest.importorskip("pyvista")
    from geobrep.adapters.pyvista import from_pyvista, to_pyvista

    multiblock = to_pyvista(scene)
    assert isinstance(multiblock, pv.MultiBlock)
    assert multiblock.keys()[:2] == ["H1", "H2"]
    h1 = multiblock["H1"]
    assert h1.points.dtype == np.float64
    np.testing.assert_array_equal(h1.point_data["depth"], -scene["H1"].vertices[:, 2])
    assert isinstance(multiblock["grid"], pv.UnstructuredGrid)
    back = from_pyvista(multiblock)
    assert isinstance(back, Scene)
    assert (
        back.entities
        == restrict_scene(scene, registries().formats.get("vtu").capabilities).entities
    )
    assert back.crs == scene.crs


def test_pyvista_entity_and_foreign_datasets() -> None:
    pv = pytest.importorskip("pyvista")
    from geobrep.adapters.pyvista import from_pyvista, to_pyvista

    sphere = pv.Sphere(theta_resolution=12, phi_resolution=8)
    sphere.point_data["height"] = sphere.points[:, 2]
    surface = from_pyvista(sphere)
    assert isinstance(surface, Surface)
    assert surface.is_closed
    np.testing.assert_array_equal(surface.point_data["height"].values, sphere.points[:, 2])
    line = from_pyvista(pv.Spline(np.random.default_rng(1).random((6, 3)), 20))
    assert isinstance(line, PolyLine)
    assert line.n_parts == 1
    assert line.n_points == 20
    octree = LinearOctree(codes=[0, 8, 9], levels=[1, 2, 2], depth=2, origin=[0, 0, 0], size=4.0)
    grid = to_pyvista(octree)
    assert grid.n_cells == 3
    assert np.isclose(grid.volume, octree.volume)
    assert isinstance(to_pyvista(surface), pv.PolyData)


def test_missing_pyvista_names_the_extra(scene: Scene, monkeypatch: pytest.MonkeyPatch) -> None:
    from geobrep.adapters.pyvista import to_pyvista

    monkeypatch.setitem(sys.modules, "pyvista", None)
    with pytest.raises(MissingDependencyError, match=r"geobrep\[viz\]"):
        to_pyvista(scene)


def test_legacy_polydata_reads(tmp_path: Path, scene: Scene) -> None:
    pytest.importorskip("pyvista")
    from geobrep.adapters.pyvista import to_pyvista

    path = tmp_path / "h1.vtk"
    to_pyvista(scene["H1"]).save(path)  # what ParaView writes: DATASET POLYDATA
    assert b"POLYDATA" in path.read_bytes()[:200]
    [surface] = read(path).entities
    assert surface == scene["H1"]


def test_meshio_system_exit_and_noise_are_contained(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture[str]
) -> None:
    import meshio

    def rude_read(*args: object, **kwargs: object) -> None:
        print("meshio: Illegal file, giving up", file=sys.stderr)
        sys.exit(1)

    monkeypatch.setattr(meshio, "read", rude_read)
    path = tmp_path / "m.obj"
    path.write_text("v 0 0 0\n")
    with pytest.raises(FormatError, match=r"SystemExit.*Illegal file") as info:
        bridge.read_mesh(path, "obj")
    assert info.value.path == path
    assert "Illegal" not in capfd.readouterr().err


def test_corrupt_vtu_is_a_format_error(tmp_path: Path, scene: Scene) -> None:
    path = write(scene, tmp_path / "m.vtu")
    path.write_bytes(path.read_bytes()[:3000])
    with pytest.raises(FormatError) as info:
        read(path)
    assert info.value.path == path


def test_foreign_ply_keeps_every_property(tmp_path: Path) -> None:
    plyfile = pytest.importorskip("plyfile")
    vertex = np.array(
        [(450000.125, 6.7e6 + 0.5, 1.0, 10, 0.5), (450001.0, 6.7e6, 2.0, 20, 0.25),
         (450001.0, 6.7e6 + 1, 3.0, 30, 0.75), (450000.0, 6.7e6 + 1, 4.0, 40, 1.0),
         (450002.0, 6.7e6 + 2, 5.0, 50, 0.0)],
        dtype=[("x", "f8"), ("y", "f8"), ("z", "f8"), ("red", "u1"), ("confidence", "f4")],
    )  # fmt: skip
    face = np.empty(2, dtype=[("vertex_indices", "O"), ("quality", "i2")])
    face["vertex_indices"] = [np.array([0, 1, 2, 3]), np.array([1, 4, 2])]
    face["quality"] = [7, 9]
    for text in (True, False):
        path = tmp_path / f"foreign_{text}.ply"
        plyfile.PlyData(
            [plyfile.PlyElement.describe(vertex, "vertex"),
             plyfile.PlyElement.describe(face, "face")], text=text,
        ).write(str(path))  # fmt: skip
        [surface] = read(path).entities
        assert isinstance(surface, Surface)
        np.testing.assert_array_equal(surface.vertices[:, 0], vertex["x"])
        assert surface.point_data["red"].dtype == np.uint8
        assert surface.point_data["confidence"].dtype == np.float32
        # a quad and a triangle in one file: fan triangles, each keeping its face's values
        assert surface.faces.tolist() == [[0, 1, 2], [0, 2, 3], [1, 4, 2]]
        assert surface.cell_data["quality"].values.tolist() == [7, 7, 9]


def test_ply_vector_and_int64_properties_roundtrip(tmp_path: Path) -> None:
    points = PointSet(
        vertices=np.array([[450000.1, 6700000.2, -3.3], [1.0, 2.0, 3.0]]),
        point_data={"normal": np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]),
                    "big": np.array([2**40, 3], dtype=np.int64),
                    "x": np.array([5.0, 6.0]), "flag": np.array([True, False])},
        name="pts",
    )  # fmt: skip
    for binary in (True, False):
        back = read(write(points, tmp_path / f"p{binary}.ply", binary=binary)).entities[0]
        assert back == points.replace(id=0)


def test_open3d_bridge_keeps_float64() -> None:
    pytest.importorskip("open3d")
    from geobrep.adapters.open3d import Open3dLossWarning, from_open3d, open3d_losses, to_open3d

    vertices = np.array([[450000.123456789, 6700000.987654321, -5.0], [450001.0, 6.7e6, 0.0],
                         [450000.0, 6700001.0, 1.0]])  # fmt: skip
    surface = Surface(
        vertices=vertices, faces=[[0, 1, 2]], name="s",
        point_data={"normals": np.tile([0.0, 0.0, 1.0], (3, 1)), "z": vertices[:, 2]},
    )  # fmt: skip
    assert open3d_losses(surface) == ["point properties dropped: z", "name dropped"]
    with pytest.warns(Open3dLossWarning, match="z"):
        mesh = to_open3d(surface)
    back = from_open3d(mesh)
    assert isinstance(back, Surface)
    np.testing.assert_array_equal(back.vertices, vertices)
    np.testing.assert_array_equal(
        back.point_data["normals"].values, surface.point_data["normals"].values
    )
    cloud = PointSet(vertices=vertices, point_data={"colors": np.full((3, 3), 0.5)})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        again = from_open3d(to_open3d(cloud))
    assert again == cloud
    line = PolyLine.from_parts(vertices, [[0, 1, 2]], closed=[True])
    assert from_open3d(to_open3d(line)).segments.tolist() == line.segments.tolist()
    octree = LinearOctree(codes=[0, 8, 9], levels=[1, 2, 2], depth=2,
                          origin=[450000.0, 6.7e6, 0.0], size=4.0)  # fmt: skip
    with pytest.warns(Open3dLossWarning, match="expanded"):
        grid = to_open3d(octree)
    voxels = from_open3d(grid)
    assert isinstance(voxels, LinearOctree)
    assert voxels.volume == octree.volume
    np.testing.assert_array_equal(voxels.origin, octree.origin)


@pytest.mark.parametrize("binary", [False, True])
def test_legacy_vtk_reads_in_vtk_and_meshio(tmp_path: Path, scene: Scene, binary: bool) -> None:
    """geobrep's legacy header was vtktypeuint8 (VTK: "Unsupported data type") and its int32
    cell arrays vtktypeint32 (the same); ``unsigned_char`` meshio 5.3.5 does not read."""
    vtk = pytest.importorskip("vtkmodules.vtkIOLegacy")
    import meshio

    from geobrep.adapters.cell_layout import HEADER_ARRAY, decode_header

    labels = PointSet(
        vertices=np.eye(3),
        name="labels",
        point_data={
            "small": np.array([1, 200, 255], dtype=np.uint8),
            "short": np.array([-3, 0, 30000], dtype=np.int16),
            "flag": np.array([True, False, True]),
        },
    )
    kept = scene.replace(entities=[*scene.entities, labels])
    path = write(kept, tmp_path / "model.vtk", binary=binary)
    errors: list[str] = []
    reader = vtk.vtkUnstructuredGridReader()
    reader.AddObserver("ErrorEvent", lambda _obj, _event: errors.append("error"))
    reader.SetFileName(str(path))
    reader.ReadAllFieldsOn()
    reader.Update()
    grid = reader.GetOutput()
    assert errors == []
    from vtkmodules.util.numpy_support import vtk_to_numpy

    stored = vtk_to_numpy(grid.GetFieldData().GetArray(HEADER_ARRAY))
    header = scene_to_layout(restrict_scene(kept, registries().formats.get("vtk").capabilities))
    assert decode_header(stored) == header.header
    mesh = meshio.read(path)
    assert grid.GetNumberOfPoints() == len(mesh.points) == len(header.points)
    for name, values in header.cell_data.items():
        in_vtk = vtk_to_numpy(grid.GetCellData().GetArray(name))
        np.testing.assert_array_equal(in_vtk, values)
        np.testing.assert_array_equal(np.concatenate(mesh.cell_data[name]), values)
    for name, values in header.point_data.items():
        np.testing.assert_array_equal(vtk_to_numpy(grid.GetPointData().GetArray(name)), values)
        np.testing.assert_array_equal(mesh.point_data[name], values)
    (back,) = [e for e in read(path).entities if e.name == "labels"]
    for name in ("small", "short", "flag"):
        assert back.point_data[name].values.dtype == labels.point_data[name].values.dtype
        np.testing.assert_array_equal(back.point_data[name].values, labels.point_data[name].values)


def test_legacy_vtk_header_of_earlier_versions_still_reads(tmp_path: Path, scene: Scene) -> None:
    """Files geobrep wrote before stored the header as vtktypeuint8 bytes."""
    path = write(scene, tmp_path / "new.vtk", binary=True)
    data = path.read_bytes()
    head, rest = data.split(b" float\n", 1)
    count = int(head.rsplit(b" ", 1)[1])
    raw = np.frombuffer(rest[: 4 * count], dtype=">f4").astype(np.uint8).tobytes()
    old = tmp_path / "old.vtk"
    old.write_bytes(head + b" vtktypeuint8\n" + raw + rest[4 * count :])
    assert read(old).entities == read(path).entities
