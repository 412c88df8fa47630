"""Pictures of grids and wells: their cells, traces and markers as pyvista datasets and PNGs."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep import Plane, RegularGrid

pytest.importorskip("pyvista")

from grid_shapes import build_well, faulted, rotated_grid

from geobrep.adapters.pyvista._grids import (
    MARKER_NAMES,
    grid_to_pyvista,
    well_to_pyvista,
)

OPENGEODE = Path(__file__).resolve().parent.parent / "data" / "opengeode"


def _pixels(path: Path) -> np.ndarray:
    from PIL import Image

    with Image.open(path) as image:
        return np.asarray(image.convert("RGB"))


def test_corner_point_cells_keep_their_volume_and_skip_inactive_cells() -> None:
    grid = faulted()
    dataset = grid_to_pyvista(grid)
    assert dataset.n_cells == grid.n_active
    volumes = dataset.compute_cell_sizes(length=False, area=False)["Volume"]
    assert volumes.sum() == pytest.approx(grid.volume, rel=1e-12)
    assert np.array_equal(dataset.cell_data["poro"], grid.cell_data["poro"].values[grid.actnum])


def test_a_clipped_regular_grid_draws_its_kept_cells() -> None:
    grid = rotated_grid()
    part = geobrep.clip(grid, Plane.from_point_normal(grid.bounds.center, (1, 2, 0.5)))
    dataset = grid_to_pyvista(part)
    assert dataset.n_cells == int(part.cell_data["active"].values.sum())
    volumes = dataset.compute_cell_sizes(length=False, area=False)["Volume"]
    assert volumes.sum() == pytest.approx(dataset.n_cells * grid.cell_volume, rel=1e-9)
    whole = grid_to_pyvista(grid)
    assert whole.n_cells == grid.n_cells
    assert np.allclose(whole.points, grid.points())


def test_a_well_is_its_trace_and_labelled_markers() -> None:
    well = build_well()
    trace, markers = well_to_pyvista(well)
    assert trace.n_points == well.n_stations
    assert trace.n_cells >= 1
    assert np.array_equal(trace.point_data["md"], well.md)
    assert markers is not None
    assert list(markers.field_data[MARKER_NAMES]) == ["topA", "topB"]
    assert np.allclose(markers.points, well.marker_positions())


@pytest.mark.parametrize("name", ["test.vo", "test.wl", "Simple20x20x5_Fault.grdecl"])
def test_render_draws_grids_and_wells(tmp_path: Path, name: str) -> None:
    options = {"window_size": (320, 240), "legend": False, "axes": False, "scale_bar": False}
    out = geobrep.write(geobrep.read(OPENGEODE / name), tmp_path / "picture.png", **options)
    pixels = _pixels(out)
    assert (pixels != 255).any(axis=2).mean() > 0.001  # something is drawn on the white


def test_render_colours_a_grid_by_its_property(tmp_path: Path) -> None:
    grid = RegularGrid(origin=[0, 0, 0], u=[1, 0, 0], v=[0, 1, 0], w=[0, 0, 1], counts=(4, 4, 4),
                       cell_data={"v": np.arange(64.0)})  # fmt: skip
    scene = geobrep.Scene(entities=[grid, build_well().replace(name="w")])
    out = geobrep.write(scene, tmp_path / "p.png", color_by="property", property="v",
                        window_size=(320, 240), view="top")  # fmt: skip
    assert (
        len(np.unique(_pixels(out).reshape(-1, 3), axis=0)) > 20
    )  # a colour scale, not one colour
