"""The format registry as the issue states it: extension + sniffing, format=, errors, plugins."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import geobrep.plugins
from geobrep.batch.conversion import convert
from geobrep.errors import UnknownFormatError
from geobrep.host.loader import register_plugin, set_host
from geobrep.model.entities import PointSet
from geobrep.model.scene import Scene
from geobrep.ops.io import read, write
from geobrep.plugins import registries

EXAMPLE_SRC = Path(__file__).parents[2] / "docs" / "examples" / "geobrep-example-plugin" / "src"


@pytest.fixture
def cake_file(tmp_path: Path, layer_cake: Scene) -> Path:
    return write(layer_cake, tmp_path / "cake.geobrep")


@pytest.mark.parametrize(
    ("name", "extension"),
    [("vtu", ".vtu"), ("vtk", ".vtk"), ("ply", ".ply"), ("vtp", ".vtp"), ("gmsh", ".msh"),
     ("stl", ".stl"), ("off", ".off")],
)  # fmt: skip
def test_content_sniffing_finds_the_format_without_extension(
    name: str, extension: str, layer_cake: Scene, tmp_path: Path
) -> None:
    written = write(layer_cake, tmp_path / f"model{extension}")
    anonymous = written.rename(tmp_path / "model.dat")
    assert registries().formats.choose_reader(anonymous).name == name
    assert len(read(anonymous).surfaces) >= 1


def test_format_keyword_overrides_extension(layer_cake: Scene, tmp_path: Path) -> None:
    path = write(layer_cake, tmp_path / "model.txt", format="ply")
    assert read(path, format="ply").surfaces == layer_cake.surfaces
    with pytest.raises(UnknownFormatError, match="formats that can read"):
        read(path, format="no-such-format")


def test_unknown_input_lists_installed_formats(tmp_path: Path) -> None:
    path = tmp_path / "notes.weird"
    path.write_text("nothing any format knows\n")
    with pytest.raises(UnknownFormatError) as info:
        read(path)
    message = str(info.value)
    for name in ("vtu", "ply", "vtk", "native"):
        assert name in message


def test_unknown_output_extension_lists_writers(layer_cake: Scene, tmp_path: Path) -> None:
    with pytest.raises(UnknownFormatError, match=r"formats that can write: .*vtu \(\.vtu"):
        write(layer_cake, tmp_path / "model.weird")


def test_png_is_write_only(tmp_path: Path) -> None:
    spec = registries().formats.get("png")
    assert spec.can_write
    assert not spec.can_read
    path = tmp_path / "x.png"
    path.write_bytes(b"\x89PNG\r\n\x1a\n")
    with pytest.raises(UnknownFormatError, match="cannot read"):
        read(path, format="png")


def test_capabilities_are_declared_honestly() -> None:
    formats = registries().formats
    assert formats.get("vtu").capabilities.names
    assert formats.get("vtu").capabilities.multiple_entities
    assert not formats.get("stl").capabilities.multiple_entities
    assert not formats.get("obj").capabilities.point_data
    assert formats.get("gmsh").capabilities.ids
    assert not formats.get("gmsh").capabilities.names
    assert "TetMesh" not in formats.get("ply").capabilities.entity_types
    assert "Block" not in formats.get("vtu").capabilities.entity_types


def test_third_party_format_converts_like_a_builtin(tmp_path: Path) -> None:
    sys.path.insert(0, str(EXAMPLE_SRC))
    previous = set_host(None)
    try:
        import geobrep_example_plugin

        info = register_plugin(geobrep_example_plugin, "example-inline")
        assert info.status == "loaded", info.error
        assert registries().formats.get("xyz").plugin == "example-inline"
        points = PointSet(
            vertices=np.array([[450000.125, 6700000.5, -12.25], [450001.0, 6700002.0, 3.0]]),
            point_data={"value": np.array([1.5, 2.5])},
        )
        source = write(points, tmp_path / "pts.ply")
        summary = convert(source, tmp_path / "pts.xyz")
        assert summary.ok, summary.table()
        assert summary.reports[0].lost == ("ids of 1 entities dropped",)
        back = convert(tmp_path / "pts.xyz", tmp_path / "again.ply")
        assert back.ok
        again = read(tmp_path / "again.ply").point_sets[0]
        np.testing.assert_array_equal(again.vertices, points.vertices)
    finally:
        set_host(previous)
        sys.path.remove(str(EXAMPLE_SRC))
        sys.modules.pop("geobrep_example_plugin", None)
        sys.modules.pop("geobrep_example_plugin.xyz", None)
        geobrep.plugins.registries()
