"""The local frame of a data set: origin, best-fit plane, and in-plane axes.

Fitting happens in local coordinates ``(a, b, h)``: ``a, b`` along the best-fit plane, ``h``
along its normal, relative to the centroid. UTM-scale coordinates keep full precision this way,
and the result goes back to world coordinates exactly (a NURBS is affine invariant: transforming the
control net transforms the surface).

>>> import numpy as np
>>> pts = np.array([[450000.0, 6700000.0, 1.0], [450010.0, 6700000.0, 1.0],
...                 [450000.0, 6700010.0, 1.0], [450010.0, 6700010.0, 1.0]])
>>> frame = LocalFrame.from_points(pts)
>>> frame.to_local(pts).round(6).tolist()[0]
[-5.0, -5.0, 0.0]
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geobrep.errors import DegenerateGeometryError
from geobrep.geometry.arrays import FloatArray

__all__ = ["LocalFrame"]


@dataclass(frozen=True)
class LocalFrame:
    """``origin (3,)`` and orthonormal ``axes (3, 3)``: rows are in-plane a, b and the normal."""

    origin: FloatArray
    axes: FloatArray

    @classmethod
    def from_points(cls, points: FloatArray, label: str = "points") -> LocalFrame:
        """Centroid and best-fit plane of ``points`` (principal axes).

        The normal points up (positive z) when the plane is not vertical; the first in-plane axis
        is world x projected onto the plane (world y for a plane across x), so survey grids stay
        aligned with the axes.

        Raises:
            DegenerateGeometryError: fewer than 3 distinct points, or all on one line.
        """
        origin = points.mean(axis=0)
        centred = points - origin
        extent = float(np.abs(centred).max(initial=0.0))
        if points.shape[0] < 3 or extent == 0.0:
            raise DegenerateGeometryError(f"{label}: at least 3 distinct points are needed")
        _, singular, vt = np.linalg.svd(centred / extent, full_matrices=False)
        if singular.shape[0] < 2 or singular[1] <= 1e-9 * singular[0]:
            raise DegenerateGeometryError(
                f"{label}: all points lie on one line; a surface cannot be fitted"
            )
        normal = vt[2] if vt.shape[0] > 2 else np.cross(vt[0], vt[1])
        normal = normal / np.linalg.norm(normal)
        if abs(normal[2]) > 1e-12:
            normal = normal * np.sign(normal[2])
        reference = np.array([1.0, 0.0, 0.0])
        a = reference - normal * (reference @ normal)
        if np.linalg.norm(a) < 0.1:
            reference = np.array([0.0, 1.0, 0.0])
            a = reference - normal * (reference @ normal)
        a = a / np.linalg.norm(a)
        b = np.cross(normal, a)
        return cls(origin=origin, axes=np.vstack([a, b, normal]))

    def rotated(self, angle: float) -> LocalFrame:
        """The same plane with the in-plane axes turned by ``angle`` radians about the normal."""
        c, s = np.cos(angle), np.sin(angle)
        a, b, n = self.axes
        return LocalFrame(self.origin, np.vstack([c * a + s * b, -s * a + c * b, n]))

    def to_local(self, points: FloatArray) -> FloatArray:
        """World → local ``(a, b, h)``."""
        return np.asarray((points - self.origin) @ self.axes.T)

    def to_world(self, local: FloatArray) -> FloatArray:
        """Local ``(a, b, h)`` → world."""
        return np.asarray(local @ self.axes + self.origin)

    def vectors_to_world(self, local: FloatArray) -> FloatArray:
        """Directions (no origin shift) local → world."""
        return np.asarray(local @ self.axes)
