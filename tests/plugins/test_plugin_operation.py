"""An operation a plugin registers (the example plugin's ``thin``): a Python function, a
``geobrep`` command, a pipeline step and a ``geobrep plugins`` line, all from one declaration."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import geobrep
import geobrep.plugins
from geobrep.cli import main


@pytest.fixture
def points(example_plugin: Path, tmp_path: Path) -> Path:
    geobrep.plugins.reload()
    cloud = geobrep.PointSet(
        vertices=np.arange(30.0).reshape(10, 3),
        name="survey",
        point_data={"depth": np.arange(10.0)},
    )
    path = tmp_path / "points.geobrep"
    geobrep.write(geobrep.Scene(entities=[cloud]), path)
    return path


def test_python_function(points: Path) -> None:
    spec = geobrep.plugins.registries().operations.get("thin")
    assert spec.plugin == "example"
    thinned = spec(geobrep.read(points), every=3, first=1)
    [cloud] = thinned.point_sets
    np.testing.assert_array_equal(cloud.point_data["depth"].values, [1.0, 4.0, 7.0])
    np.testing.assert_array_equal(cloud.vertices[:, 0], [3.0, 12.0, 21.0])
    with pytest.raises(geobrep.OptionsError, match="every"):
        spec(geobrep.read(points), every=0)


def test_command(points: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "thin.geobrep"
    assert main(["thin", str(points), str(out), "--every", "4"]) == 0
    [cloud] = geobrep.read(out).point_sets
    np.testing.assert_array_equal(cloud.point_data["depth"].values, [0.0, 4.0, 8.0])
    assert "thin.geobrep: 1 entities (thin)" in capsys.readouterr().out
    assert main(["thin", str(points), str(out), "--evry", "4"]) == 2
    err = capsys.readouterr().err
    assert "unknown option '--evry' (did you mean '--every'?)" in err
    assert "usage: geobrep thin" in err  # the command's own usage
    assert main(["thin", str(points), str(out), "--every", "0"]) == 1
    assert "--every: Input should be greater than or equal to 1" in capsys.readouterr().err


def test_pipeline_step(points: Path, tmp_path: Path) -> None:
    summary = geobrep.run_pipeline(
        {
            "inputs": [str(points)],
            "output": str(tmp_path / "out"),
            "steps": [{"thin": {"every": 5}}, {"write": {"format": "native"}}],
        }
    )
    assert summary.ok, summary.table()
    assert [s.kind for s in summary.reports[0].steps] == ["read", "thin", "write"]
    [cloud] = geobrep.read(tmp_path / "out" / "points.geobrep").point_sets
    np.testing.assert_array_equal(cloud.point_data["depth"].values, [0.0, 5.0])
    bad = {"steps": [{"thin": {"evry": 5}}, {"write": {"format": "native"}}]}
    with pytest.raises(geobrep.OptionsError, match=r"step 1 \(thin\).*'evry'"):
        geobrep.Pipeline.from_data(bad).check()


def test_plugins_line(points: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["plugins", "--json"]) == 0
    infos = {info["name"]: info for info in json.loads(capsys.readouterr().out)}
    assert infos["example"]["registered"]["operations"] == ["thin"]
    assert main(["plugins"]) == 0
    assert "    operations: thin" in capsys.readouterr().out
