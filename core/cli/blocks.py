"""``geobrep blocks IN... OUT``: build blocks and their topology from conformal surfaces.

Every input file is read and their entities are merged into one scene (ids renumbered, groups
kept, earlier blocks and topology dropped); the scene is built and written to ``OUT`` in the
format its extension names (or ``--format``).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from geobrep.cli.common import add_allow_empty, format_name, read_input
from geobrep.errors import OptionsError
from geobrep.model.entities import Block, Entity
from geobrep.model.scene import Group, Scene
from geobrep.ops.io import write

__all__ = ["add_parser", "describe", "merge_scenes", "run"]


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "blocks",
        help="build blocks from conformal surfaces",
        description=(
            "Build closed, oriented blocks, their patches, arcs and corners from the surfaces of "
            "one or more files (merged into one model), and write the result."
        ),
    )
    parser.add_argument("inputs", nargs="+", metavar="IN", help="input files (e.g. several .ts)")
    parser.add_argument("output", metavar="OUT", help="output file (e.g. .geobrep or .ml)")
    parser.add_argument(
        "--format",
        type=format_name("write"),
        help="output format name, when the extension is not enough",
    )
    parser.add_argument(
        "--input-format", type=format_name("read"), help="input format name for every input file"
    )
    parser.add_argument(
        "--tolerance",
        type=float,
        help="vertex merge and contact distance (model units; default: 4 quanta of the "
        "precision the coordinates carry, e.g. float32 or 2 decimals)",
    )
    parser.add_argument(
        "--relative-tolerance",
        type=float,
        help="vertex merge and contact distance relative to the model diagonal",
    )
    parser.add_argument(
        "--free-borders",
        choices=("internal", "remove", "error"),
        help="patches with a free border: internal surfaces (default), removed (the paper's "
        "rule) or an error",
    )
    parser.add_argument("--gap-tolerance", type=float, help="gap detection distance (model units)")
    parser.add_argument(
        "--no-conformity-check",
        action="store_true",
        help="skip the search for crossing surfaces, T-junctions and gaps",
    )
    parser.add_argument(
        "--no-validate", action="store_true", help="skip the closed/oriented check of each block"
    )
    parser.add_argument(
        "--surfaces", help="comma-separated names of the surfaces to build from (default: all)"
    )
    parser.add_argument("--report", metavar="FILE", help="also write the report as JSON here")
    parser.add_argument("--json", action="store_true", help="print the report as JSON")
    add_allow_empty(parser)
    parser.set_defaults(run=run)


def merge_scenes(scenes: list[Scene], sources: list[str]) -> Scene:
    """One scene holding the entities and groups of all, ids renumbered; blocks are dropped.

    >>> from geobrep import PointSet
    >>> a = Scene(entities=[PointSet(vertices=[[0, 0, 0]], name="a")])
    >>> b = Scene(entities=[PointSet(vertices=[[1, 0, 0]], name="b")])
    >>> [(e.id, e.name) for e in merge_scenes([a, b], ["a.vs", "b.vs"]).entities]
    [(0, 'a'), (1, 'b')]
    """
    crs = None
    crs_source = ""
    entities: list[Entity] = []
    groups: list[Group] = []
    next_id = 0
    for scene, source in zip(scenes, sources, strict=True):
        if scene.crs is not None:
            if crs is not None and scene.crs != crs:
                raise OptionsError(
                    f"{source}: its CRS ({scene.crs.label}) differs from that of {crs_source} "
                    f"({crs.label}); convert the files to one CRS first"
                )
            crs, crs_source = scene.crs, source
        renumber: dict[int, int] = {}
        for entity in scene.entities:
            if isinstance(entity, Block):
                continue
            renumber[int(entity.id or 0)] = next_id
            entities.append(entity.model_copy(update={"id": next_id}))
            next_id += 1

        def remap(group: Group, renumber: dict[int, int] = renumber) -> Group:
            return group.model_copy(
                update={
                    "members": tuple(renumber[m] for m in group.members if m in renumber),
                    "children": tuple(remap(c) for c in group.children),
                }
            )

        groups.extend(remap(g) for g in scene.groups if g.name != "blocks")
    name = scenes[0].name if len(scenes) == 1 else ""
    return Scene(entities=entities, groups=groups, crs=crs, name=name)


def _options(args: argparse.Namespace) -> dict[str, Any]:
    options: dict[str, Any] = {}
    for field in ("tolerance", "relative_tolerance", "free_borders", "gap_tolerance"):
        value = getattr(args, field)
        if value is not None:
            options[field] = value
    if args.no_conformity_check:
        options["check_conformity"] = False
    if args.no_validate:
        options["validate"] = False
    if args.surfaces:
        options["surfaces"] = tuple(s.strip() for s in args.surfaces.split(",") if s.strip())
    return options


def run(args: argparse.Namespace) -> int:
    from geobrep.ops.building import build_blocks
    from geobrep.ops.io import atomic_write

    sources = [str(path) for path in args.inputs]
    scenes = [read_input(args, path, format=args.input_format) for path in sources]
    scene = merge_scenes(scenes, sources)
    built = build_blocks(scene, **_options(args))
    target = write(built, args.output, format=args.format)
    report = built.metadata.get("block_report")
    if args.report:
        with atomic_write(Path(args.report)) as temporary:
            temporary.write_text(json.dumps(report, indent=2))
    if args.json:
        print(json.dumps({"output": str(target), "report": report}, indent=2))
    else:
        print(describe(built, report if isinstance(report, dict) else {}))
        print(f"wrote {target}")
    return 0


def describe(built: Scene, report: dict[str, Any]) -> str:
    """Lines for people: counts, removed patches, the blocks with their units and volumes."""
    topology = built.topology
    lines = [
        f"{len(built.blocks)} blocks + universe, {len(topology.patches)} patches, "
        f"{len(topology.arcs)} arcs, {len(topology.corners)} corners"
    ]
    if report:
        lines.append(
            f"merged {report.get('merged_vertices')} colocated vertices; the sort touched "
            f"{report.get('direction_triangles')} of {report.get('triangles')} triangles"
        )
        for entry in report.get("dangling", []):
            x, y, z = entry["centroid"]
            lines.append(
                f"removed dangling patch of {entry['surface']!r} ({entry['triangles']} "
                f"triangles, {entry['reason']}) near ({x:.2f}, {y:.2f}, {z:.2f})"
            )
    for block in built.blocks:
        volume = block.metadata.get("volume")
        size = f"{volume:.6g}" if isinstance(volume, float) else "?"
        unit = f" ({block.unit_name})" if block.unit_name else ""
        lines.append(f"  #{block.id} {block.name}{unit}: volume {size}")
    return "\n".join(lines)
