"""One self-contained HTML page showing a scene in 3D (three.js inlined: no server, no network).

The page embeds the model as JSON (float32 positions relative to the centre of the model,
base64; the origin is kept so the axes are labelled in world coordinates) and the vendored
three.js bundle (``vendor/``, MIT licence, shipped with its licence text).
"""

from __future__ import annotations

import base64
import html
import json
import re
from functools import cache
from importlib import resources
from typing import Any

import numpy as np

from geobrep.adapters.colors import hex_colour, scene_colours
from geobrep.adapters.display import drawn_meshes
from geobrep.errors import OptionsError
from geobrep.model.entities import Block, Entity, PolyLine, Surface
from geobrep.model.scene import Scene

__all__ = ["page_html"]

_MODES = {"Surface": 4, "PolyLine": 1, "PointSet": 0}
_PLACEHOLDER = re.compile(r"\$([a-z_]+)")


@cache
def _asset(name: str) -> str:
    return resources.files("geobrep.adapters.html").joinpath(name).read_text(encoding="utf-8")


def _b64(array: np.ndarray[Any, Any]) -> str:
    return base64.b64encode(np.ascontiguousarray(array).tobytes()).decode("ascii")


def _object(
    geometry: Entity, source: Entity, origin: np.ndarray[Any, Any], colour: str
) -> dict[str, Any]:
    vertices = np.asarray(geometry.vertices, np.float64) - origin  # type: ignore[attr-defined]
    entry: dict[str, Any] = {
        "name": source.name or source.label,
        "type": source.type,
        "kind": source.kind,
        "colour": colour,
        "visible": True,
        "positions": _b64(vertices.astype("<f4")),
        "mode": _MODES.get(geometry.type, 4),
    }
    if isinstance(source, Block):
        entry["detail"] = source.unit_name or ""
    indices = None
    if isinstance(geometry, Surface):
        indices = np.asarray(geometry.faces)
    elif isinstance(geometry, PolyLine):
        indices = np.asarray(geometry.segments)
    if indices is not None:
        entry["indices"] = _b64(indices.astype("<u4"))
        entry["count"] = int(indices.size)
    else:
        entry["count"] = len(vertices)
    return entry


def page_html(
    scene: Scene,
    *,
    title: str | None = None,
    blocks: bool = True,
    surfaces_with_blocks: bool = False,
) -> str:
    """The page showing ``scene``. With blocks drawn, the surfaces start hidden (the blocks
    cover them) unless ``surfaces_with_blocks``."""
    pairs = drawn_meshes(scene, blocks)
    if not pairs:
        raise OptionsError("nothing to show: the scene has no surfaces, lines, points or blocks")
    lows = np.min([np.asarray(g.vertices).min(axis=0) for g, _ in pairs], axis=0)  # type: ignore[attr-defined]
    highs = np.max([np.asarray(g.vertices).max(axis=0) for g, _ in pairs], axis=0)  # type: ignore[attr-defined]
    origin = np.round((lows + highs) / 2)
    colours = scene_colours(scene)
    has_blocks = any(isinstance(s, Block) for _, s in pairs)
    objects = []
    for geometry, source in pairs:
        colour = (
            hex_colour(colours.get(source.id, (0.7, 0.7, 0.7, 1.0)))
            if source.id is not None
            else "#b3b3b3"
        )
        entry = _object(geometry, source, origin, colour)
        if has_blocks and isinstance(source, Surface) and not surfaces_with_blocks:
            entry["visible"] = source.kind == "fault"
        objects.append(entry)
    crs = scene.crs.label if scene.crs is not None else "unknown"
    names = scene.crs.axis_names if scene.crs is not None else ("X", "Y", "Z")
    units = scene.crs.axis_units if scene.crs is not None else ("m", "m", "m")
    axis_names = [f"{n} ({u})" for n, u in zip(names, units, strict=True)]
    heading = title or scene.name or "geobrep model"
    model = {
        "title": heading,
        "crs": crs,
        "origin": [float(v) for v in origin],
        "bounds": [[float(v) for v in lows - origin], [float(v) for v in highs - origin]],
        "axis_names": axis_names,
        "objects": objects,
    }
    values = {
        "title": html.escape(heading),
        "crs": html.escape(crs),
        "x_axis": html.escape(axis_names[0]),
        "y_axis": html.escape(axis_names[1]),
        "z_axis": html.escape(axis_names[2]),
        "model": json.dumps(model, allow_nan=False).replace("</", "<\\/"),
        "three": _asset("vendor/three-viewer.min.js"),
        "three_licence": _asset("vendor/LICENSE-three.txt").replace("*/", "* /"),
        "viewer": _asset("viewer.js"),
    }
    return _PLACEHOLDER.sub(lambda m: values[m.group(1)], _asset("viewer.html"))
