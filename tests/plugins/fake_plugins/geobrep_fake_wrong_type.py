"""A plugin that adds a clipper to the format registry."""

from __future__ import annotations

from geobrep.host.registry import FormatRegistry
from geobrep.plugins import ClipperSpec, hookimpl


@hookimpl
def geobrep_register_formats(registry: FormatRegistry) -> None:
    registry.add(ClipperSpec(name="oops", entity_type="Surface", function=print))  # type: ignore[arg-type]
