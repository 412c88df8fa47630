"""Eclipse GRDECL: the reference files' cell and corner counts, geometry read by hand from the
file, exact round trips (reference files and a generated faulted grid) and FormatErrors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep import FormatError, Scene, StructuredGrid

OPENGEODE = Path(__file__).resolve().parent.parent / "data" / "opengeode"


def faulted_grid() -> StructuredGrid:
    """3 × 2 × 2 cells on slanted pillars; the cells with i = 2 thrown down 7.5 m (a fault
    between pillar columns 1 and 2... on the ZCORN only), two inactive cells, two properties."""
    ni, nj, nk = 3, 2, 2
    xs, ys = np.meshgrid(np.arange(ni + 1) * 50.0, np.arange(nj + 1) * 40.0)
    top = np.stack([xs.ravel(), ys.ravel(), np.full(xs.size, -1000.0)], axis=1)
    coord = np.hstack([top, top + np.array([5.0, -2.5, -200.0])])
    depth = np.empty((nk, 2, nj, 2, ni, 2))
    for k in range(nk):
        for b in range(2):
            depth[k, b] = 1000.0 + 20.0 * (k + b)
    depth[:, :, :, :, 2, :] += 7.5
    actnum = np.ones(ni * nj * nk, dtype=bool)
    actnum[[4, 9]] = False
    return StructuredGrid(
        name="faulted",
        counts=(ni, nj, nk),
        coord=coord,
        zcorn=-depth.ravel(),
        actnum=actnum,
        cell_data={"PORO": np.linspace(0.05, 0.3, 12), "SATNUM": np.arange(12, dtype=np.int32) % 3},
    )


@pytest.mark.parametrize(
    ("name", "cells", "corners"),
    [("EclipseGridTest.grdecl", 24, 60), ("Simple20x20x5_Fault.grdecl", 2000, 2772)],
)
def test_reference_counts(name: str, cells: int, corners: int) -> None:
    grid = geobrep.read(OPENGEODE / name).entities[0]
    assert isinstance(grid, StructuredGrid)
    assert grid.n_cells == cells
    points, cell_corners = grid.corner_points()
    assert points.shape[0] == corners  # distinct corners: the fault doubles those it splits
    assert cell_corners.shape == (cells, 8)


def test_reference_geometry_from_the_file() -> None:
    grid = geobrep.read(OPENGEODE / "EclipseGridTest.grdecl").entities[0]
    assert isinstance(grid, StructuredGrid)
    assert grid.counts == (2, 3, 4)
    assert grid.coord is not None
    # first pillar "1000 2000 1000 / 1100 2000 1100": depths become z up
    np.testing.assert_array_equal(grid.coord[0], [1000, 2000, -1000, 1100, 2000, -1100])
    # the first cell's top corners are at depth 1000 on the slanted pillars: x = y-pillar x
    np.testing.assert_allclose(grid.cell_corners()[0, 0], [1000.0, 2000.0, -1000.0])
    assert grid.n_active == int(np.count_nonzero(grid.actnum)) if grid.actnum is not None else 24
    assert "AGE" in grid.cell_data


@pytest.mark.parametrize("name", ["EclipseGridTest.grdecl", "Simple20x20x5_Fault.grdecl"])
def test_reference_round_trip(name: str, tmp_path: Path) -> None:
    grid = geobrep.read(OPENGEODE / name).entities[0]
    back = geobrep.read(geobrep.write(grid, tmp_path / name)).entities[0]
    assert back == grid.replace(name=Path(name).stem)


def test_generated_faulted_grid_round_trip(tmp_path: Path) -> None:
    grid = faulted_grid()
    path = geobrep.write(Scene(entities=[grid.replace(id=0)]), tmp_path / "faulted.grdecl")
    back = geobrep.read(path).entities[0]
    assert back == grid.replace(id=0)
    assert back.cell_data["SATNUM"].values.dtype == np.int32
    points, _ = back.corner_points()
    # 4 x 3 pillars x 3 depth levels shared, plus the fault pillars' column doubled
    assert points.shape[0] == 4 * 3 * 3 + 3 * 3
    # active volume: 10 cells of 50 x 40 x 20 (slanted pillars shear, they keep the volume)
    assert back.volume == pytest.approx(10 * 50 * 40 * 20)


def test_repeats_comments_and_errors(tmp_path: Path) -> None:
    path = tmp_path / "r.grdecl"
    pillars = " ".join(f"{x} {y} 0 {x} {y} 10" for y in (0, 1) for x in (0, 1))
    path.write_text(
        f"-- a comment\nSPECGRID\n1 1 1 1 F /\nCOORD\n{pillars} /\nZCORN\n4*1 4*3 /\n"
        "PORO\n0.25 / -- trailing\n"
    )
    grid = geobrep.read(path).entities[0]
    assert isinstance(grid, StructuredGrid)
    assert grid.volume == pytest.approx(2.0)
    assert grid.cell_data["PORO"].values.tolist() == [0.25]
    path.write_text(path.read_text().replace("4*1 4*3", "4*1 3*3"))
    with pytest.raises(FormatError, match="ZCORN has 7 values") as info:
        geobrep.read(path)
    assert info.value.line == 6
