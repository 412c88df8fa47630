"""GOCAD SGrid (.sg): headers written here by hand as GOCAD writes them (test039.sg's and
sgrid_tsurf.ts's keywords) with numpy-made big-endian side files, read against the values put in;
the ASCII variant; FormatErrors naming missing or short side files; exact round trips."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep import CRS, FormatError, Property, Scene, StructuredGrid

NODES = (4, 3, 3)  # AXIS_N: 36 nodes, 3 x 2 x 2 = 12 cells


def _lattice(nodes: tuple[int, int, int] = NODES) -> np.ndarray:
    """Node coordinates, i fastest: a sheared box whose cells are 10 x 20 x 5 parallelepipeds."""
    ni, nj, nk = nodes
    k, j, i = np.meshgrid(np.arange(nk), np.arange(nj), np.arange(ni), indexing="ij")
    x = 1000.0 + 10.0 * i + 2.0 * k
    y = 2000.0 + 20.0 * j
    z = -500.0 + 5.0 * k
    return np.stack([x, y, z], axis=-1).reshape(-1, 3)


def _header(body: str, zpositive: str = "Elevation") -> str:
    return (
        "GOCAD SGrid 1 \nHEADER {\nname:SGrid_Test\n}\nGOCAD_ORIGINAL_COORDINATE_SYSTEM\n"
        'NAME Default\nAXIS_NAME "X" "Y" "Z"\nAXIS_UNIT "m" "m" "m"\n'
        f"ZPOSITIVE {zpositive}\nEND_ORIGINAL_COORDINATE_SYSTEM\n"
        "AXIS_N 4 3 3 \n" + body + "\nEND\n"
    )


CELL_HEADER = _header(
    """PROP_ALIGNMENT CELLS
POINTS_OFFSET 0
POINTS_FILE t_points@@
FLAGS_OFFSET 0
FLAGS_FILE t_flags@@

REGION Area1 0
REGION Area2 1
REGION_FLAGS_ARRAY_LENGTH 36
REGION_FLAGS_BIT_LENGTH 2
REGION_FLAGS_ESIZE 1
REGION_FLAGS_OFFSET 0
REGION_FLAGS_FILE t_region_flags@@

PROPERTY 1 "Prop1"
PROPERTY_CLASS 1 "prop1"
PROPERTY_CLASS_HEADER 1 "prop1" {
pclip:99
}
PROPERTY_SUBCLASS 1 QUANTITY Float
PROP_UNIT 1 none
PROP_NO_DATA_VALUE 1 -99999
PROP_ESIZE 1 4
PROP_ETYPE 1  IEEE
PROP_ALIGNMENT 1  CELLS
PROP_FORMAT 1 RAW
PROP_OFFSET 1 0
PROP_FILE 1 t_prop1@@"""
)


def _cell_sgrid(folder: Path) -> tuple[Path, np.ndarray, np.ndarray]:
    points = _lattice()
    values = np.arange(12, dtype=np.float32) / 4
    values[5] = -99999.0
    (folder / "t.sg").write_text(CELL_HEADER)
    points.astype(">f4").tofile(folder / "t_points@@")
    (np.arange(36) % 5).astype(">i4").tofile(folder / "t_flags@@")
    (np.arange(36) % 4).astype(">u1").tofile(folder / "t_region_flags@@")
    values.astype(">f4").tofile(folder / "t_prop1@@")
    return folder / "t.sg", points, values


def test_a_cell_centred_sgrid_reads_its_nodes_cells_and_flags(tmp_path: Path) -> None:
    path, points, values = _cell_sgrid(tmp_path)
    scene = geobrep.read(path)
    (grid,) = scene.structured_grids
    assert grid.counts == (3, 2, 2)
    assert grid.n_cells == 12
    assert grid.n_points == 36
    assert grid.name == "SGrid_Test"
    np.testing.assert_array_equal(grid.points, points)
    prop = grid.cell_data["Prop1"]
    np.testing.assert_array_equal(prop.values, values)
    assert prop.values.dtype == np.float32
    assert prop.no_data_value == -99999.0
    assert prop.unit == "none"
    np.testing.assert_array_equal(grid.point_data["sgrid_flags"].values, np.arange(36) % 5)
    np.testing.assert_array_equal(grid.point_data["sgrid_region_flags"].values, np.arange(36) % 4)
    assert grid.metadata["gocad"]["regions"] == {"Area1": 0, "Area2": 1}
    # every cell is a 10 x 20 x 5 parallelepiped (the shear keeps volumes)
    np.testing.assert_allclose(grid.cell_volumes, 1000.0)
    assert scene.crs is not None
    assert scene.crs.z_positive == "up"


def test_a_point_centred_depth_sgrid_in_double_precision(tmp_path: Path) -> None:
    header = _header(
        "PROP_ALIGNMENT POINTS\nBINARY_POINTS_IN_DOUBLE_PRECISION 1\nPOINTS_OFFSET 8\n"
        "POINTS_FILE d_points@@\nPROPERTY 1 depth_index\nPROP_ETYPE 1 Octet\nPROP_SIGNED 1 1\n"
        "PROP_ESIZE 1 2\nPROP_OFFSET 1 0\nPROP_FILE 1 d_prop@@",
        zpositive="Depth",
    )
    (tmp_path / "d.sg").write_text(header)
    points = _lattice() * [1.0, 1.0, -1.0]  # depths in the file
    (tmp_path / "d_points@@").write_bytes(b"\0" * 8 + points.astype(">f8").tobytes())
    labels = (np.arange(36) - 7).astype(">i2")
    labels.tofile(tmp_path / "d_prop@@")
    scene = geobrep.read(tmp_path / "d.sg")
    (grid,) = scene.structured_grids
    np.testing.assert_array_equal(grid.points, _lattice())  # z up in geobrep
    values = grid.point_data["depth_index"].values
    assert values.dtype == np.int16
    np.testing.assert_array_equal(values, np.arange(36) - 7)
    assert scene.crs is not None
    assert scene.crs.z_positive == "down"


def test_the_ascii_variant_reads_xyz_value_ijk_rows(tmp_path: Path) -> None:
    # As mtpy's and GA's writers make it: one row per node, a cell value on its first corner's
    # row and the no-data value on the rows of the last layer, column and row of nodes.
    header = _header(
        'PROP_ALIGNMENT CELLS\nASCII_DATA_FILE a__ascii@@\nPROPERTY 1 "Resistivity"\n'
        "PROP_NO_DATA_VALUE 1 -99999\nPROP_ESIZE 1 4"
    )
    (tmp_path / "a.sg").write_text(header)
    points = _lattice()
    ni, nj, nk = NODES
    k, j, i = np.meshgrid(np.arange(nk), np.arange(nj), np.arange(ni), indexing="ij")
    cell = (i < ni - 1) & (j < nj - 1) & (k < nk - 1)
    value = np.where(cell, i + 10 * j + 100 * k, -99999).ravel().astype(float)
    rows = np.column_stack([points, value, i.ravel(), j.ravel(), k.ravel()])
    order = np.random.default_rng(3).permutation(len(rows))  # rows in any order
    text = "*\n* X Y Z Resistivity I J K\n*\n" + "\n".join(
        " ".join(repr(float(v)) if c < 4 else str(int(v)) for c, v in enumerate(row))
        for row in rows[order]
    )
    (tmp_path / "a__ascii@@").write_text(text + "\n")
    (grid,) = geobrep.read(tmp_path / "a.sg").structured_grids
    np.testing.assert_array_equal(grid.points, points)
    kk, jj, ii = np.meshgrid(np.arange(2), np.arange(2), np.arange(3), indexing="ij")
    expected = (ii + 10 * jj + 100 * kk).ravel()
    np.testing.assert_array_equal(grid.cell_data["Resistivity"].values, expected)


@pytest.mark.parametrize(
    ("side", "cut", "message"),
    [
        ("t_points@@", None, r"POINTS_FILE: its file '.*t_points@@' is missing"),
        ("t_points@@", 100, r"POINTS_FILE: its file '.*t_points@@' has 100 bytes, 108 values"),
        ("t_flags@@", 10, r"FLAGS_FILE: its file '.*t_flags@@' has 10 bytes"),
        ("t_region_flags@@", None, r"REGION_FLAGS_FILE: its file '.*' is missing"),
        ("t_prop1@@", 47, r"property 'Prop1': PROP_FILE: its file '.*t_prop1@@' has 47 bytes"),
    ],
)
def test_a_missing_or_short_side_file_is_a_format_error_naming_it(
    tmp_path: Path, side: str, cut: int | None, message: str
) -> None:
    path, _, _ = _cell_sgrid(tmp_path)
    target = tmp_path / side
    if cut is None:
        target.unlink()
    else:
        target.write_bytes(target.read_bytes()[:cut])
    with pytest.raises(FormatError, match=message) as caught:
        geobrep.read(path)
    assert caught.value.path == str(path) or Path(str(caught.value.path)) == path


def test_a_side_file_outside_the_header_folder_is_refused(tmp_path: Path) -> None:
    path, _, _ = _cell_sgrid(tmp_path)
    path.write_text(CELL_HEADER.replace("POINTS_FILE t_points@@", "POINTS_FILE ../t_points@@"))
    with pytest.raises(FormatError, match="is not a file beside the header"):
        geobrep.read(path)


def test_a_bad_alignment_and_a_flat_axis_are_format_errors(tmp_path: Path) -> None:
    path, _, _ = _cell_sgrid(tmp_path)
    path.write_text(CELL_HEADER.replace("PROP_ALIGNMENT 1  CELLS", "PROP_ALIGNMENT 1 FACES"))
    with pytest.raises(FormatError, match="'FACES' is neither POINTS nor CELLS"):
        geobrep.read(path)
    path.write_text(CELL_HEADER.replace("AXIS_N 4 3 3", "AXIS_N 4 3 1"))
    with pytest.raises(FormatError, match="AXIS_N"):
        geobrep.read(path)


def curvilinear_grid() -> StructuredGrid:
    """A warped grid: float64 nodes no float32 can hold, point and cell properties, flags."""
    nodes = (5, 4, 3)
    points = _lattice(nodes)
    points[:, 2] += 0.1 * np.sin(points[:, 0]) + 1e-7 * np.arange(len(points))
    n_points, n_cells = 60, 24
    phi = np.linspace(0.05, 0.3, n_points, dtype=np.float32)
    phi[7] = -999.0
    return StructuredGrid(
        name="warped grid",
        counts=(4, 3, 2),
        points=points,
        point_data={
            "phi": Property(values=phi, unit="frac", no_data_value=-999.0),
            "sgrid_flags": Property(values=np.arange(n_points, dtype=np.int32) % 3),
        },
        cell_data={
            "facies": Property(values=(np.arange(n_cells) % 4).astype(np.int16)),
            "perm mD": Property(values=np.geomspace(1.0, 1000.0, n_cells)),
        },
    )


def _write(scene: Scene, path: Path) -> Path:
    path.parent.mkdir(exist_ok=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return geobrep.write(scene, path)


def test_a_written_sgrid_reads_back_exactly_and_writes_the_same_bytes(tmp_path: Path) -> None:
    grid = curvilinear_grid()
    crs = CRS(name="local", z_positive="down")
    first = _write(Scene(entities=[grid], crs=crs), tmp_path / "a" / "g.sg")
    scene = geobrep.read(first)
    (back,) = scene.structured_grids
    assert back.name == grid.name
    assert back.counts == grid.counts
    np.testing.assert_array_equal(back.points, grid.points)
    assert set(back.point_data) == set(grid.point_data)
    assert set(back.cell_data) == set(grid.cell_data)
    for name, prop in [*grid.point_data.items(), *grid.cell_data.items()]:
        got = back.point_data.get(name) or back.cell_data[name]
        np.testing.assert_array_equal(got.values, prop.values)
        assert got.values.dtype == prop.values.dtype
        assert (got.unit, got.no_data_value) == (prop.unit, prop.no_data_value)
    assert scene.crs is not None
    assert scene.crs.z_positive == "down"
    second = _write(scene, tmp_path / "b" / "g.sg")
    for file in sorted(first.parent.iterdir()):
        assert (second.parent / file.name).read_bytes() == file.read_bytes(), file.name


def test_the_cell_centred_file_written_back_keeps_its_flags_and_regions(tmp_path: Path) -> None:
    path, _, _ = _cell_sgrid(tmp_path)
    (grid,) = geobrep.read(path).structured_grids
    copy = _write(Scene(entities=[grid]), tmp_path / "out" / "copy.sg")
    text = copy.read_text()
    assert "PROP_ALIGNMENT CELLS" in text
    assert "REGION Area2 1" in text
    (back,) = geobrep.read(copy).structured_grids
    for name in ("sgrid_flags", "sgrid_region_flags"):
        np.testing.assert_array_equal(back.point_data[name].values, grid.point_data[name].values)
    np.testing.assert_array_equal(back.cell_data["Prop1"].values, grid.cell_data["Prop1"].values)
    assert back.metadata["gocad"]["regions"] == {"Area1": 0, "Area2": 1}


def test_a_corner_point_grid_has_no_sgrid_form(tmp_path: Path) -> None:
    coord = [[x, y, 0.0, x, y, -10.0] for y in (0.0, 1.0) for x in (0.0, 1.0)]
    grid = StructuredGrid(counts=(1, 1, 1), coord=coord, zcorn=[0.0] * 4 + [-2.0] * 4)
    with pytest.raises(FormatError, match="corner-point grid has no SGrid form"):
        _write(Scene(entities=[grid]), tmp_path / "cp.sg")
