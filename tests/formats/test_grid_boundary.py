"""The outer boundary of grids, as the HTML viewer draws them: checked against volumes and
face counts known by hand."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from grid_shapes import build_well, faulted, rotated_grid

import geobrep
from geobrep import Plane, RegularGrid, StructuredGrid
from geobrep.adapters._grid_boundary import active_cells, grid_boundary
from geobrep.adapters.colors import ramp_colours
from geobrep.adapters.display import drawn_grids_and_wells
from geobrep.model.entities import Surface

OPENGEODE = Path(__file__).resolve().parent.parent / "data" / "opengeode"


def _enclosed(surface: Surface) -> float:
    """Signed volume enclosed by a closed triangle surface (divergence theorem)."""
    xyz = np.asarray(surface.vertices)
    xyz = xyz - xyz.mean(axis=0)  # about the centre: UTM coordinates keep their digits
    a, b, c = (xyz[surface.faces[:, m]] for m in range(3))
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def _edges_shared_twice(surface: Surface) -> bool:
    faces = np.asarray(surface.faces)
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    return bool((counts == 2).all())


def test_a_rotated_grid_is_its_parallelepiped() -> None:
    grid = rotated_grid()
    hull = grid_boundary(grid)
    assert hull.n_faces == 12
    assert hull.n_vertices == 8
    assert _enclosed(hull) == pytest.approx(grid.volume, rel=1e-12)  # outward faces
    assert _edges_shared_twice(hull)


def test_with_a_property_the_boundary_is_the_cell_faces() -> None:
    grid = rotated_grid()
    ni, nj, nk = grid.counts
    hull = grid_boundary(grid, "por")
    assert hull.n_faces == 4 * (ni * nj + nj * nk + ni * nk)
    assert _enclosed(hull) == pytest.approx(grid.volume, rel=1e-9)
    assert _edges_shared_twice(hull)
    # each triangle carries its cell's value: the cell holding its centroid
    centres = np.asarray(hull.vertices)[hull.faces].mean(axis=1)
    inward = centres + 1e-6 * (grid.bounds.center - centres)
    cells = grid.locate(inward)
    assert np.array_equal(hull.cell_data["por"].values, grid.cell_data["por"].values[cells])
    nodes = grid_boundary(grid, "t")  # a point property: the lattice points' values
    lattice = grid.points()
    found = [int(np.argmin(np.linalg.norm(lattice - p, axis=1))) for p in nodes.vertices[:20]]
    assert np.array_equal(nodes.point_data["t"].values[:20], grid.point_data["t"].values[found])


def test_a_clipped_grid_shows_its_kept_cells() -> None:
    grid = rotated_grid()
    part = geobrep.clip(grid, Plane.from_point_normal(grid.bounds.center, (1, 2, 0.5)))
    active = active_cells(part)
    assert active is not None
    assert not active.all()
    hull = grid_boundary(part)
    assert _enclosed(hull) == pytest.approx(active.sum() * grid.cell_volume, rel=1e-9)
    assert _edges_shared_twice(hull)


def test_an_inactive_cell_inside_is_a_cavity() -> None:
    points = RegularGrid(
        origin=[0, 0, 0], u=[1, 0, 0], v=[0, 2, 0], w=[0, 0.5, 1], counts=(3, 3, 3)
    ).points()
    actnum = np.ones(27, bool)
    actnum[13] = False  # the middle cell
    grid = StructuredGrid(counts=(3, 3, 3), points=points, actnum=actnum)
    hull = grid_boundary(grid)
    assert hull.n_faces == 2 * (54 + 6)
    assert _enclosed(hull) == pytest.approx(26 * 2.0, rel=1e-12)


def test_a_fault_throw_shows_both_walls() -> None:
    grid = faulted()
    hull = grid_boundary(grid)
    assert _enclosed(hull) == pytest.approx(grid.volume, rel=1e-12)
    whole = grid_boundary(faulted(throw=0.0))
    # the throw exposes the fault's faces on both sides: 4 × 3 cell faces each
    assert hull.n_faces - whole.n_faces == 2 * 2 * 4 * 3
    assert not _edges_shared_twice(whole)  # inactive cells 0 and 7 meet along an edge
    coloured = grid_boundary(grid, "poro")
    assert coloured.cell_data["poro"].values.shape == (coloured.n_faces,)


def test_the_eclipse_fault_file() -> None:
    grid = geobrep.read(OPENGEODE / "Simple20x20x5_Fault.grdecl").structured_grids[0]
    hull = grid_boundary(grid)
    # 2 (20·20 + 20·5 + 20·5) hull faces and the fault's 20 × 5 faces on each side
    assert hull.n_faces == 2 * (1200 + 200)
    assert _enclosed(hull) == pytest.approx(grid.volume, rel=1e-9)


def test_grids_and_wells_drawn_in_scene_order() -> None:
    scene = geobrep.Scene(entities=[build_well(), rotated_grid(), faulted()])
    pairs = drawn_grids_and_wells(scene)
    assert [(g.type, s.name) for g, s in pairs] == [
        ("PolyLine", "W1"), ("Surface", "g"), ("Surface", "cp")
    ]  # fmt: skip
    assert np.array_equal(pairs[0][0].vertices, build_well().vertices)


def test_ramp_colours() -> None:
    colours = ramp_colours([2.0, -1.0, 5.0, -999.0], no_data=-999.0)
    assert colours[1].tolist() == [68, 1, 84]
    assert colours[2].tolist() == [253, 231, 37]
    assert colours[3].tolist() == [153, 153, 153]
    assert ramp_colours([3.0, 3.0]).tolist()[0] == ramp_colours([0.0, 0.5, 1.0]).tolist()[1]
