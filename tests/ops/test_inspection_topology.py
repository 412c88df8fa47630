"""B-Rep topology counts of ``geobrep.inspect`` on every model of tests/data (read as written),
and — with the ``bench`` extra — OpenGeode-Inspector's BRep topology counts on the same files:
each difference as the table in docs/inspection.md explains it, checked against the file."""

from __future__ import annotations

import re
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import geobrep
from geobrep import Scene
from geobrep.geometry import mesh

DATA = Path(__file__).resolve().parents[1] / "data"

#: geobrep's B-Rep checks with a defect, per model (every other B-Rep check finds none).
GEOBREP = {
    "gocad/modelA1.ml": {},
    "gocad/modelA4.ml": {},
    "gocad/non_split_cube.ml": {"block_orientation": 2, "region_sides": 2},
    "gocad/not_sealed_cube.ml": {"universe_closure": 1},
    "gocad/split_cube.ml": {"block_orientation": 3, "region_sides": 2, "volume_balance": 1},
    "opengeode/test.lso": {},
    "opengeode/vri.lso": {},
}
#: OpenGeode-Inspector's topology criteria with an issue (every other of its 30 finds none).
OPENGEODE = {
    "gocad/modelA1.ml": {},
    "gocad/modelA4.ml": {},
    "gocad/non_split_cube.ml": {},
    "gocad/not_sealed_cube.ml": {
        "lines.line_edges_with_wrong_component_edges_around": 24,
        "lines.unique_vertices_linked_to_line_with_wrong_relationship_to_surface": 24,
    },
    "gocad/split_cube.ml": {
        "blocks.blocks_with_not_closed_boundary_surfaces": 2,
        "blocks.model_boundaries_dont_form_a_closed_surface": 1,
        "lines.line_edges_with_wrong_component_edges_around": 4,
        "lines.unique_vertices_linked_to_line_with_wrong_relationship_to_surface": 4,
    },
    "opengeode/test.lso": {},
    "opengeode/vri.lso": {},
}
BREP_CHECKS = {
    "patch_boundaries",
    "arc_ends",
    "arc_patch_order",
    "patch_sides",
    "block_closure",
    "block_orientation",
    "universe_closure",
    "volume_balance",
    "region_sides",
}


def _read(path: Path) -> Scene:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the files' own notes (seams, ATOMs) are not at issue
        return geobrep.read(path, repair=False)


def _brep_counts(scene: Scene) -> dict[str, int]:
    report = geobrep.inspect(scene)
    brep = {s.check: s.count for s in report.sections if s.family == "brep"}
    assert set(brep) == BREP_CHECKS
    return {check: count for check, count in brep.items() if count}


def _components(scene: Scene) -> tuple[int, int, int, int]:
    topology = scene.topology
    blocks = [b for b in scene.blocks if not b.is_universe]
    return len(topology.corners), len(topology.arcs), len(topology.patches), len(blocks)


@pytest.mark.parametrize("name", sorted(GEOBREP))
def test_brep_counts_of_every_model(name: str) -> None:
    assert _brep_counts(_read(DATA / name)) == GEOBREP[name]


def test_every_model_of_the_data_is_listed() -> None:
    found = {f"gocad/{p.name}" for p in (DATA / "gocad").glob("*.ml")}
    found |= {f"opengeode/{p.name}" for p in (DATA / "opengeode").glob("*.lso")}
    assert found == set(GEOBREP)


def _with_signs(text: str, signs: dict[str, str]) -> str:
    """The Model3d ``text`` with the sign lines of its REGIONs replaced (``{name: line}``)."""
    for region, line in signs.items():
        text, n = re.subn(rf"(REGION \d+ +{region} *\n)[^\n]*\n", rf"\g<1>  {line}\n", text)
        assert n == 1
    return text


def _brep_of_text(text: str, tmp_path: Path) -> dict[str, int]:
    path = tmp_path / "model.ml"
    path.write_text(text)
    return _brep_counts(_read(path))


def test_split_cube_box_and_horizon_signs_disagree(tmp_path: Path) -> None:
    # REGION Universe -1 -2, Top +1 +3, Bottom +2 -3: the box's TFACEs 1 and 2 and the horizon's
    # TFACE 3 disagree in both blocks. With the box's signs turned, every check passes; with the
    # horizon's turned instead, every block is inside out: the box's signs are the reversed ones
    # (they follow raw depth coordinates, tests/data/gocad/SOURCES.md), the horizon's not.
    path = DATA / "gocad" / "split_cube.ml"
    text = path.read_text()
    box = {"Universe": "+1  +2   0", "Top": "-1  +3   0", "Bottom": "-2  -3   0"}
    assert _brep_of_text(_with_signs(text, box), tmp_path) == {}
    horizon = {"Top": "+1  -3   0", "Bottom": "+2  +3   0"}
    assert _brep_of_text(_with_signs(text, horizon), tmp_path) == {"block_orientation": 3}
    scene = _read(path)
    report = geobrep.inspect(scene, ["region_sides", "block_orientation", "block_closure"])
    horizon_patch = next(p.id for p in scene.topology.patches if p.surface == scene.surfaces[1].id)
    sides = report.section("region_sides").defects
    assert sorted(d.entity for d in sides) == ["Bottom", "Top"]
    assert {d.ids for d in sides} == {(horizon_patch,)}  # the smaller part of each shell
    assert report.section("block_closure").count == 0  # both blocks are closed
    messages = {d.entity: d.message for d in report.section("block_orientation").defects}
    assert messages["Universe"].startswith("boundary not outward")


def test_non_split_cube_shell_turns_at_two_faces_of_the_box() -> None:
    # The box is one TFACE; its faces 18 and 19 are wound against the rest (as
    # inconsistent_orientation says), so the box's side in both blocks runs against itself.
    # Those two faces turned, the blocks are consistent but inside out: the file's signs follow
    # raw depth coordinates, as split_cube's box does.
    scene = _read(DATA / "gocad" / "non_split_cube.ml")
    report = geobrep.inspect(scene, ["region_sides", "inconsistent_orientation"])
    assert {d.ids[0] for d in report.section("inconsistent_orientation").defects} == {18, 19}
    box = scene.surfaces[0]
    box_patch = next(p.id for p in scene.topology.patches if p.surface == box.id)
    assert {d.ids for d in report.section("region_sides").defects} == {(box_patch,)}
    faces = box.faces.copy()
    faces[[18, 19]] = faces[[18, 19], ::-1]
    turned = scene.replace(
        entities=[box.replace(faces=faces) if e is box else e for e in scene.entities]
    )
    assert _brep_counts(turned) == {"block_orientation": 2}
    messages = [d.message for d in geobrep.inspect(turned).section("block_orientation").defects]
    assert all(m.startswith("boundary not outward") for m in messages)


def test_not_sealed_cube_universe_counts_the_free_border_edges() -> None:
    # Six squares of two triangles, apart from each other: nothing seals, each square's four
    # border edges are free (24 in all, the value), and the squares are 0.2 apart at least.
    scene = _read(DATA / "gocad" / "not_sealed_cube.ml")
    (defect,) = geobrep.inspect(scene, ["universe_closure"]).section("universe_closure").defects
    borders = [mesh.boundary_edges(s.faces).shape[0] for s in scene.surfaces]
    assert borders == [4] * 6
    assert defect.value == sum(borders) == 24
    points = [s.vertices for s in scene.surfaces]
    gaps = [
        np.linalg.norm(a[:, None] - b[None], axis=2).min()
        for k, a in enumerate(points)
        for b in points[k + 1 :]
    ]
    assert min(gaps) > 0.19


def test_light_tsolids_are_read_without_a_brep() -> None:
    # geobrep reads a LightTSolid as one tet mesh and its surfaces, with no corners, arcs,
    # patches or blocks: the B-Rep checks have nothing to check. Its SHAREDPVRTX lines are
    # vertices of their own at the place of the vertex they name (colocated_vertices: one
    # group per named vertex, the copies as many as the lines).
    for name, groups in (("test.lso", 117), ("vri.lso", 20)):
        path = DATA / "opengeode" / name
        scene = _read(path)
        assert _components(scene) == (0, 0, 0, 0)
        section = geobrep.inspect(scene, ["colocated_vertices"]).section("colocated_vertices")
        shared = path.read_text().count("\nSHAREDPVRTX ")
        assert section.count == groups
        assert sum(len(d.ids) - 1 for d in section.defects) == shared


# --------------------------------------------------------------------------- OpenGeode side
def _opengeode() -> tuple[Any, Any, Any]:
    og = pytest.importorskip("opengeode")
    oi = pytest.importorskip("opengeode_inspector")
    geosciences = pytest.importorskip("opengeode_geosciences")
    ogio = pytest.importorskip("opengeode_geosciencesio")
    ogio.OpenGeodeGeosciencesIOMeshLibrary.initialize()
    ogio.OpenGeodeGeosciencesIOModelLibrary.initialize()
    og.Logger.set_level(og.Logger.LEVEL.error)
    return og, oi, geosciences


def _issue_counts(result: Any, prefix: str = "", depth: int = 0) -> dict[str, int]:
    """Every criterion of an OpenGeode inspection result: ``{dotted name: issues}``."""
    counts: dict[str, int] = {}
    for name in dir(result):
        value = None if name.startswith("_") else getattr(result, name)
        if value is None or callable(value) or isinstance(value, str | int | float):
            continue
        if hasattr(value, "nb_issues"):
            counts[prefix + name] = int(value.nb_issues())
        elif depth < 3:
            counts.update(_issue_counts(value, f"{prefix}{name}.", depth + 1))
    return counts


@pytest.mark.parametrize("name", sorted(OPENGEODE))
def test_opengeode_topology_counts(name: str) -> None:
    _, oi, geosciences = _opengeode()
    model = geosciences.load_structural_model(str(DATA / name))  # alive while inspected
    counts = _issue_counts(oi.BRepInspector(model).inspect_brep().topology)
    assert len(counts) == 30
    assert {k: v for k, v in counts.items() if v} == OPENGEODE[name]
    scene = _read(DATA / name)
    theirs = (model.nb_corners(), model.nb_lines(), model.nb_surfaces(), model.nb_blocks())
    if name.endswith(".ml"):
        assert _components(scene) == theirs  # the same B-Rep, component by component
    else:
        # OpenGeode builds the B-Rep of the tet regions; its unique vertices are the tet
        # mesh's without the SHAREDPVRTX copies
        assert theirs == {"test.lso": (22, 39, 23, 4), "vri.lso": (12, 20, 11, 2)}[name[10:]]
        shared = (DATA / name).read_text().count("\nSHAREDPVRTX ")
        assert model.nb_unique_vertices() == scene.tet_meshes[0].vertices.shape[0] - shared


@pytest.mark.parametrize(("name", "edges"), [("split_cube.ml", 4), ("not_sealed_cube.ml", 24)])
def test_opengeode_records_closed_lines_as_internal(name: str, edges: int) -> None:
    # OpenGeode-GeosciencesIO records a closed line (one corner) as embedded in the surfaces
    # it borders, not as their boundary; an internal line needs two surface edges around each
    # of its edges and has one: one issue per line edge and per line vertex.
    _, oi, geosciences = _opengeode()
    model = geosciences.load_structural_model(str(DATA / "gocad" / name))
    lines = list(model.lines())
    assert all(len(list(model.boundary_corners(line))) == 1 for line in lines)
    assert all(not list(model.incident_surfaces(line)) for line in lines)
    assert all(list(model.embedding_surfaces_of_line(line)) for line in lines)
    assert sum(line.mesh().nb_edges() for line in lines) == edges
    scene = _read(DATA / "gocad" / name)
    if name == "not_sealed_cube.ml":  # the squares' free borders: universe_closure's value
        value = geobrep.inspect(scene, ["universe_closure"]).section("universe_closure")
        assert value.defects[0].value == edges
    else:  # the ring where the box's two patches meet the horizon
        (box, _) = scene.surfaces
        labels = np.asarray(box.patch_labels)
        sides = [mesh.boundary_edges(box.faces[labels == k]) for k in (0, 1)]
        welded = [
            {tuple(sorted(map(tuple, box.vertices[e].round(9).tolist()))) for e in s} for s in sides
        ]
        assert len(welded[0] & welded[1]) == edges
    result = oi.BRepInspector(model).inspect_brep().topology.lines
    assert result.line_edges_with_wrong_component_edges_around.nb_issues() == edges
