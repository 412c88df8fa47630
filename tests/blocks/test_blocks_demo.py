"""The block builder's demo stage on the sample model."""

from __future__ import annotations

import json
from pathlib import Path

import geobrep
from geobrep.demo import DemoContext
from geobrep.ops.building import demo_stage


def test_demo_stage_rebuilds_the_sample(tmp_path: Path) -> None:
    ctx = DemoContext(output=tmp_path, scene=geobrep.datasets.faulted_layer_cake())
    demo_stage(ctx)
    summary = ctx.summary["block_builder"]
    assert summary["same_blocks_and_signed_patch_sets"] is True
    assert summary["same_adjacency"] is True
    assert summary["max_relative_volume_difference"] <= 1e-9
    assert (summary["blocks"], summary["patches"], summary["arcs"]) == (6, 31, 52)
    assert summary["direction_triangles"] == 132
    assert summary["sorted_share"] == 132 / summary["triangles"]
    rebuilt = geobrep.read(summary["file"])
    assert len(rebuilt.blocks) == 6
    assert any(line.startswith("block builder: rebuilt 6 blocks") for line in ctx.lines)
    json.dumps(ctx.summary, default=str)  # the demo writes it as JSON
