"""GOCAD reader gaps found against the reference reader's own test files (issue 12, item 6).

The truths are taken from the files themselves (the PVRTX text, the tetrahedra's volumes, the
MODEL section's triangles), never from what geobrep returned before.
"""

from __future__ import annotations

import math
import re
import warnings
from pathlib import Path

import numpy as np
import pytest
from gocad_files import DATA, read_quietly, write_quietly

import geobrep
from geobrep import TetMesh
from geobrep.adapters.gocad._parser import GocadWarning

OPENGEODE = Path(__file__).resolve().parent.parent / "data" / "opengeode"


def _write(tmp_path: Path, text: str, name: str) -> Path:
    path = tmp_path / name
    path.write_text(text.lstrip())
    return path


def _volumes(tets: TetMesh) -> dict[str, float]:
    """Volume of each region, from its tetrahedra (z up)."""
    p = tets.vertices[tets.cells]
    signed = np.einsum(
        "ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0]
    )
    sums = np.bincount(tets.region_labels, weights=np.abs(signed) / 6.0)
    return dict(zip(tets.region_names, sums.tolist(), strict=True))


# -- 1. the property header is complete before the tables are sized ---------------------------


def test_unknown_line_in_the_property_header_does_not_size_the_tables() -> None:
    path = OPENGEODE / "vri.lso"
    scene = read_quietly(path)
    (tets,) = scene.tet_meshes
    assert (tets.n_points, tets.n_cells) == (123, 292)
    # the property of ESIZE 2 is a (N, 2) vector; every value is the file's, in its column
    geology = tets.point_data["SnS!ingridStructuralWorkflow/skua_model_Geology"]
    assert geology.values.shape == (123, 2)
    assert geology.no_data_value == -9999.990234375
    names = [n for n in tets.point_data if n != "gocad_vertex_flag"]
    assert len(names) == 9
    columns = np.column_stack(
        [np.asarray(tets.point_data[n].values).reshape(123, -1) for n in names]
    )
    rows = [line.split() for line in path.read_text().splitlines()]
    values = np.array(  # PVRTX id x y z values..., SHAREDPVRTX id ref values...
        [[float(t) for t in r[5:15]] for r in rows if r and r[0] == "PVRTX"]
        + [[float(t) for t in r[3:13]] for r in rows if r and r[0] == "SHAREDPVRTX"]
    )
    assert np.array_equal(columns, values)
    assert "FIXED 0 0 0 0 0 1 1 0 0" in tets.metadata["gocad"]["extra_lines"]
    # its two regions, named by MODEL_REGION, fill the unit cube
    assert set(tets.region_names) == {"Region_1", "Region_2"}
    assert math.isclose(sum(_volumes(tets).values()), 1.0, rel_tol=1e-9)
    assert "ctetra_regions" not in tets.metadata["gocad"]  # # CTETRA names agree


def test_property_header_lines_in_any_order_around_unknown_lines(tmp_path: Path) -> None:
    text = """
GOCAD VSet 1
HEADER {
name: pts
}
ESIZES 2 1
FIXED 0 1
PROPERTIES vec s
MY_OWN_KEYWORD 7
NO_DATA_VALUES -1 -2
PVRTX 1 0 0 0 1 2 3
PVRTX 2 1 0 0 4 5 6
PVRTX 3 2 0 0 7 8 -2
END
"""
    with pytest.warns(GocadWarning, match="unknown keyword 'FIXED' in the header"):
        points = geobrep.read(_write(tmp_path, text, "p.vs")).point_sets[0]
    assert points.point_data["vec"].values.tolist() == [[1, 2], [4, 5], [7, 8]]
    assert points.point_data["s"].values.tolist() == [3, 6, -2]
    assert points.point_data["s"].no_data_value == -2
    assert points.metadata["gocad"]["extra_lines"] == ["FIXED 0 1", "MY_OWN_KEYWORD 7"]


# -- 2. LightTSolid regions from # CTETRA faces and MODEL_REGION seeds -------------------------


def test_light_tsolid_regions_from_ctetra_faces_and_model_region_seeds() -> None:
    scene = read_quietly(OPENGEODE / "test.lso")
    (tets,) = scene.tet_meshes
    assert tets.n_cells == 1247
    volumes = _volumes(tets)
    assert tets.region_names == ("Region_1", "Region_2", "horizon_1_1", "horizon_1_2")
    expected = {"Region_1": 240.0, "Region_2": 1040.0, "horizon_1_1": 1760.0, "horizon_1_2": 960.0}
    for name, volume in expected.items():
        assert math.isclose(volumes[name], volume, rel_tol=1e-6), (name, volumes[name])
    # every face a # CTETRA line puts on a surface is a triangle of the MODEL section, and back
    model = [s for s in scene.surfaces if s.metadata["gocad"]["type"] == "TSolid.SURFACE"]
    triangles = {tuple(sorted(map(tuple, s.vertices[f].tolist()))) for s in model for f in s.faces}
    codes = np.asarray(tets.cell_data["gocad_ctetra_faces"].values)
    opposite = np.array([[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]])
    on_model = np.array(
        [
            [
                tuple(sorted(map(tuple, tets.vertices[cell[opposite[k]]].tolist()))) in triangles
                for k in range(4)
            ]
            for cell in tets.cells
        ]
    )
    assert np.array_equal(codes != 0, on_model)
    assert int(on_model.sum()) == 820
    # quoted surface names with spaces are one entry each
    surfaces = tets.cell_data["gocad_ctetra_faces"].metadata["gocad"]["surfaces"]
    assert '(boundary)"fracture 1"' in surfaces
    assert '"horizon_1_fault_fract 1"' in surfaces


def test_light_tsolid_regions_survive_a_write_and_read(tmp_path: Path) -> None:
    first = read_quietly(OPENGEODE / "test.lso")
    again = read_quietly(write_quietly(first, tmp_path / "test.so"))
    (a,), (b,) = first.tet_meshes, again.tet_meshes
    assert len(a.region_names) == 4
    assert a.region_names == b.region_names
    assert _volumes(a) == pytest.approx(_volumes(b), rel=1e-12)


def _two_tets(ctetra: bool, sign: str, depth: bool = False) -> str:
    """Two tetrahedra sharing the triangle z = 0 (its key triangle's normal points up)."""
    crs = "GOCAD_ORIGINAL_COORDINATE_SYSTEM\nZPOSITIVE Depth\nEND_ORIGINAL_COORDINATE_SYSTEM\n"
    z = -1 if depth else 1
    lines = [
        "GOCAD LightTSolid 1",
        "HEADER {",
        "name: pair",
        "}",
        crs if depth else "",
        "VRTX 1 0 0 0",
        "VRTX 2 1 0 0",
        "VRTX 3 0 1 0",
        f"VRTX 4 0 0 {z}",
        f"VRTX 5 0 0 {-z}",
        "TETRA 1 2 3 4",
        "# CTETRA both +mid none none none" if ctetra else "",
        "TETRA 1 3 2 5",
        "# CTETRA both -mid none none none" if ctetra else "",
        "MODEL",
        "SURFACE mid",
        "TFACE 1",
        "KEYVERTICES 1 2 3",
        "TRGL 1 2 3",
        f"MODEL_REGION upper {sign}1",
        f"MODEL_REGION lower {'-' if sign == '+' else '+'}1",
        "END",
    ]
    return "\n".join(line for line in lines if line) + "\n"


@pytest.mark.parametrize("ctetra", [True, False])
@pytest.mark.parametrize("depth", [False, True])
def test_model_region_seeds_name_the_side_of_the_key_triangle(
    tmp_path: Path, ctetra: bool, depth: bool
) -> None:
    for sign, upper_name in (("+", "upper"), ("-", "lower")):
        path = _write(tmp_path, _two_tets(ctetra, sign, depth), f"pair{sign == '+'}.so")
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            (tets,) = geobrep.read(path).tet_meshes
        assert len(tets.region_names) == 2
        centre_z = tets.vertices[tets.cells].mean(axis=1)[:, 2]
        above = int(np.argmax(centre_z))  # z up, whatever the file's ZPOSITIVE
        assert tets.region_names[tets.region_labels[above]] == upper_name
        if ctetra:  # the file's "# CTETRA both" contradicts the seeds: said and kept
            assert any("'# CTETRA' region name(s) differ" in str(w.message) for w in caught)
            assert tets.metadata["gocad"]["ctetra_regions"] == [[0, "both"], [1, "both"]]


def test_tvolume_regions_are_kept_and_match_the_faces_and_seeds(tmp_path: Path) -> None:
    """With TVOLUMEs, they are the regions; without them, the faces and seeds give the same."""
    text = (DATA / "cube_model_equi.so").read_text()
    with_tvolume = read_quietly(DATA / "cube_model_equi.so").tet_meshes[0]
    assert with_tvolume.region_names == ("Region_1", "Region_2")
    stripped = re.sub(r"(?m)^TVOLUME .*\n", "", text)
    without = read_quietly(_write(tmp_path, stripped, "no_tvolume.so")).tet_meshes[0]
    assert without.region_names == with_tvolume.region_names
    assert np.array_equal(without.region_labels, with_tvolume.region_labels)
    # an internal surface that ends inside its region does not split it
    inside = read_quietly(DATA / "solid_surf_inside.so").tet_meshes[0]
    text = (DATA / "solid_surf_inside.so").read_text()
    stripped = re.sub(r"(?m)^TVOLUME .*\n", "", text)
    again = read_quietly(_write(tmp_path, stripped, "inside.so")).tet_meshes[0]
    assert again.region_names == inside.region_names == ("Region_1",)


# -- 3. PROPERTY_CLASSES names the properties when there is no PROPERTIES line -----------------


def test_property_classes_without_properties_names_the_properties(tmp_path: Path) -> None:
    text = """
GOCAD VSet 1
HEADER {
name: samples
}
PROPERTY_CLASSES porosity depth
NO_DATA_VALUES -99999 -1
PVRTX 1 0 0 0 0.25 10
PVRTX 2 1 0 0 -99999 20
PVRTX 3 2 0 0 0.15 -1
END
"""
    with pytest.warns(GocadWarning, match="PROPERTY_CLASSES without PROPERTIES"):
        points = geobrep.read(_write(tmp_path, text, "samples.vs")).point_sets[0]
    porosity, depth = points.point_data["porosity"], points.point_data["depth"]
    assert porosity.values.tolist() == [0.25, -99999, 0.15]
    assert porosity.no_data_value == -99999
    assert float(porosity.masked().mean()) == pytest.approx(0.2)
    assert depth.values.tolist() == [10, 20, -1]
    assert depth.no_data_value == -1
    back = geobrep.read(geobrep.write(points, tmp_path / "again.vs")).point_sets[0]
    assert back.point_data["porosity"].values.tolist() == porosity.values.tolist()


# -- 4. non-finite numbers: coordinates are errors, property values become no-data -------------


@pytest.mark.parametrize(
    "rows",
    [
        ["VRTX 1 0 0 0", "VRTX 2 1.#INF 0 0", "VRTX 3 0 1 0"],  # a bulk run
        ["VRTX 1 0 0 0", "VRTX 2 1 nan 0 CNXYZ", "VRTX 3 0 1 0 CNXYZ"],  # line by line
    ],
)
def test_non_finite_coordinates_are_a_format_error(tmp_path: Path, rows: list[str]) -> None:
    text = "GOCAD TSurf 1\nHEADER {\nname: s\n}\nTFACE\n" + "\n".join(rows) + "\nTRGL 1 2 3\nEND\n"
    path = _write(tmp_path, text, "bad.ts")
    with pytest.raises(geobrep.FormatError) as caught:
        read_quietly(path)
    assert caught.value.line == 7
    assert f"{path}:7: vertex coordinates must be finite" in str(caught.value)


def test_non_finite_property_values_become_the_no_data_value(tmp_path: Path) -> None:
    text = """
GOCAD VSet 1
HEADER {
name: odd
}
PROPERTIES a b c
NO_DATA_VALUES -99999 -1.#INF
ESIZES 1 1 1
PVRTX 1 0 0 0 1.#INF 2 1
PVRTX 2 1 0 0 -inf 1e+38 2
PVRTX 3 2 0 0 nan -1.#INF inf
PATOM 4 1 7 inf 3
END
"""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        points = geobrep.read(_write(tmp_path, text, "odd.vs")).point_sets[0]
    a, b, c = (points.point_data[n] for n in "abc")
    assert a.values.tolist() == [-99999, -99999, -99999, 7]
    # b's no-data value is -inf itself: -1.#INF is that value; the other inf becomes it
    assert b.values.tolist() == [2, 1e38, -math.inf, -math.inf]
    assert c.values[[0, 1, 3]].tolist() == [1, 2, 3]
    assert np.isnan(c.values[2])
    messages = [str(w.message) for w in caught if "non-finite" in str(w.message)]
    assert all(issubclass(w.category, GocadWarning) for w in caught)
    assert sorted(messages, key=lambda m: int(m.split(":")[1])) == [
        "odd.vs:8: point property 'a': 3 non-finite value(s) (inf, nan) replaced by its "
        "no-data value -99999.0; the first on this line",
        "odd.vs:10: point property 'c': 1 non-finite value(s) (inf, nan) replaced by NaN "
        "(it has no no-data value); the first on this line",
        "odd.vs:11: point property 'b': 1 non-finite value(s) (inf, nan) replaced by its "
        "no-data value -inf; the first on this line",
    ]
    assert a.masked().count() == 1  # only the finite value is data
