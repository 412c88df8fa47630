"""The clipping demo stage: the layer cake cut into two closed halves, written to the output."""

from __future__ import annotations

from pathlib import Path

from geobrep import Scene
from geobrep.demo import DemoContext
from geobrep.ops.clipping import demo_stage
from geobrep.ops.io import read


def test_demo_stage(layer_cake: Scene, tmp_path: Path) -> None:
    ctx = DemoContext(output=tmp_path, scene=layer_cake)
    demo_stage(ctx)
    summary = ctx.summary["clip"]
    assert summary["worst_relative_volume_error"] < 1e-9
    assert all(row["closed_and_oriented"] for row in summary["blocks"])
    assert summary["cap_patches"] == len(layer_cake.blocks)  # the plane cuts every block
    assert len(summary["sections"]) == len(layer_cake.blocks)
    for name in (
        "layer_cake_west.geobrep",
        "layer_cake_east.geobrep",
        "layer_cake_section.geobrep",
    ):
        assert read(tmp_path / name).entities
    assert ctx.lines[0].startswith("clip: a vertical plane cut 6 blocks")
