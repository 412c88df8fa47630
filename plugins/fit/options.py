"""Options of the four fitters (pydantic models: validation and JSON Schema from one place).

Kriging options follow PyKrige's names (``variogram_model``, ``variogram_parameters``, ``nlags``,
``weight``, ``gridx``, ``gridy``, ``n_closest_points``, ``drift_terms``, ``exact_values``).

>>> params = {"sill": 2.0, "range": 300.0, "nugget": 0.1}
>>> KrigingOptions(variogram_model="gaussian", variogram_parameters=params).variogram_model
'gaussian'
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from geobrep import NurbsSurface

__all__ = [
    "ApproximationOptions",
    "BoundaryCurve",
    "HybridOptions",
    "KrigingOptions",
    "SkinningOptions",
]

Side = Literal["u0", "u1", "v0", "v1"]


def _as_list(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return value.tolist()
    return value


class BoundaryCurve(BaseModel):
    """A clamped B-spline curve the fitted surface must contain exactly on one of its sides.

    Take it from a neighbouring surface with :meth:`from_surface`, so the two pieces join without a
    gap: ``BoundaryCurve.from_surface(left, "u1")`` is the right-hand edge of ``left``.
    """

    model_config = ConfigDict(frozen=True, extra="forbid", defer_build=True)

    degree: int = Field(ge=1, le=9)
    knots: list[float]
    control_points: list[tuple[float, float, float]]

    _as_lists = field_validator("knots", "control_points", mode="before")(_as_list)

    @model_validator(mode="after")
    def _check(self) -> BoundaryCurve:
        n = len(self.control_points)
        knots = np.asarray(self.knots)
        if n < self.degree + 1:
            raise ValueError(f"{n} control points are too few for degree {self.degree}")
        if knots.shape[0] != n + self.degree + 1:
            raise ValueError(
                f"{knots.shape[0]} knots for {n} control points of degree {self.degree}; "
                f"expected {n + self.degree + 1}"
            )
        if not np.isfinite(knots).all() or not np.isfinite(np.asarray(self.control_points)).all():
            raise ValueError("knots and control points must be finite")
        if np.any(np.diff(knots) < 0):
            raise ValueError("knots must be non-decreasing")
        if np.ptp(knots[: self.degree + 1]) != 0 or np.ptp(knots[-self.degree - 1 :]) != 0:
            raise ValueError(
                "the knot vector must be clamped (end knots repeated degree + 1 times)"
            )
        if knots[self.degree] >= knots[n]:
            raise ValueError("the parameter domain is empty")
        return self

    @classmethod
    def from_surface(cls, surface: NurbsSurface, side: Side) -> BoundaryCurve:
        """The boundary curve of a clamped, non-rational NurbsSurface on ``side``.

        ``"u0"``/``"u1"``: the edges at the first/last u (running along v); ``"v0"``/``"v1"``: at
        the first/last v (running along u).
        """
        from geobrep.plugins.fit._curves import surface_boundary

        curve = surface_boundary(surface, side)
        return cls(
            degree=curve.degree,
            knots=curve.knots.tolist(),
            control_points=[tuple(p) for p in curve.control_points.tolist()],
        )


class _FitOptions(BaseModel):
    model_config = ConfigDict(
        frozen=True, extra="forbid", arbitrary_types_allowed=True, defer_build=True
    )

    epsilon: float | None = Field(default=None, gt=0)
    """Control error ε: the report passes when σ < ε (and the net size is chosen to meet it)."""


class _Degrees(_FitOptions):
    degree_u: int = Field(default=3, ge=1, le=7)
    degree_v: int = Field(default=3, ge=1, le=7)


class _PointRoles(_Degrees):
    weight_property: str | None = None
    """Point property of per-point weights (finite, ≥ 0) of the least-squares misfit: a point of
    weight w counts as w points (default 1 each)."""
    exact_property: str | None = None
    """Point property flagging (non-zero) points the surface must pass through exactly: hard
    data such as well markers."""


class SkinningOptions(_Degrees):
    """Skinning: ``degree_u`` along the rows/sections, ``degree_v`` across them."""

    row_property: str | None = None
    """Integer point property numbering the row of each point (rows found automatically if None)."""


class ApproximationOptions(_PointRoles):
    """Least-squares approximation with bending-energy smoothing and boundary constraints."""

    control_points: tuple[int, int] | None = None
    """Net size ``(nu, nv)``; by default the smallest net meeting ``epsilon`` is searched for."""
    max_control_points: int = Field(default=200, ge=2)
    """Upper bound of the net size per direction in the automatic search."""
    smoothing: float = Field(default=1e-8, ge=0)
    """Weight of the bending energy, relative to data density and extent: ``λ = smoothing · ρ · D⁴``
    (``ρ`` points per area, ``D`` the diagonal). Wiggles with wavelengths below about
    ``2π · smoothing^¼ · D`` are damped (1e-8: about 6 % of D); 0 turns smoothing off."""
    parameterization: Literal["plane", "base_surface"] = "plane"
    """``plane``: project onto the best-fit plane; ``base_surface``: closest points on
    ``base_surface`` (for steep, folded or overturned surfaces)."""
    base_surface: NurbsSurface | None = None
    boundary_curves: dict[Side, BoundaryCurve] = Field(default_factory=dict)
    """Curves the result must contain exactly, by side (``u0``, ``u1``, ``v0``, ``v1``)."""
    grid_shape: tuple[int, int] | None = None
    """The points are an ordered ``(rows, columns)`` grid (row-major, as
    ``geomdl.fitting.approximate_surface`` takes them): parameters by averaged chord length, all
    three coordinates fitted, and without smoothing a separable (tensor-product) solve."""

    @field_validator("control_points")
    @classmethod
    def _net_size(cls, value: tuple[int, int] | None) -> tuple[int, int] | None:
        if value is not None and min(value) < 2:
            raise ValueError("a net needs at least 2 control points per direction")
        return value

    @model_validator(mode="after")
    def _base(self) -> ApproximationOptions:
        if self.grid_shape is not None:
            if min(self.grid_shape) < 2:
                raise ValueError("grid_shape needs at least 2 rows and 2 columns")
            if self.boundary_curves or self.parameterization != "plane":
                raise ValueError("grid_shape takes neither boundary_curves nor a base_surface")
            if self.weight_property is not None or self.exact_property is not None:
                raise ValueError("grid_shape takes neither weight_property nor exact_property")
        if self.parameterization == "base_surface" and self.base_surface is None:
            raise ValueError("parameterization 'base_surface' needs the option base_surface")
        if self.parameterization == "plane" and self.base_surface is not None:
            raise ValueError("base_surface is only used with parameterization='base_surface'")
        return self


class KrigingOptions(_FitOptions):
    """Ordinary (or universal) kriging onto a grid; PyKrige's option names."""

    variogram_model: Literal["spherical", "exponential", "gaussian", "matern"] = "spherical"
    variogram_parameters: dict[str, float] | list[float] | None = None
    """``{"sill", "range", "nugget"}`` (``"psill"`` instead of ``"sill"`` allowed; ``"nu"`` for
    Matérn) or ``[sill, range, nugget]``; fitted to the experimental variogram when absent."""
    nlags: int = Field(default=12, ge=3)
    """Number of lag bins of the experimental variogram."""
    weight: bool = False
    """Weight the variogram fit towards short lags (as PyKrige's ``weight``)."""
    gridx: list[float] | None = None
    gridy: list[float] | None = None
    grid_size: int = Field(default=100, ge=2)
    """Grid nodes per axis over the data's bounding box when ``gridx``/``gridy`` are absent."""
    n_closest_points: int | None = Field(default=None, ge=2)
    """Moving neighbourhood: krige each node from its ``n`` nearest data points."""
    drift_terms: list[Literal["regional_linear"]] = Field(default_factory=list)
    """``["regional_linear"]``: universal kriging with a linear drift in x and y."""
    exact_values: bool = True
    """Honour the data exactly at nodes that coincide with data points (as PyKrige)."""

    _as_lists = field_validator("gridx", "gridy", "variogram_parameters", mode="before")(_as_list)

    @field_validator("gridx", "gridy")
    @classmethod
    def _grid_axis(cls, value: list[float] | None) -> list[float] | None:
        if value is None:
            return value
        axis = np.asarray(value, dtype=np.float64)
        if axis.shape[0] < 2 or not np.isfinite(axis).all() or np.any(np.diff(axis) <= 0):
            raise ValueError("grid axes need at least 2 finite, strictly increasing values")
        return value

    @field_validator("variogram_parameters")
    @classmethod
    def _parameters(
        cls, value: dict[str, float] | list[float] | None
    ) -> dict[str, float] | list[float] | None:
        if isinstance(value, list) and len(value) != 3:
            raise ValueError("a list must be [sill, range, nugget]")
        if isinstance(value, dict):
            unknown = set(value) - {"sill", "psill", "range", "nugget", "nu"}
            if unknown:
                raise ValueError(f"unknown keys {sorted(unknown)}: use sill, range, nugget (nu)")
            if "range" not in value or not ({"sill", "psill"} & set(value)):
                raise ValueError("give at least 'sill' (or 'psill') and 'range'")
        return value

    @model_validator(mode="after")
    def _grid(self) -> KrigingOptions:
        if (self.gridx is None) != (self.gridy is None):
            raise ValueError("give both gridx and gridy, or neither")
        return self


class HybridOptions(_PointRoles):
    """The hybrid workflow: skin the dense core, approximate the rim with the core as constraint."""

    core_property: str | None = None
    """Point property flagging core points (non-zero); by default the core is found by density."""
    core_polygon: list[tuple[float, float]] | None = None
    """Polygon (x, y) enclosing the core, in the points' coordinates."""
    smoothing: float = Field(default=1e-8, ge=0)
    """Bending-energy weight of the rim approximation (see ApproximationOptions.smoothing)."""
    max_control_points: int = Field(default=200, ge=2)
    """Upper bound of rim spans per direction in the automatic search."""

    _as_lists = field_validator("core_polygon", mode="before")(_as_list)

    @model_validator(mode="after")
    def _core(self) -> HybridOptions:
        if self.core_property is not None and self.core_polygon is not None:
            raise ValueError("give core_property or core_polygon, not both")
        if self.core_polygon is not None and len(self.core_polygon) < 3:
            raise ValueError("core_polygon needs at least 3 vertices")
        return self
