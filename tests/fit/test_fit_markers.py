"""Fitting a horizon to well markers with scattered points, checked against a known surface."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

import geobrep
from geobrep import Well, WellMarker
from geobrep.cli import main
from geobrep.datasets.scattered import dome_elevation
from geobrep.errors import DegenerateGeometryError, OptionsError
from geobrep.geometry.trajectory import minimum_curvature

ORIGIN = np.array([450_000.0, 6_700_000.0, 0.0])


def _true_z(points: np.ndarray) -> np.ndarray:
    return dome_elevation(points[:, 0] - ORIGIN[0], points[:, 1] - ORIGIN[1]) + ORIGIN[2]


def deviated_well(name: str, head_xy: tuple[float, float], azimuth: float) -> Well:
    """A well building 2°/30 m from 50 m MD, crossing the dome; its marker at the MD where the
    minimum-curvature path meets the true surface (found on the path itself)."""
    md = np.arange(0.0, 601.0, 30.0)
    inc = np.clip((md - 50.0) / 15.0, 0.0, 35.0)
    azi = np.full(md.shape, azimuth)
    head = ORIGIN + np.array([head_xy[0], head_xy[1], 20.0])
    xyz = head + minimum_curvature(md, inc, azi)
    well = Well(name=name, head=head, vertices=xyz, md=md, point_data={"INCL": inc, "AZIM_GN": azi})

    def above(m: float) -> float:
        point = well.position_at([m])
        return float(point[0, 2] - _true_z(point)[0])

    crossing = brentq(above, 0.0, float(md[-1]), xtol=1e-12)
    top = WellMarker(name=f"{name} H", md=crossing, surface="dome")
    return well.replace(markers=(top, WellMarker(name=f"{name} deeper", md=590.0, surface="base")))


WELLS = [
    deviated_well("W1", (120.0, 150.0), 45.0),
    deviated_well("W2", (880.0, 130.0), 300.0),
    deviated_well("W3", (850.0, 860.0), 200.0),
]


def test_markers_sit_on_the_true_surface() -> None:
    for well in WELLS:
        position = well.marker_positions()[:1]
        assert abs(position[0, 2] - _true_z(position)[0]) < 1e-6


def _markers(result: geobrep.FitResult, n: int = len(WELLS)) -> list[float]:
    report = result.report
    assert report is not None
    assert report.subsets["markers"].n == n
    distances = [row["distance"] for row in report.details["markers"]]
    assert report.subsets["markers"].max_abs == pytest.approx(max(abs(d) for d in distances))
    return distances


def test_approximation_misfit_falls_with_the_weight_and_vanishes_for_hard_markers() -> None:
    points = geobrep.datasets.scattered_points()
    fits = {
        weight: _markers(
            geobrep.fit(
                points,
                method="approximation",
                markers=WELLS,
                marker_surface="dome",
                marker_weight=weight,
                control_points=(8, 8),
            )
        )
        for weight in (None, 1000.0, "hard")
    }
    soft, heavy, hard = (np.abs(fits[w]).max() for w in (None, 1000.0, "hard"))
    assert soft > 1e-3  # the markers are points of the least squares, not honoured exactly
    assert heavy < soft / 10
    assert hard < 1e-6


def test_kriging_is_exact_at_the_markers() -> None:
    points = geobrep.datasets.scattered_points(n_core=100, n_rim=100, noise=0.0)
    where = np.concatenate([w.marker_positions()[:1] for w in WELLS])
    gridx = np.unique(
        np.r_[
            np.linspace(points.vertices[:, 0].min(), points.vertices[:, 0].max(), 25), where[:, 0]
        ]
    )
    gridy = np.unique(
        np.r_[
            np.linspace(points.vertices[:, 1].min(), points.vertices[:, 1].max(), 25), where[:, 1]
        ]
    )
    result = geobrep.fit(points, method="kriging", markers=WELLS, marker_surface="dome",
                         gridx=gridx.tolist(), gridy=gridy.tolist())  # fmt: skip
    assert np.abs(_markers(result)).max() < 1e-6


def test_hybrid_takes_hard_markers_in_the_rim() -> None:
    points = geobrep.datasets.scattered_points()
    result = geobrep.fit(points, method="hybrid", markers=WELLS, marker_surface="dome",
                         marker_weight="hard", core_property="core")  # fmt: skip
    assert np.abs(_markers(result)).max() < 1e-6
    # the rest of the fit still follows the true dome
    assert np.abs(result.distances[: points.n_points]).max() < 2.0


def test_marker_choice_and_errors() -> None:
    points = geobrep.datasets.scattered_points()
    with pytest.raises(OptionsError, match="name 2 surfaces"):
        geobrep.fit(points, method="approximation", markers=WELLS)
    with pytest.raises(OptionsError, match="no marker"):
        geobrep.fit(points, method="approximation", markers=WELLS, marker_surface="nothing")
    with pytest.raises(OptionsError, match="takes no marker_weight"):
        geobrep.fit(
            points, method="kriging", markers=WELLS, marker_surface="dome", marker_weight=2.0
        )
    with pytest.raises(OptionsError, match="need markers"):
        geobrep.fit(points, method="approximation", marker_surface="dome")
    scene = geobrep.Scene(entities=WELLS)
    result = geobrep.fit(points, method="approximation", markers=scene, marker_surface="base")
    assert result.report.subsets["markers"].n == 3


def test_cli_fit_takes_well_files(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    points = geobrep.datasets.scattered_points()
    geobrep.write(points, tmp_path / "points.geobrep")
    files = []
    for well in WELLS:
        files.append(
            str(geobrep.write(geobrep.Scene(entities=[well]), tmp_path / f"{well.name}.geobrep"))
        )
    code = main(["fit", str(tmp_path / "points.geobrep"), str(tmp_path / "out.geobrep"),
                 "--method", "approximation", "--markers", *files, "--marker-surface", "dome",
                 "--marker-weight", "hard", "--json"])  # fmt: skip
    assert code == 0
    report = json.loads(capsys.readouterr().out)["report"]
    assert report["subsets"]["markers"]["n"] == 3
    assert report["subsets"]["markers"]["max_abs"] < 1e-6


CORE_WELLS = [
    deviated_well("C1", (400.0, 420.0), 45.0),
    deviated_well("C2", (560.0, 520.0), 200.0),
]
MIXED_WELLS = [*CORE_WELLS, WELLS[0]]  # two markers inside the skinned core, one in the rim


def _written_misfit(result: geobrep.FitResult, path: Path, wells: list[Well]) -> np.ndarray:
    """Marker distances measured on the surface as written to and read back from ``path``."""
    from geobrep.plugins.fit.distance import surface_distances

    result.write(path)
    (surface,) = geobrep.read(path).entities
    assert isinstance(surface, geobrep.NurbsSurface)
    where = np.concatenate([w.marker_positions()[:1] for w in wells])
    return np.asarray(surface_distances(surface, where))


@pytest.mark.parametrize("core", [{"core_property": "core"}, {}], ids=["flagged", "density"])
def test_hybrid_meets_hard_markers_in_the_core_and_the_rim(
    core: dict[str, str], tmp_path: Path
) -> None:
    points = geobrep.datasets.scattered_points()
    plain = geobrep.fit(points, method="hybrid", epsilon=0.5, **core)
    result = geobrep.fit(points, method="hybrid", epsilon=0.5, markers=MIXED_WELLS,
                         marker_surface="dome", marker_weight="hard", **core)  # fmt: skip
    report = result.report
    assert report is not None
    assert report.passed
    assert report.subsets["markers"].n == 3
    assert report.subsets["markers"].max_abs < 1e-6
    assert np.abs(_written_misfit(result, tmp_path / "top.geobrep", MIXED_WELLS)).max() < 1e-6
    # without the correction the surface misses the core markers by centimetres
    from geobrep.plugins.fit.distance import surface_distances

    where = np.concatenate([w.marker_positions()[:1] for w in CORE_WELLS])
    assert np.abs(surface_distances(plain.surface, where)).max() > 1e-3
    # the skinned core is still interpolated exactly, and joins the rim without a gap
    assert report.subsets["core"].max_abs < 1e-6
    assert report.seam_gap is not None
    assert report.seam_gap < 1e-6
    assert report.details["core_points_corrected"]["exact"] == 2
    # the correction is local: far from the markers the core surface does not move (the grid
    # stays inside the skinned rows; the rim beyond them is fitted anew)
    g = np.linspace(340.0, 630.0, 30)
    grid = np.column_stack([np.repeat(g, g.size), np.tile(g, g.size), np.zeros(g.size**2)])
    grid += ORIGIN
    grid[:, 2] = _true_z(grid)
    change = np.abs(
        surface_distances(result.surface, grid) - surface_distances(plain.surface, grid)
    )
    far = np.min(np.linalg.norm(grid[:, None, :2] - where[None, :, :2], axis=2), axis=1) > 100.0
    assert change[far].max() < 2e-3 < change.max()


def test_hybrid_soft_markers_in_the_core_and_the_rim_reduce_the_misfit() -> None:
    from geobrep.plugins.fit.distance import surface_distances

    points = geobrep.datasets.scattered_points()
    where = np.concatenate([w.marker_positions()[:1] for w in MIXED_WELLS])
    plain = geobrep.fit(points, method="hybrid", epsilon=0.5, core_property="core")
    without = np.abs(surface_distances(plain.surface, where))
    misfits = {}
    for weight in (1.0, 100.0):
        result = geobrep.fit(points, method="hybrid", epsilon=0.5, core_property="core",
                             markers=MIXED_WELLS, marker_surface="dome",
                             marker_weight=weight)  # fmt: skip
        assert result.report is not None
        assert result.report.passed
        assert result.report.subsets["core"].max_abs < 1e-6
        misfits[weight] = np.abs(_markers(result, len(MIXED_WELLS)))
    assert np.all(misfits[1.0] < without)
    assert np.all(misfits[100.0] < misfits[1.0])
    assert misfits[100.0][:2].max() < 1e-5  # inside the core nothing competes with them


def test_a_hard_marker_on_a_core_point_at_another_height_is_a_clear_error() -> None:
    points = geobrep.datasets.scattered_points()
    core = points.vertices[points.point_data["core"].values == 1]
    target = core[np.argmin(np.linalg.norm(core[:, :2] - core[:, :2].mean(axis=0), axis=1))]
    head = target + np.array([0.0, 0.0, 50.0])
    well = Well(name="V", head=head, vertices=[head, head - [0.0, 0.0, 100.0]], md=[0.0, 100.0],
                markers=[WellMarker(name="top", md=49.0, surface="dome")])  # fmt: skip
    with pytest.raises(DegenerateGeometryError, match="inside the skinned core cannot be met"):
        geobrep.fit(points, method="hybrid", core_property="core", markers=[well],
                    marker_weight="hard")  # fmt: skip


def test_a_marker_outside_the_fitted_surface_is_a_clear_error() -> None:
    points = geobrep.datasets.scattered_points(n_core=100, n_rim=100)
    far = deviated_well("F", (1500.0, 400.0), 45.0)
    lo, hi = points.vertices[:, :2].min(axis=0), points.vertices[:, :2].max(axis=0)
    grid = {"gridx": np.linspace(lo[0], hi[0], 20).tolist(),
            "gridy": np.linspace(lo[1], hi[1], 20).tolist()}  # fmt: skip
    with pytest.raises(OptionsError, match=r"map view, the first 'F H' of well 'F'"):
        geobrep.fit(points, method="kriging", markers=[far], marker_surface="dome", **grid)
    inside = geobrep.fit(points, method="kriging", markers=WELLS, marker_surface="dome", **grid)
    assert inside.report is not None
    assert inside.report.subsets["markers"].n == 3


def test_exact_points_on_fixed_control_points_are_checked_not_solved() -> None:
    import scipy.sparse as sp

    from geobrep.plugins.fit._lsq import solve_penalised

    normal = sp.csr_matrix(np.eye(3))
    rhs = np.array([[1.0], [2.0], [3.0]])
    fixed = np.array([True, False, False])
    values = np.array([[5.0], [0.0], [0.0]])
    # the first exact point depends on the fixed control point only and is met by it
    rows = sp.csr_matrix(np.array([[1.0, 0.0, 0.0], [0.0, 0.5, 0.5]]))
    solution = solve_penalised(normal, rhs, fixed=fixed, fixed_values=values,
                               equality=(rows, np.array([5.0, 4.0])))  # fmt: skip
    assert solution[0, 0] == 5.0
    assert solution[1:, 0] @ [0.5, 0.5] == pytest.approx(4.0)
    with pytest.raises(DegenerateGeometryError, match="depend only on fixed control points"):
        solve_penalised(normal, rhs, fixed=fixed, fixed_values=values,
                        equality=(rows, np.array([6.0, 4.0])))  # fmt: skip


def test_a_marker_beside_a_core_point_off_its_slope_is_met_and_noted() -> None:
    points = geobrep.datasets.scattered_points()
    core = points.vertices[points.point_data["core"].values == 1]
    target = core[np.argmin(np.linalg.norm(core[:, :2] - core[:, :2].mean(axis=0), axis=1))]
    head = target + np.array([0.5, 0.0, 50.01])  # 0.5 m beside it, 1 cm above it
    well = Well(name="V", head=head, vertices=[head, head - [0.0, 0.0, 100.0]], md=[0.0, 100.0],
                markers=[WellMarker(name="top", md=50.0, surface="dome")])  # fmt: skip
    result = geobrep.fit(points, method="hybrid", epsilon=0.5, core_property="core",
                         markers=[well], marker_weight="hard")  # fmt: skip
    report = result.report
    assert report is not None
    assert report.subsets["markers"].max_abs < 1e-6
    assert report.subsets["core"].max_abs < 1e-6
    assert any("does not follow the core's slope" in note for note in report.notes)
    benign = geobrep.fit(points, method="hybrid", epsilon=0.5, core_property="core",
                         markers=CORE_WELLS, marker_surface="dome",
                         marker_weight="hard")  # fmt: skip
    assert benign.report is not None
    assert not any("core's slope" in note for note in benign.report.notes)


def test_weighted_markers_are_never_core_points() -> None:
    """The density-found core interpolates its points: a weighted marker among them would be
    met exactly (against its weight) and bend the core; it is data for the correction instead."""
    points = geobrep.datasets.scattered_points()
    core = points.vertices[points.point_data["core"].values == 1]
    target = core[np.argmin(np.linalg.norm(core[:, :2] - core[:, :2].mean(axis=0), axis=1))]
    head = target + np.array([0.5, 0.0, 50.01])  # 0.5 m beside a core point, 1 cm above it
    well = Well(name="V", head=head, vertices=[head, head - [0.0, 0.0, 100.0]], md=[0.0, 100.0],
                markers=[WellMarker(name="top", md=50.0, surface="dome")])  # fmt: skip
    plain = geobrep.fit(points, method="hybrid", epsilon=0.5)
    weighted = geobrep.fit(points, method="hybrid", epsilon=0.5, markers=[well],
                           marker_weight=100.0)  # fmt: skip
    assert plain.report is not None
    assert weighted.report is not None
    assert weighted.report.subsets["core"].n == plain.report.subsets["core"].n
    assert weighted.report.subsets["core"].max_abs < 1e-6
    assert weighted.report.details["core_points_corrected"]["least_squares"] >= 1
    from geobrep.plugins.fit.distance import surface_distances

    where = well.marker_positions()
    before = abs(surface_distances(plain.surface, where)[0])
    after = abs(surface_distances(weighted.surface, where)[0])
    assert after < before / 5, (before, after)  # pulled towards the marker, the core kept
