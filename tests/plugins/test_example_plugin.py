"""The example third-party plugin, installed with pip and found through its entry point."""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

import numpy as np
import pytest

import geobrep.plugins
from geobrep.errors import FormatError, OptionsError
from geobrep.host.loader import DISABLE_ENV
from geobrep.host.registry import FormatSpec


def xyz_format() -> FormatSpec:
    return geobrep.plugins.registries().formats.get("xyz")


def test_discovered_through_its_entry_point(example_plugin: Path) -> None:
    geobrep.plugins.reload()
    plugins = {info.name: info for info in geobrep.plugins.list_plugins()}
    info = plugins["example"]
    assert info.status == "loaded", info.error
    assert info.module == "geobrep_example_plugin"
    assert info.distribution is not None
    assert info.distribution.replace("_", "-").lower() == "geobrep-example-plugin"
    assert info.version == "0.1.0"
    assert info.registered["formats"] == ("xyz",)
    names = [p.name for p in geobrep.plugins.list_plugins()]
    assert names.index("native") < names.index("example")  # built-ins load first

    spec = xyz_format()
    assert spec.plugin == "example"
    assert spec.extensions == (".xyz",)
    assert spec.can_read
    assert spec.can_write
    assert spec.capabilities.entity_types == frozenset({"PointSet"})
    assert spec.capabilities.point_data
    assert not spec.capabilities.multiple_entities
    module_file = importlib.import_module("geobrep_example_plugin").__file__
    assert str(module_file).startswith(str(example_plugin))


def test_disabled_example_is_not_imported(
    example_plugin: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv(DISABLE_ENV, "example")
    geobrep.plugins.reload()
    info = {i.name: i for i in geobrep.plugins.list_plugins()}["example"]
    assert info.status == "disabled"
    assert info.version == "0.1.0"
    assert "geobrep_example_plugin" not in sys.modules
    assert "xyz" not in geobrep.plugins.registries().formats


def test_chosen_by_extension_and_by_sniffing(example_plugin: Path, tmp_path: Path) -> None:
    geobrep.plugins.reload()
    formats = geobrep.plugins.registries().formats
    assert formats.choose_reader(tmp_path / "Points.XYZ").name == "xyz"
    assert formats.choose_writer(tmp_path / "out.xyz").name == "xyz"
    text = tmp_path / "points.txt"
    text.write_text("# exported by a survey tool\n\n1.5 2.5 -3.0 7\n4 5 6 8\n")
    assert formats.choose_reader(text).name == "xyz"


def test_sniffer(example_plugin: Path) -> None:
    from geobrep_example_plugin import looks_like_xyz

    assert looks_like_xyz(b"1 2 3\n")
    assert looks_like_xyz(b"# comment\n  \n1.0,2.0,3.0,4.0")
    assert not looks_like_xyz(b"1 2\n")
    assert not looks_like_xyz(b"1 2 3 4 5\n")
    assert not looks_like_xyz(b"GOCAD TSurf 1\nHEADER {\n")
    assert not looks_like_xyz(b"\x00\x01\x02 binary")
    assert not looks_like_xyz(b"")
    assert not looks_like_xyz(b"# only comments\n")


def test_options(example_plugin: Path) -> None:
    geobrep.plugins.reload()
    spec = xyz_format()
    options = spec.validate_options(delimiter=",", value_name="porosity")
    assert options.model_dump() == {"delimiter": ",", "value_name": "porosity"}
    with pytest.raises(OptionsError, match="format 'xyz': option 'delimiter': String should"):
        spec.validate_options(delimiter="")
    with pytest.raises(OptionsError, match="format 'xyz': option 'delimeter': unknown option"):
        spec.validate_options(delimeter=",")


def test_bad_line_is_a_format_error_with_line_number(example_plugin: Path, tmp_path: Path) -> None:
    geobrep.plugins.reload()
    spec = xyz_format()
    assert spec.reader is not None
    path = tmp_path / "bad.xyz"
    path.write_text("# header\n1 2 3\n4 5 abc\n")
    with pytest.raises(FormatError) as caught:
        spec.reader(path, spec.validate_options())
    assert caught.value.path == path
    assert caught.value.line == 3
    assert str(caught.value) == f"{path}:3: not a number: 'abc'"

    path.write_text("1 2 3 4\n1 2 3\n")
    with pytest.raises(FormatError, match=r":2: expected 4 columns like line 1, found 3"):
        spec.reader(path, spec.validate_options())
    path.write_text("1 2\n")
    with pytest.raises(FormatError, match=r":1: expected 3 or 4 columns"):
        spec.reader(path, spec.validate_options())
    path.write_text("# nothing\n")
    with pytest.raises(FormatError, match="no points found"):
        spec.reader(path, spec.validate_options())


# The two tests below use geobrep's entities (PointSet, Scene) and geobrep.ops.io.atomic_write.


def test_read_xyz_into_a_point_set(example_plugin: Path, tmp_path: Path) -> None:
    geobrep.plugins.reload()
    spec = xyz_format()
    assert spec.reader is not None
    path = tmp_path / "wells.xyz"
    path.write_text("# x y z porosity\n500000.25 7000000.5 -120.5 0.25\n1 2 3 4\n")
    scene = spec.reader(path, spec.validate_options(value_name="porosity"))
    (points,) = scene.entities
    assert type(points).__name__ == "PointSet"
    assert points.name == "wells"
    np.testing.assert_array_equal(
        np.asarray(points.vertices), [[500000.25, 7000000.5, -120.5], [1.0, 2.0, 3.0]]
    )
    assert np.asarray(points.vertices).dtype == np.float64
    np.testing.assert_array_equal(np.asarray(points.point_data["porosity"]), [0.25, 4.0])


def test_write_then_read_round_trips_exactly(example_plugin: Path, tmp_path: Path) -> None:
    from geobrep import PointSet, Scene

    geobrep.plugins.reload()
    spec = xyz_format()
    assert spec.reader is not None
    assert spec.writer is not None
    rng = np.random.default_rng(42)
    vertices = rng.uniform(-1, 1, (50, 3)) * [1e3, 1e3, 1e2] + [500000.0, 7000000.0, 0.0]
    values = rng.normal(size=50)
    scene = Scene(entities=[PointSet(vertices=vertices, name="cloud", point_data={"v": values})])
    path = tmp_path / "cloud.xyz"
    options = spec.validate_options(delimiter=",", value_name="v")
    spec.writer(scene, path, options)
    assert path.read_text().startswith("# x y z v\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cloud.xyz"]  # no temporary left over
    (points,) = spec.reader(path, options).entities
    np.testing.assert_array_equal(np.asarray(points.vertices), vertices)  # bit-exact
    np.testing.assert_array_equal(np.asarray(points.point_data["v"]), values)


def test_through_geobrep_read_and_write(example_plugin: Path, tmp_path: Path) -> None:
    import geobrep

    geobrep.plugins.reload()
    source = tmp_path / "survey.txt"  # not .xyz: found by sniffing
    source.write_text("1,2,3,10\n4,5,6,20\n")
    scene = geobrep.read(source, delimiter=",")
    (points,) = scene.entities
    np.testing.assert_array_equal(np.asarray(points.point_data["value"]), [10.0, 20.0])
    target = geobrep.write(scene, tmp_path / "copy.xyz")
    assert target.read_text() == "# x y z value\n1.0 2.0 3.0 10.0\n4.0 5.0 6.0 20.0\n"
    with pytest.raises(OptionsError, match="format 'xyz': option 'delimeter'"):
        geobrep.read(source, format="xyz", delimeter=",")
