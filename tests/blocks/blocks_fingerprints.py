"""What the block builder finds, as plain data to compare across code changes: the blocks
(name, unit, sides, rounded volume), their adjacency, the patches (surface, label, blocks on
each side, arcs, triangle count), the arcs (corners, patches in order), the corner points and
a digest of every rebuilt surface's triangles and patch labels.

``python tests/blocks/blocks_fingerprints.py`` rewrites ``tests/blocks/data/fingerprints.json``
(only when the builder's answers are meant to change)."""

from __future__ import annotations

import hashlib
import json
import warnings
from pathlib import Path
from typing import Any

import numpy as np

import geobrep
from geobrep import Scene

HERE = Path(__file__).resolve().parent
EXPECTED = HERE / "data" / "fingerprints.json"
GOCAD = HERE.parent / "data" / "gocad"
#: Model3d files of tests/data rebuilt from their bare surfaces.
MODEL3D = ("modelA1.ml", "modelA4.ml", "split_cube.ml", "non_split_cube.ml")
#: benchmarks/blocks.py's layer cakes at small sizes (resolution → about 5k and 20k triangles).
CAKES = (46.0, 23.0)


def cake(resolution: float) -> Scene:
    """The benchmark's layer cake, its surfaces as they come (about half reversed, seed 17)."""
    truth = geobrep.datasets.faulted_layer_cake(n_horizons=2, resolution=resolution)
    rng = np.random.default_rng(17)
    surfaces = [
        s.replace(faces=s.faces[:, ::-1].copy()) if rng.random() < 0.5 else s
        for s in truth.surfaces
    ]
    return Scene(entities=surfaces, crs=truth.crs)


def model3d(name: str) -> Scene:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = geobrep.read(GOCAD / name)
    return Scene(entities=model.surfaces, crs=model.crs, name=model.name)


def inputs() -> dict[str, Scene]:
    scenes = {f"cake {r:g}": cake(r) for r in CAKES}
    scenes["sample"] = Scene(entities=geobrep.datasets.faulted_layer_cake().surfaces)
    for name in MODEL3D:
        if (GOCAD / name).exists():
            scenes[name] = model3d(name)
    return scenes


def _digest(*arrays: np.ndarray) -> str:
    h = hashlib.sha256()
    for array in arrays:
        h.update(np.ascontiguousarray(array).tobytes())
    return h.hexdigest()[:16]


def fingerprint(built: Scene) -> dict[str, Any]:
    blocks = [
        {
            "id": int(b.id or 0),
            "name": b.name,
            "kind": b.kind,
            "unit": b.unit_name,
            "sides": [[int(s.patch), int(s.side)] for s in b.sides],
            "volume": float(f"{float(b.metadata.get('volume', 0.0)):.9g}"),
        }
        for b in (*built.blocks, *([built.universe] if built.universe is not None else []))
    ]
    topology = built.topology
    surfaces = {
        str(s.id): _digest(s.vertices, s.faces, np.asarray(s.patch_labels, dtype=np.int64))
        for s in built.surfaces
    }
    return {
        "blocks": blocks,
        "adjacency": sorted([sorted(map(int, pair)) for pair in built.block_adjacency()]),
        "patches": [
            [
                p.surface,
                p.label,
                p.positive_block,
                p.negative_block,
                list(p.arcs),
                int(p.metadata.get("triangles", -1)),
            ]
            for p in topology.patches
        ],
        "arcs": [[a.start, a.end, list(a.patches), int(a.points.shape[0])] for a in topology.arcs],
        "corners": _digest(np.array([c.point for c in topology.corners])),
        "surfaces": surfaces,
    }


def fingerprints() -> dict[str, Any]:
    return {name: fingerprint(geobrep.build_blocks(scene)) for name, scene in inputs().items()}


if __name__ == "__main__":
    EXPECTED.parent.mkdir(exist_ok=True)
    found = fingerprints()
    lines = [
        f" {json.dumps(k)}: {json.dumps(found[k], sort_keys=True, separators=(',', ':'))}"
        for k in sorted(found)
    ]
    EXPECTED.write_text("{\n" + ",\n".join(lines) + "\n}\n")
    print(f"wrote {EXPECTED}")
