"""Clip and section of RegularGrid, StructuredGrid and Well entities, checked against truth."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from grid_shapes import RADIUS, build_well, faulted, rotated_grid

import geobrep
from geobrep import (
    Plane,
    RegularGrid,
    StructuredGrid,
    Well,
)
from geobrep.ops.clipping import clip, section
from geobrep.plugins.clip._wells import WellClipWarning

DATA = Path(__file__).resolve().parent.parent / "data" / "opengeode"


def oblique(grid: RegularGrid) -> Plane:
    bounds = grid.bounds
    assert bounds is not None
    return Plane.from_point_normal(bounds.center + np.array([1.3, -0.7, 0.4]), (0.6, 0.3, 0.75))


def _corners(grid: RegularGrid) -> np.ndarray:
    """Every cell's eight corners ``(n, 8, 3)`` from the lattice, the slow obvious way."""
    points = grid.points()
    ni, nj, _ = grid.counts
    out = np.empty((grid.n_cells, 8, 3))
    for c in range(grid.n_cells):
        i, j, k = c % ni, (c // ni) % nj, c // (ni * nj)
        for m, (x, y, z) in enumerate((x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)):
            out[c, m] = points[(i + x) + (ni + 1) * ((j + y) + (nj + 1) * (k + z))]
    return out


def _kept_cells(part: RegularGrid | None) -> int:
    if part is None:
        return 0
    if "active" in part.cell_data:
        return int(part.cell_data["active"].values.sum())
    return part.n_cells


class TestRegularGridClip:
    def test_centre_rule_partitions_the_cells_as_the_centres_say(self) -> None:
        grid = rotated_grid()
        plane = oblique(grid)
        negative, positive = clip(grid, plane, keep="both")
        distances = plane.signed_distance(grid.cell_centers())
        on_negative = distances < -1e-9 * grid.bounds.diagonal  # type: ignore[union-attr]
        assert _kept_cells(negative) == int(on_negative.sum())
        assert _kept_cells(positive) == int((~on_negative).sum())
        assert _kept_cells(negative) + _kept_cells(positive) == grid.n_cells
        # the kept volume is whole cells
        kept_volume = _kept_cells(negative) * negative.cell_volume
        assert kept_volume == pytest.approx(on_negative.sum() * grid.cell_volume, rel=1e-12)

    def test_kept_cells_carry_their_own_properties(self) -> None:
        grid = rotated_grid()
        part = clip(grid, oblique(grid), keep="positive")
        source = grid.locate(part.cell_centers())
        assert (source >= 0).all()
        assert np.array_equal(part.cell_data["por"].values, grid.cell_data["por"].values[source])
        assert np.array_equal(
            part.cell_data["facies"].values, grid.cell_data["facies"].values[source]
        )
        kept = part.cell_data["active"].values == 1
        centres = part.cell_centers()
        assert (oblique(grid).signed_distance(centres[kept]) >= 0).all()
        assert (oblique(grid).signed_distance(centres[~kept]) < 0).all()
        point_source = [
            int(np.argmin(np.linalg.norm(grid.points() - p, axis=1))) for p in part.points()[:50]
        ]
        assert (
            part.point_data["t"].values[:50].tolist()
            == grid.point_data["t"].values[point_source].tolist()
        )

    @pytest.mark.parametrize("rule", ["inside", "touching"])
    def test_inside_and_touching_follow_the_corners(self, rule: str) -> None:
        grid = rotated_grid()
        plane = oblique(grid)
        d = plane.signed_distance(_corners(grid).reshape(-1, 3)).reshape(-1, 8)
        tolerance = 1e-9 * grid.bounds.diagonal  # type: ignore[union-attr]
        want = (d.max(axis=1) <= tolerance) if rule == "inside" else (d.min(axis=1) < -tolerance)
        part = clip(grid, plane, options={"regular_grid": {"cells": rule}})
        assert _kept_cells(part) == int(want.sum())

    def test_a_plane_on_cell_faces_crops_the_grid_exactly(self) -> None:
        grid = RegularGrid(origin=[0, 0, 0], u=[2, 0, 0], v=[0, 1, 0], w=[0, 0, 0.5],
                           counts=(10, 4, 6), cell_data={"v": np.arange(240.0)})  # fmt: skip
        below, above = clip(grid, Plane.z(1.0), keep="both")
        assert below.counts == (10, 4, 2)
        assert above.counts == (10, 4, 4)
        assert "active" not in below.cell_data
        assert above.origin.tolist() == [0.0, 0.0, 1.0]
        assert below.volume + above.volume == grid.volume
        assert above.cell_data["v"].values[0] == 80.0
        assert clip(grid, Plane.z(-1.0), keep="positive") is grid
        assert clip(grid, Plane.z(-1.0), keep="negative") is None

    def test_an_existing_active_property_is_combined(self) -> None:
        n = 4 * 4 * 1
        active = np.ones(n, np.uint8)
        active[0] = 0
        grid = RegularGrid(origin=[0, 0, 0], u=[1, 0, 0], v=[0, 1, 0], w=[0, 0, 1],
                           counts=(4, 4, 1), cell_data={"active": active})  # fmt: skip
        part = clip(grid, Plane(1, 1, 0, -4.0))  # x + y < 4 by centre: 6 cells
        assert part.cell_data["active"].values.sum() == 6 - 1


def _box_section_area(corner: np.ndarray, axes: np.ndarray, plane: Plane) -> float:
    """Area of the plane inside a parallelepiped, from its 12 edge crossings (convex polygon)."""
    points = []
    cube = [np.array([x, y, z]) for z in (0, 1) for y in (0, 1) for x in (0, 1)]
    for a in range(8):
        for b in range(a + 1, 8):
            if np.abs(cube[a] - cube[b]).sum() != 1:
                continue
            pa, pb = corner + cube[a] @ axes, corner + cube[b] @ axes
            da, db = plane.signed_distance(np.stack([pa, pb]))
            if da * db < 0:
                points.append(pa + da / (da - db) * (pb - pa))
    pts = np.array(points)
    centre = pts.mean(axis=0)
    e1 = pts[0] - centre
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(plane.normal, e1)
    angle = np.arctan2((pts - centre) @ e2, (pts - centre) @ e1)
    ring = pts[np.argsort(angle)]
    total = np.zeros(3)
    for i in range(len(ring)):
        total += np.cross(ring[i] - centre, ring[(i + 1) % len(ring)] - centre)
    return float(np.linalg.norm(total) / 2)


class TestRegularGridSection:
    def test_area_and_cells_of_an_oblique_section(self) -> None:
        grid = rotated_grid()
        plane = oblique(grid)
        cut = section(grid, plane)
        axes = grid.axes * np.array(grid.counts)[:, None]
        assert cut.area == pytest.approx(_box_section_area(grid.origin, axes, plane), rel=1e-10)
        centroids = cut.vertices[cut.faces].mean(axis=1)
        assert np.abs(plane.signed_distance(cut.vertices)).max() < 1e-6
        cells = cut.cell_data["grid_cell"].values
        assert np.array_equal(grid.locate(centroids), cells)
        assert np.array_equal(cut.cell_data["por"].values, grid.cell_data["por"].values[cells])
        a, b, c = (cut.vertices[cut.faces[:, m]] for m in range(3))
        normals = np.cross(b - a, c - a)
        assert (normals @ plane.normal > 0).all()
        # the point data is the lattice's linear function of the point index, interpolated
        assert cut.point_data["t"].values.shape == (cut.n_vertices,)

    def test_a_section_on_a_layer_of_faces_is_one_layer(self) -> None:
        grid = RegularGrid(origin=[0, 0, 0], u=[2, 0, 0], v=[0, 1, 0], w=[0, 0, 0.5],
                           counts=(10, 4, 6))  # fmt: skip
        cut = section(grid, Plane.z(1.0))
        assert cut.area == pytest.approx(80.0, rel=1e-12)
        assert cut.n_vertices == 11 * 5  # the lattice points of that layer, each once
        assert section(grid, Plane.z(10.0)) is None

    def test_point_data_is_interpolated_on_the_edges(self) -> None:
        grid = RegularGrid(origin=[0, 0, 0], u=[1, 0, 0], v=[0, 1, 0], w=[0, 0, 1],
                           counts=(3, 3, 3))  # fmt: skip
        heights = grid.points()[:, 2] * 10.0
        grid = grid.replace(point_data={"h": heights})
        cut = section(grid, Plane(0.2, 0.1, 1.0, -1.7))
        assert np.allclose(cut.point_data["h"].values, cut.vertices[:, 2] * 10.0)


class TestStructuredGrid:
    def test_clip_keeps_active_cells_by_centre(self) -> None:
        grid = faulted()
        plane = Plane.from_point_normal([2.5, 2.0, 13.5], [0.3, 0.2, 1.0])
        centres = grid.cell_corners().mean(axis=1)
        d = plane.signed_distance(centres)
        negative, positive = clip(grid, plane, keep="both")
        assert negative.n_active == int(((d < 0) & grid.actnum).sum())
        assert positive.n_active == int(((d >= 0) & grid.actnum).sum())
        assert negative.volume + positive.volume == pytest.approx(grid.volume, rel=1e-12)
        for part in (negative, positive):
            kept_centres = part.cell_corners().mean(axis=1)
            source = [int(np.argmin(np.linalg.norm(centres - c, axis=1))) for c in kept_centres]
            assert np.array_equal(
                part.cell_data["poro"].values, grid.cell_data["poro"].values[source]
            )
            assert not (part.actnum & ~grid.actnum[source]).any()  # inactive stays inactive

    def test_a_horizontal_cut_crops_the_layers(self) -> None:
        grid = faulted(throw=0.0)
        top = clip(grid, Plane.z(14.0), keep="negative")
        assert top.counts == (6, 4, 2)
        assert top.zcorn.max() == 14.0
        assert top.n_active == 6 * 4 * 2 - 3  # cells 0, 7 and 30 are inactive

    def test_points_grid_clip_and_section(self) -> None:
        box = RegularGrid(origin=[0, 0, 0], u=[1, 0, 0], v=[0, 2, 0], w=[0, 0, 1], counts=(4, 3, 2))
        grid = StructuredGrid(counts=(4, 3, 2), points=box.points(),
                              point_data={"x": box.points()[:, 0]})  # fmt: skip
        part = clip(grid, Plane.x(2.0), keep="positive")
        assert part.counts == (2, 3, 2)
        assert part.points[:, 0].min() == 2.0
        assert part.point_data["x"].values.min() == 2.0
        plane = Plane.from_point_normal([2.1, 3.0, 1.0], [1.0, 0.4, 0.2])
        cut = section(grid, plane)
        assert cut.area == pytest.approx(
            _box_section_area(np.zeros(3), box.axes * [[4], [3], [2]], plane)
        )
        assert np.allclose(cut.point_data["x"].values, cut.vertices[:, 0])

    def test_section_of_a_faulted_grid_skips_inactive_cells(self) -> None:
        grid = faulted()
        cut = section(grid, Plane.x(1.5))
        cells = set(cut.cell_data["grid_cell"].values.tolist())
        assert cells.isdisjoint({0, 7, 30})
        # x = 1.5 crosses cells i = 1: 4 × 3 cells of 1 × 2 faces, less the inactive cell 7
        assert cut.area == pytest.approx(2.0 * (4 * 3 - 1), rel=1e-12)


# ------------------------------------------------------------------------------- wells
def _arc_md(depth_below_kickoff: float) -> float:
    """MD where the build arc reaches ``depth_below_kickoff`` below the kickoff point."""
    return 200.0 + RADIUS * float(np.arcsin(depth_below_kickoff / RADIUS))


class TestWell:
    def test_positions_between_stations_follow_the_arc(self) -> None:
        well = build_well()
        md = np.array([215.0, 512.5, 1000.0])
        phi = (md - 200.0) / RADIUS
        horizontal = RADIUS * (1.0 - np.cos(phi))
        azimuth = np.radians(60.0)
        expected = well.head + np.stack(
            [
                horizontal * np.sin(azimuth),
                horizontal * np.cos(azimuth),
                -200.0 - RADIUS * np.sin(phi),
            ],
            axis=1,
        )
        np.testing.assert_allclose(well.position_at(md), expected, atol=1e-9)
        straight = Well(head=well.head, vertices=well.vertices, md=well.md)  # no angles: chords
        assert np.abs(straight.position_at(md) - expected).max() > 0.01

    def test_the_cut_is_at_the_md_of_the_minimum_curvature_arc(self) -> None:
        well = build_well()
        z = 50.0 - 200.0 - 300.0  # 300 m below the kickoff
        deep, shallow = clip(well, Plane.z(z), keep="both")
        expected = _arc_md(300.0)
        assert shallow.md[-1] == pytest.approx(expected, abs=1e-9)
        assert deep.md[0] == shallow.md[-1]
        assert deep.vertices[0, 2] == pytest.approx(z, abs=1e-9)
        # a straight chord between the stations would put it elsewhere: the test can fail
        chord = np.interp(-z, -well.vertices[:, 2], well.md)
        assert abs(chord - expected) > 1e-3
        # the new station's angles are the arc's
        assert shallow.point_data["INCL"].values[-1] == pytest.approx(
            (expected - 200) / 10.0, abs=1e-9
        )
        assert shallow.point_data["AZIM_GN"].values[-1] == pytest.approx(60.0, abs=1e-9)

    def test_markers_zones_and_logs_follow_the_kept_part(self) -> None:
        well = build_well()
        cut = _arc_md(300.0)
        lower, upper = clip(well, Plane.z(50.0 - 500.0), keep="both")
        assert [m.name for m in lower.markers] == ["topB"]
        assert [m.name for m in upper.markers] == ["topA"]
        assert upper.zones[0].top_md == 150.0
        assert upper.zones[0].base_md == pytest.approx(cut)
        assert lower.zones[0].top_md == pytest.approx(cut)
        assert lower.zones[0].base_md == 700.0
        assert upper.logs["DT"].md.max() <= cut <= lower.logs["DT"].md.min()
        assert upper.logs["DT"].md.size + lower.logs["DT"].md.size == well.logs["DT"].md.size
        assert np.allclose(lower.marker_positions(), well.marker_positions()[1:], atol=1e-9)
        assert upper.head.tolist() == well.head.tolist()

    def test_a_trajectory_crossing_twice_keeps_the_shallowest_stretch(self) -> None:
        well = Well(head=[0, 0, 0], vertices=[[0, 0, 0], [10, 0, 0], [10, 0, -10], [0, 0, -10]],
                    md=[0, 10, 20, 30])  # fmt: skip
        with pytest.warns(WellClipWarning, match="2 stretches"):
            part = clip(well, Plane.x(5.0), keep="negative")
        assert part.md.tolist() == [0.0, 5.0]
        assert part.metadata["clip"]["md_intervals"] == [[0.0, 5.0], [25.0, 30.0]]
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            assert clip(well, Plane.x(5.0), keep="positive").md.tolist() == [5.0, 10.0, 20.0, 25.0]

    def test_section_points_and_the_well_on_a_section(self) -> None:
        well = build_well()
        z = 50.0 - 200.0 - 300.0
        points = section(well, Plane.z(z))
        assert points.point_data["md"].values.tolist() == pytest.approx([_arc_md(300.0)])
        # a vertical section along the azimuth holds the well; one across it, a short stretch
        along = Plane.from_point_normal(
            well.head, [np.cos(np.radians(60)), -np.sin(np.radians(60)), 0]
        )
        trace = section(well, along, options={"well": {"within": 1.0}})
        assert trace.point_data["md"].values[[0, -1]].tolist() == [0.0, 1100.0]
        assert np.abs(along.signed_distance(trace.vertices)).max() < 1e-6
        assert [m["name"] for m in trace.metadata["markers"]] == ["topA", "topB"]
        across = Plane.from_point_normal(
            well.position_at([600.0])[0], [np.sin(np.radians(60)), np.cos(np.radians(60)), 0]
        )
        band = section(well, across, options={"well": {"within": 25.0}})
        assert np.abs(band.point_data["offset"].values).max() <= 25.0 + 1e-9
        assert band.point_data["md"].values.min() < 600.0 < band.point_data["md"].values.max()
        assert np.abs(across.signed_distance(band.vertices)).max() < 1e-6

    def test_gocad_read_back_of_a_clipped_well(self, tmp_path: Path) -> None:
        well = build_well()
        part = clip(well, Plane.z(-400.0), keep="positive")
        path = geobrep.write(geobrep.Scene(entities=[part]), tmp_path / "w.wl")
        back = geobrep.read(path).entities[0]
        assert np.allclose(back.md, part.md)
        assert np.allclose(back.vertices, part.vertices)
        assert [m.name for m in back.markers] == [m.name for m in part.markers]


def test_scene_of_a_voxet_and_a_well_clips_and_writes(tmp_path: Path) -> None:
    voxet = geobrep.read(DATA / "test.vo")
    grid = voxet.entities[0]
    assert isinstance(grid, RegularGrid)
    bounds = grid.bounds
    assert bounds is not None
    plane = Plane.from_point_normal(bounds.center, (1.0, 0.0, 0.0))
    part = clip(voxet, plane, keep="negative")
    clipped = part.entities[0]
    centres = plane.signed_distance(grid.cell_centers())
    assert _kept_cells(clipped) == int((centres < 0).sum())
    out = geobrep.write(part, tmp_path / "half.vo")
    back = geobrep.read(out).entities[0]
    assert back.counts == clipped.counts
    assert np.allclose(back.origin, clipped.origin)
