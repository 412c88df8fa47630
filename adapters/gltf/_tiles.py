"""3D Tiles 1.1: ``tileset.json`` and one glTF content tile, placed on the globe.

The tile's glTF holds the model in east-north-up metres around the centre of its bounding box
(:class:`~geobrep.adapters.gltf._frame.EnuFrame`, through pyproj from the scene's CRS to ECEF);
the root tile's ``transform`` is the ENU-to-ECEF matrix, so Cesium (or any 3D Tiles viewer)
draws the model at its true place. A scene without a usable CRS needs the georeference from the
user: the longitude, latitude and height where the centre of the model goes.
"""

from __future__ import annotations

import json
from pathlib import Path, PurePosixPath
from typing import Any

import numpy as np

from geobrep.adapters.gltf._frame import EnuFrame
from geobrep.adapters.gltf._read import read_glb
from geobrep.adapters.gltf._write import GEOBREP_KEY, build_glb
from geobrep.errors import FormatError, OptionsError
from geobrep.model.crs import CRS, CRSError
from geobrep.model.scene import Scene
from geobrep.ops.io import atomic_write
from geobrep.ops.temporaries import parse_temporary

__all__ = ["read_tileset", "tiles_frame", "write_tileset"]

_MAX_TILESET_BYTES = 64 * 2**20


def _centre(scene: Scene) -> tuple[float, float, float]:
    bounds = scene.model_copy().bounds
    if bounds is None:
        raise OptionsError("the scene has no geometry to place on the globe")
    centre = bounds.center
    return float(centre[0]), float(centre[1]), float(centre[2])


def _placeable(crs: CRS | None) -> bool:
    """True for a CRS pyproj can put on the globe (projected or geographic); a CRS known only
    by its name (GOCAD's 'Default', 'gocad Local') is a local one and is not looked up."""
    if crs is None or (crs.epsg is None and crs.wkt is None and crs.proj is None):
        return False
    from geobrep.gis.crs_ops import parse_crs

    try:
        parsed = parse_crs(crs)
    except CRSError:
        return False
    return bool(parsed.is_projected or parsed.is_geographic)


def tiles_frame(
    scene: Scene, longitude: float | None, latitude: float | None, height: float | None
) -> EnuFrame:
    """The ENU frame of ``scene``: from its CRS, or from the georeference the user gave."""
    given = [v is not None for v in (longitude, latitude, height)]
    if any(given) and not all(given):
        raise OptionsError("longitude, latitude and height go together")
    anchor = _centre(scene)
    placeable = _placeable(scene.crs)
    if all(given):
        if placeable:
            raise OptionsError(
                f"the scene's CRS ({scene.crs.label}) places it: longitude, latitude "  # type: ignore[union-attr]
                "and height are for a model in a local or unknown CRS"
            )
        return EnuFrame.from_geodetic(anchor, float(longitude), float(latitude), float(height))  # type: ignore[arg-type]
    if not placeable:
        which = (
            "has no CRS"
            if scene.crs is None
            else f"is in a local or unknown CRS ({scene.crs.label})"
        )
        raise OptionsError(
            f"3D Tiles need the model's place on the globe: the scene {which}. Give a "
            "projected or geographic CRS (an EPSG code or WKT) or the georeference of the "
            "model's centre: longitude=..., latitude=..., height=... (degrees, degrees, metres)"
        )
    assert scene.crs is not None
    return EnuFrame.from_crs(scene.crs, anchor)


def _content_name(path: Path) -> str:
    parsed = parse_temporary(path.name)
    stem = parsed[1] if parsed is not None else path.stem
    return f"{stem}.glb"


def write_tileset(
    scene: Scene, written: Scene, path: Path, frame: EnuFrame, *, blocks: bool
) -> None:
    """``path`` (the tileset JSON) and its content ``<stem>.glb`` beside it."""
    content = build_glb(scene, frame, blocks=blocks, written=written)
    name = _content_name(path)
    with atomic_write(path.parent / name) as temporary:
        temporary.write_bytes(content.data)
    low, high = content.local_low, content.local_high
    centre, half = (low + high) / 2, np.maximum((high - low) / 2, 1e-3)
    box = [*centre, half[0], 0.0, 0.0, 0.0, half[1], 0.0, 0.0, 0.0, half[2]]
    tileset = {
        "asset": {
            "version": "1.1",
            "generator": "geobrep",
            "extras": {
                GEOBREP_KEY: {
                    "crs": None if scene.crs is None else scene.crs.label,
                    **frame.describe(),
                }
            },
        },
        "geometricError": float(np.linalg.norm(high - low)),
        "root": {
            "transform": [float(v) for v in frame.ecef_matrix.T.ravel()],  # column-major
            "boundingVolume": {"box": [float(v) for v in box]},
            "geometricError": 0.0,
            "refine": "ADD",
            "content": {"uri": name},
        },
    }
    path.write_text(json.dumps(tileset, indent=1, allow_nan=False))


def _tileset(path: Path) -> dict[str, Any]:
    if path.stat().st_size > _MAX_TILESET_BYTES:
        raise FormatError("tileset JSON larger than 64 MiB", path)
    try:
        document = json.loads(path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise FormatError(f"not a 3D Tiles tileset: {exc}", path) from exc
    if not isinstance(document, dict) or not isinstance(document.get("root"), dict):
        raise FormatError("not a 3D Tiles tileset (no root tile)", path)
    return document


def read_tileset(path: Path) -> Scene:
    """The scene of a tileset geobrep wrote (its root tile's glTF content, beside it)."""
    root = _tileset(path)["root"]
    content = root.get("content")
    uri = content.get("uri") if isinstance(content, dict) else None
    if not isinstance(uri, str):
        raise FormatError("the root tile has no content uri (only single-tile sets are read)", path)
    relative = PurePosixPath(uri)
    if relative.is_absolute() or ".." in relative.parts or ":" in uri or relative.suffix != ".glb":
        raise FormatError(f"content {uri!r}: only a .glb file beside the tileset is read", path)
    target = path.parent / relative
    if not target.is_file():
        raise FormatError(f"content {uri!r} is missing", path)
    return read_glb(target)
