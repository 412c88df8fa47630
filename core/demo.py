"""The demo job: build the sample model, check it, write it, and summarise (``geobrep demo``).

Each stage adds a section to the summary; later features (clipping, fitting, block building,
voxelization) add their own stages to :data:`STAGES`.
"""

from __future__ import annotations

import json
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from geobrep import datasets
from geobrep.batch import conversion
from geobrep.errors import MissingDependencyError, UnknownFormatError
from geobrep.gis import crs_ops
from geobrep.model.entities import Block
from geobrep.model.scene import Scene
from geobrep.ops import building, clipping, fitting, voxelization
from geobrep.ops.io import atomic_write, read, write

__all__ = ["STAGES", "DemoContext", "run_demo"]


@dataclass
class DemoContext:
    """What stages share: the output folder, the model, and the growing summary."""

    output: Path
    scene: Scene
    summary: dict[str, Any] = field(default_factory=dict)
    lines: list[str] = field(default_factory=list)


def _model_stage(ctx: DemoContext) -> None:
    scene = ctx.scene
    faces = sum(s.n_faces for s in scene.surfaces)
    ctx.summary["model"] = {
        "name": scene.name,
        "crs": scene.crs.label if scene.crs else None,
        "surfaces": len(scene.surfaces),
        "triangles": faces,
        "patches": len(scene.patches),
        "arcs": len(scene.topology.arcs),
        "corners": len(scene.topology.corners),
        "blocks": len(scene.blocks),
    }
    ctx.lines.append(
        f"model: {scene.name!r} ({ctx.summary['model']['crs']}): {len(scene.surfaces)} surfaces, "
        f"{faces} triangles, {len(scene.patches)} patches, {len(scene.topology.arcs)} arcs, "
        f"{len(scene.blocks)} blocks"
    )


def _blocks_stage(ctx: DemoContext) -> None:
    scene = ctx.scene
    rows: list[dict[str, Any]] = []
    for block in scene.blocks:
        boundary = scene.block_mesh(block)
        rows.append(
            {
                "id": block.id,
                "name": block.name,
                "unit": block.unit_name,
                "volume_m3": boundary.volume,
                "closed": boundary.is_closed,
                "oriented": boundary.is_consistently_oriented,
                "triangles": boundary.n_faces,
            }
        )
        ctx.lines.append(
            f"  block #{block.id} {block.name!r:24} volume {boundary.volume:14.1f} m³  "
            f"closed={boundary.is_closed} oriented={boundary.is_consistently_oriented}"
        )
    universe = scene.universe
    shell = -scene.block_mesh(universe).volume if universe is not None else float("nan")
    total = sum(r["volume_m3"] for r in rows)
    ctx.summary["blocks"] = rows
    ctx.summary["adjacency"] = scene.block_adjacency()
    ctx.summary["volume_check"] = {
        "sum_of_blocks": total,
        "model_shell": shell,
        "relative_difference": abs(total - shell) / shell,
    }
    ctx.lines.append(
        f"  sum of block volumes {total:.1f} m³ vs model shell {shell:.1f} m³ "
        f"(relative difference {abs(total - shell) / shell:.1e})"
    )
    ctx.lines.append(f"  adjacent blocks: {scene.block_adjacency()}")


def _native_stage(ctx: DemoContext) -> None:
    path = ctx.output / "layer_cake.geobrep"
    start = time.perf_counter()
    write(ctx.scene, path)
    written = time.perf_counter()
    again = read(path)
    loaded = time.perf_counter()
    identical = again == ctx.scene
    points = datasets.scattered_points()
    write(points, ctx.output / "survey_points.geobrep")
    ctx.summary["native"] = {
        "file": str(path),
        "bytes": path.stat().st_size,
        "write_s": written - start,
        "read_s": loaded - written,
        "round_trip_identical": identical,
    }
    ctx.lines.append(
        f"native: wrote {path} ({path.stat().st_size / 1e6:.2f} MB) in {written - start:.3f} s, "
        f"read back in {loaded - written:.3f} s, identical={identical}"
    )
    ctx.lines.append(
        f"survey points: {points.n_points} points "
        f"({int(points.point_data['core'].values.sum())} core) -> survey_points.geobrep"
    )


def _gocad_stage(ctx: DemoContext) -> None:
    """The model through GOCAD Model3d and TSurf files (the ``gocad`` format plugin)."""
    from geobrep.host import registries

    if "gocad" not in registries().formats:
        ctx.summary["gocad"] = {"status": "skipped", "reason": "format 'gocad' not installed"}
        ctx.lines.append("gocad: skipped (format plugin not installed)")
        return
    _gocad_round_trip(ctx)


def _same_geometry(a: Scene, b: Scene) -> bool:
    pairs = list(zip(a.surfaces, b.surfaces, strict=False))
    return len(a.surfaces) == len(b.surfaces) and all(
        x.name == y.name
        and np.array_equal(x.vertices, y.vertices)
        and np.array_equal(x.faces, y.faces)
        for x, y in pairs
    )


def _same_blocks(a: Scene, b: Scene) -> bool:
    """Blocks with the same signed patches, patches matched by (surface, label)."""
    number = {(p.surface, p.label): p.id for p in b.patches}
    source = {p.id: (p.surface, p.label) for p in a.patches}
    blocks_a, blocks_b = a.of_type(Block), b.of_type(Block)
    return len(blocks_a) == len(blocks_b) and all(
        [(number[source[s.patch]], s.side) for s in x.sides] == [tuple(s) for s in y.sides]
        for x, y in zip(blocks_a, blocks_b, strict=True)
    )


def _gocad_round_trip(ctx: DemoContext) -> None:
    """Write the demo model as ``layer_cake.ml`` and ``layer_cake.ts``, read both back."""
    scene = ctx.scene
    section: dict[str, Any] = {}
    for suffix in (".ml", ".ts"):
        path = ctx.output / f"layer_cake{suffix}"
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            start = time.perf_counter()
            write(scene, path)
            written = time.perf_counter()
            again = read(path)
            loaded = time.perf_counter()
        notes = sorted({str(w.message) for w in caught})
        entry: dict[str, Any] = {
            "file": str(path),
            "bytes": path.stat().st_size,
            "write_s": written - start,
            "read_s": loaded - written,
            "geometry_identical": _same_geometry(scene, again),
            "patches": len(again.patches),
            "arcs": len(again.topology.arcs),
            "corners": len(again.topology.corners),
            "blocks": len(again.blocks),
            "reported": notes,
        }
        if suffix == ".ml":
            entry["block_sides_identical"] = _same_blocks(scene, again)
            entry["crs"] = again.crs.label if again.crs else None
        section[suffix.lstrip(".")] = entry
        kind = "Model3d" if suffix == ".ml" else "TSurfs"
        ctx.lines.append(
            f"gocad: {kind} {path.name} ({entry['bytes'] / 1e6:.2f} MB) written in "
            f"{entry['write_s']:.3f} s, read back in {entry['read_s']:.3f} s: "
            f"{entry['patches']} patches, {entry['arcs']} arcs, {entry['corners']} corners, "
            f"{entry['blocks']} blocks, geometry identical={entry['geometry_identical']}"
            + (
                f", block sides identical={entry['block_sides_identical']}"
                if suffix == ".ml"
                else ""
            )
        )
        for note in notes:
            ctx.lines.append(f"  reported: {note}")
    ctx.summary["gocad"] = section


def _gis_stage(ctx: DemoContext) -> None:
    """Map products as a GeoPackage and the model in WGS 84 (needs the ``gis`` extra)."""
    try:
        crs_ops.demo_stage(ctx)
    except (MissingDependencyError, UnknownFormatError) as exc:
        ctx.summary["gis"] = {"status": "skipped", "reason": str(exc)}
        ctx.lines.append(f"gis: skipped ({exc})")


#: The demo's stages, in order. Features add theirs here.
STAGES: list[tuple[str, Callable[[DemoContext], None]]] = [
    ("model", _model_stage),
    ("blocks", _blocks_stage),
    ("native", _native_stage),
    ("clip", clipping.demo_stage),
    ("block_builder", building.demo_stage),
    ("voxelize", voxelization.demo_stage),
    ("fit", fitting.demo_stage),
    ("conversion", conversion.demo_stage),
    ("gocad", _gocad_stage),
    ("gis", _gis_stage),
]


def run_demo(output: str | Path = "demo-output") -> DemoContext:
    """Run every demo stage, write ``summary.json`` into ``output``, and return the context."""
    folder = Path(output)
    folder.mkdir(parents=True, exist_ok=True)
    ctx = DemoContext(output=folder, scene=datasets.faulted_layer_cake())
    for _, stage in STAGES:
        stage(ctx)
    with atomic_write(folder / "summary.json") as tmp:
        tmp.write_text(json.dumps(ctx.summary, indent=2, default=str))
    ctx.lines.append(f"summary: {folder / 'summary.json'}")
    return ctx
