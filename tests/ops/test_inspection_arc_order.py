"""The ``arc_patch_order`` check: the patches an arc lists against the right-hand order."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep import Scene

DATA = Path(__file__).resolve().parent.parent / "data" / "gocad"


def _with_arc(scene: Scene, arc_id: int, patches: tuple[int, ...]) -> Scene:
    topology = scene.topology
    arcs = tuple(
        a.model_copy(update={"patches": patches}) if a.id == arc_id else a for a in topology.arcs
    )
    return scene.replace(topology=topology.model_copy(update={"arcs": arcs}))


def _three_patch_arc(scene: Scene) -> geobrep.Arc:
    return next(a for a in scene.topology.arcs if len(set(a.patches)) >= 3)


def test_sample_model_and_its_rebuilt_arcs_are_in_right_hand_order() -> None:
    scene = geobrep.datasets.faulted_layer_cake()
    assert any(len(a.patches) >= 3 for a in scene.topology.arcs)
    report = geobrep.inspect(scene, ["arc_patch_order"])
    assert report.ok, report.table()


def test_a_left_handed_arc_is_found_with_its_id_and_location() -> None:
    scene = geobrep.datasets.faulted_layer_cake()
    arc = _three_patch_arc(scene)
    flipped = _with_arc(scene, arc.id, tuple(reversed(arc.patches)))
    defects = geobrep.inspect(flipped, ["arc_patch_order"]).section("arc_patch_order").defects
    assert [d.ids for d in defects] == [(arc.id,)]
    assert defects[0].element == "arc"
    assert "right-hand order" in defects[0].message
    # The location is the middle of an edge of the arc: on its polyline.
    segments = np.asarray(arc.points)
    a, b = segments[:-1], segments[1:]
    where = np.asarray(defects[0].location)
    t = np.clip(np.einsum("ij,ij->i", where - a, b - a) / np.einsum("ij,ij->i", b - a, b - a), 0, 1)
    distance = np.linalg.norm(a + t[:, None] * (b - a) - where, axis=1).min()
    assert distance < 1e-9 * float(np.ptp(segments, axis=0).max() + 1.0)


def test_a_rotation_is_the_same_order_but_a_foreign_patch_is_not() -> None:
    scene = geobrep.datasets.faulted_layer_cake()
    arc = _three_patch_arc(scene)
    rotated = _with_arc(scene, arc.id, arc.patches[1:] + arc.patches[:1])
    assert geobrep.inspect(rotated, ["arc_patch_order"]).ok
    other = next(p.id for p in scene.topology.patches if p.id not in arc.patches)
    foreign = _with_arc(scene, arc.id, (other, *arc.patches[1:]))
    defects = geobrep.inspect(foreign, ["arc_patch_order"]).section("arc_patch_order").defects
    assert [d.ids for d in defects] == [(arc.id,)]
    assert "not the patches around it" in defects[0].message


def test_a_reversed_arc_direction_reverses_the_order() -> None:
    """Thumb along the arc: the same patches seen from the other end run the other way."""
    scene = geobrep.datasets.faulted_layer_cake()
    arc = _three_patch_arc(scene)
    backwards = arc.model_copy(
        update={"points": np.asarray(arc.points)[::-1].copy(), "start": arc.end, "end": arc.start}
    )
    topology = scene.topology
    arcs = tuple(backwards if a.id == arc.id else a for a in topology.arcs)
    turned = scene.replace(topology=topology.model_copy(update={"arcs": arcs}))
    defects = geobrep.inspect(turned, ["arc_patch_order"]).section("arc_patch_order").defects
    assert [d.ids for d in defects] == [(arc.id,)]


@pytest.mark.parametrize("path", sorted(DATA.glob("*.ml")), ids=lambda p: p.name)
def test_model3d_arcs_are_in_right_hand_order(path: Path) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = geobrep.read(path, repair=False)
    assert scene.topology.arcs
    report = geobrep.inspect(scene, ["arc_patch_order"])
    assert report.ok, report.table()
