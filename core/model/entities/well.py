"""Wells: a trajectory of stations with measured depth, markers, zones and logs.

A well's ``vertices`` are its trajectory stations (z up, in the scene's CRS) and ``md`` their
measured depths along the hole, strictly increasing; the cells are the segments between
consecutive stations. ``head`` is the well head (the point MD counts from) and ``datum`` names
the depth reference (``"KB"``, ``"GL"``, ...) at ``datum_elevation``. Markers, zones and logs are
placed by measured depth; :meth:`Well.position_at` turns MD into XYZ along the path: the
minimum-curvature arc between stations whose inclination and azimuth (station properties
``INCL`` and ``AZIM_GN``, ``AZIM`` or ``AZIM_TN``, in degrees) give them, else the straight
segment.
"""

from __future__ import annotations

from functools import cached_property
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import Field, JsonValue, model_validator

from geobrep.geometry.trajectory import StationPath
from geobrep.model.arrays import FloatArray, NumericArray, Points, Vector3
from geobrep.model.base import FrozenModel
from geobrep.model.entities.base import VertexEntity
from geobrep.model.properties import NoDataValue

__all__ = ["AZIMUTH_NAMES", "INCLINATION_NAMES", "Well", "WellLog", "WellMarker", "WellZone"]

#: Station properties taken as the inclination and the azimuth (grid north first), in degrees.
INCLINATION_NAMES = ("INCL", "INC", "inclination")
AZIMUTH_NAMES = ("AZIM_GN", "AZIM", "AZIM_TN", "azimuth")


class WellMarker(FrozenModel):
    """A pick at measured depth ``md``: its ``name`` and the ``surface`` (horizon, fault) it
    hits."""

    name: str
    md: float = Field(allow_inf_nan=False)
    surface: str = ""
    metadata: dict[str, JsonValue] = Field(default_factory=dict)


class WellZone(FrozenModel):
    """An interval ``top_md .. base_md`` of the hole (a stratigraphic unit)."""

    name: str
    top_md: float = Field(allow_inf_nan=False)
    base_md: float = Field(allow_inf_nan=False)
    metadata: dict[str, JsonValue] = Field(default_factory=dict)

    @model_validator(mode="after")
    def _ordered(self) -> WellZone:
        if self.base_md < self.top_md:
            raise ValueError(f"zone {self.name!r}: base_md {self.base_md} < top_md {self.top_md}")
        return self


class WellLog(FrozenModel):
    """Samples ``values`` at measured depths ``md`` (non-decreasing), with a unit and no-data."""

    md: FloatArray
    values: NumericArray
    unit: str | None = None
    no_data_value: NoDataValue = None
    metadata: dict[str, JsonValue] = Field(default_factory=dict)

    @model_validator(mode="after")
    def _aligned(self) -> WellLog:
        if self.values.ndim != 1 or self.values.shape[0] != self.md.shape[0]:
            raise ValueError(f"log has {self.values.shape} values for {self.md.shape[0]} depths")
        if self.md.size > 1 and bool((np.diff(self.md) < 0).any()):
            raise ValueError("log depths must not decrease")
        return self


class Well(VertexEntity):
    """Stations ``vertices (N, 3)`` at measured depths ``md (N,)`` from ``head``.

    >>> well = Well(head=[0, 0, 10], vertices=[[0, 0, 10], [0, 0, 0], [30, 40, 0]],
    ...             md=[0, 10, 60], markers=[WellMarker(name="top", md=35, surface="H1")])
    >>> well.n_cells, well.marker_positions().tolist()
    (2, [[15.0, 20.0, 0.0]])
    """

    type: Literal["Well"] = "Well"
    cell_noun = "segments"
    head: Vector3
    vertices: Points
    md: FloatArray
    datum: str = ""
    datum_elevation: float | None = Field(default=None, allow_inf_nan=False)
    markers: tuple[WellMarker, ...] = ()
    zones: tuple[WellZone, ...] = ()
    logs: dict[str, WellLog] = Field(default_factory=dict)

    @property
    def n_cells(self) -> int:
        return max(int(self.vertices.shape[0]) - 1, 0)

    @property
    def n_stations(self) -> int:
        return int(self.vertices.shape[0])

    @property
    def segments(self) -> NDArray[np.int64]:
        """``(n_cells, 2)`` station pairs."""
        first = np.arange(self.n_cells, dtype=np.int64)
        return np.stack([first, first + 1], axis=1)

    @cached_property
    def length(self) -> float:
        """Length of the station polyline."""
        return float(np.linalg.norm(np.diff(self.vertices, axis=0), axis=1).sum())

    @property
    def angle_names(self) -> tuple[str, str] | None:
        """The station properties holding inclination and azimuth, or None."""
        inc = next((n for n in INCLINATION_NAMES if n in self.point_data), None)
        azi = next((n for n in AZIMUTH_NAMES if n in self.point_data), None)
        if inc is None or azi is None:
            return None
        if self.point_data[inc].values.ndim != 1 or self.point_data[azi].values.ndim != 1:
            return None
        return inc, azi

    @cached_property
    def path(self) -> StationPath:
        """The path through the stations: minimum-curvature arcs where the angles give them."""
        names = self.angle_names
        if names is None:
            return StationPath.of(self.md, self.vertices)
        inc, azi = (np.asarray(self.point_data[n].values, dtype=np.float64) for n in names)
        return StationPath.of(self.md, self.vertices, inc, azi)

    def position_at(self, md: ArrayLike) -> NDArray[np.float64]:
        """XYZ ``(n, 3)`` at measured depths ``md`` along :attr:`path` (NaN outside)."""
        depths = np.atleast_1d(np.asarray(md, dtype=np.float64))
        out = np.full((depths.shape[0], 3), np.nan)
        if self.n_stations == 0:
            return out
        inside = (depths >= self.md[0]) & (depths <= self.md[-1])
        out[inside] = self.path.at(depths[inside])[0]
        return out

    def marker_positions(self) -> NDArray[np.float64]:
        """XYZ of every marker ``(n_markers, 3)``, in marker order."""
        return self.position_at([m.md for m in self.markers]).reshape(-1, 3)

    def _check(self) -> None:
        n = self.vertices.shape[0]
        if self.md.shape[0] != n:
            raise self.fail("md", f"has {self.md.shape[0]} depths for {n} stations")
        if n > 1 and bool((np.diff(self.md) <= 0).any()):
            row = int(np.argmax(np.diff(self.md) <= 0)) + 1
            raise self.fail("md", f"measured depths must increase (station {row})")
        for index, marker in enumerate(self.markers):
            if n and not self.md[0] <= marker.md <= self.md[-1]:
                raise self.fail(
                    f"markers[{index}]",
                    f"marker {marker.name!r} at MD {marker.md} is off the trajectory "
                    f"({float(self.md[0])} .. {float(self.md[-1])})",
                )
