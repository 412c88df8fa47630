"""Check a built scene: every block closed, outward-oriented and of positive volume (through
:meth:`~geobrep.scene.Scene.block_mesh`), every patch with a block on both sides, and the block
volumes adding up to the volume inside the universe."""

from __future__ import annotations

from dataclasses import dataclass

from geobrep.errors import TopologyError
from geobrep.plugins.blocks.report import BlockCheck
from geobrep.scene import Scene

__all__ = ["Validation", "validate_scene"]


@dataclass(frozen=True)
class Validation:
    checks: list[BlockCheck]
    universe_closed: bool | None
    volume_balance: float | None


def validate_scene(scene: Scene, relative_volume_tolerance: float = 1e-6) -> Validation:
    """Validate the blocks of ``scene``; a failure is a :class:`TopologyError` naming them."""
    problems: list[str] = []
    checks: list[BlockCheck] = []
    for block in scene.blocks:
        boundary = scene.block_mesh(block)
        check = BlockCheck(
            id=int(block.id or 0),
            name=block.name,
            unit_name=block.unit_name,
            volume=boundary.volume,
            triangles=boundary.n_faces,
            closed=boundary.is_closed,
            oriented=boundary.is_consistently_oriented,
        )
        checks.append(check)
        if not (check.closed and check.oriented and check.volume > 0.0):
            problems.append(
                f"{block.label}: closed={check.closed}, oriented={check.oriented}, "
                f"volume={check.volume:.6g}"
            )
    one_sided = [
        p.id for p in scene.patches if p.positive_block is None or p.negative_block is None
    ]
    if one_sided:
        problems.append(f"patches without a block on both sides: {one_sided[:10]}")
    universe_closed: bool | None = None
    balance: float | None = None
    universe = scene.universe
    if universe is not None and universe.sides:
        shell = scene.block_mesh(universe)
        universe_closed = shell.is_closed and shell.is_consistently_oriented
        model_volume = -shell.volume
        if model_volume > 0.0:
            balance = abs(sum(c.volume for c in checks) - model_volume) / model_volume
        if not universe_closed:
            problems.append("the universe's boundary (the model's outer shell) is not closed")
        elif balance is None or balance > relative_volume_tolerance:
            problems.append(
                "the block volumes do not add up to the model volume "
                f"(relative difference {balance})"
            )
    if problems:
        raise TopologyError("block validation failed: " + "; ".join(problems))
    return Validation(checks, universe_closed, balance)
