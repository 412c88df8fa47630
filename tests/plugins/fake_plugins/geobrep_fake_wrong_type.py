"""A plugin that adds a clipper to the format registry."""

from __future__ import annotations

from geobrep.plugins import ClipperSpec, hookimpl
from geobrep.registry import FormatRegistry


@hookimpl
def geobrep_register_formats(registry: FormatRegistry) -> None:
    registry.add(ClipperSpec(name="oops", entity_type="Surface", function=print))  # type: ignore[arg-type]
