"""Pipelines read, clip, section and write grids and wells (.vo, .wl)."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep.cli.main import main

OPENGEODE = Path(__file__).resolve().parent.parent / "data" / "opengeode"


@pytest.fixture
def data(tmp_path: Path) -> Path:
    folder = tmp_path / "data"
    folder.mkdir()
    for name in ("test.vo", "test__ascii@@", "test.wl"):
        shutil.copy(OPENGEODE / name, folder / name)
    return folder


def _run(tmp_path: Path, body: str, capsys: pytest.CaptureFixture[str]) -> None:
    pipeline = tmp_path / "pipeline.yaml"
    pipeline.write_text(body, encoding="utf-8")
    assert main(["run", str(pipeline)]) == 0, capsys.readouterr().err


@pytest.mark.parametrize("name", ["{stem}.vo", "{stem}.geobrep"])
def test_a_voxet_is_read_clipped_and_written(
    data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str
) -> None:
    voxet = geobrep.read(data / "test.vo").entities[0]
    body = (
        "inputs: [data/test.vo]\noutput: out\nsteps:\n"
        "  - clip: {plane: [1, 0, 0, -450], keep: negative}\n"
        f"  - write: {{name: '{name}'}}\n"
    )
    _run(tmp_path, body, capsys)
    back = geobrep.read(tmp_path / "out" / name.format(stem="test")).entities[0]
    # whole cells whose centre has x < 450: the cells of i = 0 .. 3 (x 0..400 by 100)
    expected = int((voxet.cell_centers()[:, 0] < 450.0).sum())
    assert back.n_cells == expected
    assert back.counts == (4, 9, 9)
    assert np.allclose(back.origin, voxet.origin)


def test_a_well_is_read_clipped_and_written(
    data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    well = geobrep.read(data / "test.wl").entities[0]
    z = float(np.median(well.vertices[:, 2]))
    body = (
        "inputs: [data/test.wl]\noutput: out\nsteps:\n"
        f"  - clip: {{plane: [0, 0, 1, {-z}], keep: positive}}\n"
        "  - write: {name: '{stem}.wl'}\n"
    )
    _run(tmp_path, body, capsys)
    back = geobrep.read(tmp_path / "out" / "test.wl").entities[0]
    assert back.md[0] == pytest.approx(well.md[0])
    assert back.vertices[-1, 2] == pytest.approx(z, abs=1e-6)
    assert well.md[0] < back.md[-1] < well.md[-1]
    assert np.allclose(well.position_at([back.md[-1]]), back.vertices[-1:], atol=1e-6)


def test_a_section_step_writes_the_well_on_the_section(
    data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    well = geobrep.read(data / "test.wl").entities[0]
    x = float(np.median(well.vertices[:, 0]))
    body = (
        "inputs: [data/test.wl]\noutput: out\nsteps:\n"
        f"  - section: {{plane: [1, 0, 0, {-x}], options: {{well: {{within: 20}}}}}}\n"
        "  - write: {format: native}\n"
    )
    _run(tmp_path, body, capsys)
    trace = geobrep.read(tmp_path / "out" / "test.geobrep").entities[0]
    assert trace.type == "PolyLine"
    assert np.abs(trace.vertices[:, 0] - x).max() < 1e-6
    assert np.abs(trace.point_data["offset"].values).max() <= 20.0 + 1e-9
