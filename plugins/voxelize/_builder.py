"""The voxelizer: closed bodies of a scene → one labelled :class:`~geobrep.LinearOctree`.

The cube is processed as ``8**block_depth`` sub-cubes in Morton order (one at a time, so memory
is bounded by one sub-cube's buffers); each sub-cube casts its rays through the whole body, so
its result is exactly that sub-cube's part of the whole. For every body it classifies octants
with the depth buffers or the exact crossing count (``auto`` decides per sub-cube from the ray
crossing counts), emits the leaves in Morton order, and the sub-cubes' leaves are concatenated
(still in order) and merged bottom-up across sub-cube borders.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep import LinearOctree, Scene, VoxelizationWarning
from geobrep.errors import OptionsError
from geobrep.geometry import mesh
from geobrep.geometry.bbox import column_extremes
from geobrep.geometry.morton import morton_decode
from geobrep.plugins.voxelize._bodies import Body, collect_bodies, octree_cube
from geobrep.plugins.voxelize._classify import OctantClassifier, PriorityClassifier
from geobrep.plugins.voxelize._depth_buffers import DepthBufferClassifier, depth_buffers
from geobrep.plugins.voxelize._emission import Leaves, emit_leaves
from geobrep.plugins.voxelize._merge import merge_full_siblings
from geobrep.plugins.voxelize._parity import ExactClassifier
from geobrep.plugins.voxelize._rasterize import ray_crossings
from geobrep.plugins.voxelize.options import SUB_CUBE_DEPTH, VoxelizeOptions

__all__ = ["BodyReport", "build_octree", "voxelize_scene"]


AXES = "xyz"
#: Axes ``auto`` tries for depth buffers of one axis, in order (z first: its rule is the exact
#: mode's, so the answers coincide even for voxel centres lying on the surface).
AUTO_AXES = (2, 0, 1)


@dataclass
class BodyReport:
    """What happened to one body: the method used and the ray crossing statistics."""

    body: Body
    methods: set[str] = field(default_factory=set)
    buffer_axes: set[int] = field(default_factory=set)  # axes whose depth buffers were used
    rays_over_two: list[int | None] = field(default_factory=lambda: [None, None, None])
    max_crossings: int = 0
    doubtful: bool = False  # in some sub-cube, rays along every axis cross more than twice

    @property
    def method(self) -> str:
        if not self.methods:
            return "none"
        return "exact" if "exact" in self.methods else "depth-buffer"

    def count(self, axis: int, counts: NDArray[np.int64]) -> int:
        """Record the crossing counts of one axis' rays; return how many exceed two."""
        over = int(np.count_nonzero(counts > 2))
        self.rays_over_two[axis] = (self.rays_over_two[axis] or 0) + over
        self.max_crossings = max(self.max_crossings, int(counts.max(initial=0)))
        return over

    def as_json(self, octree_volume: float) -> dict[str, Any]:
        mesh_volume = abs(mesh.signed_volume(self.body.vertices, self.body.triangles))
        checked = all(count is not None for count in self.rays_over_two)
        return {
            "label": self.body.label,
            "name": self.body.name,
            "source": self.body.source,
            "method": self.method,
            "depth_buffer_axes": [AXES[a] for a in sorted(self.buffer_axes)],
            "max_crossings": self.max_crossings,
            "rays_over_two": dict(zip(AXES, self.rays_over_two, strict=True)),
            "depth_buffers_exact": (not self.doubtful) if checked or self.buffer_axes else None,
            "mesh_volume": mesh_volume,
            "octree_volume": octree_volume,
        }


def _classifier(
    vertices: NDArray[np.float64],
    body: Body,
    depth: int,
    options: VoxelizeOptions,
    report: BodyReport,
) -> OctantClassifier:
    """The classifier of one body in one sub-cube, recording the crossing statistics.

    Each axis test of the depth buffers keeps every inside voxel (an inside centre has a crossing
    below and above it on any ray) and is exact on rays crossing at most twice. So one axis
    whose rays all cross at most twice gives the exact answer alone: ``auto`` looks for such an
    axis (z, x, y) and falls back to the exact mode when every axis has a ray crossing more than
    twice. ``depth-buffer`` is the patent's method: always the three axes.
    """
    n = 1 << depth
    if options.method == "exact":
        crossings = ray_crossings(vertices, body.triangles, 2, n)
        report.count(2, crossings.counts())
        report.methods.add("exact")
        return ExactClassifier(crossings, depth, options.fill_rule)
    if options.method == "auto":
        z_rays = None
        for axis in AUTO_AXES:
            crossings = ray_crossings(vertices, body.triangles, axis, n)
            z_rays = crossings if axis == 2 else z_rays
            if report.count(axis, crossings.counts()) == 0:
                report.methods.add("depth-buffer")
                report.buffer_axes.add(axis)
                return DepthBufferClassifier([depth_buffers(crossings)], depth)
        assert z_rays is not None
        report.doubtful = True
        report.methods.add("exact")
        return ExactClassifier(z_rays, depth, options.fill_rule)
    per_axis = [ray_crossings(vertices, body.triangles, axis, n) for axis in range(3)]
    over = [report.count(axis, per_axis[axis].counts()) for axis in range(3)]
    report.doubtful |= all(over)
    report.methods.add("depth-buffer")
    report.buffer_axes.update(range(3))
    return DepthBufferClassifier([depth_buffers(c) for c in per_axis], depth)


def _warn(reports: list[BodyReport], requested: str) -> None:
    for report in reports:
        if not report.doubtful or requested == "exact":
            continue
        x, y, z = (count or 0 for count in report.rays_over_two)
        name = f"{report.body.source} {report.body.name!r}"
        counts = (
            f"rays along every axis cross it more than twice ({x} x, {y} y, {z} z rays; "
            f"up to {report.max_crossings} crossings)"
        )
        if requested == "auto":
            message = "depth buffers could be wrong, so the exact mode (all crossings) was used"
        else:
            message = "the depth-buffer result may be wrong (use method='exact' or 'auto')"
        warnings.warn(f"voxelize: {name}: {counts}; {message}", VoxelizationWarning, stacklevel=6)


def build_octree(scene: Scene, options: VoxelizeOptions) -> LinearOctree:
    """The labelled linear octree of the scene's bodies (see :class:`VoxelizeOptions`)."""
    bodies = collect_bodies(scene, options.bodies)
    cube = octree_cube(bodies, options.origin, options.size)
    depth = options.depth
    block_depth = (
        max(0, depth - SUB_CUBE_DEPTH) if options.block_depth is None else options.block_depth
    )
    if block_depth > depth:
        raise OptionsError(
            f"option 'block_depth' ({block_depth}) must not exceed 'depth' ({depth})"
        )
    sub_depth = depth - block_depth
    sub_edge = 1 << sub_depth
    cell = cube.size / float(1 << depth)
    grid = [(body.vertices - cube.origin) / cell for body in bodies]
    boxes = [column_extremes(g) for g in grid]
    reports = [BodyReport(body) for body in bodies]

    parts: list[Leaves] = []
    sub_codes = np.arange(8**block_depth, dtype=np.uint64)
    corners = np.stack(morton_decode(sub_codes), axis=1) * sub_edge
    for sub_code, corner in zip(sub_codes, corners, strict=True):
        active = [
            index
            for index, (lo, hi) in enumerate(boxes)
            if np.all(hi > corner) and np.all(lo < corner + sub_edge)
        ]
        if not active:
            continue
        classifiers = [
            _classifier(grid[i] - corner, bodies[i], sub_depth, options, reports[i]) for i in active
        ]
        leaves = emit_leaves(PriorityClassifier(classifiers, sub_depth))
        if leaves.codes.size == 0:
            continue
        offset = sub_code << np.uint64(3 * sub_depth)
        parts.append(
            Leaves(
                leaves.codes + offset,
                leaves.levels + np.uint8(block_depth),
                np.asarray(active, dtype=np.int64)[leaves.bodies],
            )
        )
    merged = Leaves.concatenate(parts)
    # Each body's volume (before merging across bodies when leaves carry no labels).
    cell_volumes = (cube.size / 2.0 ** np.arange(depth + 1)) ** 3
    per_body = np.bincount(
        merged.bodies, weights=cell_volumes[merged.levels], minlength=len(bodies)
    ).tolist()
    if not options.labels:
        merged = Leaves(merged.codes, merged.levels, np.zeros_like(merged.bodies))
    merged = merge_full_siblings(merged, depth)
    _warn(reports, options.method)
    del grid, parts  # the reports below gather the triangles' corners again: room for them

    labels_of_bodies = np.array([body.label for body in bodies], dtype=np.int64)
    metadata: dict[str, Any] = {
        "voxelization": {
            "requested_method": options.method,
            "fill_rule": options.fill_rule,
            "block_depth": block_depth,
            "bodies": [
                report.as_json(volume) for report, volume in zip(reports, per_body, strict=True)
            ],
        }
    }
    default_name = scene.name or (bodies[0].name if len(bodies) == 1 else "bodies")
    return LinearOctree(
        codes=merged.codes,
        levels=merged.levels,
        depth=depth,
        origin=cube.origin,
        size=cube.size,
        labels=labels_of_bodies[merged.bodies] if options.labels else None,
        name=options.name if options.name is not None else f"{default_name} octree",
        metadata=metadata,
    )


def voxelize_scene(scene: Scene, options: VoxelizeOptions) -> Scene:
    """Builder entry point: the scene with the octree of its bodies appended."""
    return scene.with_entities(build_octree(scene, options))
