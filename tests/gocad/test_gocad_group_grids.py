"""GOCAD groups (.gp) holding Voxets, SGrids and Wells: members read by their own readers with
their side files beside the group file (values checked against the bytes written by hand), side
files outside the folder refused, errors at the group file's lines, the group's CRS taken by its
members, and exact read → write → read of generated groups."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from gocad_files import DATA
from test_gocad_grids import deviated_well, rotated_voxet
from test_gocad_sgrid import curvilinear_grid

import geobrep
from geobrep import CRS, FormatError, Group, PointSet, RegularGrid, Scene, StructuredGrid, Well


def _read(path: Path) -> Scene:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return geobrep.read(path)


def _write(scene: Scene, path: Path) -> Path:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return geobrep.write(scene, path)


def test_a_voxet_member_reads_its_property_file_beside_the_group() -> None:
    scene = _read(DATA / "voxet_and_tsurf.gp")
    grid, top = scene.entities
    assert isinstance(grid, RegularGrid)
    assert (grid.name, top.name) == ("porosity_grid", "top")
    # AXIS_N 3 3 2 nodes from AXIS_MIN 0 to AXIS_MAX 1 of AXIS_U 10, AXIS_V 10, AXIS_W 5
    assert grid.counts == (2, 2, 1)
    np.testing.assert_array_equal(np.stack([grid.u, grid.v, grid.w]), np.diag([5.0, 5.0, 5.0]))
    values = np.asarray(grid.point_data["porosity"].values)
    assert values.dtype == np.float32
    raw = np.fromfile(DATA / "porosity_grid@@", dtype=">f4")
    np.testing.assert_array_equal(values, raw)
    assert raw[0] == np.float32(0.05)
    assert raw[-1] == np.float32(0.22)
    (group,) = scene.groups
    assert group.name == "grid_and_top"
    assert group.members == (grid.id, top.id)


def _group_scene() -> Scene:
    voxet = rotated_voxet().replace(id=0)
    sgrid = curvilinear_grid().replace(id=1)
    well = deviated_well().replace(id=2, logs={})
    points = PointSet(id=3, name="picks", vertices=[[451_300.0, 6_702_400.0, -1490.5]])
    inner = Group(name="wells", kind="HeterogeneousGroup", members=(2, 3))
    root = Group(name="field", kind="HeterogeneousGroup", members=(0, 1), children=(inner,))
    return Scene(entities=[voxet, sgrid, well, points], groups=[root], crs=CRS(name="local"))


def test_grids_and_wells_written_into_a_group_read_back_exactly(tmp_path: Path) -> None:
    scene = _group_scene()
    path = _write(scene, tmp_path / "field.gp")
    sides = sorted(p.name for p in tmp_path.glob("*@@"))
    assert "field_rotated_voxet__porosity@@" in sides
    assert "field_sg__points@@" in sides or any(s.endswith("__points@@") for s in sides)
    back = _read(path)
    assert [e.type for e in back.entities] == ["RegularGrid", "StructuredGrid", "Well", "PointSet"]
    voxet, sgrid, well, points = back.entities
    assert isinstance(voxet, RegularGrid)
    assert isinstance(sgrid, StructuredGrid)
    assert isinstance(well, Well)
    original = scene.entities
    for name in ("origin", "u", "v", "w"):
        np.testing.assert_array_equal(getattr(voxet, name), getattr(original[0], name))
    for name, prop in original[0].point_data.items():
        got = voxet.point_data[name]
        assert got.values.dtype == prop.values.dtype
        np.testing.assert_array_equal(got.values, prop.values)
        assert got.no_data_value == prop.no_data_value
    assert sgrid.points is not None
    np.testing.assert_array_equal(sgrid.points, original[1].points)
    for name, prop in original[1].cell_data.items():
        np.testing.assert_array_equal(sgrid.cell_data[name].values, prop.values)
    np.testing.assert_array_equal(well.vertices, original[2].vertices)
    np.testing.assert_array_equal(well.md, original[2].md)
    assert well.markers == original[2].markers
    assert well.zones == original[2].zones
    np.testing.assert_array_equal(points.vertices, original[3].vertices)
    (root,) = back.groups
    assert root.members == (0, 1)
    assert [(c.name, c.members) for c in root.children] == [("wells", (2, 3))]
    # and what was read writes and reads again to the same scene and the same bytes
    (tmp_path / "again").mkdir()
    again = _write(back, tmp_path / "again" / "field.gp")
    assert again.read_bytes() == path.read_bytes()
    for side in sides:
        assert (tmp_path / "again" / side).read_bytes() == (tmp_path / side).read_bytes()
    assert _read(again) == back


def test_members_of_the_same_name_get_their_own_side_files(tmp_path: Path) -> None:
    one = rotated_voxet().replace(name="g")
    two = one.replace(origin=one.origin + 1.0)
    path = _write(Scene(entities=[one, two]), tmp_path / "two.gp")
    assert {p.name for p in tmp_path.glob("*@@")} == {
        "two_g__facies@@",
        "two_g__porosity@@",
        "two_g_2__facies@@",
        "two_g_2__porosity@@",
    }
    first, second = _read(path).regular_grids
    np.testing.assert_array_equal(second.origin - first.origin, [1.0, 1.0, 1.0])


def _voxet_group(prop_file: str, extra: str = "") -> str:
    return (
        "GOCAD HeterogeneousGroup 1\nHEADER {\nname:g\n}\n"
        f"{extra}"
        "BEGIN_MEMBERS\nGOCAD Voxet 1\nHEADER {\nname:v\n}\n"
        "AXIS_O 0 0 0\nAXIS_U 1 0 0\nAXIS_V 0 1 0\nAXIS_W 0 0 1\n"
        "AXIS_MIN 0 0 0\nAXIS_MAX 1 1 1\nAXIS_N 2 2 2\n"
        f"PROPERTY 1 p\nPROP_ESIZE 1 4\nPROP_FILE 1 {prop_file}\nEND\nEND_MEMBERS\nEND\n"
    )


@pytest.mark.parametrize("name", ["../outside@@", "/etc/hostname", "sub/../../outside@@"])
def test_a_member_side_file_outside_the_group_folder_is_refused(tmp_path: Path, name: str) -> None:
    folder = tmp_path / "in"
    folder.mkdir()
    np.zeros(8, dtype=">f4").tofile(tmp_path / "outside@@")  # there, but not to be opened
    (folder / "g.gp").write_text(_voxet_group(name))
    with pytest.raises(FormatError, match="is not a file beside the header") as caught:
        _read(folder / "g.gp")
    assert caught.value.path == folder / "g.gp"
    assert "outside the folder of g.gp" in caught.value.message


def test_a_member_side_file_in_a_subfolder_is_read(tmp_path: Path) -> None:
    (tmp_path / "data").mkdir()
    np.arange(8, dtype=">f4").tofile(tmp_path / "data" / "v_p@@")
    (tmp_path / "g.gp").write_text(_voxet_group("data/v_p@@"))
    grid = _read(tmp_path / "g.gp").regular_grids[0]
    np.testing.assert_array_equal(grid.point_data["p"].values, np.arange(8, dtype=np.float32))


def test_a_missing_or_short_member_file_is_a_format_error_naming_it(tmp_path: Path) -> None:
    (tmp_path / "g.gp").write_text(_voxet_group("v_p@@"))
    with pytest.raises(FormatError, match=r"property 'p': PROP_FILE: its file .*v_p@@.* missing"):
        _read(tmp_path / "g.gp")
    np.zeros(7, dtype=">f4").tofile(tmp_path / "v_p@@")
    with pytest.raises(FormatError, match=r"has 28 bytes, 8 values of 4 bytes from byte 0 need 32"):
        _read(tmp_path / "g.gp")


def test_member_errors_give_the_group_file_s_line(tmp_path: Path) -> None:
    text = _voxet_group("v_p@@").replace("PROP_ESIZE 1 4", "PROP_ESIZE 1 x")
    (tmp_path / "g.gp").write_text(text)
    line = text.split("\n").index("PROP_ESIZE 1 x") + 1
    with pytest.raises(FormatError) as caught:
        _read(tmp_path / "g.gp")
    assert caught.value.path == tmp_path / "g.gp"
    assert caught.value.line == line


def test_a_member_without_a_crs_takes_the_group_s_depth_axis(tmp_path: Path) -> None:
    crs = (
        "GOCAD_ORIGINAL_COORDINATE_SYSTEM\nNAME local\nAXIS_NAME X Y Z\nAXIS_UNIT m m m\n"
        "ZPOSITIVE Depth\nEND_ORIGINAL_COORDINATE_SYSTEM\n"
    )
    text = _voxet_group("v_p@@", crs).replace("AXIS_O 0 0 0", "AXIS_O 0 0 1000")
    (tmp_path / "g.gp").write_text(text)
    np.arange(8, dtype=">f4").tofile(tmp_path / "v_p@@")
    scene = _read(tmp_path / "g.gp")
    grid = scene.regular_grids[0]
    np.testing.assert_array_equal(grid.origin, [0.0, 0.0, -1000.0])  # 1000 m deep
    np.testing.assert_array_equal(grid.w, [0.0, 0.0, -1.0])  # AXIS_W goes down
    assert scene.crs is not None
    assert scene.crs.z_positive == "down"


def test_a_group_file_reports_what_its_members_cannot_hold(tmp_path: Path) -> None:
    from geobrep.host import registries
    from geobrep.host.capabilities import format_losses

    well = deviated_well().replace(point_data={"INCL": np.zeros(5)})
    scene = Scene(entities=[well, rotated_voxet()])
    lost = format_losses(scene, registries().formats.get("gocad"), tmp_path / "g.gp")
    assert lost == [
        "ids of 2 entities dropped",
        "Well 'W 2': station and segment properties (INCL)",
    ]
