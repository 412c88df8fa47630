"""Real Model3d files: drop their REGIONs, rebuild, and get the same blocks back."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import geobrep
from geobrep import Block, Scene, Surface
from geobrep.ops.building import build_blocks
from geobrep.plugins.blocks.report import block_report

DATA = Path(__file__).resolve().parent.parent / "data" / "gocad"


def read_model(name: str) -> Scene:
    path = DATA / name
    if not path.exists():
        pytest.skip(f"{path} is not in this checkout")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # e.g. FAULT_BLOCK ids without a REGION in modelA4
        return geobrep.read(path)


def signed_sets(scene: Scene) -> dict[frozenset[tuple[tuple[int, tuple[float, ...]], int]], str]:
    """Blocks keyed by their (patch, side) sets, patches by surface id and rounded centroid."""
    key = {}
    for patch in scene.patches:
        surface = scene[patch.surface]
        assert isinstance(surface, Surface)
        faces = surface.faces[surface.patch_faces(patch.label)]
        centroid = surface.vertices[faces].mean(axis=(0, 1))
        key[patch.id] = (patch.surface, tuple(np.round(centroid, 3).tolist()))
    return {
        frozenset((key[s.patch], s.side) for s in block.sides): block.name
        for block in scene.of_type(Block)
    }


@pytest.mark.parametrize(
    ("name", "blocks", "internal"), [("modelA1.ml", 4, 0), ("modelA4.ml", 8, 4)]
)
def test_rebuilt_regions_match_the_files(name: str, blocks: int, internal: int) -> None:
    model = read_model(name)
    assert len(model.blocks) == blocks  # the REGIONs, Universe apart
    bare = Scene(entities=model.surfaces, crs=model.crs, name=model.name)
    built = build_blocks(bare)
    assert len(built.blocks) == blocks
    expected, found = signed_sets(model), signed_sets(built)
    assert expected.keys() == found.keys()  # same blocks, same signed patch lists
    assert expected[next(k for k, v in expected.items() if v == "Universe")] == "Universe"
    assert found[next(k for k, v in expected.items() if v == "Universe")] == "universe"
    report = block_report(built)
    assert len(report.internal_patches) == internal  # "+k -k" in the REGION lists
    assert report.dangling == []
    for check in report.checks:
        assert check.closed
        assert check.oriented
        assert check.volume > 0


def test_model_a4_arcs_and_corners_match_the_reference_counts() -> None:
    model = read_model("modelA4.ml")
    built = build_blocks(Scene(entities=model.surfaces, crs=model.crs))
    # OpenGeode's golden counts for modelA4: 52 corners, 98 lines, 55 surfaces.
    assert (len(built.topology.corners), len(built.topology.arcs)) == (52, 98)
    assert len(built.patches) == 55
