"""``geobrep voxelize IN OUT --depth 8``: the linear octree of a model's closed bodies.

The options are those of the ``voxelize`` operation (:class:`~geobrep.batch.pipeline.VoxelizeStep`,
the pipeline step's body); the parser is derived from it and :class:`VoxelizeCommand`.
"""

from __future__ import annotations

import json
import time
from typing import Annotated

from geobrep.batch.pipeline import VoxelizeStep
from geobrep.cli.common import read_input, recorded_warnings, refuse_empty
from geobrep.cli.operation import SceneCommand
from geobrep.host.operations import Cli

__all__ = ["COMMAND", "DESCRIPTION", "OPERATION", "VoxelizeCommand", "run"]

OPERATION = "voxelize"
DESCRIPTION = (
    "Voxelize every block of IN (or the closed surfaces of a model without blocks) into "
    "one linear octree (Morton codes, levels, block labels) and write it to OUT."
)


class VoxelizeCommand(SceneCommand):
    """The files and the command-line-only options of ``geobrep voxelize``."""

    keep_input: bool = False
    """also write the input model"""
    as_json: Annotated[bool, Cli(flags=("--json",))] = False
    """print the report as JSON"""


def run(options: VoxelizeStep, args: VoxelizeCommand) -> int:
    from geobrep.model.scene import Scene
    from geobrep.ops.io import write
    from geobrep.ops.voxelization import voxelize

    scene = read_input(args, args.input, format=args.format)
    start = time.perf_counter()
    with recorded_warnings() as caught:
        tree = voxelize(scene, **options.builder_options())
    elapsed = time.perf_counter() - start
    if tree.n_leaves == 0:
        refuse_empty(args, [f"{args.output}: the octree has no leaf"], consequence="not written")
    result = (
        scene.with_entities(tree)
        if args.keep_input
        else Scene(entities=[tree], crs=scene.crs, name=tree.name)
    )
    write(result, args.output, format=args.output_format)
    report = tree.metadata["voxelization"]
    assert isinstance(report, dict)
    full_grid = 8**tree.depth
    summary = {
        "input": args.input,
        "output": args.output,
        "depth": tree.depth,
        "seconds": elapsed,
        "leaves": tree.n_leaves,
        "leaves_per_level": tree.leaf_count_per_level().tolist(),
        "volume": tree.volume,
        "memory_bytes": tree.memory_bytes,
        "full_grid_cells": full_grid,
        "bodies": report["bodies"],
        "warnings": [str(w.message) for w in caught],
    }
    if args.as_json:
        print(json.dumps(summary, indent=2))
        return 0
    print(
        f"{args.input}: depth {tree.depth} ({2**tree.depth}³ cells), {tree.n_leaves} leaves "
        f"in {elapsed:.2f} s -> {args.output}"
    )
    per_level = summary["leaves_per_level"]
    assert isinstance(per_level, list)
    print(
        "  leaves per level: "
        + ", ".join(f"L{level}={count}" for level, count in enumerate(per_level) if count)
    )
    bodies = report["bodies"]
    assert isinstance(bodies, list)
    for body in bodies:
        assert isinstance(body, dict)
        mesh_volume = float(body["mesh_volume"])  # type: ignore[arg-type]
        octree_volume = float(body["octree_volume"])  # type: ignore[arg-type]
        versus = f" ({octree_volume / mesh_volume - 1:+.2%})" if mesh_volume > 0 else ""
        print(
            f"  {body['source']} #{body['label']} {str(body['name'])!r}: {body['method']}, "
            f"octree volume {octree_volume:.6g} vs mesh {mesh_volume:.6g}{versus}"
        )
    print(
        f"  memory: {tree.memory_bytes:,} bytes vs {full_grid:,} for a full grid "
        f"of one byte per cell ({tree.memory_bytes / full_grid:.1%})"
    )
    return 0


COMMAND = VoxelizeCommand
