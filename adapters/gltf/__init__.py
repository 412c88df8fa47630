"""glTF 2.0 binary (``.glb``) and 3D Tiles 1.1 (``tileset.json``), through pygltflib and pyproj.

Registers two formats (extra ``web``; 3D Tiles also need pyproj, extra ``gis``):

- ``gltf``: named meshes per surface, polyline, point set and block (its boundary) with
  materials of the model's colours (or a unit palette), float32 positions rebased on an origin
  kept in the file (the centre of the model's bounding box by default), and everything else
  exactly in ``extras.geobrep`` plus EXT_mesh_features / EXT_structural_metadata (name, kind,
  entity id, unit per mesh). The file records the largest float32 rounding it made
  (``asset.extras.geobrep.float32_rounding_m``): about 0.2 mm for a 10 km model.
- ``3dtiles``: a tileset JSON (any ``.json`` name; ``tileset.json`` by custom) and its content
  ``<stem>.glb`` beside it (a model of more than ``max_tile_triangles``: one ``<stem>_<n>.glb``
  tile per surface, polyline, point set and block, each with its bounding box, and a k-d
  tree of tiles for each mesh larger than that), in
  east-north-up metres with the ENU-to-ECEF root transform from the scene's CRS (pyproj), so
  Cesium shows the model at its true place. A scene without a CRS is refused unless
  ``longitude``, ``latitude`` and ``height`` say where its centre goes.

pygltflib (pure Python, maintained, a complete typed model of the glTF 2.0 schema with
extras/extensions as plain JSON and binary-chunk handling) loads the container. The writer
builds the JSON document and the buffers with numpy and writes the .glb container itself (two
chunk headers), the arrays going to the file without a copy (:mod:`._write` says why); the
tests read what it writes with pygltflib and trimesh.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from geobrep.adapters._file_format import full_capabilities
from geobrep.adapters.gltf._frame import OffsetFrame
from geobrep.adapters.gltf._read import read_glb
from geobrep.adapters.gltf._tiles import (
    MAX_TILE_TRIANGLES,
    read_tileset,
    tiles_frame,
    write_tileset,
)
from geobrep.adapters.gltf._write import build_glb
from geobrep.errors import OptionsError
from geobrep.hookspecs import hookimpl
from geobrep.host.capabilities import restrict_scene
from geobrep.host.registry import FormatRegistry, FormatSpec
from geobrep.model.scene import Scene

__all__ = [
    "CAPABILITIES",
    "GltfOptions",
    "TilesOptions",
    "geobrep_register_formats",
    "read_glb",
    "read_tileset",
]

CAPABILITIES = full_capabilities({"PointSet", "PolyLine", "Surface"})


class GltfOptions(BaseModel):
    """Options of the ``gltf`` reader and writer."""

    model_config = ConfigDict(extra="forbid")

    origin: tuple[float, float, float] | None = None
    """World point the float32 positions are relative to (default: the bounding box's centre,
    rounded to whole units)."""
    blocks: bool = True
    """Add each block's boundary mesh (a viewer's picture of the units; not read back)."""


class TilesOptions(BaseModel):
    """Options of the ``3dtiles`` reader and writer."""

    model_config = ConfigDict(extra="forbid")

    longitude: float | None = Field(default=None, ge=-180, le=180)
    """Where the model's centre goes, for a scene in a local or unknown CRS (degrees)."""
    latitude: float | None = Field(default=None, ge=-90, le=90)
    height: float | None = None
    """Ellipsoidal height of the model's centre (metres)."""
    blocks: bool = True
    max_tile_triangles: int = Field(default=MAX_TILE_TRIANGLES, ge=1)
    """A model with more triangles (segments, points) than this is written as one tile per
    surface, polyline, point set and block, each with its bounding box; a surface, point set
    or block boundary with more is split in space into tiles of at most this many."""


def _origin(scene: Scene, origin: tuple[float, float, float] | None) -> OffsetFrame:
    if origin is not None:
        if not np.all(np.isfinite(origin)):
            raise OptionsError(f"origin {origin} is not finite")
        return OffsetFrame(origin)
    bounds = scene.model_copy().bounds
    if bounds is None:
        return OffsetFrame((0.0, 0.0, 0.0))
    centre = np.round(bounds.center)
    return OffsetFrame((float(centre[0]), float(centre[1]), float(centre[2])))


def _write_glb(scene: Scene, path: Path, options: GltfOptions) -> None:
    written = restrict_scene(scene, CAPABILITIES)
    content = build_glb(
        scene, _origin(scene, options.origin), blocks=options.blocks, written=written
    )
    content.write_to(path)


def _write_tiles(scene: Scene, path: Path, options: TilesOptions) -> None:
    frame = tiles_frame(scene, options.longitude, options.latitude, options.height)
    write_tileset(
        scene,
        restrict_scene(scene, CAPABILITIES),
        path,
        frame,
        blocks=options.blocks,
        max_tile_triangles=options.max_tile_triangles,
    )


def _sniff_glb(head: bytes) -> bool:
    return head.startswith(b"glTF")


def _sniff_tiles(head: bytes) -> bool:
    return head.lstrip().startswith(b"{") and b'"geometricError"' in head


@hookimpl
def geobrep_register_formats(registry: FormatRegistry) -> None:
    """Register ``gltf`` and ``3dtiles``."""
    registry.add(
        FormatSpec(
            name="gltf",
            description="glTF 2.0 binary (pygltflib, extra 'web'): float32 rebased on an "
            "origin, names, colours, exact properties in extras",
            extensions=(".glb",),
            reader=lambda path, options: read_glb(path),
            writer=_write_glb,
            sniff=_sniff_glb,
            options=GltfOptions,
            capabilities=CAPABILITIES,
        )
    )
    registry.add(
        FormatSpec(
            name="3dtiles",
            description="3D Tiles 1.1 tileset + .glb content, georeferenced to ECEF (pygltflib "
            "and pyproj, extras 'web' and 'gis')",
            extensions=(".json",),
            reader=lambda path, options: read_tileset(path),
            writer=_write_tiles,
            sniff=_sniff_tiles,
            options=TilesOptions,
            capabilities=CAPABILITIES,
        )
    )
