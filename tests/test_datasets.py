"""Built-in sample data: the scattered survey points on a known dome."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from geobrep import PointSet
from geobrep.datasets import dome_elevation, scattered_points

ORIGIN = np.array([450_000.0, 6_700_000.0, 0.0])


def split(points: PointSet) -> tuple[np.ndarray, np.ndarray]:
    core = points.point_data["core"].values.astype(bool)
    return points.vertices[core], points.vertices[~core]


class TestDomeElevation:
    def test_known_values(self) -> None:
        # at the centre the dome peaks at -200 + 80 and the fold term vanishes (sin 0)
        assert float(dome_elevation(500.0, 500.0)) == -120.0
        u = v = -0.5  # a corner, far from the dome: only the tails remain
        expected = (
            -200
            + 80 * np.exp(-(u**2 + v**2) / 0.08)
            + 15 * np.sin(2 * np.pi * (u + 0.5 * v)) * np.exp(-(v**2) / 0.1)
        )
        assert float(dome_elevation(0.0, 0.0)) == pytest.approx(expected, rel=1e-15)

    def test_vectorised(self) -> None:
        x = np.array([[0.0, 500.0], [1000.0, 250.0]])
        z = dome_elevation(x, x.T)
        assert z.shape == (2, 2)
        assert z.dtype == np.float64
        assert z[0, 1] == float(dome_elevation(500.0, 1000.0))


class TestScatteredPoints:
    def test_default_counts(self) -> None:
        points = scattered_points()
        assert points.n_points == 600
        assert points.point_data["core"].dtype == np.int8
        assert int(points.point_data["core"].values.sum()) == 300
        assert points.point_data["true_z"].unit == "m"
        assert points.name == "survey points"
        assert points.metadata["crs"] == "EPSG:32631"

    @pytest.mark.parametrize(("n_core", "n_rim"), [(10, 7), (0, 50), (49, 0), (1, 1)])
    def test_requested_counts(self, n_core: int, n_rim: int) -> None:
        points = scattered_points(n_core=n_core, n_rim=n_rim)
        core, rim = split(points)
        assert len(core) == n_core
        assert len(rim) == n_rim
        # the core comes first
        assert points.point_data["core"].values.tolist() == [1] * n_core + [0] * n_rim

    def test_core_points_lie_exactly_on_the_dome(self) -> None:
        points = scattered_points(n_core=400, n_rim=100, noise=5.0, seed=3)
        core, _ = split(points)
        local = core - ORIGIN
        np.testing.assert_allclose(local[:, 2], dome_elevation(local[:, 0], local[:, 1]), atol=1e-9)
        true_z = points.point_data["true_z"].values[: len(core)]
        assert core[:, 2].tobytes() == true_z.tobytes()
        # the dense core covers the central 40 % of the 1 km square
        assert local[:, :2].min() >= 300.0
        assert local[:, :2].max() <= 700.0

    def test_rim_noise_has_the_requested_spread(self) -> None:
        noise = 0.5
        points = scattered_points(n_core=0, n_rim=20_000, noise=noise, seed=7)
        _, rim = split(points)
        local = rim - ORIGIN
        residual = local[:, 2] - dome_elevation(local[:, 0], local[:, 1])
        assert abs(residual.mean()) < 4 * noise / np.sqrt(len(rim))
        assert residual.std() == pytest.approx(noise, rel=0.03)
        # the rim stays outside the central square and inside the survey area
        outside = np.any(np.abs(local[:, :2] / 1000.0 - 0.5) > 0.22, axis=1)
        assert outside.all()
        assert local[:, :2].min() >= 0.0
        assert local[:, :2].max() <= 1000.0

    def test_zero_noise(self) -> None:
        points = scattered_points(n_core=5, n_rim=50, noise=0.0)
        z = points.vertices[:, 2]
        assert z.tobytes() == points.point_data["true_z"].values.tobytes()

    def test_reproducible(self) -> None:
        assert scattered_points(seed=11) == scattered_points(seed=11)
        assert scattered_points(seed=11) != scattered_points(seed=12)

    @pytest.mark.parametrize("kwargs", [{"n_core": -1}, {"n_rim": -2}, {"noise": -0.1}])
    def test_bad_arguments(self, kwargs: dict[str, float]) -> None:
        with pytest.raises(ValueError, match="must be ≥ 0"):
            scattered_points(**kwargs)  # type: ignore[arg-type]

    @given(st.integers(0, 60), st.integers(0, 60), st.integers(0, 2**16))
    def test_any_counts(self, n_core: int, n_rim: int, seed: int) -> None:
        points = scattered_points(n_core=n_core, n_rim=n_rim, seed=seed)
        assert points.n_points == n_core + n_rim
        assert int(points.point_data["core"].values.sum()) == n_core
        assert np.isfinite(points.vertices).all()
