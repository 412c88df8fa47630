"""Oriented planes a·x + b·y + c·z + d = 0 and point/plane queries."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from geobrep.errors import DegenerateGeometryError, EntityValidationError

__all__ = ["Plane"]

# Relative threshold under which three points are considered collinear.
_COLLINEAR_RTOL = 1e-12


def _as_float_array(values: ArrayLike, entity: str, field: str) -> NDArray[np.float64]:
    """Return ``values`` as a float64 array, or raise EntityValidationError naming ``field``."""
    try:
        return np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise EntityValidationError(entity, field, f"not a numeric array: {exc}") from exc


def _as_points(points: ArrayLike, entity: str, field: str = "points") -> NDArray[np.float64]:
    """Return ``points`` as a finite float64 (N, 3) array; a single (3,) point becomes (1, 3)."""
    arr = _as_float_array(points, entity, field)
    if arr.ndim == 1 and arr.shape[0] == 3:
        arr = arr.reshape(1, 3)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise EntityValidationError(
            entity, field, f"expected shape (3,) or (N, 3), got {np.shape(points)}"
        )
    if not np.isfinite(arr).all():
        raise EntityValidationError(entity, field, "contains NaN or infinite values")
    return arr


def _as_point(point: ArrayLike, entity: str, field: str) -> NDArray[np.float64]:
    """Return ``point`` as a finite float64 (3,) array."""
    arr = _as_float_array(point, entity, field)
    if arr.shape != (3,):
        raise EntityValidationError(entity, field, f"expected shape (3,), got {arr.shape}")
    if not np.isfinite(arr).all():
        raise EntityValidationError(entity, field, "contains NaN or infinite values")
    return arr


@dataclass(frozen=True, slots=True)
class Plane:
    """The oriented plane a·x + b·y + c·z + d = 0; its positive side is where the sum is > 0.

    >>> Plane.x(450).side([[400, 0, 0], [500, 0, 0]]).tolist()
    [-1, 1]
    """

    a: float
    b: float
    c: float
    d: float

    def __post_init__(self) -> None:
        for name in ("a", "b", "c", "d"):
            try:
                value = float(getattr(self, name))
            except (TypeError, ValueError) as exc:
                raise DegenerateGeometryError(
                    f"Plane: coefficient {name} is not a number: {getattr(self, name)!r}"
                ) from exc
            if not math.isfinite(value):
                raise DegenerateGeometryError(f"Plane: coefficient {name} is not finite: {value}")
            object.__setattr__(self, name, value + 0.0)  # + 0.0 turns -0.0 into 0.0
        if self.a == 0.0 and self.b == 0.0 and self.c == 0.0:
            raise DegenerateGeometryError("Plane: normal (a, b, c) is the zero vector")
        if not math.isfinite(math.hypot(self.a, self.b, self.c)):
            raise DegenerateGeometryError("Plane: normal (a, b, c) is too large to normalise")

    # ----------------------------------------------------------------- constructors
    @classmethod
    def from_point_normal(cls, point: ArrayLike, normal: ArrayLike) -> Plane:
        """Plane through ``point`` with (unit-normalised) ``normal``.

        >>> Plane.from_point_normal((0, 0, 5), (0, 0, 2))
        Plane(a=0.0, b=0.0, c=1.0, d=-5.0)
        """
        p = _as_point(point, "Plane.from_point_normal", "point")
        n = _as_point(normal, "Plane.from_point_normal", "normal")
        length = math.hypot(*n.tolist())
        if length == 0.0:
            raise DegenerateGeometryError("Plane.from_point_normal: normal is the zero vector")
        n = n / length
        return cls(float(n[0]), float(n[1]), float(n[2]), -float(n @ p))

    @classmethod
    def x(cls, value: float) -> Plane:
        """The plane x = ``value``, positive side x > value.

        >>> Plane.x(450)
        Plane(a=1.0, b=0.0, c=0.0, d=-450.0)
        """
        return cls(1.0, 0.0, 0.0, -float(value))

    @classmethod
    def y(cls, value: float) -> Plane:
        """The plane y = ``value``, positive side y > value.

        >>> Plane.y(6700000).d
        -6700000.0
        """
        return cls(0.0, 1.0, 0.0, -float(value))

    @classmethod
    def z(cls, value: float) -> Plane:
        """The plane z = ``value``, positive side z > value.

        >>> Plane.z(-100).d
        100.0
        """
        return cls(0.0, 0.0, 1.0, -float(value))

    @classmethod
    def from_points(cls, p0: ArrayLike, p1: ArrayLike, p2: ArrayLike) -> Plane:
        """Plane through three points; unit normal (p1 − p0) × (p2 − p0) (right-hand rule).

        >>> Plane.from_points((0, 0, 1), (1, 0, 1), (0, 1, 1))
        Plane(a=0.0, b=0.0, c=1.0, d=-1.0)
        """
        q0 = _as_point(p0, "Plane.from_points", "p0")
        q1 = _as_point(p1, "Plane.from_points", "p1")
        q2 = _as_point(p2, "Plane.from_points", "p2")
        u = q1 - q0
        v = q2 - q0
        n = np.cross(u, v)
        length = math.hypot(*n.tolist())
        scale = math.hypot(*u.tolist()) * math.hypot(*v.tolist())
        if length <= _COLLINEAR_RTOL * scale or length == 0.0:
            raise DegenerateGeometryError(
                "Plane.from_points: p0, p1 and p2 are collinear or coincident"
            )
        n = n / length
        # Mean of the three points as the reference: the best-conditioned d.
        centre = (q0 + q1 + q2) / 3.0
        return cls(float(n[0]), float(n[1]), float(n[2]), -float(n @ centre))

    # ----------------------------------------------------------------- properties
    @property
    def normal(self) -> NDArray[np.float64]:
        """Unit normal, float64 (3,), pointing to the positive side.

        >>> Plane(0, 0, 2, 1).normal.tolist()
        [0.0, 0.0, 1.0]
        """
        length = math.hypot(self.a, self.b, self.c)
        return np.array([self.a / length, self.b / length, self.c / length], dtype=np.float64)

    @property
    def coefficients(self) -> NDArray[np.float64]:
        """The (4,) float64 array [a, b, c, d].

        >>> Plane.z(3).coefficients.tolist()
        [0.0, 0.0, 1.0, -3.0]
        """
        return np.array([self.a, self.b, self.c, self.d], dtype=np.float64)

    @property
    def point(self) -> NDArray[np.float64]:
        """The point of the plane closest to the origin.

        >>> Plane(0, 0, 2, -4).point.tolist()
        [0.0, 0.0, 2.0]
        """
        length = math.hypot(self.a, self.b, self.c)
        return self.normal * (-self.d / length)

    # ----------------------------------------------------------------- queries
    def signed_distance(self, points: ArrayLike) -> NDArray[np.float64]:
        """Signed Euclidean distance of (N, 3) points (a single (3,) point gives shape (1,)).

        >>> Plane(0, 0, 2, -4).signed_distance([[0, 0, 5], [1, 1, 0]]).tolist()
        [3.0, -2.0]
        """
        pts = _as_points(points, "Plane.signed_distance")
        length = math.hypot(self.a, self.b, self.c)
        value = pts[:, 0] * self.a + pts[:, 1] * self.b + pts[:, 2] * self.c + self.d
        return np.asarray(value / length, dtype=np.float64)

    def side(self, points: ArrayLike, tolerance: float = 0.0) -> NDArray[np.int8]:
        """Side of each point: +1 positive, −1 negative, 0 within ``tolerance`` of the plane.

        >>> Plane.z(0).side([[0, 0, 1], [0, 0, -1], [0, 0, 1e-9]], tolerance=1e-6).tolist()
        [1, -1, 0]
        """
        tol = _check_tolerance(tolerance, "Plane.side")
        dist = self.signed_distance(points)
        out = np.zeros(dist.shape, dtype=np.int8)
        out[dist > tol] = 1
        out[dist < -tol] = -1
        return out

    def flipped(self) -> Plane:
        """The same plane with the opposite orientation.

        >>> Plane.x(1).flipped()
        Plane(a=-1.0, b=0.0, c=0.0, d=1.0)
        """
        return Plane(-self.a, -self.b, -self.c, -self.d)

    def project(self, points: ArrayLike) -> NDArray[np.float64]:
        """Orthogonal projection of (N, 3) points onto the plane (a (3,) point gives (1, 3)).

        >>> Plane.z(2).project([5, 6, 7]).tolist()
        [[5.0, 6.0, 2.0]]
        """
        pts = _as_points(points, "Plane.project")
        dist = self.signed_distance(pts)
        return pts - dist[:, None] * self.normal[None, :]


def _check_tolerance(tolerance: float, entity: str) -> float:
    tol = float(tolerance)
    if not math.isfinite(tol) or tol < 0.0:
        raise EntityValidationError(entity, "tolerance", f"must be finite and >= 0, got {tol}")
    return tol
