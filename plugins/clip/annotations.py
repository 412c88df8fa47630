"""The Annotation clipper, at the paper's three precisions, with geobrep's stroke font.

A string is laid out from its ``anchor`` along ``baseline`` with glyphs rising along ``up``; the
font's capitals are ``height`` tall and character ``i`` occupies the cell from ``i`` to ``i + 2/3``
heights along the baseline and from a third of a height below it to a height above it
(:mod:`.glyphs`).

* ``"string"``: the annotation is kept only if every character cell is on the kept side.
* ``"character"``: characters whose cell crosses the plane or lies beyond it become spaces; the
  text is trimmed (the anchor moves past dropped leading characters).
* ``"stroke"``: the glyph strokes are cut as lines; the kept parts are stored in
  ``metadata["strokes"]`` as lists of ``[u, v]`` points in heights from the anchor (``u`` along
  the baseline, ``v`` along up). :func:`annotation_polyline` draws an annotation (clipped or not).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep import Annotation, PolyLine
from geobrep.geometry import Plane
from geobrep.geometry.arrays import FloatArray
from geobrep.plugins import ClipContext, Keep, halves, pack_halves
from geobrep.plugins.clip._lines import cut_segments
from geobrep.plugins.clip._sides import vertex_sides
from geobrep.plugins.clip.glyphs import ADVANCE, CAP_HEIGHT, DESCENDER, WIDTH, text_strokes
from geobrep.plugins.clip.options import AnnotationClipOptions, tolerance_of

__all__ = ["annotation_polyline", "annotation_strokes", "clip_annotation"]


def _frame(annotation: Annotation) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Anchor and the model-space vectors of one height along the baseline and along up."""
    along = annotation.baseline / np.linalg.norm(annotation.baseline) * annotation.height
    up = annotation.up / np.linalg.norm(annotation.up) * annotation.height
    return np.asarray(annotation.anchor, dtype=np.float64), along, up


def _to_model(annotation: Annotation, uv: FloatArray) -> FloatArray:
    anchor, along, up = _frame(annotation)
    return np.asarray(anchor + uv[:, :1] * along + uv[:, 1:2] * up, dtype=np.float64)


def annotation_strokes(annotation: Annotation) -> list[FloatArray]:
    """The strokes of an annotation as ``(k, 2)`` arrays in heights from the anchor.

    A clipped annotation's ``metadata["strokes"]`` wins over the font.

    >>> [s.shape for s in annotation_strokes(Annotation(text="L", anchor=[0, 0, 0]))]
    [(3, 2)]
    """
    stored = annotation.metadata.get("strokes")
    if isinstance(stored, list):
        return [np.asarray(stroke, dtype=np.float64).reshape(-1, 2) for stroke in stored]
    return [stroke / CAP_HEIGHT for stroke in text_strokes(annotation.text)]


def annotation_polyline(annotation: Annotation) -> PolyLine:
    """The annotation drawn as a PolyLine in model coordinates (one part per stroke).

    >>> annotation_polyline(Annotation(text="T", anchor=[0, 0, 0], height=6)).length
    10.0
    """
    strokes = annotation_strokes(annotation)
    return PolyLine.from_point_lists(
        [_to_model(annotation, s) for s in strokes],
        name=annotation.name,
        kind=annotation.kind,
        metadata={"annotation": annotation.id},
    )


def _cells(annotation: Annotation) -> FloatArray:
    """``(n, 4, 3)`` corners of each character cell in model coordinates."""
    count = len(annotation.text)
    left = np.arange(count, dtype=np.float64) * ADVANCE / CAP_HEIGHT
    right = left + WIDTH / CAP_HEIGHT
    bottom, top = -DESCENDER / CAP_HEIGHT, 1.0
    u = np.stack([left, right, right, left], axis=1).reshape(-1)
    v = np.tile([bottom, bottom, top, top], count)
    return _to_model(annotation, np.stack([u, v], axis=1)).reshape(count, 4, 3)


def clip_annotation(
    annotation: Annotation,
    plane: Plane,
    keep: Keep,
    options: AnnotationClipOptions,
    context: ClipContext,
) -> Any:
    """Clipper of :class:`Annotation` entities (see the module docstring)."""
    tolerance = tolerance_of(options, context)
    parts: dict[int, Annotation | None] = {}
    for side in halves(keep):
        if options.precision == "stroke" or "strokes" in annotation.metadata:
            parts[side] = _by_stroke(annotation, plane, side, tolerance)
        elif not annotation.text:
            side_of_anchor = plane.side(annotation.anchor, tolerance)[0]
            parts[side] = annotation if side_of_anchor != -side else None
        else:
            corners = _cells(annotation)
            sides = vertex_sides(plane.signed_distance(corners.reshape(-1, 3)), tolerance)
            inside = (sides.reshape(-1, 4) != -side).all(axis=1)
            if options.precision == "string":
                parts[side] = annotation if inside.all() else None
            else:
                parts[side] = _by_character(annotation, inside)
    return pack_halves(keep, parts)


def _by_character(annotation: Annotation, inside: NDArray[np.bool_]) -> Annotation | None:
    if inside.all():
        return annotation
    text = "".join(c if ok else " " for c, ok in zip(annotation.text, inside, strict=True))
    stripped = text.lstrip()
    if not stripped.strip():
        return None
    lead = len(text) - len(stripped)
    anchor, along, _ = _frame(annotation)
    kept = [int(i) for i in np.flatnonzero(inside)]
    return annotation.replace(
        text=stripped.rstrip(),
        anchor=anchor + lead * ADVANCE / CAP_HEIGHT * along,
        metadata={**annotation.metadata, "clipped_characters": [i - lead for i in kept]},
    )


def _by_stroke(
    annotation: Annotation, plane: Plane, side: int, tolerance: float
) -> Annotation | None:
    strokes = annotation_strokes(annotation)
    if not strokes:
        return None
    uv = np.concatenate(strokes)
    points = _to_model(annotation, uv)
    lengths = np.array([len(s) for s in strokes], dtype=np.int64)
    starts = np.concatenate([[0], np.cumsum(lengths)[:-1]])
    chain = np.repeat(np.arange(len(strokes), dtype=np.int64), lengths - 1)
    first = np.arange(uv.shape[0] - 1, dtype=np.int64)
    last_of_stroke = np.zeros(uv.shape[0], dtype=np.bool_)
    last_of_stroke[starts + lengths - 1] = True
    first = first[~last_of_stroke[:-1]]
    segments = np.stack([first, first + 1], axis=1)
    distances = plane.signed_distance(points)
    if (vertex_sides(distances, tolerance) != -side).all():
        kept_uv = strokes
    else:
        cut = cut_segments(
            points, segments, chain, np.zeros(len(strokes), np.bool_), distances, tolerance, side
        )
        crossing_uv = uv[cut.edge_a] + cut.edge_t[:, None] * (uv[cut.edge_b] - uv[cut.edge_a])
        all_uv = np.concatenate([uv[cut.kept_points], crossing_uv])
        kept_uv = [
            all_uv[cut.indices[cut.offsets[r] : cut.offsets[r + 1]]]
            for r in range(cut.offsets.shape[0] - 1)
        ]
    if not kept_uv:
        return None
    stored: list[Any] = [np.asarray(s, dtype=np.float64).tolist() for s in kept_uv]
    return annotation.replace(metadata={**annotation.metadata, "strokes": stored})
