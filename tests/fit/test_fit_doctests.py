"""The examples in the fitting modules' docstrings run and give the output they show."""

from __future__ import annotations

import doctest
import importlib

import pytest

MODULES = [
    "geobrep.ops.fitting",
    "geobrep.geometry.distance",
    "geobrep.geometry.nurbs",
    "geobrep.plugins.fit._approximation",
    "geobrep.plugins.fit._bending",
    "geobrep.plugins.fit._curves",
    "geobrep.plugins.fit._design",
    "geobrep.plugins.fit.distance",
    "geobrep.plugins.fit._domain_map",
    "geobrep.plugins.fit._frame",
    "geobrep.plugins.fit._knots",
    "geobrep.plugins.fit.kriging",
    "geobrep.plugins.fit._lsq",
    "geobrep.plugins.fit.options",
    "geobrep.plugins.fit._projection",
    "geobrep.plugins.fit.report",
    "geobrep.plugins.fit._skinning",
    "geobrep.plugins.fit._split",
    "geobrep.plugins.fit._variogram",
]


@pytest.mark.parametrize("name", MODULES)
def test_fit_module_examples(name: str) -> None:
    module = importlib.import_module(name)
    finder = doctest.DocTestFinder()
    assert sum(len(t.examples) for t in finder.find(module)) > 0, f"{name} has no examples"
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS, verbose=False, report=True)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples failed in {name}"
