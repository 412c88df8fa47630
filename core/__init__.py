"""geobrep: a typed B-Rep scene graph for 3D geological structural models.

>>> import geobrep
>>> scene = geobrep.datasets.faulted_layer_cake()
>>> len(scene.blocks), scene.blocks[0].kind
(6, 'unit')

Files are read and written through the format registry (``geobrep.read`` / ``geobrep.write``);
modelling work is done by plugins (``geobrep.plugins``). Every public name is imported on first
use, and optional heavy libraries (open3d, pyvista, pyproj) only by the features that use them.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

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

if TYPE_CHECKING:
    from geobrep import datasets, plugins
    from geobrep.batch.conversion import (
        ConversionSummary,
        FileReport,
        convert,
    )
    from geobrep.batch.pipeline import (
        Pipeline,
    )
    from geobrep.batch.pipeline_run import (
        PipelineSummary,
        run_pipeline,
    )
    from geobrep.geometry import (
        BoundingBox,
        Plane,
    )
    from geobrep.gis.crs_ops import (
        from_geodataframe,
        to_geodataframe,
    )
    from geobrep.gis.map_products import (
        map_products,
    )
    from geobrep.model.crs import (
        CRS,
    )
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
        RegularGrid,
        StructuredGrid,
        Surface,
        TetMesh,
        Well,
        WellLog,
        WellMarker,
        WellZone,
    )
    from geobrep.model.properties import (
        Property,
    )
    from geobrep.model.scene import (
        Group,
        Scene,
    )
    from geobrep.model.topology import (
        Arc,
        Corner,
        Patch,
        Topology,
    )
    from geobrep.ops.building import (
        build_blocks,
    )
    from geobrep.ops.clipping import (
        clip,
        clip_box,
        section,
    )
    from geobrep.ops.fitting import (
        FitReport,
        FitResult,
        fit,
    )
    from geobrep.ops.inspection import (
        InspectionReport,
        inspect,
    )
    from geobrep.ops.io import (
        read,
        write,
    )
    from geobrep.ops.repairing import (
        RepairReport,
        repair,
    )
    from geobrep.ops.voxelization import (
        VoxelizationWarning,
        voxelize,
    )

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
    "InspectionReport",
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
    "RegularGrid",
    "RepairReport",
    "Scene",
    "StructuredGrid",
    "Surface",
    "TetMesh",
    "Topology",
    "TopologyError",
    "UnknownFormatError",
    "VoxelizationWarning",
    "Well",
    "WellLog",
    "WellMarker",
    "WellZone",
    "__version__",
    "build_blocks",
    "clip",
    "clip_box",
    "convert",
    "datasets",
    "fit",
    "from_geodataframe",
    "inspect",
    "map_products",
    "plugins",
    "read",
    "repair",
    "run_pipeline",
    "section",
    "to_geodataframe",
    "voxelize",
    "write",
]

_LAZY_SUBMODULES = {"plugins", "datasets"}
#: Where each public name lives; imported on first use, so that `import geobrep` (and
#: `import geobrep.plugins`, `geobrep.hookspecs`) stays cheap: no numpy, no entity models.
_LAZY_NAMES = {
    "Annotation": "geobrep.model.entities",
    "Arc": "geobrep.model.topology",
    "Block": "geobrep.model.entities",
    "BoundingBox": "geobrep.geometry",
    "CRS": "geobrep.model.crs",
    "ConversionSummary": "geobrep.batch.conversion",
    "Corner": "geobrep.model.topology",
    "Entity": "geobrep.model.entities",
    "FileReport": "geobrep.batch.conversion",
    "FitReport": "geobrep.ops.fitting",
    "FitResult": "geobrep.ops.fitting",
    "Group": "geobrep.model.scene",
    "InspectionReport": "geobrep.ops.inspection",
    "RepairReport": "geobrep.ops.repairing",
    "LinearOctree": "geobrep.model.entities",
    "NurbsSurface": "geobrep.model.entities",
    "Patch": "geobrep.model.topology",
    "PatchSide": "geobrep.model.entities",
    "Pipeline": "geobrep.batch.pipeline",
    "PipelineSummary": "geobrep.batch.pipeline_run",
    "Plane": "geobrep.geometry",
    "PointSet": "geobrep.model.entities",
    "PolyLine": "geobrep.model.entities",
    "Polygon": "geobrep.model.entities",
    "Property": "geobrep.model.properties",
    "RegularGrid": "geobrep.model.entities",
    "StructuredGrid": "geobrep.model.entities",
    "Scene": "geobrep.model.scene",
    "Surface": "geobrep.model.entities",
    "TetMesh": "geobrep.model.entities",
    "Topology": "geobrep.model.topology",
    "VoxelizationWarning": "geobrep.ops.voxelization",
    "Well": "geobrep.model.entities",
    "WellLog": "geobrep.model.entities",
    "WellMarker": "geobrep.model.entities",
    "WellZone": "geobrep.model.entities",
    "build_blocks": "geobrep.ops.building",
    "clip": "geobrep.ops.clipping",
    "clip_box": "geobrep.ops.clipping",
    "convert": "geobrep.batch.conversion",
    "fit": "geobrep.ops.fitting",
    "from_geodataframe": "geobrep.gis.crs_ops",
    "inspect": "geobrep.ops.inspection",
    "repair": "geobrep.ops.repairing",
    "map_products": "geobrep.gis.map_products",
    "read": "geobrep.ops.io",
    "run_pipeline": "geobrep.batch.pipeline_run",
    "section": "geobrep.ops.clipping",
    "to_geodataframe": "geobrep.gis.crs_ops",
    "voxelize": "geobrep.ops.voxelization",
    "write": "geobrep.ops.io",
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
