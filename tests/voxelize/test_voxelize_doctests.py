"""The docstring examples of the voxelizer's modules and the Morton-code kernel run."""

from __future__ import annotations

import doctest
import importlib

import pytest

MODULES = [
    "geobrep.geometry.morton",
    "geobrep.plugins.voxelize._rasterize",
    "geobrep.plugins.voxelize._depth_buffers",
    "geobrep.plugins.voxelize._parity",
    "geobrep.plugins.voxelize._merge",
]


@pytest.mark.parametrize("name", MODULES)
def test_examples(name: str) -> None:
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS, report=True)
    assert result.attempted > 0
    assert result.failed == 0
