"""The builder's answers do not change with its speed: blocks, sides, adjacency, patches,
arcs and rebuilt surfaces on the benchmark's layer cakes (small sizes, surfaces as they come)
and on the Model3d files of tests/data, against the fingerprints the builder gave before its
speed-ups (tests/blocks/data/fingerprints.json)."""

from __future__ import annotations

import json

import pytest
from blocks_fingerprints import EXPECTED, fingerprint, inputs

import geobrep

SCENES = inputs()
STORED = json.loads(EXPECTED.read_text())


@pytest.mark.parametrize("name", sorted(STORED))
def test_blocks_are_unchanged(name: str) -> None:
    if name not in SCENES:
        pytest.skip(f"{name} is not in this checkout")
    found = json.loads(json.dumps(fingerprint(geobrep.build_blocks(SCENES[name]))))
    expected = STORED[name]
    for key in ("blocks", "adjacency", "patches", "arcs", "corners", "surfaces"):
        assert found[key] == expected[key], f"{name}: {key} changed"


def test_every_input_is_checked() -> None:
    assert set(SCENES) <= set(STORED)
    assert {"cake 46", "cake 23", "modelA1.ml", "modelA4.ml"} <= set(STORED)
