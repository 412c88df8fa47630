"""The hybrid workflow on the paper-like data set: exact core, rim within ε, gap-free seams."""

from __future__ import annotations

import numpy as np
import pytest
from fit_helpers import UTM

import geobrep
from geobrep import NurbsSurface, PointSet
from geobrep.datasets import dome_elevation
from geobrep.errors import DegenerateGeometryError, OptionsError
from geobrep.ops.fitting import FitResult, fit
from geobrep.plugins.fit._frame import LocalFrame
from geobrep.plugins.fit._hybrid import layout_knots
from geobrep.plugins.fit._split import core_by_density


@pytest.fixture(scope="module")
def points() -> PointSet:
    return geobrep.datasets.scattered_points()


@pytest.fixture(scope="module")
def result(points: PointSet) -> FitResult:
    return fit(points, method="hybrid", epsilon=0.5, core_property="core")


def test_accuracy_report_meets_epsilon(result: FitResult) -> None:
    report = result.report
    assert report is not None
    assert report.passed
    assert report.sigma < 0.5
    assert report.epsilon == 0.5
    assert report.n == 600
    assert report.subsets["core"].n == 300
    assert report.subsets["rim"].n == 300
    assert report.subsets["rim"].passed
    assert report.subsets["rim"].sigma < 0.5
    # σ as the paper defines it, over the reported distances
    d = result.distances
    assert d is not None
    assert report.sigma == pytest.approx(np.sqrt(np.sum(d**2) / (d.size - 1)))
    assert report.max_abs == pytest.approx(np.abs(d).max())
    assert report.worst[0].subset == "rim"
    assert abs(report.worst[0].distance) == report.max_abs


def test_core_is_exact_and_seams_are_closed(result: FitResult, points: PointSet) -> None:
    report = result.report
    assert report is not None
    extent = float(points.bounds.size.max())  # type: ignore[union-attr]
    assert report.subsets["core"].max_abs <= 1e-9 * extent
    assert report.seam_gap is not None
    assert report.seam_gap <= 1e-9
    # partial core rows are interpolated through exact constraints of the rim fit
    assert report.details["core_points_constrained"] == 12


def test_surface_follows_the_true_dome(result: FitResult) -> None:
    surface = result.surface
    assert isinstance(surface, NurbsSurface)
    mesh = surface.tessellate(resolution=120)
    local = mesh.vertices - UTM
    inside = np.all((local[:, :2] > 30) & (local[:, :2] < 970), axis=1)
    error = local[inside, 2] - dome_elevation(local[inside, 0], local[inside, 1])
    assert np.sqrt(np.mean(error**2)) < 0.5
    assert np.abs(error).max() < 6.0


def test_core_found_from_density(points: PointSet) -> None:
    flags = np.asarray(points.point_data["core"].values) == 1
    local = LocalFrame.from_points(points.vertices).to_local(points.vertices)
    found = core_by_density(local[:, :2])
    assert (found & flags).sum() >= 295
    assert (found & ~flags).sum() <= 3
    auto = fit(points, method="hybrid", epsilon=0.5)
    assert auto.report is not None
    assert auto.report.passed
    assert auto.report.seam_gap is not None
    assert auto.report.seam_gap <= 1e-9
    assert auto.report.subsets["core"].max_abs <= 1e-6


def test_core_polygon(points: PointSet) -> None:
    square = np.array([[290, 290], [710, 290], [710, 710], [290, 710]], dtype=float) + UTM[:2]
    by_polygon = fit(points, method="hybrid", epsilon=0.5, core_polygon=square)
    assert by_polygon.report is not None
    assert by_polygon.report.subsets["core"].n == 300


def test_layout_knots_embed_the_core() -> None:
    core = np.array([0, 0, 0, 0, 0.3, 0.6, 1, 1, 1, 1], dtype=float)
    knots, offset = layout_knots(3, core, 2, 3, (0.25, 0.75))
    assert offset == 4
    assert np.count_nonzero(knots == 0.25) == 3
    assert np.count_nonzero(knots == 0.75) == 3
    np.testing.assert_allclose(knots[knots > 0.25][:2], [0.25 + 0.3 * 0.5, 0.25 + 0.6 * 0.5])


class TestBadInput:
    def test_too_few_core_points(self, points: PointSet) -> None:
        square = np.array([[490, 490], [520, 490], [520, 520], [490, 520]], dtype=float) + UTM[:2]
        with pytest.raises(OptionsError, match=r"core has .* points"):
            fit(points, method="hybrid", core_polygon=square)

    def test_missing_property_and_conflicting_options(self, points: PointSet) -> None:
        with pytest.raises(OptionsError, match="no property 'dense'"):
            fit(points, method="hybrid", core_property="dense")
        with pytest.raises(OptionsError, match="not both"):
            fit(
                points, method="hybrid", core_property="core", core_polygon=[[0, 0], [1, 0], [0, 1]]
            )

    def test_no_dense_core(self) -> None:
        rng = np.random.default_rng(0)
        pts = np.column_stack([rng.uniform(0, 1000, (400, 2)), np.zeros(400)]) + UTM
        pts[:, 2] += rng.normal(0, 1, 400)
        with pytest.raises(DegenerateGeometryError, match="no dense core"):
            fit(pts, method="hybrid")

    def test_takes_points_only(self) -> None:
        line = geobrep.PolyLine.from_point_lists([[[0, 0, 0], [1, 0, 0], [1, 1, 1]]])
        with pytest.raises(OptionsError, match="takes PointSet"):
            fit(line, method="hybrid")
