"""3D Tiles 1.1: ``tileset.json`` and its glTF content tiles, placed on the globe.

A small model is one tile; a large one (more than :data:`MAX_TILE_TRIANGLES`) one tile per
surface, polyline, point set and block, each with its bounding box, under a root tile whose
box holds them all and whose geometric error is the model's diagonal (a viewer refines to
every tile). A surface, point set or block boundary larger than that is itself split in space
(:mod:`._split`): a k-d tree of tiles without content, each with its children's box and its
diagonal as geometric error, over leaf tiles of at most that many triangles, so a viewer
loads only the leaves in view; reading puts the pieces back together exactly.

The tiles' glTF hold the meshes in east-north-up metres around the centre of the model's
bounding box (:class:`~geobrep.adapters.gltf._frame.EnuFrame`, through pyproj from the scene's
CRS to ECEF); the root tile's ``transform`` is the ENU-to-ECEF matrix, so Cesium (or any 3D
Tiles viewer) draws the model at its true place. A scene without a usable CRS
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
from geobrep.adapters.gltf._read import read_glb_parts
from geobrep.adapters.gltf._split import Part, SplitTree, leaves, reassemble, split_mesh, splittable
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


_Mesh = tuple[Entity, Entity, dict[str, Any] | None]
"""A mesh of a tile: geometry, the entity it shows, where it sits in a split whole (or None)."""
_Plan = list[_Mesh] | tuple[list["_Plan"]]
"""A tile's content (its meshes), or a tile without content over its children."""


def _place(part: Part, key: int, index: int, count: int) -> dict[str, Any]:
    return {
        "key": key,
        "index": index,
        "count": count,
        "n_vertices": part.n_vertices,
        "n_cells": part.n_cells,
        "vertex_ids": part.vertex_ids,
        "cell_ids": part.cell_ids,
    }


def _split_plan(tree: SplitTree, key: int, count: int, numbers: list[int]) -> _Plan:
    if isinstance(tree, Part):
        numbers[0] += 1
        return [(tree.geometry, tree.source, _place(tree, key, numbers[0] - 1, count))]
    return ([_split_plan(half, key, count, numbers) for half in tree],)


def _plan(meshes: list[tuple[Entity, Entity]], limit: int) -> list[_Plan]:
    """The tiles under the root: one for a model of at most ``limit`` triangles (segments,
    points); else one per mesh, and a k-d tree of tiles of at most ``limit`` for a surface or
    point set larger than that (polylines stay whole)."""
    if sum(_cells(g) for g, _ in meshes) <= limit:
        return [[(g, s, None) for g, s in meshes]]
    plans: list[_Plan] = []
    for key, (geometry, source) in enumerate(meshes):
        if _cells(geometry) <= limit or not splittable(geometry):
            plans.append([(geometry, source, None)])
            continue
        tree = split_mesh(geometry, source, limit)
        plans.append(_split_plan(tree, key, len(leaves(tree)), [0]))
    return plans


def _padded(low: NDArray[np.float64], high: NDArray[np.float64]) -> tuple[Any, Any]:
    """``low .. high`` widened to at least 2 mm on each axis (a flat mesh gets a thin box)."""
    centre, half = (low + high) / 2, np.maximum((high - low) / 2, 1e-3)
    return centre - half, centre + half


def _box(low: NDArray[np.float64], high: NDArray[np.float64]) -> list[float]:
    """A 3D Tiles bounding box (centre, then the three half-axes) around ``low .. high``."""
    low, high = _padded(low, high)
    centre, half = (low + high) / 2, (high - low) / 2
    return [float(v) for v in (*centre, half[0], 0, 0, 0, half[1], 0, 0, 0, half[2])]


class _TileWriter:
    """Writes the content tiles of a plan beside the tileset and makes their tile JSON."""

    def __init__(
        self, scene: Scene, written: Scene, path: Path, frame: EnuFrame, **how: Any
    ) -> None:
        self.scene, self.written, self.path, self.frame, self.how = scene, written, path, frame, how
        self.stem, self.count = _stem(path), 0

    def tile(self, plan: _Plan, alone: bool) -> tuple[dict[str, Any], Any, Any]:
        """The tile JSON of ``plan`` and its padded box (``low``, ``high``)."""
        if isinstance(plan, tuple):
            tiles = [self.tile(child, False) for child in plan[0]]
            low = np.min([t[1] for t in tiles], axis=0)
            high = np.max([t[2] for t in tiles], axis=0)
            tile = {
                "boundingVolume": {"box": _box(low, high)},
                "geometricError": float(np.linalg.norm(high - low)),
                "children": [t[0] for t in tiles],
            }
            return tile, low, high
        content = build_glb(
            self.scene,
            self.frame,
            written=self.written,
            meshes=[(g, s) for g, s, _ in plan],
            places=[p for _, _, p in plan],
            # the groups name entities of many tiles: the tileset holds them, not each tile
            extras=None if alone else {"groups": []},
            **self.how,
        )
        name = f"{self.stem}.glb" if alone else f"{self.stem}_{self.count}.glb"
        self.count += 1
        with atomic_write(self.path.parent / name) as temporary:
            content.write_to(temporary)
        low, high = content.local_low, content.local_high
        if not content.meshes or not np.isfinite(low).all():
            low = high = np.zeros(3)
        low, high = _padded(low, high)
        tile = {"boundingVolume": {"box": _box(low, high)}, "geometricError": 0.0}
        tile["content"] = {"uri": name}
        return tile, low, high


def write_tileset(
    scene: Scene,
    written: Scene,
    path: Path,
    frame: EnuFrame,
    *,
    blocks: bool,
    max_tile_triangles: int = MAX_TILE_TRIANGLES,
) -> None:
    """``path`` (the tileset JSON) and its content beside it: ``<stem>.glb`` for a model of at
    most ``max_tile_triangles`` triangles (segments, points); else ``<stem>_<n>.glb`` tiles, one
    per polyline, small surface, point set and block, and a k-d tree of tiles of at most
    ``max_tile_triangles`` for each larger surface, point set or block boundary, under a root
    tile without content whose box holds them all (:mod:`._split`)."""
    plans = _plan(glb_meshes(scene, blocks, written), max_tile_triangles)
    writer = _TileWriter(scene, written, path, frame, blocks=blocks)
    plan = plans[0] if len(plans) == 1 else (plans,)
    top, low, high = writer.tile(plan, isinstance(plan, list))
    error = float(np.linalg.norm(high - low))
    root: dict[str, Any] = {
        "transform": [float(v) for v in frame.ecef_matrix.T.ravel()],  # column-major
        **top,
        "refine": "ADD",
    }
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


def _gathered(tiles: list[tuple[Scene, dict[int, dict[str, Any]]]], path: Path) -> list[Entity]:
    """The entities of the tiles in order, each split mesh put back together where its first
    piece was."""
    entities: list[Entity | int] = []
    pieces: dict[int, list[tuple[Entity, dict[str, Any]]]] = {}
    for scene, places in tiles:
        for number, entity in enumerate(scene.entities):
            place = places.get(number)
            if place is None:
                entities.append(entity)
                continue
            if place["key"] not in pieces:
                entities.append(place["key"])
            pieces.setdefault(place["key"], []).append((entity, place))
    wholes = {
        key: reassemble(sorted(parts, key=lambda p: int(p[1]["index"])), str(path))
        for key, parts in pieces.items()
    }
    return [wholes[e] if isinstance(e, int) else e for e in entities]


def read_tileset(path: Path) -> Scene:
    """The scene of a tileset geobrep wrote: the entities of its tiles' glTF contents (beside
    it), in tile order, split meshes put back together, with the scene fields of the first."""
    document = _tileset(path)
    uris = _content_uris(document["root"], path)
    tiles = [read_glb_parts(_content(uri, path)) for uri in uris]
    first = tiles[0][0]
    if len(tiles) == 1 and not tiles[0][1]:
        return first
    extras = (document.get("asset") or {}).get("extras") or {}
    own = extras.get(GEOBREP_KEY) if isinstance(extras, dict) else None
    try:
        groups = [Group.model_validate(g) for g in (own or {}).get("groups", [])]
    except (TypeError, ValueError) as exc:
        raise FormatError(f"bad groups in asset.extras.geobrep: {exc}", path) from exc
    skipped = [s for scene, _ in tiles for s in scene.metadata.get(SKIPPED_ON_READ, [])]  # type: ignore[union-attr]
    metadata = {k: v for k, v in first.metadata.items() if k != SKIPPED_ON_READ}
    if skipped:
        metadata[SKIPPED_ON_READ] = skipped
    return first.replace(entities=_gathered(tiles, path), groups=groups, metadata=metadata)
