"""The one-line summaries of geobrep's own operations, importable without their options models.

:func:`geobrep.batch.operations.builtin_operations` declares each operation with its summary
from here, and ``geobrep --help`` lists the commands from here: the help costs no pydantic
model, no numpy and no plugin.
"""

from __future__ import annotations

__all__ = ["SUMMARIES"]

#: The one-line summary of each built-in operation, by operation name.
SUMMARIES: dict[str, str] = {
    "reproject": "transform a model into another CRS",
    "clip": "cut a model by a plane or to a box",
    "clip_box": "keep the inside of a box or of convex planes",
    "section": "section polygons of blocks and traces of surfaces on a plane",
    "fit": "fit a surface to points (skinning, approximation, kriging, hybrid)",
    "build_blocks": "build blocks from conformal surfaces",
    "build": "run any registered builder",
    "voxelize": "linear octree of the closed bodies of a model",
    "check": "inspect models: defects with their locations (exit 3 when found)",
    "repair": "mend a model: weld, drop degenerate elements, split T-junctions, orient",
    "map_products": "map products: block outlines, top traces and sections as GIS layers",
    "convert": "convert files between formats",
    "render": "render a picture of a model (PNG, off-screen)",
    "view": "write a model as one offline HTML page to look at in a browser",
}
