"""``geobrep clip`` and ``geobrep section`` on the command line."""

from __future__ import annotations

from pathlib import Path

import pytest

import geobrep
from geobrep.cli.main import main


@pytest.fixture(scope="module")
def model(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("cli") / "cake.geobrep"
    geobrep.write(geobrep.datasets.faulted_layer_cake(), path)
    return path


def test_clip_one_side(model: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "west.geobrep"
    assert main(["clip", str(model), str(out), "--x", "450500"]) == 0
    west = geobrep.read(out)
    assert west.bounds.maxs[0] == pytest.approx(450_500.0)
    assert "cap patches" in capsys.readouterr().out


def test_clip_both_writes_two_files(model: Path, tmp_path: Path) -> None:
    out = tmp_path / "cut.geobrep"
    assert main(["clip", str(model), str(out), "--plane", "0,1,0,-6700400", "--keep", "both"]) == 0
    negative = geobrep.read(tmp_path / "cut-negative.geobrep")
    positive = geobrep.read(tmp_path / "cut-positive.geobrep")
    assert negative.bounds.maxs[1] == pytest.approx(6_700_400.0)
    assert positive.bounds.mins[1] == pytest.approx(6_700_400.0)
    assert not out.exists()


def test_clip_box(model: Path, tmp_path: Path) -> None:
    out = tmp_path / "column.geobrep"
    box = "450200,450700,6700100,6700600,-650,100"
    assert main(["clip", str(model), str(out), "--box", box]) == 0
    column = geobrep.read(out)
    assert column.bounds.as_tuple()[:4] == pytest.approx((450_200, 450_700, 6_700_100, 6_700_600))
    assert main(["clip", str(model), str(out), "--box", box, "--keep", "both"]) == 1


def test_section(model: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "panel.geobrep"
    assert main(["section", str(model), str(out), "--z", "-300"]) == 0
    panel = geobrep.read(out)
    assert all(e.bounds.mins[2] == pytest.approx(-300.0) for e in panel.entities)
    assert "block sections" in capsys.readouterr().out


def test_bad_arguments(model: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "x.geobrep"
    assert main(["clip", str(model), str(out), "--plane", "1,2"]) == 2  # a malformed value
    assert "--plane: expected 4" in capsys.readouterr().err
    assert main(["clip", str(model), str(out)]) == 2  # a plane option is required
    assert main(["clip", str(tmp_path / "missing.geobrep"), str(out), "--x", "1"]) == 1
    assert not out.exists()
