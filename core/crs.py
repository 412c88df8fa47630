"""Coordinate reference system metadata carried by a scene.

geobrep always holds coordinates right-handed with z up. ``z_positive`` records how the *source*
stored z (GOCAD ``ZPOSITIVE Depth`` is ``"down"``), so a writer can restore the original
convention; it never changes how coordinates are held in memory.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field, JsonValue, field_validator

from geobrep.model import FrozenModel

__all__ = ["CRS"]


class CRS(FrozenModel):
    """Name, EPSG code or WKT of a coordinate reference system, with axis names and units.

    >>> CRS(epsg=32631).label
    'EPSG:32631'
    """

    name: str | None = None
    epsg: int | None = Field(default=None, gt=0)
    wkt: str | None = None
    proj: str | None = None
    axis_names: tuple[str, str, str] = ("X", "Y", "Z")
    axis_units: tuple[str, str, str] = ("m", "m", "m")
    z_positive: Literal["up", "down"] = "up"
    vertical_datum: str | None = None
    metadata: dict[str, JsonValue] = Field(default_factory=dict)

    @field_validator("axis_names", "axis_units")
    @classmethod
    def _non_empty(cls, value: tuple[str, str, str]) -> tuple[str, str, str]:
        if any(not item.strip() for item in value):
            raise ValueError("axis names and units must be non-empty")
        return value

    @property
    def label(self) -> str:
        """A short human-readable identifier: ``EPSG:xxxx``, the name, or ``unknown``."""
        if self.epsg is not None:
            return f"EPSG:{self.epsg}"
        if self.name:
            return self.name
        if self.wkt:
            return self.wkt.split("[", 1)[-1].split(",", 1)[0].strip('"') or "WKT"
        if self.proj:
            return self.proj
        return "unknown"
