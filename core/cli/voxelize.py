"""``geobrep voxelize IN OUT --depth 8``: the linear octree of a model's closed bodies."""

from __future__ import annotations

import argparse
import json
import time
from typing import Any

from geobrep.cli.common import (
    add_allow_empty,
    format_name,
    read_input,
    recorded_warnings,
    refuse_empty,
)

__all__ = ["add_parser", "run"]


def _bodies(text: str) -> list[str | int]:
    items: list[str | int] = []
    for part in text.split(","):
        part = part.strip()
        if part:
            items.append(int(part) if part.isdigit() else part)
    return items


def _origin(text: str) -> tuple[float, float, float]:
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected X,Y,Z numbers, got {text!r}") from None
    if len(values) != 3:
        raise argparse.ArgumentTypeError(f"expected three numbers X,Y,Z, got {text!r}")
    return values[0], values[1], values[2]


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "voxelize",
        help="linear octree of the closed bodies of a model",
        description=(
            "Voxelize every block of IN (or the closed surfaces of a model without blocks) into "
            "one linear octree (Morton codes, levels, block labels) and write it to OUT."
        ),
    )
    parser.add_argument("input", metavar="IN", help="model to voxelize (any readable format)")
    parser.add_argument("output", metavar="OUT", help="output file, e.g. octree.geobrep")
    parser.add_argument(
        "--depth", type=int, default=8, help="finest level: 2**depth cells per axis (default 8)"
    )
    parser.add_argument(
        "--method",
        choices=("auto", "depth-buffer", "exact"),
        default="auto",
        help="depth buffers, all ray crossings, or auto (default: auto)",
    )
    parser.add_argument(
        "--fill-rule",
        choices=("parity", "nonzero"),
        default="parity",
        help="inside test of the exact mode (default: parity)",
    )
    parser.add_argument(
        "--bodies", type=_bodies, help="comma-separated names or ids of blocks/surfaces"
    )
    parser.add_argument("--origin", type=_origin, help="cube origin X,Y,Z (default: bounds)")
    parser.add_argument("--size", type=float, help="cube edge (default: largest extent)")
    parser.add_argument(
        "--block-depth", type=int, help="process 8**N sub-cubes one at a time (default depth-8)"
    )
    parser.add_argument("--keep-input", action="store_true", help="also write the input model")
    parser.add_argument(
        "--format", type=format_name("read"), help="input format, when the extension is not enough"
    )
    parser.add_argument("--output-format", type=format_name("write"), help="output format name")
    parser.add_argument("--json", action="store_true", help="print the report as JSON")
    add_allow_empty(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from geobrep.model.scene import Scene
    from geobrep.ops.io import write
    from geobrep.ops.voxelization import voxelize

    scene = read_input(args, args.input, format=args.format)
    start = time.perf_counter()
    with recorded_warnings() as caught:
        tree = voxelize(
            scene,
            depth=args.depth,
            method=args.method,
            fill_rule=args.fill_rule,
            bodies=args.bodies,
            origin=args.origin,
            size=args.size,
            block_depth=args.block_depth,
        )
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
    if args.json:
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
