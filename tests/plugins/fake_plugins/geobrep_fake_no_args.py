"""A plugin whose hook takes no arguments (pluggy allows fewer than the spec)."""

from __future__ import annotations

from geobrep.plugins import hookimpl

calls: list[str] = []


@hookimpl
def geobrep_register_builders() -> None:
    calls.append("called")
