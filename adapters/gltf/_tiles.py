"""3D Tiles 1.1: ``tileset.json`` and its glTF content tiles, placed on the globe.

A small model is one tile; a large one (more than :data:`MAX_TILE_TRIANGLES`) one tile per
surface, polyline, point set and block, each with its bounding box, under a root tile whose
box holds them all and whose geometric error is the model's diagonal (a viewer refines to
every tile). The tiles' glTF hold the meshes in east-north-up metres around the centre of the
model's bounding box (:class:`~geobrep.adapters.gltf._frame.EnuFrame`, through pyproj from
the scene's CRS to ECEF); the root tile's ``transform`` is the ENU-to-ECEF matrix, so Cesium
(or any 3D Tiles viewer) draws the model at its true place. A scene without a usable CRS
needs the georeference from the user: the longitude, latitude and height where the centre of
the model goes.
"""

from __future__ import annotations

import json
from pathlib import Path, PurePosixPath
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.gltf._frame import EnuFrame
from geobrep.adapters.gltf._read import read_glb
from geobrep.adapters.gltf._write import GEOBREP_KEY, build_glb, glb_meshes
from geobrep.errors import FormatError, OptionsError
from geobrep.host.capabilities import SKIPPED_ON_READ
from geobrep.model.crs import CRS, CRSError
from geobrep.model.entities import Entity, PointSet
from geobrep.model.scene import Group, Scene
from geobrep.ops.io import atomic_write
from geobrep.ops.temporaries import parse_temporary

__all__ = ["MAX_TILE_TRIANGLES", "read_tileset", "tiles_frame", "write_tileset"]

_MAX_TILESET_BYTES = 64 * 2**20
_MAX_DEPTH, _MAX_TILES = 64, 100_000

MAX_TILE_TRIANGLES = 250_000
"""A model with more triangles (segments, points) than this is written as one tile per mesh."""


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


def _stem(path: Path) -> str:
    parsed = parse_temporary(path.name)
    return parsed[1] if parsed is not None else path.stem


def _cells(geometry: Entity) -> int:
    """What a mesh weighs in a tile: its triangles, segments or points."""
    return geometry.n_points if isinstance(geometry, PointSet) else geometry.n_cells


def _tiles(
    meshes: list[tuple[Entity, Entity]], max_tile_triangles: int
) -> list[list[tuple[Entity, Entity]]]:
    """One tile for a model of at most ``max_tile_triangles``, else one per mesh."""
    if len(meshes) < 2 or sum(_cells(g) for g, _ in meshes) <= max_tile_triangles:
        return [meshes]
    return [[mesh] for mesh in meshes]


def _box(low: NDArray[np.float64], high: NDArray[np.float64]) -> list[float]:
    """A 3D Tiles bounding box (centre, then the three half-axes) around ``low .. high``."""
    centre, half = (low + high) / 2, np.maximum((high - low) / 2, 1e-3)
    return [float(v) for v in (*centre, half[0], 0, 0, 0, half[1], 0, 0, 0, half[2])]


def write_tileset(
    scene: Scene,
    written: Scene,
    path: Path,
    frame: EnuFrame,
    *,
    blocks: bool,
    max_tile_triangles: int = MAX_TILE_TRIANGLES,
) -> None:
    """``path`` (the tileset JSON) and its content beside it: ``<stem>.glb``, or one
    ``<stem>_<n>.glb`` tile per surface, polyline, point set and block when the model has more
    than ``max_tile_triangles`` triangles (segments, points), children of a root tile without
    content whose box holds them all."""
    groups = _tiles(glb_meshes(scene, blocks, written), max_tile_triangles)
    stem, children = _stem(path), []
    low, high = np.full(3, np.inf), np.full(3, -np.inf)
    # the groups name entities of many tiles: the tileset holds them, not each tile
    alone: dict[str, Any] | None = None if len(groups) == 1 else {"groups": []}
    for number, group in enumerate(groups):
        content = build_glb(
            scene, frame, blocks=blocks, written=written, meshes=group, extras=alone
        )
        name = f"{stem}.glb" if len(groups) == 1 else f"{stem}_{number}.glb"
        with atomic_write(path.parent / name) as temporary:
            temporary.write_bytes(content.data)
        if content.meshes:
            low = np.minimum(low, content.local_low)
            high = np.maximum(high, content.local_high)
        children.append(
            {
                "boundingVolume": {"box": _box(content.local_low, content.local_high)},
                "geometricError": 0.0,
                "content": {"uri": name},
            }
        )
    if not np.isfinite(low).all():
        low = high = np.zeros(3)
    error = float(np.linalg.norm(high - low))
    root: dict[str, Any] = {
        "transform": [float(v) for v in frame.ecef_matrix.T.ravel()],  # column-major
        "boundingVolume": {"box": _box(low, high)},
        "refine": "ADD",
    }
    if len(children) == 1:
        root.update(geometricError=0.0, content=children[0]["content"])
    else:
        root.update(geometricError=error, children=children)
    tileset = {
        "asset": {
            "version": "1.1",
            "generator": "geobrep",
            "extras": {
                GEOBREP_KEY: {
                    "crs": None if scene.crs is None else scene.crs.label,
                    "groups": [g.model_dump(mode="json") for g in written.groups],
                    **frame.describe(),
                }
            },
        },
        "geometricError": error,
        "root": root,
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


def _content_uris(root: dict[str, Any], path: Path) -> list[str]:
    """The content uris of the tile tree, depth first (bounded depth and tile count)."""
    uris: list[str] = []
    stack: list[tuple[Any, int]] = [(root, 0)]
    count = 0
    while stack:
        tile, depth = stack.pop()
        count += 1
        if not isinstance(tile, dict) or depth > _MAX_DEPTH or count > _MAX_TILES:
            raise FormatError(f"a tile is not an object, or more than {_MAX_TILES} tiles", path)
        content = tile.get("content")
        if content is not None:
            uri = content.get("uri") if isinstance(content, dict) else None
            if not isinstance(uri, str):
                raise FormatError("a tile's content has no uri", path)
            uris.append(uri)
        children = tile.get("children", [])
        if not isinstance(children, list):
            raise FormatError("a tile's children are not a list", path)
        stack.extend((child, depth + 1) for child in reversed(children))
    if not uris:
        raise FormatError("the tileset has no content", path)
    return uris


def _content(uri: str, path: Path) -> Path:
    relative = PurePosixPath(uri)
    if relative.is_absolute() or ".." in relative.parts or ":" in uri or relative.suffix != ".glb":
        raise FormatError(f"content {uri!r}: only a .glb file beside the tileset is read", path)
    target = path.parent / relative
    if not target.is_file():
        raise FormatError(f"content {uri!r} is missing", path)
    return target


def read_tileset(path: Path) -> Scene:
    """The scene of a tileset geobrep wrote: the entities of its tiles' glTF contents (beside
    it), in tile order, with the scene fields of the first."""
    document = _tileset(path)
    uris = _content_uris(document["root"], path)
    scenes = [read_glb(_content(uri, path)) for uri in uris]
    first = scenes[0]
    if len(scenes) == 1:
        return first
    extras = (document.get("asset") or {}).get("extras") or {}
    own = extras.get(GEOBREP_KEY) if isinstance(extras, dict) else None
    try:
        groups = [Group.model_validate(g) for g in (own or {}).get("groups", [])]
    except (TypeError, ValueError) as exc:
        raise FormatError(f"bad groups in asset.extras.geobrep: {exc}", path) from exc
    skipped = [s for scene in scenes for s in scene.metadata.get(SKIPPED_ON_READ, [])]  # type: ignore[union-attr]
    metadata = {k: v for k, v in first.metadata.items() if k != SKIPPED_ON_READ}
    if skipped:
        metadata[SKIPPED_ON_READ] = skipped
    return first.replace(
        entities=[e for scene in scenes for e in scene.entities], groups=groups, metadata=metadata
    )
