"""Grid and well entities: geometry known by hand, validation errors naming the field, and the
native container keeping them bit for bit."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from test_entities import invalid

import geobrep
from geobrep import (
    Property,
    RegularGrid,
    Scene,
    StructuredGrid,
    Well,
    WellLog,
    WellMarker,
    WellZone,
)
from geobrep.geometry.trajectory import minimum_curvature

ROTATED = {
    "origin": [450_000.0, 6_700_000.0, -1200.0],
    "u": [8.660254037844387, 5.0, 0.0],
    "v": [-2.5, 4.330127018922194, 0.0],
    "w": [0.3, 0.1, 2.0],  # non-orthogonal: sheared along x and y
    "counts": (4, 3, 2),
}


def rotated_grid(**fields: object) -> RegularGrid:
    return RegularGrid(name="g", **{**ROTATED, **fields})  # type: ignore[arg-type]


def corner_point(throw: float = 0.0) -> StructuredGrid:
    """2 × 1 × 1 cells on vertical pillars, x in 0..2, y in 0..1, the second cell dropped by
    ``throw`` (a fault along x = 1)."""
    coord = [[x, y, 0.0, x, y, 100.0] for y in (0.0, 1.0) for x in (0.0, 1.0, 2.0)]
    top = np.array([10.0, 10.0 + throw])  # per cell i
    z = np.zeros((1, 2, 1, 2, 2, 2))
    for b, depth in ((0, 0.0), (1, 5.0)):
        z[0, b, 0, :, :, :] = (top + depth)[None, :, None]
    return StructuredGrid(name="cp", counts=(2, 1, 1), coord=coord, zcorn=z.ravel())


class TestRegularGrid:
    def test_counts_and_volume(self) -> None:
        grid = rotated_grid()
        assert (grid.n_cells, grid.n_points) == (24, 60)
        # u (length 10, at 30°) ⟂ v (length 5, at 120°): base area 50; w's height is 2
        assert grid.cell_volume == pytest.approx(10.0 * 5.0 * 2.0)
        assert grid.volume == pytest.approx(24 * grid.cell_volume)

    def test_points_and_centres_follow_the_axes(self) -> None:
        grid = rotated_grid()
        points = grid.points()
        u, v, w = (np.asarray(ROTATED[k]) for k in "uvw")
        origin = np.asarray(ROTATED["origin"])
        # point (i, j, k) = (1, 2, 1) is element 1 + 5 * (2 + 4 * 1)
        np.testing.assert_allclose(points[1 + 5 * (2 + 4 * 1)], origin + u + 2 * v + w)
        centres = grid.cell_centers()
        np.testing.assert_allclose(centres[0], origin + (u + v + w) / 2)
        np.testing.assert_array_equal(grid.locate(centres), np.arange(24))
        assert grid.locate([origin - u])[0] == -1

    def test_bounds_hold_every_point(self) -> None:
        grid = rotated_grid()
        bounds = grid.bounds
        assert bounds is not None
        np.testing.assert_allclose(bounds.mins, grid.points().min(axis=0))
        np.testing.assert_allclose(bounds.maxs, grid.points().max(axis=0))

    def test_properties_are_sized_by_cells_or_points(self) -> None:
        grid = rotated_grid(cell_data={"facies": np.arange(24)}, point_data={"t": np.zeros(60)})
        assert len(grid.cell_data["facies"]) == 24
        invalid(
            lambda: rotated_grid(cell_data={"f": np.zeros(23)}),
            "RegularGrid 'g'",
            "cell_data['f']",
            "23 values for 24 cells",
        )
        invalid(
            lambda: rotated_grid(point_data={"p": np.zeros(24)}),
            "RegularGrid 'g'",
            "point_data['p']",
            "24 values for 60 points",
        )

    def test_flat_axes_and_empty_counts_are_refused(self) -> None:
        invalid(
            lambda: rotated_grid(w=[1.0, 0.5773502691896257, 0.0]),
            "RegularGrid 'g'",
            "u",
            "span 3D",
        )
        invalid(lambda: rotated_grid(counts=(4, 0, 2)), "RegularGrid 'g'", "counts")


class TestStructuredGrid:
    def test_points_grid_corners_and_volume(self) -> None:
        grid = rotated_grid()
        sgrid = StructuredGrid(name="s", counts=grid.counts, points=grid.points())
        corners = sgrid.cell_corners()
        assert corners.shape == (24, 8, 3)
        u, v, w = (np.asarray(ROTATED[k]) for k in "uvw")
        np.testing.assert_allclose(corners[0, 7] - corners[0, 0], u + v + w)
        np.testing.assert_allclose(sgrid.cell_volumes, grid.cell_volume)

    def test_corner_point_geometry(self) -> None:
        grid = corner_point()
        corners = grid.cell_corners()
        np.testing.assert_allclose(corners[1, 0], [1.0, 0.0, 10.0])
        np.testing.assert_allclose(corners[1, 7], [2.0, 1.0, 15.0])
        np.testing.assert_allclose(grid.cell_volumes, [5.0, 5.0])
        points, cells = grid.corner_points()
        assert points.shape[0] == 12  # (2+1) × (1+1) pillars × top and bottom: shared corners
        assert cells.shape == (2, 8)

    def test_a_fault_throw_splits_the_corners(self) -> None:
        points, _ = corner_point(throw=2.0).corner_points()
        assert points.shape[0] == 16  # the 4 corners on the fault pillars are doubled

    def test_slanted_pillars_interpolate_xy(self) -> None:
        coord = [[x, y, 0.0, x + 10.0, y, 100.0] for y in (0.0, 1.0) for x in (0.0, 1.0)]
        grid = StructuredGrid(counts=(1, 1, 1), coord=coord, zcorn=[50.0] * 4 + [60.0] * 4)
        np.testing.assert_allclose(grid.cell_corners()[0, 0], [5.0, 0.0, 50.0])
        np.testing.assert_allclose(grid.volume, 10.0)

    def test_actnum_and_bad_sizes(self) -> None:
        grid = corner_point().replace(actnum=[True, False])
        assert grid.n_active == 1
        assert grid.volume == pytest.approx(5.0)
        base = corner_point()
        invalid(lambda: base.replace(zcorn=np.zeros(15)), "StructuredGrid 'cp'", "zcorn", "16")
        invalid(lambda: base.replace(actnum=[True]), "StructuredGrid 'cp'", "actnum")
        invalid(lambda: base.replace(coord=np.zeros((5, 6))), "StructuredGrid 'cp'", "coord")
        invalid(
            lambda: StructuredGrid(name="s", counts=(1, 1, 1)),
            "StructuredGrid 's'",
            "points",
            "either",
        )


def deviated_well() -> Well:
    """A well building angle from vertical to 60° at azimuth 45°, stations by minimum curvature."""
    md = np.arange(0.0, 1001.0, 50.0)
    inclination = np.clip((md - 200.0) * 0.1, 0.0, 60.0)
    azimuth = np.full_like(md, 45.0)
    head = np.array([451_000.0, 6_701_000.0, 120.0])
    xyz = head + minimum_curvature(md, inclination, azimuth)
    log_md = np.arange(0.0, 1000.0, 0.5)
    return Well(
        name="W-1",
        head=head,
        vertices=xyz,
        md=md,
        datum="KB",
        datum_elevation=120.0,
        markers=(
            WellMarker(name="Top A", md=412.5, surface="horizon A"),
            WellMarker(name="Top B", md=803.25, surface="horizon B"),
        ),
        zones=(WellZone(name="A", top_md=412.5, base_md=803.25),),
        logs={"GR": WellLog(md=log_md, values=np.sin(log_md), unit="API", no_data_value=-999.25)},
        point_data={"inclination": Property(values=inclination, unit="deg")},
    )


class TestWell:
    def test_stations_segments_and_markers(self) -> None:
        well = deviated_well()
        assert (well.n_stations, well.n_cells) == (21, 20)
        # the chord between two stations is never longer than the measured depth between them
        chords = np.linalg.norm(np.diff(well.vertices, axis=0), axis=1)
        assert np.all(chords <= np.diff(well.md) + 1e-9)
        assert well.length <= well.md[-1] - well.md[0] + 1e-9
        marker = well.marker_positions()[0]
        np.testing.assert_allclose(marker, well.position_at(412.5)[0])
        assert np.isnan(well.position_at(2000.0)).all()

    def test_validation(self) -> None:
        well = deviated_well()
        invalid(lambda: well.replace(md=well.md[::-1]), "Well 'W-1'", "md", "increase")
        invalid(lambda: well.replace(md=well.md[:-1]), "Well 'W-1'", "md", "20 depths")
        off = (WellMarker(name="deep", md=5000.0),)
        invalid(lambda: well.replace(markers=off), "Well 'W-1'", "markers[0]", "deep")
        with pytest.raises(ValueError, match="base_md"):
            WellZone(name="z", top_md=10, base_md=5)
        with pytest.raises(ValueError, match="values for"):
            WellLog(md=[0, 1], values=[1.0])


class TestMinimumCurvature:
    def test_vertical_and_straight_slant(self) -> None:
        xyz = minimum_curvature([0, 100, 200], [0, 0, 0], [0, 0, 0])
        np.testing.assert_allclose(xyz, [[0, 0, 0], [0, 0, -100], [0, 0, -200]])
        slant = minimum_curvature([0, 100], [30, 30], [90, 90])
        np.testing.assert_allclose(slant[1], [50.0, 0.0, -100 * np.cos(np.pi / 6)], atol=1e-12)

    def test_an_arc_keeps_its_length(self) -> None:
        # vertical to horizontal over 100 m of MD: a quarter circle of radius 200/π
        xyz = minimum_curvature([0, 100], [0, 90], [0, 0])
        radius = 200.0 / np.pi
        np.testing.assert_allclose(xyz[1], [0.0, radius, -radius], atol=1e-9)


@pytest.mark.parametrize(
    "entity",
    [
        rotated_grid(
            cell_data={"facies": np.arange(24, dtype=np.int32)},
            point_data={
                "t": Property(
                    values=np.linspace(0, 1, 60, dtype=np.float32), no_data_value=float("nan")
                )
            },
        ),
        corner_point(throw=2.0).replace(actnum=[True, False], cell_data={"poro": [0.2, 0.3]}),
        StructuredGrid(name="s", counts=(4, 3, 2), points=rotated_grid().points()),
        deviated_well(),
    ],
    ids=["regular", "corner-point", "curvilinear", "well"],
)
def test_native_round_trip_is_exact(entity: object, tmp_path: Path) -> None:
    scene = Scene(entities=[entity], crs=geobrep.CRS(epsg=32631))
    path = geobrep.write(scene, tmp_path / "grid.geobrep")
    back = geobrep.read(path)
    assert back.entities[0] == scene.entities[0]
    assert back.crs == scene.crs
