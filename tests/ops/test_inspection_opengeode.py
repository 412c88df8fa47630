"""geobrep.inspect against OpenGeode-Inspector on the same GOCAD files (the ``bench`` extra;
skipped without it): the same defects for the criteria both implement."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

import geobrep

og = pytest.importorskip("opengeode")
oi = pytest.importorskip("opengeode_inspector")
ogio = pytest.importorskip("opengeode_geosciencesio")

DATA = Path(__file__).resolve().parents[1] / "data" / "gocad"


@pytest.fixture(scope="module", autouse=True)
def _libraries() -> None:
    ogio.OpenGeodeGeosciencesIOMeshLibrary.initialize()
    ogio.OpenGeodeGeosciencesIOModelLibrary.initialize()
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


def _atoms_of_one_tface(path: Path, surface: str) -> set[tuple[int, int]]:
    """(target, atom) vertex index pairs (0-based) of the ``ATOM``/``PATOM`` lines of one TSurf
    naming a vertex of the same TFACE: one vertex id more at a place the TFACE already has."""
    pairs: set[tuple[int, int]] = set()
    inside, face_start = False, 0
    for line in path.read_text("utf-8", errors="replace").splitlines():
        words = line.split()
        if not words:
            continue
        if words[0] == "GOCAD":
            inside = False
        elif line.startswith("name:"):
            inside = inside or line[5:].strip() == surface
        elif inside and words[0] == "TFACE":
            face_start = -1  # the TFACE starts at its next vertex
        elif inside and words[0] in ("VRTX", "PVRTX", "ATOM", "PATOM"):
            number = int(words[1])
            if face_start < 0:
                face_start = number
            if words[0] in ("ATOM", "PATOM") and int(words[2]) >= face_start:
                pairs.add((int(words[2]) - 1, number - 1))
    return pairs


def _model(name: str) -> Any:
    geosciences = pytest.importorskip("opengeode_geosciences")
    return geosciences.load_structural_model(str(DATA / name))


@pytest.mark.parametrize(
    ("name", "groups"),
    [("modelA4.ml", 14), ("non_split_cube.ml", 2), ("split_cube.ml", 0), ("modelA1.ml", 0)],
)
def test_colocated_vertices_are_the_atoms_naming_a_vertex_of_their_own_tface(
    name: str, groups: int
) -> None:
    # geobrep reads a file as written: an ATOM line is a vertex of its own, at the place of the
    # vertex it names; inside one TFACE the triangles on either side of such a pair use
    # different ids (a seam), which geobrep reports and the weld joins. OpenGeode links the
    # two to one unique vertex of the model, and its colocation criterion only reports
    # colocated points that are not linked: none.
    scene = geobrep.read(DATA / name, repair=False)
    section = geobrep.inspect(scene, ["colocated_vertices"]).section("colocated_vertices")
    assert section.count == groups
    found: dict[str, set[tuple[int, ...]]] = {}
    for defect in section.defects:
        found.setdefault(defect.entity, set()).add(tuple(sorted(defect.ids)))
        entity = next(e for e in scene.entities if e.id == defect.entity_id)
        assert np.ptp(entity.vertices[list(defect.ids)], axis=0).max() == 0.0  # exact copies
    for surface, pairs in found.items():
        assert pairs == _atoms_of_one_tface(DATA / name, surface)
    model = _model(name)  # kept alive while its inspector runs
    theirs = oi.BRepInspector(model).inspect_brep().meshes.meshes_colocation
    assert theirs.colocated_points_groups.nb_issues() == 0


def test_non_split_cube_orientation_faces_and_opengeode_edge_sides() -> None:
    scene = geobrep.read(DATA / "non_split_cube.ml", repair=False)
    section = geobrep.inspect(scene, ["inconsistent_orientation"]).section(
        "inconsistent_orientation"
    )
    ours = {d.ids[0] for d in section.defects}
    assert ours == {18, 19}  # two adjacent triangles of the box wound against the rest
    model = _model("non_split_cube.ml")  # kept alive while its inspector runs
    result = oi.BRepInspector(model).inspect_brep()
    wrong = result.meshes.meshes_adjacencies.surfaces_edges_with_wrong_adjacencies
    # the four edges between {18, 19} and the rest, listed from each side by OpenGeode
    assert wrong.nb_issues() == 8
