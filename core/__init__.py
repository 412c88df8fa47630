"""geobrep: a typed B-Rep scene graph for 3D geological structural models.

>>> import geobrep
>>> scene = geobrep.datasets.faulted_layer_cake()
>>> len(scene.blocks), scene.blocks[0].kind
(6, 'unit')

Files are read and written through the format registry (``geobrep.read`` / ``geobrep.write``);
modelling work is done by plugins (``geobrep.plugins``). Optional heavy libraries (open3d,
pyvista) are imported only by the features that use them.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from geobrep.batch.conversion import ConversionSummary, FileReport, convert
from geobrep.errors import (
    DegenerateGeometryError,
    EntityNotFoundError,
    EntityValidationError,
    FileAccessError,
    FormatError,
    GeobrepError,
    MissingDependencyError,
    OptionsError,
    PluginError,
    TopologyError,
    UnknownFormatError,
)
from geobrep.geometry import BoundingBox, Plane
from geobrep.gis.crs_ops import from_geodataframe, to_geodataframe
from geobrep.gis.map_products import map_products
from geobrep.model.crs import CRS
from geobrep.model.entities import (
    Annotation,
    Block,
    Entity,
    LinearOctree,
    NurbsSurface,
    PatchSide,
    PointSet,
    Polygon,
    PolyLine,
    Surface,
    TetMesh,
)
from geobrep.model.properties import Property
from geobrep.model.scene import Group, Scene
from geobrep.model.topology import Arc, Corner, Patch, Topology
from geobrep.ops.building import build_blocks
from geobrep.ops.clipping import clip, clip_box, section
from geobrep.ops.fitting import FitReport, FitResult, fit
from geobrep.ops.io import read, write
from geobrep.ops.voxelization import VoxelizationWarning, voxelize

if TYPE_CHECKING:
    from geobrep import datasets, plugins
    from geobrep.batch.pipeline import Pipeline
    from geobrep.batch.pipeline_run import PipelineSummary, run_pipeline

__version__ = "0.1.0"

__all__ = [
    "CRS",
    "Annotation",
    "Arc",
    "Block",
    "BoundingBox",
    "ConversionSummary",
    "Corner",
    "DegenerateGeometryError",
    "Entity",
    "EntityNotFoundError",
    "EntityValidationError",
    "FileAccessError",
    "FileReport",
    "FitReport",
    "FitResult",
    "FormatError",
    "GeobrepError",
    "Group",
    "LinearOctree",
    "MissingDependencyError",
    "NurbsSurface",
    "OptionsError",
    "Patch",
    "PatchSide",
    "Pipeline",
    "PipelineSummary",
    "Plane",
    "PluginError",
    "PointSet",
    "PolyLine",
    "Polygon",
    "Property",
    "Scene",
    "Surface",
    "TetMesh",
    "Topology",
    "TopologyError",
    "UnknownFormatError",
    "VoxelizationWarning",
    "__version__",
    "build_blocks",
    "clip",
    "clip_box",
    "convert",
    "datasets",
    "fit",
    "from_geodataframe",
    "map_products",
    "plugins",
    "read",
    "run_pipeline",
    "section",
    "to_geodataframe",
    "voxelize",
    "write",
]

_LAZY_SUBMODULES = {"plugins", "datasets"}
#: Public names whose modules are imported on first use (their pydantic models take a while).
_LAZY_NAMES = {
    "Pipeline": "geobrep.batch.pipeline",
    "PipelineSummary": "geobrep.batch.pipeline_run",
    "run_pipeline": "geobrep.batch.pipeline_run",
}


def __getattr__(name: str) -> Any:
    """Import ``geobrep.plugins``, ``geobrep.datasets`` and the pipeline API on first use."""
    if name in _LAZY_SUBMODULES:
        return importlib.import_module(f"geobrep.{name}")
    if name in _LAZY_NAMES:
        value = getattr(importlib.import_module(_LAZY_NAMES[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'geobrep' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | _LAZY_SUBMODULES | set(_LAZY_NAMES))
