"""The examples in geobrep's docstrings run and give the output they show."""

from __future__ import annotations

import doctest
import importlib
import pkgutil
from pathlib import Path

import pytest

import geobrep

#: Modules whose examples run in their own suites (tests/fit, tests/gocad, tests/clip, ...).
OWNED_ELSEWHERE = (
    "geobrep.plugins",
    "geobrep.adapters",
    "geobrep.ops.fitting",
)


def count_examples(module: object) -> int:
    return sum(len(test.examples) for test in doctest.DocTestFinder().find(module))


def _modules_with_examples() -> list[str]:
    found = ["geobrep"]
    for info in pkgutil.walk_packages(geobrep.__path__, "geobrep."):
        if info.name.endswith("__main__") or info.name.startswith(OWNED_ELSEWHERE):
            continue  # __main__ modules act on import
        if count_examples(importlib.import_module(info.name)):
            found.append(info.name)
    return found


#: Every core module whose docstrings carry examples, discovered.
DOCTEST_MODULES = _modules_with_examples()


@pytest.mark.parametrize("name", DOCTEST_MODULES)
def test_module_examples(name: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)  # examples that write files write them here
    module = importlib.import_module(name)
    assert count_examples(module) > 0, f"{name} has no examples left: update DOCTEST_MODULES"
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS, verbose=False, report=True)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples failed in {name}"
    assert result.attempted > 0 or count_examples(module) == 0


def test_discovery_finds_the_core_modules() -> None:
    assert {"geobrep.model.scene", "geobrep.ops.io", "geobrep.model.orientation"} <= set(
        DOCTEST_MODULES
    )
