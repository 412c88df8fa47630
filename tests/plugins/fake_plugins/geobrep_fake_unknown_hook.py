"""A plugin implementing a hook geobrep does not define (fails check_pending)."""

from __future__ import annotations

from typing import Any

from geobrep.plugins import hookimpl


@hookimpl
def geobrep_register_widgets(registry: Any) -> None:
    raise AssertionError("never called")
