"""Voxelization: the linear octree of closed bodies (``geobrep.voxelize``), and its demo stage.

The work is done by the builder registered as ``voxelize`` (the built-in plugin
``geobrep.plugins.voxelize``); this module finds it through the registry.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from geobrep.errors import GeobrepError, OptionsError
from geobrep.model.entities import Block, Entity, LinearOctree, Surface
from geobrep.model.scene import Scene

if TYPE_CHECKING:
    from geobrep.demo import DemoContext

__all__ = ["DEMO_DEPTH", "VoxelizationWarning", "demo_stage", "voxelize"]

#: Octree depth of the demo stage (128³ finest cells).
DEMO_DEPTH = 7

Method = Literal["depth-buffer", "exact", "auto"]


class VoxelizationWarning(UserWarning):
    """The voxelizer changed or doubts its method: a ray crossed a body more than twice."""


def voxelize(
    obj: Scene | Surface | Iterable[Entity],
    depth: int = 8,
    method: Method = "auto",
    *,
    fill_rule: Literal["parity", "nonzero"] = "parity",
    bodies: Iterable[str | int] | None = None,
    origin: tuple[float, float, float] | None = None,
    size: float | None = None,
    block_depth: int | None = None,
    name: str | None = None,
    voxelizer: str = "voxelize",
) -> LinearOctree:
    """The linear octree (Morton codes and levels) of closed bodies.

    ``obj`` is a closed :class:`Surface` (one body; leaves carry no labels) or a :class:`Scene`:
    then every block — or only the blocks or closed surfaces named in ``bodies`` (names or
    ids) — is voxelized into one octree whose ``labels`` are the blocks' entity ids (a scene
    without blocks: its closed surfaces, labelled by surface id). A :class:`Block` is passed
    through its scene: ``voxelize(scene, bodies=[block.name])``.

    ``method``: ``"depth-buffer"`` (the patent's three pairs of near/far depth buffers; exact
    when every ray crosses a body at most twice), ``"exact"`` (all crossings, ``fill_rule``
    ``"parity"`` or ``"nonzero"``: right for folded, hollow, C-shaped bodies) or ``"auto"``
    (depth buffers unless some ray crosses a body more than twice, then exact, with a
    :class:`VoxelizationWarning`). The report is in ``octree.metadata["voxelization"]``.

    The cube defaults to the bodies' bounding box grown to a cube from its minimum corner
    (``origin``, ``size`` override it); the finest cells are ``size / 2**depth`` wide.
    ``voxelizer`` names the registered :class:`~geobrep.plugins.VoxelizerSpec` that does the
    work (the built-in one is ``"voxelize"``).

    Example:
        >>> import geobrep
        >>> scene = geobrep.datasets.faulted_layer_cake()
        >>> tree = voxelize(scene, depth=5)
        >>> tree.n_leaves > 0, sorted(set(tree.labels.tolist())) == [b.id for b in scene.blocks]
        (True, True)
    """
    from geobrep.host import registries

    if isinstance(obj, Block):
        raise OptionsError(
            f"{obj.label}: a block is voxelized through its scene: "
            f"voxelize(scene, bodies=[{obj.name or obj.id!r}])"
        )
    labelled = not isinstance(obj, Surface)
    if isinstance(obj, Scene):
        scene = obj
    elif isinstance(obj, Entity):
        scene = Scene(entities=[obj])
        bodies = [int(scene.entities[0].id or 0)]  # this body, closed or not
    else:
        scene = Scene(entities=list(obj))
    spec = registries().voxelizers.get(voxelizer)
    options = spec.validate_options(
        depth=depth,
        method=method,
        fill_rule=fill_rule,
        bodies=None if bodies is None else tuple(bodies),
        origin=origin,
        size=size,
        block_depth=block_depth,
        labels=labelled,
        name=name,
    )
    octree = spec.function(scene, options)
    if not isinstance(octree, LinearOctree):
        raise GeobrepError(f"{spec.label} returned {type(octree).__name__}, not a LinearOctree")
    return octree


def _volume(body: dict[str, Any], key: str) -> float:
    value = body[key]
    return float(value) if isinstance(value, int | float) else float("nan")


def demo_stage(ctx: DemoContext) -> None:
    """Voxelize the blocks of the demo model: leaves per level, volumes, memory, both modes."""
    from geobrep.ops.io import write

    scene = ctx.scene
    start = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", VoxelizationWarning)
        tree = voxelize(scene, depth=DEMO_DEPTH, method="auto")
    elapsed = time.perf_counter() - start
    start = time.perf_counter()
    exact = voxelize(scene, depth=DEMO_DEPTH, method="exact")
    elapsed_exact = time.perf_counter() - start
    same = bool(
        np.array_equal(tree.codes, exact.codes)
        and np.array_equal(tree.levels, exact.levels)
        and tree.labels is not None
        and exact.labels is not None
        and np.array_equal(tree.labels, exact.labels)
    )
    report = tree.metadata["voxelization"]
    assert isinstance(report, dict)
    bodies = report["bodies"]
    assert isinstance(bodies, list)

    cells = 8**DEMO_DEPTH
    full_grid_bytes = cells  # one uint8 block label per finest cell
    per_level = tree.leaf_count_per_level().tolist()
    ctx.lines.append(
        f"voxelize: {len(scene.blocks)} blocks at depth {DEMO_DEPTH} "
        f"({2**DEMO_DEPTH}³ cells of {tree.size / 2**DEMO_DEPTH:.2f} m): {tree.n_leaves} leaves "
        f"in {elapsed:.2f} s (auto); exact mode {elapsed_exact:.2f} s, identical={same}"
    )
    ctx.lines.append(
        "  leaves per level: "
        + ", ".join(f"L{level}={count}" for level, count in enumerate(per_level) if count)
    )
    rows: list[dict[str, Any]] = []
    for body in bodies:
        assert isinstance(body, dict)
        exact_volume = _volume(body, "mesh_volume")
        octree_volume = _volume(body, "octree_volume")
        error = (octree_volume - exact_volume) / exact_volume
        rows.append(
            {
                "label": body["label"],
                "name": body["name"],
                "method": body["method"],
                "max_crossings": body["max_crossings"],
                "mesh_volume_m3": exact_volume,
                "octree_volume_m3": octree_volume,
                "relative_error": error,
            }
        )
        ctx.lines.append(
            f"  block #{body['label']} {str(body['name'])!r:24} {body['method']:12} "
            f"octree {octree_volume:14.1f} m³ vs exact {exact_volume:14.1f} m³ ({error:+.2%})"
        )
    ctx.lines.extend(f"  note: {w.message}" for w in caught)
    ctx.lines.append(
        f"  memory: linear octree {tree.memory_bytes / 1e6:.2f} MB vs full {2**DEMO_DEPTH}³ "
        f"label grid {full_grid_bytes / 1e6:.2f} MB ({tree.memory_bytes / full_grid_bytes:.1%})"
    )
    path = ctx.output / "layer_cake_octree.geobrep"
    write(Scene(entities=[tree], crs=scene.crs, name=f"{scene.name} octree"), path)
    ctx.lines.append(f"  octree written to {path}")
    ctx.summary["voxelize"] = {
        "depth": DEMO_DEPTH,
        "seconds": elapsed,
        "seconds_exact_mode": elapsed_exact,
        "exact_mode_identical": same,
        "leaves": tree.n_leaves,
        "leaves_per_level": per_level,
        "memory_bytes": tree.memory_bytes,
        "full_grid_bytes": full_grid_bytes,
        "blocks": rows,
        "warnings": [str(w.message) for w in caught],
        "file": str(path),
    }
