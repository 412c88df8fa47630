"""Demo stage: the sample model written as a GOCAD Model3d (.ml) and TSurfs (.ts), read back."""

from __future__ import annotations

import time
import warnings
from typing import Any

import numpy as np

from geobrep.demo import DemoContext
from geobrep.model.entities import Block
from geobrep.model.scene import Scene
from geobrep.ops.io import read, write

__all__ = ["demo_stage"]


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


def demo_stage(ctx: DemoContext) -> None:
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
