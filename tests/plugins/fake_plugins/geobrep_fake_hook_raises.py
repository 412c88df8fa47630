"""A plugin that registers one format, then raises: nothing of it may be kept."""

from __future__ import annotations

from geobrep.host.registry import FormatRegistry
from geobrep.plugins import FormatSpec, hookimpl


@hookimpl
def geobrep_register_formats(registry: FormatRegistry) -> None:
    registry.add(FormatSpec(name="raiser", extensions=(".raise",), reader=print))
    raise RuntimeError("boom from geobrep_fake_hook_raises")
