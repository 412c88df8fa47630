"""B-spline curves: global interpolation, knot refinement, and the boundary curves of a surface.

>>> import numpy as np
>>> points = np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [2.0, 0.0, 0.0], [3.0, 1.0, 0.0]])
>>> curve = interpolate_curve(points, degree=3)
>>> bool(np.allclose(curve.evaluate(curve.parameters), points))
True
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from geobrep import NurbsSurface
from geobrep.errors import DegenerateGeometryError, OptionsError
from geobrep.geometry.arrays import FloatArray
from geobrep.geometry.nurbs import basis_functions, basis_matrix, find_spans
from geobrep.plugins.fit._knots import (
    averaged_knots,
    chord_parameters,
    insert_knots,
    missing_knots,
)

__all__ = ["BSplineCurve", "Side", "interpolate_curve", "surface_boundary"]

Side = Literal["u0", "u1", "v0", "v1"]


@dataclass(frozen=True)
class BSplineCurve:
    """A non-rational B-spline curve: ``degree``, clamped ``knots``, ``control_points (n, d)``.

    ``parameters`` optionally records the parameters of the points a curve interpolates.
    """

    degree: int
    knots: FloatArray
    control_points: FloatArray
    parameters: FloatArray = field(default_factory=lambda: np.zeros(0))

    @property
    def n_ctrl(self) -> int:
        return int(self.control_points.shape[0])

    @property
    def domain(self) -> tuple[float, float]:
        return float(self.knots[self.degree]), float(self.knots[self.n_ctrl])

    def evaluate(self, params: ArrayLike) -> FloatArray:
        """Curve points at ``params``: shape ``(m, d)``."""
        t = np.asarray(params, dtype=np.float64).reshape(-1)
        spans = find_spans(self.degree, self.knots, t)
        values = basis_functions(self.degree, self.knots, spans, t)
        index = spans[:, None] - self.degree + np.arange(self.degree + 1)
        return np.asarray(np.einsum("mi,mid->md", values, self.control_points[index]))

    def refined(self, knots: FloatArray) -> BSplineCurve:
        """The same curve on a finer knot vector that contains this curve's knots."""
        extra = missing_knots(knots, self.knots)
        if extra is None:
            raise OptionsError("knot vector of the target does not contain every knot of the curve")
        new_knots, points = insert_knots(self.degree, self.knots, self.control_points, extra)
        return BSplineCurve(self.degree, new_knots, points, self.parameters)

    def reparameterized(self, start: float, end: float) -> BSplineCurve:
        """The same curve with its domain mapped linearly onto ``[start, end]``."""
        a, b = self.domain
        scale = (end - start) / (b - a)
        knots = start + (self.knots - a) * scale
        knots[: self.degree + 1] = start
        knots[-self.degree - 1 :] = end
        params = start + (self.parameters - a) * scale if self.parameters.size else self.parameters
        return BSplineCurve(self.degree, knots, self.control_points, params)


def interpolate_curve(
    points: FloatArray,
    degree: int,
    params: FloatArray | None = None,
    knots: FloatArray | None = None,
    label: str = "curve",
) -> BSplineCurve:
    """Global interpolation (A9.1): the curve of ``degree`` through every point.

    Parameters default to chord length and knots to averaging (eq. 9.8).

    Raises:
        OptionsError: fewer than ``degree + 1`` points.
        DegenerateGeometryError: duplicate consecutive points, or a singular system.
    """
    pts = np.asarray(points, dtype=np.float64)
    n = pts.shape[0]
    if n < degree + 1:
        raise OptionsError(
            f"{label}: {n} points cannot define a curve of degree {degree} "
            f"(it needs at least {degree + 1})"
        )
    t = chord_parameters(pts, label=label) if params is None else np.asarray(params, np.float64)
    kv = averaged_knots(degree, t) if knots is None else knots
    matrix = basis_matrix(degree, kv, t)
    try:
        control = np.linalg.solve(matrix, pts)
    except np.linalg.LinAlgError as exc:
        raise DegenerateGeometryError(
            f"{label}: the interpolation system is singular (parameters violate the "
            "Schoenberg-Whitney condition for the knot vector)"
        ) from exc
    return BSplineCurve(degree, np.asarray(kv, np.float64), np.asarray(control, np.float64), t)


def surface_boundary(surface: NurbsSurface, side: Side) -> BSplineCurve:
    """The boundary curve of a clamped, non-rational NURBS surface on ``side``.

    ``"u0"``/``"u1"`` are the curves at the first/last u (running along v), ``"v0"``/``"v1"``
    those at the first/last v (running along u). Because the surface is clamped, the curve's
    control points are the boundary row of the net, so a neighbour fitted to it joins without a
    gap.

    >>> import numpy as np
    >>> from geobrep.model.entities import NurbsSurface
    >>> net = np.zeros((2, 2, 3)); net[1, :, 0] = 1; net[:, 1, 1] = 1
    >>> s = NurbsSurface(degree_u=1, degree_v=1, knots_u=[0, 0, 1, 1], knots_v=[0, 0, 1, 1],
    ...                  control_points=net)
    >>> surface_boundary(s, "u1").control_points.tolist()
    [[1.0, 0.0, 0.0], [1.0, 1.0, 0.0]]
    """
    if surface.is_rational:
        raise OptionsError(
            f"{surface.label}: boundary curves of rational surfaces are not supported"
        )
    net = np.asarray(surface.control_points)
    if side in ("u0", "u1"):
        degree, knots = surface.degree_u, np.asarray(surface.knots_u)
        along_degree, along_knots = surface.degree_v, np.asarray(surface.knots_v)
        row = net[0] if side == "u0" else net[-1]
    elif side in ("v0", "v1"):
        degree, knots = surface.degree_v, np.asarray(surface.knots_v)
        along_degree, along_knots = surface.degree_u, np.asarray(surface.knots_u)
        row = net[:, 0] if side == "v0" else net[:, -1]
    else:
        raise OptionsError(f"side must be one of u0, u1, v0, v1, not {side!r}")
    end = 0 if side.endswith("0") else -1
    clamp = knots[: degree + 1] if end == 0 else knots[-degree - 1 :]
    if np.ptp(clamp) != 0.0:
        raise DegenerateGeometryError(
            f"{surface.label}: knot vector is not clamped on side {side}; its boundary is not "
            "a row of the control net"
        )
    return BSplineCurve(along_degree, along_knots.copy(), np.array(row, dtype=np.float64))
