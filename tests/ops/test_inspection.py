"""geobrep.inspect and geobrep.repair on models with known, injected defects."""

from __future__ import annotations

import json
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest

import geobrep
import geobrep.schemas
from geobrep import OptionsError, PolyLine, Scene, Surface
from geobrep.plugins import CheckSpec, Defect, hookimpl

DATA = Path(__file__).resolve().parent.parent / "data" / "gocad"


def grid(n: int = 10, z: float = 0.0, name: str = "grid", x0: float = 0.0) -> Surface:
    """A flat n x n grid of unit squares, two triangles each, consistently wound."""
    xs, ys = np.meshgrid(np.arange(n + 1, dtype=float), np.arange(n + 1, dtype=float))
    vertices = np.column_stack([xs.ravel() + x0, ys.ravel(), np.full(xs.size, z)])
    i, j = np.meshgrid(np.arange(n), np.arange(n))
    a = (j * (n + 1) + i).ravel()
    faces = np.concatenate(
        [np.column_stack([a, a + 1, a + n + 2]), np.column_stack([a, a + n + 2, a + n + 1])]
    )
    return Surface(vertices=vertices, faces=faces, name=name)


def counts(report: geobrep.InspectionReport) -> dict[str, int]:
    return {k: v for k, v in report.counts().items() if v}


def test_clean_models_are_clean() -> None:
    assert geobrep.inspect(grid()).ok
    report = geobrep.inspect(geobrep.datasets.faulted_layer_cake())
    assert report.ok, report.table()
    assert report.tolerance is not None
    assert report.tolerance > 0


def test_duplicated_vertices_are_found_with_their_locations() -> None:
    surface = grid()
    picked = np.array([12, 40, 77])
    vertices = np.vstack([surface.vertices, surface.vertices[picked]])
    faces = surface.faces.copy()
    for k, v in enumerate(picked):  # one face of each uses the copy
        row = int(np.flatnonzero((faces == v).any(axis=1))[0])
        faces[row][faces[row] == v] = surface.n_vertices + k
    report = geobrep.inspect(
        surface.replace(vertices=vertices, faces=faces), ["colocated_vertices"]
    )
    section = report.section("colocated_vertices")
    assert section.count == 3
    found = sorted(d.ids for d in section.defects)
    assert found == sorted((int(v), surface.n_vertices + k) for k, v in enumerate(picked))
    for d in section.defects:
        assert np.allclose(d.location, surface.vertices[d.ids[0]])


def test_slivers_and_flipped_faces_and_duplicates() -> None:
    surface = grid()
    n = surface.n_vertices
    sliver_points = np.array(
        [[50.0, 0, 0], [52.0, 0, 0], [51.0, 0, 0], [60.0, 0, 0], [62, 0, 0], [61, 1e-12, 0]]
    )
    vertices = np.vstack([surface.vertices, sliver_points])
    flipped = np.array([3, 55, 120])  # not adjacent to each other
    faces = surface.faces.copy()
    faces[flipped] = faces[flipped][:, ::-1]
    faces = np.vstack(
        [faces, [[n, n + 1, n + 2], [n + 3, n + 4, n + 5]], faces[[10, 11]][:, [1, 2, 0]]]
    )
    report = geobrep.inspect(Surface(vertices=vertices, faces=faces, name="s"))
    assert report.section("degenerate_elements").count == 2
    assert sorted(d.ids[0] for d in report.section("degenerate_elements").defects) == [200, 201]
    assert sorted(d.ids[0] for d in report.section("inconsistent_orientation").defects) == [
        3,
        55,
        120,
    ]
    dup = report.section("duplicated_elements")
    assert sorted(d.ids[0] for d in dup.defects) == [202, 203]
    assert sorted(d.other_ids[0] for d in dup.defects) == [10, 11]


def test_non_manifold_edge_and_vertex_and_isolated_vertex() -> None:
    vertices = [
        [0, 0, 0],
        [1, 0, 0],
        [0, 1, 0],
        [0, -1, 0],
        [0, 0, 1],
        [5, 5, 5],
        [-1, -1, -1],
        [-1, 0, 0],
    ]
    faces = [[0, 1, 2], [1, 0, 3], [0, 1, 4], [0, 6, 7]]
    report = geobrep.inspect(Surface(vertices=vertices, faces=faces, name="fan"))
    edges = report.section("non_manifold_edges")
    assert edges.count == 1
    assert edges.defects[0].ids == (0, 1)
    assert edges.defects[0].value == 3
    assert [d.ids for d in report.section("isolated_vertices").defects] == [(5,)]
    assert [d.ids for d in report.section("non_manifold_vertices").defects] == [(0,)]


def test_crossing_pairs_between_surfaces_and_self_intersection() -> None:
    flat, upright = [], []
    for k in range(4):
        x = 10.0 * k
        flat.append([[x, 0, 0], [x + 2, 0, 0], [x, 2, 0]])
        upright.append([[x + 0.5, 0.5, -1], [x + 0.5, 0.5, 1], [x + 1.0, 0.6, 0.2]])
    a = Surface(vertices=np.reshape(flat, (-1, 3)), faces=np.arange(12).reshape(4, 3), name="a")
    b = Surface(vertices=np.reshape(upright, (-1, 3)), faces=np.arange(12).reshape(4, 3), name="b")
    report = geobrep.inspect(
        Scene(entities=[a, b]), ["surface_intersections", "self_intersections"]
    )
    crossings = report.section("surface_intersections")
    assert crossings.count == 4
    assert sorted((d.ids[0], d.other_ids[0]) for d in crossings.defects) == [
        (k, k) for k in range(4)
    ]
    assert report.section("self_intersections").count == 0
    both = Surface(
        vertices=np.vstack([a.vertices, b.vertices]),
        faces=np.vstack([a.faces, b.faces + 12]),
        name="ab",
    )
    selfish = geobrep.inspect(both, ["self_intersections"]).section("self_intersections")
    assert sorted((d.ids[0], d.other_ids[0]) for d in selfish.defects) == [
        (k, k + 4) for k in range(4)
    ]


def test_polyline_crossing_a_surface() -> None:
    line = PolyLine.from_point_lists([[[2.5, 2.5, -1], [2.5, 2.5, 1], [3.5, 3.5, 1]]], name="well")
    report = geobrep.inspect(Scene(entities=[grid(), line]), ["polyline_intersections"])
    section = report.section("polyline_intersections")
    assert section.count == 1
    assert section.defects[0].ids == (0,)
    assert np.allclose(section.defects[0].location, [2.5, 2.5, 0])


def test_t_junction_and_gap_along_a_contact() -> None:
    left = grid(2, name="left")  # x in [0, 2], y in [0, 2], vertices at y = 0, 1, 2 on x = 2
    xs, ys = np.meshgrid([2.0, 3.0], [0.0, 0.5, 1.0, 1.5, 2.0])
    right_vertices = np.column_stack([xs.ravel(), ys.ravel(), np.zeros(xs.size)])
    faces = []
    for j in range(4):
        a = 2 * j
        faces += [[a, a + 1, a + 3], [a, a + 3, a + 2]]
    right = Surface(vertices=right_vertices, faces=faces, name="right")
    report = geobrep.inspect(Scene(entities=[left, right]), ["t_junctions", "gaps"])
    tj = report.section("t_junctions")
    assert tj.count == 2
    assert sorted(round(d.location[1], 6) for d in tj.defects) == [0.5, 1.5]
    assert all(d.entity == "right" and d.other_entity == "left" for d in tj.defects)
    assert report.section("gaps").count == 0
    repaired, summary = geobrep.repair(Scene(entities=[left, right]))
    assert summary.after["t_junctions"] == 0
    assert summary.before["t_junctions"] == 2
    assert geobrep.inspect(repaired, ["t_junctions", "gaps", "inconsistent_orientation"]).ok
    # A gap: the right surface stops short of the left one.
    shifted = right.replace(vertices=right.vertices + np.array([1e-3, 0, 0]))
    gaps = geobrep.inspect(Scene(entities=[left, shifted]), ["gaps", "t_junctions"]).section("gaps")
    assert gaps.count > 0
    assert all(
        abs(d.location[0] - 2.0) <= 1.001e-3 and d.value is not None and d.value > 5e-4
        for d in gaps.defects
    )


def test_an_unclosed_block_is_found() -> None:
    scene = geobrep.datasets.faulted_layer_cake()
    block = scene.blocks[0]
    patch = scene.topology.patch(block.sides[0].patch)
    surface = scene.get(patch.surface)
    assert isinstance(surface, Surface)
    drop = surface.patch_faces(patch.label)[0]
    keep = np.ones(surface.n_faces, dtype=bool)
    keep[drop] = False
    holed = surface.replace(
        faces=surface.faces[keep],
        patch_labels=None if surface.patch_labels is None else surface.patch_labels[keep],
        cell_data={k: v[keep] for k, v in surface.cell_data.items()},
    )
    broken = scene.replace(entities=[holed if e.id == surface.id else e for e in scene.entities])
    report = geobrep.inspect(broken, ["block_closure", "universe_closure"])
    open_blocks = {d.entity_id for d in report.section("block_closure").defects}
    sides = {patch.positive_block, patch.negative_block} - {scene.universe.id}
    assert open_blocks == sides
    assert all(
        d.value is not None and d.value >= 3 for d in report.section("block_closure").defects
    )


@pytest.mark.parametrize("path", sorted(DATA.glob("*.ml")), ids=lambda p: p.name)
def test_every_model3d_is_inspected_as_written(path: Path) -> None:
    with _quiet():
        scene = geobrep.read(path, repair=False)
    report = geobrep.inspect(scene)
    found = counts(report)
    if path.name == "split_cube.ml":
        assert found["region_sides"] == 2  # the top face runs against its blocks
        top = {d.ids[0] for d in report.section("region_sides").defects}
        assert len(top) == 1
    elif path.name == "not_sealed_cube.ml":
        assert found == {"universe_closure": 1}
    elif path.name == "non_split_cube.ml":
        assert found["inconsistent_orientation"] == 2  # the 2 flipped triangles of `box`
    else:
        assert not {
            "region_sides",
            "block_closure",
            "block_orientation",
            "surface_intersections",
        } & set(found)
    json.loads(report.model_dump_json())


@contextmanager
def _quiet() -> Iterator[None]:
    """The reader's GOCAD warnings (unmatched LAYER ids) are not what these tests look at."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        yield


def test_repair_fixes_split_cube_and_keeps_names_and_ids() -> None:
    with _quiet():
        scene = geobrep.read(DATA / "split_cube.ml", repair=False)
    repaired, report = geobrep.repair(scene)
    assert report.before["region_sides"] == 2
    assert report.after["region_sides"] == 0
    assert geobrep.inspect(repaired).ok
    volumes = sorted(round(repaired.block_mesh(b).volume, 9) for b in repaired.blocks)
    assert volumes == [0.3, 0.7]
    assert [(e.id, e.name, e.type) for e in repaired.entities] == [
        (e.id, e.name, e.type) for e in scene.entities
    ]


def test_repair_removes_injected_mesh_defects_and_keeps_properties() -> None:
    surface = grid()
    surface = surface.replace(
        point_data={"depth": surface.vertices[:, 0] * 2.0},
        cell_data={"unit": np.arange(surface.n_faces)},
    )
    n = surface.n_vertices
    vertices = np.vstack([surface.vertices, surface.vertices[[5]], [[90.0, 0, 0]]])
    faces = surface.faces.copy()
    row = int(np.flatnonzero((faces == 5).any(axis=1))[0])
    faces[row][faces[row] == 5] = n
    faces[[7, 90]] = faces[[7, 90]][:, ::-1]
    faces = np.vstack([faces, faces[[30]]])
    broken = surface.replace(
        vertices=vertices,
        faces=faces,
        point_data={"depth": np.append(surface.point_data["depth"], [10.0, -1.0])},
        cell_data={"unit": np.append(np.arange(surface.n_faces), 30)},
    )
    before = counts(geobrep.inspect(broken))
    assert before == {
        "colocated_vertices": 1,
        "inconsistent_orientation": 2,
        "duplicated_elements": 1,
        "isolated_vertices": 1,
        "non_manifold_edges": 3,  # the duplicate's edges are used by three faces
    }
    repaired, report = geobrep.repair(broken)
    assert geobrep.inspect(repaired).ok
    fixed = repaired.surfaces[0]
    assert fixed.name == "grid"
    assert fixed.n_faces == surface.n_faces
    assert np.allclose(fixed.point_data["depth"].values, fixed.vertices[:, 0] * 2.0)
    assert sorted(fixed.cell_data["unit"].values.tolist()) == list(range(surface.n_faces))
    assert {a.action: a.count for a in report.actions if a.count} == {
        "weld": 1,
        "drop_duplicates": 1,
        "drop_isolated": 1,
        "orient": 2,
    }


def test_bad_input_is_a_clear_error() -> None:
    with pytest.raises(
        OptionsError, match=r"unknown check .colocated_vertice.*did you mean .colocated_vertices."
    ):
        geobrep.inspect(grid(), ["colocated_vertice"])
    with pytest.raises(OptionsError, match="tolerance"):
        geobrep.inspect(grid(), tolerance=-1.0)
    with pytest.raises(OptionsError, match="empty"):
        geobrep.inspect(Scene())
    with pytest.raises(OptionsError, match="gap_tolerance"):
        geobrep.inspect(grid(), ["gaps"], options={"gaps": {"gap_tolerance": -2}})
    with pytest.raises(OptionsError, match="unknown action"):
        geobrep.repair(grid(), ["polish"])


def test_report_is_json_with_a_schema_a_table_and_a_defect_layer() -> None:
    jsonschema = pytest.importorskip("jsonschema")
    surface = grid()
    faces = surface.faces.copy()
    faces[[3, 50]] = faces[[3, 50]][:, ::-1]
    report = geobrep.inspect(surface.replace(faces=faces))
    data = json.loads(report.model_dump_json())
    jsonschema.validate(data, geobrep.schemas.load("inspection"))
    assert geobrep.InspectionReport.model_validate(data) == report
    assert "inconsistent_orientation" in str(report)
    assert "2 defect(s)" in report.table()
    layer = report.to_scene()
    triangles = [e for e in layer.surfaces if e.name == "inconsistent_orientation.triangles"]
    assert len(triangles) == 1
    assert triangles[0].n_faces == 2
    assert triangles[0].metadata["colour"].startswith("#")


def test_stored_schema_is_current() -> None:
    stored = Path(geobrep.schemas.__file__).parent / "inspection.schema.json"
    assert stored.read_text("utf-8") == geobrep.schemas.render(
        geobrep.schemas.generate()["inspection"]
    )


def test_a_plugin_check_appears_in_inspect() -> None:
    def long_edges(scene: Scene, options: object, context: object) -> list[Defect]:
        return [
            Defect(
                entity=s.name, entity_id=s.id, element="face", ids=(0,), location=(0.0, 0.0, 0.0)
            )
            for s in scene.surfaces
        ]

    class Plugin:
        @hookimpl
        def geobrep_register_checks(self, registry):  # type: ignore[no-untyped-def]
            registry.add(CheckSpec(name="test.long_edges", function=long_edges, default=False))

    geobrep.plugins.register(Plugin(), "test-long-edges")
    try:
        assert "test.long_edges" not in geobrep.inspect(grid()).counts()
        report = geobrep.inspect(grid(), ["test.long_edges"])
        assert report.counts() == {"test.long_edges": 1}
        info = next(p for p in geobrep.plugins.list_plugins() if p.name == "test-long-edges")
        assert info.registered["checks"] == ("test.long_edges",)
        builtin = next(p for p in geobrep.plugins.list_plugins() if p.name == "checks")
        assert "colocated_vertices" in builtin.registered["checks"]
    finally:
        geobrep.plugins.reload()
