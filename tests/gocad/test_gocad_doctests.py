"""The examples in the GOCAD adapter's docstrings (and geobrep.model.arcs) run as written."""

from __future__ import annotations

import doctest
import importlib

import pytest

MODULES = [
    "geobrep.model.arcs",
    "geobrep.adapters.gocad._checks",
    "geobrep.adapters.gocad._headers",
    "geobrep.adapters.gocad._lexer",
    "geobrep.adapters.gocad._numbers",
    "geobrep.adapters.gocad.options",
    "geobrep.adapters.gocad._regions",
]


@pytest.mark.parametrize("name", MODULES)
def test_module_examples(name: str) -> None:
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0
    assert result.failed == 0
