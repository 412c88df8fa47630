"""``geobrep info`` on wells and grids: depths, markers, zones and the lattice, text and JSON."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from grid_shapes import build_well, rotated_grid

import geobrep
from geobrep.cli import main


@pytest.fixture
def model(tmp_path: Path) -> Path:
    scene = geobrep.Scene(entities=[build_well(), rotated_grid()])
    return geobrep.write(scene, tmp_path / "model.geobrep")


def test_info_lists_markers_zones_and_the_lattice(
    model: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["info", str(model)]) == 0
    text = capsys.readouterr().out
    assert "marker 'topA' at MD 150 -> A" in text
    assert "zone 'unit 1' MD 150 .. 700" in text
    assert "MD 0 .. 1100 from (1000.000, 2000.000, 50.000)" in text
    assert "cells 10 × 5 × 2.02485" in text  # |u|, |v|, |w| of the rotated, sheared lattice


def test_info_json_details(model: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["info", str(model), "--json"]) == 0
    well, grid = json.loads(capsys.readouterr().out)["entities"]
    assert well["details"]["markers"] == [
        {"name": "topA", "md": 150.0, "surface": "A"},
        {"name": "topB", "md": 700.0, "surface": "B"},
    ]
    assert well["details"]["md"] == [0.0, 1100.0]
    assert well["details"]["logs"] == ["DT"]
    assert grid["details"]["axes"][0] == pytest.approx([8.660254037844387, 5.0, 0.0])
