"""glTF (.glb) and 3D Tiles: round trips within the float32 error, and what reference readers see.

The float32 bound: positions are stored relative to an origin at the model's centre, so a
coordinate ``c`` rounds by at most ``|c - origin| * 2**-24`` (half an ulp); the tests check
every vertex against that bound and against 1 mm.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from formats_support import rich_scene

import geobrep
from geobrep.errors import FormatError, OptionsError
from geobrep.host.capabilities import SKIPPED_ON_READ, format_losses
from geobrep.model.entities import Entity, PointSet, PolyLine, Surface
from geobrep.model.scene import Scene
from geobrep.ops.io import read, write
from geobrep.plugins import registries

pygltflib = pytest.importorskip("pygltflib")
trimesh = pytest.importorskip("trimesh")
pyproj = pytest.importorskip("pyproj")

GOCAD = Path(__file__).parent.parent / "data" / "gocad"
MODEL3D = sorted(GOCAD.glob("*.ml"))
MILLIMETRE = 1e-3


def _bound(vertices: np.ndarray, origin: np.ndarray) -> np.ndarray:
    """Per vertex: the largest float32 rounding of its coordinates relative to ``origin``."""
    return np.abs(vertices - origin).max(axis=1) * 2.0**-24 * 1.0000001 + 1e-12


def _origin(path: Path) -> np.ndarray:
    gltf = pygltflib.GLTF2.load(str(path))
    return np.asarray(gltf.asset.extras["geobrep"]["origin"], np.float64)


def _assert_same(original: Entity, back: Entity, origin: np.ndarray) -> None:
    assert (back.type, back.id, back.name, back.kind) == (
        original.type,
        original.id,
        original.name,
        original.kind,
    )
    assert back.metadata == original.metadata
    vertices = np.asarray(original.vertices)  # type: ignore[attr-defined]
    error = np.abs(np.asarray(back.vertices) - vertices).max(axis=1)  # type: ignore[attr-defined]
    assert (error <= _bound(vertices, origin)).all(), f"{original.label}: {error.max()} m"
    assert error.max() < MILLIMETRE
    for field in ("point_data", "cell_data"):
        assert getattr(back, field) == getattr(original, field), f"{original.label} {field}"
    if isinstance(original, Surface):
        assert isinstance(back, Surface)
        assert np.array_equal(back.faces, original.faces)
        assert back.patch_names == original.patch_names
        if original.patch_labels is None:
            assert back.patch_labels is None
        else:
            assert np.array_equal(back.patch_labels, original.patch_labels)
    if isinstance(original, PolyLine):
        assert isinstance(back, PolyLine)
        for name in ("indices", "part_offsets", "closed"):
            assert np.array_equal(getattr(back, name), getattr(original, name))


def _assert_scene(original: Scene, back: Scene, origin: np.ndarray) -> None:
    kept = [e for e in original.entities if isinstance(e, Surface | PolyLine | PointSet)]
    assert len(back.entities) == len(kept)
    for entity, again in zip(kept, back.entities, strict=True):
        _assert_same(entity, again, origin)
    assert back.crs == original.crs
    assert back.name == original.name
    assert [g.name for g in back.groups] == [g.name for g in original.groups]


def test_sample_model_round_trip_within_float32_error(tmp_path: Path) -> None:
    scene = rich_scene()
    path = write(scene, tmp_path / "cake.glb")
    back = read(path)
    origin = _origin(path)
    assert np.allclose(origin, scene.bounds.center, atol=0.5)  # type: ignore[union-attr]
    _assert_scene(scene, back, origin)
    blocks = [b for b in scene.blocks if b is not scene.universe]
    skipped = back.metadata[SKIPPED_ON_READ]
    assert len(skipped) == len(blocks)
    recorded = pygltflib.GLTF2.load(str(path)).asset.extras["geobrep"]["float32_rounding_m"]
    measured = max(
        np.abs(np.asarray(b.vertices) - a.vertices).max()  # type: ignore[attr-defined]
        for a, b in zip(
            [e for e in scene.entities if hasattr(e, "vertices") and e.type != "TetMesh"],
            back.entities,
            strict=True,
        )
    )
    assert 0 < recorded < MILLIMETRE
    assert measured <= recorded * 1.01 + 1e-9  # the file says how far it rounded


def test_losses_report_what_gltf_cannot_hold() -> None:
    scene = rich_scene()
    spec = registries().formats.get("gltf")
    lost = format_losses(scene, spec, Path("x.glb"))
    assert "1 TetMesh entities dropped (format holds PointSet, PolyLine, Surface)" in lost
    assert any("Block entities dropped" in line for line in lost)
    assert any("topology dropped" in line for line in lost)


@pytest.mark.parametrize("path", MODEL3D, ids=lambda p: p.name)
def test_model3d_files_round_trip(path: Path, tmp_path: Path) -> None:
    scene = read(path)
    target = write(scene, tmp_path / "model.glb")
    _assert_scene(scene, read(target), _origin(target))


def test_clipped_model_round_trip(tmp_path: Path) -> None:
    scene = geobrep.datasets.faulted_layer_cake()
    centre = scene.bounds.center  # type: ignore[union-attr]
    clipped = geobrep.clip(scene, geobrep.Plane.from_point_normal(centre, (1.0, 0.3, 0.0)))
    target = write(clipped, tmp_path / "clipped.glb")
    back = read(target)
    _assert_scene(clipped, back, _origin(target))
    assert len(back.metadata[SKIPPED_ON_READ]) == len(
        [b for b in clipped.blocks if b is not clipped.universe]
    )


def test_origin_option_and_far_origin_error(tmp_path: Path) -> None:
    scene = geobrep.datasets.faulted_layer_cake()
    near = write(scene, tmp_path / "near.glb")
    far = write(scene, tmp_path / "far.glb", origin=(0.0, 0.0, 0.0))
    surface = scene.surfaces[0]
    err_near = np.abs(read(near).surfaces[0].vertices - surface.vertices).max()
    err_far = np.abs(read(far).surfaces[0].vertices - surface.vertices).max()
    assert err_near < MILLIMETRE < err_far < 1.0  # UTM northings in float32: ~0.25 m
    with pytest.raises(OptionsError):
        write(scene, tmp_path / "bad.glb", origin=(float("nan"), 0.0, 0.0))


def test_trimesh_and_pygltflib_read_what_geobrep_wrote(tmp_path: Path) -> None:
    scene = geobrep.datasets.faulted_layer_cake()
    path = write(scene, tmp_path / "cake.glb")
    origin = _origin(path)
    loaded = trimesh.load(path, force="scene")
    blocks = [b for b in scene.blocks if b is not scene.universe]
    assert set(loaded.geometry) == {s.name for s in scene.surfaces} | {b.name for b in blocks}
    for surface in scene.surfaces:
        mesh = loaded.geometry[surface.name]
        y_up = np.asarray(mesh.vertices, np.float64)
        z_up = np.column_stack([y_up[:, 0], -y_up[:, 2], y_up[:, 1]]) + origin
        assert np.abs(z_up - surface.vertices).max() < MILLIMETRE
        assert np.array_equal(np.asarray(mesh.faces), surface.faces)
    gltf = pygltflib.GLTF2.load(str(path))
    names = [n.name for n in gltf.nodes]
    assert names == [s.name for s in scene.surfaces] + [b.name for b in blocks]
    assert [n.extras["geobrep"]["id"] for n in gltf.nodes][: len(scene.surfaces)] == [
        s.id for s in scene.surfaces
    ]
    colours = [tuple(m.pbrMetallicRoughness.baseColorFactor) for m in gltf.materials]
    unit_of = {b.name: b.unit_name for b in blocks}
    by_unit: dict[str | None, set[tuple[float, ...]]] = {}
    for node in gltf.nodes[len(scene.surfaces) :]:
        by_unit.setdefault(unit_of[node.name], set()).add(colours[node.mesh])
    assert all(len(c) == 1 for c in by_unit.values())  # one colour per unit
    assert len({next(iter(c)) for c in by_unit.values()}) == len(by_unit)
    metadata = gltf.extensions["EXT_structural_metadata"]
    assert metadata["propertyTables"][0]["count"] == len(gltf.meshes)


def test_model_colours_are_kept(tmp_path: Path) -> None:
    scene = geobrep.datasets.faulted_layer_cake()
    red = scene.surfaces[0].replace(metadata={"color": [1.0, 0.0, 0.0]})
    path = write(scene.replace(entities=[red, *scene.entities[1:]]), tmp_path / "c.glb")
    gltf = pygltflib.GLTF2.load(str(path))
    assert gltf.materials[0].pbrMetallicRoughness.baseColorFactor == [1.0, 0.0, 0.0, 1.0]


def test_foreign_glb_reads_at_its_node_transform(tmp_path: Path) -> None:
    box = trimesh.creation.box(extents=(2.0, 4.0, 6.0))
    world = trimesh.transformations.translation_matrix((10.0, 20.0, 30.0))
    foreign = trimesh.Scene()
    foreign.add_geometry(box, node_name="box", geom_name="box", transform=world)
    path = tmp_path / "foreign.glb"
    path.write_bytes(foreign.export(file_type="glb"))
    scene = read(path)
    (surface,) = scene.surfaces
    assert surface.n_faces == 12
    y_up = np.asarray(box.vertices) + np.array([10.0, 20.0, 30.0])
    expected = np.column_stack([y_up[:, 0], -y_up[:, 2], y_up[:, 1]])
    assert np.allclose(np.sort(surface.vertices, axis=0), np.sort(expected, axis=0), atol=1e-6)


@pytest.mark.parametrize(
    ("damage", "message"),
    [
        (lambda data: b"nope" + data[4:], "magic"),
        (lambda data: data[: len(data) // 2], "glTF|outside the binary chunk"),
    ],
)
def test_bad_files_are_format_errors(damage: object, message: str, tmp_path: Path) -> None:
    good = write(geobrep.datasets.faulted_layer_cake(), tmp_path / "good.glb")
    bad = tmp_path / "bad.glb"
    bad.write_bytes(damage(good.read_bytes()))  # type: ignore[operator]
    with pytest.raises(FormatError, match=message):
        read(bad, format="gltf")


def test_accessor_outside_the_chunk_is_a_format_error(tmp_path: Path) -> None:
    good = write(geobrep.datasets.faulted_layer_cake(), tmp_path / "good.glb")
    gltf = pygltflib.GLTF2.load(str(good))
    gltf.accessors[0].count = 10**9
    bad = tmp_path / "bad.glb"
    gltf.save_binary(str(bad))
    with pytest.raises(FormatError, match="past its buffer view"):
        read(bad)


# -- 3D Tiles ------------------------------------------------------------------------------


def _ecef(scene: Scene, points: np.ndarray) -> np.ndarray:
    crs = pyproj.CRS.from_epsg(scene.crs.epsg).to_3d()  # type: ignore[union-attr]
    to_ecef = pyproj.Transformer.from_crs(crs, "EPSG:4978", always_xy=True)
    return np.column_stack(to_ecef.transform(*points.T))


def test_tileset_places_the_model_at_its_true_ecef_position(tmp_path: Path) -> None:
    scene = geobrep.datasets.faulted_layer_cake()
    tileset = write(scene, tmp_path / "tileset.json")
    document = json.loads(tileset.read_text())
    assert document["asset"]["version"] == "1.1"
    root = document["root"]
    assert root["content"]["uri"] == "tileset.glb"
    matrix = np.asarray(root["transform"], np.float64).reshape(4, 4).T  # column-major
    content = trimesh.load(tmp_path / "tileset.glb", force="scene")
    for surface in scene.surfaces:
        y_up = np.asarray(content.geometry[surface.name].vertices, np.float64)
        z_up = np.column_stack([y_up[:, 0], -y_up[:, 2], y_up[:, 1]])  # what 3D Tiles does
        placed = z_up @ matrix[:3, :3].T + matrix[:3, 3]
        assert np.abs(placed - _ecef(scene, surface.vertices)).max() < MILLIMETRE
    back = read(tileset)
    for original, again in zip(scene.surfaces, back.surfaces, strict=True):
        assert np.abs(again.vertices - original.vertices).max() < MILLIMETRE
        assert again.name == original.name
    box = np.asarray(root["boundingVolume"]["box"])
    assert np.all(box[[3, 7, 11]] > 0)


def test_tileset_of_a_local_model_needs_a_georeference(tmp_path: Path) -> None:
    scene = geobrep.datasets.faulted_layer_cake().replace(crs=None)
    with pytest.raises(OptionsError, match="no CRS"):
        write(scene, tmp_path / "tileset.json")
    with pytest.raises(OptionsError, match="go together"):
        write(scene, tmp_path / "tileset.json", longitude=2.0)
    tileset = write(scene, tmp_path / "tileset.json", longitude=2.35, latitude=48.85, height=35.0)
    matrix = np.asarray(json.loads(tileset.read_text())["root"]["transform"]).reshape(4, 4).T
    to_ecef = pyproj.Transformer.from_crs("EPSG:4979", "EPSG:4978", always_xy=True)
    assert np.allclose(matrix[:3, 3], to_ecef.transform(2.35, 48.85, 35.0), atol=1e-6)
    back = read(tileset)
    assert np.abs(back.surfaces[0].vertices - scene.surfaces[0].vertices).max() < MILLIMETRE
    with pytest.raises(OptionsError, match="places it"):
        write(
            geobrep.datasets.faulted_layer_cake(),
            tmp_path / "t.json",
            longitude=2.35,
            latitude=48.85,
            height=35.0,
        )


def test_tileset_content_outside_its_folder_is_refused(tmp_path: Path) -> None:
    tileset = write(geobrep.datasets.faulted_layer_cake(), tmp_path / "tileset.json")
    document = json.loads(tileset.read_text())
    document["root"]["content"]["uri"] = "../elsewhere.glb"
    tileset.write_text(json.dumps(document))
    with pytest.raises(FormatError, match="beside the tileset"):
        read(tileset)


def test_tileset_of_a_gocad_local_crs_takes_the_georeference(tmp_path: Path) -> None:
    scene = read(GOCAD / "modelA1.ml")
    assert scene.crs is not None
    assert scene.crs.epsg is None  # GOCAD's "Default"
    with pytest.raises(OptionsError, match="local or unknown CRS"):
        write(scene, tmp_path / "tileset.json")
    tileset = write(scene, tmp_path / "tileset.json", longitude=7.0, latitude=46.0, height=500.0)
    back = read(tileset)
    assert back.crs == scene.crs
    for original, again in zip(scene.surfaces, back.surfaces, strict=True):
        assert np.abs(again.vertices - original.vertices).max() < MILLIMETRE


def _check_tile(tile: dict, parent_error: float, folder: Path, is_root: bool) -> int:
    """The 3D Tiles 1.1 rules a tile must follow (tileset.schema.json, tile.schema.json,
    boundingVolume.schema.json); the number of tiles with content below and at ``tile``."""
    assert set(tile) <= {"boundingVolume", "geometricError", "refine", "content", "children",
                         "transform", "viewerRequestVolume", "extras", "extensions"}  # fmt: skip
    volume = tile["boundingVolume"]
    assert list(volume) == ["box"]
    assert len(volume["box"]) == 12
    assert all(np.isfinite(volume["box"]))
    assert 0.0 <= tile["geometricError"] <= parent_error  # never more than the parent's
    if is_root:
        assert tile["refine"] in ("ADD", "REPLACE")
        assert len(tile["transform"]) == 16
        assert all(np.isfinite(tile["transform"]))
    else:
        assert "transform" not in tile  # the children share the root's ENU frame
    contents = 0
    if "content" in tile:
        uri = tile["content"]["uri"]
        assert (folder / uri).is_file()
        assert not Path(uri).is_absolute()
        _check_content_inside(folder / uri, np.asarray(volume["box"], np.float64))
        contents += 1
    children = tile.get("children", [])
    assert children or "content" in tile  # a leaf has something to draw
    if children:
        assert tile["geometricError"] > 0  # refining adds what the tile lacks
    for child in children:
        contents += _check_tile(child, tile["geometricError"], folder, False)
    return contents


def _check_content_inside(glb: Path, box: np.ndarray) -> None:
    """Every position of the tile's glTF (y up, as 3D Tiles turn it z up) lies in its box."""
    gltf = pygltflib.GLTF2.load(str(glb))
    centre, half = box[:3], box[[3, 7, 11]]
    for accessor in (
        gltf.accessors[p.attributes.POSITION] for m in gltf.meshes for p in m.primitives
    ):
        low = np.asarray(accessor.min)[[0, 2, 1]] * [1, -1, 1]
        high = np.asarray(accessor.max)[[0, 2, 1]] * [1, -1, 1]
        low, high = np.minimum(low, high), np.maximum(low, high)  # y up -> z up: -z is north
        assert (low >= centre - half - 1e-3).all()
        assert (high <= centre + half + 1e-3).all()


def test_large_model_is_a_tileset_of_one_tile_per_mesh(tmp_path: Path) -> None:
    scene = geobrep.datasets.faulted_layer_cake()
    blocks = [b for b in scene.blocks if b is not scene.universe]
    n_triangles = sum(s.n_faces for s in scene.surfaces)
    tileset = write(scene, tmp_path / "tileset.json", max_tile_triangles=n_triangles - 1)
    document = json.loads(tileset.read_text())
    assert document["asset"]["version"] == "1.1"
    root = document["root"]
    assert "content" not in root
    assert len(root["children"]) == len(scene.surfaces) + len(blocks)
    assert _check_tile(root, document["geometricError"], tmp_path, True) == len(root["children"])
    assert root["geometricError"] == pytest.approx(document["geometricError"])
    # each tile is one named mesh, at its true ECEF place through the root transform
    matrix = np.asarray(root["transform"], np.float64).reshape(4, 4).T
    for surface, child in zip(scene.surfaces, root["children"], strict=False):
        content = trimesh.load(tmp_path / child["content"]["uri"], force="scene")
        assert list(content.geometry) == [surface.name]
        y_up = np.asarray(content.geometry[surface.name].vertices, np.float64)
        z_up = np.column_stack([y_up[:, 0], -y_up[:, 2], y_up[:, 1]])
        placed = z_up @ matrix[:3, :3].T + matrix[:3, 3]
        assert np.abs(placed - _ecef(scene, surface.vertices)).max() < MILLIMETRE
    # read back: the same scene as from one tile, within the float32 error of the original
    back = read(tileset)
    single = read(write(scene, tmp_path / "single.json"))
    assert json.loads((tmp_path / "single.json").read_text())["root"]["content"]["uri"]
    assert back == single
    assert back.groups == single.groups
    assert len(back.metadata[SKIPPED_ON_READ]) == len(blocks)
    for original, again in zip(scene.surfaces, back.surfaces, strict=True):
        assert (again.id, again.name, again.kind) == (original.id, original.name, original.kind)
        assert np.abs(again.vertices - original.vertices).max() < MILLIMETRE
        assert np.array_equal(again.faces, original.faces)
        assert again.point_data == original.point_data


def test_single_tile_tileset_follows_the_tile_rules(tmp_path: Path) -> None:
    scene = geobrep.datasets.faulted_layer_cake()
    document = json.loads(write(scene, tmp_path / "tileset.json").read_text())
    assert _check_tile(document["root"], document["geometricError"], tmp_path, True) == 1


def test_tileset_tree_damage_is_a_format_error(tmp_path: Path) -> None:
    scene = geobrep.datasets.faulted_layer_cake()
    n_triangles = sum(s.n_faces for s in scene.surfaces)
    tileset = write(scene, tmp_path / "tileset.json", max_tile_triangles=n_triangles - 1)
    document = json.loads(tileset.read_text())
    document["root"]["children"][1]["content"]["uri"] = "../outside.glb"
    tileset.write_text(json.dumps(document))
    with pytest.raises(FormatError, match="beside the tileset"):
        read(tileset)
    document["root"]["children"] = {"not": "a list"}
    tileset.write_text(json.dumps(document))
    with pytest.raises(FormatError, match="children are not a list"):
        read(tileset)
    document["root"]["children"] = []
    tileset.write_text(json.dumps(document))
    with pytest.raises(FormatError, match="no content"):
        read(tileset)


def _leaf_parts(root: dict, folder: Path) -> list[tuple[int, int, dict]]:
    """``(depth, triangles, tile_part)`` of every split piece in the tree's leaves."""
    found, stack = [], [(root, 0)]
    while stack:
        tile, depth = stack.pop()
        stack.extend((child, depth + 1) for child in tile.get("children", []))
        if "content" not in tile:
            continue
        gltf = pygltflib.GLTF2.load(str(folder / tile["content"]["uri"]))
        for node in gltf.nodes:
            part = node.extras["geobrep"].get("tile_part")
            if part is not None:
                indices = gltf.accessors[gltf.meshes[node.mesh].primitives[0].indices]
                found.append((depth, indices.count // 3, part))
    return found


def test_large_surfaces_are_split_in_space_and_read_back_whole(tmp_path: Path) -> None:
    scene = geobrep.datasets.faulted_layer_cake()
    blocks = [b for b in scene.blocks if b is not scene.universe]
    largest = max(scene.surfaces, key=lambda s: s.n_faces)
    limit = largest.n_faces // 5
    tileset = write(scene, tmp_path / "tileset.json", max_tile_triangles=limit)
    document = json.loads(tileset.read_text())
    root = document["root"]
    contents = _check_tile(root, document["geometricError"], tmp_path, True)
    pieces = _leaf_parts(root, tmp_path)
    assert contents > len(scene.surfaces) + len(blocks)  # more tiles than meshes
    assert max(depth for depth, _, _ in pieces) >= 4  # root, mesh node, halvings, leaf
    assert all(triangles <= limit for _, triangles, _ in pieces)
    # every triangle of a split surface is in exactly one leaf
    by_key: dict[int, list[dict]] = {}
    for _, _, part in pieces:
        by_key.setdefault(part["key"], []).append(part)
    split_sizes = sorted(parts[0]["n_cells"] for parts in by_key.values())
    assert largest.n_faces in split_sizes
    for parts in by_key.values():
        assert sorted(p["index"] for p in parts) == list(range(parts[0]["count"]))
    # read back: the same scene as one tile gives, each surface whole and exact but for float32
    back = read(tileset)
    single = read(write(scene, tmp_path / "single.json"))
    assert back == single
    assert len(back.metadata[SKIPPED_ON_READ]) == len(blocks)
    for original, again, whole in zip(scene.surfaces, back.surfaces, single.surfaces, strict=True):
        assert (again.id, again.name) == (original.id, original.name)
        assert np.array_equal(again.faces, original.faces)
        assert np.array_equal(again.vertices, whole.vertices)  # the same float32 values
        assert np.abs(again.vertices - original.vertices).max() < MILLIMETRE
        assert again.area == pytest.approx(original.area, rel=1e-8)  # float32 rounding
        assert again.point_data == original.point_data
        assert again.cell_data == original.cell_data


def test_a_large_point_set_is_split_with_its_properties(tmp_path: Path) -> None:
    rng = np.random.default_rng(7)
    points = rng.random((5_000, 3)) * [2_000.0, 3_000.0, 500.0] + [450_000.0, 6_700_000.0, -900.0]
    cloud = PointSet(
        vertices=points,
        name="survey",
        point_data={"depth": points[:, 2].copy(), "class": rng.integers(0, 9, 5_000)},
    )
    scene = Scene(entities=[cloud], crs=geobrep.CRS(epsg=32631))
    tileset = write(scene, tmp_path / "tileset.json", max_tile_triangles=700)
    document = json.loads(tileset.read_text())
    assert _check_tile(document["root"], document["geometricError"], tmp_path, True) == 8
    back = read(tileset).entities[0]
    assert isinstance(back, PointSet)
    assert back.name == "survey"
    assert np.abs(back.vertices - points).max() < MILLIMETRE
    assert np.array_equal(back.point_data["depth"].values, points[:, 2])
    assert np.array_equal(back.point_data["class"].values, cloud.point_data["class"].values)


def test_a_split_surface_missing_a_tile_is_a_format_error(tmp_path: Path) -> None:
    scene = geobrep.datasets.faulted_layer_cake()
    limit = max(s.n_faces for s in scene.surfaces) // 3
    tileset = write(scene, tmp_path / "tileset.json", max_tile_triangles=limit)
    document = json.loads(tileset.read_text())
    halving = next(c for c in document["root"]["children"] if "children" in c)
    halving["children"].pop()
    tileset.write_text(json.dumps(document))
    with pytest.raises(FormatError, match="tiles"):
        read(tileset)


def test_a_tile_claiming_a_huge_whole_is_a_format_error(tmp_path: Path) -> None:
    scene = geobrep.datasets.faulted_layer_cake()
    limit = max(s.n_faces for s in scene.surfaces) // 3
    tileset = write(scene, tmp_path / "tileset.json", max_tile_triangles=limit)
    leaf = next(p for p in sorted(tmp_path.glob("tileset_*.glb")) if _has_part(p))
    gltf = pygltflib.GLTF2.load(str(leaf))
    for node in gltf.nodes:
        if "tile_part" in node.extras["geobrep"]:
            node.extras["geobrep"]["tile_part"]["n_vertices"] = 10**12  # not allocated
    gltf.save_binary(str(leaf))
    with pytest.raises(FormatError, match="fewer vertices"):
        read(tileset)


def _has_part(glb: Path) -> bool:
    nodes = pygltflib.GLTF2.load(str(glb)).nodes
    return any("tile_part" in node.extras["geobrep"] for node in nodes)
