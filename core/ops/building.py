"""``build_blocks``: closed, oriented blocks and their topology from a conformal surface model.

The work is done by a builder plugin (the built-in one is ``blocks``, from
``geobrep.plugins.blocks``), found through the builder registry like any third-party plugin.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

from geobrep.errors import GeobrepError, TopologyError
from geobrep.model.entities import Block
from geobrep.model.scene import Scene

if TYPE_CHECKING:
    from geobrep.demo import DemoContext

__all__ = ["build_blocks", "demo_stage"]


def build_blocks(scene: Scene, builder: str = "blocks", **options: Any) -> Scene:
    """A new scene whose topology and blocks are built from the scene's surfaces.

    Existing blocks and topology are replaced. ``builder`` names a registered builder; the
    other keywords are its options (for ``blocks``: ``tolerance``, ``relative_tolerance``,
    ``free_borders``, ``check_conformity``, ``gap_tolerance``, ``relative_gap_tolerance``,
    ``angle_tolerance``, ``validate``, ``surfaces``; see ``docs/blocks.md``; by default the
    tolerance follows the precision the coordinates carry). Non-conformal input raises
    :class:`~geobrep.errors.TopologyError` with the places at fault and the options that relax
    the check; the report of the ``blocks`` builder is in ``result.metadata["block_report"]``.

    >>> import geobrep
    >>> model = geobrep.datasets.faulted_layer_cake()
    >>> built = build_blocks(geobrep.Scene(entities=model.surfaces))
    >>> len(built.blocks), built.metadata["block_report"]["direction_triangles"]
    (6, 132)
    """
    from geobrep.host import registries

    spec = registries().builders.get(builder)
    validated = spec.validate_options(options)
    if spec.input_types:
        usable = [e for e in scene.entities if type(e).__name__ in spec.input_types]
        if not usable:
            raise TopologyError(
                f"{spec.label} builds from {', '.join(spec.input_types)} entities; "
                f"the scene has none"
            )
    result = spec.function(scene, validated)
    if not isinstance(result, Scene):
        raise GeobrepError(f"{spec.label} returned {type(result).__name__}, not a Scene")
    return result


def _signed_sets(scene: Scene) -> dict[frozenset[tuple[tuple[int, int], int]], int]:
    """Each block (universe included) as its set of ((surface, label), side), to its id."""
    key = {p.id: (p.surface, p.label) for p in scene.patches}
    return {
        frozenset((key[s.patch], s.side) for s in block.sides): int(block.id or 0)
        for block in scene.of_type(Block)
    }


def demo_stage(ctx: DemoContext) -> None:
    """Rebuild the sample model's blocks from its bare surfaces and compare with the truth."""
    from geobrep.ops.io import write

    truth = ctx.scene
    bare = Scene(name=truth.name, entities=truth.surfaces, crs=truth.crs)
    start = time.perf_counter()
    built = build_blocks(bare)
    elapsed = time.perf_counter() - start
    report = built.metadata["block_report"]
    assert isinstance(report, dict)
    expected, found = _signed_sets(truth), _signed_sets(built)
    same_blocks = expected.keys() == found.keys()
    match = {expected[k]: found[k] for k in expected.keys() & found.keys()}
    worst = 0.0
    for block in truth.blocks:
        rebuilt = match.get(int(block.id or 0))
        if rebuilt is None:
            continue
        want = truth.block_mesh(block).volume
        got = built.block_mesh(rebuilt).volume
        worst = max(worst, abs(got - want) / want)
    renamed = {(match.get(a, -1), match.get(b, -1)) for a, b in truth.block_adjacency()}
    same_adjacency = {tuple(sorted(p)) for p in renamed} == set(built.block_adjacency())
    path = ctx.output / "layer_cake_rebuilt.geobrep"
    write(built, path)
    share = report["sorted_share"]
    assert isinstance(share, float)
    ctx.summary["block_builder"] = {
        "blocks": len(built.blocks),
        "patches": len(built.patches),
        "arcs": len(built.topology.arcs),
        "corners": len(built.topology.corners),
        "same_blocks_and_signed_patch_sets": same_blocks,
        "same_adjacency": same_adjacency,
        "max_relative_volume_difference": worst,
        "merged_vertices": report["merged_vertices"],
        "direction_triangles": report["direction_triangles"],
        "triangles": report["triangles"],
        "sorted_share": share,
        "seconds": elapsed,
        "stage_seconds": report["stage_seconds"],
        "file": str(path),
    }
    ctx.lines.append(
        f"block builder: rebuilt {len(built.blocks)} blocks + universe from "
        f"{len(bare.surfaces)} bare surfaces in {elapsed * 1e3:.0f} ms: same blocks and signed "
        f"patch sets={same_blocks}, same adjacency={same_adjacency}, max volume difference "
        f"{worst:.1e}; the sort touched {report['direction_triangles']} of "
        f"{report['triangles']} triangles ({100 * share:.1f} %) -> {path.name}"
    )
    if not (same_blocks and same_adjacency):
        raise GeobrepError("demo: the rebuilt blocks differ from the sample model's topology")
