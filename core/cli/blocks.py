"""``geobrep blocks IN... OUT``: build blocks and their topology from conformal surfaces.

Every input file is read and their entities are merged into one scene (ids renumbered, groups
kept, earlier blocks and topology dropped); the scene is built and written to ``OUT`` in the
format its extension names (or ``--format``).
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path
from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict

from geobrep.batch.pipeline import BuildBlocksStep
from geobrep.cli.common import format_name, read_input
from geobrep.errors import OptionsError
from geobrep.host.operations import Cli, as_dict
from geobrep.model.entities import Block, Entity
from geobrep.model.scene import Group, Scene
from geobrep.ops.io import write

__all__ = [
    "COMMAND",
    "DESCRIPTION",
    "OPERATION",
    "OPTIONS_FOR",
    "BlocksCommand",
    "describe",
    "extra_options",
    "merge_scenes",
    "run",
]

OPERATION = "build_blocks"
DESCRIPTION = (
    "Build closed, oriented blocks, their patches, arcs and corners from the surfaces of "
    "one or more files (merged into one model), and write the result."
)


class BlocksCommand(BaseModel):
    """The files and command-line-only options of ``geobrep blocks``."""

    model_config = ConfigDict(extra="forbid", frozen=True, use_attribute_docstrings=True)

    inputs: Annotated[list[str], Cli(positional=True, nargs="+", metavar="IN")]
    """input files (e.g. several .ts)"""
    output: Annotated[str, Cli(positional=True, metavar="OUT")]
    """output file (e.g. .geobrep or .ml)"""
    format: Annotated[str | None, Cli(parse=format_name("write"))] = None
    """output format name, when the extension is not enough"""
    input_format: Annotated[str | None, Cli(parse=format_name("read"))] = None
    """input format name for every input file"""
    report: Annotated[str | None, Cli(metavar="FILE")] = None
    """also write the report as JSON here"""
    as_json: Annotated[bool, Cli(flags=("--json",))] = False
    """print the report as JSON"""
    allow_empty: bool = False
    """accept a result with nothing in it (otherwise: a warning and exit 4)"""


def extra_options() -> type[BaseModel] | None:
    """The options of the ``blocks`` builder: each is a flag (``--tolerance``, ...)."""
    from geobrep.host import registries

    builders = registries().builders
    return builders.get("blocks").options if "blocks" in builders else None


def options_for(command: BlocksCommand, values: Mapping[str, Any]) -> BuildBlocksStep:
    """The ``build_blocks`` step the arguments give: the builder's flags become its options."""
    model = extra_options()
    options: dict[str, Any] = as_dict(values.get("options") or [])
    if model is not None:
        for name, info in model.model_fields.items():
            if name in values:
                options[info.alias or name] = values[name]
    data = {"builder": values.get("builder", "blocks"), "options": options}
    return BuildBlocksStep.model_validate(data)


OPTIONS_FOR = options_for


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


def run(step: BuildBlocksStep, args: BlocksCommand) -> int:
    from geobrep.ops.building import build_blocks
    from geobrep.ops.io import atomic_write

    sources = [str(path) for path in args.inputs]
    scenes = [read_input(args, path, format=args.input_format) for path in sources]
    scene = merge_scenes(scenes, sources)
    built = build_blocks(scene, step.builder, **step.options)
    target = write(built, args.output, format=args.format)
    report = built.metadata.get("block_report")
    if args.report:
        with atomic_write(Path(args.report)) as temporary:
            temporary.write_text(json.dumps(report, indent=2))
    if args.as_json:
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


COMMAND = BlocksCommand
