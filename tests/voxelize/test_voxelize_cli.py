"""``geobrep voxelize IN OUT --depth N``."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import voxel_bodies as vb

import geobrep
from geobrep import LinearOctree, Scene, Surface
from geobrep.cli import main


@pytest.fixture
def cake_file(layer_cake: Scene, tmp_path: Path) -> Path:
    return geobrep.write(layer_cake, tmp_path / "cake.geobrep")


def test_voxelize_writes_the_octree(
    cake_file: Path, tmp_path: Path, layer_cake: Scene, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "octree.geobrep"
    assert main(["voxelize", str(cake_file), str(out), "--depth", "5"]) == 0
    text = capsys.readouterr().out
    assert f"{cake_file}: depth 5 (32³ cells)" in text
    assert "leaves per level:" in text
    assert "block #" in text
    assert "memory:" in text
    written = geobrep.read(out)
    assert len(written.entities) == 1
    tree = written.octrees[0]
    assert tree.depth == 5
    assert written.crs == layer_cake.crs
    assert set(tree.labels.tolist()) == {b.id for b in layer_cake.blocks}


def test_json_report_method_and_selection(
    cake_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "one.geobrep"
    args = [
        "voxelize",
        str(cake_file),
        str(out),
        "--depth",
        "4",
        "--method",
        "exact",
        "--bodies",
        "footwall unit 1",
        "--json",
        "--keep-input",
    ]
    assert main(args) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["depth"] == 4
    assert [b["name"] for b in report["bodies"]] == ["footwall unit 1"]
    assert report["bodies"][0]["method"] == "exact"
    assert report["leaves"] == sum(report["leaves_per_level"])
    written = geobrep.read(out)
    assert len(written.entities) == 17  # the model and its octree
    assert isinstance(written.entities[-1], LinearOctree)


def test_cube_options(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    source = geobrep.write(vb.box((0.5, 0.5, 0.5), (4.5, 4.5, 4.5)), tmp_path / "box.geobrep")
    out = tmp_path / "box-octree.geobrep"
    args = ["voxelize", str(source), str(out), "--depth", "3", "--origin", "0,0,0", "--size", "8"]
    assert main(args) == 0
    tree = geobrep.read(out).octrees[0]
    assert tree.codes.tolist() == [0]
    assert tree.levels.tolist() == [1]
    np.testing.assert_array_equal(tree.origin, [0.0, 0.0, 0.0])


def test_errors_exit_with_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    sheet = Surface(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0]], faces=[[0, 1, 2]], name="sheet")
    source = geobrep.write(sheet, tmp_path / "sheet.geobrep")
    out = tmp_path / "never.geobrep"
    assert main(["voxelize", str(source), str(out)]) == 1
    err = capsys.readouterr().err
    assert err.startswith("geobrep: error: ")
    assert "no closed surface" in err
    assert not out.exists()
    assert main(["voxelize", str(source), str(out), "--depth", "40"]) == 1
    assert "option 'depth'" in capsys.readouterr().err
    assert main(["voxelize", str(source), str(out), "--origin", "1,2"]) == 2  # usage error
