"""A well-behaved plugin: one format and one clipper."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from geobrep.host.registry import ClipperRegistry, FormatRegistry
from geobrep.plugins import ClipperSpec, FormatSpec, hookimpl


def read(path: Path, options: Any) -> str:
    return f"read {path.name}"


@hookimpl
def geobrep_register_formats(registry: FormatRegistry) -> None:
    registry.add(
        FormatSpec(
            name="fakegood",
            extensions=(".fgood",),
            reader=read,
            sniff=lambda head: head.startswith(b"FAKEGOOD"),
        )
    )


@hookimpl
def geobrep_register_clippers(registry: ClipperRegistry) -> None:
    registry.add(ClipperSpec(name="fakegood.points", entity_type="PointSet", function=print))
