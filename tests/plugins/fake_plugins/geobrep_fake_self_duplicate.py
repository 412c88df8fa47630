"""A plugin that registers the same name twice."""

from __future__ import annotations

from geobrep.host.registry import BuilderRegistry
from geobrep.plugins import BuilderSpec, hookimpl


@hookimpl
def geobrep_register_builders(registry: BuilderRegistry) -> None:
    registry.add(BuilderSpec(name="twice", function=print))
    registry.add(BuilderSpec(name="twice", function=print))
