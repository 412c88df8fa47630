"""The examples in geobrep's docstrings run and give the output they show."""

from __future__ import annotations

import doctest
import importlib
import pkgutil
from pathlib import Path

import pytest

import geobrep

#: Core modules whose docstrings carry examples. The plugin system, the geometry kernels and the
#: spatial index are tested by their own suites.
DOCTEST_MODULES = [
    "geobrep",
    "geobrep.arrays",
    "geobrep.properties",
    "geobrep.crs",
    "geobrep.entities.annotation",
    "geobrep.entities.base",
    "geobrep.entities.block",
    "geobrep.entities.nurbs",
    "geobrep.entities.octree",
    "geobrep.entities.pointset",
    "geobrep.entities.polygon",
    "geobrep.entities.polyline",
    "geobrep.entities.surface",
    "geobrep.entities.tetmesh",
    "geobrep.scene",
    "geobrep.io",
    "geobrep.voxelization",
    "geobrep.clipping",
    "geobrep.cli.clip",
    "geobrep.building",
    "geobrep.cli.blocks",
    "geobrep.capabilities",
    "geobrep.cell_layout",
    "geobrep.conversion",
    "geobrep.datasets.layer_cake",
    "geobrep.datasets.scattered",
    "geobrep.schemas",
    "geobrep.arcs",
    "geobrep.crs_ops",
    "geobrep.feature_tables",
    "geobrep.map_products",
    "geobrep.pipeline",
    "geobrep.pipeline_run",
]

#: Modules covered elsewhere (their own doctest runs belong to their suites).
OWNED_ELSEWHERE = (
    "geobrep.geometry",
    "geobrep.spatial_index",
    "geobrep.registry",
    "geobrep.plugin_loader",
    "geobrep.hookspecs",
    "geobrep.plugins",
    "geobrep.fitting",
    "geobrep.nurbs_eval",
)


def count_examples(module: object) -> int:
    return sum(len(test.examples) for test in doctest.DocTestFinder().find(module))


@pytest.mark.parametrize("name", DOCTEST_MODULES)
def test_module_examples(name: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)  # examples that write files write them here
    module = importlib.import_module(name)
    assert count_examples(module) > 0, f"{name} has no examples left: update DOCTEST_MODULES"
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS, verbose=False, report=True)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples failed in {name}"
    assert result.attempted == count_examples(module)


def test_no_core_module_with_examples_is_left_out() -> None:
    found = ["geobrep"]
    for info in pkgutil.walk_packages(geobrep.__path__, "geobrep."):
        if info.name.endswith("__main__") or info.name.startswith(OWNED_ELSEWHERE):
            continue  # __main__ modules act on import
        if count_examples(importlib.import_module(info.name)):
            found.append(info.name)
    assert found, "no module was discovered"
    missing = sorted(set(found) - set(DOCTEST_MODULES))
    assert not missing, f"modules with examples not in DOCTEST_MODULES: {missing}"
