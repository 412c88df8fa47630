"""Coordinate reference system metadata carried by a scene.

geobrep always holds coordinates right-handed with z up. ``z_positive`` records how the *source*
stored z (GOCAD ``ZPOSITIVE Depth`` is ``"down"``), so a writer can restore the original
convention; it never changes how coordinates are held in memory.

:func:`as_crs` turns what ``pyproj.CRS.from_user_input`` accepts (``"EPSG:32633"``, ``32633``,
``("EPSG", 32633)``, WKT, PROJ strings, a ``pyproj.CRS``, any object with ``to_wkt()``) into a
:class:`CRS`. An EPSG code alone is read without pyproj (``import geobrep`` never imports it);
anything else imports pyproj when it is given.
"""

from __future__ import annotations

import re
from typing import Any, Literal

from pydantic import Field, JsonValue, ValidationError, field_validator

from geobrep.errors import GeobrepError
from geobrep.model.base import FrozenModel

__all__ = ["CRS", "CRSError", "as_crs"]

_EPSG_TEXT = re.compile(r"^\s*(?:epsg:)?(\d{1,9})\s*$", re.IGNORECASE)


class CRSError(GeobrepError, ValueError):
    """A CRS is missing, cannot be parsed, or two CRSs cannot be transformed between."""


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

    @classmethod
    def from_user_input(cls, value: Any) -> CRS:
        """The CRS of anything ``pyproj.CRS.from_user_input`` accepts (see :func:`as_crs`).

        >>> CRS.from_user_input("EPSG:32633").epsg
        32633
        """
        crs = as_crs(value)
        if crs is None:
            raise CRSError("None is not a CRS")
        return crs


def _epsg(code: int, value: Any) -> CRS:
    if code <= 0:
        raise CRSError(f"CRS {value!r} is not a valid CRS: an EPSG code is a positive integer")
    return CRS(epsg=code)


def _fields_only(value: dict[Any, Any]) -> bool:
    return set(value) <= set(CRS.model_fields)


def as_crs(value: Any, what: str = "CRS") -> CRS | None:
    """A :class:`CRS` from a CRS, its fields as a dict, or any input pyproj understands.

    ``None`` stays ``None``. ``32633``, ``"EPSG:32633"`` and ``("EPSG", 32633)`` give
    ``CRS(epsg=32633)`` without importing pyproj; WKT, PROJ strings, other authorities,
    ``pyproj.CRS`` objects and objects with ``to_wkt()`` are read with pyproj
    (:func:`geobrep.gis.crs_ops.crs_from_user_input`: name, EPSG code or WKT, axes, vertical datum).
    An unreadable input is a :class:`CRSError` naming it (``what`` says which parameter it was);
    without pyproj a :class:`~geobrep.errors.MissingDependencyError` names the ``gis`` extra.

    >>> as_crs("EPSG:32633") == as_crs(32633) == as_crs(("EPSG", 32633)) == CRS(epsg=32633)
    True
    >>> as_crs({"epsg": 4326}).label
    'EPSG:4326'
    """
    if value is None or isinstance(value, CRS):
        return value
    if isinstance(value, bool):
        raise CRSError(f"{what} {value!r} is not a CRS")
    if isinstance(value, int):
        return _epsg(value, value)
    if isinstance(value, str):
        if not value.strip():
            raise CRSError(f"{what}: an empty string is not a CRS")
        match = _EPSG_TEXT.match(value)
        if match:
            return _epsg(int(match.group(1)), value)
    elif isinstance(value, dict) and _fields_only(value):
        try:
            return CRS.model_validate(value)
        except ValidationError as exc:
            first = exc.errors()[0]
            where = ".".join(str(p) for p in first["loc"])
            raise CRSError(f"{what} {value!r}: {where}: {first['msg']}") from exc
    elif (
        isinstance(value, tuple | list)
        and len(value) == 2
        and isinstance(value[0], str)
        and value[0].strip().upper() == "EPSG"
        and isinstance(value[1], int | str)
        and not isinstance(value[1], bool)
        and str(value[1]).strip().isdigit()
    ):
        return _epsg(int(str(value[1]).strip()), tuple(value))
    elif not isinstance(value, tuple | list | dict) and callable(getattr(value, "to_wkt", None)):
        if type(value).__module__.split(".")[0] != "pyproj":
            value = value.to_wkt()  # rasterio, osgeo-like objects: their WKT
    elif not isinstance(value, tuple | list | dict):
        raise CRSError(
            f"{what} {str(value)[:60]!r} is not a CRS: expected a CRS, an EPSG code, WKT, a PROJ "
            f"string, an (authority, code) pair or a pyproj CRS, got {type(value).__name__}"
        )
    from geobrep.gis.crs_ops import crs_from_user_input

    try:
        return crs_from_user_input(value)
    except CRSError as exc:
        if what == "CRS":
            raise
        raise CRSError(f"{what}: {exc}") from exc
