"""Readers facing hostile files (issue 15 items 4, 6, 8, 10): the reproducers of the campaign and
generated bombs are clear FormatErrors, in bounded memory and time; file data is cast only when
it fits; NaN metadata is refused where JSON has none."""

from __future__ import annotations

import json
import re
import zipfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from read_probe import (
    MIB,
    deflate_bomb_geobrep,
    huge_array_geobrep,
    memory_bound,
    probe_reads,
    wide_gocad_header,
    zlib_bomb_vtu,
)

import geobrep
from geobrep.adapters.casting import cast_exactly, misfit_rows
from geobrep.adapters.limits import read_budget
from geobrep.errors import FormatError

DATA = Path(__file__).resolve().parents[1] / "data" / "reliability"

#: Every reader reproducer and a piece of what its error must say.
REPRODUCERS = {
    "native/deflate_error.geobrep": "member 'scene.json' is corrupt",
    "native/entity_is_string.geobrep": "entities.0",
    "native/file_is_list.geobrep": "'file' must be a member name",
    "native/npy_header_tokenerror.geobrep": "is corrupt: its .npy header",
    "native/scene_json_latin1.geobrep": "scene.json is not UTF-8 text",
    "native/shape_infinity.geobrep": "Infinity is not JSON",
    "ply/edge_without_vertex2.ply": "PLY edge element has no 'vertex2' property",
    "ply/header_entity_no_id.ply": "geobrep header: entities.0.id: Field required",
    "ply/header_pointset_1e12.ply": "points 0..1000000000000 are not within the file's 1 points",
    "ply/header_pointset_4e8.ply": "points 0..400000000 are not within the file's 1 points",
    "ply/nan_vertex.ply": "Surface 'nan_vertex': vertices: contains 1 non-finite",
    "vtu/nan_point.vtu": "Surface 'triangle': vertices: contains 1 non-finite",
    "csv/int_property_nan.csv": "column 'v' holds nan, which does not fit the int8",
    "csv/nan_metadata.csv": "holds a NaN or infinity at crs.metadata.x",
    "csv/scene_name_int.csv": "Scene: name: Input should be a valid string",
}
LINES = {
    "csv/int_property_nan.csv": 3,
    "csv/nan_metadata.csv": 1,
    "native/scene_json_latin1.geobrep": 10,  # the line of scene.json with the Latin-1 byte
}
CATCH_ALL = re.compile(r"[\w.-]+ reader failed:")


def test_every_reader_reproducer_has_an_expectation() -> None:
    present = {
        f"{p.parent.name}/{p.name}"
        for kind in ("native", "ply", "vtu", "csv")
        for p in (DATA / kind).iterdir()
    }
    assert present == set(REPRODUCERS)


@pytest.mark.parametrize("name", sorted(REPRODUCERS))
def test_reproducer_is_a_format_error_naming_file_and_cause(name: str) -> None:
    path = DATA / name
    with pytest.raises(FormatError) as caught:
        geobrep.read(path)
    error = caught.value
    assert error.path == path
    assert REPRODUCERS[name] in error.message
    assert not CATCH_ALL.match(error.message), error.message
    assert error.line == LINES.get(name)


# -- item 4: memory and time, measured in a child process --------------------------------------


@pytest.fixture(scope="module")
def bombs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Files too big to ship, generated: huge declared arrays, deflate bombs, zlib VTU bombs."""
    folder = tmp_path_factory.mktemp("bombs")
    return {
        "1 MB .geobrep declaring a 2.4 GB array": huge_array_geobrep(folder / "huge1.geobrep"),
        "3 MB .geobrep declaring a 2.4 GB array": huge_array_geobrep(
            folder / "huge3.geobrep", 3 * MIB
        ),
        "deflate bomb (1 GiB of zeros)": deflate_bomb_geobrep(folder / "bomb.geobrep", 2**30),
        "deflate bomb whose zip directory says 1 KiB": deflate_bomb_geobrep(
            folder / "bomb_lie.geobrep", 2**30, lie=True
        ),
        "zlib VTU bomb (3.2 GB)": zlib_bomb_vtu(folder / "bomb.vtu"),
        "zlib VTU bomb with understated blocks": zlib_bomb_vtu(folder / "bomb_lie.vtu", lie=True),
        "GOCAD header of 399 values per vertex, VRTX lines without": wide_gocad_header(
            folder / "wide.vs"
        ),
        "GOCAD header of 399 values per vertex, ATOM lines inheriting": wide_gocad_header(
            folder / "atoms.vs", atoms=True
        ),
    }


def test_bombs_are_what_they_claim(bombs: dict[str, Path]) -> None:
    """The generated files are small, and would inflate far beyond the read budget."""
    vtu = bombs["zlib VTU bomb (3.2 GB)"]
    assert 4 * MIB < vtu.stat().st_size < 6 * MIB
    with zipfile.ZipFile(bombs["deflate bomb (1 GiB of zeros)"]) as archive:
        member = archive.getinfo("arrays/000000.npy")
    assert member.file_size > 2**30 > 100 * member.compress_size
    assert member.file_size > read_budget(bombs["deflate bomb (1 GiB of zeros)"].stat().st_size)


def test_every_hostile_file_is_refused_within_the_memory_bound(bombs: dict[str, Path]) -> None:
    """Peak memory over the memory before the read <= max(256 MB, 20 x the file's size)."""
    hostile = {**{name: DATA / name for name in REPRODUCERS}, **bombs}
    probes = probe_reads(list(hostile.values()), timeout=300)
    assert len(probes) == len(hostile)
    for (name, path), probe in zip(hostile.items(), probes, strict=True):
        assert probe.outcome == "FormatError", (name, probe)
        assert probe.peak_over <= memory_bound(path), (name, probe.peak_over / MIB)
        assert probe.seconds < 30, (name, probe)  # a guard, not a timing test
    said = dict(zip(hostile, (probe.message for probe in probes), strict=True))
    assert (
        "block 0 inflates to more than the 4.0 KiB" in said["zlib VTU bomb with understated blocks"]
    )
    assert "declares 3.1 GiB" in said["zlib VTU bomb (3.2 GB)"]
    for kind in ("VRTX lines without", "ATOM lines inheriting"):
        message = said[f"GOCAD header of 399 values per vertex, {kind}"]
        assert "declares 399 property values per vertex" in message, message
        assert "filling them in would take more than 16 MiB" in message, message


# -- item 6: values that do not fit the declared type --------------------------------------------


def _csv(tmp_path: Path, dtype: str, values: list[str]) -> Path:
    meta = json.dumps({"name": "p", "properties": {"v": {"dtype": dtype}}})
    rows = "\n".join(f"{k},{k},{k},{v}" for k, v in enumerate(values))
    path = tmp_path / "p.csv"
    path.write_text(f"# geobrep: {meta}\nx,y,z,v\n{rows}\n")
    return path


def test_csv_integer_column_reads_exactly_when_it_fits(tmp_path: Path) -> None:
    path = _csv(tmp_path, "int8", ["1", "-128", "127", "0"])
    values = geobrep.read(path).point_sets[0].point_data["v"].values
    assert values.dtype == np.int8
    assert values.tolist() == [1, -128, 127, 0]


@pytest.mark.parametrize(
    ("dtype", "bad", "shown"),
    [("int8", "300", "300.0"), ("int8", "nan", "nan"), ("int32", "1e10", "10000000000.0"),
     ("uint16", "-1", "-1.0"), ("int64", "2.5", "2.5"), ("bool", "2", "2.0")],
)  # fmt: skip
def test_csv_value_outside_its_declared_type_is_an_error_at_its_line(
    tmp_path: Path, dtype: str, bad: str, shown: str
) -> None:
    path = _csv(tmp_path, dtype, ["1", "0", bad])
    with pytest.raises(
        FormatError, match=f"column 'v' holds {shown}, which does not fit"
    ) as caught:
        geobrep.read(path)
    assert caught.value.line == 5  # metadata, header, then rows 0, 1 and the bad one


def test_csv_writer_refuses_integers_a_float_column_cannot_hold(tmp_path: Path) -> None:
    big = geobrep.PointSet(vertices=np.zeros((2, 3)), point_data={"id": np.array([1, 2**53 + 1])})
    with pytest.raises(FormatError, match=r"property 'id' holds integers beyond 2\*\*53"):
        geobrep.write(big, tmp_path / "big.csv")
    fits = big.replace(point_data={"id": np.array([1, 2**53])})
    back = geobrep.read(geobrep.write(fits, tmp_path / "fits.csv")).point_sets[0]
    assert back.point_data["id"].values.tolist() == [1, 2**53]


@given(
    st.lists(
        st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-(2**70), 2**70)),
        min_size=1,
        max_size=20,
    ),
    st.sampled_from(["int8", "uint8", "int16", "int32", "uint32", "int64", "uint64"]),
)
@settings(max_examples=200, deadline=None)
def test_misfit_rows_is_exactly_the_values_an_integer_type_cannot_hold(
    values: list[float | int], dtype: str
) -> None:
    array = np.array([float(v) for v in values])
    info = np.iinfo(dtype)
    expected = [
        not (np.isfinite(v) and float(v).is_integer() and info.min <= int(v) <= info.max)
        for v in array
    ]
    assert misfit_rows(array, dtype).tolist() == expected
    if not any(expected):
        assert cast_exactly(array, dtype, "v").tolist() == [int(v) for v in array]


def test_integer_wraps_between_same_width_types_are_misfits() -> None:
    assert misfit_rows(np.array([2**63], dtype=np.uint64), "int64").tolist() == [True]
    assert misfit_rows(np.array([-1], dtype=np.int64), "uint64").tolist() == [True]
    assert misfit_rows(np.array([2**53 + 1], dtype=np.int64), "float64").tolist() == [True]


# -- item 10: NaN where JSON has none ------------------------------------------------------------


def test_nan_no_data_value_round_trips_through_csv_as_a_string(tmp_path: Path) -> None:
    prop = geobrep.Property(values=[1.0, 2.0], no_data_value=float("nan"))
    points = geobrep.PointSet(vertices=np.eye(2, 3), point_data={"a": prop})
    path = geobrep.write(points, tmp_path / "nd.csv")
    assert '"no_data_value": "NaN"' in path.read_text().splitlines()[0]
    assert np.isnan(geobrep.read(path).point_sets[0].point_data["a"].no_data_value)
    older = tmp_path / "older.csv"  # geobrep wrote a bare NaN before: still read
    older.write_text(path.read_text().replace('"NaN"', "NaN"))
    assert np.isnan(geobrep.read(older).point_sets[0].point_data["a"].no_data_value)
    # and what reads from CSV can be written to .geobrep
    geobrep.write(geobrep.read(older), tmp_path / "nd.geobrep")


def test_native_writer_names_a_nan_in_metadata(tmp_path: Path) -> None:
    scene = geobrep.Scene(
        entities=[geobrep.PointSet(vertices=[[0, 0, 0]], metadata={"k": [1, float("inf")]})]
    )
    with pytest.raises(FormatError, match=r"scene\.entities\.0\.metadata\.k\.1 is NaN") as caught:
        geobrep.write(scene, tmp_path / "x.geobrep")
    assert caught.value.path == tmp_path / "x.geobrep"


def test_native_reader_refuses_a_nan_constant(tmp_path: Path) -> None:
    path = geobrep.write(geobrep.PointSet(vertices=[[0, 0, 0]]), tmp_path / "p.geobrep")
    with zipfile.ZipFile(path) as archive:
        members = {name: archive.read(name) for name in archive.namelist()}
    members["scene.json"] = members["scene.json"].replace(
        b'"metadata": {}', b'"metadata": {"x": NaN}', 1
    )
    with zipfile.ZipFile(path, "w") as archive:
        for name, data in members.items():
            archive.writestr(name, data)
    with pytest.raises(FormatError, match="NaN is not JSON"):
        geobrep.read(path)


# -- the checks of each reader -------------------------------------------------------------------


@pytest.mark.parametrize("binary", [False, True])
def test_ply_element_count_beyond_the_data_is_refused_at_its_line(
    tmp_path: Path, binary: bool
) -> None:
    path = geobrep.write(
        geobrep.PointSet(vertices=np.arange(12.0).reshape(4, 3)), tmp_path / "p.ply", binary=binary
    )
    data = path.read_bytes()
    assert b"element vertex 4\n" in data
    path.write_bytes(data.replace(b"element vertex 4\n", b"element vertex 400000000\n"))
    line = data[: data.index(b"element vertex")].count(b"\n") + 1
    with pytest.raises(FormatError, match="element 'vertex' declares 400000000 rows") as caught:
        geobrep.read(path)
    assert caught.value.line == line


def test_layout_header_with_overlapping_point_ranges_is_refused(tmp_path: Path) -> None:
    two = geobrep.Scene(
        entities=[geobrep.PointSet(vertices=np.zeros((3, 3)) + k, name=f"p{k}") for k in (0, 1)]
    )
    path = geobrep.write(two, tmp_path / "two.ply", binary=False)
    text = path.read_text()
    assert '"points":[3,6]' in text
    path.write_text(text.replace('"points":[3,6]', '"points":[0,3]'))
    with pytest.raises(FormatError, match=r"points 0\.\.3 overlap another entity's"):
        geobrep.read(path)


@pytest.mark.parametrize("compression", ["zlib", "lzma"])
def test_compressed_vtu_written_by_geobrep_reads_back(tmp_path: Path, compression: str) -> None:
    scene = geobrep.datasets.faulted_layer_cake()
    path = geobrep.write(scene, tmp_path / "cake.vtu", compression=compression)
    assert geobrep.read(path).surfaces == scene.surfaces


def test_gmsh_data_section_with_billions_of_tags_is_refused(tmp_path: Path) -> None:
    points = geobrep.PointSet(vertices=np.eye(3), point_data={"a": [1.0, 2.0, 3.0]})
    path = geobrep.write(points, tmp_path / "p.msh")
    lines = path.read_bytes().split(b"\n")
    at = lines.index(b"$NodeData") + 3  # string tag count, the name, then the real tag count
    lines[at] = b"4294967296"
    path.write_bytes(b"\n".join(lines))
    with pytest.raises(FormatError, match="declares 4294967296 real tags") as caught:
        geobrep.read(path)
    assert caught.value.line == at + 1


def test_legacy_vtk_field_type_vtk_crashes_on_is_refused(tmp_path: Path) -> None:
    """VTK's legacy reader segfaults on an unknown dataset FIELD type: refused before it."""
    path = tmp_path / "field.vtk"
    path.write_text(
        "# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\nFIELD FieldData 1\n"
        "h 1 3 foo\n1 2 3\nPOINTS 3 float\n0 0 0 1 0 0 0 1 0\nPOLYGONS 1 4\n3 0 1 2\n"
    )
    (probe,) = probe_reads([path], timeout=120)
    assert probe.outcome == "FormatError", probe
    assert "a FIELD array has type 'foo'" in probe.message


def test_vtp_counts_beyond_the_budget_are_refused_before_vtk(tmp_path: Path) -> None:
    """VTK allocates what NumberOfPoints says: 4e8 points killed the process."""
    path = geobrep.write(geobrep.datasets.faulted_layer_cake(), tmp_path / "cake.vtp")
    text = path.read_bytes()
    found = re.search(rb'NumberOfPoints="\d+"', text)
    assert found is not None
    huge = tmp_path / "huge.vtp"
    huge.write_bytes(text.replace(found.group(0), b'NumberOfPoints="400000000"', 1))
    negative = tmp_path / "negative.vtp"
    negative.write_bytes(text.replace(found.group(0), b'NumberOfPoints="-1"', 1))
    probes = probe_reads([huge, negative], timeout=120)
    assert [p.outcome for p in probes] == ["FormatError", "FormatError"], probes
    assert "a <Piece> declares 8.9 GiB" in probes[0].message
    assert "NumberOfPoints=-1 is negative" in probes[1].message


def test_truncated_vtp_is_an_error_not_an_empty_scene(tmp_path: Path) -> None:
    path = geobrep.write(geobrep.datasets.faulted_layer_cake(), tmp_path / "cake.vtp")
    cut = tmp_path / "cut.vtp"
    cut.write_bytes(path.read_bytes()[:3000])
    with pytest.raises(FormatError, match="VTK could not read this file"):
        geobrep.read(cut)


def test_gmsh_data_section_declaring_more_values_than_the_file_is_refused(tmp_path: Path) -> None:
    """A 658-byte file whose $NodeData declared 4e8 values took 3.7 GB in meshio."""
    points = geobrep.PointSet(vertices=np.eye(3), point_data={"a": [1.0, 2.0, 3.0]})
    path = geobrep.write(points, tmp_path / "p.msh")
    lines = path.read_bytes().split(b"\n")
    at = lines.index(b"$NodeData") + 8  # 1 string tag, 1 real tag, 3 integer tags: the count
    assert lines[at] == b"3"
    lines[at] = b"400000000"
    path.write_bytes(b"\n".join(lines))
    (probe,) = probe_reads([path], timeout=120)
    assert probe.outcome == "FormatError", probe
    assert "declares 400000000 values of 1 components" in probe.message
    assert probe.peak_over <= memory_bound(path)


def test_damaged_legacy_vtk_of_geobrep_never_reaches_vtk(tmp_path: Path) -> None:
    """Since geobrep's legacy files hold types VTK knows, a damaged one that meshio refuses went
    on to VTK's legacy reader, which crashed the process (fuzz seed 3: 49 cases, truncations
    among them): a file meshio wrote is meshio's to read, so it is a FormatError."""
    path = geobrep.write(geobrep.datasets.faulted_layer_cake(), tmp_path / "cake.vtk", binary=False)
    data = path.read_bytes()
    cut = tmp_path / "cut.vtk"
    cut.write_bytes(data[: len(data) // 2])
    (probe,) = probe_reads([cut], timeout=120)
    assert probe.outcome == "FormatError", probe
