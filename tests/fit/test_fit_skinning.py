"""NURBS skinning: exact through every point, rows of different counts, sections, bad input."""

from __future__ import annotations

import numpy as np
import pytest

import geobrep
from geobrep import PointSet, PolyLine
from geobrep.errors import DegenerateGeometryError, EntityValidationError, OptionsError
from geobrep.ops.fitting import fit
from geobrep.plugins.fit._curves import interpolate_curve, surface_boundary
from geobrep.plugins.fit._knots import insert_knots, merge_knots, missing_knots
from geobrep.plugins.fit._skinning import rows_from_lattice, skin_rows


@pytest.fixture(scope="module")
def core_points() -> PointSet:
    points = geobrep.datasets.scattered_points()
    core = np.asarray(points.point_data["core"].values) == 1
    return PointSet(
        vertices=points.vertices[core],
        point_data={"true_z": np.asarray(points.point_data["true_z"].values)[core]},
        name="core",
    )


def test_skinning_is_exact_on_the_core(core_points: PointSet) -> None:
    result = fit(core_points, method="skinning")
    extent = float(core_points.bounds.size.max())  # type: ignore[union-attr]
    assert result.report is not None
    assert result.report.n == 300
    assert result.report.max_abs <= 1e-9 * extent
    assert result.surface.type == "NurbsSurface"
    # the data set's core is 16 rows of 18 points and a last row of 12
    assert result.report.details["points_per_section"] == [18] * 16 + [12]
    # between the points the surface follows the true dome closely
    from geobrep.datasets import dome_elevation

    mesh = result.surface.tessellate(resolution=60)
    local = mesh.vertices - np.array([450_000.0, 6_700_000.0, 0.0])
    inner = (np.abs(local[:, 0] - 500) < 150) & (np.abs(local[:, 1] - 480) < 150)
    error = local[inner, 2] - dome_elevation(local[inner, 0], local[inner, 1])
    assert np.abs(error).max() < 0.5


def test_rows_of_different_counts_are_interpolated_exactly() -> None:
    rng = np.random.default_rng(0)
    rows = []
    for k, count in enumerate([5, 9, 7, 12, 6]):
        x = np.sort(rng.uniform(0, 100, count))
        x[0], x[-1] = 0.0, 100.0
        y = 20.0 * k + rng.uniform(-2, 2, count)
        rows.append(np.column_stack([x, y, np.sin(x / 30) * 5 + y / 10]))
    skinned = skin_rows(rows, degree_u=3, degree_v=3)
    u, v = skinned.point_parameters()
    np.testing.assert_allclose(skinned.evaluate(u, v), np.concatenate(rows), atol=1e-10)
    assert skinned.net.shape[1] == 5


def test_sections_as_polyline_parts_with_alternating_directions() -> None:
    x = np.linspace(0.0, 100.0, 8)
    rows = [np.column_stack([x, np.full(8, 25.0 * k), 0.001 * x**2 - 0.3 * k]) for k in range(5)]
    zigzag = [row if k % 2 == 0 else row[::-1] for k, row in enumerate(rows)]  # a zig-zag survey
    result = fit(PolyLine.from_point_lists(zigzag), method="skinning", degree_u=3, degree_v=2)
    assert result.report is not None
    assert result.report.max_abs < 1e-10
    straight = fit(PolyLine.from_point_lists(rows), method="skinning", degree_u=3, degree_v=2)
    np.testing.assert_allclose(  # the sections were turned round: the same, untwisted surface
        result.surface.tessellate(resolution=9).vertices,
        straight.surface.tessellate(resolution=9).vertices,
        atol=1e-9,
    )


def test_row_property_and_explicit_rows() -> None:
    x, y = np.meshgrid(np.linspace(0, 1, 6), np.linspace(0, 1, 5))
    z = np.cos(3 * x) * y
    pts = PointSet(
        vertices=np.column_stack([x.ravel(), y.ravel(), z.ravel()])[::-1],
        point_data={"line": np.repeat(np.arange(5), 6)[::-1]},
    )
    result = fit(pts, method="skinning", row_property="line")
    assert result.report is not None
    assert result.report.max_abs < 1e-12
    assert result.report.details["sections"] == 5
    with pytest.raises(OptionsError, match="row_property"):
        fit(pts, method="skinning", row_property="missing")


def test_rotated_lattice_rows_are_found() -> None:
    rng = np.random.default_rng(2)
    g = np.arange(10.0)
    gx, gy = np.meshgrid(g, np.arange(7.0))
    lattice = np.column_stack([gx.ravel(), gy.ravel()]) + rng.uniform(-0.15, 0.15, (70, 2))
    angle = 0.4
    rotation = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    rows, found = rows_from_lattice(lattice @ rotation.T)
    assert [len(r) for r in rows] == [10] * 7
    assert abs(found - angle) < 0.02


class TestBadInput:
    def test_too_few_points_for_the_degree(self) -> None:
        line = PolyLine.from_point_lists([[[0, k, 0], [1, k, 0], [2, k, 1]] for k in range(4)])
        with pytest.raises(OptionsError, match=r"degree_u.*3 points.*at least 4"):
            fit(line, method="skinning")
        with pytest.raises(OptionsError, match=r"degree_v.*2 sections"):
            fit(
                PolyLine.from_point_lists(
                    [[[0, k, 0], [1, k, 0], [2, k, 1], [3, k, 0]] for k in range(2)]
                ),
                method="skinning",
            )

    def test_duplicate_points(self) -> None:
        rows = [[[0, k, 0], [1, k, 0], [1, k, 0], [2, k, 1], [3, k, 0]] for k in range(4)]
        with pytest.raises(DegenerateGeometryError, match="coincide"):
            fit(PolyLine.from_point_lists(rows), method="skinning")

    def test_collinear_points(self) -> None:
        pts = np.column_stack([np.arange(20.0), 2 * np.arange(20.0), np.arange(20.0)])
        with pytest.raises(DegenerateGeometryError, match="line"):
            fit(pts, method="skinning")

    def test_nan(self) -> None:
        pts = np.zeros((20, 3))
        pts[3, 2] = np.nan
        with pytest.raises(EntityValidationError, match="non-finite"):
            fit(pts, method="skinning")

    def test_unstructured_points(self) -> None:
        rng = np.random.default_rng(0)
        pts = np.column_stack([rng.uniform(0, 1, (200, 2)), np.zeros(200)])
        with pytest.raises(DegenerateGeometryError, match=r"do not form rows|has .* points"):
            fit(pts, method="skinning")


class TestCurves:
    def test_interpolation_and_refinement(self) -> None:
        rng = np.random.default_rng(1)
        pts = np.cumsum(rng.uniform(0.5, 1.0, (9, 3)), axis=0)
        curve = interpolate_curve(pts, 3)
        np.testing.assert_allclose(curve.evaluate(curve.parameters), pts, atol=1e-13)
        finer = merge_knots([curve.knots, np.r_[np.zeros(4), np.linspace(0.1, 0.9, 9), np.ones(4)]])
        refined = curve.refined(finer)
        t = np.linspace(0, 1, 200)
        np.testing.assert_allclose(refined.evaluate(t), curve.evaluate(t), atol=1e-13)
        assert missing_knots(curve.knots, finer) is None  # a coarser vector lacks knots

    def test_knot_insertion_keeps_the_curve(self) -> None:
        knots = np.array([0, 0, 0, 0.5, 1, 1, 1.0])
        ctrl = np.array([[0, 0], [1, 2], [2, -1], [3, 0.0]])
        new_knots, new_ctrl = insert_knots(2, knots, ctrl, np.array([0.25, 0.5, 0.75]))
        from geobrep.geometry.nurbs import basis_matrix

        t = np.linspace(0, 1, 50)
        np.testing.assert_allclose(
            basis_matrix(2, new_knots, t) @ new_ctrl, basis_matrix(2, knots, t) @ ctrl, atol=1e-14
        )

    def test_boundary_curves_of_a_surface(self, core_points: PointSet) -> None:
        surface = fit(core_points, method="skinning").surface
        assert surface.type == "NurbsSurface"
        for side, (u, v) in {
            "u0": (0.0, None),
            "u1": (1.0, None),
            "v0": (None, 0.0),
            "v1": (None, 1.0),
        }.items():
            curve = surface_boundary(surface, side)  # type: ignore[arg-type]
            t = np.linspace(0, 1, 25)
            uu = np.full(25, u) if u is not None else t
            vv = np.full(25, v) if v is not None else t
            np.testing.assert_allclose(curve.evaluate(t), surface.evaluate(uu, vv), atol=1e-8)
