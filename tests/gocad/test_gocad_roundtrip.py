"""read → write → read is lossless; geobrep scenes written as GOCAD come back intact."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from gocad_files import DATA, FILES, read_quietly, write_quietly

import geobrep
from geobrep import CRS, Block, PointSet, PolyLine, Property, Scene, Surface, TetMesh
from geobrep.adapters.gocad._parser import GocadWarning
from geobrep.host.capabilities import without_read_losses
from geobrep.model.base import arrays_identical


@pytest.mark.parametrize("name", FILES)
def test_read_write_read_is_identical(name: str, tmp_path: Path) -> None:
    # what the reader skipped (sgrid_tsurf.ts's SGrid) is not in the scene, so not in the file
    first = without_read_losses(read_quietly(DATA / name))
    out = write_quietly(first, tmp_path / name)
    second = read_quietly(out)
    assert second == first  # geometry bit for bit, ids, properties, CRS, topology, metadata
    for a, b in zip(first.entities, second.entities, strict=True):
        if hasattr(a, "vertices"):
            assert arrays_identical(a.vertices, b.vertices)
    # and the written file is stable: writing it again (under the same name, which its side
    # files' names come from) gives the same bytes
    (tmp_path / "again").mkdir()
    again = write_quietly(second, tmp_path / "again" / name)
    assert again.read_bytes() == out.read_bytes()
    for side in sorted(tmp_path.glob("*@@")):
        assert (tmp_path / "again" / side.name).read_bytes() == side.read_bytes()


def test_writer_output_conventions(tmp_path: Path) -> None:
    scene = read_quietly(DATA / "ts-2props.ts")
    text = write_quietly(scene, tmp_path / "out.ts").read_text()
    assert "\r" not in text
    assert "ZPOSITIVE Depth" in text
    assert "PVRTX 1 -745925.546875 -2618524.8125 -44070.2578125 -99999 -99999 CNXYZ" in text
    assert "TRGL 3 2 1" in text
    assert 'PROPERTIES " default property" def-prop' in text
    assert 'NAME " Pdgm_Epic Local"' in text
    assert text.rstrip().endswith("END")


def test_atoms_are_written_for_repeated_positions(tmp_path: Path) -> None:
    scene = read_quietly(DATA / "split_cube.ml")
    text = write_quietly(scene, tmp_path / "cube.ml").read_text()
    assert "ATOM 9 5" in text
    assert "ATOM 12 8" in text


def test_layer_cake_as_model3d(layer_cake: Scene, tmp_path: Path) -> None:
    # shared TFACE vertices: read back vertex for vertex (the default layout gives each TFACE
    # its own vertices: tests/gocad/test_model3d_tface_vertices.py)
    with pytest.warns(GocadWarning, match="EPSG"):
        path = geobrep.write(layer_cake, tmp_path / "cake.ml", tface_vertices="shared")
    back = geobrep.read(path)
    assert back.crs is not None
    assert back.crs.name == layer_cake.crs.name
    for a, b in zip(layer_cake.surfaces, back.surfaces, strict=True):
        assert a.name == b.name
        assert a.kind == b.kind
        assert arrays_identical(a.vertices, b.vertices)
        assert np.array_equal(a.faces, b.faces)
        assert np.array_equal(a.patch_labels, b.patch_labels)
    # blocks: same names and the same signed patches, patch ids renumbered as TFACEs 1..N
    number = {(p.surface, p.label): p.id for p in back.patches}
    original = {p.id: (p.surface, p.label) for p in layer_cake.patches}
    for a, b in zip(layer_cake.of_type(Block), back.of_type(Block), strict=True):
        assert a.kind == b.kind
        assert a.unit_name == b.unit_name
        assert b.name == ("Universe" if a.is_universe else a.name)  # GOCAD's name for it
        expected = [(number[original[s.patch]], s.side) for s in a.sides]
        assert [tuple(s) for s in b.sides] == expected
        if not a.is_universe:
            assert back.block_mesh(b).volume == pytest.approx(layer_cake.block_mesh(a).volume)
    assert len(back.topology.arcs) == len(layer_cake.topology.arcs)
    assert len(back.topology.corners) == len(layer_cake.topology.corners)
    assert {g.name for g in back.groups if g.kind == "layer"} == {"unit 1", "unit 2", "unit 3"}


def test_depth_scene_writes_depth_and_reads_back_z_up(tmp_path: Path) -> None:
    surface = Surface(
        vertices=[
            [450000.1, 6700000.2, -1200.5],
            [450010.0, 6700000.2, -1201.0],
            [450000.1, 6700010.3, -1199.25],
        ],
        faces=[[0, 1, 2]],
        name="top reservoir",
        kind="horizon",
        point_data={"porosity": Property(values=[0.1, 0.2, 0.3], unit="1", no_data_value=-999.0)},
        cell_data={"zone": [2.0]},
        metadata={"color": [1.0, 0.5, 0.0, 1.0]},
    )
    scene = Scene(entities=[surface], crs=CRS(name="local", z_positive="down"))
    path = write_quietly(scene, tmp_path / "top.ts")
    text = path.read_text()
    assert "VRTX" in text
    assert " 1200.5 " in text
    assert "ZPOSITIVE Depth" in text
    assert "name:top reservoir" in text
    assert "*solid*color:1.0 0.5 0.0 1.0" in text
    back = read_quietly(path).surfaces[0]
    assert arrays_identical(back.vertices, surface.vertices)
    assert back.face_normals[0].tolist() == surface.face_normals[0].tolist()  # winding kept
    assert back.point_data["porosity"].values.tolist() == [0.1, 0.2, 0.3]
    assert back.point_data["porosity"].no_data_value == -999.0
    assert back.cell_data["zone"].values.tolist() == [2.0]
    assert back.name == "top reservoir"
    assert back.kind == "horizon"
    assert back.metadata["color"] == [1.0, 0.5, 0.0, 1.0]


def test_lines_points_and_tetrahedra(tmp_path: Path) -> None:
    line = PolyLine.from_parts(
        [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [5, 5, 5], [6, 6, 6]],
        [[0, 1, 2, 3], [4, 5], [2, 5]],
        closed=[True, False, False],
        name="traces",
        cell_data={"length_class": np.arange(6, dtype=np.float64)},
    )
    points = PointSet(
        vertices=np.random.default_rng(1).normal(size=(5, 3)) * 1e5,
        point_data={"dip": Property(values=np.random.default_rng(2).normal(size=(5, 3)))},
        name="markers",
    )
    tets = TetMesh(
        vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]],
        cells=[[0, 1, 2, 3], [1, 2, 3, 4]],
        region_labels=[0, 1],
        region_names=("lower", "upper"),
        cell_data={"perm": [1.5, 2.5]},
        name="solid",
    )
    for entity, suffix in ((line, ".pl"), (points, ".vs"), (tets, ".so")):
        back = read_quietly(write_quietly(Scene(entities=[entity]), tmp_path / f"x{suffix}"))
        (again,) = back.entities
        assert type(again) is type(entity)
        assert arrays_identical(again.vertices, entity.vertices)  # type: ignore[attr-defined]
        for name, prop in entity.point_data.items():
            assert np.array_equal(again.point_data[name].values, prop.values)
        for name, prop in entity.cell_data.items():
            assert np.array_equal(again.cell_data[name].values, prop.values)
    back_line = read_quietly(tmp_path / "x.pl").polylines[0]
    assert back_line.closed.tolist() == [True, False, False]
    assert np.array_equal(back_line.indices, line.indices)
    back_tets = read_quietly(tmp_path / "x.so").tet_meshes[0]
    assert back_tets.region_names == ("lower", "upper")
    assert np.array_equal(back_tets.cells, tets.cells)


def test_what_gocad_cannot_hold_is_reported(tmp_path: Path) -> None:
    scene = Scene(
        entities=[
            Surface(
                vertices=[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]],
                faces=[[0, 1, 2, 3]],
                name="quad",
            ),
            PointSet(
                vertices=[[0, 0, 0]], name="p", point_data={"n": np.array([3], dtype=np.int32)}
            ),
        ],
        crs=CRS(epsg=32631),
    )
    with pytest.warns(GocadWarning) as caught:
        geobrep.write(scene, tmp_path / "out.ts")
    messages = " | ".join(str(w.message) for w in caught)
    assert "quads are written as two triangles" in messages
    assert "not written: PointSet 'p'" in messages
    assert "EPSG:32631" in messages
    with pytest.warns(GocadWarning, match="integer property 'n' is read back as float64"):
        geobrep.write(scene, tmp_path / "out.vs")


def test_nothing_to_write_is_an_error_and_leaves_no_file(tmp_path: Path) -> None:
    scene = Scene(entities=[PointSet(vertices=[[0, 0, 0]], name="p")])
    with pytest.warns(GocadWarning), pytest.raises(geobrep.FormatError, match="no Surface"):
        geobrep.write(scene, tmp_path / "empty.ts")
    assert list(tmp_path.iterdir()) == []


def test_awkward_floats_survive_the_bulk_paths_bit_for_bit(tmp_path: Path) -> None:
    rng = np.random.default_rng(3)
    n = 300
    vertices = rng.normal(0.0, 1e6, (n, 3))
    vertices[::7] = np.round(vertices[::7])  # integral coordinates: written as integers
    vertices[50] = [-0.0, 0.0, 2.0**60]  # after the PATOM: a bulk run with no nan
    vertices[60] = [5e-324, 1.7976931348623157e308, -1e-300]
    vertices[40] = vertices[3]  # a repeated position: written as PATOM
    values = rng.normal(size=(n, 2))
    values[::5, 0] = 3.0
    values[55, 1] = -0.0
    values[9] = [np.nan, -0.0]  # before it: parsed line by line
    values[10] = [np.inf, -np.inf]
    faces = np.stack([np.arange(n - 2), np.arange(1, n - 1), np.arange(2, n)], axis=1)
    cell = np.where(np.arange(n - 2) % 3 == 0, -0.0, rng.normal(size=n - 2))
    surface = Surface(
        vertices=vertices,
        faces=faces,
        name="awkward",
        point_data={"a": values[:, 0], "b": values[:, 1]},
        cell_data={"c": cell, "zone": (np.arange(n - 2) % 4).astype(np.float64)},
    )
    path = write_quietly(Scene(entities=[surface]), tmp_path / "awkward.ts")
    assert "PATOM 41 4" in path.read_text()
    back = read_quietly(path).surfaces[0]
    assert arrays_identical(back.vertices, vertices)
    assert np.array_equal(back.faces, faces)
    read_as = np.where(np.isfinite(values), values, np.nan)  # non-finite values: no data
    for name, expected in (("a", read_as[:, 0]), ("b", read_as[:, 1])):
        assert arrays_identical(back.point_data[name].values, expected)
    for name in ("c", "zone"):
        assert arrays_identical(back.cell_data[name].values, surface.cell_data[name].values)
