"""The examples in the fitting modules' docstrings run and give the output they show."""

from __future__ import annotations

import doctest
import importlib

import pytest

MODULES = [
    "geobrep.ops.fitting",
    "geobrep.geometry.distance",
    "geobrep.geometry.nurbs",
    "geobrep.plugins.fit.approximation",
    "geobrep.plugins.fit.bending",
    "geobrep.plugins.fit.curves",
    "geobrep.plugins.fit.design",
    "geobrep.plugins.fit.distance",
    "geobrep.plugins.fit.domain_map",
    "geobrep.plugins.fit.frame",
    "geobrep.plugins.fit.knots",
    "geobrep.plugins.fit.kriging",
    "geobrep.plugins.fit.lsq",
    "geobrep.plugins.fit.options",
    "geobrep.plugins.fit.projection",
    "geobrep.plugins.fit.report",
    "geobrep.plugins.fit.skinning",
    "geobrep.plugins.fit.split",
    "geobrep.plugins.fit.variogram",
]


@pytest.mark.parametrize("name", MODULES)
def test_fit_module_examples(name: str) -> None:
    module = importlib.import_module(name)
    finder = doctest.DocTestFinder()
    assert sum(len(t.examples) for t in finder.find(module)) > 0, f"{name} has no examples"
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS, verbose=False, report=True)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples failed in {name}"
