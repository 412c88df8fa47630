"""Local frames for float32 files: world coordinates (float64) to small metric ones and back.

glTF stores float32 positions: at UTM scale (x ≈ 4.5e5, y ≈ 6.7e6 m) float32 keeps only about
0.5 m. Rebased on an origin near the model, the same float32 keeps a fraction of a millimetre
over a 10 km model (the rounding is at most ``|local| x 2**-24``). Two frames:

- :class:`OffsetFrame`: world minus an origin (the glTF writer's frame; the origin is kept in
  the file).
- :class:`EnuFrame`: east-north-up metres around a point on the WGS 84 ellipsoid, through
  pyproj from the scene's CRS to ECEF (EPSG:4978); its :attr:`EnuFrame.ecef_matrix` is the 3D
  Tiles root transform that puts the model at its true place on the globe.

glTF is y-up: :func:`to_y_up` maps z-up local coordinates ``(x, y, z)`` to ``(x, z, -y)``, the
mapping 3D Tiles undoes when it loads glTF content.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from geobrep.errors import OptionsError, import_optional
from geobrep.model.crs import CRS

__all__ = ["EnuFrame", "Frame", "OffsetFrame", "enu_rotation", "from_y_up", "to_y_up"]

_ECEF = "EPSG:4978"


def to_y_up(local: NDArray[np.float64]) -> NDArray[np.float64]:
    """z-up ``(x, y, z)`` as glTF's y-up ``(x, z, -y)``."""
    return np.column_stack([local[:, 0], local[:, 2], -local[:, 1]])


def from_y_up(points: NDArray[np.float64]) -> NDArray[np.float64]:
    """glTF's y-up ``(x, y, z)`` back to z-up ``(x, -z, y)``."""
    return np.column_stack([points[:, 0], -points[:, 2], points[:, 1]])


class Frame(Protocol):
    """World coordinates to a local metric frame and back (float64 both ways)."""

    def to_local(self, world: NDArray[np.float64]) -> NDArray[np.float64]: ...

    def to_world(self, local: NDArray[np.float64]) -> NDArray[np.float64]: ...

    def describe(self) -> dict[str, Any]: ...


@dataclass(frozen=True)
class OffsetFrame:
    """``local = world - origin``."""

    origin: tuple[float, float, float]

    def to_local(self, world: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.asarray(world, np.float64) - np.asarray(self.origin, np.float64)

    def to_world(self, local: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.asarray(local, np.float64) + np.asarray(self.origin, np.float64)

    def y_up_from_world(self, world: NDArray[np.float64]) -> NDArray[np.float64]:
        """``to_y_up(to_local(world))`` in one pass into one array, the same values bit for bit."""
        x, y, z = self.origin
        y_up = np.empty((world.shape[0], 3), dtype=np.float64)
        np.subtract(world[:, 0], x, out=y_up[:, 0])
        np.subtract(world[:, 2], z, out=y_up[:, 1])
        np.subtract(world[:, 1], y, out=y_up[:, 2])
        np.negative(y_up[:, 2], out=y_up[:, 2])
        return y_up

    def world_from_y_up(self, points: NDArray[Any]) -> NDArray[np.float64]:
        """``to_world(from_y_up(points))`` in one pass into one array, the same values bit for
        bit (each coordinate widened to float64, then the origin added)."""
        x, y, z = self.origin
        world = np.empty((points.shape[0], 3), dtype=np.float64)
        np.add(points[:, 0], x, out=world[:, 0], dtype=np.float64)
        np.subtract(y, points[:, 2], out=world[:, 1], dtype=np.float64)
        np.add(points[:, 1], z, out=world[:, 2], dtype=np.float64)
        return world

    def describe(self) -> dict[str, Any]:
        return {"frame": "offset", "origin": list(self.origin)}


def enu_rotation(longitude: float, latitude: float) -> NDArray[np.float64]:
    """Rows east, north, up (ECEF components) at a geodetic longitude and latitude (degrees)."""
    lon, lat = np.radians(longitude), np.radians(latitude)
    return np.array(
        [
            [-np.sin(lon), np.cos(lon), 0.0],
            [-np.sin(lat) * np.cos(lon), -np.sin(lat) * np.sin(lon), np.cos(lat)],
            [np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)],
        ]
    )


@dataclass(frozen=True)
class EnuFrame:
    """East-north-up metres at ``anchor`` (a world point) on the WGS 84 ellipsoid.

    With ``crs``, world points go to ECEF through pyproj (z taken as the height of the CRS's
    vertical axis, ellipsoidal when the CRS has none) and are rotated into the ENU axes at the
    anchor: exact for any projection, convergence and scale included. Without ``crs`` (a local
    model) the world axes are taken as east, north and up metres and ``geodetic`` (longitude,
    latitude, height of the anchor) places the model.
    """

    anchor: tuple[float, float, float]
    crs: CRS | None
    geodetic: tuple[float, float, float]
    ecef_origin: tuple[float, float, float]

    @classmethod
    def from_crs(cls, crs: CRS, anchor: tuple[float, float, float]) -> EnuFrame:
        to_ecef = _transformer(crs, inverse=False)
        ecef = np.array(to_ecef.transform(*anchor), dtype=np.float64)
        to_geodetic = _between(_ECEF, "EPSG:4979")
        lon, lat, height = to_geodetic.transform(*ecef)
        return cls(anchor, crs, (float(lon), float(lat), float(height)), _floats(ecef))

    @classmethod
    def from_geodetic(
        cls, anchor: tuple[float, float, float], longitude: float, latitude: float, height: float
    ) -> EnuFrame:
        to_ecef = _between("EPSG:4979", _ECEF)
        x, y, z = to_ecef.transform(longitude, latitude, height)
        return cls(anchor, None, (longitude, latitude, height), _floats((x, y, z)))

    @property
    def rotation(self) -> NDArray[np.float64]:
        return enu_rotation(self.geodetic[0], self.geodetic[1])

    @property
    def ecef_matrix(self) -> NDArray[np.float64]:
        """4x4 ENU-to-ECEF matrix (columns east, north, up, origin)."""
        matrix = np.eye(4)
        matrix[:3, :3] = self.rotation.T
        matrix[:3, 3] = self.ecef_origin
        return matrix

    def to_local(self, world: NDArray[np.float64]) -> NDArray[np.float64]:
        world = np.asarray(world, np.float64)
        if self.crs is None:
            return world - np.asarray(self.anchor, np.float64)
        ecef = np.column_stack(_transformer(self.crs, inverse=False).transform(*world.T))
        local: NDArray[np.float64] = (ecef - np.asarray(self.ecef_origin, np.float64)) @ (
            self.rotation.T
        )
        return local

    def to_world(self, local: NDArray[np.float64]) -> NDArray[np.float64]:
        local = np.asarray(local, np.float64)
        if self.crs is None:
            return local + np.asarray(self.anchor, np.float64)
        ecef: NDArray[np.float64] = local @ self.rotation + np.asarray(self.ecef_origin, np.float64)
        back = _transformer(self.crs, inverse=True).transform(*ecef.T)
        return np.column_stack(back).astype(np.float64)

    def describe(self) -> dict[str, Any]:
        return {
            "frame": "enu",
            "placed_by": "crs" if self.crs is not None else "georeference",
            "origin": list(self.anchor),
            "geodetic_origin": list(self.geodetic),
            "ecef_origin": list(self.ecef_origin),
        }


def _floats(values: Any) -> tuple[float, float, float]:
    return float(values[0]), float(values[1]), float(values[2])


def _pyproj() -> Any:
    return import_optional("pyproj", "gis", "georeferencing 3D Tiles")


_TRANSFORMERS = threading.local()
"""Each thread's pyproj transformers by CRS and direction (a transformer takes about 10 ms to
make; pyproj's are not to be shared between threads)."""


def _cached(key: tuple[str, str], make: Callable[[], Any]) -> Any:
    """This thread's transformer for ``key``, made by ``make`` the first time."""
    cache: dict[tuple[str, str], Any] = _TRANSFORMERS.__dict__.setdefault("cache", {})
    if key not in cache:
        if len(cache) >= 16:
            cache.clear()
        cache[key] = make()
    return cache[key]


def _between(source: str, target: str) -> Any:
    """pyproj's transformer from ``source`` to ``target`` (CRS names), x/y as lon/lat order."""
    return _cached(
        (source, target),
        lambda: _pyproj().Transformer.from_crs(source, target, always_xy=True),
    )


def _transformer(crs: CRS, *, inverse: bool) -> Any:
    """pyproj's transformer between ``crs`` (made 3D) and ECEF."""
    key = (crs.model_dump_json(), "from ECEF" if inverse else "to ECEF")
    return _cached(key, lambda: _new_transformer(crs, inverse=inverse))


def _new_transformer(crs: CRS, *, inverse: bool) -> Any:
    """pyproj's transformer between ``crs`` (made 3D) and ECEF."""
    pyproj = _pyproj()
    from geobrep.gis.crs_ops import parse_crs

    parsed = parse_crs(crs)
    if not (parsed.is_projected or parsed.is_geographic):
        raise OptionsError(
            f"CRS {crs.label} is neither projected nor geographic: give the georeference "
            "(longitude, latitude, height)"
        )
    source = parsed.to_3d()
    if inverse:
        return pyproj.Transformer.from_crs(_ECEF, source, always_xy=True)
    return pyproj.Transformer.from_crs(source, _ECEF, always_xy=True)
