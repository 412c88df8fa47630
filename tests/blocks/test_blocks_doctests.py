"""The examples in the block builder's docstrings run and give the output they show."""

from __future__ import annotations

import doctest
import importlib
import pkgutil
from pathlib import Path

import pytest

import geobrep.plugins.blocks

MODULES = [
    "geobrep.ops.building",
    "geobrep.cli.blocks",
    "geobrep.plugins.blocks",
    *(
        f"geobrep.plugins.blocks.{info.name}"
        for info in pkgutil.iter_modules(geobrep.plugins.blocks.__path__)
    ),
]


@pytest.mark.parametrize("name", MODULES)
def test_block_builder_examples(name: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS, verbose=False, report=True)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples failed in {name}"


def test_most_modules_carry_examples() -> None:
    with_examples = [
        name
        for name in MODULES
        if any(t.examples for t in doctest.DocTestFinder().find(importlib.import_module(name)))
    ]
    assert len(with_examples) >= len(MODULES) - 6
