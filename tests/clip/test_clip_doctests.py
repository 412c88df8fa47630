"""The examples in the clipping modules' docstrings run."""

from __future__ import annotations

import doctest
import importlib

import pytest

MODULES = [
    "geobrep.ops.clipping",
    "geobrep.cli.clip",
    *(
        f"geobrep.plugins.clip.{name}"
        for name in ("_sides", "_triangles", "_loops", "_caps", "_lines", "annotations", "glyphs")
    ),
]


@pytest.mark.parametrize("name", MODULES)
def test_examples(name: str) -> None:
    result = doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0
    assert result.failed == 0
