"""The block builder's report, stored in the built scene's ``metadata["block_report"]``."""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, ConfigDict, Field

from geobrep import Scene
from geobrep.errors import TopologyError

__all__ = ["REPORT_KEY", "BlockCheck", "BlockReport", "DanglingEntry", "block_report"]

#: Key of the report in ``Scene.metadata``.
REPORT_KEY = "block_report"


class _ReportModel(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid")


class DanglingEntry(_ReportModel):
    """A removed patch: its surface, size, why, and where (centroid, model coordinates)."""

    surface: str
    surface_id: int | None
    triangles: int
    reason: str
    centroid: tuple[float, float, float]


class BlockCheck(_ReportModel):
    """Validation of one block through ``Scene.block_mesh``."""

    id: int
    name: str
    unit_name: str | None
    volume: float
    triangles: int
    closed: bool
    oriented: bool


class BlockReport(_ReportModel):
    """Counts, removed patches, the share of triangles the sort touched, times, validation."""

    surfaces: int
    triangles: int
    vertices: int
    merged_vertices: int
    degenerate_triangles: int
    orientation_seams: int
    patches: int
    arcs: int
    corners: int
    blocks: int
    internal_patches: list[int]
    dangling: list[DanglingEntry]
    removed_surfaces: list[str]
    nested_bodies: int
    direction_triangles: int
    sorted_share: float = Field(description="direction triangles / triangles")
    retried_arcs: int
    passes: int
    tolerance: float
    tolerance_source: str = Field(
        default="precision",
        description='"tolerance", "relative_tolerance" or "precision" (from the coordinates)',
    )
    precision: float | None = Field(
        default=None, description="rounding quantum of the coordinates (model units)"
    )
    precision_source: str | None = Field(
        default=None, description='"float32", "2 decimals", "8 significant digits", "float64"'
    )
    gap_tolerance: float
    stage_seconds: dict[str, float]
    validated: bool
    checks: list[BlockCheck]
    universe_closed: bool | None
    volume_balance: float | None = Field(
        description="|Σ block volumes − model volume| / model volume (model = −universe volume)"
    )
    adjacency: list[tuple[int, int]]

    def summary(self) -> str:
        """A few lines for people (the CLI prints them)."""
        times = ", ".join(f"{k} {v * 1e3:.1f}" for k, v in self.stage_seconds.items())
        lines = [
            f"{self.blocks} blocks + universe from {self.surfaces} surfaces "
            f"({self.triangles} triangles, {self.patches} patches, {self.arcs} arcs, "
            f"{self.corners} corners)",
            f"merged {self.merged_vertices} colocated vertices; the sort touched "
            f"{self.direction_triangles} triangles ({100 * self.sorted_share:.2f} %)",
        ]
        if self.internal_patches:
            lines.append(f"internal patches: {self.internal_patches}")
        for entry in self.dangling:
            x, y, z = entry.centroid
            lines.append(
                f"removed dangling patch of {entry.surface!r} ({entry.triangles} triangles, "
                f"{entry.reason}) near ({x:.2f}, {y:.2f}, {z:.2f})"
            )
        for check in self.checks:
            lines.append(
                f"  block #{check.id} {check.name!r} ({check.unit_name or 'unit unknown'}): "
                f"volume {check.volume:.6g}, closed={check.closed}, oriented={check.oriented}"
            )
        lines.append(f"stage times (ms): {times}")
        return "\n".join(lines)


def block_report(scene: Scene) -> BlockReport:
    """The report of the builder that produced ``scene``.

    >>> import geobrep
    >>> block_report(geobrep.datasets.faulted_layer_cake())
    Traceback (most recent call last):
    ...
    geobrep.errors.TopologyError: the scene holds no block report (it was not built by the blocks builder)
    """  # noqa: E501
    data: Any = scene.metadata.get(REPORT_KEY)
    if data is None:
        raise TopologyError(
            "the scene holds no block report (it was not built by the blocks builder)"
        )
    return BlockReport.model_validate(data)
