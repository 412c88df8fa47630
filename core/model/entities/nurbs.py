"""NURBS surfaces: the output of the fitters and an exact, compact surface representation."""

from __future__ import annotations

from functools import cached_property
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import Field, model_validator

from geobrep.geometry.bbox import BoundingBox
from geobrep.model.arrays import ControlNet, FloatArray, WeightGrid
from geobrep.model.entities.base import Entity

if TYPE_CHECKING:
    from geobrep.geometry import nurbs as nurbs_eval
    from geobrep.model.entities.surface import Surface

__all__ = ["NurbsSurface"]


class NurbsSurface(Entity):
    """A tensor-product NURBS surface of degrees ``(degree_u, degree_v)``.

    ``control_points`` is the ``(nu, nv, 3)`` control net, ``weights`` its ``(nu, nv)`` positive
    weights (all ones when omitted: a B-spline surface), and the knot vectors have
    ``nu + degree_u + 1`` and ``nv + degree_v + 1`` non-decreasing values. ``point_data`` holds one
    value per control point, flattened in row-major ``(u, v)`` order.

    >>> import numpy as np
    >>> net = np.zeros((2, 2, 3)); net[1, :, 0] = 1; net[:, 1, 1] = 1
    >>> NurbsSurface(degree_u=1, degree_v=1, knots_u=[0, 0, 1, 1], knots_v=[0, 0, 1, 1],
    ...              control_points=net).shape
    (2, 2)
    """

    type: Literal["NurbsSurface"] = "NurbsSurface"
    degree_u: int = Field(ge=1)
    degree_v: int = Field(ge=1)
    knots_u: FloatArray
    knots_v: FloatArray
    control_points: ControlNet
    weights: WeightGrid

    @model_validator(mode="before")
    @classmethod
    def _default_weights(cls, data: Any) -> Any:
        if isinstance(data, dict) and "weights" not in data and "control_points" in data:
            net = np.asarray(data["control_points"])
            if net.ndim == 3:
                data = {**data, "weights": np.ones(net.shape[:2])}
        return data

    @property
    def shape(self) -> tuple[int, int]:
        """Control-net size ``(nu, nv)``."""
        return int(self.control_points.shape[0]), int(self.control_points.shape[1])

    @property
    def n_points(self) -> int:
        nu, nv = self.shape
        return nu * nv

    @property
    def is_rational(self) -> bool:
        return (
            not bool(np.all(self.weights == self.weights.flat[0])) if self.weights.size else False
        )

    @property
    def domain(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """Parameter domain ``((u_min, u_max), (v_min, v_max))``."""
        return self.net.domain

    @property
    def net(self) -> nurbs_eval.NurbsNet:
        """The evaluation net (degrees, knots, control points; weights only when rational).

        >>> net = np.zeros((2, 2, 3)); net[1, :, 0] = 1; net[:, 1, 1] = 1
        >>> s = NurbsSurface(degree_u=1, degree_v=1, knots_u=[0, 0, 1, 1], knots_v=[0, 0, 1, 1],
        ...                  control_points=net)
        >>> s.net.shape, s.net.weights is None
        ((2, 2), True)
        """
        from geobrep.geometry import nurbs as nurbs_eval  # the evaluator, on first use

        return nurbs_eval.NurbsNet(
            self.degree_u,
            self.degree_v,
            self.knots_u,
            self.knots_v,
            self.control_points,
            self.weights if self.is_rational else None,
        )

    def evaluate(self, u: ArrayLike, v: ArrayLike) -> NDArray[np.float64]:
        """Surface points at parameter pairs ``(u[i], v[i])``: shape ``(m, 3)``.

        >>> net = np.zeros((2, 2, 3)); net[1, :, 0] = 1; net[:, 1, 1] = 1
        >>> s = NurbsSurface(degree_u=1, degree_v=1, knots_u=[0, 0, 1, 1], knots_v=[0, 0, 1, 1],
        ...                  control_points=net)
        >>> s.evaluate([0.5], [0.25]).tolist()
        [[0.5, 0.25, 0.0]]
        """
        from geobrep.geometry import nurbs as nurbs_eval

        return nurbs_eval.surface_points(self.net, u, v)

    def derivatives(self, u: ArrayLike, v: ArrayLike, order: int = 1) -> NDArray[np.float64]:
        """Partial derivatives ``[:, k, l] = ∂^(k+l)S/∂u^k∂v^l`` (``k + l <= order``)."""
        from geobrep.geometry import nurbs as nurbs_eval

        return nurbs_eval.surface_derivatives(self.net, u, v, order=order)

    def tessellate(
        self, resolution: int | tuple[int, int] | None = None, tolerance: float | None = None
    ) -> Surface:
        """A triangle mesh of the surface on a parameter grid.

        ``resolution`` is the number of samples per direction; ``tolerance`` refines a grid that
        keeps the knot lines until the mesh is within ``tolerance`` of the surface (checked at cell
        centres and edge midpoints). The mesh has point properties ``u`` and ``v`` and metadata
        ``grid_shape`` and ``deviation``.

        >>> net = np.zeros((2, 2, 3)); net[1, :, 0] = 1; net[:, 1, 1] = 1
        >>> s = NurbsSurface(degree_u=1, degree_v=1, knots_u=[0, 0, 1, 1], knots_v=[0, 0, 1, 1],
        ...                  control_points=net)
        >>> mesh = s.tessellate(resolution=3)
        >>> mesh.n_vertices, mesh.n_faces, mesh.area
        (9, 8, 1.0)
        """
        from geobrep.geometry import nurbs as nurbs_eval
        from geobrep.model.entities.surface import Surface

        if resolution is not None and tolerance is not None:
            raise self.fail("tessellate", "give resolution or tolerance, not both")
        if tolerance is not None and not tolerance > 0:
            raise self.fail("tessellate", f"tolerance must be > 0, got {tolerance}")
        try:
            grid = nurbs_eval.tessellate(self.net, resolution=resolution, tolerance=tolerance)
        except ValueError as exc:
            raise self.fail("tessellate", str(exc)) from exc
        uu, vv = np.meshgrid(grid.u, grid.v, indexing="ij")
        return Surface(
            vertices=grid.vertices,
            faces=grid.faces,
            name=self.name,
            kind=self.kind,
            metadata={
                **self.metadata,
                "grid_shape": [int(grid.u.shape[0]), int(grid.v.shape[0])],
                "deviation": grid.deviation,
            },
            point_data={"u": uu.reshape(-1), "v": vv.reshape(-1)},
        )

    @cached_property
    def bounds(self) -> BoundingBox | None:
        """Box of the control net (it contains the surface: convex-hull property)."""
        if self.control_points.size == 0:
            return None
        return BoundingBox.from_points(self.control_points.reshape(-1, 3))

    def _check(self) -> None:
        nu, nv = self.shape
        for axis, degree, count, knots in (
            ("u", self.degree_u, nu, self.knots_u),
            ("v", self.degree_v, nv, self.knots_v),
        ):
            if count < degree + 1:
                raise self.fail(
                    "control_points", f"{count} rows along {axis} need degree ≤ {count - 1}"
                )
            if knots.shape[0] != count + degree + 1:
                raise self.fail(
                    f"knots_{axis}",
                    f"has {knots.shape[0]} values; {count} control points of degree {degree} "
                    f"need {count + degree + 1}",
                )
            if np.any(np.diff(knots) < 0):
                raise self.fail(f"knots_{axis}", "must be non-decreasing")
            if knots[degree] >= knots[count]:
                raise self.fail(f"knots_{axis}", "the parameter domain is empty")
        if self.weights.shape != (nu, nv):
            raise self.fail(
                "weights", f"shape {self.weights.shape} does not match the net ({nu}, {nv})"
            )
        if self.weights.size and self.weights.min() <= 0:
            raise self.fail("weights", "must be positive")
        if self.cell_data:
            raise self.fail("cell_data", "a NurbsSurface has no cells; tessellate it first")
