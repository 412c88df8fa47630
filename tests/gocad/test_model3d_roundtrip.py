"""Model3d write → read keeps surfaces, patches, kinds, blocks with signed sides, corners, arcs.

Scenes: the sample model, its clipped halves (fixed and random planes), blocks rebuilt from bare
surfaces, and every .ml in tests/data/gocad. Compared by geometry (ids are renumbered on write).
"""

from __future__ import annotations

import tempfile
import warnings
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from gocad_files import DATA, read_quietly
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import geobrep
from geobrep import Scene, Surface
from geobrep.adapters.gocad._parser import GocadWarning
from geobrep.model.topology import Topology

MODELS = sorted(p.name for p in DATA.glob("*.ml"))
DIGITS = 6


def _point(p: Any) -> tuple[float, ...]:
    return tuple(float(v) for v in np.round(np.asarray(p, dtype=np.float64), DIGITS) + 0.0)


def _patch_keys(scene: Scene) -> dict[int, tuple[Any, ...]]:
    """Patch id → (surface name, triangles, centroid, area vector): geometry, not ids."""
    keys = {}
    for patch in scene.topology.patches:
        surface = scene[patch.surface]
        assert isinstance(surface, Surface)
        faces = surface.faces[surface.patch_faces(patch.label)]
        corners = surface.vertices[faces[:, :3]]
        centroid = corners.reshape(-1, 3).mean(axis=0)
        keys[patch.id] = (surface.name, faces.shape[0], _point(centroid))
    return keys


def _normal(scene: Scene, patch_id: int) -> np.ndarray:
    patch = scene.topology.patch(patch_id)
    surface = scene[patch.surface]
    assert isinstance(surface, Surface)
    c = surface.vertices[surface.faces[surface.patch_faces(patch.label)][:, :3]]
    area = np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0]).sum(axis=0)
    return np.asarray(area / np.linalg.norm(area))


def _summary(scene: Scene, topology: Topology | None = None) -> dict[str, Any]:
    topology = topology or scene.topology
    keyed = scene.replace(topology=topology)
    keys = _patch_keys(keyed)
    blocks = Counter()
    for block in [*scene.blocks, *([scene.universe] if scene.universe else [])]:
        # a side times its patch's normal: the same whichever way the file winds the patch
        sides = frozenset(
            (keys[p], _point(side * _normal(keyed, p) * 1e3)) for p, side in block.sides
        )
        blocks[(block.is_universe, sides)] += 1
    arcs = Counter(
        (
            frozenset((_point(a.points[0]), _point(a.points[-1]))),
            a.points.shape[0],
            tuple(sorted(keys[p] for p in a.patches)),
        )
        for a in topology.arcs
    )
    return {
        "surfaces": sorted(
            # the centroid of the triangles' corners: the same whether patches share their
            # border vertices or each patch has its own (a Model3d member's TFACEs)
            (s.name, s.kind, s.n_vertices > 0, _point(s.vertices[s.faces].reshape(-1, 3).mean(0)))
            for s in scene.surfaces
            if s.n_faces
        ),
        "patches": Counter(keys.values()),
        "blocks": blocks,
        "corners": sorted(_point(c.point) for c in topology.corners),
        "arcs": arcs,
    }


def _round_trip(scene: Scene) -> tuple[Scene, list[str]]:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "model.ml"
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", GocadWarning)
            geobrep.write(scene, path)
        text = path.read_text()
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", GocadWarning)
            back = geobrep.read(path)
    assert "geobrep_kind" not in text or any(
        s.kind not in (None, "horizon", "fault", "boundary") for s in scene.surfaces
    )
    return back, [str(w.message) for w in caught]


def _assert_same(scene: Scene, back: Scene, expected: Topology | None = None) -> None:
    want, got = _summary(scene, expected), _summary(back)
    for key in want:
        assert got[key] == want[key], key


def _model_blocks_checked(messages: list[str]) -> None:
    assert not [m for m in messages if "does not match a REGION" in m]
    assert not [m for m in messages if "key triangle" in m]


def test_sample_model(layer_cake: Scene) -> None:
    back, messages = _round_trip(layer_cake)
    _assert_same(layer_cake, back)
    _model_blocks_checked(messages)
    assert (len(back.topology.corners), len(back.topology.arcs)) == (28, 52)


def _halves(scene: Scene, plane: geobrep.Plane) -> list[Scene]:
    halves = []
    for keep in ("negative", "positive"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            halves.append(geobrep.clip(scene, plane, keep=keep))
    return halves


def _check_half(half: Scene) -> None:
    back, messages = _round_trip(half)
    # the half's corners and arcs by the one rule (the clip carries the cut arcs, not the cap's)
    _assert_same(half, back)
    _model_blocks_checked(messages)
    assert Counter(s.kind for s in back.surfaces) == Counter(s.kind for s in half.surfaces)
    assert len(back.topology.patches) == len(half.topology.patches)


@pytest.mark.parametrize("x", [450_500.0, 450_830.0])
def test_clipped_halves_of_the_sample_model(layer_cake: Scene, x: float) -> None:
    for half in _halves(layer_cake, geobrep.Plane.x(x)):
        _check_half(half)


@settings(
    max_examples=6, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    u=st.floats(0.15, 0.85),
    azimuth=st.floats(0.0, np.pi),
    dip=st.floats(0.0, 1.2),
)
def test_random_clip_planes(layer_cake: Scene, u: float, azimuth: float, dip: float) -> None:
    box = layer_cake.bounds
    low, high = np.asarray(box.mins), np.asarray(box.maxs)
    point = low + u * (high - low)
    normal = np.array([np.cos(azimuth) * np.cos(dip), np.sin(azimuth) * np.cos(dip), np.sin(dip)])
    for half in _halves(layer_cake, geobrep.Plane.from_point_normal(point, normal)):
        if half.blocks:
            _check_half(half)


def test_clipped_real_model_lists_only_written_regions() -> None:
    scene = read_quietly(DATA / "modelA1.ml")
    v = np.concatenate([s.vertices for s in scene.surfaces])
    z = float(v[:, 2].min() + 0.2 * np.ptp(v[:, 2]))
    for half in _halves(scene, geobrep.Plane.z(z)):
        back, messages = _round_trip(half)
        _model_blocks_checked(messages)
        _assert_same(half, back)


def test_clipped_layers_list_only_the_regions_written() -> None:
    """modelA4's LAYERs name the REGIONs of blocks a clip drops; its own FAULT_BLOCK lists
    ids 65-67 that match no REGION in the source: those stay, as the file had them."""
    scene = read_quietly(DATA / "modelA4.ml")
    box = scene.bounds
    assert box is not None
    plane = geobrep.Plane.x(0.5 * (box.mins[0] + box.maxs[0]))
    for half in _halves(scene, plane):
        back, messages = _round_trip(half)
        unmatched = [m for m in messages if "does not match a REGION" in m]
        assert all("FAULT_BLOCK 'no_fault_block_name': id 65" in m for m in unmatched)
        assert len(back.blocks) == len(half.blocks)


@pytest.mark.parametrize("name", ["modelA1.ml", "modelA4.ml"])
def test_rebuilt_blocks(name: str) -> None:
    scene = read_quietly(DATA / name)
    rebuilt = geobrep.build_blocks(Scene(entities=scene.surfaces))
    # the builder, the reader and the reference reader agree on corners and arcs
    counts = (len(rebuilt.topology.corners), len(rebuilt.topology.arcs))
    assert counts == (len(scene.topology.corners), len(scene.topology.arcs))
    assert counts == {"modelA1.ml": (20, 36), "modelA4.ml": (52, 98)}[name]
    back, messages = _round_trip(rebuilt)
    _assert_same(rebuilt, back)
    _model_blocks_checked(messages)


def test_rebuilt_sample_model(layer_cake: Scene) -> None:
    rebuilt = geobrep.build_blocks(Scene(entities=layer_cake.surfaces))
    assert _summary(rebuilt)["corners"] == _summary(layer_cake)["corners"]
    back, messages = _round_trip(rebuilt)
    _assert_same(rebuilt, back)
    _model_blocks_checked(messages)


@pytest.mark.parametrize("name", MODELS)
def test_every_model3d_file(name: str) -> None:
    scene = read_quietly(DATA / name)
    back, _ = _round_trip(scene)
    _assert_same(scene, back)
