"""Files geobrep writes (Voxet, Well, GRDECL) read back in OpenGeode-GeosciencesIO, the
reference C++ reader, with the same counts. Skipped when ``opengeode-geosciencesio`` is not
installed (the ``bench`` extra)."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from test_gocad_grids import deviated_well, rotated_voxet

import geobrep
from geobrep import Scene

og = pytest.importorskip("opengeode")
ogio = pytest.importorskip("opengeode_geosciencesio")

OPENGEODE = Path(__file__).resolve().parent.parent / "data" / "opengeode"


@pytest.fixture(scope="module", autouse=True)
def _libraries() -> None:
    ogio.OpenGeodeGeosciencesIOMeshLibrary.initialize()
    og.Logger.set_level(og.Logger.LEVEL.error)


def _write(data: object, path: Path, **options: object) -> Path:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return geobrep.write(data, path, **options)  # type: ignore[arg-type]


def test_a_written_voxet_has_one_reference_cell_per_node(tmp_path: Path) -> None:
    grid = rotated_voxet()
    # OpenGeode reads ASCII_DATA_FILE Voxets only (no PROP_FILE), hence voxet_ascii
    path = _write(Scene(entities=[grid]), tmp_path / "rot.vo", voxet_ascii=True)
    loaded = og.load_regular_grid3D(str(path))
    assert loaded.nb_cells() == grid.n_points  # OpenGeode: one cell around each Voxet node


def test_the_reference_voxet_written_back_keeps_its_counts(tmp_path: Path) -> None:
    scene = geobrep.read(OPENGEODE / "test.vo")
    path = _write(scene, tmp_path / "copy.vo", voxet_ascii=True)
    assert og.load_regular_grid3D(str(path)).nb_cells() == 1000


def test_a_written_well_has_the_same_stations(tmp_path: Path) -> None:
    well = deviated_well()
    path = _write(Scene(entities=[well]), tmp_path / "w.wl")
    curve = og.load_edged_curve3D(str(path))
    assert (curve.nb_vertices(), curve.nb_edges()) == (well.n_stations, well.n_cells)


@pytest.mark.parametrize(
    ("name", "cells", "corners"),
    [("EclipseGridTest.grdecl", 24, 60), ("Simple20x20x5_Fault.grdecl", 2000, 2772)],
)
def test_a_written_grdecl_has_the_same_cells_and_corners(
    name: str, cells: int, corners: int, tmp_path: Path
) -> None:
    grid = geobrep.read(OPENGEODE / name).entities[0]
    path = _write(grid, tmp_path / name)
    solid = og.load_hybrid_solid3D(str(path))
    assert (solid.nb_polyhedra(), solid.nb_vertices()) == (cells, corners)
    # the same corners, once depths are turned to z up
    points = np.array([solid.point(v).string().split() for v in range(solid.nb_vertices())], float)
    ours, _ = grid.corner_points()
    ours_depth = ours * [1.0, 1.0, -1.0]
    assert np.allclose(np.sort(points, axis=0), np.sort(ours_depth, axis=0))
