"""Property tests: random planes share a grid's cells out exactly once and cut wells seamlessly."""

from __future__ import annotations

import warnings

import numpy as np
from grid_shapes import build_well, rotated_grid
from hypothesis import given
from hypothesis import strategies as st

from geobrep import Plane, RegularGrid, StructuredGrid
from geobrep.ops.clipping import clip, section
from geobrep.plugins.clip._wells import WellClipWarning

unit = st.floats(-1.0, 1.0, allow_nan=False)


def _plane(grid: RegularGrid, normal: tuple[float, float, float], offset: float) -> Plane | None:
    if np.linalg.norm(normal) < 1e-3:
        return None
    bounds = grid.bounds
    assert bounds is not None
    corner = np.asarray(bounds.as_tuple())[[1, 3, 5]]
    point = bounds.center + offset * (corner - bounds.center)
    return Plane.from_point_normal(point, normal)


def _kept(part: RegularGrid | StructuredGrid | None) -> int:
    if part is None:
        return 0
    if isinstance(part, StructuredGrid):
        return part.n_active
    return (
        int(part.cell_data["active"].values.sum()) if "active" in part.cell_data else part.n_cells
    )


@given(normal=st.tuples(unit, unit, unit), offset=st.floats(-1.2, 1.2))
def test_both_sides_share_the_cells_out_once(
    normal: tuple[float, float, float], offset: float
) -> None:
    grid = rotated_grid()
    plane = _plane(grid, normal, offset)
    if plane is None:
        return
    negative, positive = clip(grid, plane, keep="both")
    assert _kept(negative) + _kept(positive) == grid.n_cells
    as_structured = StructuredGrid(counts=grid.counts, points=grid.points(),
                                   cell_data=grid.cell_data)  # fmt: skip
    parts = clip(as_structured, plane, keep="both")
    assert [_kept(p) for p in parts] == [_kept(negative), _kept(positive)]
    cut = section(grid, plane)
    if cut is not None:
        assert np.abs(plane.signed_distance(cut.vertices)).max() < 1e-6
        centroids = cut.vertices[cut.faces].mean(axis=1)
        assert np.array_equal(grid.locate(centroids), cut.cell_data["grid_cell"].values)


@given(normal=st.tuples(unit, unit, unit), depth=st.floats(0.0, 1.0))
def test_a_well_cut_on_either_side_meets_at_the_cut(
    normal: tuple[float, float, float], depth: float
) -> None:
    well = build_well()
    if np.linalg.norm(normal) < 1e-3:
        return
    point = well.position_at([well.md[0] + depth * (well.md[-1] - well.md[0])])[0]
    plane = Plane.from_point_normal(point, normal)
    crossings = section(well, plane)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", WellClipWarning)  # several stretches: the first is kept
        negative, positive = clip(well, plane, keep="both")
    for part in (negative, positive):
        if part is None:
            continue
        # every kept station is on its side or on the plane, and the path stays the well's
        assert np.allclose(well.position_at(part.md), part.vertices, atol=1e-6)
    if crossings is not None:
        where = well.position_at(crossings.point_data["md"].values)
        assert np.abs(plane.signed_distance(where)).max() < 1e-6
