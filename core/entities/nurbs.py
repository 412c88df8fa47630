"""NURBS surfaces: the output of the fitters and an exact, compact surface representation."""

from __future__ import annotations

from functools import cached_property
from typing import Any, Literal

import numpy as np
from pydantic import Field, model_validator

from geobrep.arrays import ControlNet, FloatArray, WeightGrid
from geobrep.entities.base import Entity
from geobrep.geometry.bbox import BoundingBox

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
