"""A plugin that reuses the name 'fakegood' (taken by geobrep_fake_good) and adds its own."""

from __future__ import annotations

from geobrep.host.registry import FormatRegistry
from geobrep.plugins import FormatSpec, hookimpl


@hookimpl
def geobrep_register_formats(registry: FormatRegistry) -> None:
    registry.add(FormatSpec(name="fakegood", extensions=(".other",), writer=print))
    registry.add(FormatSpec(name="dupextra", extensions=(".dupx",), writer=print))
