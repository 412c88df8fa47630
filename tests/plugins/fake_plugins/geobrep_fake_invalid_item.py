"""A plugin that registers a good fitter, then an item with an invalid name."""

from __future__ import annotations

from geobrep.host.registry import FitterRegistry
from geobrep.plugins import FitterSpec, hookimpl


@hookimpl
def geobrep_register_fitters(registry: FitterRegistry) -> None:
    registry.add(FitterSpec(name="partial", function=print))
    registry.add(FitterSpec(name="Not A Valid Name", function=print))
