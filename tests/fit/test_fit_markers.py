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
from geobrep.errors import OptionsError
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


def _markers(result: geobrep.FitResult) -> list[float]:
    report = result.report
    assert report is not None
    assert report.subsets["markers"].n == len(WELLS)
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
