"""geobrep.inspect against OpenGeode-Inspector on the same GOCAD files (the ``bench`` extra;
skipped without it): the same defects for the criteria both implement."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

import geobrep

og = pytest.importorskip("opengeode")
oi = pytest.importorskip("opengeode_inspector")
ogio = pytest.importorskip("opengeode_geosciencesio")

DATA = Path(__file__).resolve().parents[1] / "data" / "gocad"


@pytest.fixture(scope="module", autouse=True)
def _libraries() -> None:
    ogio.OpenGeodeGeosciencesIOMeshLibrary.initialize()
    og.Logger.set_level(og.Logger.LEVEL.error)


def _surface(name: str) -> Any:
    mesh = og.load_triangulated_surface3D(str(DATA / name))
    return oi.SurfaceMeshInspector3D(mesh).inspect_surface()


def test_self_intersections_are_the_same_pairs() -> None:
    theirs = {tuple(sorted(pair)) for pair in _surface("surf2d.ts").intersecting_elements.issues()}
    report = geobrep.inspect(geobrep.read(DATA / "surf2d.ts", repair=False), ["self_intersections"])
    ours = {
        tuple(sorted((d.ids[0], d.other_ids[0])))
        for d in report.section("self_intersections").defects
    }
    assert len(ours) == 5
    assert ours == theirs


def test_colocated_points_of_a_polyline_file() -> None:
    mesh = og.load_edged_curve3D(str(DATA / "normal_lines.pl"))
    theirs = oi.EdgedCurveInspector3D(mesh).inspect_edged_curve().colocated_points_groups
    report = geobrep.inspect(geobrep.read(DATA / "normal_lines.pl"), ["colocated_vertices"])
    assert report.section("colocated_vertices").count == theirs.nb_issues() == 3745


def test_orientation_counts_faces_where_opengeode_counts_edge_sides() -> None:
    theirs = _surface("2triangles.ts").polygon_edges_with_wrong_adjacency.nb_issues()
    report = geobrep.inspect(geobrep.read(DATA / "2triangles.ts", repair=False))
    # one shared edge run the same way by both triangles: seen from each side by OpenGeode,
    # one face to flip for geobrep
    assert theirs == 2
    assert report.counts()["inconsistent_orientation"] == 1
