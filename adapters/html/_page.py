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

from geobrep.adapters.colors import hex_colour, known_values, ramp_colours, scene_colours
from geobrep.adapters.display import drawn_grids_and_wells, drawn_meshes
from geobrep.errors import OptionsError
from geobrep.model.entities import (
    Block,
    Entity,
    PolyLine,
    RegularGrid,
    StructuredGrid,
    Surface,
    Well,
)
from geobrep.model.properties import Property
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
    if isinstance(source, Well):
        _add_markers(entry, source, origin)
    if isinstance(source, RegularGrid | StructuredGrid) and isinstance(geometry, Surface):
        entry["detail"] = " × ".join(str(n) for n in source.counts)
        if geometry.cell_data or geometry.point_data:
            return _coloured(entry, geometry, vertices)
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


def _add_markers(entry: dict[str, Any], well: Well, origin: np.ndarray[Any, Any]) -> None:
    """The well's markers: their points and names (labelled in the view, listed in the panel)."""
    if not well.markers:
        return
    at = well.marker_positions() - origin
    entry["markers"] = {
        "positions": _b64(at.astype("<f4")),
        "names": [m.name or m.surface for m in well.markers],
    }
    entry["detail"] = ", ".join(entry["markers"]["names"])


def _coloured(
    entry: dict[str, Any], boundary: Surface, vertices: np.ndarray[Any, Any]
) -> dict[str, Any]:
    """A grid's boundary coloured by its property: per vertex (a point property) or per face
    (a cell property: each triangle gets its own three vertices)."""
    name, prop = next(iter({**boundary.point_data, **boundary.cell_data}.items()))
    faces = np.asarray(boundary.faces)
    colours = _property_colours(prop)
    if name in boundary.cell_data:
        vertices = vertices[faces].reshape(-1, 3)
        colours = np.repeat(colours, 3, axis=0)
        faces = np.arange(vertices.shape[0]).reshape(-1, 3)
    values = np.asarray(prop.values, dtype=np.float64)
    known = values[known_values(values, _no_data(prop))]
    span = f" {known.min():.4g} – {known.max():.4g}" if known.size else ""
    entry["detail"] = f"{entry['detail']}, {name}{span}"
    entry["positions"] = _b64(vertices.astype("<f4"))
    entry["indices"] = _b64(faces.astype("<u4"))
    entry["count"] = int(faces.size)
    entry["colours"] = _b64(colours)
    return entry


def _property_colours(prop: Property) -> np.ndarray[Any, Any]:
    values = np.asarray(prop.values)
    if values.ndim != 1 or values.dtype.kind not in "biuf":
        raise OptionsError("property: only a numeric scalar property colours a grid")
    return ramp_colours(values, _no_data(prop))


def _no_data(prop: Property) -> float | None:
    return None if prop.no_data_value is None else float(prop.no_data_value)


def page_html(
    scene: Scene,
    *,
    title: str | None = None,
    blocks: bool = True,
    surfaces_with_blocks: bool = False,
    property: str | None = None,
) -> str:
    """The page showing ``scene``. With blocks drawn, the surfaces start hidden (the blocks
    cover them) unless ``surfaces_with_blocks``. Grids are drawn as their outer boundary,
    coloured by their property ``property`` (cell or point) where they have it; wells as
    their trajectory with their markers."""
    pairs = drawn_meshes(scene, blocks) + drawn_grids_and_wells(scene, property)
    if not pairs:
        raise OptionsError(
            "nothing to show: the scene has no surfaces, lines, points, blocks, grids or wells"
        )
    if property is not None and not any(
        property in g.cell_data or property in g.point_data
        for g, s in pairs
        if isinstance(s, RegularGrid | StructuredGrid)
    ):
        raise OptionsError(f"property: no grid of the scene has a property {property!r}")
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
