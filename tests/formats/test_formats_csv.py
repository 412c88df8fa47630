"""The ``csv`` format: points tables in and out, exact and honest about what a table holds."""

from __future__ import annotations

import doctest
import warnings
from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep.adapters.csv._table import looks_like_points_table
from geobrep.errors import FormatError
from geobrep.host.capabilities import capability_losses
from geobrep.plugins import registries


def _survey() -> geobrep.Scene:
    rng = np.random.default_rng(7)
    xyz = np.column_stack(
        [
            450_000 + rng.uniform(0, 1000, 50),
            6_700_000 + rng.uniform(0, 800, 50),
            rng.uniform(-600, 40, 50),
        ]
    )
    points = geobrep.PointSet(
        vertices=xyz,
        name="well tops",
        kind="wells",
        point_data={
            "porosity": geobrep.Property(
                values=np.where(np.arange(50) % 7 == 0, -999.0, rng.uniform(0, 0.3, 50)),
                unit="1",
                no_data_value=-999.0,
            ),
            "facies": np.arange(50, dtype=np.int32) % 4,
            "dip": rng.normal(size=(50, 3)),
            "flag": np.where(np.arange(50) % 5 == 0, np.nan, 1.0),
        },
    )
    return geobrep.Scene(entities=[points], crs=geobrep.CRS(epsg=32631), name="survey")


def test_round_trip_is_exact(tmp_path: Path) -> None:
    scene = _survey()
    back = geobrep.read(geobrep.write(scene, tmp_path / "tops.csv"))
    assert back.crs == scene.crs
    assert back.name == "survey"
    assert back.point_sets[0] == scene.point_sets[0]  # float64 bits, dtypes, units, no-data
    assert back.point_sets[0].point_data["dip"].element_size == 3


@pytest.mark.parametrize("delimiter", [",", ";", "\t", " "])
def test_plain_table_without_metadata(delimiter: str, tmp_path: Path) -> None:
    scene = _survey()
    path = geobrep.write(scene, tmp_path / "tops.csv", metadata=False, delimiter=delimiter)
    text = path.read_text()
    assert not text.startswith("#")
    header = text.splitlines()[0].split(delimiter)
    assert header[:5] == ["x", "y", "z", "porosity", "facies"]
    assert header[5:8] == ["dip[0]", "dip[1]", "dip[2]"]
    rows = np.genfromtxt(path, delimiter=None if delimiter == " " else delimiter, skip_header=1)
    np.testing.assert_array_equal(rows[:, :3], scene.point_sets[0].vertices)
    back = geobrep.read(path).point_sets[0]
    np.testing.assert_array_equal(back.vertices, scene.point_sets[0].vertices)
    np.testing.assert_array_equal(
        back.point_data["dip"].values, scene.point_sets[0].point_data["dip"].values
    )
    assert back.point_data["facies"].dtype == np.float64  # a plain table holds no types
    assert back.crs is None if hasattr(back, "crs") else True


def test_found_by_content_under_other_names(tmp_path: Path) -> None:
    path = tmp_path / "survey.xyz"
    path.write_text("# exported\nX Y Z depth_error\n1.5 2 3 0.1\n4 5 6 0.2\n7 8 9 0.3\n")
    assert registries().formats.choose_reader(path).name == "csv"
    points = geobrep.read(path).point_sets[0]
    np.testing.assert_array_equal(points.vertices[:, 0], [1.5, 4.0, 7.0])
    assert list(points.point_data) == ["depth_error"]


def test_named_columns_in_any_order(tmp_path: Path) -> None:
    path = tmp_path / "p.csv"
    path.write_text("id,Z,X,Y\n1,-5,10,20\n2,-6,11,21\n")
    points = geobrep.read(path).point_sets[0]
    np.testing.assert_array_equal(points.vertices, [[10, 20, -5], [11, 21, -6]])
    np.testing.assert_array_equal(points.point_data["id"].values, [1, 2])


@pytest.mark.parametrize(
    ("head", "expected"),
    [
        (b"x,y,z\n1,2,3\n4,5,6\n", True),
        (b"1 2 3\n4 5 6\n", True),
        (b"OFF\n8 6 12\n0 0 0\n", False),  # a header narrower than the rows
        (b"solid cube\nfacet normal 0 0 1\n", False),
        (b"x,y\n1,2\n3,4\n", False),  # two columns
        (b"1,2,3\n4,5\n", False),  # ragged
        (b"ply\nformat binary_little_endian 1.0\n\0\0", False),
        (b"x,y,z\n", False),  # no rows
    ],
)
def test_sniffer(head: bytes, expected: bool) -> None:
    assert looks_like_points_table(head) is expected


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("x,y,z\n1,2,3\n4,5\n", r"p\.csv:3: expected 3 values, found 2"),
        ("x,y,z\n1,2,3\n4,five,6\n", r"p\.csv:3: not a number: 'five'"),
        ("x,y,z\n1,2,nan\n", r"p\.csv:2: coordinates must be finite"),
        ("x,y,z,w\n1,2,3\n", r"the header names 4 columns but the rows have 3"),
        ("x,y\n1,2\n", r"need x, y, z columns, found 2"),
        ("x,y,z\n", "the file has a header but no points"),
        ("# geobrep: {oops\nx,y,z\n1,2,3\n", r"p\.csv:1: the '# geobrep:' line is not valid JSON"),
        ('# geobrep: {"crs": 5}\nx,y,z\n1,2,3\n', "the '# geobrep:' line does not describe"),
        ('# geobrep: {"properties": {"w": {"dtype": "nope"}}}\nx,y,z,w\n1,2,3,4\n', "describe"),
    ],
)
def test_bad_tables_name_file_and_line(text: str, message: str, tmp_path: Path) -> None:
    path = tmp_path / "p.csv"
    path.write_text(text)
    with pytest.raises(FormatError, match=message):
        geobrep.read(path)


def test_what_a_table_cannot_hold_is_reported(tmp_path: Path) -> None:
    cake = geobrep.datasets.faulted_layer_cake()
    scene = cake.with_entities(
        _survey().point_sets[0].replace(id=None), geobrep.datasets.scattered_points()
    )
    lost = capability_losses(scene, registries().formats.get("csv").capabilities)
    assert any("Surface entities dropped" in line for line in lost)
    assert any("2 entities merged into one" in line for line in lost)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        path = geobrep.write(scene, tmp_path / "merged.csv")
    merged = geobrep.read(path).point_sets[0]
    assert merged.n_points == 50 + geobrep.datasets.scattered_points().n_points
    assert list(merged.point_data) == []  # no property is shared by both point sets


def test_a_scene_without_points_is_refused_and_nothing_is_written(tmp_path: Path) -> None:
    with pytest.raises(FormatError, match="needs a PointSet"):
        geobrep.write(geobrep.datasets.faulted_layer_cake(), tmp_path / "none.csv")
    assert not (tmp_path / "none.csv").exists()


def test_bad_writer_options(tmp_path: Path) -> None:
    with pytest.raises(geobrep.OptionsError, match="delimite"):
        geobrep.write(_survey(), tmp_path / "a.csv", delimiter_="|")
    with pytest.raises(FormatError, match="delimiter"):
        geobrep.write(_survey(), tmp_path / "a.csv", delimiter="|")


def test_module_examples() -> None:
    import geobrep.adapters.csv as module

    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0
    assert result.failed == 0


def test_a_specific_sniffer_beats_the_generic_table(tmp_path: Path) -> None:
    from geobrep.host.registry import FormatRegistry, FormatSpec

    path = tmp_path / "survey.txt"
    path.write_text("1 2 3\n4 5 6\n")
    csv = registries().formats.get("csv")
    assert csv.generic_content
    specific = FormatSpec(
        name="survey", extensions=(".srv",), reader=lambda p, o: None, sniff=lambda h: True
    )
    assert FormatRegistry([csv, specific]).choose_reader(path).name == "survey"
    assert FormatRegistry([csv]).choose_reader(path).name == "csv"
    twin = specific.model_copy(update={"name": "twin"})
    with pytest.raises(geobrep.UnknownFormatError, match="several formats can read"):
        FormatRegistry([csv, specific, twin]).choose_reader(path)
