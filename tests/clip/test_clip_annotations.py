"""Annotation clipping at string, character and stroke precision, with the built-in stroke font."""

from __future__ import annotations

import numpy as np
import pytest

from geobrep import Annotation, Plane
from geobrep.ops.clipping import clip, clip_box
from geobrep.plugins.clip.annotations import annotation_polyline
from geobrep.plugins.clip.glyphs import GLYPHS, glyph_strokes

# height 6: character i spans x = 6i .. 6i + 4 along the baseline
LABEL = Annotation(text="Fault F1", anchor=[0.0, 0.0, 0.0], height=6.0, name="label")


def _precision(name: str) -> dict[str, dict[str, str]]:
    return {"annotation": {"precision": name}}


def test_the_font_covers_printable_ascii() -> None:
    assert set(GLYPHS) == {chr(c) for c in range(32, 127)}
    for character in GLYPHS:
        for stroke in glyph_strokes(character):
            assert stroke.shape[0] >= 2
            assert (stroke[:, 0] >= 0).all()
            assert (stroke[:, 0] <= 4).all()
            assert (stroke[:, 1] >= -2).all()
            assert (stroke[:, 1] <= 6).all()
    assert len(glyph_strokes("é")) == 1  # outside ASCII: a box


def test_string_precision() -> None:
    assert clip(LABEL, Plane.x(60.0), options=_precision("string")) is LABEL
    assert clip(LABEL, Plane.x(20.0), options=_precision("string")) is None
    assert clip(LABEL, Plane.x(20.0), keep="positive", options=_precision("string")) is None


def test_character_precision() -> None:
    left, right = clip(LABEL, Plane.x(20.0), keep="both", options=_precision("character"))
    assert left.text == "Fau"  # 'l' (x = 18..22) crosses the plane: dropped on both sides
    assert left.anchor.tolist() == [0.0, 0.0, 0.0]
    assert right.text == "t F1"
    assert right.anchor.tolist() == [24.0, 0.0, 0.0]  # moved past the dropped characters
    assert right.name == "label"


def test_stroke_precision_conserves_stroke_length() -> None:
    plane = Plane.from_point_normal((19.0, 2.0, 0.0), (1.0, 0.3, 0.0))
    left, right = clip(LABEL, plane, keep="both", options=_precision("stroke"))
    whole = annotation_polyline(LABEL).length
    assert annotation_polyline(left).length + annotation_polyline(right).length == pytest.approx(
        whole
    )
    drawn = annotation_polyline(left)
    assert (plane.signed_distance(drawn.vertices) <= 1e-9).all()
    assert left.text == LABEL.text
    assert "strokes" in left.metadata


def test_oriented_annotation_strokes_follow_its_frame() -> None:
    label = Annotation(
        text="N",
        anchor=[450_000.0, 6_700_000.0, -100.0],
        baseline=[0, 1, 0],
        up=[0, 0, 1],
        height=30.0,
    )
    drawn = annotation_polyline(label)
    assert np.allclose(drawn.vertices[:, 0], 450_000.0)
    assert drawn.bounds.size[2] == pytest.approx(30.0)
    cut = clip(label, Plane.z(-85.0), options=_precision("stroke"))
    assert annotation_polyline(cut).bounds.maxs[2] == pytest.approx(-85.0)


def test_box_cut_by_strokes_twice() -> None:
    kept = clip_box(LABEL, (5.0, 40.0, -10.0, 10.0, -10.0, 10.0), options=_precision("stroke"))
    drawn = annotation_polyline(kept)
    assert drawn.bounds.mins[0] >= 5.0 - 1e-12
    assert drawn.bounds.maxs[0] <= 40.0 + 1e-12


def test_scene_annotations_are_always_given_to_their_clipper(layer_cake) -> None:
    label = Annotation(text="FW1", anchor=[450_495.0, 6_700_400.0, -100.0], height=20.0)
    scene = layer_cake.with_entities(label)
    west, east = clip(scene, Plane.x(450_500.0), keep="both")  # the anchor is west of the plane
    assert west.annotations == ()  # 'F' crosses the plane, 'W1' lies east of it
    assert [a.text for a in east.annotations] == ["W1"]
