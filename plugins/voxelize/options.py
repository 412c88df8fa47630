"""Options of the ``voxelize`` builder (validated by pydantic; the CLI and docs share them)."""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, FiniteFloat

__all__ = ["MAX_VOXELIZE_DEPTH", "SUB_CUBE_DEPTH", "VoxelizeOptions"]

#: Deepest octree the voxelizer builds (4096³ finest cells).
MAX_VOXELIZE_DEPTH = 12
#: Depth of the sub-cubes processed one at a time (256³ voxels) when ``block_depth`` is not set.
SUB_CUBE_DEPTH = 8


class VoxelizeOptions(BaseModel):
    """How to voxelize.

    ``depth``: the finest level (``2**depth`` cells per axis). ``method``: ``"depth-buffer"``
    (the patent's three near/far buffer pairs: exact only for bodies convex along each axis),
    ``"exact"`` (every ray crossing: any closed body) or ``"auto"`` (depth buffers unless a ray
    crosses a body more than twice, then exact, with a warning). ``fill_rule``: ``"parity"``
    (odd number of crossings below) or ``"nonzero"`` (winding number, uses the orientation),
    for the exact mode. ``bodies``: names or ids of the blocks or closed surfaces to voxelize
    (default: every block, or every closed surface of a scene without blocks). ``origin`` and
    ``size``: the octree cube (default: the bodies' bounding box, grown to a cube from its
    minimum corner). ``block_depth``: the cube is processed as ``8**block_depth`` sub-cubes, one
    at a time, to bound memory (default ``max(0, depth - 8)``). ``labels``: label each leaf with
    the id of its block or surface. ``name``: the octree's name.
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    depth: int = Field(default=8, ge=0, le=MAX_VOXELIZE_DEPTH)
    method: Literal["depth-buffer", "exact", "auto"] = "auto"
    fill_rule: Literal["parity", "nonzero"] = "parity"
    bodies: tuple[str | int, ...] | None = None
    origin: tuple[FiniteFloat, FiniteFloat, FiniteFloat] | None = None
    size: float | None = Field(default=None, gt=0, allow_inf_nan=False)
    block_depth: int | None = Field(default=None, ge=0, le=MAX_VOXELIZE_DEPTH)
    labels: bool = True
    name: str | None = None
